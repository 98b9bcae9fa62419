// SPDX-License-Identifier: MIT
/// @file 3D segment-integrated (mortar-type, lumped) and dual contact weights of one contactor
/// node against target triangles (Puso & Laursen 2004): the 3D counterpart of the segment and
/// dual weights of node_on_facet_search (contact/search.hpp), with its building blocks, the
/// clipping of convex polygons and the exact integral of a product of two linear functions on a
/// triangle.
#pragma once

#include "contact/element.hpp"
#include "contact/search3.hpp"
#include "core/types.hpp"
#include "mesh/simplex_mesh.hpp"

#include <array>
#include <limits>
#include <vector>

namespace mlc::contact {

/// A triangle of a boundary surface: its vertex ids and their coordinates, in the order of
/// mesh::BoundaryFace (its normal (x1 - x0) x (x2 - x0) points out of its body).
struct SurfaceTriangle {
    std::array<int, 3> v{-1, -1, -1}; ///< vertex ids
    std::array<mesh::Vec3, 3> x{mesh::Vec3::Zero(), mesh::Vec3::Zero(),
                                mesh::Vec3::Zero()}; ///< coordinates
};

/// Signed area of a polygon of the plane (the shoelace formula): positive when its vertices run
/// counter-clockwise; 0 for fewer than 3 vertices.
double polygon_area(const std::vector<Vec2>& polygon);

/// The intersection of two convex polygons of the plane (Sutherland–Hodgman: `subject` clipped
/// by each edge of `clip` in turn), counter-clockwise whatever the orientation of the inputs
/// (each may run either way; a polygon of zero area clips to nothing). A point on an edge of
/// `clip` counts as inside. Consecutive vertices closer than 1e-14 times the size of the inputs
/// (their bounding boxes' largest extent) are merged; the result is empty when fewer than 3
/// vertices remain: the polygons are disjoint or meet in an edge or a point. An intersection of
/// round-off size may still come back as a sliver; polygon_area says how large it is.
std::vector<Vec2> clip_convex_polygons(const std::vector<Vec2>& subject,
                                       const std::vector<Vec2>& clip);

/// The exact integral over a triangle of area `area` of f g, f and g linear on it and given by
/// their values at its three vertices (the same vertex order for both):
///   int_T f g dA = area / 12 (sum_a f_a g_a + (sum_a f_a)(sum_b g_b)),
/// the consistent mass matrix area / 12 (1 + delta_ab) between the vertex values (with g = 1:
/// int_T f dA = area / 3 sum_a f_a). `area` is the triangle's own (positive) area in whatever
/// measure the integral is wanted; nothing is checked.
double integrate_linear_products_on_triangle(double area, const std::array<double, 3>& f,
                                             const std::array<double, 3>& g);

/// The weights of one contactor node (mortar_weights3): the node itself has weight 1, the
/// target vertex targets[k] weight weights[k], and the weights sum to 0 (to round-off).
struct MortarWeights3 {
    std::vector<int> targets;    ///< target vertex ids, ascending; those with M_ik != 0
    std::vector<double> weights; ///< -M_ik / D_covered, one per target vertex
    double D = 0.0;              ///< int N_i dA over the whole patch (its area / 3)
    /// The covered part of D: the integral of the test function (N_i, or psi_i when `dual`)
    /// over the pieces; D when the patch lies entirely over the target, 0 when nothing is.
    double D_covered = 0.0;
    /// Pairs (contactor triangle, target triangle) whose projections overlap (and count).
    int pieces = 0;
    /// true when the dual test functions were used: asked for, and the patch entirely covered.
    bool dual = false;
};

/// The segment-integrated (FacetIntegration::segment) or dual (FacetIntegration::dual) weights
/// of contactor node `node`, the 3D counterpart of those of node_on_facet_search
/// (contact/search.hpp), after Puso & Laursen 2004.
///
/// `patch` are the contactor boundary triangles that have `node` as a vertex (the support of its
/// linear shape function N_i on the contactor surface; the node's position is taken from the
/// first), `n` the node's contact normal as in BasicContactElement: the target's normal toward
/// the contactor (normalized here), and `targets` the candidate target boundary triangles,
/// oriented as mesh::BoundaryFace (every pair is tried: the caller picks the candidates, e.g.
/// those within the node's search distance). Every triangle is projected along n onto the plane
/// through the node orthogonal to n. A target triangle counts for a contactor triangle when it
/// faces the same way as n (its outward normal n_t has n_t . n > 0, as the facets in 2D; more
/// than 1e-12, since a triangle parallel to n projects on a line), has no vertex in common with
/// it (a contactor triangle on the target surface itself), and the two projections overlap in
/// more than 1e-12 of the smaller one's projected area; with a finite `reach`, also when the
/// distance along n between the two triangles is at most `reach` at some vertex of the overlap.
/// A contactor triangle nearly parallel to n (|n_c . n| <= 1e-12) has no pieces. Each overlap
/// (a piece) is cut into triangles from its centroid, and on those the shape functions (the
/// barycentric coordinates of the contactor triangle, N_i, and of the target triangle, N_k, at
/// the projections) are linear, so that integrate_linear_products_on_triangle is exact:
///   D_i = int N_i dA over the patch,  M_ik = int N_i N_k dA,  D_i^cov = int N_i dA,
/// the last two over the pieces, dA the area of the contactor (the projected area divided by
/// |n_c . n|, n_c the contactor triangle's unit normal). Weights (1, -M_ik / D_i^cov): since
/// sum_k N_k = 1 they sum to 0. With uniform pressure p the multipliers p D_i pass to a target
/// vertex k whose support is covered by nodes that are entirely covered as
/// sum_i p D_i M_ik / D_i = p int N_k dA, the consistent load (the patch test).
///
/// FacetIntegration::dual uses psi_i = 4 N_i - 1 on each contactor triangle in place of N_i in
/// M_ik and D_i^cov (biorthogonal on linear triangles: int_T psi_i N_j = delta_ij int_T N_j),
/// which gives the weights (1, -1) on a matching interface; sum_i psi_i = 1 on a triangle keeps
/// the patch test. As in 2D, only when the patch is entirely covered (D_i^cov > (1 - 1e-9)
/// D_i), otherwise the weights are the segment ones (MortarWeights3::dual says which). When
/// nothing is covered the result has no pieces, no targets and D_covered = 0
/// (node_on_facet_search falls back to the nodal weights there).
///
/// Throws InvalidInput for an integration other than segment or dual, an empty patch, a patch
/// triangle without `node`, a zero or non-finite n, or a triangle of zero area (contactor or
/// target, named by its vertex ids and coordinates: twice its area at most 1e-14 times its
/// longest edge squared).
MortarWeights3 mortar_weights3(int node, const std::vector<SurfaceTriangle>& patch,
                               const mesh::Vec3& n, const std::vector<SurfaceTriangle>& targets,
                               FacetIntegration integration,
                               double reach = std::numeric_limits<double>::infinity());

/// The segment or dual node-on-facet element of contactor vertex `c` of mesh `m` (the 3D
/// counterpart of 2D node_on_facet_search's segment elements): `nodal` is its node-on-facet
/// element with the nodal weights (node_on_facet_search3: the normal n, the tangents and g0 are
/// kept), `patch` the contactor faces at c (the support of its shape function), `index` the
/// level's target faces and `reach` the search distance of c. The targets tried are the faces
/// of `index` within reach of the patch; mortar_weights3 gives the weights (1, -M_ck / D_c^cov).
/// A node whose patch covers nothing keeps `nodal`.
ContactElement3 segment_element3(const mesh::TetMesh& m, const ContactElement3& nodal,
                                 const std::vector<SurfaceTriangle>& patch,
                                 const FacetIndex3& index, double reach,
                                 FacetIntegration integration);

} // namespace mlc::contact
