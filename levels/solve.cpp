// SPDX-License-Identifier: MIT
// The load steps and the levels of a run, in named phases.
#include "levels/solve.hpp"
#include "levels/diagnoses.hpp"
#include "levels/initial_gap.hpp"
#include "levels/level_step.hpp"
#include "levels/r_continuation.hpp"
#include "levels/resources.hpp"

#include "core/check.hpp"
#include "core/first_touch.hpp"
#include "core/memory.hpp"
#include "solvers/factory.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <utility>

namespace mlc::levels {

double LevelStep::agreement() const {
    if (!predicted || final_statuses.empty()) return 1.0;
    int same = 0;
    for (size_t e = 0; e < final_statuses.size(); ++e)
        same += predicted_statuses[e] == final_statuses[e];
    return static_cast<double>(same) / static_cast<double>(final_statuses.size());
}

namespace {

// The registry says which preconditioners use the level below.
bool needs_coarse_level(const LinearSolverSpec& spec) {
    return spec.uses_level_below();
}

/// The problem at load step `step`, its levels numbered as the solver needs them
/// (LinearSolverSpec::numbering, set by check_before_building).
Problem numbered_at_step(const Problem& problem, int step, const LinearSolverSpec& spec) {
    Problem p = problem.at_step(step);
    p.numbering = spec.numbering.value_or(problem.numbering);
    return p;
}

/// The checks before anything is built: the problem and the solver are valid, the levels are
/// numbered as the solver needs them (a lattice sweep: by macro triangles), and the run's estimated
/// peak memory fits in what the process may use (throws InvalidInput naming both). Fills the
/// solver, the predicted sizes and the memory figures of `res`.
void check_before_building(const Problem& problem, const SolveOptions& options, RunResult& res) {
    problem.validate();
    options.linear.validate();
    res.solver.spec = options.linear;
    res.solver.spec.numbering = hierarchy_numbering(problem, options.linear);
    res.solver.reason = "as given";
    MLC_CHECK(options.predicted_sizes.empty() ||
                  options.predicted_sizes.size() == static_cast<size_t>(problem.levels) + 1,
              "SolveOptions::predicted_sizes has " << options.predicted_sizes.size()
                                                   << " levels, the problem "
                                                   << problem.levels + 1);
    res.predicted_sizes =
        options.predicted_sizes.empty() ? predict_level_sizes(problem) : options.predicted_sizes;
    res.memory = estimate_memory(res.predicted_sizes, options.linear,
                                 options.coarse_to_fine || options.solve_all_levels ||
                                     needs_coarse_level(options.linear),
                                 {problem.load_steps, options.keep_step_states});
    res.memory_limit = process_memory_limit();
    check_memory_fits(res.memory, res.memory_limit, res.predicted_sizes);
}

/// The contact nodes must stay those of the first step: the per-step states (step_nodes,
/// contact_steps.csv) are read with the final level's contact elements. They change only when a
/// support fully fixes or frees a contactor vertex. Throws InvalidInput when the rebuilt level L
/// (index l) at load step `step` has other contact nodes than `old` (the contactor vertex and
/// multipliers of each element before the rebuild).
void check_same_contact_nodes(const Level& L, const std::vector<std::pair<int, Vector>>& old, int l,
                              int step) {
    bool same = old.size() == L.contacts.size();
    for (size_t e = 0; same && e < old.size(); ++e)
        same = old[e].first == L.contacts[e].vertex[0];
    if (same) return;
    // A vertex that is no longer a contact node (now fully fixed), or a new one.
    std::vector<char> was(static_cast<size_t>(L.mesh.n_vertices()), 0);
    for (const auto& o : old)
        was[static_cast<size_t>(o.first)] = 1;
    int v = -1;
    bool fixed = false;
    for (const auto& o : old)
        if (v < 0 && L.contact_of_vertex[static_cast<size_t>(o.first)] < 0) {
            v = o.first;
            fixed = true;
        }
    for (const auto& c : L.contacts)
        if (v < 0 && !was[static_cast<size_t>(c.vertex[0])]) v = c.vertex[0];
    const Vec2& p = L.mesh.vertices[static_cast<size_t>(std::max(v, 0))];
    MLC_CHECK(false, "load step " << step << ": the supports active from this step on "
                                  << (fixed ? "fix both components of" : "free a component of")
                                  << " the contactor vertex (" << p.x() << ", " << p.y()
                                  << ") on level " << l
                                  << ", which changes the contact nodes; a support that is "
                                     "released or taken up along the path may hold one "
                                     "component of a contactor vertex only");
}

/// The "large rotation", "large strain" and "not unique" warnings of the finest level's largest
/// deformation and first non-unique state over the completed steps.
class DeformationWatch {
public:
    /// The finest level's state at the end of a completed load step.
    void add(const Problem& problem, const Level& F, int step, const Vector& u_full,
             const std::vector<ContactNodeState>& nodes) {
        const Deformation d = max_deformation(F, u_full);
        if (d.rotation > deformation_.rotation) {
            deformation_.rotation = d.rotation;
            deformation_.rotation_triangle = d.rotation_triangle;
            rotation_step_ = step;
        }
        if (d.strain > deformation_.strain) {
            deformation_.strain = d.strain;
            deformation_.strain_triangle = d.strain_triangle;
            strain_step_ = step;
        }
        if (not_unique_.empty()) {
            not_unique_ = unheld_tangential_motion(problem, F, nodes);
            if (!not_unique_.empty())
                not_unique_ = "load step " + std::to_string(step) + ": " + not_unique_;
        }
    }
    /// One sentence per warning, appended to `warnings`.
    void warn(const Level& F, std::vector<std::string>& warnings) const {
        const auto centroid = [&](int t) {
            const auto& tri = F.mesh.cells[static_cast<size_t>(t)];
            Vec2 c = Vec2::Zero();
            for (int v : tri)
                c += F.mesh.vertices[static_cast<size_t>(v)] / 3.0;
            std::ostringstream os;
            os << "triangle " << t << " at (" << c.x() << ", " << c.y() << ")";
            return os.str();
        };
        std::ostringstream os;
        os << std::setprecision(3);
        if (deformation_.rotation > kSmallRotationLimit) {
            os << "large rotation: " << centroid(deformation_.rotation_triangle)
               << " of the finest level rotates by " << deformation_.rotation
               << " rad at load step " << rotation_step_ << ", above " << kSmallRotationLimit
               << " rad: small-displacement theory (linear strains, contact normals and gaps of "
                  "the undeformed shape) does not hold there and the results are not reliable; "
                  "hold the body so that it cannot roll or turn, or reduce the loads";
            warnings.push_back(os.str());
            os.str("");
        }
        if (deformation_.strain > kSmallStrainLimit) {
            os << "large strain: " << centroid(deformation_.strain_triangle)
               << " of the finest level has a principal strain of " << deformation_.strain
               << " at load step " << strain_step_ << ", above " << kSmallStrainLimit
               << ": small-displacement theory (linear elasticity) does not hold there and the "
                  "results are not reliable; reduce the loads or prescribed displacements";
            warnings.push_back(os.str());
        }
        if (!not_unique_.empty()) warnings.push_back(not_unique_);
    }

private:
    Deformation deformation_; // the largest of the completed steps
    int rotation_step_ = 0, strain_step_ = 0;
    std::string not_unique_; // the first completed step whose state is not unique
};

/// The load steps of one run over the levels of its hierarchy: the state of every level, its
/// solver and Newton driver, and what the report collects. run() is the load-step loop; a load
/// step is the level loop (solve_levels) over OneLevel, whose phases are extrapolation, the
/// coarse-to-fine guess, Newton with the r continuation, the report, and what the level above
/// takes from it.
class LoadStepping {
public:
    LoadStepping(const Problem& problem, const SolveOptions& options, SolveObserver* observer,
                 RunResult& res);
    void run();

private:
    void setup_solvers();
    void change_supports(int step);
    class OneLevel;
    bool try_extrapolation(size_t li, double s, LevelStep& ls);
    void interpolate_from_below(size_t li, int step);
    void newton_with_continuation(size_t li, double s, LevelStep& ls);
    void report_level_step(const LevelStep& ls) const;
    std::string failure(int l, int step, double s, const StepReport& rep) const;
    void accept_level(size_t li, int step, double s);
    void finish_load_step(int step, double s);

    const Problem& problem_;
    const SolveOptions& options_;
    SolveObserver* observer_; // the caller's, or null
    SolveObserver& obs_;      // the caller's, or one that does nothing
    RunResult& res_;
    int n_levels_ = 0, finest_ = 0;
    int first_ = 0;      // the lowest level solved
    int phase_step_ = 1; // the load step whose supports the current hierarchy has
    // Solvers, Newton drivers and the level below of each level (fixed while the supports are;
    // the coarse statuses are passed by set_coarse_statuses after every coarse load step).
    std::vector<LevelBelow> below_;
    std::vector<std::unique_ptr<ContactNewton>> newton_;
    std::vector<NewtonSystemSolver*> system_;
    // Per level: the unknowns (the last converged step's, then the current iterate), the nodal
    // displacements at the previous and the current step.
    std::vector<Vector> x_, u_prev_, u_now_;
    std::vector<Vector> x_before_; // each level's state before its solve
    // SolveOptions::extrapolate: each level's state two steps back (x^0 = 0; emptied when the
    // supports change, the states before then being of another set of unknowns).
    std::vector<Vector> x_older_;
    double t_start_ = 0.0;
    // SolveOptions::r_continuation: the factor that worked on each level (0: not needed yet),
    // and the schur solver of its scaled level.
    std::vector<double> continued_;
    std::vector<std::unique_ptr<NewtonSystemSolver>> continuation_solver_;
    DeformationWatch deformation_;
    std::vector<std::unique_ptr<StepLevel>> step_levels_; // levels first..finest, for the loop
};

/// A level of the hierarchy in the level loop (levels/level_step.hpp): its state is the run's.
class LoadStepping::OneLevel final : public StepLevel {
public:
    OneLevel(LoadStepping& run, int l) : run_(run), l_(l), li_(static_cast<size_t>(l)) {}
    ContactNewton& newton() override { return *run_.newton_[li_]; }
    const Vector& u_prev() const override { return run_.u_prev_[li_]; }
    Vector& x() override { return run_.x_[li_]; }
    int index() const override { return l_; }
    void begin_step() override {
        if (run_.options_.transfer_increment) run_.x_before_[li_] = run_.x_[li_]; // for above
    }
    bool extrapolate(double s, LevelStep& ls) override {
        return run_.try_extrapolation(li_, s, ls);
    }
    bool interpolate(int step) override {
        if (!run_.options_.coarse_to_fine || l_ == run_.first_) return false;
        run_.interpolate_from_below(li_, step);
        return true;
    }
    void solve(int step, double s, LevelStep& ls) override {
        try {
            run_.newton_with_continuation(li_, s, ls);
        } catch (const Interrupted& e) {
            throw Interrupted("load step " + std::to_string(step) + "/" +
                              std::to_string(run_.problem_.load_steps) + " on level " +
                              std::to_string(l_) + ": " + e.what());
        }
    }
    const StepReport& report(LevelStep ls) override {
        run_.report_level_step(ls);
        if (l_ == run_.finest_) run_.res_.steps.push_back(ls.report);
        run_.res_.level_steps[li_].push_back(std::move(ls));
        return run_.res_.level_steps[li_].back().report;
    }
    void fail(int step, double s, const StepReport& rep) override {
        run_.res_.failure = run_.failure(l_, step, s, rep);
        run_.res_.stopped = rep.stopped;
        run_.res_.converged = false;
    }
    void accept(int step, double s) override { run_.accept_level(li_, step, s); }

private:
    LoadStepping& run_;
    int l_;
    size_t li_;
};

SolveObserver& no_observer() {
    static SolveObserver none;
    return none;
}

LoadStepping::LoadStepping(const Problem& problem, const SolveOptions& options,
                           SolveObserver* observer, RunResult& res)
    : problem_(problem), options_(options), observer_(observer),
      obs_(observer ? *observer : no_observer()), res_(res) {
    // Supports released or taken up between load steps (Support::active) change which components
    // are unknowns: the hierarchy, its solvers and Newton drivers are then rebuilt for the new
    // step's supports (Problem::at_step), and the state carried over through the nodal values.
    res.hierarchy = build_hierarchy(numbered_at_step(problem, 1, res.solver.spec), options.q_rule,
                                    &res.timings);
    const auto& levels = res.hierarchy.levels;
    res.warnings = initial_gap_warnings(problem, levels.front());
    n_levels_ = res.hierarchy.n_levels();
    finest_ = n_levels_ - 1;
    const bool all_levels =
        options.coarse_to_fine || options.solve_all_levels || needs_coarse_level(options.linear);
    first_ = all_levels ? 0 : finest_;
    const auto n = static_cast<size_t>(n_levels_);
    below_.resize(n);
    newton_.resize(n);
    system_.assign(n, nullptr);
    setup_solvers();
    x_.resize(n);
    u_prev_.resize(n);
    u_now_.resize(n);
    for (size_t li = 0; li < n; ++li) {
        x_[li] = Vector::Zero(levels[li].n_unknowns());
        u_prev_[li] = Vector::Zero(2 * levels[li].mesh.n_vertices());
    }
    x_before_.resize(n);
    x_older_.resize(n);
    if (options.extrapolate)
        for (size_t li = 0; li < n; ++li)
            x_older_[li] = Vector::Zero(x_[li].size());
    res.level_steps.resize(n);
    res.converged = true;
    t_start_ = wall_seconds();
    continued_.assign(n, 0.0);
    continuation_solver_.resize(n);
    for (int l = first_; l < n_levels_; ++l)
        step_levels_.push_back(std::make_unique<OneLevel>(*this, l));
}

void LoadStepping::setup_solvers() {
    const auto& levels = res_.hierarchy.levels;
    for (int l = first_; l < n_levels_; ++l) {
        const auto li = static_cast<size_t>(l);
        ScopedTimer t(&res_.timings, "setup/linear_solver");
        const Level& L = levels[li];
        LinearSolverSpec spec = options_.linear;
        if (l == 0 && l != finest_) spec = LinearSolverSpec{};
        if (options_.exact_fallback && spec.method == solvers::Method::krylov)
            spec.give_up_budget = kFallbackKrylovBudget;
        auto& lb = below_[li];
        lb = LevelBelow{};
        if (l > first_) {
            lb.coarse = &levels[li - 1];
            lb.transfer = &res_.hierarchy.transfers[li - 1];
            lb.solver = system_[li - 1];
            if (l - 1 > first_) lb.below = &below_[li - 1];
        }
        auto sys = make_newton_system_solver(L, spec, &lb);
        sys = obs_.wrap_system_solver(l, L, std::move(sys));
        system_[li] = sys.get();
        newton_[li] =
            std::make_unique<ContactNewton>(L, problem_.newton, std::move(sys), &res_.timings);
        if (options_.exact_fallback && spec.method == solvers::Method::krylov) {
            const LevelSize size = res_.predicted_sizes[li];
            newton_[li]->set_fallback([&L, size, l]() {
                const std::string why = schur_does_not_fit(size, l);
                MLC_CHECK(why.empty(), why);
                return make_schur_system_solver(L);
            });
        }
        if (observer_) {
            newton_[li]->set_interrupt([o = observer_] { return o->interrupt_requested(); });
            newton_[li]->set_stop([o = observer_] { return o->stop_requested(); });
        }
    }
}

void LoadStepping::change_supports(int step) {
    const auto& levels = res_.hierarchy.levels;
    // New supports: rebuild, then carry the state over. Displacements through the nodal
    // values at the end of the previous step (u_prev, every component, prescribed or
    // not), multipliers by contactor vertex.
    std::vector<std::vector<std::pair<int, Vector>>> lambda(static_cast<size_t>(n_levels_));
    for (int l = first_; l < n_levels_; ++l) {
        const auto li = static_cast<size_t>(l);
        const Level& L = levels[li];
        for (size_t e = 0; e < L.contacts.size(); ++e)
            lambda[li].emplace_back(L.contacts[e].vertex[0],
                                    x_[li].segment(L.lambda_dof[e], L.contacts[e].n_multipliers()));
    }
    for (auto& nw : newton_)
        nw.reset(); // they refer to the levels about to be replaced
    for (auto& c : continuation_solver_)
        c.reset(); // likewise (SolveOptions::r_continuation starts over)
    std::fill(continued_.begin(), continued_.end(), 0.0);
    {
        ScopedTimer t(&res_.timings, "setup/supports_changed");
        try {
            res_.hierarchy = build_hierarchy(numbered_at_step(problem_, step, res_.solver.spec),
                                             options_.q_rule, &res_.timings);
        } catch (const InvalidInput& e) {
            throw InvalidInput("load step " + std::to_string(step) +
                               ", with the supports active from this step on: " + e.what());
        }
    }
    MLC_CHECK(res_.hierarchy.n_levels() == n_levels_,
              "internal error: the rebuilt hierarchy has another number of levels");
    for (int l = first_; l < n_levels_; ++l)
        check_same_contact_nodes(levels[static_cast<size_t>(l)], lambda[static_cast<size_t>(l)], l,
                                 step);
    setup_solvers();
    phase_step_ = step;
    for (auto& xo : x_older_)
        xo.resize(0);
    for (int l = 0; l < n_levels_; ++l) {
        const auto li = static_cast<size_t>(l);
        const Level& L = levels[li];
        x_[li] = Vector::Zero(L.n_unknowns());
        for (int v = 0; v < L.mesh.n_vertices(); ++v)
            for (int c = 0; c < 2; ++c)
                if (const int d = L.dofs.u_dof(v, c); d >= 0) x_[li][d] = u_prev_[li][2 * v + c];
        for (const auto& [v, lam] : lambda[li]) {
            const int e = L.contact_of_vertex[static_cast<size_t>(v)];
            if (e >= 0 &&
                L.contacts[static_cast<size_t>(e)].n_multipliers() == static_cast<int>(lam.size()))
                x_[li].segment(L.lambda_dof[static_cast<size_t>(e)], lam.size()) = lam;
        }
    }
}

void LoadStepping::run() {
    for (int step = 1; step <= problem_.load_steps && res_.converged; ++step) {
        const double s = static_cast<double>(step) / problem_.load_steps;
        if (!problem_.same_supports(step, phase_step_)) change_supports(step);
        std::vector<StepLevel*> levels;
        for (const auto& l : step_levels_)
            levels.push_back(l.get());
        if (!solve_levels(levels, step, s)) break;
        finish_load_step(step, s);
    }
    res_.x = x_.back();
    deformation_.warn(res_.hierarchy.levels[static_cast<size_t>(finest_)], res_.warnings);
    if (const solvers::Multigrid* mg = system_[static_cast<size_t>(finest_)]->multigrid())
        res_.multigrid = mg->report();
}

bool LoadStepping::try_extrapolation(size_t li, double s, LevelStep& ls) {
    // SolveOptions::extrapolate: the level's own state extrapolated from its last two steps,
    // taken when Newton would stop there at once (the step is then linear: no status changed);
    // otherwise the usual guess, as without the option.
    if (!options_.extrapolate) return false;
    if (x_older_[li].size() != x_[li].size()) {
        x_older_[li] = x_[li];
        return false;
    }
    Vector older = std::exchange(x_older_[li], x_[li]);
    return take_extrapolation(*newton_[li], s, u_prev_[li], older, x_[li], ls);
}

void LoadStepping::interpolate_from_below(size_t li, int step) {
    // Initial guess (P u_H, Q lambda_H): displacements through the full nodal vectors
    // (prescribed values included), multipliers through Q.
    ScopedTimer t(&res_.timings, "newton/interpolate");
    const Level& L = res_.hierarchy.levels[li];
    const auto& T = res_.hierarchy.transfers[li - 1];
    // Increment mode: interpolate the coarse change over this step and add it to the
    // level's own previous state (x[li] still holds step - 1).
    const bool inc = options_.transfer_increment && step > 1;
    Vector uf;
    T.interpolate_nodal(inc ? Vector(u_now_[li - 1] - u_prev_[li - 1]) : u_now_[li - 1], uf);
    const Vector inc_coarse = inc ? Vector(x_[li - 1] - x_before_[li - 1]) : Vector();
    const Vector& xc = inc ? inc_coarse : x_[li - 1];
    Vector& xl = x_[li];
    parallel::for_rows(static_cast<size_t>(L.mesh.n_vertices()), parallel::kTouchRowsPerChunk / 2,
                       [&](size_t b, size_t e) {
                           for (auto v = static_cast<int>(b); v < static_cast<int>(e); ++v)
                               for (int c = 0; c < 2; ++c)
                                   if (const int d = L.dofs.u_dof(v, c); d >= 0)
                                       xl[d] = (inc ? xl[d] : 0.0) + uf[2 * v + c];
                       });
    // Q's rows of the multipliers only (Q is zero on the displacement rows); the sums
    // of Eigen's row-major `T.Q * xc`, whose result starts at zero.
    const SparseMatrix& Q = T.Q;
    for (size_t e = 0; e < L.contacts.size(); ++e)
        for (int k = 0; k < L.contacts[e].n_multipliers(); ++k) {
            const Index d = L.lambda_dof[e] + k;
            double row = 0.0;
            for (SparseMatrix::InnerIterator it(Q, d); it; ++it)
                row += it.value() * xc[it.index()];
            xl[d] = (inc ? xl[d] : 0.0) + (0.0 + 1.0 * row);
        }
}

void LoadStepping::newton_with_continuation(size_t li, double s, LevelStep& ls) {
    Level& L = res_.hierarchy.levels[li];
    ContactNewton& nw = *newton_[li];
    const Vector x0 = options_.r_continuation ? x_[li] : Vector();
    if (continued_[li] > 0) {
        // Newton at r failed on this level in an earlier step: straight to the
        // continuation (a failed attempt at r would only cost).
        ls.report = StepReport{};
        ls.report.load_factor = s;
        ls.report.message = "as in an earlier load step of this level";
    } else {
        ls.report = nw.solve(s, u_prev_[li], x_[li]);
    }
    if (!options_.r_continuation || ls.report.converged || ls.report.stopped || L.contacts.empty())
        return;
    x_[li] = x0;
    NewtonPolls polls;
    if (observer_) {
        polls.stop = [o = observer_] { return o->stop_requested(); };
        polls.interrupt = [o = observer_] { return o->interrupt_requested(); };
    }
    ls.report = continue_in_r(L, static_cast<int>(li), res_.predicted_sizes[li], problem_.newton,
                              nw, s, u_prev_[li], x0, x_[li], std::move(ls.report), continued_[li],
                              continuation_solver_[li], polls, &res_.timings);
    continued_[li] = ls.report.continuation_factor;
}

void LoadStepping::report_level_step(const LevelStep& ls) const {
    LevelStepProgress p;
    p.step = &ls;
    p.load_steps = problem_.load_steps;
    p.n_levels = n_levels_;
    p.first_level = first_;
    p.levels = &res_.hierarchy.levels;
    p.elapsed = wall_seconds() - t_start_;
    obs_.level_step_done(p);
}

std::string LoadStepping::failure(int l, int step, double s, const StepReport& rep) const {
    std::ostringstream os;
    if (rep.stopped) {
        os << "stopped during load step " << step << " of " << problem_.load_steps
           << " (load factor " << s << ")";
        if (n_levels_ > 1) os << " on level " << l;
        os << " after " << rep.iterations << " Newton iterations; " << res_.completed_steps
           << " load steps completed";
        return os.str();
    }
    const Level& L = res_.hierarchy.levels[static_cast<size_t>(l)];
    os << "load step " << step << " (load factor " << s << ")";
    if (n_levels_ > 1) os << " on level " << l;
    // The cause, when it is one of the problem's (a load with no equilibrium, a
    // rigid motion nothing holds), comes first: how Newton failed on it follows.
    std::string why = no_equilibrium(problem_, L, s);
    if (why.empty() && rep.counts.stick == 0 &&
        rep.counts.slip_forward + rep.counts.slip_backward > 0) {
        // Newton's last iterate (the report's statuses): no node sticks. Whether a
        // free rigid motion is tangential at every contact node is then all to ask.
        std::vector<ContactNodeState> slipping(L.contacts.size());
        for (auto& n : slipping)
            n.status = contact::Status::slip_forward;
        why = unheld_tangential_motion(problem_, L, slipping);
    }
    if (!why.empty()) os << ": " << why << ". Newton";
    os << " did not converge: " << rep.message << "; residual history:" << residual_history(rep);
    return os.str();
}

void LoadStepping::accept_level(size_t li, int step, double s) {
    const Level& L = res_.hierarchy.levels[li];
    ContactNewton& nw = *newton_[li];
    L.dofs.expand(x_[li], L.u_fixed_at(s), u_now_[li]);
    LevelStepState st;
    st.level = static_cast<int>(li);
    st.step = step;
    st.s = s;
    st.L = &L;
    st.u_full = &u_now_[li];
    st.node_states = [&] { return nw.node_states(s, u_prev_[li], x_[li]); };
    obs_.level_step(st);
    if (static_cast<int>(li) + 1 < n_levels_) {
        // The level above's preconditioner (cf, sorcf, mg) uses this level at its
        // converged statuses.
        Vector R(x_[li].size());
        std::vector<Eigen::Matrix2d> converged;
        nw.residual(s, u_prev_[li], x_[li], R, nullptr, &converged, nullptr);
        system_[li + 1]->set_coarse_statuses(converged);
    }
}

void LoadStepping::finish_load_step(int step, double s) {
    res_.nodes = newton_.back()->node_states(s, u_prev_.back(), x_.back());
    res_.u_full = u_now_.back();
    if (options_.keep_step_states) res_.step_u_full.push_back(res_.u_full);
    res_.step_nodes.push_back(res_.nodes);
    res_.completed_steps = step;
    // Small-displacement theory and uniqueness, on the finest level at this step.
    deformation_.add(problem_, res_.hierarchy.levels[static_cast<size_t>(finest_)], step,
                     res_.u_full, res_.nodes);
    for (int l = first_; l < n_levels_; ++l)
        u_prev_[static_cast<size_t>(l)] = u_now_[static_cast<size_t>(l)];
}

} // namespace

RunResult solve(const Problem& problem, const SolveOptions& options, SolveObserver* observer) {
    RunResult res;
    check_before_building(problem, options, res);
    LoadStepping(problem, options, observer, res).run();
    return res;
}

} // namespace mlc::levels
