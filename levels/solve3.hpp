// SPDX-License-Identifier: MIT
/// @file A 3D contact problem (one elastic body against rigid obstacles) through its load steps
/// on the tetrahedral hierarchy: coarse-to-fine Newton with status prediction (each level starts
/// from the level below's converged state, displacements by P and multipliers by the surface Q
/// of transfer/surface_q.hpp), or cold (the finest level alone, from its previous step).
#pragma once

#include "core/timer.hpp"
#include "levels/elastic3d_levels.hpp"
#include "levels/newton.hpp"
#include "levels/newton_system.hpp"
#include "transfer/surface_q.hpp"

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace mlc::levels {

/// The status codes the 3D outputs write: 0 gap, 1 stick, 2 slip (the direction apart).
int status_code3(contact::Status s);
/// "gap", "stick", "slip" for the codes of status_code3.
inline constexpr std::array<const char*, 3> kStatusNames3 = {"gap", "stick", "slip"};

/// How the Newton systems of a 3D level are solved.
enum class Method3 {
    schur, ///< condensed on the contact components (exact; make_schur_system_solver)
    lu,    ///< sparse LU of the assembled Jacobian (exact)
    /// GMRES preconditioned by the multigrid on the levels at and below (Galerkin operators
    /// R J T of the assembled Jacobian, T the displacements' P and the multipliers' surface Q,
    /// vertex blocks of three displacements and the vertex's multipliers; elastic3_mg_params).
    mg,
    /// SolveOptions3::krylov: a Krylov method with a preconditioner of the registry
    /// (make_krylov_system_solver for Level3: diag, ilu, sor, ssor, cf, sorcf, mgr, ...).
    krylov
};

/// "schur", "lu", "gmres + mg", "krylov".
const char* to_string(Method3 m);

/// The Krylov solve of Method3::krylov by default: GMRES (restart 50) with the spec's default
/// preconditioner and limits.
LinearSolverSpec gmres_spec3();

/// Options of a 3D run that are not part of the problem.
struct SolveOptions3 {
    /// Coarse-to-fine: every load step solves level 0, then each level from the level below's
    /// converged state of the same step. Off ("cold"): the finest level alone, from its own
    /// previous step.
    bool coarse_to_fine = true;
    /// Solve every level also in cold mode (the status-transfer study compares per level).
    bool solve_all_levels = false;
    /// Secant predictor: from the second load step on, each level starts from its last two
    /// converged states extrapolated linearly in the load factor,
    /// E = x_{k-1} + (s_k - s_{k-1}) / (s_{k-1} - s_{k-2}) (x_{k-1} - x_{k-2}), with the unloaded
    /// state x_0 = 0 at s_0 = 0. Coarse to fine, a level above the first then starts from
    /// E + I (x_below - E_below): its own extrapolation corrected by what the level below changed
    /// from its extrapolation, interpolated (P on displacements, Q on multipliers). Under
    /// proportional loading with unchanged statuses and slip directions the solution is linear in
    /// the load factor and E is exact; 3D slip makes Newton end only asymptotically, so this is
    /// where the Newton iterations of steps 2, 3, ... go. Along a loading path
    /// (ElasticProblem3::n_path_points K > 1) this holds between path points; a step across one,
    /// where the loading changes direction, starts from the extrapolation all the same (a start
    /// like any other). Only the unknowns are extrapolated: the prescribed components are those
    /// of the new step (Level3::u_fixed_at). Off: each level starts from its previous step (cold)
    /// or from the level below's state of this step, interpolated (coarse to fine).
    bool extrapolate = true;
    /// The Newton systems of level 0 and of the levels above.
    Method3 level0 = Method3::schur;
    Method3 upper = Method3::mg;
    /// Relative tolerance of each GMRES solve (Method3::mg); the Newton forcing may loosen it.
    double krylov_rel_tol = 1e-10;
    /// Method3::krylov: the Krylov method, its preconditioner, iteration limit and restart
    /// (method krylov; its rel_tol is krylov_rel_tol's).
    LinearSolverSpec krylov = gmres_spec3();
    /// Called after each load step of each solved level (converged or not); may be empty.
    std::function<void(int level, int step, const StepReport&)> progress;
    /// Polled before every Newton iteration; true stops the solve by throwing mlc::Interrupted
    /// (ContactNewton::set_interrupt). Empty: never polled.
    std::function<bool()> interrupt;
    /// Receives each solved level's index, the level and the Newton-system solver the run built
    /// for it, and returns the one the run uses (a forwarding solver: `bench square` counts each
    /// level's passes and memory this way). Empty: the solvers as built.
    std::function<std::unique_ptr<NewtonSystemSolver3>(int level, const Level3& L,
                                                       std::unique_ptr<NewtonSystemSolver3>)>
        wrap_system_solver;
};

/// A load step of one level and what coarse-to-fine predicted of its statuses.
struct LevelStep3 {
    int level = 0;
    StepReport report;
    bool predicted = false; ///< started from the level below's state
    std::vector<contact::Status> predicted_statuses, final_statuses;
    /// confusion[a][b]: contact nodes predicted with code a and converged with code b
    /// (status_code3).
    std::array<std::array<int, 3>, 3> confusion{};
    /// Fraction of contact nodes whose predicted status was final (1 when not predicted).
    double agreement() const;
};

/// What a 3D run produced.
struct RunResult3 {
    Hierarchy3 hierarchy;
    /// level_steps[l][k]: load step k + 1 of level l (empty for levels not solved).
    std::vector<std::vector<LevelStep3>> level_steps;
    std::vector<StepReport> steps; ///< finest level, one per load step
    Vector x;                      ///< finest level's unknowns at the end
    Vector u_full;                 ///< finest level's nodal displacements (3 per vertex)
    std::vector<ContactNodeState3> nodes;                   ///< finest, at the end
    std::vector<std::vector<ContactNodeState3>> step_nodes; ///< finest, per completed step
    std::vector<Vector> step_u_full;                        ///< finest, per completed step
    Timings timings;
    bool converged = false;
    std::string failure;     ///< where and why the first failed step failed
    int completed_steps = 0; ///< load steps completed on every solved level
    const Level3& finest() const { return hierarchy.finest(); }
};

/// Estimated peak memory of a 3D contact run (bytes), from the predicted sizes of its levels
/// (predict_elastic3_sizes): the elastic hierarchy and its multigrid (estimate_elastic3_memory),
/// per level the Jacobian and its Galerkin operator (24 bytes per nonzero of K), GMRES(50)'s
/// 51 vectors on the finest level, and for each level solved by `schur` its dense systems on the
/// contact components m (48 m^2 bytes: S, the reduced system and, in 3D slip, the doubled one)
/// and the Cholesky factor of its regularized stiffness (estimate_direct3_bytes); for each level
/// solved by `lu`, the sparse LU of its Jacobian, whose fill grows about as the square of the
/// level's unknowns (calibrated on block3d, docs/results/contact3d.md#results-contact3d-lu-memory).
double estimate_contact3_bytes(const std::vector<ElasticLevelSize3>& sizes, Method3 level0,
                               Method3 upper);

/// The Newton-system solvers of a 3D contact run and why.
struct Plan3 {
    Method3 level0 = Method3::schur; ///< level 0 (the exact solve below the multigrid)
    Method3 upper = Method3::mg;     ///< the levels above
    std::string why;                 ///< one line for the run report
};

/// The plan for levels of these sizes (predict_elastic3_sizes). `forced` (--linear schur|lu):
/// that exact solver on every level. Otherwise the multigrid above level 0, and on level 0
/// `schur` when the run fits in `limit` with it (its dense systems grow as the square of the
/// level's contact components), else the sparse `lu`. schur is the faster exact solve at every
/// size measured (up to 1 800 contact components, 2.6 times faster than lu there:
/// docs/results/contact3d.md#results-contact3d-plan), so memory alone decides. Throws
/// InvalidInput, as check_contact3_fits, when the planned run does not fit.
Plan3 plan_contact3(const std::vector<ElasticLevelSize3>& sizes, std::optional<Method3> forced,
                    const MemoryLimit& limit);

/// Throws InvalidInput when estimate_contact3_bytes of `problem`'s levels with these solvers
/// exceeds `limit`, naming the finest level, its unknowns and contact components, the estimate
/// and the limit, and what to change (fewer levels, or the multigrid instead of schur).
void check_contact3_fits(const ElasticProblem3& problem, Method3 level0, Method3 upper,
                         const MemoryLimit& limit);

/// Builds the hierarchy of `problem` (problem.levels refinements) and solves every load step.
/// Stops at the first level and step that does not converge (converged false, failure set).
RunResult3 solve(const ElasticProblem3& problem, const SolveOptions3& options = {});

/// The multiplier transfer of two nested 3D contact levels on their contactor surface: the
/// coarse multipliers, in each node's frame, become nodal forces in global components, go
/// through transfer::build_surface_q's Q (mass form: the total force is conserved), and are
/// projected on each fine node's frame (only the normal for a frictionless node). Built once
/// per pair of levels.
class MultiplierTransfer3 {
public:
    /// `coarse_faces` and `fine_faces`: the contactor faces of each level (contactor_faces; the
    /// fine ones refine the coarse ones). Both levels must outlive this object.
    MultiplierTransfer3(const Level3& coarse, const Level3& fine,
                        const transfer::SurfaceFacets<3>& coarse_faces,
                        const transfer::SurfaceFacets<3>& fine_faces);
    /// The fine multipliers of the coarse unknowns `x_coarse`, written into the multiplier
    /// entries of `x_fine` (the displacement entries are left as they are).
    void apply(const Vector& x_coarse, Vector& x_fine) const;
    const transfer::SurfaceQ& q() const { return q_; }
    const Level3& coarse() const { return coarse_; }
    const Level3& fine() const { return fine_; }
    /// Per surface index (q().coarse / q().fine), the contact element there or -1, and its frame.
    const std::vector<int>& coarse_element() const { return coarse_element_; }
    const std::vector<int>& fine_element() const { return fine_element_; }
    const std::vector<transfer::NodeFrame>& coarse_frames() const { return coarse_frames_; }
    const std::vector<transfer::NodeFrame>& fine_frames() const { return fine_frames_; }

private:
    const Level3& coarse_;
    const Level3& fine_;
    transfer::SurfaceQ q_;
    std::vector<transfer::NodeFrame> coarse_frames_, fine_frames_;
    std::vector<int> coarse_element_, fine_element_; ///< per surface index, element or -1
};

/// The prolongation of all the unknowns of two nested 3D contact levels (fine unknowns x coarse
/// unknowns): the displacement part `T_u` (a hierarchy's transfers[l].T, empty multiplier rows
/// and columns) plus the multipliers' block of `q`: each fine node's components in its frame
/// receive the coarse nodes' components through their global forces (F_f^T Q_fc F_c, restricted
/// to the normal for a frictionless node).
SparseMatrix full_prolongation3(const SparseMatrix& T_u, const MultiplierTransfer3& q);

/// Contactor surface faces of a 3D level: the boundary faces whose tag is some pair's contactor.
transfer::SurfaceFacets<3> contactor_faces(const ElasticProblem3& problem, const Level3& L);

/// Lumped contact areas int N_i dA of the contact nodes of a level (one per element of
/// L.contacts), over its contactor faces: the pressure of a node is lambda_n / area.
std::vector<double> contact_areas(const ElasticProblem3& problem, const Level3& L);

} // namespace mlc::levels
