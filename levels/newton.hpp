// SPDX-License-Identifier: MIT
/// @file Generalized Newton method over contact statuses for one level and one load step
/// (Alart & Curnier; formulation.md §2), with the Jacobian pattern fixed per level.
#pragma once

#include "contact/law.hpp"
#include "core/communicator.hpp"
#include "core/linear_operator.hpp"
#include "core/timer.hpp"
#include "levels/level.hpp"
#include "levels/newton_system.hpp"

#include <functional>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

namespace mlc::levels {

/// Number of contact nodes per status.
struct StatusCounts {
    int gap = 0, stick = 0, slip_forward = 0, slip_backward = 0, slip = 0;
    void add(contact::Status s);
    int total() const { return gap + stick + slip_forward + slip_backward + slip; }
};

/// What one load step's Newton did.
struct StepReport {
    int step = 0; ///< 1-based load step
    double load_factor = 0.0;
    bool converged = false;
    int iterations = 0;              ///< Newton iterations (linear solves)
    std::vector<double> residuals;   ///< ||R|| / scale at each iterate (first = initial)
    std::vector<int> status_changes; ///< statuses changed between consecutive iterates
    StatusCounts counts;             ///< final statuses (reported, see node_statuses)
    int linear_iterations = 0;       ///< Krylov iterations summed over the step (0 if direct)
    std::vector<int> linear_iterations_per_newton; ///< Krylov iterations of each Newton system
    double linear_seconds = 0.0;          ///< time in the Newton-system solves (setup + solve)
    double linear_setup_seconds = 0.0;    ///< of which Jacobian assembly and preconditioner setup
    double linear_assembly_seconds = 0.0; ///< of which Jacobian assembly
    int inexact_steps = 0;                ///< steps taken from a Krylov solve stopped at max_iter
    int cycling_detected_at = -1;         ///< iterate at which statuses returned to an earlier set
    int damped_steps = 0;                 ///< steps taken with backtracking on ||R|| after cycling
    /// Newton systems solved again by the exact fallback solver after the solver failed on them
    /// (ContactNewton::set_fallback), and why the first of them failed.
    int fallback_solves = 0;
    std::string fallback_reason;
    /// r continuation (SolveOptions::r_continuation): when Newton failed at the scene's r, the
    /// step was solved again from the same initial guess at continuation_factor * r with the
    /// exact schur solver, and Newton at the scene's r was restarted from that solution (the
    /// discrete contact solution does not depend on r; the convergence test is the one at the
    /// scene's r). 0: not used. `iterations` counts every Newton iteration of the step, those of
    /// the failed attempt and of the reduced r included; continuation_iterations the latter two.
    double continuation_factor = 0.0;
    int continuation_iterations = 0;
    std::string continuation_note; ///< what failed at r and what the continuation did
    double seconds = 0.0;
    std::string message;  ///< diagnosis when not converged
    bool stopped = false; ///< stopped on request (ContactNewton::set_stop), not converged
};

/// The full state of a contact node at a converged (or last) iterate, for reports and output,
/// in `dim` dimensions. A tangential quantity is a number in 2D (along t) and a 2-vector in 3D
/// (along t1, t2: contact::tangent_basis).
template <int dim> struct BasicContactNodeState {
    using Point = Eigen::Matrix<double, dim, 1>;
    using Tangential = std::conditional_t<dim == 2, double, Eigen::Matrix<double, dim - 1, 1>>;
    int vertex = -1;
    Point x = Point::Zero(); ///< reference position
    Point u = Point::Zero(); ///< displacement (global axes)
    Tangential lambda_t = Tangential{}; ///< tangential multiplier(s) in the tangent basis
    double lambda_n = 0.0;
    double d_n = 0.0;              ///< gap
    Tangential d_t = Tangential{}; ///< slip increment of the step in the tangent basis
    contact::Status status = contact::Status::gap;
    /// 3D, status slip: the unit slip direction sigma_t / |sigma_t| in the tangent basis (the
    /// projection's; 0 otherwise). Unused in 2D (the status says forward or backward).
    Tangential slip_direction = Tangential{};
    /// The contact frame: n and the tangents (columns) of the element.
    Point n = Point::Zero();
    Eigen::Matrix<double, dim, dim - 1> t = Eigen::Matrix<double, dim, dim - 1>::Zero();
};

/// The 2D contact node state.
using ContactNodeState = BasicContactNodeState<2>;
/// The 3D contact node state.
using ContactNodeState3 = BasicContactNodeState<3>;

/// One process's share of the Newton of a distributed level (levels/distributed.hpp): the
/// level is this process's part, whose first `n_owned` unknowns are the ones it owns (its contact
/// elements are at owned contact nodes; Level::ghost_contacts add the forces of other processes'
/// elements on owned vertices); iterates, residuals and Newton systems hold the owned
/// entries only, K x is the distributed stiffness's product, and every norm, count and decision is
/// reduced over `comm`, so that all processes take the same steps.
struct NewtonDistribution {
    const Communicator* comm = nullptr; ///< borrowed; null: one process (the default)
    Index n_owned = 0;
    const LinearOperator* K = nullptr; ///< the stiffness on the owned unknowns, borrowed
    /// Collective: overwrites the ghost entries of a vector of the part's unknowns (owned ones
    /// first) with their owners' values (GhostExchange::update), which two-body elements read
    /// (Level::ghost_contacts). Empty: ghost entries are zero (node-on-rigid elements read
    /// owned unknowns only).
    std::function<void(Vector&)> fill_ghosts;
};

/// Generalized Newton on one level in `dim` dimensions (`ContactNewton` in 2D, `ContactNewton3`
/// in 3D; the distribution is 2D so far).
template <int dim> class BasicContactNewton {
public:
    using Level = BasicLevel<dim>;
    using Matrix = StatusMatrix<dim>;
    using Solver = BasicNewtonSystemSolver<dim>;
    using NodeState = BasicContactNodeState<dim>;

    /// `level` must outlive this object. `timings` may be null.
    BasicContactNewton(const Level& level, NewtonParams params, std::unique_ptr<Solver> solver,
                       Timings* timings = nullptr);

    /// Runs Newton for load factor `s` from the initial guess x (updated in place), with the
    /// slip increment measured from `u_prev_full` (full nodal displacements of the previous
    /// converged step). Never throws for non-convergence: see StepReport::converged/message.
    StepReport solve(double s, const Vector& u_prev_full, Vector& x);

    /// solve() allowed no iteration: converged when x already passes the convergence test (the
    /// report is then the one solve would return, 0 iterations); otherwise not converged, x
    /// unchanged and no Newton system solved.
    StepReport check(double s, const Vector& u_prev_full, Vector& x);

    /// Statuses the projection gives at (x, u_prev) for load factor s (the Newton statuses).
    std::vector<contact::Status> statuses(double s, const Vector& u_prev_full,
                                          const Vector& x) const;

    /// Per contact node state (reported statuses: a frictionless node in contact is reported as
    /// slip_forward/backward by the sign of its slip increment, or stick if it did not move).
    /// A gap node reports lambda = (0, 0) exactly, the value of the projection at the converged
    /// state (the iterate carries round-off such as 1e-111).
    std::vector<NodeState> node_states(double s, const Vector& u_prev_full,
                                       const Vector& x) const;

    /// The relative tolerance asked of the iterative solver at Newton iteration k with residual
    /// norm `norm` (NewtonParams::forcing); 0: the solver's own.
    double forcing_term(int k, double norm, double scale) const;

    /// Residual R(x) at load factor s and its scaled norm (force units); also returns statuses
    /// (one per element of level().contacts) and the status matrices M (one per element of
    /// level().contacts, then one per element of level().ghost_contacts).
    double residual(double s, const Vector& u_prev_full, const Vector& x, Vector& R,
                    std::vector<contact::Status>* st, std::vector<Matrix>* M,
                    double* scale) const;

    const Level& level() const { return level_; }
    /// Makes this Newton one process's share of a distributed level's (see NewtonDistribution).
    void set_distribution(NewtonDistribution d);
    /// Hands the Newton-system solver back (this object cannot solve afterwards).
    std::unique_ptr<Solver> release_solver() { return std::move(solver_); }

    /// A fallback for the Newton systems the solver fails on (a Krylov solve that neither
    /// converged nor reduced the residual by half, or a numerical breakdown): `make` builds it on
    /// first use (the driver gives the exact `schur` solver, after checking that it fits in
    /// memory; `make` throws InvalidInput when it does not), and the system is solved again with
    /// it; the later systems of this level are then solved by it directly (a preconditioner
    /// that failed once on a level is not tried again there). Counted in
    /// StepReport::fallback_solves. Without one (default) the failure ends the step.
    void set_fallback(std::function<std::unique_ptr<Solver>()> make) {
        make_fallback_ = std::move(make);
    }
    /// Polled after every Newton iteration: once it returns true, solve() returns after the
    /// current iteration with StepReport::stopped (and converged false). Empty: never stops.
    void set_stop(std::function<bool()> requested) { stop_ = std::move(requested); }
    /// Polled before every iteration of solve(); true stops it by throwing mlc::Interrupted
    /// (levels::SolveObserver::interrupt_requested). Empty: never polled.
    void set_interrupt(std::function<bool()> requested) { interrupt_ = std::move(requested); }

private:
    StepReport solve(double s, const Vector& u_prev_full, Vector& x, int max_iter);
    // The phases of an iteration k of solve(). Whether Newton ends at the current iterate
    // (converged, failed, at max_iter, or stopped on request), with rep.message said why.
    bool stop_test(int k, int max_iter, double norm, double scale, int changes,
                   StepReport& rep) const;
    // The Newton system J(M) dx = b, with the exact fallback when the solver fails; false (and
    // rep.message) when no usable step came out of it.
    bool solve_system(int k, const std::vector<Matrix>& M, const Vector& b, Vector& dx,
                      double forcing, StepReport& rep);
    // x += alpha dx with alpha halved until ||R|| falls below `norm` (after status cycling).
    void damped_step(double s, const Vector& u_prev_full, const Vector& dx, double norm,
                     Vector& x) const;
    const Level& level_;
    NewtonParams params_;
    std::unique_ptr<Solver> solver_;
    Timings* timings_;
    std::function<std::unique_ptr<Solver>()> make_fallback_;
    std::unique_ptr<Solver> fallback_;
    std::function<bool()> stop_;
    std::function<bool()> interrupt_;
    NewtonDistribution dist_;
    Index n_iterate() const { return dist_.comm ? dist_.n_owned : level_.n_unknowns(); }
    // The iterate padded to the level's unknowns (zeros past the owned ones) when distributed.
    const Vector& padded(const Vector& x, Vector& work) const;
};

extern template class BasicContactNewton<2>;
extern template class BasicContactNewton<3>;
/// Generalized Newton on a 2D level.
using ContactNewton = BasicContactNewton<2>;
/// Generalized Newton on a 3D level.
using ContactNewton3 = BasicContactNewton<3>;

} // namespace mlc::levels
