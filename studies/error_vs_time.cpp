// SPDX-License-Identifier: MIT
// Work-precision study (issue: error against run time).
#include "studies/error_vs_time.hpp"

#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "fem/assembly.hpp"
#include "levels/solve.hpp"
#include "run/closed_form.hpp"
#include "run/plot_script.hpp"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <toml++/toml.h>

namespace mlc::apps {

namespace {

/// One solver configuration of the grid.
struct Config {
    std::string name;
    bool coarse_to_fine = true;
    levels::LinearSolverSpec linear;
    double newton_tol = 1e-10;
    /// What bounds the levels it runs on: none (0..L), ILU(0) (0..min(L, ilu_max_level)) or the
    /// multigrid (1..L: it needs a level below).
    enum class Family { exact, ilu, mg } family = Family::exact;
    /// The run's default above the crossover on every level, planned per level by
    /// levels::plan_default_mg (the lattice sweep from level 4 on, on levels numbered for it).
    bool planned_default = false;
};

std::vector<Config> configurations(const levels::Problem& problem) {
    std::vector<Config> c;
    using F = Config::Family;
    // The multilevel solvers: the run's default above the crossover (BiCGStab + mg's V(0,2)
    // cycle, damped with a two-body pair; from level kMgDefaultLatticeLevel on with the lattice
    // sweep on levels numbered by lattices: `planned_default`), `--pc mg` (CGS + V(1,1), an
    // earlier default) and hypre's MGR with `--pc mgr`, to the run's default linear
    // tolerance.
    const levels::LinearSolverSpec def{.method = solvers::Method::krylov,
                                       .krylov = levels::kMgDefaultKrylov,
                                       .pc = levels::default_mg(levels::has_two_body_pair(problem)),
                                       .rel_tol = 1e-10};
    c.push_back({"c2f default bicgstab+mg", true, def, 1e-10, F::mg, true});
    const levels::LinearSolverSpec mg{.method = solvers::Method::krylov,
                                      .krylov = solvers::Krylov::cgs,
                                      .pc = solvers::parse_pc("mg"),
                                      .rel_tol = 1e-10};
    c.push_back({"c2f cgs+mg", true, mg, 1e-10, F::mg});
    c.push_back({"cold cgs+mg", false, mg, 1e-10, F::mg});
#if defined(MLC_HAVE_HYPRE)
    const levels::LinearSolverSpec mgr{.method = solvers::Method::krylov,
                                       .krylov = solvers::Krylov::cgs,
                                       .pc = solvers::parse_pc("mgr"),
                                       .rel_tol = 1e-10};
    c.push_back({"c2f cgs+mgr", true, mgr, 1e-10, F::exact});
#endif
    c.push_back({"c2f schur", true, {}, 1e-10});
    c.push_back({"cold schur", false, {}, 1e-10});
    c.push_back({"c2f schur newton 1e-6", true, {}, 1e-6});
    c.push_back({"c2f lu", true, {.method = solvers::Method::lu}, 1e-10});
    c.push_back({"cold lu", false, {.method = solvers::Method::lu}, 1e-10});
    c.push_back({"c2f gmres+ilu0 1e-8",
                 true,
                 {.method = solvers::Method::krylov,
                  .krylov = solvers::Krylov::gmres,
                  .pc = solvers::parse_pc("ilu:0"),
                  .rel_tol = 1e-8},
                 1e-8,
                 F::ilu});
    c.push_back({"cold gmres+ilu0 1e-8",
                 false,
                 {.method = solvers::Method::krylov,
                  .krylov = solvers::Krylov::gmres,
                  .pc = solvers::parse_pc("ilu:0"),
                  .rel_tol = 1e-8},
                 1e-8,
                 F::ilu});
    c.push_back({"c2f cgs+ilu0 1e-6",
                 true,
                 {.method = solvers::Method::krylov,
                  .krylov = solvers::Krylov::cgs,
                  .pc = solvers::parse_pc("ilu:0"),
                  .rel_tol = 1e-6},
                 1e-6,
                 F::ilu});
    return c;
}

/// The linear solver a configuration runs on level `level`.
levels::LinearSolverSpec linear_for(const Config& c, const levels::Problem& problem, int level) {
    if (!c.planned_default) return c.linear;
    levels::Problem p = problem;
    p.levels = level;
    return levels::plan_default_mg(p, {.rel_tol = c.linear.rel_tol}).spec;
}

/// Prolongates a full nodal vector from level l to level L of a hierarchy (P_nodal chain).
Vector prolongate_nodal(const levels::Hierarchy& h, int l, int L, const Vector& u) {
    Vector v = u, w;
    for (int k = l; k < L; ++k) {
        h.transfers[static_cast<size_t>(k)].interpolate_nodal(v, w);
        v.swap(w);
    }
    return v;
}

/// Nodal traction (2 components per vertex, local frame, force per length) of a contact state:
/// lambda over the tributary length (half the adjacent contact edges); zero off the contact.
Vector nodal_traction(const levels::Level& L, const std::vector<levels::ContactNodeState>& nodes,
                      Vector& tributary) {
    const int nv = L.mesh.n_vertices();
    tributary = Vector::Zero(nv);
    for (const auto& e : L.mesh.boundary) {
        const int a = L.contact_of_vertex[static_cast<size_t>(e.v0)];
        const int b = L.contact_of_vertex[static_cast<size_t>(e.v1)];
        if (a < 0 && b < 0) continue;
        const double len = (L.mesh.vertices[static_cast<size_t>(e.v1)] -
                            L.mesh.vertices[static_cast<size_t>(e.v0)])
                               .norm();
        if (a >= 0) tributary[e.v0] += 0.5 * len;
        if (b >= 0) tributary[e.v1] += 0.5 * len;
    }
    Vector t = Vector::Zero(2 * nv);
    for (size_t e = 0; e < nodes.size(); ++e) {
        const int v = nodes[e].vertex;
        if (tributary[v] > 0) {
            t[2 * v] = nodes[e].lambda_t / tributary[v];
            t[2 * v + 1] = nodes[e].lambda_n / tributary[v];
        }
    }
    return t;
}

struct Errors {
    double energy = 0.0;       ///< relative energy-norm displacement error
    double traction = 0.0;     ///< relative L2 traction error along the contact boundary
    double closed_form = -1.0; ///< relative L2 pressure error against the closed form (hertz)
};

Errors errors_against(const levels::RunResult& ref, int l, const levels::RunResult& run,
                      const levels::Problem& p) {
    Errors e;
    const auto& H = ref.hierarchy;
    const int Lr = H.n_levels() - 1;
    const auto& R = H.finest();
    const Vector d = ref.u_full - prolongate_nodal(H, l, Lr, run.u_full);
    const Vector Kd = fem::internal_forces(R.mesh, R.materials, d);
    const Vector Ku = fem::internal_forces(R.mesh, R.materials, ref.u_full);
    e.energy = std::sqrt(std::max(d.dot(Kd), 0.0) / ref.u_full.dot(Ku));
    Vector trib_ref, trib_l;
    const Vector t_ref = nodal_traction(R, ref.nodes, trib_ref);
    const Vector t_l = nodal_traction(run.levels()[static_cast<size_t>(l)], run.nodes, trib_l);
    // Tractions as vertex fields, prolongated linearly along edges (components separately).
    const Vector t_lf = prolongate_nodal(H, l, Lr, t_l);
    double num = 0, den = 0;
    for (const auto& n : ref.nodes) {
        const int v = n.vertex;
        num += trib_ref[v] * (t_ref.segment<2>(2 * v) - t_lf.segment<2>(2 * v)).squaredNorm();
        den += trib_ref[v] * t_ref.segment<2>(2 * v).squaredNorm();
    }
    e.traction = den > 0 ? std::sqrt(num / den) : 0.0;
    if (p.name == "hertz") {
        // Closed form of benchmarks.md: P = 8.6307e-3 (full half-disc), R = 1.
        const auto& mat = p.bodies.front().material;
        const Hertz hz{.P = 8.6307e-3, .R = 1.0, .E_star = mat.effective_modulus()};
        const auto& Ll = run.levels()[static_cast<size_t>(l)];
        double pn = 0, pd = 0;
        for (const auto& n : run.nodes) {
            const double tr = trib_l[n.vertex];
            const double ph = tr > 0 ? -n.lambda_n / tr : 0.0;
            const double pe = hz.pressure(n.x.x());
            pn += tr * (ph - pe) * (ph - pe);
            pd += tr * pe * pe;
        }
        (void)Ll;
        e.closed_form = pd > 0 ? std::sqrt(pn / pd) : -1.0;
    }
    return e;
}

} // namespace

std::string error_vs_time_pc(const levels::Problem& problem, const std::string& configuration,
                             int level) {
    for (const auto& c : configurations(problem))
        if (c.name == configuration) return linear_for(c, problem, level).pc.text();
    throw InvalidInput("study error-vs-time has no configuration named '" + configuration + "'");
}

int study_error_vs_time(const levels::Problem& problem_in, const ErrorVsTimeOptions& opt,
                        std::ostream& os) {
    MLC_CHECK(opt.max_level >= 0 && opt.max_level <= 6, "--levels must lie in [0, 6]");
    MLC_CHECK(opt.ilu_max_level >= 0, "--ilu-levels must be >= 0");
    MLC_CHECK(opt.reference_offset >= 1 && opt.reference_offset <= 2,
              "reference offset must be 1 or 2");
    levels::Problem problem = problem_in;
    const auto dir = opt.out.empty()
                         ? std::filesystem::path("out/studies") / (problem.name + "_error_vs_time")
                         : opt.out;
    std::filesystem::create_directories(dir);
    const int Lref = opt.max_level + opt.reference_offset;
    os << "work-precision study: scene '" << problem.name << "', levels 0.." << opt.max_level
       << ", reference on level " << Lref << " (coarse-to-fine, exact)\n"
       << std::flush;
    problem.levels = Lref;
    const levels::RunResult ref = levels::solve(problem);
    if (!ref.converged) {
        os << "error: the reference solve failed: " << ref.failure << "\n";
        return 2;
    }
    struct Row {
        std::string config;
        int level;
        Index unknowns;
        double seconds;
        bool converged;
        Errors err;
        int newton, krylov;
        bool pareto = false;
    };
    std::vector<Row> rows;
    os << "\n"
       << std::left << std::setw(26) << "configuration" << std::right << std::setw(6) << "level"
       << std::setw(10) << "unknowns" << std::setw(10) << "seconds" << std::setw(13) << "energy err"
       << std::setw(14) << "traction err";
    if (problem.name == "hertz") os << std::setw(14) << "closed form";
    os << std::setw(8) << "newton" << std::setw(9) << "krylov"
       << "\n";
    for (const auto& c : configurations(problem)) {
        if (!opt.only.empty() && c.name.find(opt.only) == std::string::npos) continue;
        // mg needs a level below; the lattice sweep (smoother=lattice) levels 4 and finer.
        const int lo = c.linear.pc.lattice_numbering()  ? levels::kMgDefaultLatticeLevel
                       : c.family == Config::Family::mg ? 1
                                                        : 0;
        const int hi = c.family == Config::Family::ilu ? std::min(opt.max_level, opt.ilu_max_level)
                                                       : opt.max_level;
        for (int l = lo; l <= hi; ++l) {
            levels::Problem p = problem;
            p.levels = l;
            p.newton.rel_tol = c.newton_tol;
            levels::SolveOptions so;
            so.coarse_to_fine = c.coarse_to_fine;
            so.linear = linear_for(c, p, l);
            const double t0 = wall_seconds();
            levels::RunResult r;
            try {
                r = levels::solve(p, so);
            } catch (const std::exception& e) {
                // A configuration that cannot run here (memory, a singular system) is a row
                // that did not converge, not the end of the study.
                r.converged = false;
                r.failure = e.what();
            }
            const Index unknowns =
                r.levels().empty() ? 0 : static_cast<Index>(r.finest().n_unknowns());
            Row row{c.name, l, unknowns, wall_seconds() - t0, r.converged, {}, 0, 0};
            for (const auto& ls : r.level_steps)
                for (const auto& st : ls) {
                    row.newton += st.report.iterations;
                    row.krylov += st.report.linear_iterations;
                }
            if (r.converged) row.err = errors_against(ref, l, r, problem);
            os << std::left << std::setw(26) << c.name << std::right << std::setw(6) << l
               << std::setw(10) << row.unknowns << std::setw(10) << std::setprecision(3)
               << row.seconds;
            if (r.converged) {
                os << std::setw(13) << row.err.energy << std::setw(14) << row.err.traction;
                if (row.err.closed_form >= 0) os << std::setw(14) << row.err.closed_form;
            } else {
                os << "  no conv: " << r.failure.substr(0, 80);
            }
            os << std::setw(8) << row.newton << std::setw(9) << row.krylov << "\n" << std::flush;
            rows.push_back(row);
        }
    }
    // Pareto front on (seconds, primary error): a run is on the front unless another is at least
    // as fast and at least as accurate. Errors within 1% of each other count as equal: runs
    // that solve the same level to tolerance differ only in the digits the solver tolerance
    // leaves, which is no accuracy a user can buy.
    auto primary = [&](const Row& r) {
        return r.err.closed_form >= 0 ? r.err.closed_form : r.err.energy;
    };
    auto no_worse = [&](const Row& b, const Row& a) { return primary(b) <= 1.01 * primary(a); };
    for (auto& a : rows) {
        if (!a.converged) continue;
        a.pareto = true;
        for (const auto& b : rows)
            if (&a != &b && b.converged && b.seconds <= a.seconds && no_worse(b, a) &&
                (b.seconds < a.seconds || primary(b) < primary(a))) {
                a.pareto = false;
                break;
            }
    }
    AtomicOfstream csv(dir / "error_vs_time.csv");
    csv << "configuration,level,unknowns,seconds,converged,energy_error,traction_error,closed_form_"
           "error,"
           "primary_error,newton,krylov,pareto\n"
        << std::setprecision(6);
    toml::array jr;
    os << "\nPareto front (seconds, "
       << (problem.name == "hertz" ? "pressure error vs closed form" : "energy error") << "):\n";
    for (const auto& r : rows) {
        csv << '"' << r.config << "\"," << r.level << "," << r.unknowns << "," << r.seconds << ","
            << r.converged << "," << r.err.energy << "," << r.err.traction << ","
            << r.err.closed_form << "," << primary(r) << "," << r.newton << "," << r.krylov << ","
            << r.pareto << "\n";
        toml::table t;
        t.insert("configuration", r.config);
        t.insert("level", static_cast<int64_t>(r.level));
        t.insert("unknowns", static_cast<int64_t>(r.unknowns));
        t.insert("seconds", r.seconds);
        t.insert("converged", r.converged);
        t.insert("energy_error", r.err.energy);
        t.insert("traction_error", r.err.traction);
        if (r.err.closed_form >= 0) t.insert("closed_form_error", r.err.closed_form);
        t.insert("pareto", r.pareto);
        jr.push_back(t);
        if (r.pareto)
            os << "  " << std::left << std::setw(26) << r.config << std::right << " level "
               << r.level << "  " << std::setprecision(3) << r.seconds << " s  error " << primary(r)
               << "\n";
    }
    toml::table root;
    root.insert("scene", problem.name);
    root.insert("reference_level", static_cast<int64_t>(Lref));
    root.insert("runs", jr);
    AtomicOfstream js(dir / "error_vs_time.json");
    js << toml::json_formatter{root} << "\n";
    csv.close();
    js.close();
    os << "wrote " << (dir / "error_vs_time.csv").string() << ", error_vs_time.json\n";
    if (opt.plot && run_plot_script("plot_error_vs_time.py", dir, os))
        os << "wrote " << (dir / "error_vs_time.png").string() << "\n";
    return 0;
}

} // namespace mlc::apps
