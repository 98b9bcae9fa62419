// SPDX-License-Identifier: MIT
// Coarse-to-fine Newton over the distributed levels, with the distributed multigrid.
#include "levels/distributed_solve.hpp"

#include "comm/world.hpp"
#include "contact/element.hpp"
#include "core/check.hpp"
#include "levels/krylov_system.hpp"
#include "levels/level_step.hpp"
#include "levels/newton.hpp"
#include "levels/newton_system.hpp"
#include "smoothers/block_sor.hpp"
#include "solvers/factory.hpp"
#include "solvers/krylov.hpp"

#include <Eigen/SparseLU>

#include <cmath>
#include <iomanip>
#include <optional>
#include <sstream>

namespace mlc::levels {

namespace {

/// The NewtonSystemSolver of distributed level k.
class DistributedSystem final : public NewtonSystemSolver {
public:
    DistributedSystem(DistributedMultigrid& s, size_t k) : s_(s), k_(k) {}
    using NewtonSystemSolver::solve;
    SolveResult solve(const std::vector<Eigen::Matrix2d>& M, const Vector& b, Vector& dx,
                      double forcing) override {
        return s_.solve(k_, M, b, dx, forcing);
    }
    std::string name() const override { return s_.name(); }
    void prepare(const std::vector<Eigen::Matrix2d>& M) override { s_.prepare(k_, M); }

private:
    DistributedMultigrid& s_;
    size_t k_;
};

} // namespace

namespace {

/// Sums a confusion table over the processes.
void reduce_confusion(const Communicator& comm, Confusion& c) {
    std::array<int, 16> flat{};
    for (size_t i = 0; i < 4; ++i)
        for (size_t j = 0; j < 4; ++j)
            flat[4 * i + j] = c[i][j];
    comm.allreduce(std::span<int>(flat), ReduceOp::sum);
    for (size_t i = 0; i < 4; ++i)
        for (size_t j = 0; j < 4; ++j)
            c[i][j] = flat[4 * i + j];
}

/// The checks before anything is built, alike on every process: the partition level, the
/// coarse-to-fine mode, supports that stay, the distributed multigrid's options (returned), and
/// the memory of a process (about 1/N of the one-process run, the processes on one machine
/// sharing its memory).
solvers::MultigridParams check_distributable(const Problem& problem, const SolveOptions& options,
                                             const Communicator& comm, int p) {
    const int L = problem.levels;
    MLC_CHECK(p >= 0 && p < L, "the partition level must lie in [0, " << L - 1 << "] for --levels "
                                                                      << L << ", found " << p);
    MLC_CHECK(options.coarse_to_fine,
              "on several processes the levels are solved coarse to fine (--cold is one process "
              "only)");
    for (int step = 2; step <= problem.load_steps; ++step)
        MLC_CHECK(problem.same_supports(step, 1),
                  "supports released or taken up along the loading path are solved on one "
                  "process only so far (load step "
                      << step << ")");
    const solvers::MultigridParams mg = distributed_mg_params(options.linear);
    const auto sizes = predict_level_sizes(problem);
    const MemoryEstimate one =
        estimate_memory(sizes, options.linear, true, {problem.load_steps, false});
    MemoryEstimate per = one;
    // The per-step data is kept whole on every process.
    per.bytes =
        1.15 * (one.bytes - one.steps_bytes) / comm.size() * comm::processes_on_this_machine() +
        one.steps_bytes * comm::processes_on_this_machine();
    const MemoryLimit limit = process_memory_limit();
    std::string error;
    try {
        check_memory_fits(per, limit, sizes);
    } catch (const InvalidInput& e) {
        error = std::string(e.what()) + " (the " +
                std::to_string(comm::processes_on_this_machine()) +
                " processes on this machine together; each holds about 1/" +
                std::to_string(comm.size()) + " of the run)";
    }
    MLC_CHECK(
        comm.max(error.empty() ? 0 : 1) == 0,
        (error.empty() ? std::string("the run does not fit in another process's memory") : error));
    return mg;
}

/// The partitioned level p and this process's part of it and of the levels above, and the
/// transfers between them, into res.levels and res.transfers.
void build_distributed_levels(const Problem& problem, const SolveOptions& options,
                              const Communicator& comm, int p, DistributedRunResult& res) {
    mesh::Mesh mp = problem.mesh0;
    {
        ScopedTimer t(&res.timings, "setup/refine");
        for (int l = 0; l < p; ++l)
            mp = mesh::refine(mp);
    }
    {
        // The partition and the refined parts, then each part's levels (as "setup/levels" of
        // one process: numbering, assembly, contact elements).
        std::optional<ScopedTimer> t1(std::in_place, &res.timings, "setup/distribute");
        auto dh =
            mesh::distribute(mp, problem.levels - p, comm, {}, contact_ghost_reach(problem, mp));
        mp = mesh::Mesh{};
        t1.reset();
        ScopedTimer t2(&res.timings, "setup/levels");
        for (auto& lv : dh.levels)
            res.levels.push_back(build_distributed_level(problem, std::move(lv), comm));
    }
    ScopedTimer t(&res.timings, "setup/transfers");
    for (size_t k = 1; k < res.levels.size(); ++k)
        res.transfers.push_back(
            build_distributed_transfer(res.levels[k - 1], res.levels[k], comm, options.q_rule));
}

/// The load steps of the distributed levels p+1..L: after each converged load step of level p
/// (solved on every process by levels::solve), step() takes level p's state to this process's
/// part of it and solves the same step on the distributed levels, coarse to fine, each level in
/// the level loop of levels::solve (solve_levels over Part, levels/level_step.hpp), with the
/// status counts and the confusion reduced over the processes.
class DistributedSteps {
public:
    DistributedSteps(const Problem& problem, const SolveOptions& options, const Communicator& comm,
                     int p, SolveObserver* observer, DistributedRunResult& res);
    /// Level p's load step `st` converged: solves it on the distributed levels.
    void step(const LevelStepState& st);
    /// A distributed level failed (the serial solve is then stopped).
    bool failed() const { return failed_; }
    /// The finest level's state, into res.
    void finish();

private:
    void take_level_p(const LevelStepState& st);
    class Part;
    void interpolate_from_below(size_t k, Vector& xo);
    void accept_level(size_t k, double s, const Vector& xo);

    const Problem& problem_;
    const SolveOptions& options_;
    const Communicator& comm_;
    int p_;
    DistributedRunResult& res_;
    size_t m_; // distributed levels above p: 1..m
    std::unique_ptr<DistributedMultigrid> mg_;
    std::vector<std::unique_ptr<ContactNewton>> newton_;
    // Per level: the state of the last converged step (local unknowns with ghosts, nodal
    // displacements of the part's vertices).
    std::vector<Vector> x_, u_prev_, u_now_;
    Vector u_prev_p_; // level p's (serial) nodal displacements at the previous step
    // SolveOptions::extrapolate: each distributed level's owned state at the last two steps
    // (x^0 = 0: the supports never change on several processes).
    std::vector<Vector> xo_last_, xo_older_;
    std::vector<Vector> xo_; // each level's owned iterate in the current step
    std::vector<std::unique_ptr<StepLevel>> parts_; // levels 1..m, for the level loop
    bool failed_ = false;
    SolveObserver* progress_; // the caller's observer on rank 0, null elsewhere
};

/// This process's part of distributed level k in the level loop (levels/level_step.hpp): it
/// iterates on its owned unknowns, takes its guess from the part of the level below, and sums
/// its status counts and confusion over the processes.
class DistributedSteps::Part final : public StepLevel {
public:
    Part(DistributedSteps& run, size_t k) : run_(run), k_(k) {}
    ContactNewton& newton() override { return *run_.newton_[k_]; }
    const Vector& u_prev() const override { return run_.u_prev_[k_]; }
    Vector& x() override { return run_.xo_[k_]; }
    int index() const override { return run_.p_ + static_cast<int>(k_); }
    void begin_step() override { run_.xo_[k_].resize(run_.res_.levels[k_].n_owned); }
    bool extrapolate(double s, LevelStep& ls) override {
        // As levels::solve does (SolveOptions::extrapolate): the extrapolated state when Newton
        // would stop there at once, otherwise the interpolated coarse state.
        if (!run_.options_.extrapolate) return false;
        x() = run_.xo_last_[k_];
        return take_extrapolation(newton(), s, u_prev(), run_.xo_older_[k_], x(), ls);
    }
    bool interpolate(int /*step*/) override {
        run_.interpolate_from_below(k_, x());
        return true;
    }
    void solve(int /*step*/, double s, LevelStep& ls) override {
        ls.report = newton().solve(s, u_prev(), x());
    }
    void reduce(LevelStep& ls) override {
        ls.report.counts = reduce_counts(run_.comm_, ls.report.counts);
        reduce_confusion(run_.comm_, ls.confusion);
    }
    void settle(const LevelStep& /*ls*/) override {
        if (!run_.options_.extrapolate) return;
        run_.xo_older_[k_] = std::move(run_.xo_last_[k_]);
        run_.xo_last_[k_] = x();
    }
    const StepReport& report(LevelStep ls) override {
        if (run_.progress_) {
            LevelStepProgress lp;
            lp.step = &ls;
            lp.load_steps = run_.problem_.load_steps;
            lp.n_levels = run_.problem_.levels + 1;
            lp.first_level = 0;
            lp.processes = run_.comm_.size();
            run_.progress_->level_step_done(lp);
        }
        if (k_ == run_.m_) run_.res_.steps.push_back(ls.report);
        run_.res_.level_steps[k_].push_back(std::move(ls));
        return run_.res_.level_steps[k_].back().report;
    }
    void fail(int step, double s, const StepReport& rep) override {
        std::ostringstream os;
        os << "load step " << step << " (load factor " << s << ") on level " << index()
           << " did not converge: " << rep.message
           << "; residual history:" << residual_history(rep);
        run_.res_.failure = os.str();
    }
    void accept(int /*step*/, double s) override { run_.accept_level(k_, s, x()); }

private:
    DistributedSteps& run_;
    size_t k_;
};

DistributedSteps::DistributedSteps(const Problem& problem, const SolveOptions& options,
                                   const Communicator& comm, int p, SolveObserver* observer,
                                   DistributedRunResult& res)
    : problem_(problem), options_(options), comm_(comm), p_(p), res_(res),
      m_(res.levels.size() - 1), progress_(comm.rank() == 0 ? observer : nullptr) {
    mg_ = std::make_unique<DistributedMultigrid>(res.levels, res.transfers, comm, options.linear,
                                                 res.mg);
    newton_.resize(m_ + 1);
    const bool two_body =
        std::any_of(problem.contacts.begin(), problem.contacts.end(), [](const ContactPair& c) {
            return c.element != ContactElementKind::node_on_rigid;
        });
    for (size_t k = 1; k <= m_; ++k) {
        newton_[k] = std::make_unique<ContactNewton>(res.levels[k].local, problem.newton,
                                                     std::make_unique<DistributedSystem>(*mg_, k),
                                                     &res.timings);
        const DistributedLevel& D = res.levels[k];
        NewtonDistribution nd{&comm, D.n_owned, D.K.get(), {}};
        // Two-body elements read ghost values (every process alike: the call is collective).
        if (two_body) nd.fill_ghosts = [&D](Vector& x) { D.ghosts.update(D.local.dofs, x); };
        newton_[k]->set_distribution(std::move(nd));
        if (observer)
            newton_[k]->set_interrupt([observer] { return observer->interrupt_requested(); });
    }
    res.level_steps.resize(m_ + 1);
    x_.resize(m_ + 1);
    u_prev_.resize(m_ + 1);
    u_now_.resize(m_ + 1);
    for (size_t k = 0; k <= m_; ++k) {
        x_[k] = Vector::Zero(res.levels[k].local.n_unknowns());
        u_prev_[k] = Vector::Zero(2 * res.levels[k].local.mesh.n_vertices());
    }
    xo_last_.resize(m_ + 1);
    xo_older_.resize(m_ + 1);
    for (size_t k = 1; k <= m_; ++k)
        xo_last_[k] = xo_older_[k] = Vector::Zero(res.levels[k].n_owned);
    xo_.resize(m_ + 1);
    for (size_t k = 1; k <= m_; ++k)
        parts_.push_back(std::make_unique<Part>(*this, k));
}

void DistributedSteps::take_level_p(const LevelStepState& st) {
    const Level& Lp = *st.L;
    const std::vector<ContactNodeState>& nodes = st.nodes();
    if (u_prev_p_.size() != st.u_full->size()) u_prev_p_ = Vector::Zero(st.u_full->size());
    // Level p's converged state on its unknowns, and its statuses.
    Vector xs = Vector::Zero(Lp.n_unknowns());
    for (int v = 0; v < Lp.mesh.n_vertices(); ++v)
        for (int c = 0; c < 2; ++c)
            if (const int d = Lp.dofs.u_dof(v, c); d >= 0) xs[d] = (*st.u_full)[2 * v + c];
    for (size_t e = 0; e < Lp.contacts.size(); ++e) {
        const auto& ns = nodes[e];
        const int d = Lp.lambda_dof[e];
        if (Lp.contacts[e].n_multipliers() == 2) {
            xs[d] = ns.lambda_t;
            xs[d + 1] = ns.lambda_n;
        } else {
            xs[d] = ns.lambda_n;
        }
    }
    std::vector<Eigen::Matrix2d> Mp(Lp.contacts.size());
    for (size_t e = 0; e < Lp.contacts.size(); ++e)
        Mp[e] =
            contact::evaluate(Lp.contacts[e], *st.u_full, u_prev_p_, xs, Lp.lambda_dof[e]).proj.M;
    {
        ScopedTimer t(&res_.timings, "distributed/coarse_setup");
        mg_->set_coarse(Lp, Mp);
    }
    // Level p's part: its local unknowns and nodal values, from the serial state.
    const DistributedLevel& D = res_.levels[0];
    const auto& dofs = D.local.dofs;
    u_now_[0].resize(2 * D.local.mesh.n_vertices());
    for (int v = 0; v < D.local.mesh.n_vertices(); ++v) {
        const int vp = D.part.vertex_location[static_cast<size_t>(v)].id;
        for (int c = 0; c < 2; ++c) {
            u_now_[0][2 * v + c] = (*st.u_full)[2 * vp + c];
            if (const int d = dofs.u_dof(v, c); d >= 0) x_[0][d] = xs[Lp.dofs.u_dof(vp, c)];
        }
        const int e = dofs.extra_dof(v);
        for (int q = 0; e >= 0 && q < D.n_extra[static_cast<size_t>(v)]; ++q)
            x_[0][e + q] = xs[Lp.dofs.extra_dof(vp) + q];
    }
}

void DistributedSteps::step(const LevelStepState& st) {
    if (st.level != p_ || failed_) return;
    const double t0 = wall_seconds();
    take_level_p(st);
    // The distributed levels, coarse to fine: the level loop of levels::solve.
    std::vector<StepLevel*> parts;
    for (const auto& part : parts_)
        parts.push_back(part.get());
    failed_ = !solve_levels(parts, st.step, st.s);
    if (!failed_) {
        res_.nodes =
            newton_[m_]->node_states(st.s, u_prev_[m_], x_[m_].head(res_.levels[m_].n_owned));
        res_.step_nodes.push_back(res_.nodes);
        for (size_t k = 1; k <= m_; ++k)
            u_prev_[k] = u_now_[k];
        u_prev_p_ = *st.u_full;
        res_.completed_steps = st.step;
    }
    res_.distributed_seconds += wall_seconds() - t0;
}

void DistributedSteps::interpolate_from_below(size_t k, Vector& xo) {
    ScopedTimer t(&res_.timings, "newton/interpolate");
    const DistributedLevel& D = res_.levels[k];
    const Level& Lk = D.local;
    const auto& T = res_.transfers[k - 1].local;
    Vector uf;
    T.interpolate_nodal(u_now_[k - 1], uf);
    const Vector q = T.Q * x_[k - 1];
    for (int v = 0; v < Lk.mesh.n_vertices(); ++v)
        for (int c = 0; c < 2; ++c)
            if (const int d = Lk.dofs.u_dof(v, c); d >= 0 && d < D.n_owned) xo[d] = uf[2 * v + c];
    for (size_t e = 0; e < Lk.contacts.size(); ++e)
        for (int j = 0; j < Lk.contacts[e].n_multipliers(); ++j) {
            const Index d = Lk.lambda_dof[e] + j;
            xo[d] = q[d];
        }
}

void DistributedSteps::accept_level(size_t k, double s, const Vector& xo) {
    // The part's whole state (ghost unknowns from their owners) for the level above and the
    // output; this level's operator at its converged statuses for the multigrid.
    const DistributedLevel& D = res_.levels[k];
    const Level& Lk = D.local;
    x_[k].setZero();
    x_[k].head(D.n_owned) = xo;
    D.ghosts.update(Lk.dofs, x_[k]);
    Lk.dofs.expand(x_[k], Lk.u_fixed_at(s), u_now_[k]);
    if (k < m_) {
        ScopedTimer t(&res_.timings, "distributed/prepare_level");
        Vector R;
        std::vector<Eigen::Matrix2d> converged;
        newton_[k]->residual(s, u_prev_[k], xo, R, nullptr, &converged, nullptr);
        mg_->prepare(k, converged);
    }
}

void DistributedSteps::finish() {
    res_.x = x_[m_];
    res_.u_full = u_now_[m_];
}

/// What the serial solve of levels 0..p reports to: each converged step of level p taken on
/// by the distributed levels, a stop once one of them failed, the rest the caller's observer's
/// (progress on rank 0 only).
class DistributedObserver final : public SolveObserver {
public:
    DistributedObserver(DistributedSteps& steps, SolveObserver* user, bool root)
        : steps_(steps), user_(user), root_(root) {}
    void level_step_done(const LevelStepProgress& p) override {
        if (user_ && root_) user_->level_step_done(p);
    }
    void level_step(const LevelStepState& st) override { steps_.step(st); }
    bool stop_requested() override { return steps_.failed(); }
    bool interrupt_requested() override { return user_ && user_->interrupt_requested(); }
    std::unique_ptr<NewtonSystemSolver>
    wrap_system_solver(int level, const Level& L,
                       std::unique_ptr<NewtonSystemSolver> solver) override {
        return user_ ? user_->wrap_system_solver(level, L, std::move(solver)) : std::move(solver);
    }

private:
    DistributedSteps& steps_;
    SolveObserver* user_;
    bool root_;
};

} // namespace

StatusCounts reduce_counts(const Communicator& comm, StatusCounts c) {
    std::array<int, 5> v{c.gap, c.stick, c.slip_forward, c.slip_backward, c.slip};
    comm.allreduce(std::span<int>(v), ReduceOp::sum);
    return {v[0], v[1], v[2], v[3], v[4]};
}

DistributedRunResult solve_distributed(const Problem& problem, const SolveOptions& options,
                                       const Communicator& comm, int p, SolveObserver* observer) {
    const double t_start = wall_seconds();
    problem.validate();
    DistributedRunResult res;
    res.n_processes = comm.size();
    res.partition_level = p;
    res.mg = check_distributable(problem, options, comm, p);
    build_distributed_levels(problem, options, comm, p, res);
    // The distributed multigrid (each level's ParCSR Jacobian and transfer) and the Newton
    // solvers, as one process's "setup/linear_solver".
    std::optional<ScopedTimer> t_solver(std::in_place, &res.timings, "setup/linear_solver");
    DistributedSteps steps(problem, options, comm, p, observer, res);
    t_solver.reset();
    // Levels 0..p on every process alike, each converged step of level p continued on the
    // distributed levels; a distributed level that fails stops the serial solve.
    DistributedObserver serial_observer(steps, observer, comm.rank() == 0);
    SolveOptions so = options;
    so.linear = serial_levels_spec(options.linear, p);
    so.keep_step_states = false;
    res.serial = solve(
        [&] {
            Problem sp = problem;
            sp.levels = p;
            return sp;
        }(),
        so, &serial_observer);
    steps.finish();
    res.converged =
        !steps.failed() && res.serial.converged && res.completed_steps == problem.load_steps;
    if (!steps.failed() && !res.serial.converged)
        res.failure =
            res.serial.failure.empty() ? "the levels up to p did not converge" : res.serial.failure;
    res.seconds = wall_seconds() - t_start;
    return res;
}

} // namespace mlc::levels
