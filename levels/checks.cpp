// SPDX-License-Identifier: MIT
// Physics checks of a converged state: force balance and the contact conditions.
#include "levels/checks.hpp"

#include "fem/assembly.hpp"
#include "fem/elasticity.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>

namespace mlc::levels {

namespace {

/// Per axis: the resultant of loads, contact forces and support reactions, and the sum of their
/// magnitudes, over the vertices `count` accepts (all, or a process's own).
/// `x` (a distributed part's unknowns with their ghost values; null on one process) gives the
/// multipliers of Level::ghost_contacts, whose forces act on owned vertices too.
template <class Count>
std::array<double, 5> balance_sums(const Level& level, double s, const Vector& u_full,
                                   const std::vector<ContactNodeState>& nodes, Count&& count,
                                   const Vector* x = nullptr) {
    // External forces on the body: loads F, contact forces -C (C = sum_j w_j (lambda_t t +
    // lambda_n n), the multiplier being the force the body exerts), and support reactions
    // Rs = K u - F + C on the fixed components (nodal equilibrium K u = F - C + Rs). The
    // resultant F - C + Rs must vanish per axis; K u is recomputed element by element.
    const Vector Ku = fem::internal_forces(level.mesh, level.materials, u_full);
    const Vector F = level.f_nodal_at(s);
    Vector C = Vector::Zero(Ku.size());
    for (size_t e = 0; e < level.contacts.size(); ++e) {
        const auto& el = level.contacts[e];
        const Vec2 f = nodes[e].lambda_t * el.t + nodes[e].lambda_n * el.n;
        for (int j = 0; j < el.n_nodes(); ++j)
            C.segment<2>(2 * el.vertex[static_cast<size_t>(j)]) +=
                el.weight[static_cast<size_t>(j)] * f;
    }
    for (size_t e = 0; x && e < level.ghost_contacts.size(); ++e) {
        const auto& el = level.ghost_contacts[e];
        const int d = level.ghost_lambda_dof[e];
        const double lt = el.frictional() ? (*x)[d] : 0.0;
        const double ln = (*x)[el.frictional() ? d + 1 : d];
        const Vec2 f = lt * el.t + ln * el.n;
        for (int j = 0; j < el.n_nodes(); ++j)
            C.segment<2>(2 * el.vertex[static_cast<size_t>(j)]) +=
                el.weight[static_cast<size_t>(j)] * f;
    }
    // The internal forces' own scale: sum of |K_e| |u_e| over the rows of counted vertices.
    double internal = 0.0;
    for (int t = 0; t < level.mesh.n_cells(); ++t) {
        const auto& tri = level.mesh.cells[static_cast<size_t>(t)];
        const auto ke = fem::element_stiffness(level.mesh.vertices[static_cast<size_t>(tri[0])],
                                               level.mesh.vertices[static_cast<size_t>(tri[1])],
                                               level.mesh.vertices[static_cast<size_t>(tri[2])],
                                               fem::material_of(level.mesh, level.materials, t));
        Eigen::Matrix<double, 6, 1> ue;
        for (int i = 0; i < 3; ++i)
            ue.segment<2>(2 * i) = u_full.segment<2>(2 * tri[static_cast<size_t>(i)]).cwiseAbs();
        const Eigen::Matrix<double, 6, 1> fe = ke.cwiseAbs() * ue;
        for (int i = 0; i < 3; ++i)
            if (count(tri[static_cast<size_t>(i)])) internal += fe[2 * i] + fe[2 * i + 1];
    }
    std::array<double, 5> sums{}; // resultant x, y, magnitude x, y, internal scale
    sums[4] = internal;
    for (int a = 0; a < 2; ++a)
        for (int v = 0; v < level.mesh.n_vertices(); ++v) {
            if (!count(v)) continue;
            const int i = 2 * v + a;
            const double Rs = level.fixed[static_cast<size_t>(v)][static_cast<size_t>(a)]
                                  ? Ku[i] - F[i] + C[i]
                                  : 0.0;
            sums[static_cast<size_t>(a)] += F[i] - C[i] + Rs;
            sums[static_cast<size_t>(2 + a)] += std::abs(F[i]) + std::abs(C[i]) + std::abs(Rs);
        }
    return sums;
}

double balance_error(const std::array<double, 5>& sums) {
    const double err = std::max(std::abs(sums[0]), std::abs(sums[1]));
    const double total = std::max(sums[2], sums[3]);
    return total > 0 ? err / total : err;
}

/// See StateChecks::force_balance_applicable.
bool balance_applicable(const std::array<double, 5>& sums) {
    return sums[2] + sums[3] > kNoForceRatio * sums[4];
}

/// The unnormalised contact figures: max |lambda_n|, max |u|, then the six maxima of StateChecks.
std::array<double, 8> node_maxima(const Problem& p, const Level& L, const Vector& u_full,
                                  const std::vector<ContactNodeState>& nodes) {
    std::array<double, 8> m{};
    for (const auto& n : nodes)
        m[0] = std::max(m[0], std::abs(n.lambda_n));
    m[1] = u_full.size() ? u_full.cwiseAbs().maxCoeff() : 0.0;
    for (size_t e = 0; e < nodes.size(); ++e) {
        const auto& n = nodes[e];
        const double mu = p.contacts[static_cast<size_t>(L.contacts[e].pair)].mu;
        const double excess = std::abs(n.lambda_t) - mu * std::abs(n.lambda_n);
        // At open nodes lambda = 0 up to round-off: the cone test is meaningful in contact only.
        if (n.status != contact::Status::gap) m[2] = std::max(m[2], std::max(excess, 0.0));
        if (L.contacts[e].frictional() && (n.status == contact::Status::slip_forward ||
                                           n.status == contact::Status::slip_backward))
            m[3] = std::max(m[3], std::abs(excess));
        m[4] = std::max(m[4], std::abs(n.lambda_n * n.d_n));
        m[5] = std::max(m[5], std::max(-n.d_n, 0.0));
        m[6] = std::max(m[6], std::max(n.lambda_n, 0.0));
    }
    return m;
}

StateChecks normalised(const std::array<double, 8>& m, const std::array<double, 5>& sums) {
    StateChecks c;
    c.force_balance = balance_error(sums);
    c.force_balance_applicable = balance_applicable(sums);
    const double lmax = m[0], umax = m[1];
    c.coulomb_excess = m[2];
    c.slip_equality = m[3];
    c.complementarity = m[4];
    c.penetration = m[5];
    c.tension = m[6];
    if (lmax > 0) {
        c.coulomb_excess /= lmax;
        c.slip_equality /= lmax;
        c.tension /= lmax;
        if (umax > 0) c.complementarity /= lmax * umax;
    }
    if (umax > 0) c.penetration /= umax;
    return c;
}

} // namespace

double force_balance_error(const Level& level, double s, const Vector& u_full,
                           const std::vector<ContactNodeState>& nodes) {
    return balance_error(balance_sums(level, s, u_full, nodes, [](int) { return true; }));
}

StateChecks check_state(const Problem& p, const RunResult& r) {
    const auto& L = r.finest();
    return normalised(node_maxima(p, L, r.u_full, r.nodes),
                      balance_sums(L, 1.0, r.u_full, r.nodes, [](int) { return true; }));
}

StateChecks check_state(const Problem& p, const DistributedRunResult& r, const Communicator& comm) {
    const DistributedLevel& F = r.finest();
    const int me = comm.rank();
    auto sums = balance_sums(
        F.local, 1.0, r.u_full, r.nodes,
        [&](int v) { return F.part.vertex_owner[static_cast<size_t>(v)] == me; }, &r.x);
    comm.allreduce(std::span<double>(sums), ReduceOp::sum);
    auto m = node_maxima(p, F.local, r.u_full, r.nodes);
    comm.allreduce(std::span<double>(m), ReduceOp::max);
    return normalised(m, sums);
}

Vec2 contact_resultant(const Level& L, const std::vector<ContactNodeState>& nodes, int pair,
                       int* in_contact) {
    Vec2 f = Vec2::Zero();
    int closed = 0;
    for (size_t e = 0; e < L.contacts.size() && e < nodes.size(); ++e) {
        if (L.contacts[e].pair != pair) continue;
        f -= nodes[e].lambda_t * L.contacts[e].t + nodes[e].lambda_n * L.contacts[e].n;
        closed += nodes[e].status != contact::Status::gap;
    }
    if (in_contact) *in_contact = closed;
    return f;
}

Vec2 contact_resultant(const RunResult& r, int pair, int* in_contact) {
    return contact_resultant(r.finest(), r.nodes, pair, in_contact);
}

} // namespace mlc::levels
