// SPDX-License-Identifier: MIT
/// @file Q on a contact surface in mass form, Q = M_h P M_H^-1 with lumped surface masses (nodal
/// force -> traction -> linear interpolation -> nodal force), for any facet size: triangles (a 3D
/// body's contact surface) or segments (a contact line). Written against plain data: vertex
/// positions, facets as vertex indices, and the parents of the new vertices of a refinement
/// (mesh/tet_refine.hpp: coarse vertices keep their indices, the new vertex v >= n_coarse is the
/// midpoint of the coarse edge parents[v - n_coarse], each coarse face splits 1->4).
///
/// Reduction to the 2D rule (docs/theory.md#theory-q). On a uniformly refined line (facets =
/// segments of length h, fine h/2) the lumped masses are h at an inner coarse vertex and h/2 at
/// every inner fine vertex, so Q gives (m_h / m_H) lambda_H = lambda_H / 2 at a coarse vertex and
/// (h/2) (lambda_H(a)/h + lambda_H(b)/h) / 2 = (lambda_H(a) + lambda_H(b)) / 4 at the midpoint of
/// (a, b): the paper's weights (QRule::paper). They differ at the end e of a line, where the mass
/// form gives lambda_H(e)/2 to e and lambda_H(e)/2 + lambda_H(b)/4 to the midpoint next to it (end
/// masses h/2 and h/4), and on graded lines (a coarse vertex always keeps 1/2; the midpoint of a
/// segment of length l receives l / (4 m_H(a)) of lambda_H(a)). Every coarse vertex then sends
/// exactly its force, as QRule::conservative does with other weights at the ends (3/4, 1/4).
#pragma once

#include "core/types.hpp"

#include <Eigen/Core>

#include <array>
#include <vector>

namespace mlc::transfer {

/// Vertex positions, indexed by mesh vertex (a 2D mesh puts z = 0).
using SurfacePoints = std::vector<Eigen::Vector3d>;
/// Facets of a surface as mesh vertex indices: F = 3 triangles, F = 2 segments.
template <int F> using SurfaceFacets = std::vector<std::array<int, F>>;
/// parents[v - n_coarse]: the two coarse vertices whose edge new vertex v refines.
using VertexParents = std::vector<std::array<int, 2>>;
/// One 3-vector per surface vertex (rows in surface index order): nodal forces in global
/// components (x, y, z), or a node's (lambda_t1, lambda_t2, lambda_n) in its frame.
using SurfaceForces = Eigen::Matrix<double, Eigen::Dynamic, 3>;

/// The vertices a set of facets touches, numbered 0..size()-1 in increasing mesh vertex order.
struct SurfaceVertices {
    std::vector<int> vertex; ///< surface index -> mesh vertex (increasing)
    std::vector<int> index;  ///< mesh vertex -> surface index, -1 for a vertex on no facet
    int size() const { return static_cast<int>(vertex.size()); }
};

/// The vertices touched by `facets` of a mesh with n_vertices vertices. Throws InvalidInput on
/// a vertex index outside 0..n_vertices-1 or a facet that repeats a vertex.
template <int F> SurfaceVertices surface_vertices(const SurfaceFacets<F>& facets, int n_vertices);

/// Length (F = 2) or area (F = 3) of one facet.
template <int F> double facet_measure(const SurfacePoints& x, const std::array<int, F>& facet);

/// Lumped surface masses per surface index: m_i = sum over the facets touching i of
/// |facet| / F, the integral of the P1 hat function N_i over the surface (the weight that turns
/// a nodal force into a traction, such as the pressure lambda_n / int N_i dA). Throws InvalidInput
/// on a facet of zero measure, an index outside `x`, or a facet vertex not in `s`.
template <int F>
Vector lumped_surface_masses(const SurfacePoints& x, const SurfaceFacets<F>& facets,
                             const SurfaceVertices& s);

/// Which coarse masses M_H Q divides by.
enum class CoarseMass {
    /// m_H = P^T m_h: each coarse hat function interpolated onto the fine surface and integrated
    /// there. Every column of Q then sums to one, so Q conserves the total force on any surface.
    /// Equal to `own` (up to rounding) when the fine surface lies on the coarse one: flat facets
    /// with the new vertices at the edge midpoints, planar or not.
    on_fine_surface,
    /// m_H = the coarse surface's own lumped masses. Conserves the total force only when the fine
    /// surface lies on the coarse one; where refinement moved midpoints onto a curved surface, a
    /// uniform traction's total changes by the ratio of the fine and coarse areas.
    own
};

/// Q from a coarse surface to the fine surface refined from it, over surface indices.
struct SurfaceQ {
    SurfaceVertices coarse, fine; ///< surface index <-> mesh vertex, per level
    Vector coarse_mass;           ///< m_H: the coarse surface's own lumped masses
    Vector coarse_mass_on_fine;   ///< P^T m_h (CoarseMass::on_fine_surface)
    Vector fine_mass;             ///< m_h: the fine surface's lumped masses
    /// P restricted to the surface (n_fine x n_coarse surface vertices): 1 at a coarse vertex,
    /// 1/2 at both parents of a midpoint. Rows in column order.
    MovableSparseMatrix P;
    /// Q = diag(m_h) P diag(1 / m_H), m_H chosen by `rule`; same pattern as P.
    MovableSparseMatrix Q;
    CoarseMass rule = CoarseMass::on_fine_surface;
};

/// Builds Q on the contact surface of two nested levels: coarse_points are the coarse mesh's
/// vertices (n_coarse of them), fine_points the fine mesh's (n_coarse + parents.size()), and the
/// facets the contact surface on each level (the fine facets are the children of the coarse
/// ones). Per component, with m the lumped masses (lumped_surface_masses; m_H as `rule` says):
///   coarse vertex i kept:        (Q lambda_H)(i) = m_h(i) lambda_H(i) / m_H(i);
///   new vertex j of edge (a, b): (Q lambda_H)(j) = m_h(j) (lambda_H(a)/m_H(a) +
///                                                          lambda_H(b)/m_H(b)) / 2.
/// Throws InvalidInput when the sizes do not match, a fine surface vertex below n_coarse is no
/// coarse surface vertex, a new fine surface vertex has a parent off the coarse surface, a coarse
/// surface vertex is not on the fine surface, or a facet is degenerate.
template <int F>
SurfaceQ build_surface_q(const SurfacePoints& coarse_points, const SurfaceFacets<F>& coarse_facets,
                         const SurfacePoints& fine_points, const SurfaceFacets<F>& fine_facets,
                         const VertexParents& parents,
                         CoarseMass rule = CoarseMass::on_fine_surface);

/// Q applied per component to nodal forces in global components: row i of the result is the
/// force on fine surface vertex i. Throws InvalidInput unless `coarse` has Q.cols() rows.
SurfaceForces transfer_forces(const SurfaceQ& q, const SurfaceForces& coarse);

/// A contact node's orthonormal frame: tangents t1, t2 and normal n.
struct NodeFrame {
    Eigen::Vector3d t1, t2, n;
};

/// The global force of local components (lambda_t1, lambda_t2, lambda_n) in `frame`.
inline Eigen::Vector3d to_global(const NodeFrame& frame, const Eigen::Vector3d& local) {
    return local[0] * frame.t1 + local[1] * frame.t2 + local[2] * frame.n;
}

/// The components (f.t1, f.t2, f.n) of a global force f in `frame` (orthonormal).
inline Eigen::Vector3d to_local(const NodeFrame& frame, const Eigen::Vector3d& f) {
    return {f.dot(frame.t1), f.dot(frame.t2), f.dot(frame.n)};
}

/// Q for multipliers held in each node's own frame (rows (lambda_t1, lambda_t2, lambda_n) in
/// surface index order): each coarse node's force is formed in global components, transferred
/// by Q, and projected onto each fine node's frame. Component-by-component transfer of the local
/// values would be wrong on a curved surface, where coarse and fine tangent bases differ. A
/// frictionless node carries no tangential multipliers: give it lambda_t = 0, and drop the
/// tangential part it receives (on a curved surface, the part of the coarse normals' forces along
/// the fine tangents). Throws InvalidInput on sizes that do not match Q, or a frame that is not
/// orthonormal to 1e-10.
SurfaceForces transfer_local_forces(const SurfaceQ& q, const SurfaceForces& coarse_local,
                                    const std::vector<NodeFrame>& coarse_frames,
                                    const std::vector<NodeFrame>& fine_frames);

} // namespace mlc::transfer
