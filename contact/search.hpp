// SPDX-License-Identifier: MIT
/// @file Contact search between two bodies: for each contactor vertex the closest target facet
/// (node on facet) or the coincident target vertex (node on node), on the reference
/// configuration (small strain: once per level).
#pragma once

#include "contact/element.hpp"
#include "core/types.hpp"
#include "mesh/mesh.hpp"

#include <array>
#include <memory>
#include <optional>
#include <vector>

namespace mlc::contact {

/// A target facet: a boundary edge (a, b) oriented counter-clockwise around its body (the body
/// lies to the left of a -> b), so that its unit normal toward the outside, which points toward
/// a contactor facing it, is n = (d_y, -d_x) / |d| with d = x_b - x_a.
struct Facet {
    int a = -1;
    int b = -1;
};

/// The boundary edges of `m` tagged `tag`, in mesh order.
std::vector<Facet> target_facets(const mesh::Mesh& m, int tag);

/// Projection of a point x on a facet (a, b).
struct FacetProjection {
    int facet = -1;        ///< index into the facet list
    double alpha = 0.0;    ///< barycentric coordinate of the projection, clamped to [0, 1]
    Vec2 n = Vec2::Zero(); ///< unit facet normal toward the contactor
    double g0 = 0.0;       ///< signed gap n . (x - x_a) (>= 0 outside the target body)
    double distance = 0.0; ///< Euclidean distance from x to the (closed) segment
};

/// Projects x on the segment [xa, xb]: alpha = clamp((x - xa).d / |d|^2, 0, 1), n = (d_y, -d_x)
/// / |d|, g0 = n . (x - xa), distance = |x - (xa + alpha d)|. Throws InvalidInput for a facet of
/// zero length.
FacetProjection project_on_facet(const Vec2& x, const Vec2& xa, const Vec2& xb);

/// Spatial index over a set of facets: a mesh::PointSearch on the facet midpoints (a CGAL Kd-tree,
/// or a linear scan when the build has no CGAL). Holds copies of the end points; `vertices` need
/// not outlive it.
class FacetIndex {
public:
    /// Throws InvalidInput for an empty facet list, an index out of range or a facet of zero
    /// length.
    FacetIndex(const std::vector<Vec2>& vertices, std::vector<Facet> facets);
    ~FacetIndex();
    FacetIndex(FacetIndex&&) noexcept;
    FacetIndex& operator=(FacetIndex&&) noexcept;

    /// The facet closest to x (smallest distance to the segment) among those within `radius`,
    /// skipping facets that have vertex `skip` as an end (a contactor vertex on the target
    /// boundary itself); nullopt when there is none, or when x lies beyond an end of the whole
    /// target boundary (the closest point is a facet end that no other facet shares, and the
    /// unclamped projection passes it by more than a relative 1e-9 of the facet length: x is
    /// over no facet). A projection clamped at a vertex shared by two facets (a corner of the
    /// target) is kept. Ties (a projection on a shared vertex) go to the facet on which the
    /// unclamped projection falls inside, then to the lower index. Exact: every facet within
    /// `radius` has its midpoint within radius + half the longest facet of x, and only those
    /// are examined.
    std::optional<FacetProjection> closest(const Vec2& x, double radius, int skip = -1) const;
    /// Indices (ascending) of the facets whose distance to x is at most `radius`.
    std::vector<int> within(const Vec2& x, double radius) const;
    /// End points of facet i.
    const std::array<Vec2, 2>& ends(int i) const;
    /// Length of the facet whose midpoint is nearest to x: the local target mesh size.
    double local_size(const Vec2& x) const;
    const std::vector<Facet>& facets() const;
    /// Length of the longest facet.
    double max_length() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// What a search found for one contact pair.
struct SearchResult {
    std::vector<ContactElement> elements; ///< one per contactor node that found a target
    std::vector<int> not_found;           ///< contactor vertices that found none (left out)
};

/// Node-on-facet search (docs/theory.md#theory-contact-elements). A contactor vertex c of `m` is a contact node when
/// `reference` has a facet within search_radius * h0(c) of it, h0(c) = `reference.local_size`,
/// and c is not beyond the ends of the reference target (FacetIndex::closest). Pass the level-0
/// target facets as `reference` (vertex indices of level 0 are kept by refinement): the decision
/// is then the same on every level and the contact nodes nest under refinement, even on a
/// curved target whose polygon moves. The element uses the closest facet of `m` tagged
/// `target_tag`: weights (1, -(1-alpha), -alpha), the facet normal toward the contactor,
/// t = (n_y, -n_x) and g0 = the signed distance of c to the facet line. Contactor vertices that
/// are not contact nodes are listed in `not_found`, in input order.
///
/// With `integration` = FacetIntegration::segment or dual (then `contactor_tag`, the tag of the
/// contactor boundary edges, is required) the contact nodes, n, t and g0 are the same, but the
/// weights are segment-integrated (mortar-type, lumped; El-Abbasi & Bathe 2001): N_i the hat
/// function of contactor node c on the contactor boundary (its support: the edges tagged
/// `contactor_tag` at c) and N_k those of the target vertices on the target facets,
///   D_i = int N_i ds,  M_ik = int N_i N_k ds   (ds along the contactor),
/// integrated over the pieces where a contactor edge, projected orthogonally on a target facet's
/// line, overlaps that facet (2-point Gauss per piece: exact, the integrands are quadratic).
/// Facets count when they lie within the node's search distance of the piece and face the same
/// way as the node's facet (n_f . n > 0). Weights (1, -M_ik / D_i^cov) with D_i^cov the part
/// of D_i that is covered (the sum over the pieces): they sum to 0 exactly, so rigid
/// translations give no gap. D_i^cov = D_i when the support of N_i projects entirely onto the
/// target; at an end of the target boundary (or at a convex corner of it) only the covered part
/// counts, i.e. the weights are renormalised by it. A node whose support covers nothing (a
/// degenerate case) keeps the nodal weights. With uniform pressure p the multipliers
/// lambda_i = p D_i pass to the target vertex k as sum_i lambda_i M_ik / D_i = p int N_k ds:
/// the consistent load, so the contact patch test is passed exactly.
/// FacetIntegration::dual uses psi_i = 3 N_i - 1 on each contactor edge in place of N_i in M_ik
/// (biorthogonal: int psi_i N_j = delta_ij D_i; Wohlmuth 2000), so that the weights are (1, -1)
/// on a matching interface and the contactor is not smoothed by the target (segment's lumped
/// weights are, which makes tractions oscillate on similar meshes); sum psi_i = 1 keeps the
/// patch test exact. A node whose support is only partly over the target keeps N_i (segment).
/// Throws InvalidInput when the mesh has no facet tagged `target_tag`, or (segment, dual) when
/// `contactor_tag` is missing.
SearchResult node_on_facet_search(const mesh::Mesh& m, const std::vector<int>& contactors,
                                  int target_tag, const FacetIndex& reference, double search_radius,
                                  double mu, double r, int pair,
                                  FacetIntegration integration = FacetIntegration::nodal,
                                  int contactor_tag = -1);

/// Node-on-node search for matching interfaces: for each contactor vertex c, the target vertex
/// (an end of a facet tagged `target_tag`) nearest to c, accepted when within
/// match_tolerance * h, h the mean length of the target facets at that vertex. The normal is
/// the normalized sum of the outward unit normals of those facets (their average direction),
/// g0 = n . (x_c - x_a). Unmatched contactor vertices are listed in `not_found`.
/// Throws InvalidInput when the mesh has no facet tagged `target_tag`.
SearchResult node_on_node_search(const mesh::Mesh& m, const std::vector<int>& contactors,
                                 int target_tag, double match_tolerance, double mu, double r,
                                 int pair);

} // namespace mlc::contact
