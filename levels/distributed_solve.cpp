// SPDX-License-Identifier: MIT
// Coarse-to-fine Newton over the distributed levels, with the distributed multigrid.
#include "levels/distributed_solve.hpp"

#include "comm/world.hpp"
#include "contact/element.hpp"
#include "core/check.hpp"
#include "levels/krylov_system.hpp"
#include "levels/newton.hpp"
#include "levels/newton_system.hpp"
#include "smoothers/block_sor.hpp"
#include "solvers/factory.hpp"
#include "solvers/krylov.hpp"

#include <Eigen/SparseLU>

#include <atomic>
#include <cmath>
#include <iomanip>
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

StatusCounts reduce_counts(const Communicator& comm, StatusCounts c) {
    std::array<int, 4> v{c.gap, c.stick, c.slip_forward, c.slip_backward};
    comm.allreduce(std::span<int>(v), ReduceOp::sum);
    return {v[0], v[1], v[2], v[3]};
}

} // namespace

DistributedRunResult solve_distributed(const Problem& problem, const SolveOptions& options,
                                       const Communicator& comm, int p) {
    const double t_start = wall_seconds();
    problem.validate();
    DistributedRunResult res;
    res.n_processes = comm.size();
    res.partition_level = p;
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
    res.mg = distributed_mg_params(options.linear);
    {
        // Memory: a process holds about 1/N of what one process needs for the run (the square at
        // level 6 on 2 processes: 0.54 of the one-process peak each), and the processes on one
        // machine share its memory. Decided alike on every process.
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
        MLC_CHECK(comm.max(error.empty() ? 0 : 1) == 0,
                  (error.empty() ? std::string("the run does not fit in another process's memory")
                                 : error));
    }

    // The partitioned level p and this process's part of it and of the levels above.
    mesh::Mesh mp = problem.mesh0;
    for (int l = 0; l < p; ++l)
        mp = mesh::refine(mp);
    {
        ScopedTimer t(&res.timings, "setup/distribute");
        auto dh = mesh::distribute(mp, L - p, comm, {}, contact_ghost_reach(problem, mp));
        mp = mesh::Mesh{};
        for (auto& lv : dh.levels)
            res.levels.push_back(build_distributed_level(problem, std::move(lv), comm));
    }
    const size_t m = res.levels.size() - 1; // distributed levels above p: 1..m
    {
        ScopedTimer t(&res.timings, "setup/transfers");
        for (size_t k = 1; k <= m; ++k)
            res.transfers.push_back(
                build_distributed_transfer(res.levels[k - 1], res.levels[k], comm, options.q_rule));
    }
    DistributedMultigrid mg(res.levels, res.transfers, comm, options.linear, res.mg);
    std::vector<std::unique_ptr<ContactNewton>> newton(m + 1);
    const bool two_body =
        std::any_of(problem.contacts.begin(), problem.contacts.end(), [](const ContactPair& c) {
            return c.element != ContactElementKind::node_on_rigid;
        });
    for (size_t k = 1; k <= m; ++k) {
        newton[k] = std::make_unique<ContactNewton>(res.levels[k].local, problem.newton,
                                                    std::make_unique<DistributedSystem>(mg, k),
                                                    &res.timings);
        const DistributedLevel& D = res.levels[k];
        NewtonDistribution nd{&comm, D.n_owned, D.K.get(), {}};
        // Two-body elements read ghost values (every process alike: the call is collective).
        if (two_body) nd.fill_ghosts = [&D](Vector& x) { D.ghosts.update(D.local.dofs, x); };
        newton[k]->set_distribution(std::move(nd));
        newton[k]->set_interrupt(options.interrupt_requested);
    }
    res.level_steps.resize(m + 1);

    // Per level: the state of the last converged step (local unknowns with ghosts, nodal
    // displacements of the part's vertices).
    std::vector<Vector> x(m + 1), u_prev(m + 1), u_now(m + 1);
    for (size_t k = 0; k <= m; ++k) {
        x[k] = Vector::Zero(res.levels[k].local.n_unknowns());
        u_prev[k] = Vector::Zero(2 * res.levels[k].local.mesh.n_vertices());
    }
    Vector u_prev_p; // level p's (serial) nodal displacements at the previous step
    // SolveOptions::extrapolate: each distributed level's owned state at the last two steps
    // (x^0 = 0: the supports never change on several processes, checked above).
    std::vector<Vector> xo_last(m + 1), xo_older(m + 1);
    for (size_t k = 1; k <= m; ++k)
        xo_last[k] = xo_older[k] = Vector::Zero(res.levels[k].n_owned);
    std::atomic<bool> stop{false};
    bool failed = false;
    std::ostream* progress = comm.rank() == 0 ? options.progress : nullptr;

    SolveOptions so = options;
    so.linear = serial_levels_spec(options.linear, p);
    so.progress = progress;
    so.stop = &stop;
    so.keep_step_states = false;
    so.on_level_step = [&](const LevelStepState& st) {
        if (st.level != p || failed) return;
        const double t0 = wall_seconds();
        const Level& Lp = *st.L;
        const double s = st.s;
        if (u_prev_p.size() != st.u_full->size()) u_prev_p = Vector::Zero(st.u_full->size());
        // Level p's converged state on its unknowns, and its statuses.
        Vector xs = Vector::Zero(Lp.n_unknowns());
        for (int v = 0; v < Lp.mesh.n_vertices(); ++v)
            for (int c = 0; c < 2; ++c)
                if (const int d = Lp.dofs.u_dof(v, c); d >= 0) xs[d] = (*st.u_full)[2 * v + c];
        for (size_t e = 0; e < Lp.contacts.size(); ++e) {
            const auto& ns = (*st.nodes)[e];
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
            Mp[e] = contact::evaluate(Lp.contacts[e], *st.u_full, u_prev_p, xs, Lp.lambda_dof[e])
                        .proj.M;
        {
            ScopedTimer t(&res.timings, "distributed/coarse_setup");
            mg.set_coarse(Lp, Mp);
        }
        // Level p's part: its local unknowns and nodal values, from the serial state.
        {
            const DistributedLevel& D = res.levels[0];
            const auto& dofs = D.local.dofs;
            u_now[0].resize(2 * D.local.mesh.n_vertices());
            for (int v = 0; v < D.local.mesh.n_vertices(); ++v) {
                const int vp = D.part.vertex_location[static_cast<size_t>(v)].id;
                for (int c = 0; c < 2; ++c) {
                    u_now[0][2 * v + c] = (*st.u_full)[2 * vp + c];
                    if (const int d = dofs.u_dof(v, c); d >= 0) x[0][d] = xs[Lp.dofs.u_dof(vp, c)];
                }
                const int e = dofs.extra_dof(v);
                for (int q = 0; e >= 0 && q < D.n_extra[static_cast<size_t>(v)]; ++q)
                    x[0][e + q] = xs[Lp.dofs.extra_dof(vp) + q];
            }
        }
        // The distributed levels, coarse to fine.
        for (size_t k = 1; k <= m && !failed; ++k) {
            const DistributedLevel& D = res.levels[k];
            const Level& Lk = D.local;
            ContactNewton& nw = *newton[k];
            LevelStep ls;
            ls.level = p + static_cast<int>(k);
            Vector xo(D.n_owned);
            // As levels::solve does (SolveOptions::extrapolate): the extrapolated state when
            // Newton would stop there at once, otherwise the interpolated coarse state.
            bool extrapolated = false;
            if (options.extrapolate) {
                Vector xe = 2.0 * xo_last[k] - xo_older[k];
                StepReport r = nw.check(s, u_prev[k], xe);
                if (r.converged) {
                    xo = std::move(xe);
                    ls.report = std::move(r);
                    extrapolated = true;
                    ls.extrapolated = true;
                }
            }
            if (!extrapolated) {
                ScopedTimer t(&res.timings, "newton/interpolate");
                const auto& T = res.transfers[k - 1].local;
                Vector uf;
                T.interpolate_nodal(u_now[k - 1], uf);
                const Vector q = T.Q * x[k - 1];
                for (int v = 0; v < Lk.mesh.n_vertices(); ++v)
                    for (int c = 0; c < 2; ++c)
                        if (const int d = Lk.dofs.u_dof(v, c); d >= 0 && d < D.n_owned)
                            xo[d] = uf[2 * v + c];
                for (size_t e = 0; e < Lk.contacts.size(); ++e)
                    for (int j = 0; j < Lk.contacts[e].n_multipliers(); ++j) {
                        const Index d = Lk.lambda_dof[e] + j;
                        xo[d] = q[d];
                    }
            }
            ls.predicted = !extrapolated;
            if (ls.predicted) ls.predicted_statuses = nw.statuses(s, u_prev[k], xo);
            if (!extrapolated) ls.report = nw.solve(s, u_prev[k], xo);
            ls.report.step = st.step;
            ls.report.counts = reduce_counts(comm, ls.report.counts);
            ls.final_statuses = nw.statuses(s, u_prev[k], xo);
            if (ls.predicted)
                for (size_t e = 0; e < ls.final_statuses.size(); ++e)
                    ++ls.confusion[static_cast<size_t>(ls.predicted_statuses[e])]
                                  [static_cast<size_t>(ls.final_statuses[e])];
            if (options.extrapolate) {
                xo_older[k] = std::move(xo_last[k]);
                xo_last[k] = xo;
            }
            reduce_confusion(comm, ls.confusion);
            if (progress) {
                const auto& r = ls.report;
                *progress << "  level " << ls.level << " step " << st.step << "/"
                          << problem.load_steps << ": " << (r.converged ? "converged" : "FAILED")
                          << " in " << r.iterations << " Newton it, " << r.linear_iterations
                          << " Krylov it, final residual " << std::scientific
                          << std::setprecision(2)
                          << (r.residuals.empty() ? 0.0 : r.residuals.back()) << std::defaultfloat
                          << std::setprecision(6) << ", " << std::fixed << std::setprecision(2)
                          << r.seconds << " s" << std::defaultfloat << std::setprecision(6) << " ("
                          << comm.size() << " processes)" << std::endl;
            }
            const bool ok = ls.report.converged;
            if (k == m) res.steps.push_back(ls.report);
            res.level_steps[k].push_back(std::move(ls));
            if (!ok) {
                const auto& r = res.level_steps[k].back().report;
                std::ostringstream os;
                os << "load step " << st.step << " (load factor " << s << ") on level "
                   << p + static_cast<int>(k) << " did not converge: " << r.message
                   << "; residual history:";
                for (double v : r.residuals)
                    os << " " << std::scientific << std::setprecision(2) << v;
                res.failure = os.str();
                failed = true;
                stop = true;
                break;
            }
            // The part's whole state (ghost unknowns from their owners) for the level above and
            // the output; this level's operator at its converged statuses for the multigrid.
            x[k].setZero();
            x[k].head(D.n_owned) = xo;
            D.ghosts.update(Lk.dofs, x[k]);
            Lk.dofs.expand(x[k], Lk.u_fixed_at(s), u_now[k]);
            if (k < m) {
                Vector R;
                std::vector<Eigen::Matrix2d> converged;
                nw.residual(s, u_prev[k], xo, R, nullptr, &converged, nullptr);
                mg.prepare(k, converged);
            }
        }
        if (!failed) {
            res.nodes = newton[m]->node_states(s, u_prev[m], x[m].head(res.levels[m].n_owned));
            res.step_nodes.push_back(res.nodes);
            for (size_t k = 1; k <= m; ++k)
                u_prev[k] = u_now[k];
            u_prev_p = *st.u_full;
            res.completed_steps = st.step;
        }
        res.distributed_seconds += wall_seconds() - t0;
    };
    res.serial = solve(
        [&] {
            Problem sp = problem;
            sp.levels = p;
            return sp;
        }(),
        so);
    res.x = x[m];
    res.u_full = u_now[m];
    res.converged = !failed && res.serial.converged && res.completed_steps == problem.load_steps;
    if (!failed && !res.serial.converged)
        res.failure =
            res.serial.failure.empty() ? "the levels up to p did not converge" : res.serial.failure;
    res.seconds = wall_seconds() - t_start;
    return res;
}

} // namespace mlc::levels
