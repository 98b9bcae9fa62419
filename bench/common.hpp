// SPDX-License-Identifier: MIT
/// @file What the benches share: medians, JSON strings and files, memory, Jacobian sizes.
#pragma once

#include "core/atomic_file.hpp"
#include "core/memory.hpp"
#include "core/traffic.hpp"
#include "levels/level.hpp"
#include "levels/newton_system.hpp"

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace mlc::apps {

/// Peak resident set size of this process, MiB.
double peak_rss_mib();

/// Median of `v` (0 when empty).
double median(std::vector<double> v);

/// `s` as a JSON string (quotes and backslashes escaped).
std::string json_string(const std::string& s);

/// The JSON a bench writes: `given`, or out/bench/<prefix><scene>_L<levels>.json.
std::filesystem::path bench_json_path(const std::string& given, const std::string& prefix,
                                      const std::string& scene, int levels);

/// `file` opened for writing (its folder created), 6 significant digits.
AtomicOfstream open_json(const std::filesystem::path& file);

/// Nonzeros of the Jacobian pattern of a level: K plus the contact tangent entries outside it.
long jacobian_nonzeros(const levels::Level& L);

/// Median seconds of one csr_multiply of A (after one untimed call), at least `min_calls` calls
/// and about `min_seconds` in all (at most 1000 calls).
double time_matvec(const SparseMatrix& A, int min_calls = 10, double min_seconds = 0.5);

/// A count rounded to the nearest integer, to be printed exactly (JSON numbers are written with
/// 6 significant digits otherwise).
long long whole(double v);

/// 1e9 bytes per second (0 when no time was measured).
double gbs(double bytes, double seconds);

/// Bytes of the kinds whose passes read an assembled matrix: matvec, smoother, transfer (the
/// lattice smoother's structured passes, Kind::structured, are judged by their time instead).
double matrix_bytes(const traffic::Account& a);
/// Seconds of the same kinds.
double matrix_seconds(const traffic::Account& a);

/// What `bench square` records about one level during a run.
struct LevelTraffic {
    traffic::Account account;  ///< counted passes of the level's Newton solves (outermost only)
    double krylov_seconds = 0; ///< SolveResult::solve_seconds of those solves
    int solves = 0;            ///< Newton systems solved
    double rss_at_build = 0;   ///< current RSS when the run handed over the level's solver
    double rss_growth = 0;     ///< RSS growth: building the solver + its first Newton solve
    bool first_done = false;   ///< the first Newton solve is behind
};

/// Forwards to a level's Newton-system solver and adds the counted passes of each Newton solve
/// to the level's record. `depth` is shared by all levels: a solve reached from inside another
/// level's solve (a coarse solve by the level below's solver) counts for the outermost level
/// only. `last_M` (may be null) receives the statuses of each outermost solve.
template <int dim> class TrafficRecorder final : public levels::BasicForwardingSystemSolver<dim> {
public:
    /// The status matrices of the level's contact elements.
    using Matrix = levels::StatusMatrix<dim>;
    /// Records into `slot`; `rss_before_build` is the RSS before the run built `inner`.
    TrafficRecorder(std::unique_ptr<levels::BasicNewtonSystemSolver<dim>> inner, LevelTraffic* slot,
                    int* depth, double rss_before_build, std::vector<Matrix>* last_M)
        : levels::BasicForwardingSystemSolver<dim>(std::move(inner)), slot_(slot), depth_(depth),
          last_M_(last_M) {
        slot_->rss_at_build = current_rss_bytes();
        slot_->rss_growth = slot_->rss_at_build - rss_before_build;
    }
    using levels::BasicForwardingSystemSolver<dim>::solve;
    /// The inner solve, counted.
    SolveResult solve(const std::vector<Matrix>& M, const Vector& b, Vector& dx,
                      double forcing) override {
        const bool outer = *depth_ == 0;
        const traffic::Account before = traffic::snapshot();
        const double rss0 = current_rss_bytes();
        ++*depth_;
        SolveResult r;
        try {
            r = this->inner().solve(M, b, dx, forcing);
        } catch (...) {
            --*depth_;
            throw;
        }
        --*depth_;
        if (outer) {
            slot_->account += traffic::snapshot() - before;
            slot_->krylov_seconds += r.solve_seconds;
            ++slot_->solves;
            if (last_M_ != nullptr) *last_M_ = M;
        }
        if (!slot_->first_done) {
            slot_->rss_growth += current_rss_bytes() - rss0;
            slot_->first_done = true;
        }
        return r;
    }

private:
    LevelTraffic* slot_;
    int* depth_;
    std::vector<Matrix>* last_M_;
};

} // namespace mlc::apps
