// SPDX-License-Identifier: MIT
// Coarse-to-fine Newton over the distributed 3D levels, with the distributed multigrid.
#include "levels/distributed_solve3.hpp"

#include "comm/world.hpp"
#include "contact/element.hpp"
#include "core/check.hpp"
#include "levels/agree_errors.hpp"
#include "levels/distributed_multigrid.hpp"
#include "levels/distributed_solve.hpp"
#include "levels/newton.hpp"
#include "levels/newton_system.hpp"
#include "levels/resources.hpp"
#include "transfer/prolongation.hpp"

#include <algorithm>
#include <array>
#include <memory>
#include <span>
#include <sstream>

namespace mlc::levels {

namespace {

/// The NewtonSystemSolver3 of distributed level k.
class DistributedSystem3 final : public NewtonSystemSolver3 {
public:
    DistributedSystem3(DistributedMultigrid3& mg, size_t k) : mg_(mg), k_(k) {}
    using NewtonSystemSolver3::solve;
    SolveResult solve(const std::vector<Matrix>& M, const Vector& b, Vector& dx,
                      double forcing) override {
        return mg_.solve(k_, M, b, dx, forcing);
    }
    void prepare(const std::vector<Matrix>& M) override { mg_.prepare(k_, M); }
    std::string name() const override { return mg_.name(); }

private:
    DistributedMultigrid3& mg_;
    size_t k_;
};

/// The checks before anything is built, alike on every process: the levels, the options, and
/// the memory of a process (about 1/N of the one-process run, plus levels 0..p whole, the
/// processes on one machine sharing its memory).
void check_distributable3(const ElasticProblem3& problem, const SolveOptions3& options,
                          const Communicator& comm, int p) {
    const int L = problem.levels;
    MLC_CHECK(L >= 1, "a distributed 3D run needs at least one level above level 0 (--levels "
                      ">= 1), found --levels "
                          << L);
    MLC_CHECK(p >= 0 && p < L, "the partition level must lie in [0, " << L - 1 << "] for --levels "
                                                                      << L << ", found " << p);
    MLC_CHECK(options.coarse_to_fine,
              "on several processes the levels are solved coarse to fine (--cold is one process "
              "only)");
    MLC_CHECK(options.upper == Method3::mg || options.upper == Method3::krylov,
              "on several processes the levels above the partition level are solved by GMRES "
              "with the distributed multigrid; '"
                  << to_string(options.upper)
                  << "' needs the whole level on one process (--linear schur and lu are one "
                     "process only)");
    MLC_CHECK(!options.solve_all_levels && !options.wrap_system_solver,
              "a distributed 3D run solves every level coarse to fine with its own solvers");
    std::string error;
    try {
        MemoryLimit limit = process_memory_limit();
        const double share = 1.15 * comm::processes_on_this_machine() / comm.size();
        if (limit.bytes > 0) limit.bytes /= share;
        check_contact3_fits(problem, options.level0, options.upper, limit);
    } catch (const InvalidInput& e) {
        error = std::string(e.what()) + " (the " +
                std::to_string(comm::processes_on_this_machine()) +
                " processes on this machine together; each holds about 1/" +
                std::to_string(comm.size()) + " of the run)";
    }
    detail::throw_first_error(comm, error);
}

/// Level p's unknowns at a converged step of the serial solve: the free displacements of
/// `u_full` and the multipliers of its contact node states (in each node's frame).
Vector level_p_unknowns(const Level3& Lp, const Vector& u_full,
                        const std::vector<ContactNodeState3>& nodes) {
    Vector x = Vector::Zero(Lp.n_unknowns());
    for (int v = 0; v < Lp.mesh.n_vertices(); ++v)
        for (int c = 0; c < 3; ++c)
            if (const int d = Lp.dofs.u_dof(v, c); d >= 0) x[d] = u_full[3 * v + c];
    MLC_CHECK(nodes.size() == Lp.contacts.size(),
              "internal error: " << nodes.size() << " node states for " << Lp.contacts.size()
                                 << " contact elements");
    for (size_t e = 0; e < Lp.contacts.size(); ++e) {
        const int d = Lp.lambda_dof[e];
        if (Lp.contacts[e].frictional()) {
            x[d] = nodes[e].lambda_t[0];
            x[d + 1] = nodes[e].lambda_t[1];
            x[d + 2] = nodes[e].lambda_n;
        } else {
            x[d] = nodes[e].lambda_n;
        }
    }
    return x;
}

/// P_vertex applied to each component of interleaved nodal displacements.
Vector interpolate_nodal3(const SparseMatrix& P_vertex, const Vector& u_coarse) {
    const Index nc = P_vertex.cols();
    const Index nf = P_vertex.rows();
    Vector out = Vector::Zero(3 * nf);
    for (int c = 0; c < 3; ++c) {
        const Vector uc =
            Eigen::Map<const Vector, 0, Eigen::InnerStride<3>>(u_coarse.data() + c, nc);
        const Vector uf = P_vertex * uc;
        for (Index v = 0; v < nf; ++v)
            out[3 * v + c] = uf[v];
    }
    return out;
}

/// The load steps of the distributed levels (see the file comment of the header).
class DistributedSteps3 {
public:
    DistributedSteps3(const ElasticProblem3& problem, const SolveOptions3& options,
                      const Communicator& comm, DistributedRunResult3& res);
    /// Solves load step `step` on the distributed levels from level p's converged state;
    /// false (res.failure set) when a level did not converge.
    bool step(int step);

private:
    void take_level_p(int step);
    void start_from_below(size_t k, int step, Vector& xo);
    void accept(size_t k, double s, const Vector& xo);

    const ElasticProblem3& problem_;
    const SolveOptions3& options_;
    const Communicator& comm_;
    DistributedRunResult3& res_;
    size_t m_; // distributed levels above p: 1..m
    std::unique_ptr<DistributedMultigrid3> mg_;
    std::vector<std::unique_ptr<ContactNewton3>> newton_;
    std::vector<SparseMatrix> P_vertex_; // [k]: the part's vertex prolongation from k - 1
    std::vector<std::unique_ptr<MultiplierTransfer3>> q_; // [k]: multipliers from k - 1
    // Per level: the state of the last converged step (local unknowns with ghosts, nodal
    // displacements of the part's vertices) and the nodal displacements of the step before.
    std::vector<Vector> x_, u_prev_, u_now_;
    // Per level (local unknowns with ghosts): the converged state of the step before x_'s, and
    // this step's own start (x_, or its secant extrapolation: SolveOptions3::extrapolate).
    std::vector<Vector> x_before_, start_;
};

DistributedSteps3::DistributedSteps3(const ElasticProblem3& problem, const SolveOptions3& options,
                                     const Communicator& comm, DistributedRunResult3& res)
    : problem_(problem), options_(options), comm_(comm), res_(res),
      m_(res.parts.levels.size() - 1) {
    auto& levels = res.parts.levels;
    solvers::KrylovParams kp;
    kp.rel_tol = options.krylov_rel_tol;
    kp.max_iter = 500;
    kp.restart = 50;
    if (options.upper == Method3::krylov) {
        LinearSolverSpec spec = options.krylov;
        spec.rel_tol = options.krylov_rel_tol;
        kp.max_iter = spec.max_iter;
        kp.restart = spec.restart;
        mg_ = std::make_unique<DistributedMultigrid3>(levels, res.parts.transfers, comm, spec, kp,
                                                      elastic3_mg_params());
    } else {
        mg_ = std::make_unique<DistributedMultigrid3>(levels, res.parts.transfers, comm, kp,
                                                      elastic3_mg_params());
    }
    res.solver = mg_->name();
    const bool two_body = std::any_of(problem.contacts.begin(), problem.contacts.end(),
                                      [](const ContactPair3& c) { return c.two_body(); });
    newton_.resize(m_ + 1);
    P_vertex_.resize(m_ + 1);
    q_.resize(m_ + 1);
    for (size_t k = 1; k <= m_; ++k) {
        const DistributedLevel3& D = levels[k];
        newton_[k] = std::make_unique<ContactNewton3>(
            D.local, problem.newton, std::make_unique<DistributedSystem3>(*mg_, k), &res.timings);
        NewtonDistribution nd{&comm, D.n_owned, D.K.get(), {}};
        // Two-body elements read ghost values (every process alike: the call is collective).
        if (two_body) nd.fill_ghosts = [&D](Vector& x) { D.ghosts.update(D.local.dofs, x); };
        newton_[k]->set_distribution(std::move(nd));
        if (options.interrupt) newton_[k]->set_interrupt(options.interrupt);
        P_vertex_[k] = transfer::vertex_prolongation(D.local.mesh);
        const Level3& C = levels[k - 1].local;
        q_[k] = std::make_unique<MultiplierTransfer3>(C, D.local, contactor_faces(problem, C),
                                                      contactor_faces(problem, D.local));
    }
    res.level_steps.resize(m_ + 1);
    x_.resize(m_ + 1);
    u_prev_.resize(m_ + 1);
    u_now_.resize(m_ + 1);
    x_before_.resize(m_ + 1);
    start_.resize(m_ + 1);
    for (size_t k = 0; k <= m_; ++k) {
        x_[k] = x_before_[k] = start_[k] = Vector::Zero(levels[k].local.n_unknowns());
        u_prev_[k] = u_now_[k] = Vector::Zero(3 * levels[k].local.mesh.n_vertices());
    }
}

void DistributedSteps3::take_level_p(int step) {
    const RunResult3& serial = res_.serial;
    const Level3& Lp = serial.finest();
    const auto k = static_cast<size_t>(step - 1);
    const Vector& u = serial.step_u_full[k];
    const Vector u_before = k > 0 ? serial.step_u_full[k - 1] : Vector(Vector::Zero(u.size()));
    const Vector xs = level_p_unknowns(Lp, u, serial.step_nodes[k]);
    std::vector<Eigen::Matrix3d> Mp(Lp.contacts.size());
    for (size_t e = 0; e < Lp.contacts.size(); ++e)
        Mp[e] = contact::evaluate(Lp.contacts[e], u, u_before, xs, Lp.lambda_dof[e]).proj.M;
    {
        ScopedTimer t(&res_.timings, "distributed/coarse_setup");
        mg_->set_coarse(Lp, Mp);
    }
    // Level p's own start of this step, as the one-process solve of levels 0..p took it (the
    // level above corrects its start by what level p changed from it).
    start_[0] = x_[0];
    if (options_.extrapolate && step >= 2) start_[0] += x_[0] - x_before_[0];
    x_before_[0] = x_[0];
    // Level p's part: its local unknowns and nodal values, from the serial state.
    const DistributedLevel3& D = res_.parts.levels[0];
    const auto& dofs = D.local.dofs;
    for (int v = 0; v < D.local.mesh.n_vertices(); ++v) {
        const auto& loc = D.part.vertex_location[static_cast<size_t>(v)];
        MLC_CHECK(loc.kind == mesh::TetLocation::Kind::vertex,
                  "internal error: a vertex of level p's part is not a level-p vertex");
        const int vp = loc.id;
        for (int c = 0; c < 3; ++c) {
            u_now_[0][3 * v + c] = u[3 * vp + c];
            if (const int d = dofs.u_dof(v, c); d >= 0) x_[0][d] = xs[Lp.dofs.u_dof(vp, c)];
        }
        const int e = dofs.extra_dof(v);
        for (int q = 0; e >= 0 && q < D.n_extra[static_cast<size_t>(v)]; ++q)
            x_[0][e + q] = xs[Lp.dofs.extra_dof(vp) + q];
    }
}

void DistributedSteps3::start_from_below(size_t k, int step, Vector& xo) {
    ScopedTimer t(&res_.timings, "newton/interpolate");
    const DistributedLevel3& D = res_.parts.levels[k];
    const Level3& L = D.local;
    // Secant predictor (as levels::solve): this level's own extrapolation, corrected by what the
    // level below changed from its own, interpolated. Else the level below's state.
    const bool secant = options_.extrapolate && step >= 2;
    start_[k] = x_[k];
    if (secant) start_[k] += x_[k] - x_before_[k];
    Vector uc;
    const Vector xc = secant ? Vector(x_[k - 1] - start_[k - 1]) : x_[k - 1];
    if (secant)
        res_.parts.levels[k - 1].local.dofs.expand(xc, Vector::Zero(u_now_[k - 1].size()), uc);
    const Vector uf = interpolate_nodal3(P_vertex_[k], secant ? uc : u_now_[k - 1]);
    Vector xi = Vector::Zero(L.n_unknowns());
    for (int v = 0; v < L.mesh.n_vertices(); ++v)
        for (int c = 0; c < 3; ++c)
            if (const int d = L.dofs.u_dof(v, c); d >= 0) xi[d] = uf[3 * v + c];
    // The multipliers of the coarse part's own contact nodes (a fine node near a cut may miss
    // the contribution of a coarse node owned elsewhere: a start, Newton corrects it).
    q_[k]->apply(xc, xi);
    if (secant) xi += start_[k];
    xo = xi.head(D.n_owned);
}

void DistributedSteps3::accept(size_t k, double s, const Vector& xo) {
    // The part's whole state (ghost unknowns from their owners) for the level above and the
    // output; this level's operator at its converged statuses for the multigrid.
    const DistributedLevel3& D = res_.parts.levels[k];
    const Level3& L = D.local;
    x_before_[k] = x_[k];
    x_[k].setZero();
    x_[k].head(D.n_owned) = xo;
    D.ghosts.update(L.dofs, x_[k]);
    L.dofs.expand(x_[k], L.u_fixed_at(s), u_now_[k]);
    if (k < m_) {
        ScopedTimer t(&res_.timings, "distributed/prepare_level");
        Vector R;
        std::vector<Eigen::Matrix3d> converged;
        newton_[k]->residual(s, u_prev_[k], xo, R, nullptr, &converged, nullptr);
        mg_->prepare(k, converged);
    }
}

bool DistributedSteps3::step(int step) {
    const double t0 = wall_seconds();
    const double s = static_cast<double>(step) / problem_.load_steps;
    take_level_p(step);
    bool ok = true;
    for (size_t k = 1; k <= m_ && ok; ++k) {
        const int level = res_.partition_level + static_cast<int>(k);
        LevelStep3 ls;
        ls.level = level;
        Vector xo;
        start_from_below(k, step, xo);
        ls.predicted = true;
        ls.predicted_statuses = newton_[k]->statuses(s, u_prev_[k], xo);
        ls.report = newton_[k]->solve(s, u_prev_[k], xo);
        ls.report.step = step;
        ls.final_statuses = newton_[k]->statuses(s, u_prev_[k], xo);
        for (size_t i = 0; i < ls.final_statuses.size(); ++i)
            ++ls.confusion[static_cast<size_t>(status_code3(ls.predicted_statuses[i]))]
                          [static_cast<size_t>(status_code3(ls.final_statuses[i]))];
        std::array<int, 9> flat{};
        for (size_t a = 0; a < 3; ++a)
            for (size_t b = 0; b < 3; ++b)
                flat[3 * a + b] = ls.confusion[a][b];
        comm_.allreduce(std::span<int>(flat), ReduceOp::sum);
        for (size_t a = 0; a < 3; ++a)
            for (size_t b = 0; b < 3; ++b)
                ls.confusion[a][b] = flat[3 * a + b];
        ls.report.counts = reduce_counts(comm_, ls.report.counts);
        if (options_.progress && comm_.rank() == 0) options_.progress(level, step, ls.report);
        ok = ls.report.converged;
        if (ok) {
            accept(k, s, xo);
            if (k == m_) {
                res_.nodes = newton_[k]->node_states(s, u_prev_[k], xo);
                res_.step_nodes.push_back(res_.nodes);
            }
        } else {
            std::ostringstream os;
            os << "load step " << step << " on level " << level << ": " << ls.report.message;
            res_.failure = os.str();
        }
        if (k == m_) res_.steps.push_back(ls.report);
        res_.level_steps[k].push_back(std::move(ls));
    }
    if (ok) {
        for (size_t k = 1; k <= m_; ++k)
            u_prev_[k] = u_now_[k];
        res_.completed_steps = step;
        res_.x = x_[m_];
        res_.u_full = u_now_[m_];
    }
    res_.distributed_seconds += wall_seconds() - t0;
    return ok;
}

} // namespace

DistributedRunResult3 solve_distributed3(const ElasticProblem3& problem,
                                         const SolveOptions3& options, const Communicator& comm,
                                         int partition_level) {
    const double t_start = wall_seconds();
    problem.validate();
    const int p = partition_level;
    check_distributable3(problem, options, comm, p);
    DistributedRunResult3 res;
    res.n_processes = comm.size();
    res.partition_level = p;
    {
        ScopedTimer t(&res.timings, "setup/distribute");
        res.parts = build_distributed_hierarchy3(problem, p, problem.levels - p, comm);
    }
    std::unique_ptr<DistributedSteps3> steps;
    {
        ScopedTimer t(&res.timings, "setup/linear_solver");
        steps = std::make_unique<DistributedSteps3>(problem, options, comm, res);
    }
    // Levels 0..p on every process alike (progress on rank 0 only).
    ElasticProblem3 sp = problem;
    sp.levels = p;
    SolveOptions3 so = options;
    if (comm.rank() != 0) so.progress = nullptr;
    res.serial = solve(sp, so);
    bool ok = true;
    for (int step = 1; step <= res.serial.completed_steps && ok; ++step)
        ok = steps->step(step);
    res.converged = ok && res.serial.converged && res.completed_steps == problem.load_steps;
    if (ok && !res.serial.converged)
        res.failure =
            res.serial.failure.empty() ? "the levels up to p did not converge" : res.serial.failure;
    res.seconds = wall_seconds() - t_start;
    return res;
}

} // namespace mlc::levels
