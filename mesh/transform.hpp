// SPDX-License-Identifier: MIT
/// @file Whole-mesh transformations used to build a scene's level-0 mesh: a half domain mirrored
/// about a vertical line, and the meshes of several bodies merged into one.
#pragma once

#include "mesh/mesh.hpp"

namespace mlc::mesh {

/// The mesh of a half domain reflected about the vertical line x = x0 and glued to itself.
///
/// Every vertex of `half` must lie on one side of the line or on it (within a relative 1e-10 of
/// the mesh diameter), and at least one must lie on it. The result keeps the vertices, triangles,
/// attributes and circles of `half` with their indices and appends the mirror images:
///  - a vertex v off the line gets an image at (2 x0 - x_v, y_v), appended in vertex order;
///    vertices on the line are shared (they are their own image);
///  - each triangle (a, b, c) gets an image (a', c', b') (reversed, so still counter-clockwise),
///    with the same attribute;
///  - each circle gets a mirrored circle (center reflected, same radius), appended after them;
///  - each boundary edge (v0, v1) is kept and followed by its image (v1', v0') (reversed, so the
///    body still lies to its left) with the same tag and the mirrored circle, except straight
///    edges with both ends on the line: those become interior lines (Mesh::lines) with their
///    tag, so that the mirror line can carry a support (and refinement keeps it tagged);
///  - each interior line is kept and followed by its image (lines on the mirror line once).
/// An exactly mirror-symmetric mesh gives an exactly mirror-symmetric discrete problem.
/// The result passes check_quality (it is called). Throws InvalidInput when `half` has vertices
/// on both sides of the line or none on it, or when the result fails check_quality.
Mesh mirror_about_x(const Mesh& half, double x0);

/// A rigid motion of a mesh: a rotation by `rotate_deg` degrees (counter-clockwise) about the
/// point `about`, then a translation by `translate`. Vertices and circle centres move; triangles
/// stay counter-clockwise and tags, lines and curves are kept. Multiples of 90 degrees use the
/// exact sine and cosine (0, 1, -1), so that a mirror-symmetric mesh stays exactly symmetric.
struct RigidMotion {
    double rotate_deg = 0.0;
    Vec2 about = Vec2::Zero();
    Vec2 translate = Vec2::Zero();
    /// The image of a point.
    Vec2 apply(const Vec2& p) const;
    /// The point whose image is p.
    Vec2 inverse(const Vec2& p) const;
    /// Whether the rotation is a multiple of 90 degrees (axes map onto axes).
    bool keeps_axes() const;
};

/// Applies a rigid motion to every vertex and circle centre of `m`.
void transform_mesh(Mesh& m, const RigidMotion& motion);

/// Appends mesh `b` to `all` as body number `body` (2D or 3D): b's vertices and shapes (circles,
/// curved surfaces) are appended, its cells, boundary facets and lines renumbered accordingly
/// (vertex indices shifted by the former vertex count of `all`, shape indices by its former
/// shape count), its tags merged by name (a name already in `all` keeps its id, a new one gets
/// the next free id), and every appended cell gets attribute `body` (b's own attributes are not
/// kept). `all` may be empty; its existing cells without an attribute get `body` too. Coincident
/// vertices of two bodies stay distinct. Nothing is checked.
template <int dim> void merge_into(SimplexMesh<dim>& all, const SimplexMesh<dim>& b, int body);
extern template void merge_into(SimplexMesh<2>&, const SimplexMesh<2>&, int);
extern template void merge_into(SimplexMesh<3>&, const SimplexMesh<3>&, int);

} // namespace mlc::mesh
