// SPDX-License-Identifier: MIT
// Greedy vertex aggregation, the tentative and smoothed prolongations and the multiplier
// transfer Q of the algebraic multigrid hierarchy.
#include "solvers/aggregation.hpp"

#include "core/check.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>

namespace mlc::solvers {

void AggregationParams::validate() const {
    MLC_CHECK(coarse_size >= 1, "aggregation: coarse_size must be >= 1, found " << coarse_size);
    MLC_CHECK(max_levels >= 2, "aggregation: max_levels must be >= 2, found " << max_levels);
    MLC_CHECK(smoothing >= 0.0 && smoothing < 2.0,
              "aggregation: smoothing must be in [0, 2), found " << smoothing);
}

std::ostream& operator<<(std::ostream& os, const AggregationParams& p) {
    return os << "AggregationParams{coarse_size=" << p.coarse_size
              << ", max_levels=" << p.max_levels << ", smoothing=" << p.smoothing << "}";
}

void AggregationInput::validate() const {
    MLC_CHECK(K != nullptr, "AggregationInput: no K");
    MLC_CHECK(K->rows() == K->cols(), "AggregationInput: K is " << K->rows() << " x " << K->cols());
    MLC_CHECK(K->isCompressed(), "AggregationInput: K must be compressed");
    MLC_CHECK(static_cast<Index>(vertex.size()) == K->rows() &&
                  static_cast<Index>(kind.size()) == K->rows(),
              "AggregationInput: K has " << K->rows() << " rows, vertex " << vertex.size()
                                         << " and kind " << kind.size() << " entries");
    MLC_CHECK(near_null.size() == 0 || near_null.rows() == K->rows(),
              "AggregationInput: near_null has " << near_null.rows() << " rows, K " << K->rows());
    for (Index i = 0; i < K->rows(); ++i)
        if (is_multiplier(kind[static_cast<size_t>(i)]))
            MLC_CHECK(K->outerIndexPtr()[i + 1] == K->outerIndexPtr()[i],
                      "AggregationInput: K has entries in multiplier row " << i);
}

namespace {

// The nodes of a level: runs of unknowns of one owner.
struct Nodes {
    std::vector<Index> start; // first unknown of each node, then the number of unknowns
    std::vector<int> of_unknown;
    int size() const { return static_cast<int>(start.size()) - 1; }
};

Nodes make_nodes(const std::vector<int>& vertex) {
    Nodes n;
    n.start = vertex_block_starts(vertex);
    n.start.push_back(static_cast<Index>(vertex.size()));
    n.of_unknown.resize(vertex.size());
    for (int k = 0; k < n.size(); ++k)
        for (Index i = n.start[static_cast<size_t>(k)]; i < n.start[static_cast<size_t>(k) + 1];
             ++i)
            n.of_unknown[static_cast<size_t>(i)] = k;
    return n;
}

// Node adjacency from the pattern of K (sorted, unique, no self loops).
std::vector<std::vector<int>> node_graph(const SparseMatrix& K, const Nodes& nodes) {
    std::vector<std::vector<int>> adj(static_cast<size_t>(nodes.size()));
    for (Index i = 0; i < K.rows(); ++i) {
        const int a = nodes.of_unknown[static_cast<size_t>(i)];
        for (int k = K.outerIndexPtr()[i]; k < K.outerIndexPtr()[i + 1]; ++k) {
            const int b = nodes.of_unknown[static_cast<size_t>(K.innerIndexPtr()[k])];
            if (a != b && K.valuePtr()[k] != 0.0) adj[static_cast<size_t>(a)].push_back(b);
        }
    }
    for (auto& l : adj) {
        std::sort(l.begin(), l.end());
        l.erase(std::unique(l.begin(), l.end()), l.end());
    }
    return adj;
}

// Greedy aggregation (Vanek, Mandel & Brezina 1996, without a strength threshold: P1 elasticity
// on a mesh of reasonable shape couples every edge): (1) a node whose neighbours are all free
// makes an aggregate of itself and them, contact nodes tried first so that contact aggregates
// sit along the contact boundary; (2) a node left over joins the neighbouring aggregate it shares
// most edges with (a contact node one that holds contact nodes, when there is one); (3) what is
// still left forms aggregates of itself and its free neighbours.
std::vector<int> aggregate_nodes(const std::vector<std::vector<int>>& adj,
                                 const std::vector<char>& is_contact, int& n_aggregates) {
    const int n = static_cast<int>(adj.size());
    std::vector<int> agg(static_cast<size_t>(n), -1);
    int na = 0;
    std::vector<int> order;
    order.reserve(static_cast<size_t>(n));
    for (int v = 0; v < n; ++v)
        if (is_contact[static_cast<size_t>(v)]) order.push_back(v);
    for (int v = 0; v < n; ++v)
        if (!is_contact[static_cast<size_t>(v)]) order.push_back(v);
    for (int v : order) {
        if (agg[static_cast<size_t>(v)] >= 0) continue;
        const auto& nb = adj[static_cast<size_t>(v)];
        if (std::any_of(nb.begin(), nb.end(),
                        [&](int w) { return agg[static_cast<size_t>(w)] >= 0; }))
            continue;
        agg[static_cast<size_t>(v)] = na;
        for (int w : nb)
            agg[static_cast<size_t>(w)] = na;
        ++na;
    }
    std::vector<char> agg_contact(static_cast<size_t>(na), 0);
    for (int v = 0; v < n; ++v)
        if (agg[static_cast<size_t>(v)] >= 0 && is_contact[static_cast<size_t>(v)])
            agg_contact[static_cast<size_t>(agg[static_cast<size_t>(v)])] = 1;
    std::vector<int> joined(agg); // phase 2 reads the phase 1 aggregates only
    for (int v : order) {
        if (agg[static_cast<size_t>(v)] >= 0) continue;
        int best = -1, best_count = 0;
        bool best_contact = false;
        for (int w : adj[static_cast<size_t>(v)]) {
            const int a = agg[static_cast<size_t>(w)];
            if (a < 0) continue;
            int count = 0;
            for (int u : adj[static_cast<size_t>(v)])
                count += agg[static_cast<size_t>(u)] == a;
            const bool c =
                is_contact[static_cast<size_t>(v)] && agg_contact[static_cast<size_t>(a)];
            if (best < 0 || (c && !best_contact) || (c == best_contact && count > best_count)) {
                best = a;
                best_count = count;
                best_contact = c;
            }
        }
        joined[static_cast<size_t>(v)] = best;
    }
    agg = std::move(joined);
    for (int v : order) {
        if (agg[static_cast<size_t>(v)] >= 0) continue;
        agg[static_cast<size_t>(v)] = na;
        for (int w : adj[static_cast<size_t>(v)])
            if (agg[static_cast<size_t>(w)] < 0) agg[static_cast<size_t>(w)] = na;
        ++na;
    }
    n_aggregates = na;
    return agg;
}

// rho(D^-1 K) on the displacement unknowns by power iteration (an estimate from below; the
// smoothing factor is a fraction of its inverse, so a few percent do not matter).
double spectral_radius(const SparseMatrix& DinvK) {
    Vector x = Vector::Ones(DinvK.cols());
    for (Index i = 0; i < x.size(); ++i)
        x[i] += 0.5 * std::sin(static_cast<double>(i) * 12.9898); // not an eigenvector
    double rho = 0.0;
    for (int it = 0; it < 30; ++it) {
        const double nx = x.norm();
        if (nx == 0.0) return 0.0;
        x /= nx;
        Vector y = DinvK * x;
        rho = y.norm();
        x.swap(y);
    }
    return rho;
}

} // namespace

AggregationStep aggregate_once(const AggregationInput& in, const AggregationParams& params) {
    params.validate();
    in.validate();
    const SparseMatrix& K = *in.K;
    const Nodes nodes = make_nodes(in.vertex);
    const auto adj = node_graph(K, nodes);
    std::vector<char> is_contact(static_cast<size_t>(nodes.size()), 0);
    for (size_t i = 0; i < in.kind.size(); ++i)
        if (is_multiplier(in.kind[i])) is_contact[static_cast<size_t>(nodes.of_unknown[i])] = 1;

    AggregationStep s;
    s.aggregate_of_node = aggregate_nodes(adj, is_contact, s.n_aggregates);
    const size_t na = static_cast<size_t>(s.n_aggregates);

    // Near-null space of the displacements: the input's rigid modes, or the translations.
    Eigen::MatrixXd B = in.near_null;
    if (B.size() == 0) {
        B = Eigen::MatrixXd::Zero(K.rows(), 2);
        for (size_t i = 0; i < in.kind.size(); ++i)
            if (in.kind[i] == UnknownKind::ux || in.kind[i] == UnknownKind::uy)
                B(static_cast<Index>(i), static_cast<Index>(in.kind[i])) = 1.0;
    }
    const Index nb = B.cols();

    // Unknowns of each aggregate: displacements, and multipliers per component.
    std::vector<std::vector<Index>> u_of(na);
    std::vector<std::array<std::vector<Index>, 2>> lambda_of(na);
    for (size_t i = 0; i < in.kind.size(); ++i) {
        const auto a =
            static_cast<size_t>(s.aggregate_of_node[static_cast<size_t>(nodes.of_unknown[i])]);
        if (is_multiplier(in.kind[i]))
            lambda_of[a][in.kind[i] == UnknownKind::lambda_t ? 0 : 1].push_back(
                static_cast<Index>(i));
        else
            u_of[a].push_back(static_cast<Index>(i));
    }

    // Tentative P per aggregate: B restricted to its displacements = Q_a R_a (QR with column
    // pivoting, columns beyond the numerical rank dropped); its coarse displacements are the
    // coefficients of Q_a's columns and the coarse near-null space is R_a. Then Q (the
    // multipliers: 1 / m, the force shared out), lambda_t before lambda_n.
    std::vector<Eigen::Triplet<double, int>> tp;
    tp.reserve(in.kind.size() * static_cast<size_t>(nb));
    std::vector<Eigen::MatrixXd> Rc(na);
    int nc = 0;
    for (size_t a = 0; a < na; ++a) {
        const auto& u = u_of[a];
        if (!u.empty()) {
            const auto m = static_cast<Index>(u.size());
            Eigen::MatrixXd Ba(m, nb);
            for (Index r = 0; r < m; ++r)
                Ba.row(r) = B.row(u[static_cast<size_t>(r)]);
            Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Ba);
            qr.setThreshold(1e-10);
            const Index rank = qr.rank();
            const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(m, rank);
            const Eigen::MatrixXd R =
                qr.matrixR().topRows(rank).template triangularView<Eigen::Upper>();
            Rc[a] = R * qr.colsPermutation().transpose();
            for (Index r = 0; r < m; ++r)
                for (Index c = 0; c < rank; ++c)
                    if (Q(r, c) != 0.0)
                        tp.emplace_back(static_cast<int>(u[static_cast<size_t>(r)]),
                                        nc + static_cast<int>(c), Q(r, c));
            for (Index c = 0; c < rank; ++c) {
                s.coarse_vertex.push_back(static_cast<int>(a));
                s.coarse_kind.push_back(UnknownKind::rigid_mode);
            }
            nc += static_cast<int>(rank);
        }
        for (int c = 0; c < 2; ++c) {
            const auto& l = lambda_of[a][static_cast<size_t>(c)];
            if (l.empty()) continue;
            for (Index i : l)
                tp.emplace_back(static_cast<int>(i), nc, 1.0 / static_cast<double>(l.size()));
            s.coarse_vertex.push_back(static_cast<int>(a));
            s.coarse_kind.push_back(c == 0 ? UnknownKind::lambda_t : UnknownKind::lambda_n);
            ++nc;
        }
    }
    s.P_tentative.resize(K.rows(), nc);
    s.P_tentative.setFromTriplets(tp.begin(), tp.end());
    s.P_tentative.makeCompressed();
    s.near_null_coarse = Eigen::MatrixXd::Zero(nc, nb);
    for (Index J = 0, a_prev = -1, r = 0; J < nc; ++J) {
        const auto a = static_cast<Index>(s.coarse_vertex[static_cast<size_t>(J)]);
        if (a != a_prev) r = 0;
        a_prev = a;
        if (s.coarse_kind[static_cast<size_t>(J)] == UnknownKind::rigid_mode)
            s.near_null_coarse.row(J) = Rc[static_cast<size_t>(a)].row(r++);
    }

    // D^-1: the inverse of each vertex's displacement block of K (up to 3 x 3); zero on
    // multiplier rows, so that they stay unsmoothed.
    std::vector<Eigen::Triplet<double, int>> td;
    for (int v = 0; v < nodes.size(); ++v) {
        std::vector<Index> u;
        for (Index i = nodes.start[static_cast<size_t>(v)];
             i < nodes.start[static_cast<size_t>(v) + 1]; ++i)
            if (!is_multiplier(in.kind[static_cast<size_t>(i)])) u.push_back(i);
        if (u.empty()) continue;
        const auto m = static_cast<Index>(u.size());
        Eigen::MatrixXd Kv(m, m);
        for (Index a = 0; a < m; ++a)
            for (Index b = 0; b < m; ++b)
                Kv(a, b) = K.coeff(u[static_cast<size_t>(a)], u[static_cast<size_t>(b)]);
        Eigen::FullPivLU<Eigen::MatrixXd> lu(Kv);
        MLC_CHECK(lu.isInvertible(), "aggregation: the displacement block of K at unknown "
                                         << u.front() << " is singular (" << Kv.norm()
                                         << "); every free displacement needs stiffness");
        const Eigen::MatrixXd Binv = lu.inverse();
        for (Index a = 0; a < m; ++a)
            for (Index b = 0; b < m; ++b)
                td.emplace_back(static_cast<int>(u[static_cast<size_t>(a)]),
                                static_cast<int>(u[static_cast<size_t>(b)]), Binv(a, b));
    }
    SparseMatrix Dinv(K.rows(), K.cols());
    Dinv.setFromTriplets(td.begin(), td.end());
    if (params.smoothing > 0.0) {
        const SparseMatrix DinvK = Dinv * K;
        const double rho = spectral_radius(DinvK);
        s.omega = rho > 0.0 ? params.smoothing / rho : 0.0;
        const SparseMatrix KP = K * s.P_tentative;
        const SparseMatrix DinvKP = Dinv * KP;
        s.T = s.P_tentative - s.omega * DinvKP;
        s.T.prune(0.0);
    } else {
        s.T = s.P_tentative;
    }
    s.T.makeCompressed();
    const SparseMatrix KT = K * s.T;
    s.K_coarse = SparseMatrix(s.T.transpose()) * KT;
    s.K_coarse.prune(0.0);
    s.K_coarse.makeCompressed();
    return s;
}

std::vector<MultigridLevelData> aggregation_levels(const AggregationInput& in,
                                                   const AggregationParams& params) {
    params.validate();
    in.validate();
    // Finest first while building, reversed at the end.
    std::vector<MultigridLevelData> out;
    MultigridLevelData finest;
    finest.block_starts = vertex_block_starts(in.vertex);
    out.push_back(std::move(finest));
    AggregationInput level = in;
    SparseMatrix K_level;
    Index rows = in.K->rows();
    double shrink = 2.0;
    while (static_cast<int>(out.size()) < params.max_levels &&
           (out.size() == 1 || (rows > params.coarse_size && shrink >= 1.2))) {
        AggregationStep s = aggregate_once(level, params);
        auto T = std::make_shared<const SparseMatrix>(std::move(s.T));
        auto R = std::make_shared<SparseMatrix>(T->transpose());
        R->makeCompressed();
        out.back().T = T.get();
        out.back().R = R.get();
        out.back().T_storage = T;
        out.back().R_storage = std::move(R);
        MultigridLevelData coarse;
        coarse.block_starts = vertex_block_starts(s.coarse_vertex);
        out.push_back(std::move(coarse));
        shrink = static_cast<double>(rows) / static_cast<double>(T->cols());
        rows = T->cols();
        K_level = std::move(s.K_coarse);
        level = AggregationInput{&K_level, std::move(s.coarse_vertex), std::move(s.coarse_kind),
                                 std::move(s.near_null_coarse)};
    }
    std::reverse(out.begin(), out.end());
    return out;
}

} // namespace mlc::solvers
