// SPDX-License-Identifier: MIT
/// @file One level of the hierarchy: its mesh, unknown numbering, assembled elastic operator and
/// load, and its contact elements.
#pragma once

#include "contact/element.hpp"
#include "fem/assembly.hpp"
#include "fem/dof_map.hpp"
#include "levels/problem.hpp"
#include "mesh/mesh.hpp"

#include <vector>

namespace mlc::levels {

/// Everything one mesh level needs to solve. Built by `build_level`; immutable afterwards.
struct Level {
    mesh::Mesh mesh;
    std::vector<fem::Material> materials;   ///< per body (triangle attribute)
    std::vector<std::array<bool, 2>> fixed; ///< per vertex and component
    Vector u_fixed;                         ///< prescribed displacements at load factor 1
    fem::DofMap dofs;
    fem::ElasticSystem elastic;                    ///< K and f at load factor 1
    std::vector<contact::ContactElement> contacts; ///< one per contactor node
    std::vector<int> lambda_dof;                   ///< first multiplier unknown of each element
    std::vector<int> contact_of_vertex;            ///< element index of a contactor vertex, or -1

    Index n_unknowns() const { return dofs.n_dofs(); }
    int n_contact_nodes() const { return static_cast<int>(contacts.size()); }
};

/// Builds a level from the problem and a mesh of it (level 0 or a refinement).
/// Contactor nodes: vertices on the pair's contactor tag (inside its region, if any) that are
/// not fully fixed. Throws InvalidInput for an unknown tag, a support point that is not a vertex,
/// or a pair with no contactor node.
Level build_level(const Problem& problem, mesh::Mesh m);

} // namespace mlc::levels
