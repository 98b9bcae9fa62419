// SPDX-License-Identifier: MIT
// Construction and application of the two-level interpolation P (displacements) and Q (contact
// multipliers) of Alart & Lebon (1995), sect. 2.4 (docs/theory.md#theory-transfer).
#include "transfer/transfer.hpp"
#include "transfer/prolongation.hpp"

#include "core/check.hpp"
#include "core/first_touch.hpp"

#include <array>

namespace mlc::transfer {

namespace {

/// Component (0 = t, 1 = n) of multiplier slot q of a node with nm multipliers.
int component_of_slot(int nm, int q) {
    return q + (2 - nm);
}

/// Slot of component c in a node with nm multipliers, or -1 when the node lacks it.
int slot_of_component(int nm, int c) {
    const int q = c - (2 - nm);
    return q >= 0 ? q : -1;
}

/// y = A x by rows; allocates nothing beyond resizing y.
void csr_apply(const SparseMatrix& A, const Vector& x, Vector& y, const char* what) {
    MLC_CHECK(x.size() == A.cols(),
              what << ": input has " << x.size() << " entries, expected " << A.cols());
    MLC_CHECK(&x != &y, what << ": input and output must be different vectors");
    y.resize(A.rows());
    // The rows over the threads, each row's sum in its own order (the same values serially).
    parallel::for_rows(static_cast<size_t>(A.outerSize()), parallel::kTouchRowsPerChunk,
                       [&](size_t b, size_t e) {
                           for (auto i = static_cast<Index>(b); i < static_cast<Index>(e); ++i) {
                               double s = 0.0;
                               for (SparseMatrix::InnerIterator it(A, i); it; ++it)
                                   s += it.value() * x[it.index()];
                               y[i] = s;
                           }
                       });
}

/// Checks one level's contact nodes against its numbering; returns node index per vertex.
std::vector<int> node_of_vertex(const ContactNodes& c, const fem::DofMap& dofs, const char* level) {
    const size_t n = c.vertex.size();
    MLC_CHECK(c.pinned.empty() || c.pinned.size() == n,
              level << " contact nodes: " << n << " vertices but " << c.pinned.size()
                    << " pinned masks; give one per node or none");
    MLC_CHECK(c.lambda_dof.size() == n && c.n_multipliers.size() == n,
              level << " contact nodes: " << n << " vertices, " << c.lambda_dof.size()
                    << " lambda_dof, " << c.n_multipliers.size()
                    << " n_multipliers; the three lists must have one entry per node");
    std::vector<int> of(static_cast<size_t>(dofs.n_vertices()), -1);
    for (size_t i = 0; i < n; ++i) {
        const int v = c.vertex[i];
        MLC_CHECK(v >= 0 && v < dofs.n_vertices(), level << " contact node " << i << ": vertex "
                                                         << v << " outside 0.."
                                                         << dofs.n_vertices() - 1);
        MLC_CHECK(of[static_cast<size_t>(v)] < 0,
                  level << " contact nodes " << of[static_cast<size_t>(v)] << " and " << i
                        << " share vertex " << v << "; one contactor node per vertex");
        const int nm = c.n_multipliers[i];
        MLC_CHECK(nm == 1 || nm == 2, level << " contact node " << i << " (vertex " << v << ") has "
                                            << nm << " multipliers, expected 1 or 2");
        MLC_CHECK(c.lambda_dof[i] == dofs.extra_dof(v) && c.lambda_dof[i] >= 0 &&
                      c.lambda_dof[i] + nm <= dofs.n_dofs(),
                  level << " contact node " << i << " (vertex " << v << "): lambda_dof "
                        << c.lambda_dof[i] << " but the numbering puts the vertex's multipliers at "
                        << dofs.extra_dof(v) << "; build ContactNodes from the same level");
        of[static_cast<size_t>(v)] = static_cast<int>(i);
    }
    return of;
}

/// The numberings nest: they have the meshes' vertex counts, and the supports nest (that the fine
/// mesh refines the coarse one, vertex_prolongation checks).
void check_levels_nest(const mesh::Mesh& fine, const fem::DofMap& coarse_dofs,
                       const fem::DofMap& fine_dofs) {
    const int nf = fine.n_vertices();
    const int nc = fine.n_coarse_vertices;
    MLC_CHECK(coarse_dofs.n_vertices() == nc, "build_transfer: coarse numbering has "
                                                  << coarse_dofs.n_vertices()
                                                  << " vertices, the coarse mesh " << nc);
    MLC_CHECK(fine_dofs.n_vertices() == nf, "build_transfer: fine numbering has "
                                                << fine_dofs.n_vertices()
                                                << " vertices, the fine mesh " << nf);
    for (int v = 0; v < nc; ++v)
        for (int c = 0; c < 2; ++c)
            MLC_CHECK((coarse_dofs.u_dof(v, c) < 0) == (fine_dofs.u_dof(v, c) < 0),
                      "build_transfer: component " << c << " of coarse vertex " << v << " is "
                                                   << (coarse_dofs.u_dof(v, c) < 0 ? "" : "not ")
                                                   << "prescribed on the coarse level but "
                                                   << (fine_dofs.u_dof(v, c) < 0 ? "" : "not ")
                                                   << "on the fine one; supports must nest");
}

/// The fine contact boundary contains the coarse one, with the same multipliers per vertex.
void check_contacts_nest(int nc, const std::vector<int>& cnode, const std::vector<int>& fnode,
                         const ContactNodes& coarse_contacts, const ContactNodes& fine_contacts) {
    for (int v = 0; v < nc; ++v) {
        const int i = cnode[static_cast<size_t>(v)];
        const int j = fnode[static_cast<size_t>(v)];
        MLC_CHECK(i < 0 || j >= 0, "build_transfer: coarse contact vertex "
                                       << v
                                       << " is not a fine contact vertex; the fine contact "
                                          "boundary must contain the coarse one");
        MLC_CHECK(j < 0 || i >= 0, "build_transfer: fine contact node "
                                       << j << " sits on coarse vertex " << v
                                       << ", which is not a coarse contact node");
        if (i >= 0)
            MLC_CHECK(coarse_contacts.n_multipliers[static_cast<size_t>(i)] ==
                          fine_contacts.n_multipliers[static_cast<size_t>(j)],
                      "build_transfer: contact vertex "
                          << v << " has " << coarse_contacts.n_multipliers[static_cast<size_t>(i)]
                          << " multipliers on the coarse level and "
                          << fine_contacts.n_multipliers[static_cast<size_t>(j)]
                          << " on the fine one");
    }
}

/// Multiplier rows (Q). k[i][c]: fine contact midpoints next to coarse node i that receive
/// component c from it; the conservative rule keeps 1 - k/4 at i so that the weights of
/// lambda_H(i, c) over the fine nodes sum to one. Returns Q's triplets.
std::vector<Triplet> multiplier_rows(const mesh::Mesh& fine, const std::vector<int>& cnode,
                                     const ContactNodes& coarse_contacts,
                                     const ContactNodes& fine_contacts, QRule rule) {
    const int nc = fine.n_coarse_vertices;
    std::vector<std::array<int, 2>> k(coarse_contacts.vertex.size(), {0, 0});
    auto for_each_midpoint_source = [&](int j, auto&& f) {
        const int v = fine_contacts.vertex[static_cast<size_t>(j)];
        const int nm = fine_contacts.n_multipliers[static_cast<size_t>(j)];
        for (int q = 0; q < nm; ++q) {
            const int c = component_of_slot(nm, q);
            if (fine_contacts.is_pinned(static_cast<size_t>(j), c)) continue;
            for (int p : fine.parents[static_cast<size_t>(v - nc)]) {
                const int i = cnode[static_cast<size_t>(p)];
                if (i < 0 || coarse_contacts.is_pinned(static_cast<size_t>(i), c)) continue;
                const int qc =
                    slot_of_component(coarse_contacts.n_multipliers[static_cast<size_t>(i)], c);
                if (qc >= 0) f(q, c, i, qc);
            }
        }
    };
    const int n_fine_nodes = static_cast<int>(fine_contacts.vertex.size());
    for (int j = 0; j < n_fine_nodes; ++j)
        if (fine_contacts.vertex[static_cast<size_t>(j)] >= nc)
            for_each_midpoint_source(j, [&](int, int c, int i, int) {
                ++k[static_cast<size_t>(i)][static_cast<size_t>(c)];
            });

    std::vector<Triplet> tq;
    tq.reserve(static_cast<size_t>(4 * n_fine_nodes));
    for (int j = 0; j < n_fine_nodes; ++j) {
        const int v = fine_contacts.vertex[static_cast<size_t>(j)];
        const int row0 = fine_contacts.lambda_dof[static_cast<size_t>(j)];
        if (v < nc) {
            const int i = cnode[static_cast<size_t>(v)];
            const int nm = coarse_contacts.n_multipliers[static_cast<size_t>(i)];
            const int col0 = coarse_contacts.lambda_dof[static_cast<size_t>(i)];
            for (int q = 0; q < nm; ++q) {
                const int c = component_of_slot(nm, q);
                const double w =
                    rule == QRule::paper
                        ? 0.5
                        : 1.0 - 0.25 * k[static_cast<size_t>(i)][static_cast<size_t>(c)];
                tq.emplace_back(row0 + q, col0 + q, w);
            }
        } else {
            for_each_midpoint_source(j, [&](int q, int, int i, int qc) {
                tq.emplace_back(row0 + q, coarse_contacts.lambda_dof[static_cast<size_t>(i)] + qc,
                                0.25);
            });
        }
    }
    return tq;
}

/// T = P on the displacement rows (prescribed components dropped) and Q on the multiplier
/// rows, row by row into CSR.
void build_full_prolongation(const mesh::Mesh& fine, const fem::DofMap& coarse_dofs,
                             const fem::DofMap& fine_dofs, LevelTransfer& tr) {
    const int nc = fine.n_coarse_vertices;
    const Index n_f = fine_dofs.n_dofs(), n_c = coarse_dofs.n_dofs();
    const SparseMatrix& Q = tr.Q;
    const int* qo = Q.outerIndexPtr();
    // The columns of displacement row d (at most two), in increasing order.
    auto u_cols = [&](Index d, int cols[2]) {
        const int v = fine_dofs.vertex_of(d);
        const int c = fine_dofs.u_dof(v, 0) == d ? 0 : 1;
        if (v < nc) {
            cols[0] = coarse_dofs.u_dof(v, c);
            return 1;
        }
        int m = 0;
        for (int p : fine.parents[static_cast<size_t>(v - nc)])
            if (const int col = coarse_dofs.u_dof(p, c); col >= 0) cols[m++] = col;
        if (m == 2 && cols[1] < cols[0]) std::swap(cols[0], cols[1]);
        return m;
    };
    tr.T.resize(n_f, n_c);
    int* to = tr.T.outerIndexPtr();
    to[0] = 0;
    int cols[2];
    for (Index d = 0; d < n_f; ++d)
        to[d + 1] = to[d] + (fine_dofs.is_displacement(d) ? u_cols(d, cols) : qo[d + 1] - qo[d]);
    tr.T.resizeNonZeros(to[n_f]);
    int* ti = tr.T.innerIndexPtr();
    double* tv = tr.T.valuePtr();
    for (Index d = 0; d < n_f; ++d) {
        const int at = to[d];
        if (fine_dofs.is_displacement(d)) {
            const int m = u_cols(d, cols);
            for (int j = 0; j < m; ++j) {
                ti[at + j] = cols[j];
                tv[at + j] = m == 1 && fine_dofs.vertex_of(d) < nc ? 1.0 : 0.5;
            }
        } else {
            std::copy(Q.innerIndexPtr() + qo[d], Q.innerIndexPtr() + qo[d + 1], ti + at);
            std::copy(Q.valuePtr() + qo[d], Q.valuePtr() + qo[d + 1], tv + at);
        }
    }
}

/// Coarse/fine splitting: unknowns on coarse vertices and their coarse counterparts.
void split_coarse_fine(int nc, const fem::DofMap& coarse_dofs, const fem::DofMap& fine_dofs,
                       LevelTransfer& tr) {
    const Index n_f = fine_dofs.n_dofs(), n_c = coarse_dofs.n_dofs();
    tr.coarse_set.reserve(static_cast<size_t>(n_c));
    tr.coarse_dof.reserve(static_cast<size_t>(n_c));
    tr.fine_set.reserve(static_cast<size_t>(n_f - n_c));
    for (Index d = 0; d < n_f; ++d) {
        const int v = fine_dofs.vertex_of(d);
        if (v >= nc) {
            tr.fine_set.push_back(static_cast<int>(d));
            continue;
        }
        tr.coarse_set.push_back(static_cast<int>(d));
        if (fine_dofs.is_displacement(d)) {
            const int c = fine_dofs.u_dof(v, 0) == d ? 0 : 1;
            tr.coarse_dof.push_back(coarse_dofs.u_dof(v, c));
        } else {
            // Extra unknowns the contact lists do not describe would have no coarse partner.
            MLC_CHECK(coarse_dofs.extra_dof(v) >= 0,
                      "build_transfer: fine unknown "
                          << d << " is an extra unknown of coarse vertex " << v
                          << ", which has none on the coarse level");
            tr.coarse_dof.push_back(coarse_dofs.extra_dof(v) +
                                    static_cast<int>(d - fine_dofs.extra_dof(v)));
        }
    }
    MLC_CHECK(static_cast<Index>(tr.coarse_set.size()) == n_c,
              "build_transfer: " << tr.coarse_set.size() << " fine unknowns on coarse vertices but "
                                 << n_c << " coarse unknowns; the numberings do not nest");
}

} // namespace

Eigen::Vector2d multiplier_resultant(const ContactNodes& nodes, const Vector& x) {
    Eigen::Vector2d s = Eigen::Vector2d::Zero();
    for (size_t i = 0; i < nodes.vertex.size(); ++i) {
        const int nm = nodes.n_multipliers[i];
        for (int q = 0; q < nm; ++q)
            s[component_of_slot(nm, q)] += x[nodes.lambda_dof[i] + q];
    }
    return s;
}

LevelTransfer build_transfer(const mesh::Mesh& fine, const fem::DofMap& coarse_dofs,
                             const fem::DofMap& fine_dofs, const ContactNodes& coarse_contacts,
                             const ContactNodes& fine_contacts, QRule rule) {
    LevelTransfer tr;
    tr.P_vertex = vertex_prolongation(fine); // checks the parents of every new vertex
    check_levels_nest(fine, coarse_dofs, fine_dofs);
    const int nc = fine.n_coarse_vertices;
    const std::vector<int> cnode = node_of_vertex(coarse_contacts, coarse_dofs, "coarse");
    const std::vector<int> fnode = node_of_vertex(fine_contacts, fine_dofs, "fine");
    check_contacts_nest(nc, cnode, fnode, coarse_contacts, fine_contacts);
    tr.rule = rule;
    tr.P_nodal = expand_components(tr.P_vertex, 2);
    const std::vector<Triplet> tq =
        multiplier_rows(fine, cnode, coarse_contacts, fine_contacts, rule);
    const Index n_f = fine_dofs.n_dofs(), n_c = coarse_dofs.n_dofs();
    tr.Q.resize(n_f, n_c);
    tr.Q.setFromTriplets(tq.begin(), tq.end());
    build_full_prolongation(fine, coarse_dofs, fine_dofs, tr);
    tr.R = tr.T.transpose();
    split_coarse_fine(nc, coarse_dofs, fine_dofs, tr);
    return tr;
}

void LevelTransfer::interpolate_nodal(const Vector& u_coarse, Vector& u_fine) const {
    csr_apply(P_nodal, u_coarse, u_fine, "LevelTransfer::interpolate_nodal");
}

void LevelTransfer::prolongate(const Vector& x_coarse, Vector& x_fine) const {
    csr_apply(T, x_coarse, x_fine, "LevelTransfer::prolongate");
}

void LevelTransfer::restrict_to_coarse(const Vector& r_fine, Vector& r_coarse) const {
    csr_apply(R, r_fine, r_coarse, "LevelTransfer::restrict_to_coarse");
}

} // namespace mlc::transfer
