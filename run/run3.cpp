// SPDX-License-Identifier: MIT
// `mlcontact run` on a 3D scene: options, report and files.
#include "run/run3.hpp"
#include "run/run3_detail.hpp"

#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "levels/solve3.hpp"
#include "mesh/io/vtu_tet.hpp"
#include "run/interrupt.hpp"
#include "run/output.hpp"
#include "scene/scene3.hpp"
#include "solvers/krylov.hpp"
#include "solvers/pc_spec.hpp"

#include <toml++/toml.h>

#include <cmath>
#include <iomanip>
#include <sstream>

namespace mlc::apps {

namespace detail3 {

using levels::ContactNodeState3;
using levels::ElasticProblem3;
using mesh::Vec3;

void apply_overrides3(ElasticProblem3& p, const RunOptions& opt) {
    if (opt.levels) {
        MLC_CHECK(*opt.levels >= 0 && *opt.levels <= levels::kMaxLevels3,
                  "--levels must lie in 0.." << levels::kMaxLevels3 << " for a 3D scene, found "
                                             << *opt.levels);
        p.levels = *opt.levels;
    }
    if (opt.load_steps) {
        MLC_CHECK(*opt.load_steps >= 1, "--steps must be >= 1, found " << *opt.load_steps);
        p.load_steps = *opt.load_steps;
    }
    if (opt.mu) {
        MLC_CHECK(std::isfinite(*opt.mu) && *opt.mu >= 0,
                  "--mu must be a finite number >= 0, found " << *opt.mu);
        for (auto& c : p.contacts)
            c.mu = *opt.mu;
    }
    if (opt.linear_rel_tol)
        MLC_CHECK(std::isfinite(*opt.linear_rel_tol) && *opt.linear_rel_tol > 0 &&
                      *opt.linear_rel_tol < 1,
                  "--linear-tol must lie in (0, 1), found " << *opt.linear_rel_tol);
    if (opt.r) {
        MLC_CHECK(std::isfinite(*opt.r) && *opt.r > 0, "--r must be > 0, found " << *opt.r);
        for (auto& c : p.contacts)
            c.r = *opt.r;
    }
    p.validate();
}

std::string csv_name(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s)
        q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
}

void require_finite3(double v, const char* what) {
    if (!std::isfinite(v))
        throw SolverBreakdown(std::string("refusing to write a non-finite value (") + what +
                              "): the solve produced NaN/Inf");
}

Vec3 global_lambda(const ContactNodeState3& n) {
    return n.t.col(0) * n.lambda_t[0] + n.t.col(1) * n.lambda_t[1] + n.n * n.lambda_n;
}

void write_node(std::ostream& f, const std::string& pair, const ContactNodeState3& n, double area) {
    const Vec3 lg = global_lambda(n);
    const Vec3 slip = n.t.col(0) * n.slip_direction[0] + n.t.col(1) * n.slip_direction[1];
    auto per_area = [&](double v) { return area > 0 ? -v / area + 0.0 : 0.0; };
    f << csv_name(pair) << "," << n.vertex << "," << n.x.x() << "," << n.x.y() << "," << n.x.z()
      << "," << n.u.x() << "," << n.u.y() << "," << n.u.z() << ","
      << levels::kStatusNames3[static_cast<size_t>(levels::status_code3(n.status))] << ","
      << levels::status_code3(n.status) << "," << n.d_n << "," << area << "," << n.lambda_n << ","
      << n.lambda_t[0] << "," << n.lambda_t[1] << "," << lg.x() << "," << lg.y() << "," << lg.z()
      << "," << per_area(n.lambda_n) << "," << per_area(lg.x()) << "," << per_area(lg.y()) << ","
      << per_area(lg.z()) << "," << slip.x() << "," << slip.y() << "," << slip.z() << "," << n.n.x()
      << "," << n.n.y() << "," << n.n.z() << "," << n.t(0, 0) << "," << n.t(1, 0) << ","
      << n.t(2, 0) << "," << n.t(0, 1) << "," << n.t(1, 1) << "," << n.t(2, 1) << "\n";
}

const char* const kNodeColumns =
    "pair,vertex,x,y,z,ux,uy,uz,status,status_code,gap,area,lambda_n,lambda_t1,lambda_t2,"
    "lambda_x,lambda_y,lambda_z,pressure,traction_x,traction_y,traction_z,slip_x,slip_y,slip_z,"
    "n_x,n_y,n_z,t1_x,t1_y,t1_z,t2_x,t2_y,t2_z";

std::function<void(int, int, const levels::StepReport&)> progress_lines(std::ostream& os) {
    return [&os](int l, int k, const levels::StepReport& s) {
        os << "level " << l << " step " << k << ": " << s.iterations << " Newton iterations, "
           << (s.converged ? "converged" : "not converged") << " (" << std::fixed
           << std::setprecision(3) << s.seconds << " s)\n";
        os.unsetf(std::ios::floatfield);
        os << std::setprecision(6);
    };
}

void check_nodes(const std::vector<ContactNodeState3>& nodes) {
    for (const auto& n : nodes) {
        require_finite3(n.lambda_n, "lambda_n");
        require_finite3(n.lambda_t.norm(), "lambda_t");
        require_finite3(n.u.norm(), "displacement");
    }
}

void refuse_2d_options(const RunOptions& opt, bool distributed) {
    auto refuse = [](bool given, const std::string& option, const std::string& why) {
        if (given) throw InvalidInput(option + " does not apply to a 3D scene: " + why);
    };
    refuse(opt.no_fallback, "--no-fallback", "there is no Krylov solve to fall back from");
    refuse(opt.numbering.has_value(), "--numbering",
           "3D levels number their vertices along a Hilbert curve only");
    refuse(opt.no_continuation, "--no-continuation", "3D runs have no r continuation to turn off");
    refuse(opt.every_step || opt.every_level, opt.every_step ? "--every-step" : "--every-level",
           "3D runs write the final state's solution.vtu and every step's contact_steps.csv");
    refuse(opt.plot, "--plot", "the contact plot draws 2D contact lines");
    refuse(opt.partition_level.has_value() && !distributed, "--partition-level",
           "it applies to runs on several processes (mpirun -np N, N > 1)");
}

std::optional<levels::LinearSolverSpec> krylov_spec3(const RunOptions& opt, bool distributed) {
    if (!opt.pc && !opt.krylov) return std::nullopt;
    MLC_CHECK(!opt.linear || *opt.linear == "krylov",
              (opt.pc ? "--pc" : "--krylov")
                  << " sets the Krylov solve of the levels above level 0, and --linear "
                  << *opt.linear << " solves every level exactly: give one or the other");
    levels::SolveOptions3 defaults;
    levels::LinearSolverSpec spec = defaults.krylov;
    if (opt.krylov) spec.krylov = solvers::parse_krylov(*opt.krylov);
    if (opt.pc) spec.pc = solvers::parse_pc(*opt.pc);
    if (!opt.pc || spec.pc.name() == "mg") {
        MLC_CHECK(!opt.pc || spec.pc.text() == "mg",
                  "--pc " << *opt.pc
                          << ": the 3D multigrid's cycle is fixed (W(2,2), vertex-block "
                             "Gauss-Seidel); give --pc mg without options");
        MLC_CHECK(spec.krylov == solvers::Krylov::gmres,
                  "--krylov " << *opt.krylov
                              << ": the 3D multigrid runs with GMRES; give --pc with another "
                                 "preconditioner (diag, ilu, sorcf, ...) for another method");
        return std::nullopt;
    }
    if (const std::string why = spec.pc.dimension_reason(3); !why.empty())
        throw InvalidInput("--pc " + *opt.pc + ": " + why);
    if (distributed)
        if (const std::string why = spec.pc.distributed(); !why.empty())
            throw InvalidInput("--pc " + *opt.pc + " on several processes: " + why);
    if (distributed && spec.pc.entry->needs_level_below)
        throw InvalidInput("--pc " + *opt.pc +
                           " needs the whole level below on one process; on several processes "
                           "use mg or a preconditioner of each process's diagonal block (diag, "
                           "ilu, sor, ssor)");
    return spec;
}

std::string upper_solver_text(const levels::SolveOptions3& so) {
    if (so.upper != levels::Method3::krylov) return levels::to_string(so.upper);
    return std::string(solvers::to_string(so.krylov.krylov)) + " + " + so.krylov.pc.text();
}

} // namespace detail3

namespace {

using namespace detail3;
using levels::Level3;
using levels::RunResult3;

const std::string& pair_name(const ElasticProblem3& p, const Level3& L, size_t e) {
    return p.contacts[static_cast<size_t>(L.contacts[e].pair)].name;
}

void write_solution_vtu3(const std::filesystem::path& file, const Level3& L, const Vector& u_full,
                         const std::vector<ContactNodeState3>& nodes,
                         const std::vector<double>& areas, mesh::VtuFormat format) {
    const auto nv = static_cast<size_t>(L.mesh.n_vertices());
    mesh::Field disp{"displacement", 3, std::vector<double>(u_full.data(), u_full.data() + 3 * nv)};
    mesh::Field status{"contact_status", 1, std::vector<double>(nv, -1.0)};
    mesh::Field force{"contact_force", 3, std::vector<double>(3 * nv, 0.0)};
    mesh::Field pressure{"pressure", 1, std::vector<double>(nv, 0.0)};
    for (size_t e = 0; e < nodes.size(); ++e) {
        const auto& n = nodes[e];
        const auto v = static_cast<size_t>(n.vertex);
        status.values[v] = levels::status_code3(n.status);
        const Vec3 lg = global_lambda(n);
        for (int c = 0; c < 3; ++c)
            force.values[3 * v + static_cast<size_t>(c)] = -lg[c] + 0.0;
        pressure.values[v] = areas[e] > 0 ? -n.lambda_n / areas[e] + 0.0 : 0.0;
    }
    (void)format; // the tetrahedral writer writes binary (appended, zlib) only
    mesh::write_vtu(file, L.mesh, {disp, status, force, pressure}, {});
}

/// The force the obstacle of each pair exerts on its contactor (global components) and the
/// number of its nodes in contact.
std::vector<std::pair<Vec3, int>> resultants(const ElasticProblem3& p, const Level3& L,
                                             const std::vector<ContactNodeState3>& nodes) {
    std::vector<std::pair<Vec3, int>> out(p.contacts.size(), {Vec3::Zero(), 0});
    for (size_t e = 0; e < nodes.size(); ++e) {
        auto& r = out[static_cast<size_t>(L.contacts[e].pair)];
        r.first -= global_lambda(nodes[e]);
        if (nodes[e].status != contact::Status::gap) ++r.second;
    }
    return out;
}

void print_header3(std::ostream& os, const ElasticProblem3& p, const RunResult3& r,
                   const levels::SolveOptions3& so, const levels::Plan3& plan) {
    os << "scene      " << p.name << ": " << p.description << "\n";
    if (!p.units.empty()) os << "units      " << p.units << "\n";
    r.hierarchy.report(os);
    const auto& L = r.finest();
    for (size_t k = 0; k < p.contacts.size(); ++k) {
        const auto& c = p.contacts[k];
        os << "contact    " << c.name << ": nodes on '" << c.contactor << "' against ";
        if (!c.two_body())
            os << c.obstacle;
        else
            os << two_body_target_text(c);
        os << ", mu = " << c.mu << ", r = " << c.r << "\n";
        if (k < L.not_found.size() && !L.not_found[k].empty())
            os << "           " << L.not_found[k].size() << " contactor vertices of '"
               << c.contactor << "' found no target on the finest level and are left out\n";
    }
    os << loading_text(p);
    os << "; Newton rel_tol = " << p.newton.rel_tol << ", max_iter = " << p.newton.max_iter << "\n";
    os << "solve      " << (so.coarse_to_fine ? "coarse-to-fine" : "cold (finest level alone)")
       << "; Newton systems: level 0 " << levels::to_string(so.level0) << ", levels above "
       << upper_solver_text(so) << "\n";
    os << "plan       " << plan.why << "\n";
}

void print_steps3(std::ostream& os, const RunResult3& r) {
    os << "\n step   load  newton  residual    gap  stick   slip   time[s]\n";
    for (const auto& s : r.steps) {
        int gap = 0, stick = 0, slip = 0;
        gap = s.counts.gap;
        stick = s.counts.stick;
        slip = s.counts.slip + s.counts.slip_forward + s.counts.slip_backward;
        os << std::setw(5) << s.step << std::setw(7) << std::fixed << std::setprecision(3)
           << s.load_factor << std::setw(8) << s.iterations << std::setw(10) << std::scientific
           << std::setprecision(2) << (s.residuals.empty() ? 0.0 : s.residuals.back())
           << std::setw(7) << gap << std::setw(7) << stick << std::setw(7) << slip << std::setw(10)
           << std::fixed << std::setprecision(3) << s.seconds << "\n";
        os.unsetf(std::ios::floatfield);
        os << std::setprecision(6);
    }
}

void write_iterations3(const std::filesystem::path& file, const RunResult3& r) {
    write_file_atomically(file, [&](std::ostream& f) {
        f << "level,unknowns,distributed,step,newton,krylov\n";
        for (size_t l = 0; l < r.level_steps.size(); ++l)
            for (const auto& st : r.level_steps[l])
                for (size_t i = 0; i < st.report.linear_iterations_per_newton.size(); ++i)
                    f << l << "," << r.hierarchy.levels[l].n_unknowns() << ",0," << st.report.step
                      << "," << i + 1 << "," << st.report.linear_iterations_per_newton[i] << "\n";
    });
}

void write_summary3(const std::filesystem::path& dir, const ElasticProblem3& p, const RunResult3& r,
                    const std::vector<std::string>& files, const levels::SolveOptions3& so,
                    const levels::Plan3& plan) {
    toml::table root;
    root.insert("complete", true);
    root.insert("scene", p.name);
    root.insert("dimension", 3);
    root.insert("converged", r.converged);
    if (!r.converged) root.insert("failure", r.failure);
    root.insert("levels", static_cast<int64_t>(p.levels));
    root.insert("load_steps", static_cast<int64_t>(p.load_steps));
    root.insert("completed_steps", static_cast<int64_t>(r.completed_steps));
    root.insert("coarse_to_fine", so.coarse_to_fine);
    root.insert("solver_level0", std::string(levels::to_string(so.level0)));
    root.insert("solver_upper", upper_solver_text(so));
    root.insert("plan", plan.why);
    root.insert("unknowns", static_cast<int64_t>(r.finest().n_unknowns()));
    root.insert("contact_nodes", static_cast<int64_t>(r.finest().n_contact_nodes()));
    toml::array steps;
    int total = 0;
    for (const auto& s : r.steps) {
        toml::table t;
        t.insert("step", static_cast<int64_t>(s.step));
        t.insert("load_factor", s.load_factor);
        t.insert("converged", s.converged);
        t.insert("newton_iterations", static_cast<int64_t>(s.iterations));
        t.insert("gap", static_cast<int64_t>(s.counts.gap));
        t.insert("stick", static_cast<int64_t>(s.counts.stick));
        t.insert("slip", static_cast<int64_t>(s.counts.slip));
        t.insert("seconds", s.seconds);
        total += s.iterations;
        steps.push_back(std::move(t));
    }
    root.insert("steps", std::move(steps));
    root.insert("newton_iterations", static_cast<int64_t>(total));
    toml::array lv;
    for (size_t l = 0; l < r.level_steps.size(); ++l) {
        if (r.level_steps[l].empty()) continue;
        toml::table t;
        t.insert("level", static_cast<int64_t>(l));
        t.insert("unknowns", static_cast<int64_t>(r.hierarchy.levels[l].n_unknowns()));
        toml::array its, agree;
        for (const auto& st : r.level_steps[l]) {
            its.push_back(static_cast<int64_t>(st.report.iterations));
            agree.push_back(st.agreement());
        }
        t.insert("newton_iterations", std::move(its));
        t.insert("predicted_status_agreement", std::move(agree));
        lv.push_back(std::move(t));
    }
    root.insert("level_steps", std::move(lv));
    toml::array contacts;
    const auto res = resultants(p, r.finest(), r.nodes);
    for (size_t c = 0; c < p.contacts.size(); ++c) {
        toml::table t;
        t.insert("name", p.contacts[c].name);
        t.insert("resultant", toml::array{res[c].first.x(), res[c].first.y(), res[c].first.z()});
        t.insert("in_contact", static_cast<int64_t>(res[c].second));
        contacts.push_back(std::move(t));
    }
    root.insert("contacts", std::move(contacts));
    toml::array fl;
    for (const auto& f : files)
        fl.push_back(f);
    fl.push_back("summary.json");
    root.insert("files", std::move(fl));
    root.insert("stopped", false);
    write_file_atomically(dir / "summary.json",
                          [&](std::ostream& f) { f << toml::json_formatter{root} << "\n"; });
}

} // namespace

int run_scene3(const RunOptions& opt, std::ostream& os) {
    refuse_2d_options(opt, false);
    ElasticProblem3 p = scene::load_scene3(opt.scene);
    apply_overrides3(p, opt);
    MLC_CHECK(!p.contacts.empty(),
              "scene '" << p.name << "' has no contact: a 3D scene without contact runs with "
                        << "`mlcontact bench elastic " << opt.scene << "`");
    MLC_CHECK(opt.vtu == "binary", "--vtu ascii is 2D-only: 3D runs write binary VTU");
    levels::SolveOptions3 so;
    so.coarse_to_fine = !opt.cold;
    so.extrapolate = !opt.no_extrapolation;
    std::optional<levels::Method3> forced;
    if (opt.linear && *opt.linear != "krylov")
        forced = *opt.linear == "lu" ? levels::Method3::lu : levels::Method3::schur;
    // The solvers by the levels' predicted sizes; a run that cannot fit is refused before
    // anything is built.
    levels::Plan3 plan = levels::plan_contact3(levels::predict_elastic3_sizes(p, p.levels), forced,
                                               levels::process_memory_limit());
    so.level0 = plan.level0;
    so.upper = plan.upper;
    if (const auto spec = krylov_spec3(opt, false)) {
        MLC_CHECK(p.levels >= 1, "--pc " << spec->pc.text()
                                         << " sets the solver of the levels above level 0, and "
                                            "this run has none (--levels 0)");
        so.upper = levels::Method3::krylov;
        so.krylov = *spec;
        if (const auto at = plan.why.find(", gmres + mg above"); at != std::string::npos)
            plan.why = plan.why.substr(0, at) + ", " + upper_solver_text(so) + " above (--pc)";
    }
    if (opt.linear_rel_tol) {
        MLC_CHECK(so.upper != levels::Method3::schur && so.upper != levels::Method3::lu &&
                      p.levels >= 1,
                  "--linear-tol sets the tolerance of the GMRES solves of the levels above level "
                  "0, and this run has none (--levels 0 or --linear schur|lu)");
        so.krylov_rel_tol = *opt.linear_rel_tol;
    }
    const std::filesystem::path dir = opt.out.empty() ? "out/" + p.name : opt.out;
    OutputFolder folder(dir);
    if (opt.stop) so.interrupt = [&] { return opt.stop->load(); };
    if (!opt.quiet) so.progress = progress_lines(os);
    os << "mlcontact: solving '" << p.name << "' (3D)\n";
    RunResult3 r;
    try {
        r = levels::solve(p, so);
    } catch (const Interrupted& e) {
        const int sig = stop_signal();
        os << "stopped by " << signal_name(sig) << " during the solve (" << e.what()
           << "); nothing written\n";
        return 128 + (sig > 0 ? sig : 2);
    }
    os << "\n";
    print_header3(os, p, r, so, plan);
    print_steps3(os, r);
    if (!r.converged) {
        os << "\nerror: " << r.failure << "\n";
        return 2;
    }
    const Level3& L = r.finest();
    const auto areas = levels::contact_areas(p, L);
    const auto res = resultants(p, L, r.nodes);
    for (size_t c = 0; c < p.contacts.size(); ++c)
        os << "contact '" << p.contacts[c].name << "': resultant on the contactor ("
           << res[c].first.x() << ", " << res[c].first.y() << ", " << res[c].first.z() << "), "
           << res[c].second << " nodes in contact\n";
    for (const auto& nodes : r.step_nodes)
        check_nodes(nodes);
    for (Index i = 0; i < r.u_full.size(); ++i)
        require_finite3(r.u_full[i], "displacement");
    folder.begin_writing(p.name);
    std::vector<std::string> files;
    write_solution_vtu3(dir / "solution.vtu", L, r.u_full, r.nodes, areas, mesh::VtuFormat::binary);
    files.push_back("solution.vtu");
    write_file_atomically(dir / "contact.csv", [&](std::ostream& f) {
        f << kNodeColumns << "\n" << std::setprecision(17);
        for (size_t e = 0; e < r.nodes.size(); ++e)
            write_node(f, pair_name(p, L, e), r.nodes[e], areas[e]);
    });
    files.push_back("contact.csv");
    write_file_atomically(dir / "contact_steps.csv", [&](std::ostream& f) {
        f << "step,s," << kNodeColumns << "\n" << std::setprecision(17);
        for (size_t k = 0; k < r.step_nodes.size(); ++k)
            for (size_t e = 0; e < r.step_nodes[k].size(); ++e) {
                f << k + 1 << "," << static_cast<double>(k + 1) / p.load_steps << ",";
                write_node(f, pair_name(p, L, e), r.step_nodes[k][e], areas[e]);
            }
    });
    files.push_back("contact_steps.csv");
    write_iterations3(dir / "iterations.csv", r);
    files.push_back("iterations.csv");
    for (const auto& f : files)
        folder.add(f);
    write_summary3(dir, p, r, files, so, plan);
    os << "\nwrote";
    for (const auto& f : files)
        os << " " << (dir / f).string() << ",";
    os << " " << (dir / "summary.json").string() << "\n";
    return 0;
}

} // namespace mlc::apps
