// SPDX-License-Identifier: MIT
/// @file Global assembly of the elastic stiffness, surface tractions, body forces and the load
/// induced by prescribed (Dirichlet) displacements; stress recovery.
#pragma once

#include "core/types.hpp"
#include "fem/dof_map.hpp"
#include "fem/elasticity.hpp"
#include "mesh/mesh.hpp"

#include <vector>

namespace mlc::fem {

/// Uniform traction on all boundary edges with one tag. Either a pressure (normal, positive
/// pushing into the body: t = -p n_out) or a constant vector traction; both per unit length.
struct Traction {
    int tag = 0;
    double pressure = 0.0;
    Vec2 vector = Vec2::Zero();
};

/// Consistent nodal forces (2 per vertex, interleaved) of tractions and body forces:
/// for P1 and a constant traction each edge end receives half the edge resultant; a constant
/// body force b gives area/3 b per triangle vertex.
/// @param body_force per triangle attribute (size = number of attributes, may be empty)
Vector nodal_loads(const mesh::Mesh& m, const std::vector<Traction>& tractions,
                   const std::vector<Vec2>& body_force);

/// Elastic operator on the unknowns of `dofs`.
struct ElasticSystem {
    MovableSparseMatrix K; ///< n_dofs x n_dofs stiffness (rows/cols of multipliers are empty)
    Vector f;              ///< loads on the unknowns: nodal loads minus K_(free,fixed) u_fixed
    Vector f_nodal_full;   ///< nodal loads on every vertex component (for reactions)
};

/// Assembles K on the free unknowns and the right-hand side for the full load:
/// f = F_free - K_(free,fixed) u_fixed, where F are the nodal loads and u_fixed the prescribed
/// displacements (2 per vertex, read where fixed). Materials are indexed by triangle attribute.
ElasticSystem assemble_elastic(const mesh::Mesh& m, const std::vector<Material>& materials,
                               const DofMap& dofs, const Vector& nodal_load_full,
                               const Vector& u_fixed);

/// Internal force K_full u_full on every vertex component (2 per vertex), used for reactions.
Vector internal_forces(const mesh::Mesh& m, const std::vector<Material>& materials,
                       const Vector& u_full);

/// Constant stress (sxx, syy, sxy) per triangle, 3 values per triangle.
std::vector<double> triangle_stresses(const mesh::Mesh& m, const std::vector<Material>& materials,
                                      const Vector& u_full);

/// Material of triangle t (attribute lookup with range check done at assembly).
inline const Material& material_of(const mesh::Mesh& m, const std::vector<Material>& materials,
                                   int t) {
    const int a = m.attribute.empty() ? 0 : m.attribute[static_cast<size_t>(t)];
    return materials[static_cast<size_t>(a)];
}

} // namespace mlc::fem
