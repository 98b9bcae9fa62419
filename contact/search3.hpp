// SPDX-License-Identifier: MIT
/// @file Contact search between two bodies in 3D, the counterpart of contact/search.hpp: for each
/// contactor vertex the closest target triangle (node on facet) or the coincident target vertex
/// (node on node), on the reference configuration (small strain: once per level). The target
/// triangles are indexed by CGAL's AABB tree (a linear scan in a build without CGAL).
///
/// The normal of a projection (the rule every function here follows):
/// - a point whose closest point lies inside a target triangle takes the triangle's unit normal;
/// - one whose closest point lies on an edge takes the edge's normal: the normalised sum of the
///   unit normals of the target triangles that share the edge (one on the rim of the target, two
///   inside it: their mean direction, which is the angle-weighted mean, each triangle meeting an
///   edge at the angle pi);
/// - one whose closest point is a vertex takes the vertex's normal: the angle-weighted mean of
///   the unit normals of the target triangles at the vertex, sum_f theta_f n_f normalised,
///   theta_f the interior angle of triangle f at the vertex (Thuermer & Wuethrich 1998).
/// These are the pseudo-normals of Baerentzen & Aanaes (2005): the sign of n . (x - p), p the
/// closest point, tells outside from inside for any point x near a closed surface. The initial
/// gap is measured along the normal used, g0 = n . (x - p), >= 0 apart as in 2D: the signed
/// distance to the triangle's plane inside, the distance times the cosine of the angle between
/// x - p and n on an edge or a vertex (equal to the distance on a flat target, smaller by at most
/// a factor cos(theta / 2) at a ridge of dihedral angle pi - theta).
#pragma once

#include "contact/element.hpp"
#include "core/types.hpp"
#include "mesh/simplex_mesh.hpp"

#include <array>
#include <memory>
#include <optional>
#include <vector>

namespace mlc::contact {

/// A target facet in 3D: a boundary triangle (v[0], v[1], v[2]) oriented so that its normal
/// (x1 - x0) x (x2 - x0) points out of its body, toward a contactor facing it.
struct Facet3 {
    std::array<int, 3> v{-1, -1, -1}; ///< the three vertices
};

/// The boundary triangles of `m` tagged `tag`, in mesh order. mesh::BoundaryFace is oriented
/// with its normal out of the body (mesh::check_quality refuses a face whose normal points into
/// the body), so the vertex order is kept.
std::vector<Facet3> target_facets3(const mesh::TetMesh& m, int tag);

/// Where on a triangle its closest point to a given point lies.
enum class TriangleFeature {
    interior, ///< inside the triangle (every barycentric coordinate > 0)
    edge,     ///< on edge k, opposite vertex k (barycentric coordinate k is 0)
    vertex    ///< at vertex k (barycentric coordinate k is 1)
};

/// Projection of a point x on a triangle (a, b, c): its closest point.
struct TriangleProjection {
    int facet = -1; ///< index into the facet list (FacetIndex3), -1 from project_on_triangle
    /// Barycentric coordinates of the closest point p = bary[0] x_a + bary[1] x_b + bary[2] x_c:
    /// each in [0, 1], summing to 1 (to round-off); exactly 0 on the edge opposite a vertex,
    /// exactly (1, 0, 0) and its permutations at a vertex.
    std::array<double, 3> bary{1.0, 0.0, 0.0};
    TriangleFeature where = TriangleFeature::interior; ///< where p lies
    int feature = -1; ///< the edge (opposite vertex k) or the vertex k; -1 inside
    mesh::Vec3 point = mesh::Vec3::Zero(); ///< the closest point p
    mesh::Vec3 n = mesh::Vec3::UnitZ(); ///< unit normal toward the contactor (see the file's rule)
    double g0 = 0.0;                    ///< signed gap n . (x - p) (>= 0 outside the target body)
    double distance = 0.0;              ///< Euclidean distance |x - p| to the closed triangle
};

/// Closest point of the triangle (xa, xb, xc) to x (Ericson 2005, Real-Time Collision Detection,
/// 5.1.5: the Voronoi region of x among the vertices, the edges and the inside), with n the unit
/// triangle normal (xb - xa) x (xc - xa) / |..| whatever the feature (this function does not know
/// the neighbours: FacetIndex3::closest applies the edge and vertex normals) and g0 = n . (x - p),
/// the signed distance of x to the triangle's plane. A point exactly over an edge or a vertex
/// gets that feature. Throws InvalidInput naming the three corners for a degenerate triangle:
/// |(xb - xa) x (xc - xa)| <= kDegenerateTriangleTol L^2, L its longest edge.
TriangleProjection project_on_triangle(const mesh::Vec3& x, const mesh::Vec3& xa,
                                       const mesh::Vec3& xb, const mesh::Vec3& xc);

/// Relative area below which a triangle counts as degenerate (zero area): twice its area over
/// the square of its longest edge (an equilateral triangle has 0.87).
inline constexpr double kDegenerateTriangleTol = 1e-12;

/// Spatial index over a set of target triangles: CGAL's AABB tree over them (a linear scan over
/// their bounding boxes when the build has no CGAL: the same candidates, the same answers). Holds
/// copies of the corners and the edge and vertex normals of the surface they form; `vertices`
/// need not outlive it. The queries are const and safe to call from several threads.
class FacetIndex3 {
public:
    /// Throws InvalidInput for an empty facet list, a vertex index out of range, or a degenerate
    /// triangle (zero area, kDegenerateTriangleTol), naming its vertices and their positions.
    FacetIndex3(const std::vector<mesh::Vec3>& vertices, std::vector<Facet3> facets);
    ~FacetIndex3();
    FacetIndex3(FacetIndex3&&) noexcept;
    FacetIndex3& operator=(FacetIndex3&&) noexcept;

    /// The facet closest to x among those within `radius` (their distance to x), skipping the
    /// facets that have vertex `skip` as a corner (a contactor vertex on the target boundary
    /// itself), with the normal and the gap of the file's rule (an edge's or a vertex's normal
    /// when the closest point lies there). Ties (distances within 1e-12 of the largest facet
    /// size, e.g. a closest point on a shared edge) go to the facet on which the orthogonal
    /// projection of x onto its plane falls inside (the largest of min(0, smallest barycentric
    /// coordinate)), then to the lower index. nullopt when there is none, or when x lies beyond
    /// the rim of the target (the edges that no other target facet shares): its closest point
    /// lies on a rim edge, or is an end of one, and x lies outside that edge's wall, the plane
    /// through the edge perpendicular to its facet (its projection onto the facet's plane falls
    /// outside the facet across the edge), by more than 1e-9 in barycentric coordinate (x is
    /// over no facet; the 3D form of 2D's end of the target boundary). A closest point on an
    /// edge or a vertex inside the target (a ridge or a corner of it) is kept. Exact: the
    /// candidates are the facets whose box meets the cube of half side `radius` (slightly
    /// enlarged) around x, then the exact distance.
    std::optional<TriangleProjection> closest(const mesh::Vec3& x, double radius,
                                              int skip = -1) const;
    /// Indices (ascending) of the facets whose distance to x is at most `radius`.
    std::vector<int> within(const mesh::Vec3& x, double radius) const;
    /// The local target mesh size at x: the longest edge of the facet closest to x (of the
    /// largest one among ties).
    double local_size(const mesh::Vec3& x) const;
    /// Corners of facet i.
    const std::array<mesh::Vec3, 3>& corners(int i) const;
    /// Unit normal of facet i (out of its body).
    const mesh::Vec3& facet_normal(int i) const;
    /// Normal of the target edge (a, b) (the file's rule). Throws InvalidInput when (a, b) is no
    /// edge of a facet, or when the normals of its facets cancel.
    mesh::Vec3 edge_normal(int a, int b) const;
    /// Normal of target vertex v (the file's rule: angle-weighted). Throws InvalidInput when v is
    /// no corner of a facet, or when the normals of its facets cancel.
    mesh::Vec3 vertex_normal(int v) const;
    /// Whether the target edge (a, b) lies on the rim of the target (one facet only).
    bool is_rim_edge(int a, int b) const;
    /// The facets, as given.
    const std::vector<Facet3>& facets() const;
    /// Longest edge of all facets.
    double max_size() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// What a 3D search found for one contact pair.
struct SearchResult3 {
    std::vector<ContactElement3> elements; ///< one per contactor node that found a target
    std::vector<int> not_found;            ///< contactor vertices that found none (left out)
};

/// Node-on-facet element in 3D: contactor vertex c against the target triangle f, the projection
/// of c at barycentric coordinates `bary`: node_on_facet_weighted with the weights
/// (1, -bary[0], -bary[1], -bary[2]) on (c, f.v[0], f.v[1], f.v[2]), n the unit normal toward
/// the contactor, t = tangent_basis(n), g0 the initial signed gap. Throws InvalidInput for a
/// coordinate outside [0, 1], coordinates not summing to 1 (to 1e-10), a normal that is not of
/// unit length, c a corner of f, or a corner of f repeated. The node-on-node element in 3D is
/// node_on_node<3> (contact/element.hpp).
ContactElement3 node_on_facet3(int c, const Facet3& f, const std::array<double, 3>& bary,
                               const mesh::Vec3& n, double g0, double mu, double r, int pair);

/// Node-on-facet search in 3D (the counterpart of node_on_facet_search with its nodal weights). A
/// contactor vertex c of `m` is a contact node when `reference` has a facet within
/// search_radius * h0(c) of it, h0(c) = reference.local_size(x_c), and c is not beyond the rim
/// of the reference target (FacetIndex3::closest). Pass the level-0 target facets as `reference`
/// (vertex indices of level 0 are kept by refinement): the decision is then the same on every
/// level and the contact nodes nest under refinement, even on a curved target whose facets move.
/// The element uses the closest facet of `m` tagged `target_tag` (searched within the reference
/// radius plus the reference's largest facet): weights (1, -N_a, -N_b, -N_c) with N the
/// barycentric coordinates of the closest point, the normal of the file's rule, t =
/// tangent_basis(n), g0 = n . (x_c - p). Contactor vertices that are not contact nodes are
/// listed in `not_found`, in input order.
///
/// With `integration` = FacetIntegration::segment or dual (then `contactor_tag`, the tag of the
/// contactor faces, is required) the contact nodes, n, t and g0 are the same, but the weights
/// are those of mortar_weights3 (contact/mortar3.hpp: the node's contactor faces projected on
/// its plane, clipped against the target faces within the node's search distance, integrated
/// exactly; segment_element3), which pass the contact patch test on non-matching meshes. A node
/// whose patch covers nothing keeps the nodal weights.
///
/// Throws InvalidInput when the mesh has no boundary face tagged `target_tag`, for a degenerate
/// target triangle, or (segment, dual) when `contactor_tag` is missing or a contactor vertex is
/// on no face with it.
SearchResult3 node_on_facet_search3(const mesh::TetMesh& m, const std::vector<int>& contactors,
                                    int target_tag, const FacetIndex3& reference,
                                    double search_radius, double mu, double r, int pair,
                                    FacetIntegration integration = FacetIntegration::nodal,
                                    int contactor_tag = -1);

/// Node-on-node search in 3D for matching interfaces: for each contactor vertex c, the target
/// vertex (a corner of a face tagged `target_tag`) nearest to c (ties to the lower index),
/// accepted when within match_tolerance * h, h the mean length of the target edges at that
/// vertex, and when it is not c itself. The normal is the vertex's (the file's rule:
/// angle-weighted), g0 = n . (x_c - x_a). Unmatched contactor vertices are listed in
/// `not_found`. Throws InvalidInput when the mesh has no boundary face tagged `target_tag`, for
/// a degenerate target triangle, or when the normals cancel at a matched vertex.
SearchResult3 node_on_node_search3(const mesh::TetMesh& m, const std::vector<int>& contactors,
                                   int target_tag, double match_tolerance, double mu, double r,
                                   int pair);

} // namespace mlc::contact
