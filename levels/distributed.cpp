// SPDX-License-Identifier: MIT
// A process's part of a distributed level: ghost data from the owners, numbering, ParCSR rows.
#include "levels/distributed.hpp"
#include "levels/agree_errors.hpp"
#include "levels/ghost_lists.hpp"

#include "core/check.hpp"
#include "levels/hierarchy.hpp"
#include "mesh/lattice.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <sstream>

namespace mlc::levels {

// ---------------------------------------------------------------------------------------------
GhostExchange::GhostExchange(const mesh::LocalLevel& part, const Communicator& comm)
    : comm_(&comm) {
    detail::ghost_lists(part, comm, "GhostExchange", recv_, send_);
}

void GhostExchange::vertex_records(std::vector<double>& rec, int width) const {
    detail::exchange_vertex_records(*comm_, "GhostExchange", recv_, send_, rec, width);
}

namespace {
/// The unknowns of vertex v in a fixed order: u_x, u_y (when free), then its multipliers.
template <class F> void for_vertex_dofs(const fem::DofMap& dofs, int v, int n_extra, F&& f) {
    for (int c = 0; c < 2; ++c)
        if (const int d = dofs.u_dof(v, c); d >= 0) f(d);
    for (int k = 0; k < n_extra; ++k)
        f(dofs.extra_dof(v) + k);
}
int n_extra_of(const fem::DofMap& dofs, int v) {
    const int e = dofs.extra_dof(v);
    if (e < 0) return 0;
    int k = 0;
    while (e + k < dofs.n_dofs() && dofs.vertex_of(e + k) == v && !dofs.is_displacement(e + k))
        ++k;
    return k;
}

/// Problem::Numbering::lattice on a part: the interior lattice points of the macro triangles
/// (level-0 triangles) that lie whole among this process's owned triangles, on a level of at
/// least 16 subdivisions per macro edge (solvers::kMinLatticeSubdivisions, as build_level numbers
/// one process's levels); std::nullopt otherwise. Macro m of the result is the m-th such macro.
/// The part's triangles are refine()'s of level p's in increasing level-p order (children of
/// local triangle t are 4t..4t+3), so a whole macro's triangles follow each other in refine
/// order, which mesh::macro_lattice reads.
std::optional<mesh::MacroLattice> owned_macro_lattice(const Problem& problem,
                                                      const mesh::LocalLevel& part) {
    if (problem.numbering != Problem::Numbering::lattice) return std::nullopt;
    const std::int64_t t0 = problem.mesh0.n_cells();
    const long nt = part.mesh.n_cells();
    int depth = -1; // this level is depth refinements of mesh0
    for (int d = 0; d <= 14 && t0 > 0; ++d)
        if (t0 << (2 * d) == part.n_global_triangles) depth = d;
    if (depth < 4 || nt == 0) return std::nullopt;
    // Refinements of level p in the part: local triangles per level-p triangle.
    long groups = 1;
    for (long t = 1; t < nt; ++t)
        groups += part.triangle_ancestor[static_cast<size_t>(t)] !=
                  part.triangle_ancestor[static_cast<size_t>(t - 1)];
    int k = -1;
    for (int d = 0; d <= depth; ++d)
        if (groups << (2 * d) == nt) k = d;
    if (k < 0) return std::nullopt;
    const int p = depth - k;
    const long per_macro = 1L << (2 * depth);
    // The whole owned macros' triangles, macro after macro, on their own vertex numbering.
    mesh::Mesh sub;
    std::vector<int> local_of, sub_of(static_cast<size_t>(part.mesh.n_vertices()), -1);
    for (long t = 0; t < nt;) {
        const int m = part.triangle_ancestor[static_cast<size_t>(t)] >> (2 * p);
        long e = t;
        bool owned = true;
        while (e < nt && part.triangle_ancestor[static_cast<size_t>(e)] >> (2 * p) == m) {
            owned = owned && part.triangle_owned[static_cast<size_t>(e)] != 0;
            ++e;
        }
        if (owned && e - t == per_macro)
            for (long q = t; q < e; ++q) {
                std::array<int, 3> tri = part.mesh.cells[static_cast<size_t>(q)];
                for (int& v : tri) {
                    int& s = sub_of[static_cast<size_t>(v)];
                    if (s < 0) {
                        s = static_cast<int>(local_of.size());
                        local_of.push_back(v);
                    }
                    v = s;
                }
                sub.cells.push_back(tri);
            }
        t = e;
    }
    if (sub.cells.empty()) return std::nullopt;
    sub.vertices.resize(local_of.size());
    auto lattice = mesh::macro_lattice(sub, depth);
    if (!lattice) return std::nullopt;
    for (int& v : lattice->vertex)
        v = local_of[static_cast<size_t>(v)];
    return lattice;
}

/// The lattice rows of a part's owned unknowns (the diagonal block the multigrid smooths): the
/// part's lattice_rows with the points and blocks of other processes' unknowns left out.
smoothers::LatticeRows owned_lattice_rows(const Level& L, const mesh::MacroLattice& lattice,
                                          Index n_owned) {
    smoothers::LatticeRows rows = lattice_rows(L, lattice);
    for (Index& r : rows.first_row)
        if (r >= n_owned) r = -1;
    std::erase_if(rows.visit, [n_owned](Index r) { return r >= n_owned; });
    return rows;
}
} // namespace

void GhostExchange::update(const fem::DofMap& dofs, Vector& x) const {
    std::vector<std::vector<double>> out(send_.size());
    for (size_t q = 0; q < send_.size(); ++q)
        for (const int v : send_[q])
            for_vertex_dofs(dofs, v, n_extra_of(dofs, v), [&](int d) { out[q].push_back(x[d]); });
    const auto in = comm_->exchange(out);
    for (size_t q = 0; q < recv_.size(); ++q) {
        size_t i = 0;
        for (const int v : recv_[q])
            for_vertex_dofs(dofs, v, n_extra_of(dofs, v), [&](int d) {
                MLC_CHECK(i < in[q].size(),
                          "GhostExchange: process " << q << " sent too few values");
                x[d] = in[q][i++];
            });
        MLC_CHECK(i == in[q].size(), "GhostExchange: process " << q << " sent too many values");
    }
}

// ---------------------------------------------------------------------------------------------
solvers::DistributedRows DistributedLevel::owned_rows(const SparseMatrix& A) const {
    solvers::DistributedRows r;
    r.first_row = first_dof;
    const int n = static_cast<int>(n_owned);
    const int nnz = A.outerIndexPtr()[n];
    r.row_ptr.assign(A.outerIndexPtr(), A.outerIndexPtr() + n + 1);
    r.cols.resize(static_cast<size_t>(nnz));
    for (int k = 0; k < nnz; ++k)
        r.cols[static_cast<size_t>(k)] = global_dof[static_cast<size_t>(A.innerIndexPtr()[k])];
    r.values.assign(A.valuePtr(), A.valuePtr() + nnz);
    return r;
}

solvers::RowBlocks DistributedLevel::row_blocks(const SparseMatrix& A) const {
    solvers::RowBlocks b;
    b.first_row = b.first_col = first_dof;
    const int n = static_cast<int>(n_owned);
    // The ghost columns referenced, in increasing global order.
    std::vector<int> ghost_cols;
    for (int k = 0; k < A.outerIndexPtr()[n]; ++k)
        if (A.innerIndexPtr()[k] >= n) ghost_cols.push_back(A.innerIndexPtr()[k]);
    std::sort(ghost_cols.begin(), ghost_cols.end(), [&](int a, int c) {
        return global_dof[static_cast<size_t>(a)] < global_dof[static_cast<size_t>(c)];
    });
    ghost_cols.erase(std::unique(ghost_cols.begin(), ghost_cols.end()), ghost_cols.end());
    std::vector<int> offd_col(static_cast<size_t>(A.cols()), -1);
    for (size_t j = 0; j < ghost_cols.size(); ++j) {
        offd_col[static_cast<size_t>(ghost_cols[j])] = static_cast<int>(j);
        b.col_map.push_back(global_dof[static_cast<size_t>(ghost_cols[j])]);
    }
    // Both blocks written row by row in place (A's rows hold each column once): the owned
    // columns in A's order, the ghost columns sorted by their place in col_map.
    b.diag.resize(n, n);
    b.offd.resize(n, static_cast<Index>(ghost_cols.size()));
    int* d_outer = b.diag.outerIndexPtr();
    int* o_outer = b.offd.outerIndexPtr();
    d_outer[0] = o_outer[0] = 0;
    for (int i = 0; i < n; ++i) {
        int nd = 0, no = 0;
        for (SparseMatrix::InnerIterator it(A, i); it; ++it)
            (it.col() < n ? nd : no) += 1;
        d_outer[i + 1] = d_outer[i] + nd;
        o_outer[i + 1] = o_outer[i] + no;
    }
    b.diag.resizeNonZeros(d_outer[n]);
    b.offd.resizeNonZeros(o_outer[n]);
    int* d_inner = b.diag.innerIndexPtr();
    double* d_val = b.diag.valuePtr();
    int* o_inner = b.offd.innerIndexPtr();
    double* o_val = b.offd.valuePtr();
    std::vector<std::pair<int, double>> row_offd;
    for (int i = 0; i < n; ++i) {
        int kd = d_outer[i];
        row_offd.clear();
        for (SparseMatrix::InnerIterator it(A, i); it; ++it) {
            if (it.col() < n) {
                d_inner[kd] = static_cast<int>(it.col());
                d_val[kd++] = it.value();
            } else {
                row_offd.emplace_back(offd_col[static_cast<size_t>(it.col())], it.value());
            }
        }
        std::sort(row_offd.begin(), row_offd.end(),
                  [](const auto& x, const auto& y) { return x.first < y.first; });
        int ko = o_outer[i];
        for (const auto& [c, v] : row_offd) {
            o_inner[ko] = c;
            o_val[ko++] = v;
        }
    }
    return b;
}

transfer::ContactNodes DistributedLevel::contact_nodes() const {
    transfer::ContactNodes c;
    for (int v = 0; v < local.mesh.n_vertices(); ++v)
        if (n_extra[static_cast<size_t>(v)] > 0) {
            c.vertex.push_back(v);
            c.lambda_dof.push_back(local.dofs.extra_dof(v));
            c.n_multipliers.push_back(n_extra[static_cast<size_t>(v)]);
            c.pinned.push_back(pinned[static_cast<size_t>(v)]);
        }
    return c;
}

DistributedLevel build_distributed_level(const Problem& problem, mesh::LocalLevel part,
                                         const Communicator& comm) {
    static constexpr const char* kAnother = "another process could not build its part of the level";
    DistributedLevel d;
    const int me = comm.rank();
    const int nv = part.mesh.n_vertices();
    d.ghosts = GhostExchange(part, comm);
    LevelPart lp;
    lp.owned.resize(static_cast<size_t>(nv));
    for (int v = 0; v < nv; ++v)
        lp.owned[static_cast<size_t>(v)] = part.vertex_owner[static_cast<size_t>(v)] == me;
    // Owned vertices first: the interior points of the owned lattice macros (numbering
    // lattice), then the others along a Hilbert curve; then the ghosts.
    const std::optional<mesh::MacroLattice> lattice = owned_macro_lattice(problem, part);
    lp.order = mesh::hilbert_order(part.mesh.vertices);
    std::vector<char> placed(static_cast<size_t>(nv), 0);
    if (lattice) {
        std::vector<int> order;
        order.reserve(lp.order.size());
        for (const int v : lattice->vertex)
            if (lp.owned[static_cast<size_t>(v)]) {
                order.push_back(v);
                placed[static_cast<size_t>(v)] = 1;
            }
        for (const int v : lp.order)
            if (!placed[static_cast<size_t>(v)]) order.push_back(v);
        lp.order = std::move(order);
    }
    std::stable_partition(lp.order.begin(), lp.order.end(),
                          [&](int v) { return lp.owned[static_cast<size_t>(v)] != 0; });
    // An error on one process before `complete` (whose exchanges are collective) is agreed on
    // at its start, so that the others do not wait in the exchange.
    bool reached_complete = false;
    lp.complete = [&](Level& L, std::vector<int>& n_extra, std::vector<int>& contact_pair) {
        reached_complete = true;
        MLC_CHECK(comm.max(0) == 0, kAnother);
        // Owners send: fixed x, fixed y, multipliers, contact pair, then the prescribed values at
        // every path point.
        const int K = static_cast<int>(L.path_u_fixed.size());
        const int w = 4 + 2 * K;
        std::vector<double> rec(static_cast<size_t>(nv) * static_cast<size_t>(w), 0.0);
        for (int v = 0; v < nv; ++v) {
            double* r = rec.data() + static_cast<size_t>(v) * static_cast<size_t>(w);
            r[0] = L.fixed[static_cast<size_t>(v)][0];
            r[1] = L.fixed[static_cast<size_t>(v)][1];
            r[2] = n_extra[static_cast<size_t>(v)];
            r[3] = contact_pair[static_cast<size_t>(v)];
            for (int k = 0; k < K; ++k)
                for (int c = 0; c < 2; ++c)
                    r[4 + 2 * k + c] = L.path_u_fixed[static_cast<size_t>(k)][2 * v + c];
        }
        d.ghosts.vertex_records(rec, w);
        for (int v = 0; v < nv; ++v) {
            if (lp.owned[static_cast<size_t>(v)]) continue;
            const double* r = rec.data() + static_cast<size_t>(v) * static_cast<size_t>(w);
            L.fixed[static_cast<size_t>(v)] = {r[0] != 0.0, r[1] != 0.0};
            n_extra[static_cast<size_t>(v)] = static_cast<int>(r[2]);
            contact_pair[static_cast<size_t>(v)] = static_cast<int>(r[3]);
            for (int k = 0; k < K; ++k)
                for (int c = 0; c < 2; ++c)
                    L.path_u_fixed[static_cast<size_t>(k)][2 * v + c] = r[4 + 2 * k + c];
        }
        L.u_fixed = L.path_u_fixed.back();
        d.n_extra = n_extra;
    };
    // Errors of one part (e.g. a support point no process holds) must stop every process.
    std::string error;
    try {
        d.local = build_level(problem, std::move(part.mesh), &lp);
    } catch (const InvalidInput& e) {
        error = e.what();
        if (!reached_complete) comm.max(1); // the agreement at the start of `complete`
    }
    detail::throw_first_error(comm, error, kAnother);
    part.mesh = mesh::Mesh{};
    d.part = std::move(part);
    // Pairs with no contact node anywhere; support points held by no process.
    std::vector<int> per_pair(problem.contacts.size(), 0);
    for (const auto& e : d.local.contacts)
        ++per_pair[static_cast<size_t>(e.pair)];
    comm.allreduce(std::span<int>(per_pair), ReduceOp::sum);
    for (size_t p = 0; p < per_pair.size(); ++p)
        MLC_CHECK(per_pair[p] > 0, "contact '" << problem.contacts[p].name
                                               << "' has no contactor node on '"
                                               << problem.contacts[p].contactor << "'");
    d.n_global_contacts = comm.sum(d.local.n_contact_nodes());
    // The pinned components of every local contact node, ghosts from their owners (the owner
    // decides them once it knows the supports of its element's vertices).
    {
        std::vector<double> rec(static_cast<size_t>(nv), 0.0);
        for (const auto& e : d.local.contacts)
            rec[static_cast<size_t>(e.vertex[0])] = e.pinned;
        d.ghosts.vertex_records(rec, 1);
        d.pinned.resize(static_cast<size_t>(nv));
        for (int v = 0; v < nv; ++v)
            d.pinned[static_cast<size_t>(v)] =
                static_cast<unsigned char>(rec[static_cast<size_t>(v)]);
    }

    // Owned unknowns first (the order puts the owned vertices first).
    const auto& dofs = d.local.dofs;
    d.n_owned = 0;
    for (int v = 0; v < nv; ++v)
        if (lp.owned[static_cast<size_t>(v)])
            for_vertex_dofs(dofs, v, d.n_extra[static_cast<size_t>(v)], [&](int) { ++d.n_owned; });
    for (int v = 0; v < nv; ++v)
        if (lp.owned[static_cast<size_t>(v)])
            for_vertex_dofs(
                dofs, v, d.n_extra[static_cast<size_t>(v)], [&]([[maybe_unused]] int dof) {
                    MLC_ASSERT(dof < d.n_owned, "an owned unknown is numbered after a ghost one");
                });
    d.first_dof = comm.exclusive_sum(static_cast<std::int64_t>(d.n_owned));
    d.n_global_dofs = comm.sum(static_cast<std::int64_t>(d.n_owned));
    Vector g = Vector::Constant(dofs.n_dofs(), -1.0);
    for (Index i = 0; i < d.n_owned; ++i)
        g[i] = static_cast<double>(d.first_dof + i);
    d.ghosts.update(dofs, g);
    d.global_dof.resize(static_cast<size_t>(dofs.n_dofs()));
    for (Index i = 0; i < dofs.n_dofs(); ++i) {
        MLC_CHECK(g[i] >= 0, "internal error: unknown " << i << " has no global number");
        d.global_dof[static_cast<size_t>(i)] = std::llround(g[i]);
    }
    if (lattice)
        d.local.lattice = std::make_shared<const smoothers::LatticeRows>(
            owned_lattice_rows(d.local, *lattice, d.n_owned));
    d.K_blocks = std::make_unique<solvers::RowBlocks>(d.row_blocks(d.local.elastic.K));
    d.local.elastic.K = SparseMatrix(); // its owned rows are in K_blocks
    d.K = std::make_unique<solvers::ParMatrix>(comm, *d.K_blocks);
    return d;
}

DistributedTransfer build_distributed_transfer(const DistributedLevel& coarse,
                                               const DistributedLevel& fine,
                                               const Communicator& comm, transfer::QRule rule) {
    DistributedTransfer t;
    t.local = transfer::build_transfer(fine.local.mesh, coarse.local.dofs, fine.local.dofs,
                                       coarse.contact_nodes(), fine.contact_nodes(), rule);
    solvers::DistributedRows r;
    const SparseMatrix& T = t.local.T;
    r.first_row = fine.first_dof;
    const int n = static_cast<int>(fine.n_owned);
    const int nnz = T.outerIndexPtr()[n];
    r.row_ptr.assign(T.outerIndexPtr(), T.outerIndexPtr() + n + 1);
    r.cols.resize(static_cast<size_t>(nnz));
    for (int k = 0; k < nnz; ++k)
        r.cols[static_cast<size_t>(k)] =
            coarse.global_dof[static_cast<size_t>(T.innerIndexPtr()[k])];
    r.values.assign(T.valuePtr(), T.valuePtr() + nnz);
    t.T = std::make_unique<solvers::ParMatrix>(comm, r, coarse.first_dof,
                                               static_cast<int>(coarse.n_owned));
    // Kept: P_nodal and Q (the coarse-to-fine initial guess); T lives in the ParMatrix.
    t.local.T = t.local.R = t.local.P_vertex = SparseMatrix();
    return t;
}

std::vector<mesh::GhostReach> contact_ghost_reach(const Problem& problem,
                                                  const mesh::Mesh& level_p) {
    std::vector<mesh::GhostReach> out;
    const auto& m0 = problem.mesh0;
    for (const auto& pair : problem.contacts) {
        if (pair.element == ContactElementKind::node_on_rigid) continue;
        mesh::GhostReach r;
        r.tags = {level_p.tag(pair.contactor), level_p.tag(pair.target)};
        double h0 = 0.0, hp = 0.0;
        const int t0 = m0.tag(pair.target);
        for (const auto& e : m0.boundary)
            if (e.tag == t0)
                h0 = std::max(h0, (m0.vertices[static_cast<size_t>(e.v1)] -
                                   m0.vertices[static_cast<size_t>(e.v0)])
                                      .norm());
        for (const auto& e : level_p.boundary)
            if (e.tag == r.tags[0] || e.tag == r.tags[1])
                hp = std::max(hp, (level_p.vertices[static_cast<size_t>(e.v1)] -
                                   level_p.vertices[static_cast<size_t>(e.v0)])
                                      .norm());
        r.distance = contact_reach_distance(pair, h0, hp);
        out.push_back(std::move(r));
    }
    return out;
}

int partition_level(std::int64_t level0_triangles, int finest, int n_processes) {
    MLC_CHECK(n_processes >= 1, "partition_level: " << n_processes << " processes");
    int p = 0;
    std::int64_t t = level0_triangles;
    while (p < finest - 1 && t < static_cast<std::int64_t>(kTrianglesPerProcess) * n_processes) {
        ++p;
        t *= 4;
    }
    return std::max(0, std::min(p, finest - 1));
}

} // namespace mlc::levels
