// SPDX-License-Identifier: MIT
/// @file `mlcontact bench`: scaling benchmarks of the multilevel preconditioner.
///
/// - `bench square`: the full coarse-to-fine solve of a scene (all levels, all load steps) with
///   each requested Newton-system solver; per level: unknowns, Jacobian nonzeros, Newton steps,
///   Krylov iterations per Newton step, Jacobian assembly, preconditioner setup and solve seconds,
///   and per run the wall time and peak resident memory (getrusage ru_maxrss). Beside it the
///   bandwidth account: the compulsory bytes of every counted pass (core/traffic.hpp) of each
///   level's Newton solves by kind, their time and GB/s, a STREAM copy/triad measured by the same
///   binary after the first solver's runs, the time of one CSR mat-vec of the finest Jacobian
///   (same threads) and a fine Newton step in those mat-vecs; and per level the RSS growth of
///   building its solver and running its first Newton solve, per unknown. On a 3D scene:
///   bench_square3 (the 3D run's solvers, and the scaling criterion with --scaling).
/// - `bench elastic`: the elastic block alone (K on the free displacement unknowns of the finest
///   level, right-hand side the full load) solved to the same relative tolerance by hypre
///   BoomerAMG-PCG and by our geometric V-cycle (vertex-block Gauss–Seidel, P / P^T, sparse LU
///   on level 0) inside CG and GMRES, side by side in one run. Under mpirun with N > 1 processes:
///   bench/distributed.hpp (bench_elastic_distributed).
/// - `bench newton`: the Newton systems of the finest level, captured from a real coarse-to-fine
///   run (one per Newton step, through levels::SolveObserver::wrap_system_solver), each solved
///   from zero to the same relative tolerance by our Krylov method with `mg` as the run uses it
///   (at each requested thread count), with hypre MGR (solvers/hypre/mgr.hpp) and with
///   BoomerAMG on the whole Jacobian (the naive choice), both at one thread through our
///   Preconditioner interface (hypre has no CGS), and MGR inside hypre's own FlexGMRES;
///   per system: statuses, setup and solve seconds,
///   iterations and the true relative residual ||b - J x|| / ||b|| computed here.
/// All print a table and write JSON.
#pragma once

#include "levels/resources.hpp"

#include <cstddef>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace mlc::apps {

/// Options of `bench square`.
struct BenchSquareOptions {
    std::string scene = "square";
    int levels = 3; ///< finest level L (levels 0..L are all solved)
    /// "schur", "lu", "default" (the run's default mg and Krylov method above the crossover:
    /// levels::kMgDefaultOneBody or kMgDefaultTwoBody with levels::kMgDefaultKrylov), or Krylov
    /// preconditioner specs.
    std::vector<std::string> pcs = {"default"};
    /// Krylov method for the preconditioner specs; unset: CGS, and for "default" the run's.
    std::optional<std::string> krylov;
    /// Order of the unknowns, "hilbert" or "lattice" (levels::Problem::numbering); unset:
    /// bench_numbering.
    std::optional<std::string> numbering;
    double rel_tol = 1e-8; ///< Krylov relative tolerance
    int max_iter = 5000;   ///< Krylov iterations per Newton step
    int repeat = 1;        ///< runs per solver; times are medians over them
    /// Linear load steps taken at the extrapolated state (levels::SolveOptions::extrapolate, the
    /// run's default); off by default here, so that every load step's Newton is measured.
    bool extrapolate = false;
    std::filesystem::path out; ///< JSON file (default out/bench/square_L<L>.json)
    /// STREAM (core/traffic.hpp) array length in doubles, and its repetitions (best taken).
    std::size_t stream_doubles = std::size_t(1) << 25;
    int stream_repeats = 5;
    /// A 3D scene: take the finest level from its [scene].levels (no --levels given).
    bool levels_from_scene = false;
    /// A 3D scene: the scaling criterion (bench_square3): finest levels - 1 and finest levels,
    /// `repeat` runs each, alternated.
    bool scaling = false;
    /// The options given on the command line, by name ("--tol", "--krylov", ...): a 3D scene
    /// refuses those that have no meaning there, naming them.
    std::vector<std::string> given;
};

/// The scaling criterion's bound on the growth of the fine Newton step in fine mat-vecs, from
/// the level below to the finest (`bench square --scaling`): +10 %.
inline constexpr double kScalingMatvecGrowth = 0.10;
/// The scaling criterion's bound on the whole-run wall-time ratio, finest over the level below
/// (8 times the unknowns in 3D): 10.
inline constexpr double kScalingTimeRatio = 10.0;

/// The solver `bench square` runs for the entry `pc` of opt.pcs ("default", "schur", "lu" or a
/// preconditioner spec), planned by levels::plan_solver for `problem` (whose numbering is the
/// bench's, bench_numbering) on `processes`: "default" is the run's Krylov default (BiCGStab +
/// the V(0,2) mg, damped with a two-body pair, the lattice sweep from
/// levels::kMgDefaultLatticeLevel on levels numbered by lattices) whatever the size; a spec
/// runs with opt.krylov (CGS if unset); opt.rel_tol and opt.max_iter bound each Krylov solve.
levels::SolverPlan bench_plan(const BenchSquareOptions& opt, const std::string& pc,
                              const levels::Problem& problem, int processes = 1);

/// "krylov + pc" of a plan (the method name for schur and lu), for tables and JSON.
std::string bench_label(const levels::SolverPlan& plan);

/// The numbering of a single-process `bench square`: opt.numbering if set, else "lattice" when
/// every solver is the default one and the finest level is at least
/// levels::kMgDefaultLatticeLevel (the numbering the run's default takes there) or one of them
/// names the lattice sweep (mg:...,smoother=lattice), else "hilbert" (the named preconditioners
/// keep the numbering they always had).
std::string bench_numbering(const BenchSquareOptions& opt);

/// Runs the benchmark (see the file comment); returns the exit code (0: every run converged).
/// A 3D scene ([scene] dimension = 3) runs bench_square3.
int bench_square(const BenchSquareOptions& opt, std::ostream& os);

/// `bench square` on a 3D contact scene (one process): the whole coarse-to-fine run of
/// levels/solve3.hpp (every level 0..L, every load step, the secant predictor on) with the
/// Newton-system solvers `mlcontact run` plans (levels::plan_contact3): opt.pcs entries
/// "default" or "mg" (the run's plan), "schur" or "lu" (that exact solver on every level).
/// L is opt.levels, or the scene's [scene].levels with opt.levels_from_scene. Per level: unknowns,
/// contact nodes, Newton steps (per load step), Krylov iterations of every Newton system (median,
/// max), the Newton systems' seconds per Newton step and per unknown, one CSR mat-vec of the
/// level's Jacobian (timed after each run at its last statuses) and a Newton step in those
/// mat-vecs, the bandwidth account (counted bytes by kind per Newton step, per unknown and in
/// mat-vecs of the level's Jacobian) and the RSS growth of building the level's solver and its
/// first Newton solve; per run the wall time, peak RSS and the estimate
/// (levels::estimate_contact3_bytes); a STREAM measurement after every run. opt.repeat runs per
/// solver, times are medians. With opt.scaling (one solver, L >= 1): finest L - 1 and finest L,
/// opt.repeat runs each, alternated, and the criterion: the fine Newton step in fine mat-vecs
/// grows by at most kScalingMatvecGrowth, and the whole-run wall-time ratio is at most
/// kScalingTimeRatio (medians). Refuses, naming the option, what applies to 2D scenes only
/// (--krylov, --tol, --max-iter, --numbering, --extrapolate, preconditioner specs). Table and JSON
/// (default out/bench/<scene name>_L<L>.json). Returns 0, or 2 when a run did not converge (the
/// criterion's outcome does not change it).
int bench_square3(const BenchSquareOptions& opt, std::ostream& os);

/// Options of `bench elastic`.
struct BenchElasticOptions {
    std::string scene = "square";
    int levels = 3;        ///< the elastic block of level L
    double rel_tol = 1e-8; ///< relative tolerance of every solve
    int max_iter = 1000;   ///< iterations of every solve
    int repeat = 1;        ///< runs per solver; times are medians over them
    /// JSON file (default out/bench/elastic_<scene>_L<L>.json; on N > 1 processes
    /// out/bench/elastic_<scene>_L<L>_np<N>.json)
    std::filesystem::path out;
    /// A 3D scene: take the finest level from its [scene].levels (no --levels given).
    bool levels_from_scene = false;
    /// A 3D scene: also the direct solve (CHOLMOD's Cholesky factor in its fill-reducing order),
    /// refused when its estimated memory does not fit. A 2D scene refuses it.
    bool direct = false;
};

/// Runs the benchmark (see the file comment); returns the exit code (0: every solve converged).
/// A 3D scene ([scene] dimension = 3) runs bench_elastic3d.
int bench_elastic(const BenchElasticOptions& opt, std::ostream& os);

/// `bench elastic` on a 3D scene (one process): the elastic block of the finest level (K on the
/// free displacement unknowns of the tetrahedral level, right-hand side the full load) solved to
/// opt.rel_tol by our geometric W(2,2) cycle (levels::elastic3_mg_params; 3 x 3 vertex blocks, P /
/// P^T of the 1 -> 8 refinement, sparse LU on level 0) inside CG, and by hypre's PCG with BoomerAMG
/// at hypre's settings for elasticity (solvers::boomeramg_elasticity3d, the three rotational
/// rigid-body modes as interpolation vectors), both on hypre's thread count. The level sizes and
/// the memory are predicted first and a run that cannot fit is refused. Per solver: unknowns,
/// iterations, setup and solve seconds, peak RSS after it and the predicted peak; the time ratio mg
/// / BoomerAMG. Table and JSON (default out/bench/elastic_<scene>_L<L>.json).
int bench_elastic3d(const BenchElasticOptions& opt, std::ostream& os);

/// Options of `bench newton`.
struct BenchNewtonOptions {
    std::string scene = "square";
    int levels = 3;          ///< the finest level L (>= 1; levels 0..L are solved)
    std::string pc = "mg";   ///< our preconditioner spec (the run's)
    std::string mgr = "mgr"; ///< the hypre MGR spec (registry options, e.g. "mgr:theta=0.5")
    bool amg = true;         ///< also BoomerAMG on the whole Jacobian
    /// Also MGR inside hypre's own FlexGMRES(50) ("mgr+fgmres"), as hypre users run it (hypre
    /// has no CGS), at 1 thread.
    bool hypre_gmres = true;
    std::string krylov = "cgs";        ///< Krylov method of every solve
    double rel_tol = 1e-8;             ///< relative tolerance of every solve
    int max_iter = 1000;               ///< iterations per solve (slow solves are cut short earlier)
    int repeat = 1;                    ///< runs per thread count; times are medians over them
    std::vector<int> threads = {1, 2}; ///< thread counts for our pc (hypre: the 1-thread runs)
    std::filesystem::path out;         ///< JSON file (default out/bench/newton_<scene>_L<L>.json)
};

/// Runs the benchmark (see the file comment); returns the exit code (0: every mg and MGR solve
/// reached the tolerance, 2 otherwise).
int bench_newton(const BenchNewtonOptions& opt, std::ostream& os);

} // namespace mlc::apps
