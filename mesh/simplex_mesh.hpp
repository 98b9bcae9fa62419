// SPDX-License-Identifier: MIT
/// @file The simplex mesh of one or several bodies in `dim` dimensions (triangles in 2D,
/// tetrahedra in 3D): vertices, cells, tagged boundary facets, tagged lines, the exact shapes
/// curved boundaries lie on, and what a refinement records (parents). One template for both
/// dimensions, with the dimension-specific parts (the facet type and the curved shapes) chosen
/// by SimplexTraits; the algorithms that differ by dimension (refinement 1->4 or 1->8, the
/// quality checks, the structured meshes) are overloads on SimplexMesh<2> (mesh/mesh.hpp) and
/// SimplexMesh<3> (mesh/tet_mesh.hpp).
#pragma once

#include "core/types.hpp"

#include <array>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mlc::mesh {

/// A 3D point or vector.
using Vec3 = Eigen::Vector3d;

/// Exact geometry a 2D boundary edge lies on, so that refinement can put new vertices on it.
/// Only circles are needed (straight edges need nothing).
struct Circle {
    Vec2 center = Vec2::Zero();
    double radius = 0.0;
};

/// Exact geometry 3D boundary faces lie on, so that refinement can put new vertices on it (the 3D
/// counterpart of Circle): a sphere, or a circular cylinder of infinite length.
struct CurvedSurface {
    enum class Kind { sphere, cylinder };
    Kind kind = Kind::sphere;
    Vec3 center = Vec3::Zero(); ///< the sphere's centre, or a point of the cylinder's axis
    Vec3 axis = Vec3::UnitZ();  ///< the cylinder's axis direction (unit length); sphere: unused
    double radius = 0.0;

    /// The point of the surface nearest to p (radially from the centre or the axis); nullopt for
    /// p at the centre or on the axis.
    std::optional<Vec3> project(const Vec3& p) const;
    /// Distance of p from the surface.
    double distance(const Vec3& p) const;
    /// "sphere (center (x, y, z), radius r)" or "cylinder (axis through (..) along (..),
    /// radius r)".
    std::string describe() const;
};

/// One boundary edge (v0, v1) of a triangle, oriented counter-clockwise around its body
/// (the domain lies to the left of v0 -> v1); in 3D, a tagged edge (a line).
struct BoundaryEdge {
    int v0 = -1;
    int v1 = -1;
    int tag = 0;    ///< tag id; names in SimplexMesh::tag_names
    int shape = -1; ///< index into SimplexMesh<2>::shapes (a circle), or -1 for a straight edge
    /// The two vertices.
    std::array<int, 2> vertices() const { return {v0, v1}; }
};

/// One boundary face (v[0], v[1], v[2]) of a tetrahedron, oriented so that its normal
/// (v1 - v0) x (v2 - v0) points out of the body.
struct BoundaryFace {
    std::array<int, 3> v{-1, -1, -1};
    int tag = 0;    ///< boundary tag id; names in SimplexMesh::tag_names
    int shape = -1; ///< index into SimplexMesh<3>::shapes (a curved surface), or -1 for flat
    /// The three vertices.
    const std::array<int, 3>& vertices() const { return v; }
};

/// What differs between the dimensions in a mesh's data: the boundary facet and the exact shape
/// a curved facet lies on.
template <int dim> struct SimplexTraits;
/// Triangles: boundary edges, circles.
template <> struct SimplexTraits<2> {
    using Facet = BoundaryEdge;
    using Shape = Circle;
    static constexpr std::string_view cell_name = "triangle";
};
/// Tetrahedra: boundary faces, spheres and cylinders.
template <> struct SimplexTraits<3> {
    using Facet = BoundaryFace;
    using Shape = CurvedSurface;
    static constexpr std::string_view cell_name = "tetrahedron";
};

/// A `dim`-dimensional simplex mesh (dim = 2: triangles, 3: tetrahedra) of one or several
/// bodies; `Mesh` and `TetMesh` name the two.
///
/// Cells: in 2D counter-clockwise (positive signed_measure); in 3D either orientation (Bey's
/// refinement, mesh/tet_refine.hpp, keeps the vertex order it depends on, and mirrors some
/// children; code that needs the orientation takes the sign of signed_measure).
///
/// Boundary facets carry an integer tag and, optionally, the curved shape they lie on. Lines are
/// tagged edges that are not boundary facets (2D: interior edges of two triangles; the mirror line
/// of mirror_about_x, physical lines of a Gmsh file inside the body): refinement splits them like
/// boundary facets and the halves keep the tag, so supports may name their tags.
///
/// A mesh made by `refine` keeps the coarse vertices with their indices (0 .. n_coarse - 1) and
/// appends one vertex per coarse edge; `parents` records the two coarse vertices of each new
/// one, which is all the interpolation P needs.
template <int dim> struct SimplexMesh {
    static_assert(dim == 2 || dim == 3, "SimplexMesh: dim is 2 or 3");
    static constexpr int dimension = dim;
    using Point = Eigen::Matrix<double, dim, 1>; ///< Vec2 or Vec3
    using Cell = std::array<int, dim + 1>;
    using Facet = typename SimplexTraits<dim>::Facet;
    using Shape = typename SimplexTraits<dim>::Shape;

    std::vector<Point> vertices;
    std::vector<Cell> cells;
    /// Per-cell body (or material) id, inherited by refinement; empty means all 0.
    std::vector<int> attribute;
    /// Tagged boundary facets (2D: every boundary edge; 3D: untagged faces need not be listed).
    std::vector<Facet> boundary;
    /// Tagged edges that are no boundary facets (see above); `shape` is -1.
    std::vector<BoundaryEdge> lines;
    /// The exact shapes curved boundary facets lie on (Facet::shape).
    std::vector<Shape> shapes;
    std::map<std::string, int> tag_names; ///< name -> tag id
    /// For a refined mesh: parents[v - n_coarse_vertices] = the two coarse vertices of new
    /// vertex v. Empty for a level-0 mesh.
    std::vector<std::array<int, 2>> parents;
    /// Number of vertices of the mesh this one was refined from (0 for a level-0 mesh).
    int n_coarse_vertices = 0;

    int n_vertices() const { return static_cast<int>(vertices.size()); }
    int n_cells() const { return static_cast<int>(cells.size()); }

    /// Tag id of a name; throws InvalidInput naming the known tags if absent.
    int tag(const std::string& name) const;
    /// Tag id of a name, or nullopt.
    std::optional<int> find_tag(const std::string& name) const;
    /// Name of a tag id ("tag <id>" if unnamed).
    std::string tag_name(int tag) const;
    /// Registers a name (returns the existing id if already present).
    int add_tag(const std::string& name);

    /// Signed measure of cell c: the area of a triangle (positive when counter-clockwise), the
    /// volume det(x1 - x0, x2 - x0, x3 - x0) / 6 of a tetrahedron.
    double signed_measure(int c) const;
    /// Vertices on boundary facets carrying `tag`, sorted and unique.
    std::vector<int> vertices_with_tag(int tag) const;
    /// Vertices on boundary facets or lines carrying `tag`, sorted and unique (what a support on
    /// the tag holds).
    std::vector<int> vertices_on_tag(int tag) const;
    /// Whether some boundary facet carries `tag` (a tag only on lines does not).
    bool is_boundary_tag(int tag) const;
    /// Smallest and largest edge length.
    std::pair<double, double> edge_length_range() const;
    /// Diameter of the bounding box (the mesh's length scale).
    double diameter() const;
    /// Index of the vertex nearest to p (the first of equals).
    int nearest_vertex(const Point& p) const;
};

extern template struct SimplexMesh<2>;
extern template struct SimplexMesh<3>;

/// The cells of every vertex (CSR): those of vertex v are cells[offset[v] .. offset[v + 1]), in
/// ascending cell order.
struct VertexCells {
    std::vector<int> offset; ///< n_vertices + 1 entries
    std::vector<int> cells;  ///< (dim + 1) n_cells entries
};
/// The VertexCells of m. Throws InvalidInput for a cell vertex out of range.
template <int dim> VertexCells vertex_cells(const SimplexMesh<dim>& m);
extern template VertexCells vertex_cells(const SimplexMesh<2>&);
extern template VertexCells vertex_cells(const SimplexMesh<3>&);

/// The 2D mesh (triangles); its algorithms are in mesh/mesh.hpp.
using Mesh = SimplexMesh<2>;
/// The 3D mesh (tetrahedra); its algorithms are in mesh/tet_mesh.hpp.
using TetMesh = SimplexMesh<3>;

} // namespace mlc::mesh
