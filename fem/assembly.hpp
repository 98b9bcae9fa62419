// SPDX-License-Identifier: MIT
/// @file P1 elasticity on simplex meshes, one code for both dimensions (dim = 2: triangles,
/// dim = 3: tetrahedra): supports (any subset of the components on listed vertices: tagged
/// facets, lines, points), tractions and body forces as consistent nodal loads, the assembly of
/// the stiffness on the free unknowns of a BasicDofMap<dim> (dim x dim vertex blocks, unknowns
/// interleaved per vertex) with the load of the prescribed displacements, internal forces and
/// stress recovery. Full nodal vectors (loads, displacements, internal forces) hold dim values per
/// vertex, interleaved. The element kernels are fem/simplex.hpp's (2D: fem/elasticity.hpp's, which
/// the 2D results were computed with, bit for bit).
#pragma once

#include "core/types.hpp"
#include "fem/dof_map.hpp"
#include "fem/elasticity.hpp"
#include "mesh/simplex_mesh.hpp"

#include <array>
#include <functional>
#include <type_traits>
#include <vector>

namespace mlc::fem {

using mesh::Vec3;

/// A point or vector of dim components.
template <int dim> using PointD = Eigen::Matrix<double, dim, 1>;

/// The same, where a function template takes the dimension from its mesh argument alone
/// (std::type_identity_t: braced lists and lambdas convert).
template <int dim> using PointArg = std::type_identity_t<PointD<dim>>;
template <class T> using NoDeduce = std::type_identity_t<T>;

/// Which displacement components (ux, uy (, uz)) a support holds.
template <int dim> using Components = std::array<bool, dim>;
using Components3 = Components<3>;

/// Prescribed displacement `value` on the components `components` of each listed vertex. A facet
/// support lists facet_vertices, a line support line_vertices or segment_vertices, a point
/// support one vertex (e.g. SimplexMesh::nearest_vertex).
template <int dim> struct BasicVertexSupport {
    std::vector<int> vertices;
    Components<dim> components = all_components();
    PointD<dim> value = PointD<dim>::Zero();
    static Components<dim> all_components() {
        Components<dim> c;
        c.fill(true);
        return c;
    }
};
using VertexSupport2 = BasicVertexSupport<2>;
using VertexSupport3 = BasicVertexSupport<3>;

/// The fixed flags and prescribed values of a list of supports, ready for BasicDofMap and
/// assemble_elastic.
template <int dim> struct BasicSupports {
    std::vector<Components<dim>> fixed; ///< per vertex: the components held
    Vector u_fixed;                     ///< dim per vertex: the prescribed values (0 where free)
};
using Supports3 = BasicSupports<3>;

/// Combines supports: a component is fixed if some support holds it; where several hold the same
/// component, the last one's value counts. Throws InvalidInput naming a vertex out of range or a
/// value that is not finite.
template <int dim>
BasicSupports<dim> collect_supports(const mesh::SimplexMesh<dim>& m,
                                    const NoDeduce<std::vector<BasicVertexSupport<dim>>>& supports);

/// Vertices of the boundary facets tagged `tag`, sorted. Throws InvalidInput when no boundary
/// facet carries the tag (naming it and the boundary tags there are).
template <int dim> std::vector<int> facet_vertices(const mesh::SimplexMesh<dim>& m, int tag);

/// Vertices on facets of both tags (where two tagged boundaries meet: a corner in 2D, a box's
/// edge in 3D), sorted. Throws as facet_vertices for an unknown tag.
template <int dim>
std::vector<int> line_vertices(const mesh::SimplexMesh<dim>& m, int tag_a, int tag_b);

/// Vertices within `tol` of the segment a-b, sorted (a line support away from tags). Throws
/// InvalidInput when tol is negative or the segment's ends are not finite.
template <int dim>
std::vector<int> segment_vertices(const mesh::SimplexMesh<dim>& m, const PointArg<dim>& a,
                                  const PointArg<dim>& b, double tol);

/// Uniform traction on the boundary facets with one tag, per unit length (2D) or area (3D): a
/// pressure (normal, positive pushing into the body: t = -p n_out) plus a constant vector.
template <int dim> struct BasicTraction {
    int tag = 0;
    double pressure = 0.0;
    PointD<dim> vector = PointD<dim>::Zero();
};
using Traction = BasicTraction<2>;
using Traction3 = BasicTraction<3>;

/// Consistent P1 nodal loads (dim per vertex): a facet with a constant traction gives each of its
/// dim vertices 1/dim of the facet's resultant, a constant body force b gives each vertex of a
/// cell 1/(dim + 1) of |measure| b.
/// @param body_force per cell attribute (may be empty: none)
/// Throws InvalidInput for a traction or body force that is not finite and for an attribute
/// without a body force. A traction whose tag no facet of m carries adds nothing: the callers
/// check tags against the whole problem (a process's part of a mesh may lack a tag's facets).
template <int dim>
Vector nodal_loads(const mesh::SimplexMesh<dim>& m,
                   const NoDeduce<std::vector<BasicTraction<dim>>>& tractions,
                   const NoDeduce<std::vector<PointD<dim>>>& body_force);

/// Consistent nodal loads of a body force given as a function of the position, integrated by a
/// rule of degree 2 per cell (2D: 3 points, 3D: 4 points; manufactured solutions).
template <int dim>
Vector body_force_loads(const mesh::SimplexMesh<dim>& m,
                        const NoDeduce<std::function<PointD<dim>(const PointD<dim>&)>>& b);

/// Elastic operator on the unknowns of a DofMap.
struct ElasticSystem {
    MovableSparseMatrix K; ///< n_dofs x n_dofs stiffness (rows/cols of multipliers are empty)
    Vector f;              ///< loads on the unknowns: nodal loads minus K_(free,fixed) u_fixed
    Vector f_nodal_full;   ///< nodal loads on every vertex component (for reactions)
};

/// Assembles K on the free unknowns of `dofs` (rows and columns of its extra unknowns stay empty)
/// and f = F_free - K_(free,fixed) u_fixed, where F = nodal_load_full and u_fixed the prescribed
/// displacements (dim per vertex, read where fixed). Materials by cell attribute; in 3D
/// Material::plane must stay plane strain, the default (plane stress is a 2D reduction).
/// Tetrahedra may have either orientation. Each vertex's rows sum its cells' entries in
/// ascending cell order, whatever the threads. Throws InvalidInput for an attribute without a
/// material, a bad material and sizes that disagree.
template <int dim>
ElasticSystem assemble_elastic(const mesh::SimplexMesh<dim>& m,
                               const std::vector<Material>& materials, const BasicDofMap<dim>& dofs,
                               const Vector& nodal_load_full, const Vector& u_fixed);

/// Internal force K_full u_full on every vertex component (dim per vertex), for reactions.
template <int dim>
Vector internal_forces(const mesh::SimplexMesh<dim>& m, const std::vector<Material>& materials,
                       const Vector& u_full);

/// Constant stress per cell in Voigt order: 2D 3 values (sxx, syy, sxy), 3D 6 values (sxx, syy,
/// szz, sxy, syz, sxz) per cell.
template <int dim>
std::vector<double> cell_stresses(const mesh::SimplexMesh<dim>& m,
                                  const std::vector<Material>& materials, const Vector& u_full);

/// Material of cell t (attribute lookup; assemble_elastic checks the range).
template <int dim>
const Material& material_of(const mesh::SimplexMesh<dim>& m, const std::vector<Material>& materials,
                            int t) {
    const int a = m.attribute.empty() ? 0 : m.attribute[static_cast<size_t>(t)];
    return materials[static_cast<size_t>(a)];
}

} // namespace mlc::fem
