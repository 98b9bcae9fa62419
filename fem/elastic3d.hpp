// SPDX-License-Identifier: MIT
/// @file P1 elasticity on tetrahedral meshes: supports (faces, lines, points; any subset of
/// ux, uy, uz), surface and body loads, the assembly of the stiffness on the free unknowns of a
/// DofMap3 (3 x 3 vertex blocks, unknowns interleaved x, y, z per vertex) and stress recovery.
/// The 3D counterpart of fem/assembly.hpp, on the kernels of fem/simplex.hpp. Full nodal vectors
/// (loads, displacements, internal forces) hold 3 values per vertex, interleaved.
#pragma once

#include "core/types.hpp"
#include "fem/assembly.hpp"
#include "fem/dof_map.hpp"
#include "fem/elasticity.hpp"
#include "mesh/tet_mesh.hpp"

#include <array>
#include <functional>
#include <vector>

namespace mlc::fem {

using mesh::Vec3;

/// Which displacement components (ux, uy, uz) a support holds.
using Components3 = std::array<bool, 3>;

/// Prescribed displacement `value` on the components `components` of each listed vertex. A face
/// support lists face_vertices, a line support line_vertices or segment_vertices, a point
/// support one vertex (e.g. TetMesh::nearest_vertex).
struct VertexSupport {
    std::vector<int> vertices;
    Components3 components{true, true, true};
    Vec3 value = Vec3::Zero();
};

/// The fixed flags and prescribed values of a list of supports, ready for DofMap3 and
/// assemble_elastic.
struct Supports3 {
    std::vector<Components3> fixed; ///< per vertex: the components held
    Vector u_fixed;                 ///< 3 per vertex: the prescribed values (0 where free)
};

/// Combines supports: a component is fixed if some support holds it; where several hold the same
/// component, the last one's value counts. Throws InvalidInput naming a vertex out of range.
Supports3 collect_supports(const mesh::TetMesh& m, const std::vector<VertexSupport>& supports);

/// Vertices of the boundary faces tagged `tag`, sorted. Throws InvalidInput when no boundary face
/// carries the tag (naming it and the boundary tags there are).
std::vector<int> face_vertices(const mesh::TetMesh& m, int tag);

/// Vertices on faces of both tags (the line where two tagged surfaces meet, e.g. a box's edge),
/// sorted. Throws as face_vertices for an unknown tag.
std::vector<int> line_vertices(const mesh::TetMesh& m, int tag_a, int tag_b);

/// Vertices within `tol` of the segment a-b, sorted (a line support away from tags). Throws
/// InvalidInput when tol is negative or the segment's ends are not finite.
std::vector<int> segment_vertices(const mesh::TetMesh& m, const Vec3& a, const Vec3& b, double tol);

/// Uniform traction on the boundary faces with one tag, per unit area: a pressure (normal,
/// positive pushing into the body: t = -p n_out) plus a constant vector.
struct Traction3 {
    int tag = 0;
    double pressure = 0.0;
    Vec3 vector = Vec3::Zero();
};

/// Consistent P1 nodal loads (3 per vertex): a face with constant traction gives each of its
/// vertices a third of the face's resultant, a constant body force b a quarter of |V| b to each
/// vertex of a tetrahedron.
/// @param body_force per tetrahedron attribute (may be empty: none)
/// Throws InvalidInput for a traction whose tag no boundary face carries and for an attribute
/// without a body force.
Vector nodal_loads(const mesh::TetMesh& m, const std::vector<Traction3>& tractions,
                   const std::vector<Vec3>& body_force);

/// Consistent nodal loads of a body force given as a function of the position, integrated by a
/// 4-point rule of degree 2 per tetrahedron (manufactured solutions).
Vector body_force_loads(const mesh::TetMesh& m, const std::function<Vec3(const Vec3&)>& b);

/// Assembles K on the free unknowns of `dofs` (rows and columns of its extra unknowns stay
/// empty) and f = F_free - K_(free,fixed) u_fixed, where F = nodal_load_full (3 per vertex) and
/// u_fixed the prescribed displacements (3 per vertex, read where fixed). Materials by
/// tetrahedron attribute (Material::plane must stay plane strain, the default: plane stress is a
/// 2D reduction). Either orientation of a tetrahedron is accepted. Throws InvalidInput for an
/// attribute without a material, a bad material and sizes that disagree.
ElasticSystem assemble_elastic(const mesh::TetMesh& m, const std::vector<Material>& materials,
                               const DofMap3& dofs, const Vector& nodal_load_full,
                               const Vector& u_fixed);

/// Internal force K_full u_full on every vertex component (3 per vertex), for reactions.
Vector internal_forces(const mesh::TetMesh& m, const std::vector<Material>& materials,
                       const Vector& u_full);

/// Constant stress per tetrahedron, 6 values (sxx, syy, szz, sxy, syz, sxz) per tetrahedron.
std::vector<double> tetrahedron_stresses(const mesh::TetMesh& m,
                                         const std::vector<Material>& materials,
                                         const Vector& u_full);

} // namespace mlc::fem
