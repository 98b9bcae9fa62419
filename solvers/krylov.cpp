// SPDX-License-Identifier: MIT
// CGS, BiCG, BiCGStab and restarted GMRES with shared entry checks, breakdown detection and a
// true-residual check before convergence is declared.
#include "solvers/krylov.hpp"

#include "core/check.hpp"
#include "core/first_touch.hpp"
#include "core/timer.hpp"
#include "core/traffic.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>

namespace mlc::solvers {

void KrylovParams::validate() const {
    MLC_CHECK(std::isfinite(rel_tol) && rel_tol >= 0.0 && rel_tol < 1.0,
              "KrylovParams::rel_tol must be in [0, 1), found " << rel_tol);
    MLC_CHECK(std::isfinite(abs_tol) && abs_tol >= 0.0,
              "KrylovParams::abs_tol must be finite and >= 0, found " << abs_tol);
    MLC_CHECK(max_iter >= 0, "KrylovParams::max_iter must be >= 0, found " << max_iter);
    MLC_CHECK(restart >= 1, "KrylovParams::restart must be >= 1, found " << restart);
    MLC_CHECK(give_up_budget >= 0,
              "KrylovParams::give_up_budget must be >= 0, found " << give_up_budget);
}

std::ostream& operator<<(std::ostream& os, const KrylovParams& p) {
    return os << "KrylovParams{rel_tol=" << p.rel_tol << ", abs_tol=" << p.abs_tol
              << ", max_iter=" << p.max_iter << ", restart=" << p.restart
              << ", record_history=" << (p.record_history ? "true" : "false")
              << ", processes=" << (p.comm ? p.comm->size() : 1) << "}";
}

namespace {

// A zero or non-finite inner product ends a Lanczos-type recursion.
bool bad(double v) {
    return v == 0.0 || !std::isfinite(v);
}

// An elementwise vector statement over the threads: fn(begin, size) on the chunks of [0, n)
// (one chunk on the caller below 2^15 entries). Each entry is computed by the operations of the
// whole-vector expression, so the values are the same whichever thread writes them; reductions
// (inner products, norms) stay whole-vector Eigen ones, bit for bit as before.
template <class Fn> void elementwise(Index n, Fn&& fn) {
    parallel::for_rows(static_cast<std::size_t>(n), parallel::kTouchRowsPerChunk,
                       [&](std::size_t b, std::size_t e) {
                           fn(static_cast<Index>(b), static_cast<Index>(e - b));
                       });
}

// Entry checks, tolerances, history and the final report shared by the four methods.
class Run {
public:
    Run(const char* who, const LinearOperator& A, const Vector& b, Vector& x, const KrylovParams& p)
        : who_(who), A_(A), b_(b), x_(x), p_(p), t0_(wall_seconds()) {
        p.validate();
        MLC_CHECK(A.rows() == A.cols(),
                  who << ": A must be square, found " << A.rows() << " x " << A.cols());
        MLC_CHECK(b.size() == A.rows(),
                  who << ": b has size " << b.size() << ", expected A.rows() = " << A.rows());
        if (x.size() == 0) x.setZero(b.size());
        MLC_CHECK(x.size() == b.size(), who << ": initial guess x has size " << x.size()
                                            << ", expected " << b.size() << " (or empty for 0)");
        if (!b.allFinite()) {
            std::ostringstream os;
            os << who
               << ": the right-hand side b contains NaN or Inf; check the assembly of "
                  "the residual before the linear solve";
            throw SolverBreakdown(os.str());
        }
        MLC_CHECK(x.allFinite(), who << ": the initial guess x contains NaN or Inf");
        bnorm_ = norm(b);
        tol_ = std::max(p.rel_tol * bnorm_, p.abs_tol);
        if (p.record_history) res_.history.reserve(static_cast<size_t>(p.max_iter) + 2);
    }

    // b = 0: x = 0 exactly, nothing to iterate.
    bool trivial() {
        if (bnorm_ > 0.0) return false;
        x_.setZero();
        res_.converged = true;
        res_.reason = StopReason::converged;
        if (p_.record_history) res_.history.push_back(0.0);
        res_.solve_seconds = wall_seconds() - t0_;
        return true;
    }

    // Inner products and norms of distributed vectors: the local part, summed over the
    // processes of params().comm (the global reduction of every iteration). Without comm, the
    // plain Eigen reductions, bit for bit as before.
    double dot(const Eigen::Ref<const Vector>& a, const Eigen::Ref<const Vector>& b) const {
        const double d = a.dot(b);
        return p_.comm ? p_.comm->sum(d) : d;
    }
    double squared_norm(const Eigen::Ref<const Vector>& a) const {
        const double d = a.squaredNorm();
        return p_.comm ? p_.comm->sum(d) : d;
    }
    double norm(const Eigen::Ref<const Vector>& a) const {
        return p_.comm ? std::sqrt(p_.comm->sum(a.squaredNorm())) : a.norm();
    }

    bool ok(double rnorm) const { return rnorm <= tol_; }
    const KrylovParams& params() const { return p_; }

    void initial(double rnorm) {
        res_.initial_residual = rnorm;
        record(rnorm);
    }
    void record(double rnorm) {
        if (p_.record_history) res_.history.push_back(rnorm);
        if (rnorm < best_) best_ = rnorm;
    }

    // Whether to stop before iteration `it`: max_iter reached (empty message), or a rate that
    // projects more than give_up_budget iterations in all.
    std::optional<std::string> should_stop(int it) const {
        if (it >= p_.max_iter) return std::string();
        if (p_.give_up_budget <= 0 || it == 0 || it % 50 != 0) return std::nullopt;
        const double r0 = res_.initial_residual;
        if (!(r0 > 0.0) || !(best_ > tol_)) return std::nullopt;
        const double rate = std::log(r0 / best_) / it; // per iteration, natural log
        const double needed = rate > 0.0 ? std::log(best_ / tol_) / rate : 1e300;
        if (static_cast<double>(it) + needed <= p_.give_up_budget) return std::nullopt;
        std::ostringstream os;
        os << std::setprecision(3) << "given up at iteration " << it << ": the residual fell by "
           << r0 / best_ << ", at that rate the tolerance needs about " << needed
           << " more iterations (budget " << p_.give_up_budget << ")";
        return os.str();
    }

    // t = b - A x; returns ||t||.
    double true_residual(Vector& t) const {
        A_.apply(x_, t);
        traffic::vectors(b_.size(), 4); // t = b - t, ||t||
        elementwise(b_.size(), [&](Index i, Index m) {
            t.segment(i, m) = b_.segment(i, m) - t.segment(i, m);
        });
        return norm(t);
    }

    // Ends the solve: the reported residual is the true one, `true_rnorm` = ||b - A x||.
    SolveResult finish(StopReason reason, int iterations, double true_rnorm,
                       std::string message = {}) {
        res_.iterations = iterations;
        res_.final_residual = true_rnorm;
        res_.relative_residual = true_rnorm / bnorm_;
        if (!std::isfinite(true_rnorm)) {
            reason = StopReason::breakdown;
            if (message.empty()) message = "the true residual is not finite";
        } else if (ok(true_rnorm)) {
            reason = StopReason::converged; // the true residual is what counts
            message.clear();
        } else if (reason == StopReason::converged) {
            reason = StopReason::max_iter; // cannot happen by construction; stay honest
        }
        res_.reason = reason;
        res_.converged = reason == StopReason::converged;
        if (!message.empty()) res_.message = std::string(who_) + ": " + message;
        if (iterations > 0 && res_.initial_residual > 0.0 && std::isfinite(true_rnorm))
            res_.average_rate =
                std::pow(true_rnorm / res_.initial_residual, 1.0 / static_cast<double>(iterations));
        res_.solve_seconds = wall_seconds() - t0_;
        return std::move(res_);
    }

    SolveResult result() { return std::move(res_); }

private:
    const char* who_;
    const LinearOperator& A_;
    const Vector& b_;
    Vector& x_;
    const KrylovParams& p_;
    double t0_;
    double bnorm_ = 0.0;
    double tol_ = 0.0;
    double best_ = std::numeric_limits<double>::infinity(); // smallest monitored residual
    SolveResult res_;
};

std::string at(const char* what, int it, double value) {
    std::ostringstream os;
    os << what << " = " << value << " at iteration " << it;
    return os.str();
}

} // namespace

SolveResult cg(const LinearOperator& A, const Preconditioner& M, const Vector& b, Vector& x,
               const KrylovParams& params) {
    Run run("cg", A, b, x, params);
    if (run.trivial()) return run.result();
    const Index n = b.size();
    // Workspace from parallel::zeros: its pages are first touched by all threads
    // (core/first_touch).
    Vector r = parallel::zeros(n), z = parallel::zeros(n), p = parallel::zeros(n),
           q = parallel::zeros(n), t = parallel::zeros(n);
    double rn = run.true_residual(t);
    r = t;
    run.initial(rn);
    if (run.ok(rn)) return run.finish(StopReason::converged, 0, rn);
    int it = 0;
    double rz = 0.0;
    while (true) {
        if (const auto stop = run.should_stop(it))
            return run.finish(StopReason::max_iter, it, run.true_residual(t), *stop);
        M.apply(r, z);
        const double rz_new = run.dot(r, z);
        if (it == 0)
            p = z;
        else
            p = z + (rz_new / rz) * p;
        rz = rz_new;
        A.apply(p, q);
        const double pq = run.dot(p, q);
        if (!(pq > 0.0) || !std::isfinite(pq))
            return run.finish(StopReason::breakdown, it, run.true_residual(t),
                              at("(p, A p)", it, pq));
        const double a = rz / pq;
        x += a * p;
        r -= a * q;
        ++it;
        rn = run.norm(r);
        traffic::vectors(n, 10); // (r, z), p, (p, q), x, r, ||r||
        run.record(rn);
        if (!std::isfinite(rn))
            return run.finish(StopReason::breakdown, it, run.true_residual(t),
                              at("residual norm", it, rn));
        if (run.ok(rn)) return run.finish(StopReason::converged, it, run.true_residual(t));
    }
}

SolveResult cgs(const LinearOperator& A, const Preconditioner& M, const Vector& b, Vector& x,
                const KrylovParams& params) {
    Run run("cgs", A, b, x, params);
    if (run.trivial()) return run.result();
    const Index n = b.size();
    Vector r = parallel::zeros(n), z0 = parallel::zeros(n), z = parallel::zeros(n),
           p = parallel::zeros(n), q = parallel::zeros(n), y = parallel::zeros(n),
           h = parallel::zeros(n), w = parallel::zeros(n), t = parallel::zeros(n);

    double rn = run.true_residual(t);
    r = t;
    traffic::vectors(n, 2);
    run.initial(rn);
    if (run.ok(rn)) return run.finish(StopReason::converged, 0, rn);

    int it = 0;
    bool restart = true;
    double rho = 0.0;
    while (true) {
        if (restart) { // (re)start the recursion from the true residual r
            M.apply(r, z0);
            p = z0;
            q = z0;
            rho = run.squared_norm(z0);
            traffic::vectors(n, 5);
            if (bad(rho))
                return run.finish(StopReason::breakdown, it, run.true_residual(t),
                                  at("(z0, z0) with z0 = C^{-1} r0", it, rho));
            restart = false;
        }
        if (const auto stop = run.should_stop(it))
            return run.finish(StopReason::max_iter, it, run.true_residual(t), *stop);

        A.apply(q, t);
        M.apply(t, y); // y = C^{-1} A q
        const double sigma = run.dot(z0, y);
        if (bad(sigma))
            return run.finish(StopReason::breakdown, it, run.true_residual(t),
                              at("(z0, C^{-1} A q)", it, sigma));
        const double a = rho / sigma;
        if (!std::isfinite(a))
            return run.finish(StopReason::breakdown, it, run.true_residual(t), at("alpha", it, a));
        h = p - a * y;
        w = p + h;
        x += a * w;
        A.apply(w, t);
        r -= a * t;
        ++it;
        rn = run.norm(r);
        traffic::vectors(n, 15); // (z0, y), h, w, x, r, ||r||
        run.record(rn);
        if (!std::isfinite(rn))
            return run.finish(StopReason::breakdown, it, run.true_residual(t),
                              at("residual norm", it, rn));
        if (run.ok(rn)) {
            const double tr = run.true_residual(t);
            if (run.ok(tr) || !std::isfinite(tr)) return run.finish(StopReason::converged, it, tr);
            r = t; // recursive residual drifted: restart from the true one
            traffic::vectors(n, 2);
            restart = true;
            continue;
        }
        M.apply(r, z);
        const double rho_new = run.dot(z0, z);
        if (bad(rho_new))
            return run.finish(StopReason::breakdown, it, run.true_residual(t),
                              at("(z0, C^{-1} r)", it, rho_new));
        const double beta = rho_new / rho;
        rho = rho_new;
        p = z + beta * h;
        q = p + beta * (h + beta * q);
        traffic::vectors(n, 9); // (z0, z), p, q
    }
}

SolveResult bicg(const LinearOperator& A, const Preconditioner& M, const Vector& b, Vector& x,
                 const KrylovParams& params) {
    Run run("bicg", A, b, x, params);
    if (run.trivial()) return run.result();
    const Index n = b.size();
    Vector r = parallel::zeros(n), rt = parallel::zeros(n), z = parallel::zeros(n),
           zt = parallel::zeros(n), p = parallel::zeros(n), pt = parallel::zeros(n),
           q = parallel::zeros(n), qt = parallel::zeros(n), t = parallel::zeros(n);

    double rn = run.true_residual(t);
    r = t;
    rt = r;
    traffic::vectors(n, 4);
    run.initial(rn);
    if (run.ok(rn)) return run.finish(StopReason::converged, 0, rn);

    int it = 0;
    bool restart = true;
    double rho_old = 1.0;
    while (true) {
        if (const auto stop = run.should_stop(it))
            return run.finish(StopReason::max_iter, it, run.true_residual(t), *stop);
        M.apply(r, z);
        M.apply_transpose(rt, zt);
        const double rho = run.dot(z, rt);
        if (bad(rho))
            return run.finish(StopReason::breakdown, it, run.true_residual(t),
                              at("rho = (C^{-1} r, r~)", it, rho));
        if (restart) {
            p = z;
            pt = zt;
            restart = false;
            traffic::vectors(n, 6); // (z, r~), p, p~
        } else {
            const double beta = rho / rho_old;
            p = z + beta * p;
            pt = zt + beta * pt;
            traffic::vectors(n, 8);
        }
        A.apply(p, q);
        A.apply_transpose(pt, qt);
        const double d = run.dot(pt, q);
        if (bad(d))
            return run.finish(StopReason::breakdown, it, run.true_residual(t),
                              at("(p~, A p)", it, d));
        const double alpha = rho / d;
        x += alpha * p;
        r -= alpha * q;
        rt -= alpha * qt;
        rho_old = rho;
        ++it;
        rn = run.norm(r);
        traffic::vectors(n, 12); // (p~, q), x, r, r~, ||r||
        run.record(rn);
        if (!std::isfinite(rn) || !std::isfinite(alpha))
            return run.finish(StopReason::breakdown, it, run.true_residual(t),
                              at("residual norm", it, rn));
        if (run.ok(rn)) {
            const double tr = run.true_residual(t);
            if (run.ok(tr) || !std::isfinite(tr)) return run.finish(StopReason::converged, it, tr);
            r = t;
            rt = r;
            traffic::vectors(n, 4);
            restart = true;
        }
    }
}

SolveResult bicgstab(const LinearOperator& A, const Preconditioner& M, const Vector& b, Vector& x,
                     const KrylovParams& params) {
    Run run("bicgstab", A, b, x, params);
    if (run.trivial()) return run.result();
    const Index n = b.size();
    Vector r = parallel::zeros(n), rh = parallel::zeros(n), p = parallel::zeros(n),
           ph = parallel::zeros(n), v = parallel::zeros(n), sh = parallel::zeros(n),
           t = parallel::zeros(n);

    double rn = run.true_residual(t);
    parallel::copy(t.data(), static_cast<std::size_t>(n), r.data());
    traffic::vectors(n, 2);
    run.initial(rn);
    if (run.ok(rn)) return run.finish(StopReason::converged, 0, rn);

    int it = 0;
    bool restart = true;
    double rho_old = 1.0, alpha = 1.0, omega = 1.0;
    // On a claimed convergence: accept when the true residual agrees, else restart from it.
    auto check_true = [&](bool& done, SolveResult& out) {
        const double tr = run.true_residual(t);
        if (run.ok(tr) || !std::isfinite(tr)) {
            out = run.finish(StopReason::converged, it, tr);
            done = true;
            return;
        }
        parallel::copy(t.data(), static_cast<std::size_t>(n), r.data());
        traffic::vectors(t.size(), 2);
        restart = true;
    };
    while (true) {
        if (restart) {
            parallel::copy(r.data(), static_cast<std::size_t>(n), rh.data());
            rho_old = alpha = omega = 1.0;
            parallel::fill(v.data(), static_cast<std::size_t>(n), 0.0);
            parallel::fill(p.data(), static_cast<std::size_t>(n), 0.0);
            restart = false;
            traffic::vectors(n, 4);
        }
        if (const auto stop = run.should_stop(it))
            return run.finish(StopReason::max_iter, it, run.true_residual(t), *stop);
        const double rho = run.dot(rh, r);
        if (bad(rho))
            return run.finish(StopReason::breakdown, it, run.true_residual(t),
                              at("rho = (r^, r)", it, rho));
        const double beta = (rho / rho_old) * (alpha / omega);
        elementwise(n, [&](Index i, Index m) {
            p.segment(i, m) = r.segment(i, m) + beta * (p.segment(i, m) - omega * v.segment(i, m));
        });
        M.apply(p, ph);
        A.apply(ph, v);
        const double d = run.dot(rh, v);
        if (bad(d))
            return run.finish(StopReason::breakdown, it, run.true_residual(t),
                              at("(r^, A C^{-1} p)", it, d));
        alpha = rho / d;
        elementwise(n, [&](Index i, Index m) { r.segment(i, m) -= alpha * v.segment(i, m); }); // s
        const double sn = run.norm(r);
        traffic::vectors(n, 12); // (r^, r), p, (r^, v), s, ||s||
        if (!std::isfinite(sn) || !std::isfinite(alpha))
            return run.finish(StopReason::breakdown, it + 1, run.true_residual(t),
                              at("half-step residual norm", it + 1, sn));
        if (run.ok(sn)) { // converged at the half step: x += alpha p^
            elementwise(n, [&](Index i, Index m) { x.segment(i, m) += alpha * ph.segment(i, m); });
            traffic::vectors(n, 3);
            ++it;
            run.record(sn);
            bool done = false;
            SolveResult out;
            check_true(done, out);
            if (done) return out;
            continue;
        }
        M.apply(r, sh);
        A.apply(sh, t);
        const double tt = run.squared_norm(t);
        const double ts = run.dot(t, r);
        omega = ts / tt;
        if (bad(tt) || bad(omega)) {
            elementwise(n, [&](Index i, Index m) {
                x.segment(i, m) += alpha * ph.segment(i, m);
            }); // the half step is still a valid update
            return run.finish(StopReason::breakdown, it + 1, run.true_residual(t),
                              at("omega = (t, s) / (t, t)", it + 1, omega));
        }
        elementwise(n, [&](Index i, Index m) {
            x.segment(i, m) += alpha * ph.segment(i, m) + omega * sh.segment(i, m);
            r.segment(i, m) -= omega * t.segment(i, m);
        });
        rho_old = rho;
        ++it;
        rn = run.norm(r);
        traffic::vectors(n, 11); // (t, t), (t, s), x, r, ||r||
        run.record(rn);
        if (!std::isfinite(rn))
            return run.finish(StopReason::breakdown, it, run.true_residual(t),
                              at("residual norm", it, rn));
        if (run.ok(rn)) {
            bool done = false;
            SolveResult out;
            check_true(done, out);
            if (done) return out;
        }
    }
}

SolveResult gmres(const LinearOperator& A, const Preconditioner& M, const Vector& b, Vector& x,
                  const KrylovParams& params) {
    Run run("gmres", A, b, x, params);
    if (run.trivial()) return run.result();
    const Index n = b.size();
    const Index m = std::min<Index>(params.restart, n);
    Eigen::MatrixXd V(n, m + 1), H(m + 1, m);
    Vector cs(m), sn(m), g(m + 1), y(m), w(n), t(n), u(n);

    double beta = run.true_residual(w);
    run.initial(beta);
    int it = 0;
    while (true) {
        if (run.ok(beta)) return run.finish(StopReason::converged, it, beta);
        if (const auto stop = run.should_stop(it))
            return run.finish(StopReason::max_iter, it, beta, *stop);

        V.col(0) = w / beta;
        traffic::vectors(n, 2);
        g.setZero();
        g(0) = beta;
        Index k = 0; // Arnoldi columns done in this cycle
        std::string failure;
        while (k < m && it < params.max_iter) {
            const Index j = k;
            t = V.col(j);
            M.apply(t, u);
            A.apply(u, w);                   // w = A C^{-1} v_j
            for (Index i = 0; i <= j; ++i) { // modified Gram-Schmidt
                const double hij = run.dot(w, V.col(i));
                w -= hij * V.col(i);
                H(i, j) = hij;
            }
            const double hn = run.norm(w);
            H(j + 1, j) = hn;
            if (!std::isfinite(hn)) {
                failure = at("Arnoldi norm h(j+1,j)", it + 1, hn);
                break;
            }
            if (hn > 0.0) V.col(j + 1) = w / hn;
            // t = v_j, j + 1 dots and axpys, ||w||, v_{j+1}
            traffic::vectors(n, 2 + 5 * static_cast<int>(j + 1) + 1 + 2);
            for (Index i = 0; i < j; ++i) { // previous Givens rotations
                const double hi = H(i, j), hi1 = H(i + 1, j);
                H(i, j) = cs(i) * hi + sn(i) * hi1;
                H(i + 1, j) = -sn(i) * hi + cs(i) * hi1;
            }
            const double den = std::hypot(H(j, j), H(j + 1, j));
            if (bad(den)) {
                failure =
                    at("Hessenberg pivot (A C^{-1} singular on the Krylov space)", it + 1, den);
                break;
            }
            cs(j) = H(j, j) / den;
            sn(j) = H(j + 1, j) / den;
            H(j, j) = den;
            H(j + 1, j) = 0.0;
            g(j + 1) = -sn(j) * g(j);
            g(j) = cs(j) * g(j);
            ++k;
            ++it;
            const double est = std::abs(g(j + 1));
            run.record(est);
            if (run.ok(est) || hn == 0.0) break;
        }
        // x += C^{-1} V_k y_k with H_k y_k = g_k (back substitution, no allocation).
        if (k > 0) {
            for (Index i = k - 1; i >= 0; --i) {
                double s = g(i);
                for (Index l = i + 1; l < k; ++l)
                    s -= H(i, l) * y(l);
                y(i) = s / H(i, i);
            }
            t.noalias() = V.leftCols(k) * y.head(k);
            M.apply(t, u);
            x += u;
            traffic::vectors(n, static_cast<int>(k) + 1 + 3);
        }
        const double beta_old = beta;
        beta = run.true_residual(w);
        if (!failure.empty()) return run.finish(StopReason::breakdown, it, beta, failure);
        if (!std::isfinite(beta))
            return run.finish(StopReason::breakdown, it, beta, at("true residual", it, beta));
        if (!run.ok(beta) && !(beta < beta_old) && it < params.max_iter)
            return run.finish(StopReason::breakdown, it, beta,
                              "a full restart cycle did not reduce the residual (stagnation); "
                              "use a larger restart or a better preconditioner");
    }
}

std::string_view to_string(Krylov k) {
    switch (k) {
    case Krylov::cgs:
        return "cgs";
    case Krylov::bicg:
        return "bicg";
    case Krylov::bicgstab:
        return "bicgstab";
    case Krylov::gmres:
        return "gmres";
    }
    return "unknown";
}

std::ostream& operator<<(std::ostream& os, Krylov k) {
    return os << to_string(k);
}

Krylov parse_krylov(std::string_view name) {
    for (Krylov k : {Krylov::cgs, Krylov::bicg, Krylov::bicgstab, Krylov::gmres})
        if (name == to_string(k)) return k;
    MLC_CHECK(false,
              "unknown Krylov method '" << name << "'; valid names: cgs, bicg, bicgstab, gmres");
    return Krylov::cgs; // not reached
}

SolveResult solve(Krylov method, const LinearOperator& A, const Preconditioner& M, const Vector& b,
                  Vector& x, const KrylovParams& params) {
    switch (method) {
    case Krylov::cgs:
        return cgs(A, M, b, x, params);
    case Krylov::bicg:
        return bicg(A, M, b, x, params);
    case Krylov::bicgstab:
        return bicgstab(A, M, b, x, params);
    case Krylov::gmres:
        return gmres(A, M, b, x, params);
    }
    MLC_CHECK(false, "solve: invalid Krylov value " << static_cast<int>(method));
    return {};
}

SolveResult solve(Krylov method, const SparseMatrix& A, const Preconditioner& M, const Vector& b,
                  Vector& x, const KrylovParams& params) {
    const MatrixOperator op(A);
    return solve(method, op, M, b, x, params);
}

} // namespace mlc::solvers
