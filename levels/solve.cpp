// SPDX-License-Identifier: MIT
// Load stepping on the finest level.
#include "levels/solve.hpp"

#include "core/check.hpp"

#include <iomanip>
#include <sstream>

namespace mlc::levels {

RunResult solve(const Problem& problem, const SolveOptions& options) {
    problem.validate();
    RunResult res;
    {
        ScopedTimer t(&res.timings, "setup/levels");
        mesh::Mesh m = problem.mesh0;
        for (int l = 0;; ++l) {
            res.levels.push_back(build_level(problem, m));
            if (l == problem.levels) break;
            m = mesh::refine(m);
        }
    }
    const Level& L = res.finest();
    std::unique_ptr<NewtonSystemSolver> system;
    {
        ScopedTimer t(&res.timings, "setup/linear_solver");
        system = make_newton_system_solver(L, options.linear);
    }
    ContactNewton newton(L, problem.newton, std::move(system), &res.timings);
    Vector x = Vector::Zero(L.n_unknowns());
    Vector u_prev = Vector::Zero(2 * L.mesh.n_vertices());
    res.converged = true;
    for (int step = 1; step <= problem.load_steps; ++step) {
        const double s = static_cast<double>(step) / problem.load_steps;
        StepReport rep = newton.solve(s, u_prev, x);
        rep.step = step;
        if (options.progress) {
            auto& os = *options.progress;
            os << "  step " << std::setw(3) << step << "/" << problem.load_steps << "  load "
               << std::fixed << std::setprecision(3) << s << "  newton " << std::setw(3)
               << rep.iterations << "  residual " << std::scientific << std::setprecision(2)
               << rep.residuals.back() << "  gap " << rep.counts.gap << " stick "
               << rep.counts.stick << " slip+ " << rep.counts.slip_forward << " slip- "
               << rep.counts.slip_backward << "  " << std::fixed << std::setprecision(2)
               << rep.seconds << " s" << std::defaultfloat << (rep.converged ? "" : "  FAILED")
               << "\n";
        }
        const bool ok = rep.converged;
        res.steps.push_back(rep);
        if (!ok) {
            std::ostringstream os;
            os << "load step " << step << " (load factor " << s
               << ") did not converge: " << rep.message << "; residual history:";
            for (double r : rep.residuals)
                os << " " << std::scientific << std::setprecision(2) << r;
            res.failure = os.str();
            res.converged = false;
            break;
        }
        res.nodes = newton.node_states(s, u_prev, x);
        res.u_prev_full = u_prev;
        L.dofs.expand(x, s * L.u_fixed, res.u_full);
        if (options.keep_step_states) {
            res.step_u_full.push_back(res.u_full);
            res.step_nodes.push_back(res.nodes);
        }
        u_prev = res.u_full;
    }
    res.x = x;
    return res;
}

double force_balance_error(const Level& level, double s, const Vector& u_full,
                           const std::vector<ContactNodeState>& nodes) {
    // External forces on the body: loads F, contact forces -C (C = sum_j w_j (lambda_t t +
    // lambda_n n), the multiplier being the force the body exerts), and support reactions
    // Rs = K u - F + C on the fixed components (nodal equilibrium K u = F - C + Rs). The
    // resultant F - C + Rs must vanish per axis; K u is recomputed element by element.
    const Vector Ku = fem::internal_forces(level.mesh, level.materials, u_full);
    const Vector F = s * level.elastic.f_nodal_full;
    Vector C = Vector::Zero(Ku.size());
    for (size_t e = 0; e < level.contacts.size(); ++e) {
        const auto& el = level.contacts[e];
        const Vec2 f = nodes[e].lambda_t * el.t + nodes[e].lambda_n * el.n;
        for (int j = 0; j < el.n_nodes; ++j)
            C.segment<2>(2 * el.vertex[static_cast<size_t>(j)]) +=
                el.weight[static_cast<size_t>(j)] * f;
    }
    double err = 0.0, total = 0.0;
    for (int a = 0; a < 2; ++a) {
        double resultant = 0.0, magnitude = 0.0;
        for (int v = 0; v < level.mesh.n_vertices(); ++v) {
            const int i = 2 * v + a;
            const double Rs = level.fixed[static_cast<size_t>(v)][static_cast<size_t>(a)]
                                  ? Ku[i] - F[i] + C[i]
                                  : 0.0;
            resultant += F[i] - C[i] + Rs;
            magnitude += std::abs(F[i]) + std::abs(C[i]) + std::abs(Rs);
        }
        err = std::max(err, std::abs(resultant));
        total = std::max(total, magnitude);
    }
    return total > 0 ? err / total : err;
}

} // namespace mlc::levels
