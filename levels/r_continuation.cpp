// SPDX-License-Identifier: MIT
// The r continuation of a load step.
#include "levels/r_continuation.hpp"

#include "core/memory.hpp"

#include <sstream>
#include <vector>

namespace mlc::levels {

std::string schur_does_not_fit(const LevelSize& size, int l) {
    const double need = estimate_memory({size}, LinearSolverSpec{}, false).solver_bytes;
    const MemoryLimit limit = process_memory_limit();
    const double free = limit.bytes - peak_rss_bytes();
    if (need < free) return {};
    std::ostringstream os;
    os << "the exact schur solver of level " << l << " needs an estimated " << format_bytes(need)
       << ", more than the " << format_bytes(free) << " left (" << limit.source << ")";
    return os.str();
}

namespace {

/// Multiplies the augmentation parameter of every contact element of a level by `factor` for
/// its lifetime, and restores the exact values after.
class ScaledAugmentation {
public:
    ScaledAugmentation(Level& L, double factor) : L_(L) {
        r_.reserve(L.contacts.size());
        for (auto& e : L.contacts) {
            r_.push_back(e.r);
            e.r *= factor;
        }
    }
    ~ScaledAugmentation() {
        for (size_t e = 0; e < r_.size(); ++e)
            L_.contacts[e].r = r_[e];
    }
    ScaledAugmentation(const ScaledAugmentation&) = delete;
    ScaledAugmentation& operator=(const ScaledAugmentation&) = delete;

private:
    Level& L_;
    std::vector<double> r_;
};

} // namespace

StepReport continue_in_r(Level& L, int l, const LevelSize& size, const NewtonParams& params,
                         ContactNewton& nw, double s, const Vector& u_prev, const Vector& x0,
                         Vector& x, StepReport failed, double first_factor,
                         std::unique_ptr<NewtonSystemSolver>& kept, const NewtonPolls& polls,
                         Timings* timings) {
    int spent = failed.iterations;
    std::ostringstream tried;
    std::vector<double> factors;
    for (const double f : {1e-2, 1e-4})
        if (first_factor <= 0 || f <= first_factor) factors.push_back(f);
    for (const double factor : factors) {
        const bool reuse = kept && factor == first_factor;
        if (const std::string why = reuse ? std::string() : schur_does_not_fit(size, l);
            !why.empty()) {
            tried << "; no r continuation: " << why;
            break;
        }
        Vector xc = x0;
        StepReport low;
        {
            ScopedTimer t(timings, "newton/r_continuation");
            ScaledAugmentation scaled(L, factor);
            // The schur solver of the scaled level (its factorization holds r) is kept for the
            // later steps of the level, which start at the same factor.
            if (!reuse) kept = make_schur_system_solver(L);
            ContactNewton cn(L, params, std::move(kept), timings);
            cn.set_stop(polls.stop);
            cn.set_interrupt(polls.interrupt);
            low = cn.solve(s, u_prev, xc);
            kept = cn.release_solver();
        }
        spent += low.iterations;
        if (low.stopped) {
            low.iterations = spent;
            return low;
        }
        if (!low.converged) {
            tried << "; at " << factor << " r (schur) from the same initial guess: " << low.message;
            continue;
        }
        const int low_iterations = low.iterations;
        Vector xf = xc;
        StepReport fin = nw.solve(s, u_prev, xf);
        spent += fin.iterations;
        if (fin.stopped) {
            fin.iterations = spent;
            return fin;
        }
        if (!fin.converged) {
            tried << "; at " << factor << " r: converged in " << low_iterations
                  << " Newton iterations, then at r from there: " << fin.message;
            continue;
        }
        std::ostringstream note;
        if (failed.iterations > 0)
            note << "Newton at r failed (" << failed.message << "); ";
        else
            note << "r continuation " << failed.message << ": ";
        note << "solved at " << factor << " r by schur in " << low_iterations
             << " Newton iterations, then at r in " << fin.iterations;
        fin.continuation_factor = factor;
        fin.continuation_iterations = spent - fin.iterations;
        fin.continuation_note = note.str();
        fin.iterations = spent;
        fin.linear_iterations += failed.linear_iterations;
        fin.linear_seconds += failed.linear_seconds + low.linear_seconds;
        fin.linear_setup_seconds += failed.linear_setup_seconds + low.linear_setup_seconds;
        fin.linear_assembly_seconds += failed.linear_assembly_seconds + low.linear_assembly_seconds;
        fin.fallback_solves += failed.fallback_solves;
        if (fin.fallback_reason.empty()) fin.fallback_reason = failed.fallback_reason;
        fin.seconds += failed.seconds + low.seconds;
        x = xf;
        return fin;
    }
    failed.iterations = spent;
    failed.message += tried.str();
    return failed;
}

} // namespace mlc::levels
