// SPDX-License-Identifier: MIT
/// @file The description of a contact problem independent of any mesh level: bodies and
/// materials, loads, supports, contact pairs, load stepping and solver settings. A scene file is
/// parsed into this (apps/), and every level is built from it and a mesh.
#pragma once

#include "contact/element.hpp"
#include "contact/obstacle.hpp"
#include "core/types.hpp"
#include "fem/elasticity.hpp"
#include "mesh/mesh.hpp"

#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace mlc::levels {

/// Axis-aligned box in `dim` dimensions used to select vertices (the closed box [lo, hi]; the
/// defaults hold every point).
template <int dim> struct BasicBox {
    static_assert(dim == 2 || dim == 3, "BasicBox: dim is 2 or 3");
    using Point = Eigen::Matrix<double, dim, 1>;
    Point lo = Point::Constant(-1e300);
    Point hi = Point::Constant(1e300);
    /// Whether lo <= p <= hi in every coordinate.
    bool contains(const Point& p) const {
        for (int c = 0; c < dim; ++c)
            if (!(p[c] >= lo[c] && p[c] <= hi[c])) return false;
        return true;
    }
};

/// The 2D box (a rectangle).
using Box = BasicBox<2>;
/// The 3D box.
using Box3 = BasicBox<3>;

/// A body: one material region of the merged mesh (triangle attribute = body index).
struct Body {
    std::string name;
    fem::Material material;
    Vec2 body_force = Vec2::Zero(); ///< force per unit area
};

/// Uniform surface load on the boundary edges with a tag (at the full load factor 1).
///
/// Loading path (see Problem::n_path_points): without `factors` the load grows in proportion to
/// the path parameter s in [0, 1]; with `factors` = (f_1 .. f_K) it is f_k times (pressure,
/// traction) at path point k (s = k / K), linear in between, and 0 at s = 0.
struct Load {
    std::string tag;
    double pressure = 0.0;        ///< normal pressure, positive pushes into the body
    Vec2 traction = Vec2::Zero(); ///< vector traction per unit length
    std::vector<double> factors;  ///< per path point, or empty (proportional)
};

/// Prescribed displacement components on a tagged boundary or at a point (full load factor 1).
///
/// A component is either proportional (`ux` alone: s * ux along the path) or given per path point
/// (`ux_path` = (u_1 .. u_K), linear in between, 0 at s = 0; `ux` then holds u_K).
struct Support {
    std::string tag;             ///< boundary tag, or empty when `point` is given
    std::optional<Vec2> point;   ///< a vertex position (must coincide with a level-0 vertex)
    std::optional<double> ux;    ///< prescribed x displacement at s = 1, if any
    std::optional<double> uy;    ///< prescribed y displacement at s = 1, if any
    std::vector<double> ux_path; ///< x displacement per path point, or empty (proportional)
    std::vector<double> uy_path; ///< y displacement per path point, or empty (proportional)
    /// Per point of the loading path (K entries, like `ux_path`): active[k-1] says whether the
    /// support holds in the load steps whose parameter s lies in ((k-1)/K, k/K] (with
    /// load_steps = K: one entry per load step). Empty: it holds in every step. A released
    /// component is an unknown from that step on, starting from its value at the end of the
    /// previous step (solve() rebuilds the levels; Problem::at_step).
    std::vector<bool> active;
};

/// Kind of contact element a pair is discretized with (formulation.md §2).
enum class ContactElementKind {
    node_on_rigid, ///< contactor nodes against a rigid obstacle
    node_on_facet, ///< contactor nodes against the closest facet of a target boundary
    node_on_node   ///< contactor nodes against coincident target nodes (matching interface)
};

/// "node_on_rigid", "node_on_facet", "node_on_node".
std::string_view to_string(ContactElementKind k);

/// One contact pair: contactor nodes on a tagged boundary (optionally inside a box) against a
/// rigid obstacle, or against the boundary edges ("facets") tagged `target` of another body.
struct ContactPair {
    std::string name;
    std::string contactor;                     ///< boundary tag of the contactor nodes
    std::optional<Box> region;                 ///< keep only contactor vertices inside this box
    std::optional<contact::Obstacle> obstacle; ///< rigid target (node_on_rigid)
    std::string target; ///< boundary tag of the target facets (node_on_facet, node_on_node)
    ContactElementKind element = ContactElementKind::node_on_rigid;
    /// node_on_facet: a contactor node is kept when its distance to the closest target facet is
    /// at most search_radius * h0, h0 the length of the level-0 target facet whose midpoint is
    /// nearest to it (the same radius on every level, so that contact nodes nest under
    /// refinement), and it is not beyond an end of the target boundary. 2 keeps nodes a couple
    /// of elements away (curved surfaces opening slowly) and drops nodes on parts of the
    /// contactor boundary that face no target.
    double search_radius = 2.0;
    /// node_on_node: a target vertex matches when it lies within match_tolerance * h (h the
    /// length of its adjacent target facets) of the contactor vertex. Relative, so that a
    /// matching interface in any unit system matches; 1e-6 accepts mesher round-off only.
    double match_tolerance = 1e-6;
    /// node_on_facet: how a contactor node's force is spread over the target (contact::
    /// FacetIntegration): nodal (the papers' weights (1, -(1-alpha), -alpha), default), segment
    /// (mortar-type lumped weights, passes the contact patch test exactly) or dual (the same with
    /// dual test functions: also exact, and no smoothing of the contactor by the target).
    contact::FacetIntegration integration = contact::FacetIntegration::nodal;
    double mu = 0.0; ///< Coulomb friction coefficient >= 0
    double r = 0.0;  ///< augmentation parameter > 0 (force/length^2 units x length)
    bool two_body() const { return element != ContactElementKind::node_on_rigid; }
};

/// Generalized Newton settings.
struct NewtonParams {
    /// Converged when the statuses did not change and ||R|| <= rel_tol * scale, with scale the
    /// largest of the load norm and the internal/contact force norms (no absolute tolerance).
    double rel_tol = 1e-10;
    /// Iterations per load step before the step is declared not converged. The papers converge
    /// in 3-10; 50 leaves room for cycling detection to act.
    int max_iter = 50;
    /// Inexact Newton (forcing terms) for iterative Newton-system solvers; direct solvers are
    /// exact whatever it says. The first iteration of a load step solves its system only to the
    /// relative tolerance `forcing` (its statuses are a prediction, usually corrected by that
    /// step: solving it to round-off would be wasted), and every later one to
    /// 0.1 rel_tol scale / ||R||, what reaches the Newton tolerance if the statuses stay, capped
    /// at 0.5; never tighter than the linear solver's own rel_tol. 0 solves every system to the
    /// linear solver's rel_tol (exact Newton). In [0, 1).
    double forcing = 1e-3;
    void validate() const;
};

std::ostream& operator<<(std::ostream& os, const NewtonParams& p);

/// Everything needed to build a level and solve.
struct Problem {
    std::string name;
    std::string description;
    std::string units; ///< free text, e.g. "N, mm, N/mm^2"
    mesh::Mesh mesh0;  ///< level-0 mesh (all bodies; attribute = body index)
    std::vector<Body> bodies;
    std::vector<Load> loads;
    std::vector<Support> supports;
    std::vector<ContactPair> contacts;
    /// Load steps: step j solves at the path parameter s = j / load_steps (equal increments).
    int load_steps = 1;
    int levels = 0; ///< number of 1->4 refinements of mesh0
    /// Order of the unknowns of each level (fem::DofMap). hilbert (default): the vertices along a
    /// Hilbert curve. lattice: on a level that is uniform refinements of mesh0, macro triangle by
    /// macro triangle, each one's interior row by row (mesh::lattice_vertex_order), the order in
    /// which mg:smoother=lattice sweeps without copies; other levels keep the Hilbert order.
    enum class Numbering { hilbert, lattice };
    Numbering numbering = Numbering::hilbert;
    /// Levels recovered from a Gmsh mesh that is a uniform refinement (scene/scene.cpp,
    /// mesh::unrefine): mesh0 is then its coarsest ancestor and the file's mesh is level
    /// `recovered_levels`; 0 otherwise.
    int recovered_levels = 0;
    NewtonParams newton;

    /// Checks materials, pairs (mu >= 0, r > 0, one target of the right kind, an integration
    /// other than nodal only with node_on_facet), load_steps >= 1,
    /// levels >= 0, and the loading path (every per-point list of the same length, the support
    /// activities included).
    /// Throws InvalidInput naming the offending entry.
    void validate() const;
    /// Characteristic Young's modulus (the largest), for defaults such as r = 0.1 E.
    double max_young_modulus() const;
    /// Smallest Young's modulus of the bodies (the scale of the default augmentation r: the
    /// softer body governs the compliance of a contact pair).
    double min_young_modulus() const;

    /// Whether support `s` holds in load step `step` (1-based; Support::active).
    bool support_active(const Support& s, int step) const;
    /// The problem of load step `step` (1-based): the supports released in that step removed and
    /// the activity of the others cleared (they hold). build_level uses the supports active in
    /// step 1, so build_level(problem.at_step(k), m) is the level of step k.
    Problem at_step(int step) const;
    /// Whether the supports active in steps a and b are the same.
    bool same_supports(int a, int b) const;

    /// Number K of points of the loading path: the common length of the per-point lists of
    /// loads (`factors`) and supports (`ux_path`, `uy_path`, `active`), or 1 when there is none
    /// (proportional loading). Path point k (1..K) sits at s = k / K; s = 0 is the unloaded state.
    int n_path_points() const;
    /// Value at path point k (1..K) of a proportional quantity `full` (k / K * full) or of a
    /// per-point list (`path[k-1]`).
    static double path_value(const std::vector<double>& path, double full, int k, int K);
};

/// The loading path's length check, shared by 2D and 3D problems: a per-point list of `n`
/// entries (0: none) named `what` (e.g. "load on 'top'", "support on 'platen' (ux)") joins a
/// path whose common length so far is K (0 before any list). Throws InvalidInput when both are
/// non-zero and differ; otherwise K becomes n (when n > 0).
void check_path_length(int& K, size_t n, const std::string& what);

/// "hilbert" or "lattice".
std::string_view to_string(Problem::Numbering n);
/// The numbering named "hilbert" or "lattice"; anything else throws InvalidInput naming `what`
/// (the option, e.g. "--numbering") and the value.
Problem::Numbering parse_numbering(std::string_view name, std::string_view what);

} // namespace mlc::levels
