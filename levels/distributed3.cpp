// SPDX-License-Identifier: MIT
// A process's part of a distributed 3D level: ghost data from the owners, contact elements,
// numbering, the owned rows of K and of the transfers as ParCSR matrices.
#include "levels/distributed3.hpp"
#include "levels/agree_errors.hpp"
#include "levels/elastic3d_detail.hpp"
#include "levels/ghost_lists.hpp"

#include "core/check.hpp"
#include "fem/assembly.hpp"
#include "levels/distributed.hpp"
#include "levels/solve3.hpp"
#include "mesh/tet_refine.hpp"
#include "transfer/prolongation.hpp"
#include "transfer/surface_q.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <string>

namespace mlc::levels {

// ---------------------------------------------------------------------------------------------
GhostExchange3::GhostExchange3(const mesh::LocalTetLevel& part, const Communicator& comm)
    : comm_(&comm) {
    detail::ghost_lists(part, comm, "GhostExchange3", recv_, send_);
}

void GhostExchange3::vertex_records(std::vector<double>& rec, int width) const {
    detail::exchange_vertex_records(*comm_, "GhostExchange3", recv_, send_, rec, width);
}

namespace {
/// The unknowns of vertex v in a fixed order: its free components, then its extra unknowns.
template <class F> void for_vertex_dofs3(const fem::DofMap3& dofs, int v, F&& f) {
    for (int c = 0; c < 3; ++c)
        if (const int d = dofs.u_dof(v, c); d >= 0) f(d);
    if (const int e = dofs.extra_dof(v); e >= 0)
        for (int k = e; k < dofs.n_dofs() && dofs.vertex_of(k) == v && !dofs.is_displacement(k);
             ++k)
            f(k);
}

/// Relative distance (to the level-0 diameter) under which a support point is a vertex, or a
/// vertex lies on a support line (elastic3d_levels.cpp's kPointTol).
constexpr double kSupportTol3 = 1e-9;

/// line_vertices with the tolerance of the whole level-0 mesh (a part's diameter is smaller).
std::vector<int> line_vertices_within(const mesh::TetMesh& m, const std::array<Vec3, 2>& line,
                                      double tol) {
    const Vec3 d = line[1] - line[0];
    const double len2 = d.squaredNorm();
    std::vector<int> out;
    for (int v = 0; v < m.n_vertices(); ++v) {
        const Vec3 x = m.vertices[static_cast<size_t>(v)] - line[0];
        const double s = len2 > 0 ? x.dot(d) / len2 : 0.0;
        if (s < -tol || s > 1 + tol) continue;
        if ((x - s * d).norm() <= tol) out.push_back(v);
    }
    return out;
}

/// The contact elements of a part (`owned`: its owned vertices): those of its owned contact nodes
/// (detail::find_contact_nodes3), each pair checked over all parts, the multiplier counts and
/// contact pairs of the ghost vertices from their owners, Level3::ghost_contacts (the two-body
/// elements of other processes' contact nodes that reach an owned vertex, searched again here as
/// their owners search them), the pinned components (detail::pin_held_components3) and `pinned`
/// per vertex (ghosts: their owners'). Sets n_extra per vertex.
void build_part_contacts3(const ElasticProblem3& p, Level3& L, const std::vector<char>& owned,
                          const GhostExchange3& ghosts, const Communicator& comm,
                          std::vector<int>& n_extra, std::vector<unsigned char>& pinned) {
    const int nv = L.mesh.n_vertices();
    const size_t np = p.contacts.size();
    detail::agree_on_errors(comm, [&] { detail::find_contact_nodes3(p, L, n_extra, &owned); });
    // Per pair over all parts: its elements, then its contactor nodes (found or not).
    std::vector<int> count(2 * np, 0);
    for (const auto& e : L.contacts)
        ++count[static_cast<size_t>(e.pair)];
    for (size_t k = 0; k < np; ++k)
        count[np + k] = count[k] + static_cast<int>(L.not_found[k].size());
    comm.allreduce(std::span<int>(count), ReduceOp::sum);
    for (size_t k = 0; k < np; ++k) {
        const ContactPair3& pair = p.contacts[k];
        MLC_CHECK(count[np + k] > 0, "contact '" << pair.name << "' has no contactor node on '"
                                                 << pair.contactor << "' on any process");
        MLC_CHECK(count[k] > 0,
                  detail::no_target_message(pair, static_cast<std::size_t>(count[np + k])));
    }
    // The ghosts' multipliers and contact pairs from their owners.
    std::vector<int> contact_pair(static_cast<size_t>(nv), -1);
    {
        std::vector<double> rec(2 * static_cast<size_t>(nv), 0.0);
        for (int v = 0; v < nv; ++v)
            rec[2 * static_cast<size_t>(v)] = n_extra[static_cast<size_t>(v)];
        for (const auto& e : L.contacts)
            rec[2 * static_cast<size_t>(e.vertex[0]) + 1] = e.pair + 1;
        ghosts.vertex_records(rec, 2);
        for (int v = 0; v < nv; ++v) {
            n_extra[static_cast<size_t>(v)] =
                static_cast<int>(std::lround(rec[2 * static_cast<size_t>(v)]));
            contact_pair[static_cast<size_t>(v)] =
                static_cast<int>(std::lround(rec[2 * static_cast<size_t>(v) + 1])) - 1;
        }
    }
    detail::agree_on_errors(comm, [&] {
        for (size_t k = 0; k < np; ++k) {
            const ContactPair3& pair = p.contacts[k];
            if (!pair.two_body()) continue;
            // Other processes' nodes of the pair on a local contactor face (a node whose element
            // reaches an owned vertex has all its faces here: contact_ghost_reach3).
            std::vector<int> nodes;
            for (const int v : L.mesh.vertices_with_tag(L.mesh.tag(pair.contactor)))
                if (!owned[static_cast<size_t>(v)] &&
                    contact_pair[static_cast<size_t>(v)] == static_cast<int>(k))
                    nodes.push_back(v);
            if (nodes.empty()) continue;
            for (auto& e : detail::two_body_search3(p, L.mesh, k, nodes, true).elements) {
                bool reaches = false;
                for (int j = 1; j < e.n_nodes(); ++j)
                    reaches =
                        reaches || owned[static_cast<size_t>(e.vertex[static_cast<size_t>(j)])];
                if (reaches) L.ghost_contacts.push_back(std::move(e));
            }
        }
        detail::pin_held_components3(p, L);
    });
    // The pinned components per vertex, ghosts from their owners.
    std::vector<double> rec(static_cast<size_t>(nv), 0.0);
    for (const auto& e : L.contacts)
        rec[static_cast<size_t>(e.vertex[0])] = e.pinned;
    ghosts.vertex_records(rec, 1);
    pinned.resize(static_cast<size_t>(nv));
    for (int v = 0; v < nv; ++v)
        pinned[static_cast<size_t>(v)] =
            static_cast<unsigned char>(std::lround(rec[static_cast<size_t>(v)]));
}

/// The numbering view of a part (first_dof, n_owned, global_dof) as a DistributedLevel, whose
/// row_blocks and owned_rows read nothing else: the 2D code cuts the rows.
struct NumberingView {
    DistributedLevel d;
    explicit NumberingView(const DistributedLevel3& l) {
        d.first_dof = l.first_dof;
        d.n_owned = l.n_owned;
        d.global_dof = l.global_dof;
    }
};
} // namespace

void GhostExchange3::update(const fem::DofMap3& dofs, Vector& x) const {
    std::vector<std::vector<double>> out(send_.size());
    for (size_t q = 0; q < send_.size(); ++q)
        for (const int v : send_[q])
            for_vertex_dofs3(dofs, v, [&](int d) { out[q].push_back(x[d]); });
    const auto in = comm_->exchange(out);
    for (size_t q = 0; q < recv_.size(); ++q) {
        size_t i = 0;
        for (const int v : recv_[q])
            for_vertex_dofs3(dofs, v, [&](int d) {
                MLC_CHECK(i < in[q].size(),
                          "GhostExchange3: process " << q << " sent too few values");
                x[d] = in[q][i++];
            });
        MLC_CHECK(i == in[q].size(), "GhostExchange3: process " << q << " sent too many values");
    }
}

// ---------------------------------------------------------------------------------------------
solvers::DistributedRows DistributedLevel3::owned_rows(const SparseMatrix& A) const {
    return NumberingView(*this).d.owned_rows(A);
}

solvers::RowBlocks DistributedLevel3::row_blocks(const SparseMatrix& A) const {
    return NumberingView(*this).d.row_blocks(A);
}

solvers::DistributedRows DistributedLevel3::K_rows() const {
    return solvers::distributed_rows(*K_blocks);
}

std::vector<int> DistributedLevel3::dof_function() const {
    std::vector<int> f(static_cast<size_t>(n_owned), -1);
    for (int v = 0; v < local.mesh.n_vertices(); ++v)
        for (int c = 0; c < 3; ++c)
            if (const int d = local.dofs.u_dof(v, c); d >= 0 && d < n_owned)
                f[static_cast<size_t>(d)] = c;
    return f;
}

DistributedLevel3 build_distributed_level3(const ElasticProblem3& p, mesh::LocalTetLevel part,
                                           const Communicator& comm) {
    DistributedLevel3 d;
    const int me = comm.rank();
    const int nv = part.mesh.n_vertices();
    d.ghosts = GhostExchange3(part, comm);
    const double tol = kSupportTol3 * p.mesh0.diameter();
    Level3& L = d.local;
    L.mesh = std::move(part.mesh);
    const mesh::TetMesh& m = L.mesh;

    // Supports on the local mesh; a point support is held where its vertex is local.
    std::vector<fem::VertexSupport3> vs;
    std::vector<int> point_owned;
    for (const Support3& s : p.supports) {
        fem::VertexSupport3 v;
        if (!s.tag.empty()) {
            if (const auto id = m.find_tag(s.tag)) v.vertices = m.vertices_on_tag(*id);
        } else if (s.line) {
            v.vertices = line_vertices_within(m, *s.line, tol);
        } else {
            const int w = m.nearest_vertex(*s.point);
            const bool here = (m.vertices[static_cast<size_t>(w)] - *s.point).norm() <= tol;
            if (here) v.vertices = {w};
            point_owned.push_back(here && part.vertex_owner[static_cast<size_t>(w)] == me);
        }
        for (int c = 0; c < 3; ++c) {
            v.components[static_cast<size_t>(c)] = s.u[static_cast<size_t>(c)].has_value();
            v.value[c] = s.u[static_cast<size_t>(c)].value_or(0.0);
        }
        vs.push_back(std::move(v));
    }
    comm.allreduce(std::span<int>(point_owned), ReduceOp::sum);
    for (const int n : point_owned)
        MLC_CHECK(n == 1, "a support point is a vertex of " << n
                                                            << " processes' owned vertices (one "
                                                               "expected)");
    fem::Supports3 sup = fem::collect_supports(m, vs);
    // Ghost vertices: their owners' fixed components and values (of the last path point).
    {
        std::vector<double> rec(static_cast<size_t>(nv) * 6);
        for (int v = 0; v < nv; ++v)
            for (int c = 0; c < 3; ++c) {
                rec[6 * static_cast<size_t>(v) + static_cast<size_t>(c)] =
                    sup.fixed[static_cast<size_t>(v)][static_cast<size_t>(c)];
                rec[6 * static_cast<size_t>(v) + 3 + static_cast<size_t>(c)] =
                    sup.u_fixed[3 * v + c];
            }
        d.ghosts.vertex_records(rec, 6);
        for (int v = 0; v < nv; ++v)
            for (int c = 0; c < 3; ++c) {
                sup.fixed[static_cast<size_t>(v)][static_cast<size_t>(c)] =
                    rec[6 * static_cast<size_t>(v) + static_cast<size_t>(c)] != 0.0;
                sup.u_fixed[3 * v + c] =
                    rec[6 * static_cast<size_t>(v) + 3 + static_cast<size_t>(c)];
            }
    }
    L.fixed = std::move(sup.fixed);
    L.u_fixed = std::move(sup.u_fixed);
    std::vector<char> owned(static_cast<size_t>(nv), 0);
    for (const int v : part.owned_vertices)
        owned[static_cast<size_t>(v)] = 1;
    build_part_contacts3(p, L, owned, d.ghosts, comm, d.n_extra, d.pinned);
    d.n_global_contacts = comm.sum(L.n_contact_nodes());

    // Owned vertices first (in their global order), then the ghosts.
    std::vector<int> order = part.owned_vertices;
    for (int v = 0; v < nv; ++v)
        if (!owned[static_cast<size_t>(v)]) order.push_back(v);
    L.dofs = fem::DofMap3(L.fixed, d.n_extra, order);
    L.lambda_dof.clear();
    for (const auto& e : L.contacts)
        L.lambda_dof.push_back(L.dofs.extra_dof(e.vertex[0]));
    L.ghost_lambda_dof.clear();
    for (const auto& e : L.ghost_contacts)
        L.ghost_lambda_dof.push_back(L.dofs.extra_dof(e.vertex[0]));

    // Materials and the full load.
    std::vector<Vec3> bf;
    bool any_force = false;
    for (const Body3& b : p.bodies) {
        bf.push_back(b.body_force);
        L.materials.push_back(b.material);
        any_force = any_force || !b.body_force.isZero(0.0);
    }
    if (!any_force) bf.clear();
    // The nodal loads at path point k of K (K: the full load), as build_level's.
    const int K = p.n_path_points();
    auto nodal_loads_at = [&](int k) {
        std::vector<fem::Traction3> tr;
        for (const FaceLoad3& l : p.loads) {
            const double a = K == 1 ? 1.0 : Problem::path_value(l.factors, 1.0, k, K);
            if (const auto id = m.find_tag(l.tag))
                tr.push_back({*id, a * l.pressure, a * l.traction});
        }
        std::vector<Vec3> bk = bf;
        if (K > 1)
            for (Vec3& b : bk)
                b *= static_cast<double>(k) / K;
        return fem::nodal_loads(m, tr, bk);
    };
    L.elastic = fem::assemble_elastic(m, L.materials, L.dofs, nodal_loads_at(K), L.u_fixed);
    // Along a loading path, the prescribed values of every path point, ghost vertices' from their
    // owners (as the last point's above).
    if (K > 1)
        detail::set_load_path3(p, L, vs, nodal_loads_at, [&d](Vector& u) {
            std::vector<double> rec(u.data(), u.data() + u.size());
            d.ghosts.vertex_records(rec, 3);
            u = Eigen::Map<const Vector>(rec.data(), u.size());
        });

    // Owned unknowns first.
    d.n_owned = 0;
    for (const int v : part.owned_vertices)
        for_vertex_dofs3(L.dofs, v, [&]([[maybe_unused]] int dof) {
            MLC_ASSERT(dof == d.n_owned, "an owned unknown is numbered after a ghost one");
            ++d.n_owned;
        });
    d.first_dof = comm.exclusive_sum(static_cast<std::int64_t>(d.n_owned));
    d.n_global_dofs = comm.sum(static_cast<std::int64_t>(d.n_owned));
    Vector g = Vector::Constant(L.dofs.n_dofs(), -1.0);
    for (Index i = 0; i < d.n_owned; ++i)
        g[i] = static_cast<double>(d.first_dof + i);
    d.ghosts.update(L.dofs, g);
    d.global_dof.resize(static_cast<size_t>(L.dofs.n_dofs()));
    for (Index i = 0; i < L.dofs.n_dofs(); ++i) {
        MLC_CHECK(g[i] >= 0, "internal error: unknown " << i << " has no global number");
        d.global_dof[static_cast<size_t>(i)] = std::llround(g[i]);
    }
    d.K_blocks = std::make_unique<solvers::RowBlocks>(d.row_blocks(L.elastic.K));
    L.elastic.K = SparseMatrix(); // its owned rows are in K_blocks
    d.K = std::make_unique<solvers::ParMatrix>(comm, *d.K_blocks);
    part.mesh = mesh::TetMesh{};
    d.part = std::move(part);
    return d;
}

std::vector<mesh::GhostReach> contact_ghost_reach3(const ElasticProblem3& p,
                                                   const mesh::TetMesh& level_p) {
    std::vector<mesh::GhostReach> out;
    const mesh::TetMesh& m0 = p.mesh0;
    // The longest edge of the faces of `m` tagged one of `tags`.
    auto longest_edge = [](const mesh::TetMesh& m, const std::vector<int>& tags) {
        double h = 0.0;
        for (const mesh::BoundaryFace& f : m.boundary) {
            if (std::find(tags.begin(), tags.end(), f.tag) == tags.end()) continue;
            for (size_t i = 0; i < 3; ++i)
                h = std::max(h, (m.vertices[static_cast<size_t>(f.v[i])] -
                                 m.vertices[static_cast<size_t>(f.v[(i + 1) % 3])])
                                    .norm());
        }
        return h;
    };
    for (const ContactPair3& pair : p.contacts) {
        if (!pair.two_body()) continue;
        mesh::GhostReach r;
        r.tags = {level_p.tag(pair.contactor), level_p.tag(pair.target)};
        const double h0 = longest_edge(m0, {m0.tag(pair.target)});
        const double hp = longest_edge(level_p, r.tags);
        r.distance = contact_reach_distance(pair, h0, hp);
        out.push_back(std::move(r));
    }
    return out;
}

namespace {

/// The multiplier rows of the owned fine contact nodes (the multiplier block of
/// full_prolongation3 on these parts): per fine node, F_f^T Q_fc F_c over the coarse contact
/// nodes of its surface row, with Q = diag(m_h) P diag(1 / m_H) and m_H = P^T m_h. The coarse
/// masses and frames are the coarse vertices' owners' (a ghost coarse vertex's fine surface is
/// not all local); entries (local fine row, global coarse column, value) into `rows`.
void multiplier_rows3(const ElasticProblem3& p, const DistributedLevel3& coarse,
                      const DistributedLevel3& fine, const Communicator& comm,
                      std::vector<std::vector<std::pair<std::int64_t, double>>>& rows) {
    const Level3& C = coarse.local;
    const Level3& F = fine.local;
    if (p.contacts.empty()) return; // the same on every process
    transfer::SurfaceQ q;
    detail::agree_on_errors(comm, [&] {
        q = transfer::build_surface_q<3>(
            transfer::SurfacePoints(C.mesh.vertices.begin(), C.mesh.vertices.end()),
            contactor_faces(p, C),
            transfer::SurfacePoints(F.mesh.vertices.begin(), F.mesh.vertices.end()),
            contactor_faces(p, F), F.mesh.parents);
    });
    // Per coarse vertex: m_H, contact node?, frictional?, t1, t2, n (owners' values).
    constexpr int w = 12;
    const auto nc = static_cast<size_t>(C.mesh.n_vertices());
    std::vector<double> rec(w * nc, 0.0);
    for (int i = 0; i < q.coarse.size(); ++i)
        rec[w * static_cast<size_t>(q.coarse.vertex[static_cast<size_t>(i)])] =
            q.coarse_mass_on_fine[i];
    for (const auto& el : C.contacts) {
        double* r = rec.data() + w * static_cast<size_t>(el.vertex[0]);
        r[1] = 1.0;
        r[2] = el.frictional() ? 1.0 : 0.0;
        for (int c = 0; c < 3; ++c) {
            r[3 + c] = el.t(c, 0);
            r[6 + c] = el.t(c, 1);
            r[9 + c] = el.n[c];
        }
    }
    coarse.ghosts.vertex_records(rec, w);
    for (size_t e = 0; e < F.contacts.size(); ++e) {
        const auto& el = F.contacts[e];
        const int i = q.fine.index[static_cast<size_t>(el.vertex[0])];
        if (i < 0) continue;
        Eigen::Matrix3d Bf;
        Bf << el.t.col(0), el.t.col(1), el.n;
        const int a0 = el.frictional() ? 0 : 2;
        const int df = F.lambda_dof[e];
        for (MovableSparseMatrix::InnerIterator it(q.P, i); it; ++it) {
            const int vc = q.coarse.vertex[static_cast<size_t>(it.col())];
            const double* r = rec.data() + w * static_cast<size_t>(vc);
            if (r[1] == 0.0 || r[0] <= 0.0) continue;
            Eigen::Matrix3d Bc;
            Bc << Eigen::Vector3d(r[3], r[4], r[5]), Eigen::Vector3d(r[6], r[7], r[8]),
                Eigen::Vector3d(r[9], r[10], r[11]);
            const Eigen::Matrix3d B = q.fine_mass[i] * it.value() / r[0] * Bf.transpose() * Bc;
            const int b0 = r[2] != 0.0 ? 0 : 2;
            const int dc = C.dofs.extra_dof(vc);
            for (int a = a0; a < 3; ++a)
                for (int b = b0; b < 3; ++b)
                    if (B(a, b) != 0.0)
                        rows[static_cast<size_t>(df + a - a0)].emplace_back(
                            coarse.global_dof[static_cast<size_t>(dc + b - b0)], B(a, b));
        }
    }
}

} // namespace

DistributedTransfer3 build_distributed_transfer3(const ElasticProblem3& p,
                                                 const DistributedLevel3& coarse,
                                                 const DistributedLevel3& fine,
                                                 const Communicator& comm) {
    const SparseMatrix P_vertex = transfer::vertex_prolongation(fine.local.mesh);
    MLC_CHECK(P_vertex.cols() == coarse.local.mesh.n_vertices(),
              "build_distributed_transfer3: the fine part's mesh refines a mesh of "
                  << P_vertex.cols() << " vertices, the coarse part has "
                  << coarse.local.mesh.n_vertices());
    const SparseMatrix T = transfer::restrict_to_unknowns(
        P_vertex, 3, transfer::vertex_unknowns(coarse.local.dofs, 3),
        static_cast<int>(coarse.local.dofs.n_dofs()), transfer::vertex_unknowns(fine.local.dofs, 3),
        static_cast<int>(fine.local.dofs.n_dofs()));
    const int n = static_cast<int>(fine.n_owned);
    std::vector<std::vector<std::pair<std::int64_t, double>>> extra(static_cast<size_t>(n));
    multiplier_rows3(p, coarse, fine, comm, extra);
    solvers::DistributedRows r;
    r.first_row = fine.first_dof;
    r.row_ptr.assign(1, 0);
    for (int i = 0; i < n; ++i) {
        for (SparseMatrix::InnerIterator it(T, i); it; ++it) {
            r.cols.push_back(coarse.global_dof[static_cast<size_t>(it.col())]);
            r.values.push_back(it.value());
        }
        for (const auto& [col, v] : extra[static_cast<size_t>(i)]) {
            r.cols.push_back(col);
            r.values.push_back(v);
        }
        r.row_ptr.push_back(static_cast<int>(r.cols.size()));
    }
    DistributedTransfer3 t;
    t.T = std::make_unique<solvers::ParMatrix>(comm, r, coarse.first_dof,
                                               static_cast<int>(coarse.n_owned));
    return t;
}

DistributedHierarchy3 build_distributed_hierarchy3(const ElasticProblem3& p, int p_level,
                                                   int n_refinements, const Communicator& comm) {
    MLC_CHECK(p_level >= 0, "the partition level must be >= 0, found " << p_level);
    MLC_CHECK(n_refinements >= 0,
              "the refinements above the partition level must be >= 0, found " << n_refinements);
    mesh::TetMesh level_p = p.mesh0;
    for (int l = 0; l < p_level; ++l)
        level_p = mesh::refine(level_p);
    mesh::DistributedTetHierarchy dh =
        mesh::distribute(level_p, n_refinements, comm, {}, contact_ghost_reach3(p, level_p));
    DistributedHierarchy3 h;
    for (auto& part : dh.levels) {
        h.levels.push_back(build_distributed_level3(p, std::move(part), comm));
        if (h.levels.size() >= 2)
            h.transfers.push_back(build_distributed_transfer3(p, h.levels[h.levels.size() - 2],
                                                              h.levels.back(), comm));
    }
    return h;
}

} // namespace mlc::levels
