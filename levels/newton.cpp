// SPDX-License-Identifier: MIT
// Generalized Newton over contact statuses (Alart & Lebon 1995, sect. 2.3).
#include "levels/newton.hpp"

#include "core/check.hpp"
#include "core/csr.hpp"
#include "core/first_touch.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <sstream>
#include <tuple>

namespace mlc::levels {

void StatusCounts::add(contact::Status s) {
    switch (s) {
    case contact::Status::gap:
        ++gap;
        break;
    case contact::Status::stick:
        ++stick;
        break;
    case contact::Status::slip_forward:
        ++slip_forward;
        break;
    case contact::Status::slip_backward:
        ++slip_backward;
        break;
    case contact::Status::slip:
        ++slip;
        break;
    }
}

// ---------------------------------------------------------------------------------------------
template <int dim>
BasicContactNewton<dim>::BasicContactNewton(const Level& level, NewtonParams params,
                                            std::unique_ptr<Solver> solver, Timings* timings)
    : level_(level), params_(params), solver_(std::move(solver)), timings_(timings) {
    params_.validate();
    MLC_CHECK(solver_ != nullptr, "ContactNewton needs a linear solver");
}

template <int dim> void BasicContactNewton<dim>::set_distribution(NewtonDistribution d) {
    MLC_CHECK(!d.comm || (d.K && d.n_owned >= 0 && d.n_owned <= level_.n_unknowns() &&
                          d.K->rows() == d.n_owned),
              "ContactNewton: inconsistent distribution (" << d.n_owned << " owned unknowns of "
                                                           << level_.n_unknowns() << ")");
    dist_ = d;
}

template <int dim>
const Vector& BasicContactNewton<dim>::padded(const Vector& x, Vector& work) const {
    if (!dist_.comm) return x;
    work = Vector::Zero(level_.n_unknowns());
    work.head(x.size()) = x;
    if (dist_.fill_ghosts) dist_.fill_ghosts(work);
    return work;
}

template <int dim>
double BasicContactNewton<dim>::residual(double s, const Vector& u_prev_full, const Vector& x,
                                         Vector& R, std::vector<contact::Status>* st,
                                         std::vector<Matrix>* M, double* scale) const {
    const Level& L = level_;
    // Level-size work vectors, written over the threads (core/first_touch).
    struct {
        Vector u_fixed, u_full, padded, f, contact_force;
    } w;
    L.u_fixed_at(s, w.u_fixed);
    const Vector& xl = padded(x, w.padded);
    L.dofs.expand(xl, w.u_fixed, w.u_full);
    const Vector& u_full = w.u_full;
    if (dist_.comm)
        dist_.K->apply(x, R);
    else
        csr_multiply_in_order(L.elastic.K, x, R); // Eigen's K * x, bit for bit, row-parallel
    double internal2 = R.squaredNorm();
    L.f_at(s, w.f);
    if (dist_.comm) w.f = Vector(w.f.head(x.size()));
    const Vector& f = w.f;
    parallel::for_rows(static_cast<size_t>(R.size()), parallel::kTouchRowsPerChunk,
                       [&](size_t b, size_t e) {
                           const auto i = static_cast<Index>(b);
                           const auto m = static_cast<Index>(e - b);
                           R.segment(i, m) -= f.segment(i, m); // R -= f, elementwise
                       });
    double load2 = f.squaredNorm();
    // Distributed: the part's unknowns (ghost rows included; those are other processes').
    parallel::set_zero(w.contact_force, xl.size());
    Vector& contact_force = w.contact_force;
    double lambda_res2 = 0.0;
    if (st) st->resize(L.contacts.size());
    if (M) M->resize(L.contacts.size() + L.ghost_contacts.size());
    for (size_t e = 0; e < L.contacts.size(); ++e) {
        const auto& el = L.contacts[e];
        const auto es = contact::evaluate(el, u_full, u_prev_full, xl, L.lambda_dof[e]);
        contact::add_residual(el, es, L.dofs, L.lambda_dof[e], contact_force);
        // add_residual wrote the multiplier rows of contact_force; move them into R.
        for (int q = 0; q < el.n_multipliers(); ++q) {
            const int d = L.lambda_dof[e] + q;
            R[d] = contact_force[d];
            lambda_res2 += std::pow(el.r * contact_force[d], 2);
            contact_force[d] = 0.0;
        }
        if (st) (*st)[e] = es.proj.status;
        if (M) (*M)[e] = es.proj.M;
    }
    // Other processes' elements reaching owned vertices: their forces on the owned rows.
    for (size_t e = 0; e < L.ghost_contacts.size(); ++e) {
        const auto& el = L.ghost_contacts[e];
        const auto es = contact::evaluate(el, u_full, u_prev_full, xl, L.ghost_lambda_dof[e]);
        contact::add_residual(el, es, L.dofs, L.ghost_lambda_dof[e], contact_force);
        for (int q = 0; q < el.n_multipliers(); ++q)
            contact_force[L.ghost_lambda_dof[e] + q] = 0.0;
        if (M) (*M)[L.contacts.size() + e] = es.proj.M;
    }
    parallel::for_rows(static_cast<size_t>(R.size()), parallel::kTouchRowsPerChunk,
                       [&](size_t b, size_t e) {
                           const auto i = static_cast<Index>(b);
                           const auto m = static_cast<Index>(e - b);
                           R.segment(i, m) += contact_force.segment(i, m); // elementwise
                       });
    // Norm in force units: displacement rows as they are, multiplier rows times r.
    double ru2 = 0.0;
    for (Index i = 0; i < R.size(); ++i)
        if (L.dofs.is_displacement(i)) ru2 += R[i] * R[i];
    double contact2 = contact_force.head(R.size()).squaredNorm();
    if (dist_.comm) {
        std::array<double, 5> sums{internal2, load2, contact2, ru2, lambda_res2};
        dist_.comm->allreduce(sums, ReduceOp::sum);
        std::tie(internal2, load2, contact2, ru2, lambda_res2) =
            std::tuple(sums[0], sums[1], sums[2], sums[3], sums[4]);
    }
    if (scale) *scale = std::sqrt(std::max({load2, internal2, contact2}));
    return std::sqrt(ru2 + lambda_res2);
}

template <int dim>
std::vector<contact::Status> BasicContactNewton<dim>::statuses(double s, const Vector& u_prev_full,
                                                               const Vector& x) const {
    Vector R(x.size());
    std::vector<contact::Status> st;
    residual(s, u_prev_full, x, R, &st, nullptr, nullptr);
    return st;
}

template <int dim>
double BasicContactNewton<dim>::forcing_term(int k, double norm, double scale) const {
    if (params_.forcing <= 0.0) return 0.0;
    if (k == 0) return params_.forcing;
    // Enough to reach the tolerance if the statuses stay (a margin of 10 for the Krylov norm,
    // which weights the multiplier rows differently from ||R||), never looser than 0.5.
    const double target = norm > 0.0 ? 0.1 * params_.rel_tol * scale / norm : 0.0;
    return std::min(0.5, target);
}

template <int dim>
StepReport BasicContactNewton<dim>::solve(double s, const Vector& u_prev_full, Vector& x) {
    return solve(s, u_prev_full, x, params_.max_iter);
}

template <int dim>
StepReport BasicContactNewton<dim>::check(double s, const Vector& u_prev_full, Vector& x) {
    return solve(s, u_prev_full, x, 0);
}

namespace {

/// Status cycling: the status vector `st` returns to one of `history` other than the last (seen
/// two or more iterates ago). Distributed: only if every process's part does.
bool statuses_cycle(const std::vector<std::vector<contact::Status>>& history,
                    const std::vector<contact::Status>& st, const Communicator* comm) {
    std::vector<int> differ(history.size() - 1);
    for (size_t j = 0; j + 1 < history.size(); ++j)
        differ[j] = history[j] == st ? 0 : 1;
    if (comm) comm->allreduce(std::span<int>(differ), ReduceOp::max);
    return std::find(differ.begin(), differ.end(), 0) != differ.end();
}

} // namespace

template <int dim>
bool BasicContactNewton<dim>::stop_test(int k, int max_iter, double norm, double scale, int changes,
                              StepReport& rep) const {
    const double rel = rep.residuals.back();
    if (!std::isfinite(norm)) {
        rep.message = "the residual became NaN/Inf at Newton iteration " + std::to_string(k);
        return true;
    }
    if (norm <= params_.rel_tol * scale && (k == 0 || changes == 0)) {
        rep.converged = true;
        return true;
    }
    // Round-off floor: the problem is linear for fixed statuses, so once two consecutive
    // steps kept every status, the last step was exact up to the linear solver's accuracy;
    // a residual that then stops decreasing is the conditioning floor (e.g. nu -> 0.5),
    // not a failure. Accepted and said so, if within 1e3 times the tolerance.
    if (k >= 2 && changes == 0 && rep.status_changes.size() >= 2 &&
        rep.status_changes[rep.status_changes.size() - 2] == 0 &&
        rel > 0.5 * rep.residuals[rep.residuals.size() - 2] &&
        norm <= 1e3 * params_.rel_tol * scale) {
        rep.converged = true;
        std::ostringstream os;
        os << "residual stagnated at " << rel << " (round-off floor above the tolerance "
           << params_.rel_tol << ") with statuses fixed";
        rep.message = os.str();
        return true;
    }
    if (k == max_iter) {
        std::ostringstream os;
        os << "no convergence in " << max_iter << " Newton iterations; relative "
           << "residual went " << rep.residuals.front() << " -> " << rel << " (tolerance "
           << params_.rel_tol << "), " << changes << " status changes in the last iteration";
        if (rep.cycling_detected_at >= 0)
            os << "; statuses cycled from iteration " << rep.cycling_detected_at
               << " (damped steps did not break the cycle)";
        rep.message = os.str();
        return true;
    }
    if (stop_ && stop_()) {
        rep.stopped = true;
        rep.message = "stopped on request after " + std::to_string(k) + " Newton iterations";
        return true;
    }
    return false;
}

template <int dim>
bool BasicContactNewton<dim>::solve_system(int k, const std::vector<Matrix>& M, const Vector& b,
                                 Vector& dx, double forcing, StepReport& rep) {
    SolveResult lin;
    {
        ScopedTimer t(timings_, "newton/linear_solve");
        dx.setZero();
        try {
            if (fallback_) {
                // The Krylov solve failed on this level before: the exact solver from then
                // on (it is set up; another failed attempt per system would only cost).
                lin = fallback_->solve(M, b, dx);
                ++rep.fallback_solves;
            } else {
                lin = solver_->solve(M, b, dx, forcing);
            }
        } catch (const SolverBreakdown& e) {
            if (!make_fallback_) throw;
            lin = SolveResult{};
            lin.reason = StopReason::breakdown;
            lin.message = e.what();
        }
    }
    rep.linear_iterations += lin.iterations;
    rep.linear_iterations_per_newton.push_back(lin.iterations);
    rep.linear_seconds += lin.setup_seconds + lin.solve_seconds;
    rep.linear_setup_seconds += lin.setup_seconds;
    rep.linear_assembly_seconds += lin.assembly_seconds;
    // Inexact Newton: a Krylov solve that hit its iteration limit but reduced the linear
    // residual by at least half still gives a descent-quality step; the Newton test decides.
    const bool usable = !lin.converged && lin.reason == StopReason::max_iter &&
                        std::isfinite(lin.relative_residual) && lin.relative_residual < 0.5 &&
                        dx.allFinite();
    if (usable) ++rep.inexact_steps;
    if (!lin.converged && !usable && make_fallback_ && !fallback_) {
        // The exact fallback: the same system solved again, exactly.
        const std::string why = std::string(to_string(lin.reason)) +
                                (lin.message.empty() ? "" : " (" + lin.message + ")");
        try {
            if (!fallback_) fallback_ = make_fallback_();
        } catch (const InvalidInput& e) {
            rep.message = "linear solve failed at Newton iteration " + std::to_string(k) + ": " +
                          why + "; no exact fallback: " + e.what();
            return false;
        }
        ScopedTimer t(timings_, "newton/fallback_solve");
        dx.setZero();
        const SolveResult ex = fallback_->solve(M, b, dx);
        rep.linear_seconds += ex.setup_seconds + ex.solve_seconds;
        if (rep.fallback_solves++ == 0)
            rep.fallback_reason = solver_->name() + " failed at Newton iteration " +
                                  std::to_string(k) + ": " + why + "; solved by " +
                                  fallback_->name();
        lin.converged = ex.converged;
        lin.reason = ex.reason;
        lin.message = ex.message;
    }
    if (!lin.converged && !usable) {
        rep.message = "linear solve failed at Newton iteration " + std::to_string(k) + ": " +
                      std::string(to_string(lin.reason)) +
                      (lin.message.empty() ? "" : " (" + lin.message + ")");
        return false;
    }
    return true;
}

template <int dim>
void BasicContactNewton<dim>::damped_step(double s, const Vector& u_prev_full, const Vector& dx, double norm,
                                Vector& x) const {
    // Backtracking on the residual norm: halve the step until ||R|| decreases (at most
    // 30 halvings; the last trial is taken whatever it gives).
    ScopedTimer t(timings_, "newton/line_search");
    const Index n = x.size();
    Vector trial(n), Rt(n);
    double alpha = 1.0;
    for (int h = 0; h < 30; ++h, alpha *= 0.5) {
        trial = x + alpha * dx;
        if (residual(s, u_prev_full, trial, Rt, nullptr, nullptr, nullptr) < norm) break;
    }
    x = trial;
}

template <int dim>
StepReport BasicContactNewton<dim>::solve(double s, const Vector& u_prev_full, Vector& x,
                                          int max_iter) {
    const double t_start = wall_seconds();
    StepReport rep;
    rep.load_factor = s;
    const Index n = n_iterate();
    MLC_CHECK(x.size() == n, "Newton initial guess has " << x.size() << " entries, expected " << n);
    Vector R(n), dx(n);
    std::vector<contact::Status> st, st_prev;
    std::vector<Matrix> M;
    std::vector<std::vector<contact::Status>> history; // status vectors of the iterates
    bool damped = false;
    for (int k = 0;; ++k) {
        if (interrupt_ && interrupt_())
            throw Interrupted("interrupted before Newton iteration " + std::to_string(k + 1) +
                              " at load factor " + std::to_string(s));
        double scale = 0.0, norm = 0.0;
        {
            ScopedTimer t(timings_, "newton/residual");
            norm = residual(s, u_prev_full, x, R, &st, &M, &scale);
        }
        rep.residuals.push_back(scale > 0 ? norm / scale : norm);
        int changes = 0;
        if (k > 0)
            for (size_t e = 0; e < st.size(); ++e)
                changes += st[e] != st_prev[e];
        if (dist_.comm) changes = dist_.comm->sum(changes);
        if (k > 0) rep.status_changes.push_back(changes);
        // Status cycling: the generalized Newton map can cycle between status sets (Alart &
        // Curnier's method is only locally convergent); from then on each step is damped by
        // backtracking on ||R||.
        if (!damped && k > 0 && changes > 0 && history.size() >= 2 &&
            statuses_cycle(history, st, dist_.comm)) {
            damped = true;
            rep.cycling_detected_at = k;
        }
        if (!damped) history.push_back(st);
        if (stop_test(k, max_iter, norm, scale, changes, rep)) break;
        R = -R;
        if (!solve_system(k, M, R, dx, forcing_term(k, norm, scale), rep)) break;
        if (damped) {
            damped_step(s, u_prev_full, dx, norm, x);
            ++rep.damped_steps;
        } else {
            x += dx;
        }
        st_prev = st;
        ++rep.iterations;
    }
    for (const auto& ns : node_states(s, u_prev_full, x))
        rep.counts.add(ns.status);
    rep.seconds = wall_seconds() - t_start;
    return rep;
}

template <int dim>
std::vector<BasicContactNodeState<dim>>
BasicContactNewton<dim>::node_states(double s, const Vector& u_prev_full, const Vector& x) const {
    const Level& L = level_;
    Vector u_full, work;
    const Vector& xl = padded(x, work);
    L.dofs.expand(xl, L.u_fixed_at(s), u_full);
    // Threshold below which a frictionless node is said not to move: relative to the largest
    // displacement of the step (no absolute tolerance).
    double umax = (u_full - u_prev_full).cwiseAbs().maxCoeff();
    if (dist_.comm) umax = dist_.comm->max(umax);
    std::vector<NodeState> out;
    out.reserve(L.contacts.size());
    for (size_t e = 0; e < L.contacts.size(); ++e) {
        const auto& el = L.contacts[e];
        const auto es = contact::evaluate(el, u_full, u_prev_full, xl, L.lambda_dof[e]);
        NodeState ns;
        ns.vertex = el.vertex[0];
        ns.x = L.mesh.vertices[static_cast<size_t>(ns.vertex)];
        ns.u = u_full.template segment<dim>(dim * ns.vertex);
        ns.n = el.n;
        ns.t = el.t;
        ns.lambda_n = es.lambda[dim - 1];
        ns.d_n = es.d_n;
        ns.status = es.proj.status;
        if constexpr (dim == 2) {
            ns.lambda_t = es.lambda[0];
            ns.d_t = es.d_t[0];
            if (ns.status == contact::Status::gap) ns.lambda_t = ns.lambda_n = 0.0;
            if (!el.frictional() && ns.status != contact::Status::gap) {
                if (es.d_t[0] > 1e-9 * umax)
                    ns.status = contact::Status::slip_forward;
                else if (es.d_t[0] < -1e-9 * umax)
                    ns.status = contact::Status::slip_backward;
            }
        } else {
            ns.lambda_t = es.lambda.template head<dim - 1>();
            ns.d_t = es.d_t;
            ns.slip_direction = es.proj.slip_direction;
            if (ns.status == contact::Status::gap) {
                ns.lambda_t.setZero();
                ns.lambda_n = 0.0;
            }
            // A frictionless node in contact slips when it moved along the plane.
            if (!el.frictional() && ns.status != contact::Status::gap) {
                const double slip = es.d_t.norm();
                if (slip > 1e-9 * umax) {
                    ns.status = contact::Status::slip;
                    ns.slip_direction = es.d_t / slip;
                }
            }
        }
        out.push_back(ns);
    }
    return out;
}

template class BasicContactNewton<2>;
template class BasicContactNewton<3>;

} // namespace mlc::levels
