// SPDX-License-Identifier: MIT
/// @file Interpolation between two nested levels (fine = coarse with every triangle split into
/// four): P for displacements, Q for contact multipliers (Alart & Lebon 1995, sect. 2.4), their
/// restrictions, and the coarse/fine splitting of the fine unknowns.
#pragma once

#include "core/types.hpp"
#include "fem/dof_map.hpp"
#include "mesh/mesh.hpp"

#include <vector>

namespace mlc::transfer {

/// The contact nodes of one level, as plain data (one entry per contact element).
struct ContactNodes {
    std::vector<int> vertex;        ///< contactor vertex
    std::vector<int> lambda_dof;    ///< first multiplier unknown
    std::vector<int> n_multipliers; ///< 1 (lambda_n) or 2 (lambda_t, lambda_n)
    /// Per node, the components pinned to zero by supports (contact::ContactElement::pinned:
    /// bit 0 lambda_t, bit 1 lambda_n). Empty: none.
    std::vector<unsigned char> pinned;
    /// true when component c (0 = t, 1 = n) of node i is pinned.
    bool is_pinned(size_t i, int c) const { return !pinned.empty() && (pinned[i] >> c & 1) != 0; }
};

/// How Q treats the ends of a contact boundary.
enum class QRule {
    /// The paper's rule: lambda_h = lambda_H / 2 at a coarse contact vertex, (lambda_H(x1) +
    /// lambda_H(x2)) / 4 at the midpoint of a coarse contact edge (x1, x2). Preserves the
    /// resultant only when the end nodes of the contact boundary carry no force.
    paper,
    /// Same, except that a coarse contact vertex keeps 1 - k / 4 of its force, k being the number
    /// of fine contact nodes that are midpoints of coarse edges incident to it and receive from
    /// it (k = 2: 1/2 as in `paper`; an end node with one contact edge, k = 1: 3/4), so that
    /// sum_h Q lambda = sum_H lambda, component by component, for every coarse multiplier field.
    conservative
};

/// Transfer operators from a coarse level to the fine level refined from it.
struct LevelTransfer {
    /// Nodal interpolation, one scalar per vertex (n_fine_vertices x n_coarse_vertices):
    /// identity at coarse vertices, 1/2, 1/2 at edge midpoints.
    MovableSparseMatrix P_vertex;
    /// The same for interleaved nodal displacement vectors (2 n_fine x 2 n_coarse).
    MovableSparseMatrix P_nodal;
    /// On the unknowns (fine n_dofs x coarse n_dofs): P on displacement unknowns (rows and columns
    /// of prescribed components dropped, so it maps homogeneous corrections), Q on multiplier
    /// unknowns, component by component (t to t, n to n).
    MovableSparseMatrix T;
    /// Q alone on the multiplier unknowns, as rows/cols of T (fine n_dofs x coarse n_dofs, zero
    /// on displacement rows). T = P_u + Q.
    MovableSparseMatrix Q;
    /// Restriction of residuals, R = T^T (stored explicitly).
    MovableSparseMatrix R;
    /// Coarse/fine splitting of the fine unknowns: `coarse_set` lists the fine unknowns that
    /// live on coarse vertices (their displacements, and the multipliers of coarse contact
    /// nodes), in increasing order; `fine_set` the others (new vertices), increasing.
    std::vector<int> coarse_set, fine_set;
    /// For each entry of coarse_set, the coarse-level unknown it corresponds to (a bijection
    /// onto the coarse unknowns: T restricted to coarse_set rows is the identity on
    /// displacements and 1/2 (paper) on multipliers).
    std::vector<int> coarse_dof;
    QRule rule = QRule::paper;

    /// Interpolates a full nodal displacement vector (2 per vertex): u_f = P_nodal u_c.
    /// u_f is resized (the only allocation); it must not be u_c. Throws InvalidInput on a size
    /// mismatch.
    void interpolate_nodal(const Vector& u_coarse, Vector& u_fine) const;
    /// x_f = T x_c on unknowns. x_f is resized (the only allocation); it must not be x_c.
    void prolongate(const Vector& x_coarse, Vector& x_fine) const;
    /// r_c = R r_f (= T^T r_f). r_c is resized (the only allocation); it must not be r_f.
    void restrict_to_coarse(const Vector& r_fine, Vector& r_coarse) const;
};

/// Builds the transfer from a coarse level to the fine level. `fine` must come from
/// mesh::refine(coarse mesh) (its `parents` and `n_coarse_vertices` are used). Every coarse
/// contact vertex must be a fine contact vertex with the same number of multipliers, and every
/// fine contact node on a coarse vertex a coarse contact node; a coarse vertex has the same
/// prescribed components on both levels. `lambda_dof` of each node must be the `extra_dof` of its
/// vertex in the matching DofMap.
///
/// Displacements (P_u, rows and columns of free components only):
///   fine vertex v < n_coarse:  u_h(v, c) = u_H(v, c);
///   new vertex m of edge (a, b): u_h(m, c) = (u_H(a, c) + u_H(b, c)) / 2,
/// where a prescribed parent component contributes 0 (T maps homogeneous corrections).
/// Multipliers (Q), per component c in {t, n} (a node with one multiplier has n only):
///   coarse contact vertex:    lambda_h(c) = w lambda_H(c), w = 1/2 (paper) or 1 - k/4
///                             (conservative, see QRule);
///   contact midpoint of (a, b): lambda_h(c) = (lambda_H(a, c) + lambda_H(b, c)) / 4,
/// where a parent that is not a coarse contact node, or lacks component c, contributes 0 (the
/// square's fully fixed corner). A fine contact midpoint neither of whose parents is a coarse
/// contact node therefore gets 0: it has no coarse force to inherit. A component pinned by
/// supports (ContactNodes::pinned) neither receives nor gives at a midpoint: a pinned
/// multiplier is zero, and a correction of it must not reach a free one (a coarse vertex keeps
/// its w lambda_H, zero on both levels where it is pinned on both).
///
/// Throws InvalidInput when the meshes, numberings or contact nodes do not nest.
LevelTransfer build_transfer(const mesh::Mesh& fine, const fem::DofMap& coarse_dofs,
                             const fem::DofMap& fine_dofs, const ContactNodes& coarse_contacts,
                             const ContactNodes& fine_contacts, QRule rule = QRule::paper);

/// Resultant of a multiplier field: (sum_i lambda_t(i), sum_i lambda_n(i)) over the contact nodes,
/// read from the unknowns x at `lambda_dof` (a node with one multiplier adds to lambda_n only).
/// These are the sums that Q preserves (QRule). Precondition: x.size() covers every lambda_dof.
Eigen::Vector2d multiplier_resultant(const ContactNodes& nodes, const Vector& x);

} // namespace mlc::transfer
