// SPDX-License-Identifier: MIT
// Level sizes predicted from level 0, the default Newton-system solver, the memory estimate and
// the memory this process may use.
#include "levels/resources.hpp"

#include "solvers/factory.hpp"

#include "core/check.hpp"
#include "levels/level.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <unordered_set>

namespace mlc::levels {

std::vector<LevelSize> predict_level_sizes(const Problem& problem) {
    problem.validate();
    const Level L0 = build_level(problem, problem.mesh0);
    std::unordered_set<std::uint64_t> edges;
    for (const auto& t : L0.mesh.cells)
        for (int k = 0; k < 3; ++k) {
            const auto a = static_cast<std::uint64_t>(t[static_cast<size_t>(k)]);
            const auto b = static_cast<std::uint64_t>(t[static_cast<size_t>((k + 1) % 3)]);
            edges.insert(std::min(a, b) << 32 | std::max(a, b));
        }
    LevelSize s;
    s.vertices = L0.mesh.n_vertices();
    s.edges = static_cast<double>(edges.size());
    s.triangles = L0.mesh.n_cells();
    s.contact_nodes = L0.n_contact_nodes();
    for (const auto& c : L0.contacts)
        s.multipliers += c.n_multipliers();
    s.unknowns = static_cast<double>(L0.n_unknowns());
    s.k_nonzeros = static_cast<double>(L0.elastic.K.nonZeros());
    // Fixed displacement components: on the boundary (doubling per level).
    const double fixed0 = 2 * s.vertices - (s.unknowns - s.multipliers);
    // Nonzeros of K: 2 x 2 blocks for every vertex and each of its neighbours, less those of
    // fixed components (on the boundary, so their share doubles per level like the boundary).
    const double deficit0 = 4 * (s.vertices + 2 * s.edges) - s.k_nonzeros;
    std::vector<LevelSize> out{s};
    for (int l = 1; l <= problem.levels; ++l) {
        const LevelSize& c = out.back();
        LevelSize f;
        f.level = l;
        f.vertices = c.vertices + c.edges;
        f.edges = 2 * c.edges + 3 * c.triangles;
        f.triangles = 4 * c.triangles;
        const double grow = std::ldexp(1.0, l); // boundary quantities
        f.contact_nodes = s.contact_nodes * grow;
        f.multipliers = s.multipliers * grow;
        f.unknowns = std::max(0.0, 2 * f.vertices - fixed0 * grow) + f.multipliers;
        f.k_nonzeros = std::max(0.0, 4 * (f.vertices + 2 * f.edges) - deficit0 * grow);
        out.push_back(f);
    }
    return out;
}

// ------------------------------------------------------------------------------------------
bool has_two_body_pair(const Problem& problem) {
    for (const auto& c : problem.contacts)
        if (c.two_body()) return true;
    return false;
}

double mg_crossover_unknowns(const Problem& problem) {
    return has_two_body_pair(problem) ? kMgCrossoverTwoBody : kMgCrossoverOneBody;
}

solvers::PcSpec default_mg(bool two_body, bool lattice) {
    solvers::PcSpec s = solvers::parse_pc("mg");
    auto& m = std::get<solvers::MgOptions>(s.options);
    m.pre = 0;
    m.post = 2;
    if (two_body) m.omega = 0.8;
    if (lattice) m.smoother = solvers::MultigridParams::Smoother::lattice;
    return s;
}

Problem::Numbering hierarchy_numbering(const Problem& problem, const LinearSolverSpec& spec) {
    const bool lattice = spec.method == solvers::Method::krylov && spec.pc.lattice_numbering();
    if (!lattice) return spec.numbering.value_or(problem.numbering);
    MLC_CHECK(problem.levels >= kMgDefaultLatticeLevel,
              "--pc " << spec.pc
                      << ": smoother=lattice sweeps levels 4 and finer of a refined hierarchy (16 "
                         "subdivisions of every level-0 edge), and the finest level here is level "
                      << problem.levels << ": use --levels >= 4");
    MLC_CHECK(spec.numbering.value_or(Problem::Numbering::lattice) == Problem::Numbering::lattice,
              "--pc " << spec.pc
                      << ": smoother=lattice needs the levels' unknowns numbered macro triangle "
                         "by macro triangle (--numbering lattice, which the option takes when "
                         "no numbering is given; Problem::numbering = lattice in the library): "
                         "drop --numbering hilbert");
    return Problem::Numbering::lattice;
}

namespace {

// A Krylov option next to a direct method: the message naming both.
void refuse_krylov_option_with_direct(const SolverRequest& req) {
    const bool krylov_option = req.pc || req.krylov || req.rel_tol;
    if (!req.linear || *req.linear == solvers::Method::krylov || !krylov_option) return;
    std::ostringstream os;
    os << "--linear " << *req.linear << " is a direct solve, but ";
    if (req.pc)
        os << "--pc " << *req.pc;
    else if (req.krylov)
        os << "--krylov " << *req.krylov;
    else
        os << "--linear-tol";
    os << " applies to Krylov solves only: drop --linear " << *req.linear
       << " (a preconditioner alone means --linear krylov) or the Krylov option";
    throw InvalidInput(os.str());
}

// On several processes: a Krylov method with mg or a preconditioner with a distributed form.
SolverPlan plan_distributed(const Problem& problem, const SolverRequest& req, int processes) {
    MLC_CHECK(!req.linear || *req.linear == solvers::Method::krylov,
              "--linear " << *req.linear
                          << " has no distributed form (it needs the whole level on one "
                             "process); on several processes the Newton systems are solved by "
                             "a Krylov method with mg (--linear krylov, the default there)");
    SolverPlan c;
    c.processes = processes;
    LinearSolverSpec& s = c.spec;
    const bool two_body = has_two_body_pair(problem);
    s.method = solvers::Method::krylov;
    // The default (BiCGStab + V(0,2) mg) when no preconditioner is named; a named one keeps
    // the Krylov method it always had there (CGS, BiCGStab with a two-body pair).
    s.krylov = req.krylov.value_or(
        req.pc ? (two_body ? solvers::Krylov::bicgstab : solvers::Krylov::cgs) : kMgDefaultKrylov);
    // The default sweeps levels 4 and finer by lattices from a finest level of
    // kMgDistributedLatticeLevel on (not when the request keeps the Hilbert numbering).
    const bool lattice =
        problem.levels >= kMgDistributedLatticeLevel &&
        req.numbering.value_or(Problem::Numbering::lattice) == Problem::Numbering::lattice;
    s.pc = req.pc.value_or(default_mg(two_body, lattice));
    if (req.rel_tol) s.rel_tol = *req.rel_tol;
    const std::string why = s.pc.distributed();
    MLC_CHECK(why.empty(), why);
    if (s.pc.lattice_numbering()) {
        // mg:smoother=lattice: each part numbered by lattices, as on one process.
        s.numbering = req.numbering;
        s.numbering = hierarchy_numbering(problem, s);
    } else {
        MLC_CHECK(!req.numbering || *req.numbering == Problem::Numbering::hilbert,
                  "the lattice numbering has no distributed form without a lattice sweep: on "
                  "several processes each process numbers its unknowns along a Hilbert curve "
                  "(drop --numbering lattice)");
        s.numbering = Problem::Numbering::hilbert;
    }
    c.reason = req.pc ? "Krylov solve with --pc " + s.pc.text() + " as requested"
                      : "on " + std::to_string(processes) +
                            " processes: BiCGStab + distributed multilevel mg (V(0,2) cycle" +
                            (two_body ? ", damped with a two-body pair" : "") +
                            (s.pc.lattice_numbering()
                                 ? "; levels 4 and finer numbered and swept macro triangle by "
                                   "macro triangle on each process, --numbering hilbert for the "
                                   "block sweep)"
                                 : ")");
    s.validate();
    return c;
}

// A Krylov solve asked for (a preconditioner, a Krylov method, a tolerance or --linear krylov).
void plan_krylov(const Problem& problem, const SolverRequest& req, SolverPlan& c) {
    LinearSolverSpec& s = c.spec;
    const bool has_levels = problem.levels >= 1;
    s.method = solvers::Method::krylov;
    if (req.pc) {
        s.pc = *req.pc;
        c.reason = "Krylov solve with --pc " + s.pc.text() + " as requested";
        const solvers::PreconditionerEntry& entry = *s.pc.entry;
        MLC_CHECK(has_levels || !entry.needs_level_below || entry.single_level_too,
                  "--pc " << s.pc << " needs the level below: use --levels >= 1");
        return;
    }
    // mg over the levels, or over an aggregation hierarchy on a single level (there it is
    // faster than ILU(0), which falls back to schur from the square's level-3 export on).
    const bool two_body = has_two_body_pair(problem);
    s.pc = default_mg(two_body);
    if (!req.krylov) s.krylov = kMgDefaultKrylov;
    const std::string asked = req.linear   ? std::string("--linear krylov")
                              : req.krylov ? "--krylov " + std::string(to_string(*req.krylov))
                                           : std::string("--linear-tol");
    c.reason = asked + " without --pc: multilevel mg " +
               (has_levels ? "over the levels" : "over an aggregation hierarchy (one level)") +
               " (V(0,2) cycle)" + (two_body ? ", damped (omega = 0.8) with a two-body pair" : "");
}

// BiCGStab (unless the request names a Krylov method) + the default mg, as above the crossover.
void plan_mg_default(const Problem& problem, const SolverRequest& req, SolverPlan& c) {
    LinearSolverSpec& s = c.spec;
    s.method = solvers::Method::krylov;
    const bool two_body = has_two_body_pair(problem);
    if (!req.krylov) s.krylov = kMgDefaultKrylov;
    // Levels 4 and finer swept by lattices, numbered for it (not when the request keeps the
    // Hilbert numbering).
    const bool lattice =
        problem.levels >= kMgDefaultLatticeLevel &&
        req.numbering.value_or(Problem::Numbering::lattice) == Problem::Numbering::lattice;
    s.pc = default_mg(two_body, lattice);
    std::ostringstream os;
    os << "BiCGStab + " << s.pc << " (faster and smaller than schur there"
       << (two_body ? "; with a two-body pair damped sweeps need fewer V-cycles" : "")
       << (lattice ? "; levels 4 and finer numbered and swept macro triangle by macro "
                     "triangle, --numbering hilbert for the block sweep)"
                   : ")");
    c.reason = os.str();
}

// Nothing asked for: schur up to the crossover, BiCGStab + the default mg above it.
void plan_by_size(const Problem& problem, const SolverRequest& req,
                  const std::vector<LevelSize>* known_sizes, SolverPlan& c) {
    LinearSolverSpec& s = c.spec;
    c.automatic = true;
    const bool has_levels = problem.levels >= 1;
    const double n =
        known_sizes ? known_sizes->back().unknowns : predict_level_sizes(problem).back().unknowns;
    const double crossover = mg_crossover_unknowns(problem);
    std::ostringstream os;
    os << std::setprecision(3);
    if (has_levels && n > crossover) {
        plan_mg_default(problem, req, c);
        os << "default: " << n << " unknowns on the finest level exceed the crossover " << crossover
           << ": " << c.reason;
    } else {
        s.method = solvers::Method::schur;
        if (!has_levels && n > crossover)
            os << "default: " << n << " unknowns on a single level: exact schur (faster "
               << "there than mg over an aggregation hierarchy, which --linear krylov builds)";
        else
            os << "default: " << n << " unknowns on the finest level, at most the crossover "
               << crossover << ": exact schur (faster there)";
    }
    c.reason = os.str();
}

} // namespace

SolverPlan plan_solver(const Problem& problem, const SolverRequest& req, int processes,
                       const std::vector<LevelSize>* known_sizes) {
    MLC_CHECK(processes >= 1, "plan_solver: " << processes << " processes");
    refuse_krylov_option_with_direct(req);
    if (processes > 1) return plan_distributed(problem, req, processes);
    SolverPlan c;
    LinearSolverSpec& s = c.spec;
    if (req.krylov) s.krylov = *req.krylov;
    if (req.rel_tol) s.rel_tol = *req.rel_tol;
    if (req.linear && *req.linear != solvers::Method::krylov) {
        s.method = *req.linear;
        c.reason = "--linear " + std::string(to_string(s.method)) + " as requested";
    } else if (req.linear || req.pc || req.krylov || req.rel_tol) {
        plan_krylov(problem, req, c);
    } else {
        plan_by_size(problem, req, known_sizes, c);
    }
    s.numbering = req.numbering;
    s.numbering = hierarchy_numbering(problem, s);
    s.validate();
    return c;
}

SolverPlan plan_default_mg(const Problem& problem, const SolverRequest& req, int processes) {
    MLC_CHECK(!req.linear && !req.pc,
              "plan_default_mg: the request names a method or a preconditioner");
    if (processes > 1) return plan_solver(problem, req, processes);
    SolverPlan c;
    LinearSolverSpec& s = c.spec;
    if (req.krylov) s.krylov = *req.krylov;
    if (req.rel_tol) s.rel_tol = *req.rel_tol;
    plan_mg_default(problem, req, c);
    c.reason = "the default above the crossover: " + c.reason;
    s.numbering = req.numbering;
    s.numbering = hierarchy_numbering(problem, s);
    s.validate();
    return c;
}

// ------------------------------------------------------------------------------------------
namespace {

// Fitted on measured peaks: bytes per nonzero of K and per unknown over all
// levels, for the hierarchy and for each solver, plus the process baseline.
constexpr double kBaseline = 12.0 * (1 << 20);
constexpr double kHierarchyPerNonzero = 26.0;
constexpr double kHierarchyPerUnknown = 104.0;
constexpr double kKrylovPerNonzero = 24.4;
constexpr double kKrylovPerUnknown = 130.0;
constexpr double kLuPerNonzero = 120.0;
constexpr double kCholeskyPerNonzero = 20.0;
// mg on a single level adds its aggregation hierarchy: the smoothed prolongations, the Galerkin
// coarse operators and the products that form them.
constexpr double kAggregationPerNonzero = 80.0;

} // namespace

MemoryEstimate estimate_memory(const std::vector<LevelSize>& sizes, const LinearSolverSpec& spec,
                               bool coarse_to_fine, const StepsKept& steps) {
    MLC_CHECK(!sizes.empty(), "estimate_memory: no levels");
    MemoryEstimate e;
    const int finest = static_cast<int>(sizes.size()) - 1;
    double worst = 0;
    for (const LevelSize& s : sizes) {
        e.hierarchy_bytes +=
            kHierarchyPerNonzero * s.k_nonzeros + kHierarchyPerUnknown * s.unknowns;
        // The finest level's solver, and every level's in coarse-to-fine (level 0 by schur).
        const bool solved =
            coarse_to_fine || s.level == finest || spec.method == solvers::Method::krylov;
        if (!solved) continue;
        double b = 0;
        const solvers::Method method =
            s.level == 0 && finest > 0 ? solvers::Method::schur : spec.method;
        const double m = s.multipliers;
        if (method == solvers::Method::krylov)
            b = kKrylovPerNonzero * s.k_nonzeros + kKrylovPerUnknown * s.unknowns;
        else if (method == solvers::Method::lu)
            b = kLuPerNonzero * s.k_nonzeros * std::max(1.0, std::log2(s.unknowns) / 4);
        else // schur: Cholesky of K0, S (m x m) and the dense m x m LU of every Newton step
            b = kCholeskyPerNonzero * s.k_nonzeros * std::max(1.0, std::log2(s.unknowns) / 4) +
                3 * 8.0 * m * m;
        // A single level's mg builds its aggregation hierarchy.
        if (method == solvers::Method::krylov && finest == 0 && spec.pc.entry != nullptr &&
            spec.pc.entry->single_level_too)
            b += kAggregationPerNonzero * s.k_nonzeros;
        e.solver_bytes += b;
        if (b >= worst) {
            worst = b;
            e.largest_level = s.level;
        }
    }
    // Per load step: every solved level's reports, the finest level's contact states.
    const LevelSize& f = sizes.back();
    const double solved_levels = coarse_to_fine ? static_cast<double>(sizes.size()) : 1.0;
    const double n_steps = std::max(1, steps.load_steps);
    e.steps_bytes =
        n_steps * (kStepBytesPerLevel * solved_levels + kStepBytesPerContactNode * f.contact_nodes +
                   (steps.keep_step_states ? kStepBytesPerKeptVertex * f.vertices : 0));
    e.output_bytes = n_steps * (kOutputBytesPerLevel * solved_levels +
                                kOutputBytesPerContactNode * f.contact_nodes);
    e.bytes = kBaseline + e.hierarchy_bytes + e.solver_bytes + e.steps_bytes;
    return e;
}

namespace {

double read_meminfo_available() {
    std::ifstream in("/proc/meminfo");
    std::string key;
    double kib = 0;
    std::string unit;
    while (in >> key >> kib) {
        std::getline(in, unit);
        if (key == "MemAvailable:") return kib * 1024.0;
    }
    return std::numeric_limits<double>::infinity();
}

// A number from a one-line file; "max" or a missing file give infinity.
double read_number_file(const std::string& path) {
    std::ifstream in(path);
    std::string v;
    if (!(in >> v) || v == "max") return std::numeric_limits<double>::infinity();
    try {
        return std::stod(v);
    } catch (...) {
        return std::numeric_limits<double>::infinity();
    }
}

// The cgroup of this process: the v2 path, or v1's memory controller path.
double cgroup_room() {
    std::ifstream in("/proc/self/cgroup");
    std::string line;
    double room = std::numeric_limits<double>::infinity();
    while (std::getline(in, line)) {
        // "0::/path" (v2) or "N:memory:/path" (v1)
        const auto a = line.find(':'), b = line.find(':', a + 1);
        if (a == std::string::npos || b == std::string::npos) continue;
        const std::string ctl = line.substr(a + 1, b - a - 1), path = line.substr(b + 1);
        if (ctl.empty()) {
            for (std::string p = path;; p = p.substr(0, p.rfind('/'))) {
                const std::string dir = "/sys/fs/cgroup" + (p == "/" ? std::string() : p);
                const double max = read_number_file(dir + "/memory.max");
                if (std::isfinite(max))
                    room = std::min(room, max - read_number_file(dir + "/memory.current"));
                if (p.empty() || p == "/") break;
            }
        } else if (ctl.find("memory") != std::string::npos) {
            const std::string dir = "/sys/fs/cgroup/memory" + (path == "/" ? std::string() : path);
            const double max = read_number_file(dir + "/memory.limit_in_bytes");
            if (std::isfinite(max) && max < 1e18)
                room = std::min(room, max - read_number_file(dir + "/memory.usage_in_bytes"));
        }
    }
    return room;
}

double address_space_room() {
    rlimit rl{};
    if (getrlimit(RLIMIT_AS, &rl) != 0 || rl.rlim_cur == RLIM_INFINITY)
        return std::numeric_limits<double>::infinity();
    // Address space already mapped: VmSize in /proc/self/status.
    std::ifstream in("/proc/self/status");
    std::string key;
    double used = 0;
    for (std::string line; std::getline(in, line);)
        if (line.rfind("VmSize:", 0) == 0) used = std::stod(line.substr(7)) * 1024.0;
    return static_cast<double>(rl.rlim_cur) - used;
}

} // namespace

MemoryLimit process_memory_limit() {
    MemoryLimit m{read_meminfo_available(), "MemAvailable (/proc/meminfo)"};
    if (const double c = cgroup_room(); c < m.bytes) m = {c, "the cgroup memory limit"};
    if (const double a = address_space_room(); a < m.bytes) m = {a, "RLIMIT_AS (ulimit -v)"};
    return m;
}

std::string format_bytes(double bytes) {
    std::ostringstream os;
    os << std::fixed;
    if (!std::isfinite(bytes))
        os << "unlimited";
    else if (bytes >= 1024.0 * 1024 * 1024)
        os << std::setprecision(1) << bytes / (1024.0 * 1024 * 1024) << " GiB";
    else
        os << std::setprecision(0) << bytes / (1024.0 * 1024) << " MiB";
    return os.str();
}

void check_memory_fits(const MemoryEstimate& estimate, const MemoryLimit& limit,
                       const std::vector<LevelSize>& sizes) {
    if (estimate.bytes <= limit.bytes) return;
    const LevelSize& f = sizes.back();
    std::ostringstream os;
    const bool steps = estimate.steps_bytes > estimate.hierarchy_bytes + estimate.solver_bytes;
    os << std::setprecision(3) << "the run needs an estimated " << format_bytes(estimate.bytes)
       << " (finest level " << f.level << ": " << f.unknowns << " unknowns, " << f.contact_nodes
       << " contact nodes; largest solver on level " << estimate.largest_level;
    if (steps)
        os << "; " << format_bytes(estimate.steps_bytes)
           << " of it for what every load step keeps until the files are written, which take "
           << format_bytes(estimate.output_bytes);
    os << ") but this process may use " << format_bytes(std::max(0.0, limit.bytes)) << " ("
       << limit.source << "): use fewer " << (steps ? "load steps" : "--levels");
    throw InvalidInput(os.str());
}

LevelSize level_size_from_triangles(double triangles) {
    LevelSize s;
    s.triangles = triangles;
    s.vertices = triangles / 2;
    s.edges = 1.5 * triangles;
    s.unknowns = 2 * s.vertices;
    s.k_nonzeros = 4 * (s.vertices + 2 * s.edges);
    return s;
}

double meshing_memory(double triangles) {
    const double solve =
        estimate_memory({level_size_from_triangles(triangles)}, LinearSolverSpec{}, false).bytes;
    return solve + kMeshingBytesPerTriangle * triangles;
}

void check_meshing_fits(double triangles, const std::string& what, const std::string& fix,
                        const MemoryLimit& limit) {
    const double need = meshing_memory(triangles);
    if (need <= limit.bytes) return;
    std::ostringstream os;
    os << what << " needs an estimated " << format_bytes(need)
       << " to mesh and solve as one level, but this process may use "
       << format_bytes(std::max(0.0, limit.bytes)) << " (" << limit.source << "): " << fix;
    throw InvalidInput(os.str());
}

} // namespace mlc::levels
