// SPDX-License-Identifier: MIT
/// @file One level of the hierarchy: its mesh, unknown numbering, assembled elastic operator and
/// load, and its contact elements.
#pragma once

#include "contact/element.hpp"
#include "fem/assembly.hpp"
#include "fem/dof_map.hpp"
#include "levels/problem.hpp"
#include "mesh/lattice.hpp"
#include "mesh/mesh.hpp"
#include "mesh/simplex_mesh.hpp"
#include "smoothers/lattice_gs.hpp"

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

namespace mlc::levels {

/// Everything one mesh level needs to solve, in `dim` dimensions (`Level` in 2D, `Level3` in
/// 3D). Built by `build_level` (2D) or `build_level3` (3D); immutable afterwards.
template <int dim> struct BasicLevel {
    static constexpr int dimension = dim;
    mesh::SimplexMesh<dim> mesh;
    std::vector<fem::Material> materials;     ///< per body (cell attribute)
    std::vector<std::array<bool, dim>> fixed; ///< per vertex and component
    Vector u_fixed;                           ///< prescribed displacements at load factor 1
    fem::BasicDofMap<dim> dofs;
    fem::ElasticSystem elastic;                              ///< K and f at load factor 1
    std::vector<contact::BasicContactElement<dim>> contacts; ///< one per contactor node
    std::vector<int> lambda_dof;        ///< first multiplier unknown of each element
    std::vector<int> contact_of_vertex; ///< element index of a contactor vertex, or -1
    /// Per contact pair: contactor vertices left out because the search found no target facet
    /// (node_on_facet) or no coincident target vertex (node_on_node). Empty for rigid pairs.
    std::vector<std::vector<int>> not_found;
    /// A distributed level's part only (build_level with a LevelPart; empty otherwise): the
    /// elements of contact nodes owned by other processes that reach a vertex this process owns
    /// (a two-body element couples its contactor with target vertices, which another process
    /// may own), built here as their owners build them, so that the owned rows of the residual
    /// and the Jacobian are complete without sending contributions. Their multiplier rows are
    /// their owners'; they count in no status, norm or output.
    std::vector<contact::BasicContactElement<dim>> ghost_contacts;
    std::vector<int> ghost_lambda_dof; ///< first multiplier unknown of each ghost element

    /// Loading path (Problem::n_path_points K): prescribed displacements (dim per vertex), loads
    /// on the unknowns (f = F_free - K_(free,fixed) u_fixed) and nodal loads (dim per vertex) at
    /// path points k = 1..K, entry k-1. The last entries equal u_fixed, elastic.f,
    /// elastic.f_nodal_full. Empty with one path point (proportional loading; build_level leaves
    /// them empty then) and in a level assembled by hand: the loading is then proportional to
    /// those.
    std::vector<Vector> path_u_fixed, path_f, path_f_nodal;

    /// Prescribed displacements at path parameter s in [0, 1] (s = step / load_steps): linear
    /// between path points, 0 at s = 0; s * u_fixed for proportional loading (K = 1).
    Vector u_fixed_at(double s) const;
    /// Loads on the unknowns at path parameter s (s * elastic.f for proportional loading).
    Vector f_at(double s) const;
    /// Nodal loads (dim per vertex) at path parameter s (s * elastic.f_nodal_full if
    /// proportional).
    Vector f_nodal_at(double s) const;
    /// u_fixed_at(s) and f_at(s) written into `out` (resized; no allocation when it has the size).
    void u_fixed_at(double s, Vector& out) const;
    void f_at(double s, Vector& out) const;

    /// 2D only (null in 3D): with Problem::Numbering::lattice on a level that is 4 or more
    /// refinements of mesh0, the rows of its macro triangles' interiors (mg:smoother=lattice).
    std::shared_ptr<const smoothers::LatticeRows> lattice;

    Index n_unknowns() const { return dofs.n_dofs(); }
    int n_contact_nodes() const { return static_cast<int>(contacts.size()); }
    /// Vertex of each unknown (the smoothers' vertex blocks).
    std::vector<int> vertex_of_dof() const;
};

extern template struct BasicLevel<2>;
extern template struct BasicLevel<3>;

/// A 2D level (triangles).
using Level = BasicLevel<2>;
/// A 3D level (tetrahedra).
using Level3 = BasicLevel<3>;

/// Builds a level from the problem and a mesh of it (level 0 or a refinement of
/// problem.mesh0).
///
/// Contactor nodes: vertices on the pair's contactor tag (inside its region, if any) that are
/// not fully fixed and not claimed by an earlier pair. Rigid pairs make node-on-rigid elements;
/// two-body pairs search their target once, on the reference configuration
/// (contact::node_on_facet_search with the level-0 target facets setting the search radius and
/// the pair's integration, nodal, segment or dual, computed on this level's meshes, or
/// contact::node_on_node_search); contactor nodes that find nothing are left out and listed in
/// `not_found`. Throws InvalidInput for an unknown tag, a support point that is not a vertex, or
/// a pair with no contact node. The mesh is checked with mesh::check_quality, or, when it was
/// made by mesh::refine (of a checked mesh), with mesh::check_refined_quality.
Level build_level(const Problem& problem, mesh::Mesh m);

/// What build_level needs to know to build one process's part of a distributed level
/// (levels/distributed.hpp): which vertices this process owns, and how to complete what it cannot
/// know of the others.
struct LevelPart {
    std::vector<char> owned; ///< per vertex of the part's mesh: 1 where this process owns it
    /// Called once the supports and contact nodes of the owned vertices are known, before the
    /// unknowns are numbered: sets the fixed flags and path values (Level::fixed,
    /// path_u_fixed, u_fixed), the multiplier counts (n_extra) and the contact pair of the
    /// contact nodes (contact_pair, -1 elsewhere) of the vertices owned by other processes to
    /// their owners' (a part's mesh may lack the boundary edges that decide them).
    std::function<void(Level&, std::vector<int>& n_extra, std::vector<int>& contact_pair)> complete;
    std::vector<int> order; ///< numbering order of the vertices (empty: Hilbert order)
};

/// build_level for one process's part (`part` non-null): contact nodes only at owned vertices (a
/// pair may have none in the part; the caller checks the pairs over all parts), support points
/// held only by the part that owns them, and `part->complete` before numbering. Two-body pairs
/// also get Level::ghost_contacts: the contact nodes of other processes (contact_pair from
/// `complete`) are searched again here, and their elements kept where they reach an owned
/// vertex. Null `part`: build_level(problem, m).
Level build_level(const Problem& problem, mesh::Mesh m, const LevelPart* part);

/// The rows of the macro triangles' interior points of L's mesh (smoothers::LatticeGS; a vertex
/// whose unknowns are not its two displacements, in a row, gets -1) and the serpentine visit
/// order; build_level fills Level::lattice with it under Problem::Numbering::lattice.
smoothers::LatticeRows lattice_rows(const Level& L, const mesh::MacroLattice& lattice);

} // namespace mlc::levels
