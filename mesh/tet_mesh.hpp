// SPDX-License-Identifier: MIT
/// @file P1 tetrahedral mesh with tagged boundary faces, the structured (Kuhn) box and the
/// quality checks. The 3D counterpart of mesh/mesh.hpp: TetMesh mirrors Mesh member by member
/// (tetrahedra for triangles, BoundaryFace for BoundaryEdge, signed_volume for signed_area,
/// structured_box for structured_rectangle), so that both can become one `Mesh<dim>` with the
/// dimension as a template parameter.
#pragma once

#include "core/types.hpp"

#include <Eigen/Geometry> // Vec3::cross

#include <array>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace mlc::mesh {

/// A 3D point or vector.
using Vec3 = Eigen::Vector3d;

/// Exact geometry boundary faces lie on, so that refinement can put new vertices on it (the 3D
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

/// One boundary face (v[0], v[1], v[2]) of a tetrahedron, oriented so that its normal
/// (v1 - v0) x (v2 - v0) points out of the body.
struct BoundaryFace {
    std::array<int, 3> v{-1, -1, -1};
    int tag = 0;      ///< boundary tag id; names in TetMesh::tag_names
    int surface = -1; ///< index into TetMesh::surfaces, or -1 for a flat face
};

/// A 3D tetrahedral mesh of one or several bodies.
///
/// Vertex order: a tetrahedron (x0, x1, x2, x3) may have either orientation (sign of
/// signed_volume). Bey's refinement (mesh/tet_refine.hpp) depends on the order of the four
/// vertices and keeps it in the children, some of which are mirrored; the box lists every
/// tetrahedron along its Kuhn path; the Gmsh reader keeps Gmsh's positive order. Code that
/// needs the orientation takes the sign of signed_volume.
///
/// A mesh made by `refine` keeps the coarse vertices with their indices (0 .. n_coarse - 1) and
/// appends one vertex per coarse edge; `parents` records the two coarse vertices of each new
/// one. The children of coarse tetrahedron t are the fine tetrahedra 8 t .. 8 t + 7 (Bey's
/// order), and the children of coarse boundary face f the fine faces 4 f .. 4 f + 3.
struct TetMesh {
    static constexpr int dim = 3;
    std::vector<Vec3> vertices;
    std::vector<std::array<int, 4>> tetrahedra;
    /// Per-tetrahedron body (or material) id, inherited by refinement; empty means all 0.
    std::vector<int> attribute;
    /// Tagged boundary faces (faces of one tetrahedron). Untagged boundary faces need not be
    /// listed.
    std::vector<BoundaryFace> boundary;
    /// Curved surfaces boundary faces lie on (BoundaryFace::surface; attach_surface).
    std::vector<CurvedSurface> surfaces;
    std::map<std::string, int> tag_names; ///< name -> tag id
    /// For a refined mesh: parents[v - n_coarse_vertices] = the two coarse vertices of new
    /// vertex v (the smaller index first). Empty for a level-0 mesh.
    std::vector<std::array<int, 2>> parents;
    /// Number of vertices of the mesh this one was refined from (0 for a level-0 mesh).
    int n_coarse_vertices = 0;

    int n_vertices() const { return static_cast<int>(vertices.size()); }
    int n_tetrahedra() const { return static_cast<int>(tetrahedra.size()); }

    /// Tag id of a name; throws InvalidInput naming the known tags if absent.
    int tag(const std::string& name) const;
    /// Tag id of a name, or nullopt.
    std::optional<int> find_tag(const std::string& name) const;
    /// Name of a tag id ("tag <id>" if unnamed).
    std::string tag_name(int tag) const;
    /// Registers a name (returns the existing id if already present).
    int add_tag(const std::string& name);

    /// Signed volume of tetrahedron t: det(x1 - x0, x2 - x0, x3 - x0) / 6.
    double signed_volume(int t) const;
    /// Vertices on boundary faces carrying `tag`, sorted and unique.
    std::vector<int> vertices_with_tag(int tag) const;
    /// Whether some boundary face carries `tag`.
    bool is_boundary_tag(int tag) const;
    /// Smallest and largest edge length.
    std::pair<double, double> edge_length_range() const;
    /// Diameter of the bounding box (the mesh's length scale).
    double diameter() const;
    /// Index of the vertex nearest to p.
    int nearest_vertex(const Vec3& p) const;
};

/// Tolerance of attach_surface, relative to the surface's radius.
inline constexpr double kOnSurfaceTol = 1e-6;

/// Declares that the boundary faces tagged `tag` lie on `surface` (a cylinder's axis is
/// normalized), so that refinement moves the vertices it creates on them onto it. Throws
/// InvalidInput naming the tag when it is no boundary tag (listing those there are), the radius
/// is not positive or the axis zero, or a vertex of the tag lies farther than kOnSurfaceTol
/// times the radius off the surface (naming the vertex, its position and the distance).
void attach_surface(TetMesh& m, const std::string& tag, CurvedSurface surface);

/// How a message names tetrahedron t (e.g. its element and line in a file); empty:
/// "tetrahedron t".
using TetrahedronNamer = std::function<std::string(int)>;

/// Relative volume below which a tetrahedron is flat: 6 |V| / L^3 with L its longest edge (a
/// regular tetrahedron has 0.71, a Kuhn tetrahedron 0.19).
inline constexpr double kFlatTetrahedronTol = 1e-10;

/// Checks a tetrahedral mesh for use, and throws InvalidInput naming the first defect:
/// - no tetrahedra, an attribute list of the wrong size, a vertex not finite, an index out of
///   range;
/// - a flat tetrahedron (6 |V| / L^3 <= kFlatTetrahedronTol, L its longest edge);
/// - a duplicated element (two tetrahedra with the same four vertices);
/// - a face shared by more than two tetrahedra;
/// - an inverted tetrahedron: two tetrahedra on the same side of their common face (one is
///   folded over the other), whatever the vertex order;
/// - a non-manifold boundary: an edge on more than two boundary faces (parts touching along an
///   edge) or a vertex where separate sheets of the boundary meet (parts touching at a point);
/// - a BoundaryFace that is not a face of exactly one tetrahedron, or whose normal points into
///   the body, or whose surface is not in TetMesh::surfaces.
/// O(n log n) (sorting faces and edges). Tetrahedra are named by `name`.
void check_quality(const TetMesh& m, const TetrahedronNamer& name = {});

/// The part of check_quality a refinement of a checked mesh still needs: no flat tetrahedron.
/// Bey's children of a checked mesh are conforming and manifold by construction.
void check_refined_quality(const TetMesh& m);

/// The edges of a mesh: edges[e] = (a, b) with a < b, in the order of their first appearance
/// over the tetrahedra (local edges 01, 02, 03, 12, 13, 23), and tet_edges[t] the six edge
/// indices of tetrahedron t in that local order.
struct TetEdges {
    std::vector<std::array<int, 2>> edges;
    std::vector<std::array<int, 6>> tet_edges;
};
TetEdges tet_edges(const TetMesh& m);

/// Number of distinct faces (triangles) of the tetrahedra: interior faces once, boundary faces
/// once.
long long count_faces(const TetMesh& m);

/// Structured mesh of the box [x0, x0+lx] x [y0, y0+ly] x [z0, z0+lz] with nx x ny x nz cells,
/// each cut into six tetrahedra around its main diagonal from (x0, y0, z0) to the far corner
/// (the Kuhn/Freudenthal split), so that the faces of neighbouring cells match. Vertex
/// (i, j, k) has index (k (ny + 1) + j) (nx + 1) + i. The tetrahedra of a cell follow its
/// Kuhn paths (corner, +e_a, +e_a +e_b, far corner) for the permutations (a, b, c) of the axes
/// in lexicographic order; with cubic cells all are congruent. Boundary tags "xmin", "xmax",
/// "ymin", "ymax", "zmin", "zmax", each square face cut into two triangles along its diagonal
/// from its lowest to its highest corner.
TetMesh structured_box(Vec3 corner, Vec3 size, int nx, int ny, int nz);

} // namespace mlc::mesh
