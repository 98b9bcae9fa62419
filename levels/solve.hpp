// SPDX-License-Identifier: MIT
/// @file Runs a problem through its load steps on the level hierarchy: coarse-to-fine (the
/// multilevel Newton of Alart & Lebon 1995, sect. 2.4) or cold (each level from its own previous
/// step), and collects what the report, the studies and the output files need.
#pragma once

#include "core/timer.hpp"
#include "levels/hierarchy.hpp"
#include "levels/newton.hpp"
#include "levels/newton_system.hpp"
#include "levels/problem.hpp"
#include "levels/resources.hpp"

#include <array>
#include <functional>
#include <optional>
#include <ostream>
#include <vector>

namespace mlc::levels {

/// A converged load step of one level, as SolveObserver::level_step sees it (valid during the
/// call only).
struct LevelStepState {
    int level = 0;
    int step = 0;                   ///< 1-based load step
    double s = 0.0;                 ///< load parameter step / load_steps
    const Level* L = nullptr;       ///< the level
    const Vector* u_full = nullptr; ///< nodal displacements (2 per vertex)
    /// The contact node states, computed on the first call.
    const std::vector<ContactNodeState>& nodes() const;
    /// What nodes() computes (set by the run).
    std::function<std::vector<ContactNodeState>()> node_states;

private:
    mutable std::optional<std::vector<ContactNodeState>> nodes_;
};

/// Options of one run that are not part of the problem: plain values (what a run reports as it
/// goes and asks of its caller is the SolveObserver's).
struct SolveOptions {
    /// Keep the finest displacements after every step (step_u_full); the contact node states of
    /// every step (step_nodes) are always kept.
    bool keep_step_states = false;
    /// Coarse-to-fine: in every load step solve level 0, interpolate (P u, Q lambda) to level 1 as
    /// the initial guess, solve there, and so on to the finest. Off ("cold"): only the finest
    /// level is solved, from its previous step's state (every level when the preconditioner
    /// needs the level below).
    bool coarse_to_fine = true;
    transfer::QRule q_rule = transfer::QRule::paper; ///< multiplier interpolation rule
    /// Coarse-to-fine initial guess of level l in load step k: false (the paper's): the
    /// interpolated coarse state (P u_H^k, Q lambda_H^k); true: the level's own state of step
    /// k-1 plus the interpolated coarse increment, x_h^(k-1) + (P, Q)(x_H^k - x_H^(k-1)). The
    /// two agree in step 1; later, the increment keeps the fine level's own resolution of the
    /// zone ends and interpolates only what changed.
    bool transfer_increment = false;
    /// Load steps that are linear: in load step k >= 3 (k >= 2 from the unloaded state x^0 = 0
    /// when the supports never changed), each level first tries its own last two states
    /// extrapolated, 2 x^(k-1) - x^(k-2) (the load steps are uniform), and takes it when Newton
    /// would stop there at once (residual within NewtonParams::rel_tol: no status changed over
    /// the step, so the step is linear and the extrapolation exact to round-off); otherwise the
    /// guess is the usual one (coarse-to-fine or the previous step), so that no step takes more
    /// Newton iterations than without it. Costs one residual per level and step.
    bool extrapolate = false;
    /// How Newton systems are solved on levels >= 1 (level 0 always uses the exact "schur").
    LinearSolverSpec linear;
    /// Solve every level even in cold mode (the status-transfer study compares per level).
    bool solve_all_levels = false;
    /// Levels solved by a Krylov method: a Newton system the Krylov solve fails on (neither
    /// converged nor reduced the residual by half, or a breakdown) is solved again by the exact
    /// `schur` solver of that level, built on first use when it fits in memory
    /// (ContactNewton::set_fallback; counted in StepReport::fallback_solves and reported).
    /// The driver (`mlcontact run`, `study extremes`) turns it on; studies that measure the
    /// preconditioners themselves leave it off.
    bool exact_fallback = false;
    /// A load step whose Newton fails at the scene's r on some level (status cycling, as at
    /// r = 1e4 E, where the generalized Newton method is only locally convergent) is solved again
    /// from the same initial guess with r reduced by 100 (then 1e4) on that level, with the
    /// exact `schur` solver (built for it when it fits in memory, then freed), and Newton at the
    /// scene's r restarts from that solution with the level's own solver. The answer is the one
    /// at the scene's r: the discrete contact solution does not depend on r, and the step must
    /// pass the Newton test at the scene's r. Reported in StepReport::continuation_*. The driver
    /// (`mlcontact run`, `study extremes`, the Python module) turns it on.
    bool r_continuation = false;
    /// predict_level_sizes(problem) when the caller computed it already (it builds level 0);
    /// empty: solve computes it.
    std::vector<LevelSize> predicted_sizes;
};

/// Confusion table of predicted (rows) against converged (columns) statuses, indexed by
/// contact::Status (gap, stick, slip_forward, slip_backward).
using Confusion = std::array<std::array<int, 4>, 4>;

/// A load step on one level, with what coarse-to-fine predicted.
struct LevelStep {
    int level = 0;
    StepReport report;
    bool predicted = false;    ///< an interpolated initial guess was used
    bool extrapolated = false; ///< the extrapolated state was taken (SolveOptions::extrapolate)
    std::vector<contact::Status> predicted_statuses; ///< statuses of the initial guess
    std::vector<contact::Status> final_statuses;     ///< Newton (projection) statuses at the end
    Confusion confusion{};                           ///< predicted x final counts
    /// Fraction of contact nodes whose predicted status was final (1 when not predicted).
    double agreement() const;
};

/// A load step of one level as it ends, converged or not (SolveObserver::level_step_done).
struct LevelStepProgress {
    const LevelStep* step = nullptr; ///< the level's step: its report and prediction
    int load_steps = 0;              ///< the problem's load steps
    int n_levels = 0;                ///< levels of the hierarchy
    int first_level = 0;             ///< the lowest level solved
    /// The hierarchy's levels (their sizes estimate the time left); null for a distributed level.
    const std::vector<Level>* levels = nullptr;
    double elapsed = 0.0; ///< seconds since the first load step began
    /// A distributed level's processes (levels/distributed_solve.hpp); 0 for a level that is
    /// solved whole.
    int processes = 0;
};

/// What a run reports as it goes and what it asks of its caller, as a monitor of deal.II's or
/// PETSc's does: solve() calls these at the points named; every default does nothing.
class SolveObserver {
public:
    virtual ~SolveObserver() = default;
    /// After every load step of every solved level, converged, failed or stopped (progress).
    virtual void level_step_done(const LevelStepProgress&) {}
    /// After every converged load step of every solved level (levels bottom up, then the next
    /// step), e.g. to write that step's files as soon as it is done.
    virtual void level_step(const LevelStepState&) {}
    /// Polled after every Newton iteration: once true, the run stops after the current iteration
    /// (RunResult::stopped; the completed load steps are kept).
    virtual bool stop_requested() { return false; }
    /// Polled before every Newton iteration on every level; true stops the solve there by
    /// throwing mlc::Interrupted naming the level, load step and iteration. The Python module
    /// checks Python's signal handlers here, so that Ctrl-C during mlcontact.solve() raises
    /// KeyboardInterrupt within one Newton iteration.
    virtual bool interrupt_requested() { return false; }
    /// The Newton-system solver of each level solved (bottom up, once, before the first load
    /// step): receives the level's index, the level and the solver the run built, and returns the
    /// one the run uses (forwarding prepare, set_coarse_statuses and multigrid to it). `bench
    /// newton` records and times the finest level's systems this way.
    virtual std::unique_ptr<NewtonSystemSolver>
    wrap_system_solver(int /*level*/, const Level& /*L*/,
                       std::unique_ptr<NewtonSystemSolver> solver) {
        return solver;
    }
};

/// Progress lines, one per load step and level, on a stream (none on a null one); with `eta`,
/// a converged step's line also gives the time elapsed and an estimate of the time left (the
/// driver asks for it when its output is a terminal). Derive from it to observe more.
class ProgressLines : public SolveObserver {
public:
    explicit ProgressLines(std::ostream* os, bool eta = false) : os_(os), eta_(eta) {}
    void level_step_done(const LevelStepProgress& p) override;

private:
    std::ostream* os_;
    bool eta_;
    std::vector<double> seconds_; // per level, over its steps
    std::vector<int> count_;
};

/// An observer that only wraps the Newton-system solvers (SolveObserver::wrap_system_solver)
/// by a function: the benches and tests that record or time the systems.
class SolverWrapper : public SolveObserver {
public:
    using Wrap = std::function<std::unique_ptr<NewtonSystemSolver>(
        int level, const Level& L, std::unique_ptr<NewtonSystemSolver>)>;
    explicit SolverWrapper(Wrap wrap) : wrap_(std::move(wrap)) {}
    std::unique_ptr<NewtonSystemSolver>
    wrap_system_solver(int level, const Level& L,
                       std::unique_ptr<NewtonSystemSolver> solver) override {
        return wrap_(level, L, std::move(solver));
    }

private:
    Wrap wrap_;
};

/// Result of a run.
struct RunResult {
    Hierarchy hierarchy;
    /// level_steps[l][k]: load step k+1 on level l (empty for levels not solved).
    std::vector<std::vector<LevelStep>> level_steps;
    std::vector<StepReport> steps;       ///< finest level, one per load step
    Vector x;                            ///< final unknowns of the finest level
    Vector u_full;                       ///< final nodal displacements (2 per vertex)
    std::vector<ContactNodeState> nodes; ///< final contact node states (finest)
    std::vector<Vector> step_u_full;     ///< finest, per step, when keep_step_states
    std::vector<std::vector<ContactNodeState>> step_nodes; ///< finest, per completed step
    Timings timings;
    /// Predicted sizes, the peak-memory estimate for this run's solver and what the process may
    /// use, all computed before the hierarchy was built.
    std::vector<LevelSize> predicted_sizes;
    /// The Newton-system solver of levels >= 1 (SolveOptions::linear); the driver that chose
    /// it (plan_solver) fills `automatic` and `reason`.
    SolverPlan solver;
    /// The finest level's multigrid (levels, sizes, complexities, smoother, coarse solve) when
    /// its solver uses one.
    std::optional<solvers::MultigridReport> multigrid;
    MemoryEstimate memory;
    MemoryLimit memory_limit;
    bool converged = false;
    std::string failure; ///< diagnosis of the first step that failed (or where the run stopped)
    /// Stopped on request (SolveObserver::stop_requested) before the last load step was complete;
    /// `failure` says where. converged is false.
    bool stopped = false;
    int completed_steps = 0; ///< load steps completed on every solved level
    /// What makes the solution doubtful though it converged (levels/diagnoses.hpp): a rotation
    /// or strain of the finest level too large for small-displacement theory, a solution that
    /// is not unique; and notes on legal but suspicious input (initial_gap_warnings of level 0:
    /// an initial penetration or gap larger than a fraction of the body). One sentence each,
    /// without a "warning:" prefix.
    std::vector<std::string> warnings;
    const Level& finest() const { return hierarchy.finest(); }
    const std::vector<Level>& levels() const { return hierarchy.levels; }
};

/// Builds the hierarchy and solves every load step (see SolveOptions), reporting to `observer`
/// (null: none). Stops at the first level and step that does not converge (RunResult::converged
/// false, failure set). Before building anything it estimates the peak memory of the run
/// (estimate_memory) and throws InvalidInput when that exceeds what the process may use
/// (process_memory_limit), naming both.
RunResult solve(const Problem& problem, const SolveOptions& options = {},
                SolveObserver* observer = nullptr);

} // namespace mlc::levels
