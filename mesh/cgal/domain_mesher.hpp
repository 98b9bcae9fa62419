// SPDX-License-Identifier: MIT
/// @file Quality triangle meshes of domains bounded by line and circular-arc loops (CGAL Mesh_2).
#pragma once

#include "mesh/mesh.hpp"

#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

namespace mlc::mesh {

/// One piece of a boundary loop: a straight line or a circular arc from `from` to `to`.
///
/// For an arc, `from` and `to` must lie on the circle (center, radius) to a relative 1e-6 of the
/// radius; the mesher snaps them onto it exactly. The arc runs counter-clockwise about `center`
/// when `ccw` is true, clockwise otherwise. An arc whose `from` equals `to` is a full circle and
/// must then be the only segment of its loop. `tag` names the boundary edges made from the
/// segment (Mesh::tag_names); an empty tag means "boundary".
struct Segment {
    enum class Kind { line, arc };
    Kind kind = Kind::line;     ///< straight line or circular arc
    Vec2 from = Vec2::Zero();   ///< start point (end point of the previous segment)
    Vec2 to = Vec2::Zero();     ///< end point (start point of the next segment)
    Vec2 center = Vec2::Zero(); ///< arc only: center of the circle
    double radius = 0;          ///< arc only: radius of the circle, > 0
    bool ccw = true;            ///< arc only: counter-clockwise about `center` from `from` to `to`
    std::string tag = {};       ///< boundary tag name of the edges made from this segment

    /// A straight segment from -> to.
    static Segment line(const Vec2& from, const Vec2& to, std::string tag);
    /// An arc about `center` from -> to with radius |from - center|.
    static Segment arc(const Vec2& from, const Vec2& to, const Vec2& center, bool ccw,
                       std::string tag);
};

/// Target edge length of the mesh, refined towards focus points.
///
/// h(x) = min(max_size, min_size + grading * min_i |x - focus_i|), and h = max_size when there is
/// no focus point. Lengths are in the units of the geometry.
struct SizeField {
    /// Largest edge length anywhere (> 0). Sets the mesh size away from the focus points.
    double max_size = 0;
    /// Edge length at a focus point, 0 < min_size <= max_size; 0 means "= max_size" (uniform).
    double min_size = 0;
    /// Points the mesh is refined towards (contact zones, corners, load points).
    std::vector<Vec2> focus = {};
    /// Growth of h per unit distance from the focus (> 0). 0.25 keeps neighbouring triangles
    /// within about 25% of each other's size, which the Delaunay mesher meets without extra
    /// vertices; larger values give fewer triangles and a faster transition.
    double grading = 0.25;

    /// Throws InvalidInput naming the field and its value if a field is out of range.
    void validate() const;
    /// h(x) as defined above (brute force over the focus points: O(focus.size())).
    double operator()(const Vec2& x) const;
};

/// Prints every field of a SizeField on one line.
std::ostream& operator<<(std::ostream& os, const SizeField& size);

/// Polled by mesh_domain while it refines (every few thousand inserted points, a few
/// milliseconds apart): returns true to stop, and mesh_domain then throws mlc::Interrupted. It may
/// also throw itself. The library sets no signal handlers: a driver passes its stop flag here.
using StopPoll = std::function<bool()>;

/// What mesh_domain is predicted to make, from the domain and the size field alone (nothing is
/// meshed).
struct MeshPrediction {
    double area = 0;      ///< area of the domain: outer loop less holes (arcs as arcs)
    double integral = 0;  ///< upper bound of the integral of 1 / h(x)^2 over the domain
    double triangles = 0; ///< kTrianglesPerUnitIntegral * integral
};

/// Triangles mesh_domain makes per unit of the integral of 1 / h^2 over the domain (its
/// triangles have their longest edge <= h and angles >= 20.7 degrees): set a little above the
/// count per unit integral of the hertz scene's domain and of uniform and graded squares, quarter
/// discs and discs (tests/mesh/test_mesh_prediction.cpp), so that the prediction is at or just
/// above the count. Parts of a domain narrower than h get more triangles than predicted (the
/// angle bound makes them smaller than h there).
inline constexpr double kTrianglesPerUnitIntegral = 6.0;

/// Predicts the size of mesh_domain(loops, size) before meshing, without meshing:
/// triangles = kTrianglesPerUnitIntegral * I, I the integral of 1 / h^2 over the domain of area A,
/// taken as A / M^2 plus, for each focus point, the integral of 1 / h_f^2 - 1 / M^2 over the
/// part of its disc r < (M - m) / g inside the domain (h_f = m + g r; M = max_size, m = min_size,
/// g = grading; 32 rings of 32 points each), and at most A / m^2 (h >= m). Overlapping focus
/// discs are counted each: an upper bound there. Throws InvalidInput for the geometry
/// mesh_domain refuses (as it would).
MeshPrediction predict_mesh_size(const std::vector<std::vector<Segment>>& loops,
                                 const SizeField& size);

/// Meshes a 2D domain with quality triangles (CGAL constrained Delaunay mesher).
///
/// `loops[0]` is the outer boundary, counter-clockwise; each further loop bounds a hole (either
/// orientation) lying strictly inside the outer loop. Consecutive segments of a loop must join
/// (`to` of one equals `from` of the next to a relative 1e-9 of the domain diameter) and each loop
/// closes. Loops may not cross or touch each other or themselves.
///
/// Every segment is split with spacing following h along it (arcs additionally into pieces of at
/// most 15 degrees, with every point exactly on the circle), then the interior is refined until
/// every triangle has its longest edge <= h(centroid) and its smallest angle >= 20.7 degrees
/// (CGAL shape bound 0.125 on the squared sine). The mesher may split boundary edges; new
/// vertices on arcs are put on the circle, so every boundary vertex of an arc lies on its circle
/// to round-off. The polygonal domain differs from the curved one by the arc sagitta
/// (about h^2 / (8 r) per edge).
///
/// Output: CCW triangles; boundary edges oriented counter-clockwise around the body (domain on the
/// left), tagged with their segment's tag (registered in input order) and, for arcs, `curve` =
/// index into `circles` (one Circle per distinct center and radius). Vertices are in Hilbert-curve
/// order. Throws InvalidInput for bad geometry or sizes, naming the loop and segment; calls
/// check_quality on the result. Runs at about 10^5 triangles per second or faster.
///
/// `lines`: constrained interior segments (straight; `from`, `to`, `tag`, default tag "line"),
/// split along h like the loop segments and kept as edges of the triangulation: their edges are
/// the tagged interior lines of the result (Mesh::lines). Each must lie inside the domain; its
/// ends may be inside or at a loop segment's end, and lines may meet at their ends only
/// (InvalidInput naming the line otherwise).
///
/// The refinement runs one CGAL step at a time (Delaunay_mesher_2::try_one_step_refine_mesh, the
/// same sequence of insertions as refine_mesh), polling `stop` between steps: a true answer
/// throws mlc::Interrupted.
Mesh mesh_domain(const std::vector<std::vector<Segment>>& loops, const SizeField& size,
                 const std::vector<Segment>& lines = {}, const StopPoll& stop = {});

} // namespace mlc::mesh
