// SPDX-License-Identifier: MIT
/// @file 3D linear elasticity over a hierarchy of tetrahedral levels: the problem a 3D scene
/// describes (scene/scene3.hpp), its level sizes and memory predicted before anything is built,
/// the levels (mesh refined 1->8, DofMap3, stiffness on the free unknowns, the P transfers
/// restricted to the unknowns) and the geometric multigrid on them (solvers::Multigrid with
/// rediscretized operators and 3 x 3 vertex blocks). Loads and supports follow a loading path as
/// in 2D (levels/problem.hpp): per-point load factors and prescribed values, linear between the
/// path points, evaluated by Level3::u_fixed_at(s) and f_at(s).
#pragma once

#include "core/types.hpp"
#include "fem/assembly.hpp"
#include "fem/dof_map.hpp"
#include "fem/elasticity.hpp"
#include "levels/hierarchy.hpp"
#include "levels/level.hpp"
#include "levels/resources.hpp"
#include "mesh/tet_mesh.hpp"
#include "solvers/mg.hpp"

#include <algorithm>
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace mlc::levels {

using mesh::Vec3;

/// One body of a 3D problem: the tetrahedra whose attribute is its index.
struct Body3 {
    std::string name;
    fem::Material material;         ///< plane strain (the 3D law; no plane reduction)
    Vec3 body_force = Vec3::Zero(); ///< per unit volume
};

/// A uniform pressure (positive pushing into the body) and traction (per unit area) on the
/// boundary faces with a tag, at the full load.
///
/// Loading path (ElasticProblem3::n_path_points), as a 2D Load: without `factors` the load grows
/// in proportion to the path parameter s in [0, 1]; with `factors` = (f_1 .. f_K) it is f_k
/// times (pressure, traction) at path point k (s = k / K), linear in between, and 0 at s = 0.
struct FaceLoad3 {
    std::string tag;
    double pressure = 0.0;
    Vec3 traction = Vec3::Zero();
    std::vector<double> factors; ///< per path point, or empty (proportional)
};

/// Prescribed displacement components on the faces with a tag, along a line, or at a vertex of
/// level 0 (a point; refinement keeps its index). Unset components are free.
///
/// A component is either proportional (u[c] alone: s * u[c] along the path) or given per path
/// point (u_path[c] = (u_1 .. u_K), linear in between, 0 at s = 0; u[c] then holds u_K), as a
/// 2D Support's ux/ux_path. A 3D support holds in every load step (the 2D `active` has no 3D
/// counterpart).
struct Support3 {
    std::string
        tag; ///< a tag of boundary faces and/or tagged lines; empty for a line or point support
    std::optional<Vec3> point; ///< a level-0 vertex (for a point support)
    /// A line support: the straight segment between two level-0 vertices, which must run along
    /// edges of the level-0 mesh; it holds every vertex on the segment, on every level (the
    /// midpoints refinement puts on its edges).
    std::optional<std::array<Vec3, 2>> line;
    std::array<std::optional<double>, 3> u{}; ///< ux, uy, uz (at s = 1)
    /// Per component: the values per path point, or empty (proportional).
    std::array<std::vector<double>, 3> u_path{};
};

/// The vertices of m on a line support's segment (within 1e-9 of m's diameter), ordered along
/// it from line[0].
std::vector<int> line_vertices(const mesh::TetMesh& m, const std::array<Vec3, 2>& line);

/// One contact pair of a 3D problem: the contactor nodes on a tagged boundary (inside `region`,
/// if given) against a rigid obstacle (node-on-rigid elements) or against the boundary faces
/// tagged `target` of another body (node on facet, node on node: contact/search3.hpp), with the
/// keys and defaults of the 2D pairs (levels::ContactPair).
struct ContactPair3 {
    std::string name;
    std::string contactor;      ///< boundary face tag of the contactor nodes
    std::optional<Box3> region; ///< keep only contactor vertices inside this box
    contact::BasicObstacle<3> obstacle; ///< node_on_rigid: the rigid target
    std::string target; ///< node_on_facet, node_on_node: boundary face tag of the target
    ContactElementKind element = ContactElementKind::node_on_rigid;
    /// node_on_facet: a contactor node is kept when the level-0 target has a face within
    /// search_radius * h0 of it, h0 the longest edge of the level-0 target face closest to it
    /// (the same decision on every level, so that contact nodes nest), and it is not beyond the
    /// rim of the target (contact::node_on_facet_search3).
    double search_radius = 2.0;
    /// node_on_node: a target vertex matches when within match_tolerance * h of the contactor
    /// vertex, h the mean length of its target edges (contact::node_on_node_search3).
    double match_tolerance = 1e-6;
    /// node_on_facet: nodal (the closest point's barycentric weights), segment (mortar-type
    /// lumped weights of the clipped contactor patch, contact::mortar_weights3: the patch test
    /// exactly) or dual (the same with psi = 4 N - 1: identity weights on matching meshes).
    contact::FacetIntegration integration = contact::FacetIntegration::nodal;
    double mu = 0.0; ///< Coulomb coefficient >= 0
    /// Augmentation parameter > 0. A 3D multiplier is a nodal force, so r has the units of a
    /// force per length (E times a length; scene/scene3.hpp's default r_over_E E h0).
    double r = 0.0;
    bool two_body() const { return element != ContactElementKind::node_on_rigid; }
};

/// A 3D problem: the level-0 mesh (attribute = body index), bodies, loads and supports, the
/// contact pairs (rigid obstacles), load stepping, Newton settings and the finest level.
struct ElasticProblem3 {
    std::string name, description, units;
    mesh::TetMesh mesh0;
    std::vector<Body3> bodies;
    std::vector<FaceLoad3> loads;
    std::vector<Support3> supports;
    std::vector<ContactPair3> contacts;
    /// Load steps: step j solves at the path parameter s = j / load_steps (equal increments).
    int load_steps = 1;
    NewtonParams newton;
    int levels = 0;
    /// Throws InvalidInput naming the first defect: no body, an attribute without a body, a bad
    /// material, a support tag no boundary face or tagged line carries (a
    /// load tag no boundary face carries), a point that is no level-0 vertex, a line whose
    /// ends are no level-0 vertices or whose segment does not run along level-0 edges, a support
    /// that fixes nothing, levels outside 0..12, load_steps < 1, bad Newton settings
    /// (NewtonParams::validate), and per contact pair: a contactor tag on no boundary face
    /// (naming it and the face tags there are), mu < 0 or not finite, r not > 0 or not finite,
    /// a region with min > max, a bad obstacle (BasicObstacle::validate) of a node-on-rigid
    /// pair; of a two-body pair a target tag on no boundary face, a target equal to the
    /// contactor, search_radius or match_tolerance not > 0, an integration other than nodal for
    /// node on node; and the loading path: every per-point list of the same length
    /// (check_path_length, the 2D message), a component's u equal to the last entry of its
    /// u_path.
    void validate() const;

    /// Number K of points of the loading path: the common length of the per-point lists of the
    /// loads (`factors`) and supports (`u_path`), or 1 when there is none (proportional loading).
    /// Path point k (1..K) sits at s = k / K; s = 0 is the unloaded state. Values at the path
    /// points are Problem::path_value's, as in 2D.
    int n_path_points() const;
};

/// The mean length of the level-0 edges of the boundary faces tagged `tag` (each edge once):
/// the length h0 of the default augmentation r = r_over_E E h0 of a 3D pair. Throws
/// InvalidInput when no boundary face carries the tag.
double mean_face_edge_length(const mesh::TetMesh& m, const std::string& tag);

/// Largest finest level of a 3D problem.
inline constexpr int kMaxLevels3 = 12;

/// Predicted size of one 3D elastic level.
struct ElasticLevelSize3 {
    int level = 0;
    double vertices = 0, edges = 0, tetrahedra = 0;
    double unknowns = 0;    ///< free displacement components
    double multipliers = 0; ///< contact multipliers (3 per frictional, 1 per frictionless node)
    double k_nonzeros = 0;  ///< of K on the unknowns
};

/// Sizes of levels 0..levels from the level-0 mesh alone (mesh::predict_tet_level_sizes; level
/// 0's DofMap3 and stiffness counted). Unknowns are 3 V less the fixed components, exact: per
/// component the vertices of the supported faces refine as V' = V + E, E' = 2 E + 3 F,
/// F' = 4 F, and point supports stay. The nonzeros of K are 9 (V + 2 E) less level 0's deficit
/// per fixed component times the fixed components.
///
/// Multipliers: the contact nodes of a level are the points of the refined contactor faces, each
/// counted once: a level-0 vertex, the 2^l - 1 points refinement puts inside a level-0 edge and
/// the (2^l - 1)(2^l - 2) / 2 inside a level-0 face, less those whose three components are
/// fixed (a level-0 edge's points are fixed in a component when a face or line support of that
/// component holds the edge, a face's when a support holds the face), 3 per node of a
/// frictional pair and 1 of a frictionless one. Exact without a region. With a region: exact for
/// the edges and faces whose level-0 vertices all lie inside it (a box holds a flat face with
/// its corners) and for those whose bounding box misses it; those it cuts have their points
/// counted at their positions on the level-0 face (refinement moves the points of a curved
/// surface onto it: there the count near the region's boundary is an estimate). A point on the
/// contactor faces of two pairs counts for the first whose region holds it, as build_level
/// claims it.
std::vector<ElasticLevelSize3> predict_elastic3_sizes(const ElasticProblem3& p, int levels);

/// Estimated peak resident memory of `bench elastic` on a 3D problem: the hierarchy (meshes,
/// DofMaps, K, loads, transfers of every level), then either solver beside it: the multigrid
/// (its smoothers, work vectors, the coarse factor) or BoomerAMG-PCG (hypre's copy of K and its
/// AMG hierarchy); the peak is the hierarchy and the larger of the two.
struct ElasticMemory3 {
    double hierarchy_bytes = 0, mg_bytes = 0, amg_bytes = 0;
    double baseline_bytes = 0;
    double mg_peak() const { return baseline_bytes + hierarchy_bytes + mg_bytes; }
    double amg_peak() const { return baseline_bytes + hierarchy_bytes + amg_bytes; }
    double bytes() const { return std::max(mg_peak(), amg_peak()); }
};
ElasticMemory3 estimate_elastic3_memory(const std::vector<ElasticLevelSize3>& sizes);

/// The solver of a 3D elastic level: the multigrid (mg-CG, elastic3_multigrid) whenever a level
/// below exists, and the direct factor only on a single level. This is the 3D crossover
/// (docs/results/benchmarks.md#results-3d-direct): mg-CG beats the direct factor from the first
/// refinement on, where the 2D planner keeps the exact solver up to a few thousand unknowns
/// (kMgCrossoverOneBody).
struct ElasticPlan3 {
    bool multigrid = true;
    std::string reason; ///< one sentence, for the bench's output
};
ElasticPlan3 plan_elastic3(int finest_level);

/// Estimated memory of the direct solve of a 3D elastic level beside its hierarchy (`bench elastic
/// --direct`): CHOLMOD's supernodal factor in its fill-reducing order, whose nonzeros grow like
/// unknowns^1.39 on box3d's levels 3 and 4 (faster than nested dissection's unknowns^(4/3) bound
/// at these sizes), at 12 bytes per factor nonzero, and the two copies of K the ordering makes.
/// Fitted on box3d's levels 3 and 4 alone; its error against the measured peaks is in
/// docs/results/benchmarks.md#results-3d-direct.
double estimate_direct3_bytes(const ElasticLevelSize3& finest);

/// Throws InvalidInput when `e` does not fit in `limit`: the finest level, its unknowns, the
/// estimate and the limit, and the fix (fewer levels).
void check_elastic3_fits(const ElasticMemory3& e, const MemoryLimit& limit,
                         const std::vector<ElasticLevelSize3>& sizes);

/// Builds one 3D level on mesh `m` (a refinement of p.mesh0, or p.mesh0): supports
/// (Level3::fixed, u_fixed), contact elements, numbering (by vertex index: the free components
/// of a vertex, then its multipliers), materials, loads and the assembled system (K on the
/// unknowns, its multiplier rows and columns empty; f for the full load). With a loading path
/// (K = p.n_path_points() > 1) also the prescribed values and loads at every path point
/// (Level3::path_u_fixed, path_f, path_f_nodal, as the 2D build_level; body forces grow in
/// proportion to s), which u_fixed_at(s), f_at(s) and f_nodal_at(s) interpolate; with K = 1
/// they stay empty and the loading is s times the full load, as before.
///
/// Contactor nodes, pair by pair: the vertices of the boundary faces with the pair's contactor
/// tag, inside its region (if any), not fully fixed (all three components) and not claimed by
/// an earlier pair; each gets a node-on-rigid element (contact::node_on_rigid, Level3::contacts
/// in pair order, contact_of_vertex) and its multipliers (n_multipliers: 3 frictional, 1
/// frictionless) right after its displacements (lambda_dof: the first of them). not_found
/// holds one empty list per pair. Components held by supports are pinned
/// (contact::held_components). Throws InvalidInput for a pair with no contact node, and for a
/// node whose supports hold a direction its contact frame meets only in part (`ambiguous`),
/// naming the pair, the vertex, its position, the held components, the frame and the fixes.
Level3 build_level(const ElasticProblem3& p, mesh::TetMesh m);

/// Refines p.mesh0 `levels` times (mesh::refine) and builds every level and transfer: transfers[l]
/// from level l to l + 1 holds P_vertex (linear interpolation through the 1->8 refinement), T
/// (P_vertex on the free displacement unknowns, transfer::restrict_to_unknowns; n_dofs x n_dofs
/// of the two levels, the rows and columns of multipliers empty) and R = T^T; P_nodal, Q and the
/// coarse/fine splitting, which contact levels use, stay empty (Q: transfer/surface_q.hpp).
Hierarchy3 build_hierarchy(const ElasticProblem3& p, int levels);

/// The geometric multigrid on a hierarchy of at least two levels: rediscretized operators (each
/// level's K), smoother blocks of the 3 components of a vertex, T and R of the hierarchy
/// (borrowed: `h` must outlive it), sparse LU on level 0. With the default params
/// (elastic3_mg_params), a symmetric W(2,2) cycle (forward pre-sweeps, backward post-sweeps)
/// that preconditions CG. The lattice smoother is 2D-only and refused (InvalidInput).
std::unique_ptr<solvers::Multigrid> elastic3_multigrid(const Hierarchy3& h,
                                                       solvers::MultigridParams params);
std::unique_ptr<solvers::Multigrid> elastic3_multigrid(const Hierarchy3& h);

/// The default cycle of the 3D elastic multigrid: W(2,2). The V(1,1) cycle of the 2D runs needs
/// more CG iterations as the levels grow (box3d: 13, 15, 17, 18, 18 on levels 1-5); two sweeps
/// and the W-cycle keep them level-independent (9, 9, 10, 10) for about the same time per solve
/// as V(2,2), since in 3D each coarser level holds an eighth of the unknowns
/// (docs/results/benchmarks.md#results-3d-cycle).
solvers::MultigridParams elastic3_mg_params();

/// The rigid-body modes of a level on its unknowns: the translations along x, y, z and the
/// rotations about the x, y, z axes through the centre of the mesh's bounding box (6 vectors).
std::vector<Vector> rigid_body_modes3(const Level3& L);

} // namespace mlc::levels
