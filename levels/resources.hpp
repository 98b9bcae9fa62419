// SPDX-License-Identifier: MIT
/// @file What a run will need before it is built: the sizes of every level predicted from level
/// 0, the Newton-system solver the driver chooses for them (the default picks by size), the peak
/// memory that run is estimated to need, and the memory this process may use.
#pragma once

#include "levels/newton_system.hpp"
#include "levels/problem.hpp"
#include "solvers/pc_spec.hpp"

#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace mlc::levels {

/// Predicted size of one level (exact on level 0; refinement counts for vertices, edges and
/// triangles; boundary quantities doubled per level).
struct LevelSize {
    int level = 0;
    double vertices = 0, edges = 0, triangles = 0;
    double unknowns = 0;      ///< displacements and multipliers
    double contact_nodes = 0; ///< contact elements
    double multipliers = 0;   ///< contact multiplier unknowns
    double k_nonzeros = 0;    ///< of the elastic operator K on the unknowns
};

/// Sizes of levels 0..problem.levels from problem.mesh0 alone (level 0 is built to count its
/// unknowns and contact nodes; nothing finer is allocated). Vertices, edges and triangles follow
/// the 1 -> 4 refinement exactly (V' = V + E, E' = 2 E + 3 T, T' = 4 T); unknowns and the
/// nonzeros of K scale with V + 2 E (a vertex row couples to itself and its neighbours),
/// fixed components and contact nodes with the boundary, which doubles per level.
std::vector<LevelSize> predict_level_sizes(const Problem& problem);

/// Finest-level unknowns above which the default Newton-system solver is Krylov + mg (BiCGStab +
/// the V(0,2) cycle) rather than the exact `schur`, with rigid obstacles only and with a two-body
/// pair: where the two take about the same time with OpenBLAS behind CHOLMOD, mg's memory no
/// larger than schur's wherever it is chosen (docs/solver-guide.md#solver-default).
inline constexpr double kMgCrossoverOneBody = 2000;
inline constexpr double kMgCrossoverTwoBody = 10000;

/// The preconditioner the driver takes for `mg` when nobody named one: a V(0,2) cycle (no
/// pre-smoothing, two backward sweeps after the coarse correction), which needs fewer bytes per
/// Newton step than V(1,1) for the same or fewer Krylov iterations
/// (docs/solver-guide.md#solver-why-default); with a two-body pair the sweeps are also damped
/// (omega = 0.8), which needs fewer BiCGStab iterations there; with rigid obstacles only they are
/// not (the square's iterations grow with omega = 0.8). Their canonical text, as reports print it.
inline constexpr const char* kMgDefaultOneBody = "mg:pre=0,post=2";
inline constexpr const char* kMgDefaultTwoBody = "mg:omega=0.8,pre=0,post=2";
/// The Krylov method the driver takes with its default mg (the V(0,2) cycle is not symmetric,
/// and BiCGStab needs fewer V-cycles than CGS with it).
inline constexpr solvers::Krylov kMgDefaultKrylov = solvers::Krylov::bicgstab;

/// The crossover that applies to `problem` (two-body pairs or not).
double mg_crossover_unknowns(const Problem& problem);

/// Whether `problem` has a two-body pair (node on facet or node on node): what selects the
/// two-body crossover and the damped default mg.
bool has_two_body_pair(const Problem& problem);

/// The finest level from which the default mg sweeps by lattices (16 subdivisions of every
/// level-0 edge: solvers::kMinLatticeSubdivisions).
inline constexpr int kMgDefaultLatticeLevel = 4;

/// The finest level from which the default mg sweeps by lattices on several processes (each
/// process its own level-0 triangles). Level 4 keeps the block sweep there: its values would move
/// by about 1e-11 against the block sweep's.
inline constexpr int kMgDistributedLatticeLevel = 5;

/// The default mg: kMgDefaultTwoBody with a two-body pair, else kMgDefaultOneBody; with
/// `lattice`, the lattice sweep of levels 4 and finer (smoother=lattice) too.
solvers::PcSpec default_mg(bool two_body, bool lattice = false);

/// What the user asked for, parsed at the edge (solvers::parse_pc, solvers::parse_method,
/// solvers::parse_krylov, parse_numbering); unset fields take the planner's defaults.
struct SolverRequest {
    std::optional<solvers::Method> linear{};
    std::optional<solvers::Krylov> krylov{};
    std::optional<solvers::PcSpec> pc{};
    std::optional<double> rel_tol{}; ///< Krylov relative tolerance
    /// The numbering of the levels as requested; unset: the problem's, or lattice where the
    /// preconditioner sweeps by lattices.
    std::optional<Problem::Numbering> numbering{};
};

/// The whole Newton-system solver of a run: method, Krylov method, preconditioner and
/// tolerances (`spec`, whose `numbering` is the levels' numbering the hierarchy is built with),
/// whether the planner chose it by size, and why.
struct SolverPlan {
    LinearSolverSpec spec;
    bool automatic = false; ///< chosen by size (no solver option given)
    int processes = 1;      ///< the processes it was planned for
    std::string reason;     ///< one sentence, for the report and summary.json
    /// The numbering of the levels (spec.numbering, always set by the planner).
    Problem::Numbering numbering() const {
        return spec.numbering.value_or(Problem::Numbering::hilbert);
    }
    /// The levels are numbered by lattices (macro triangle by macro triangle).
    bool lattice_numbering() const { return numbering() == Problem::Numbering::lattice; }
};

/// The one planner of every front end (run on one process and many, benches, studies, Python).
///
/// On one process: `pc`, `krylov` or `rel_tol` alone mean a Krylov solve; `linear krylov`
/// without `pc` uses the default mg (damped with a two-body pair; over an aggregation hierarchy
/// on a single level) with BiCGStab; nothing at all chooses by size: `schur` up to
/// mg_crossover_unknowns(problem) unknowns on the finest level, Krylov + mg above it when levels
/// exist (BiCGStab + the V(0,2) cycle, damped with a two-body pair; from level
/// kMgDefaultLatticeLevel on with the lattice sweep on levels numbered for it, unless the
/// request names numbering hilbert). `pc` alone without `krylov` takes CGS. A Krylov option
/// next to `linear schur` or `linear lu` contradicts it and throws InvalidInput saying so.
///
/// On several processes (`processes` > 1): always a Krylov method, BiCGStab + the default mg
/// (never schur; from level kMgDistributedLatticeLevel on with the lattice sweep on each
/// process's part numbered for it, unless the request names numbering hilbert); a named `pc` takes
/// CGS, BiCGStab with a two-body pair; a method or preconditioner without a distributed form
/// (PreconditionerEntry::distributed) is refused naming the alternative; the levels keep the
/// Hilbert numbering unless the preconditioner sweeps by lattices (mg:smoother=lattice: each
/// process's part numbered by lattices).
///
/// A preconditioner that sweeps by lattices numbers the levels for it (spec.numbering lattice)
/// and is refused below level 4 or with numbering hilbert requested; one that needs the level
/// below is refused on a single level. `sizes`: predict_level_sizes(problem) when the caller
/// has it already (it builds level 0).
SolverPlan plan_solver(const Problem& problem, const SolverRequest& request, int processes = 1,
                       const std::vector<LevelSize>* sizes = nullptr);

/// The plan the default takes above the crossover whatever the size (BiCGStab unless
/// `request.krylov` says otherwise, the default mg, the lattice sweep where the default takes
/// it): what `bench square` and the studies call "default". `request` names no method and no
/// preconditioner.
SolverPlan plan_default_mg(const Problem& problem, const SolverRequest& request, int processes = 1);

/// The numbering the hierarchy of a solve with `spec` is built with: spec.numbering when set,
/// else lattice when its preconditioner sweeps by lattices, else the problem's. Throws
/// InvalidInput naming the fix when a lattice sweep cannot take effect (a finest level below 4,
/// or numbering hilbert asked for). levels::solve calls it: no caller numbers levels by hand.
Problem::Numbering hierarchy_numbering(const Problem& problem, const LinearSolverSpec& spec);

/// Peak resident memory a run is estimated to need, and its parts.
struct MemoryEstimate {
    double bytes = 0;           ///< total
    double hierarchy_bytes = 0; ///< meshes, K, transfers, vectors of all levels
    double solver_bytes = 0;    ///< Jacobians, smoothers, factors of the Newton-system solvers
    /// What the run keeps per load step until its files are written (the reports of every solved
    /// level, the finest level's contact states, the step states when kept) and the summary
    /// built from them: grows with the load steps.
    double steps_bytes = 0;
    /// Size of the files the run writes (contact_steps.csv, iterations.csv, summary.json and
    /// the final state; not the per-step VTU files): on disk, not in memory.
    double output_bytes = 0;
    int largest_level = 0; ///< the level whose solver dominates
};

/// What a run keeps per load step, for estimate_memory.
struct StepsKept {
    int load_steps = 1;
    bool keep_step_states = false; ///< SolveOptions::keep_step_states (a displacement per step)
};

/// Bytes a run holds per load step until its files are written: per solved level (its LevelStep
/// and StepReport with their vectors, and the entries of summary.json built from them before it is
/// written, most of the peak), per contact node of the finest level (its ContactNodeState and
/// statuses), and per vertex of the finest level when the step states are kept (two doubles).
/// Fitted on the peak resident memory of a block on a floor with two numbers of contact nodes
/// and of load steps, rounded up.
inline constexpr double kStepBytesPerLevel = 7168;
inline constexpr double kStepBytesPerContactNode = 128;
inline constexpr double kStepBytesPerKeptVertex = 16;
/// Bytes written per load step: a contact_steps.csv row per contact node of the finest level,
/// and per solved level its summary.json entries and iterations.csv rows (the same runs' files,
/// rounded up).
inline constexpr double kOutputBytesPerContactNode = 150;
inline constexpr double kOutputBytesPerLevel = 1024;

/// Estimates the peak resident memory of `levels::solve` for these sizes and solver (a fit of
/// measured peaks on the square, hertz and dovetail ladders), with what the
/// run keeps per load step (`steps`: MemoryEstimate::steps_bytes) and the size of its files.
MemoryEstimate estimate_memory(const std::vector<LevelSize>& sizes, const LinearSolverSpec& spec,
                               bool coarse_to_fine, const StepsKept& steps = {});

/// The memory this process may use: the smallest of MemAvailable (/proc/meminfo), the cgroup
/// limit less its current usage (v2 memory.max / v1 memory.limit_in_bytes) and RLIMIT_AS less the
/// address space already mapped.
struct MemoryLimit {
    double bytes = 0;
    std::string source; ///< which of the three it is, e.g. "RLIMIT_AS (ulimit -v)"
};
MemoryLimit process_memory_limit();

/// Throws InvalidInput when `estimate` does not fit in `limit`, naming the level, the estimate
/// (and its per-step part when that is the larger one) and the limit.
void check_memory_fits(const MemoryEstimate& estimate, const MemoryLimit& limit,
                       const std::vector<LevelSize>& sizes);

/// "123 MiB" / "4.5 GiB".
std::string format_bytes(double bytes);

/// Level 0 of a mesh known only by its predicted triangle count T (before meshing): V = T / 2,
/// E = 3 T / 2 (Euler's relation without the boundary), 2 V unknowns, the nonzeros of K
/// 4 (V + 2 E), no multipliers.
LevelSize level_size_from_triangles(double triangles);

/// Bytes the CGAL domain mesher holds per triangle at its peak (the constrained Delaunay
/// triangulation, the queue of bad triangles, the Mesh it returns): the growth of the peak
/// resident memory of Scene.from_file with the triangles of uniform hertz domains, rounded up.
inline constexpr double kMeshingBytesPerTriangle = 400.0;

/// Estimated peak memory of meshing `triangles` triangles and solving them as a single level
/// (estimate_memory of level_size_from_triangles with the default single-level solver): a
/// mesh that fails this cannot be used whatever the levels.
double meshing_memory(double triangles);

/// Throws InvalidInput when meshing_memory(triangles) does not fit in `limit`: "<what> needs an
/// estimated ... to mesh and solve as one level, but this process may use ... (<source>)", then
/// `fix`. Called before meshing, so that a size field that cannot fit is refused at once.
void check_meshing_fits(double triangles, const std::string& what, const std::string& fix,
                        const MemoryLimit& limit);

} // namespace mlc::levels
