// SPDX-License-Identifier: MIT
/// @file P1 triangle mesh with tagged boundary edges, uniform 1->4 refinement and quality checks.
#pragma once

#include "core/types.hpp"

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace mlc::mesh {

/// Exact geometry a boundary edge lies on, so that refinement can put new vertices on it.
/// Only circles are needed (straight edges need nothing).
struct Circle {
    Vec2 center = Vec2::Zero();
    double radius = 0.0;
};

/// One boundary edge (v0, v1) of a triangle, oriented counter-clockwise around its body
/// (the domain lies to the left of v0 -> v1).
struct BoundaryEdge {
    int v0 = -1;
    int v1 = -1;
    int tag = 0;    ///< boundary tag id; names in Mesh::tag_names
    int curve = -1; ///< index into Mesh::circles, or -1 for a straight edge
};

/// A 2D triangle mesh of one body.
///
/// Triangles are counter-clockwise (positive signed area). Boundary edges carry an integer tag
/// and, optionally, the circle they lie on. A mesh made by `refine` keeps the coarse vertices
/// with their indices (0 .. n_coarse-1) and appends one vertex per coarse edge; `parents`
/// records the two coarse vertices of each new one, which is all the interpolation P needs.
struct Mesh {
    std::vector<Vec2> vertices;
    std::vector<std::array<int, 3>> triangles;
    /// Per-triangle body (or material) id, inherited by refinement; empty means all 0.
    std::vector<int> attribute;
    std::vector<BoundaryEdge> boundary;
    /// Tagged interior edges ("lines": constrained interior segments of a domain, physical lines
    /// of a Gmsh file inside the body, the mirror line of mirror_about_x). Both ends are vertices
    /// of the mesh and the edge is an edge of two triangles; the orientation means nothing and
    /// `curve` is -1. Refinement splits them like boundary edges (the halves keep the tag), so
    /// the vertices it creates on a tagged line carry the tag. Supports may name their tags;
    /// loads and contact pairs need boundary tags.
    std::vector<BoundaryEdge> lines;
    std::vector<Circle> circles;
    std::map<std::string, int> tag_names; ///< name -> tag id
    /// For a refined mesh: parents[v - n_coarse] = the two coarse vertices of new vertex v.
    /// Empty for a level-0 mesh.
    std::vector<std::array<int, 2>> parents;
    /// Number of vertices of the mesh this one was refined from (0 for a level-0 mesh).
    int n_coarse_vertices = 0;

    int n_vertices() const { return static_cast<int>(vertices.size()); }
    int n_triangles() const { return static_cast<int>(triangles.size()); }

    /// Tag id of a name; throws InvalidInput naming the known tags if absent.
    int tag(const std::string& name) const;
    /// Tag id of a name, or nullopt.
    std::optional<int> find_tag(const std::string& name) const;
    /// Name of a tag id ("tag <id>" if unnamed).
    std::string tag_name(int tag) const;
    /// Registers a name (returns the existing id if already present).
    int add_tag(const std::string& name);

    /// Signed area of triangle t (positive when counter-clockwise).
    double signed_area(int t) const;
    /// Vertices on boundary edges carrying `tag`, sorted and unique.
    std::vector<int> vertices_with_tag(int tag) const;
    /// Vertices on boundary edges or interior lines carrying `tag`, sorted and unique (what a
    /// support on the tag holds).
    std::vector<int> vertices_on_tag(int tag) const;
    /// Whether some boundary edge carries `tag` (a tag only on interior lines does not).
    bool is_boundary_tag(int tag) const;
    /// Smallest and largest edge length.
    std::pair<double, double> edge_length_range() const;
    /// Diameter of the bounding box (the mesh's length scale).
    double diameter() const;
    /// Index of the vertex nearest to p.
    int nearest_vertex(const Vec2& p) const;
};

/// Checks a mesh for use: at least one triangle, indices in range, every triangle with positive
/// area (relative to the square of the mesh diameter), no two vertices of one body (attribute)
/// closer than 1e-10 of the diameter (two touching bodies' may coincide), no duplicated element,
/// edge of over two triangles or hanging node (check_topology, mesh/topology.hpp), boundary edges
/// of one triangle, interior lines of two. Throws InvalidInput naming the first defect (indices).
void check_quality(const Mesh& m);

/// The part of check_quality a refinement of a checked mesh still needs: every triangle with
/// positive area (a midpoint moved onto a circular boundary can fold a thin triangle). Its
/// vertices are distinct and its boundary edges are halves of checked ones by construction.
void check_refined_quality(const Mesh& m);

/// Uniform refinement: every triangle split into four by its edge midpoints. Boundary edges and
/// interior lines are split in two with the tag and curve inherited; a midpoint on a circular
/// boundary edge is moved onto the circle. Coarse vertex indices are kept; `parents` is filled.
Mesh refine(const Mesh& coarse);

/// The triangles of every vertex (CSR): those of vertex v are triangles[offset[v] ..
/// offset[v + 1]), in ascending triangle order.
struct VertexTriangles {
    std::vector<int> offset;    ///< n_vertices + 1 entries
    std::vector<int> triangles; ///< 3 n_triangles entries
    /// The triangles of m with the edge (a, b): how many, and the first two in triangle order
    /// (-1 where there are fewer). None for a == b or a vertex out of range.
    struct OnEdge {
        int count = 0;
        std::array<int, 2> first{-1, -1};
    };
    OnEdge on_edge(const Mesh& m, int a, int b) const;
};
/// The VertexTriangles of m (its triangles' indices must lie in [0, n_vertices)).
VertexTriangles vertex_triangles(const Mesh& m);

/// The inverse of `refine`, when `fine` is a uniform 1->4 refinement (what Gmsh's `RefineMesh`
/// and `gmsh -refine`, or `mlcontact show --msh-level`, write): the coarse mesh c with
/// refine(c) = fine up to the vertex numbering (every vertex of refine(c) within `tol` of its
/// vertex of `fine`; the same triangles, boundary halves and interior-line halves, with their
/// tags, curves and attributes). Found from the topology alone (the middle child of each coarse
/// triangle has three midpoints; the children around it have one coarse vertex each), then
/// checked by refining. nullopt when `fine` is not such a refinement. The coarse vertices keep
/// the order of their indices in `fine`; `parents` is empty.
std::optional<Mesh> unrefine(const Mesh& fine, double tol);

/// The vertices in the order of a Hilbert curve through their bounding box (2^16 cells a side;
/// ties keep index order): neighbours in the mesh get nearby positions, so vectors indexed in
/// this order are read with few cache misses by the sparse mat-vecs and sweeps of a level.
/// Returns a permutation of 0..n-1 (position -> vertex).
std::vector<int> hilbert_order(const std::vector<Vec2>& points);

/// How a structured rectangle's squares are cut into two triangles.
enum class Diagonal {
    right,    ///< "/" from lower-left to upper-right in every square
    left,     ///< "\" from lower-right to upper-left
    alternate ///< union-jack style alternation
};

/// Structured mesh of [x0, x0+lx] x [y0, y0+ly] with nx x ny squares cut along one diagonal.
/// Boundary tags "bottom", "right", "top", "left". Vertex (i, j) has index j*(nx+1) + i.
Mesh structured_rectangle(Vec2 corner, Vec2 size, int nx, int ny,
                          Diagonal diagonal = Diagonal::right);

} // namespace mlc::mesh
