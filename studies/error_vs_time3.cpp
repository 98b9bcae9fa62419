// SPDX-License-Identifier: MIT
// Work-precision study of a 3D scene: error against run time over levels and solvers.
#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "levels/resources.hpp"
#include "levels/solve3.hpp"
#include "run/plot_script.hpp"
#include "studies/error_vs_time.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <optional>

namespace mlc::apps {

namespace {

using levels::Method3;

/// One solver configuration of the 3D grid.
struct Config3 {
    std::string name;
    bool coarse_to_fine = true;
    /// Exact on every level; none: the run's plan (schur or lu on level 0, GMRES + mg above),
    /// which needs a level below and so starts at level 1.
    std::optional<Method3> forced;
};

/// The reference: coarse-to-fine, sparse LU on every level (exact, and no dense Schur systems)
/// where it fits in memory; else the multigrid with the Newton and GMRES tolerances at 1e-12
/// (kReferenceMg3), whose memory grows as the unknowns (the LU's fill grows as their square).
const char* const kReference3 = "c2f lu";
const char* const kReferenceMg3 = "c2f gmres+mg, tolerances 1e-12";


std::vector<Config3> configurations3() {
    return {{"c2f gmres+mg", true, std::nullopt}, {"cold gmres+mg", false, std::nullopt},
            {"c2f schur", true, Method3::schur},  {"cold schur", false, Method3::schur},
            {kReference3, true, Method3::lu},     {"cold lu", false, Method3::lu}};
}

/// Solves `problem` on levels 0..level with a configuration (its plan checked against the
/// process's memory first: a refusal is thrown as InvalidInput), GMRES to krylov_rel_tol.
levels::RunResult3 solve_config3(levels::ElasticProblem3 problem, const Config3& c, int level,
                                 double krylov_rel_tol = levels::SolveOptions3{}.krylov_rel_tol) {
    problem.levels = level;
    const levels::Plan3 plan = levels::plan_contact3(levels::predict_elastic3_sizes(problem, level),
                                                     c.forced, levels::process_memory_limit());
    levels::SolveOptions3 so;
    so.coarse_to_fine = c.coarse_to_fine;
    so.level0 = plan.level0;
    so.upper = plan.upper;
    so.krylov_rel_tol = krylov_rel_tol;
    return levels::solve(problem, so);
}

/// Interleaved nodal values (3 per vertex) of level l carried to level `to` of `H`, by
/// P_vertex per component (linear interpolation through each 1 -> 8 refinement).
Vector prolongate_nodal3(const levels::Hierarchy3& H, int l, int to, const Vector& u) {
    Vector v = u;
    for (int k = l; k < to; ++k) {
        const SparseMatrix& P = H.transfers[static_cast<size_t>(k)].P_vertex;
        Vector w = Vector::Zero(3 * P.rows());
        for (int c = 0; c < 3; ++c) {
            const Vector vc =
                Eigen::Map<const Vector, 0, Eigen::InnerStride<3>>(v.data() + c, P.cols());
            const Vector wc = P * vc;
            for (Index i = 0; i < P.rows(); ++i)
                w[3 * i + c] = wc[i];
        }
        v.swap(w);
    }
    return v;
}

/// Contact tractions of a level as a nodal field (3 global components per vertex, zero off the
/// contact nodes): each node's multiplier in global components over its lumped area.
Vector nodal_traction3(const levels::ElasticProblem3& p, const levels::Level3& L,
                       const std::vector<levels::ContactNodeState3>& nodes,
                       std::vector<double>& areas) {
    areas = levels::contact_areas(p, L);
    Vector t = Vector::Zero(3 * L.mesh.n_vertices());
    for (size_t e = 0; e < nodes.size(); ++e) {
        const auto& n = nodes[e];
        if (areas[e] <= 0) continue;
        const mesh::Vec3 lg =
            n.t.col(0) * n.lambda_t[0] + n.t.col(1) * n.lambda_t[1] + n.n * n.lambda_n;
        t.segment<3>(3 * n.vertex) = lg / areas[e];
    }
    return t;
}

struct Errors3 {
    double energy = 0.0;   ///< relative energy-norm displacement error
    double traction = 0.0; ///< relative L2 traction error on the contactor surface
};

/// The errors of a run on level l against the reference on level Lr >= l: both its nodal
/// displacements and its nodal tractions are interpolated to level Lr (P_vertex); the
/// displacement error is measured in the energy norm of level Lr's K on its unknowns, the
/// traction error in the L2 norm along the reference's contact nodes with their lumped areas.
Errors3 errors_against3(const levels::ElasticProblem3& p, const levels::RunResult3& ref, int l,
                        const levels::RunResult3& run) {
    const auto& H = ref.hierarchy;
    const int Lr = H.n_levels() - 1;
    MLC_CHECK(l <= Lr && run.finest().mesh.n_vertices() ==
                             H.levels[static_cast<size_t>(l)].mesh.n_vertices(),
              "error-vs-time (3D): level " << l << " of the run is not level " << l
                                           << " of the reference hierarchy");
    const auto& R = H.finest();
    const Vector d_full = ref.u_full - prolongate_nodal3(H, l, Lr, run.u_full);
    Vector d = Vector::Zero(R.n_unknowns()), u = Vector::Zero(R.n_unknowns());
    for (int v = 0; v < R.mesh.n_vertices(); ++v)
        for (int c = 0; c < 3; ++c)
            if (const int k = R.dofs.u_dof(v, c); k >= 0) {
                d[k] = d_full[3 * v + c];
                u[k] = ref.u_full[3 * v + c];
            }
    const SparseMatrix& K = R.elastic.K;
    Errors3 e;
    const double uKu = u.dot(K * u);
    e.energy = uKu > 0 ? std::sqrt(std::max(d.dot(K * d), 0.0) / uKu) : 0.0;
    std::vector<double> a_ref, a_l;
    const Vector t_ref = nodal_traction3(p, R, ref.nodes, a_ref);
    const Vector t_l =
        prolongate_nodal3(H, l, Lr, nodal_traction3(p, run.finest(), run.nodes, a_l));
    double num = 0.0, den = 0.0;
    for (size_t k = 0; k < ref.nodes.size(); ++k) {
        const int v = ref.nodes[k].vertex;
        num += a_ref[k] * (t_ref.segment<3>(3 * v) - t_l.segment<3>(3 * v)).squaredNorm();
        den += a_ref[k] * t_ref.segment<3>(3 * v).squaredNorm();
    }
    e.traction = den > 0 ? std::sqrt(num / den) : 0.0;
    return e;
}

struct Row3 {
    std::string config;
    int level = 0;
    Index unknowns = 0;
    double seconds = 0.0;
    bool converged = false;
    std::string failure;
    Errors3 err;
    int newton = 0, krylov = 0;
    bool pareto = false;
};

/// Pareto front on (seconds, energy error), errors within 1 % counting as equal (as in 2D).
void mark_pareto3(std::vector<Row3>& rows) {
    for (auto& a : rows) {
        if (!a.converged) continue;
        a.pareto = true;
        for (const auto& b : rows)
            if (&a != &b && b.converged && b.seconds <= a.seconds &&
                b.err.energy <= 1.01 * a.err.energy &&
                (b.seconds < a.seconds || b.err.energy < a.err.energy)) {
                a.pareto = false;
                break;
            }
    }
}

void write_files3(const std::string& scene, int Lref, const std::string& reference,
                  const std::vector<Row3>& rows,
                  const std::filesystem::path& dir) {
    // The 2D study's columns (scripts/plot_error_vs_time.py reads them); no closed form: -1.
    AtomicOfstream csv(dir / "error_vs_time.csv");
    csv << "configuration,level,unknowns,seconds,converged,energy_error,traction_error,"
           "closed_form_error,primary_error,newton,krylov,pareto\n"
        << std::setprecision(6);
    toml::array jr;
    for (const auto& r : rows) {
        csv << '"' << r.config << "\"," << r.level << "," << r.unknowns << "," << r.seconds << ","
            << r.converged << "," << r.err.energy << "," << r.err.traction << ",-1," << r.err.energy
            << "," << r.newton << "," << r.krylov << "," << r.pareto << "\n";
        toml::table t;
        t.insert("configuration", r.config);
        t.insert("level", static_cast<int64_t>(r.level));
        t.insert("unknowns", static_cast<int64_t>(r.unknowns));
        t.insert("seconds", r.seconds);
        t.insert("converged", r.converged);
        if (r.converged) {
            t.insert("energy_error", r.err.energy);
            t.insert("traction_error", r.err.traction);
        } else {
            t.insert("failure", r.failure);
        }
        t.insert("newton", static_cast<int64_t>(r.newton));
        t.insert("krylov", static_cast<int64_t>(r.krylov));
        t.insert("pareto", r.pareto);
        jr.push_back(t);
    }
    toml::table root;
    root.insert("scene", scene);
    root.insert("dimension", 3);
    root.insert("reference_level", static_cast<int64_t>(Lref));
    root.insert("reference_configuration", reference);
    root.insert("runs", jr);
    AtomicOfstream js(dir / "error_vs_time.json");
    js << toml::json_formatter{root} << "\n";
    csv.close();
    js.close();
    MLC_CHECK(csv.good() && js.good(), "cannot write the study's files in " << dir.string());
}

} // namespace

bool lu_reference_fits3(const levels::ElasticProblem3& problem, int level,
                        const levels::MemoryLimit& limit) {
    try {
        (void)levels::plan_contact3(levels::predict_elastic3_sizes(problem, level), Method3::lu,
                                    limit);
        return true;
    } catch (const InvalidInput&) {
        return false;
    }
}

int study_error_vs_time3(const levels::ElasticProblem3& problem, const ErrorVsTimeOptions& opt,
                         std::ostream& os) {
    MLC_CHECK(opt.max_level >= 0 && opt.max_level <= 3,
              "the 3D error-vs-time study needs --levels between 0 and 3, found " << opt.max_level);
    MLC_CHECK(opt.reference_offset >= 0 && opt.reference_offset <= 2,
              "the 3D error-vs-time study's reference offset must be 0, 1 or 2, found "
                  << opt.reference_offset);
    MLC_CHECK(!problem.contacts.empty(),
              "scene '" << problem.name << "' has no contact: the error-vs-time study needs one");
    const auto dir = opt.out.empty()
                         ? std::filesystem::path("out/studies") / (problem.name + "_error_vs_time")
                         : opt.out;
    std::filesystem::create_directories(dir);
    const int Lref = opt.max_level + opt.reference_offset;
    const auto configs = configurations3();
    const bool lu_ref = lu_reference_fits3(problem, Lref, levels::process_memory_limit());
    const std::string reference = lu_ref ? kReference3 : kReferenceMg3;
    os << "work-precision study: scene '" << problem.name << "' (3D), levels 0.." << opt.max_level
       << ", reference on level " << Lref << " (" << reference
       << (lu_ref ? "" : ": the sparse LU does not fit in memory there") << ")\n"
       << std::flush;
    levels::RunResult3 ref;
    if (lu_ref) {
        ref = solve_config3(problem, *std::find_if(configs.begin(), configs.end(),
                                                   [](const Config3& c) {
                                                       return c.name == kReference3;
                                                   }),
                            Lref);
    } else {
        levels::ElasticProblem3 tight = problem;
        tight.newton.rel_tol = std::min(tight.newton.rel_tol, 1e-12);
        ref = solve_config3(tight, {"reference", true, std::nullopt}, Lref, 1e-12);
    }
    if (!ref.converged) {
        os << "error: the reference solve failed: " << ref.failure << "\n";
        return 2;
    }
    std::vector<Row3> rows;
    os << "\n"
       << std::left << std::setw(16) << "configuration" << std::right << std::setw(6) << "level"
       << std::setw(10) << "unknowns" << std::setw(10) << "seconds" << std::setw(13) << "energy err"
       << std::setw(14) << "traction err" << std::setw(8) << "newton" << std::setw(9) << "krylov"
       << "\n";
    for (const auto& c : configs) {
        if (!opt.only.empty() && c.name.find(opt.only) == std::string::npos) continue;
        for (int l = c.forced ? 0 : 1; l <= opt.max_level; ++l) {
            Row3 row;
            row.config = c.name;
            row.level = l;
            const double t0 = wall_seconds();
            levels::RunResult3 r;
            try {
                r = solve_config3(problem, c, l);
            } catch (const std::exception& e) {
                // A configuration that cannot run here (a refused memory estimate, a singular
                // system) is a row that did not converge, not the end of the study.
                r.converged = false;
                r.failure = e.what();
            }
            row.seconds = wall_seconds() - t0;
            row.converged = r.converged;
            row.failure = r.failure;
            row.unknowns = r.hierarchy.levels.empty() ? 0 : r.finest().n_unknowns();
            for (const auto& ls : r.level_steps)
                for (const auto& st : ls) {
                    row.newton += st.report.iterations;
                    row.krylov += st.report.linear_iterations;
                }
            if (r.converged) row.err = errors_against3(problem, ref, l, r);
            os << std::left << std::setw(16) << c.name << std::right << std::setw(6) << l
               << std::setw(10) << row.unknowns << std::setw(10) << std::setprecision(3)
               << row.seconds;
            if (r.converged)
                os << std::setw(13) << row.err.energy << std::setw(14) << row.err.traction;
            else
                os << "  no conv: " << r.failure.substr(0, 80);
            os << std::setw(8) << row.newton << std::setw(9) << row.krylov << "\n" << std::flush;
            rows.push_back(row);
        }
    }
    mark_pareto3(rows);
    os << "\nPareto front (seconds, energy error):\n";
    for (const auto& r : rows)
        if (r.pareto)
            os << "  " << std::left << std::setw(16) << r.config << std::right << " level "
               << r.level << "  " << std::setprecision(3) << r.seconds << " s  error "
               << r.err.energy << "\n";
    write_files3(problem.name, Lref, reference, rows, dir);
    os << "wrote " << (dir / "error_vs_time.csv").string() << ", error_vs_time.json\n";
    if (opt.plot && run_plot_script("plot_error_vs_time.py", dir, os))
        os << "wrote " << (dir / "error_vs_time.png").string() << "\n";
    return 0;
}

} // namespace mlc::apps
