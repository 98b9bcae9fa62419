// SPDX-License-Identifier: MIT
// Stability study of the 3D contact solve: block3d and stack3d pushed to their extremes.
#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "levels/resources.hpp"
#include "levels/solve3.hpp"
#include "scene/scene3.hpp"
#include "studies/extremes.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <vector>

namespace mlc::apps {

namespace {

using levels::ElasticProblem3;
using levels::Method3;

/// One case: a variant of a 3D scene, solved by the study's solver on its levels.
struct Case3 {
    std::string name;
    std::string what;
    std::function<ElasticProblem3()> problem;
    /// Checks a converged case beyond convergence (e.g. every node open); may be empty.
    std::function<void(ExtremesFields&)> expect;
};

std::string num3(double v, int digits = 3) {
    std::ostringstream os;
    os << std::setprecision(digits) << v;
    return os.str();
}

/// Solves a case on levels 0..levels (coarse-to-fine) with `forced` (exact on every level) or,
/// without it, the run's plan, and summarizes it.
ExtremesFields solve_case3(ElasticProblem3 p, int levels, std::optional<Method3> forced) {
    p.levels = levels;
    const levels::Plan3 plan = levels::plan_contact3(levels::predict_elastic3_sizes(p, levels),
                                                     forced, levels::process_memory_limit());
    levels::SolveOptions3 so;
    so.level0 = plan.level0;
    so.upper = plan.upper;
    ExtremesFields f;
    const double t0 = wall_seconds();
    const levels::RunResult3 r = levels::solve(p, so);
    f["seconds"] = num3(wall_seconds() - t0);
    int newton = 0, krylov = 0, systems = 0, cycling = 0, inexact = 0;
    for (const auto& ls : r.level_steps)
        for (const auto& st : ls) {
            newton += st.report.iterations;
            krylov += st.report.linear_iterations;
            systems += static_cast<int>(st.report.linear_iterations_per_newton.size());
            cycling += st.report.cycling_detected_at >= 0;
            inexact += st.report.inexact_steps;
        }
    f["newton"] = std::to_string(newton);
    f["krylov"] = std::to_string(krylov);
    if (systems > 0 && krylov > 0)
        f["krylov_per_newton"] = num3(static_cast<double>(krylov) / systems);
    if (cycling > 0) f["cycling"] = std::to_string(cycling);
    if (inexact > 0) f["inexact"] = std::to_string(inexact);
    if (!r.converged) {
        f["status"] = "no conv";
        f["diagnosis"] = r.failure.empty() ? std::string("no diagnosis given") : r.failure;
        return f;
    }
    // Nothing non-finite is reported as converged.
    bool finite = r.u_full.allFinite();
    double umax = 0.0, lmax = 0.0;
    for (const auto& n : r.nodes) {
        finite =
            finite && std::isfinite(n.lambda_n) && n.lambda_t.allFinite() && std::isfinite(n.d_n);
        umax = std::max(umax, n.u.norm());
        lmax = std::max(lmax, std::abs(n.lambda_n));
    }
    for (Index i = 0; i < r.u_full.size(); i += 3)
        umax = std::max(umax, r.u_full.segment<3>(i).norm());
    double res = 0.0;
    for (const auto& s : r.steps)
        if (!s.residuals.empty()) res = std::max(res, s.residuals.back());
    if (!finite || !std::isfinite(res)) {
        f["status"] = "NaN";
        f["diagnosis"] = "non-finite displacement, multiplier or residual";
        return f;
    }
    // Penetration: the deepest negative gap relative to the largest displacement; Coulomb: the
    // largest of |lambda_t| - mu |lambda_n| and a tensile lambda_n, relative to max |lambda_n|.
    const auto& L = r.finest();
    double pen = 0.0, coulomb = 0.0;
    int gap = 0, stick = 0, slip = 0;
    for (size_t e = 0; e < r.nodes.size(); ++e) {
        const auto& n = r.nodes[e];
        const double mu = p.contacts[static_cast<size_t>(L.contacts[e].pair)].mu;
        pen = std::max(pen, -n.d_n);
        coulomb = std::max({coulomb, n.lambda_t.norm() - mu * std::abs(n.lambda_n), n.lambda_n});
        const int code = levels::status_code3(n.status);
        (code == 0 ? gap : code == 1 ? stick : slip) += 1;
    }
    f["residual"] = num3(res);
    f["penetration"] = num3(umax > 0 ? std::max(pen, 0.0) / umax : 0.0);
    f["coulomb"] = num3(lmax > 0 ? std::max(coulomb, 0.0) / lmax : 0.0);
    f["statuses"] = std::to_string(gap) + "/" + std::to_string(stick) + "/" + std::to_string(slip);
    f["contacts"] = std::to_string(r.nodes.size());
    f["status"] = "converged";
    return f;
}

ElasticProblem3 block3d() {
    return scene::load_scene3("block3d");
}

/// The r = factor E h0 of a 3D pair (scene/scene3.hpp's r_over_E).
double r_of(const ElasticProblem3& p, double factor) {
    double Emin = p.bodies.front().material.E;
    for (const auto& b : p.bodies)
        Emin = std::min(Emin, b.material.E);
    return factor * Emin * levels::mean_face_edge_length(p.mesh0, p.contacts.front().contactor);
}

/// block3d with one parameter pushed to its extremes: friction, r, Poisson's ratio, loads.
void add_block_parameter_cases(std::vector<Case3>& cs) {
    for (double mu : {0.0, 0.01, 2.0, 10.0})
        cs.push_back({"mu=" + num3(mu),
                      "block3d, friction coefficient (scene: 1)",
                      [mu] {
                          auto p = block3d();
                          p.contacts[0].mu = mu;
                          return p;
                      },
                      {}});
    for (double rf : {1e-4, 1e-2, 10.0, 1e4})
        cs.push_back({"r=" + num3(rf) + " E h0",
                      "block3d, augmentation parameter (scene: 0.1 E h0)",
                      [rf] {
                          auto p = block3d();
                          p.contacts[0].r = r_of(p, rf);
                          return p;
                      },
                      {}});
    for (double nu : {0.45, 0.49, 0.4999})
        cs.push_back({"nu=" + num3(nu, 6),
                      "block3d, near-incompressible (scene: 0.2)",
                      [nu] {
                          auto p = block3d();
                          p.bodies[0].material.nu = nu;
                          return p;
                      },
                      {}});
    for (double s : {1e-8, 1e3})
        cs.push_back({"load x" + num3(s),
                      "block3d, both loads scaled",
                      [s] {
                          auto p = block3d();
                          for (auto& ld : p.loads) {
                              ld.pressure *= s;
                              ld.traction *= s;
                          }
                          return p;
                      },
                      {}});
}

/// Extreme loadings of block3d: every node open, and gross slip.
void add_block_loading_cases(std::vector<Case3>& cs) {
    cs.push_back({"lift-off", "block3d with suction on top, no side load: every node opens",
                  [] {
                      auto p = block3d();
                      for (auto& ld : p.loads) {
                          if (ld.tag == "zmax") ld.pressure = -50.0;
                          if (ld.tag == "xmin") ld.traction.setZero();
                      }
                      return p;
                  },
                  [](ExtremesFields& f) {
                      if (f["statuses"] != f["contacts"] + "/0/0") {
                          f["status"] = "wrong";
                          f["diagnosis"] = "expected every contact node open";
                      }
                  }});
    cs.push_back({"gross slip",
                  "block3d, mu = 0.1, side load 10 x nominal (30 mu p)",
                  [] {
                      auto p = block3d();
                      p.contacts[0].mu = 0.1;
                      for (auto& ld : p.loads)
                          if (ld.tag == "xmin") ld.traction *= 10.0;
                      return p;
                  },
                  {}});
}

/// stack3d with Young's moduli 1e6 apart, both ways round, and friction at the interface.
void add_contrast_cases(std::vector<Case3>& cs) {
    for (const bool soft_on_stiff : {true, false})
        cs.push_back({soft_on_stiff ? "contrast 1e6 soft/stiff" : "contrast 1e6 stiff/soft",
                      soft_on_stiff ? "stack3d: upper E = 1 on lower E = 1e6, mu = 0.3"
                                    : "stack3d: upper E = 1e6 on lower E = 1, mu = 0.3",
                      [soft_on_stiff] {
                          auto p = scene::load_scene3("stack3d");
                          MLC_CHECK(p.bodies.size() == 2 && p.bodies[0].name == "lower",
                                    "extremes (3D): stack3d must have the bodies lower and upper");
                          // r stays the scene's: 0.1 x the smaller E (1) x h0.
                          p.bodies[0].material.E = soft_on_stiff ? 1e6 : 1.0;
                          p.bodies[1].material.E = soft_on_stiff ? 1.0 : 1e6;
                          p.contacts[0].mu = 0.3;
                          return p;
                      },
                      {}});
}

std::vector<Case3> make_cases3() {
    std::vector<Case3> cs;
    add_block_parameter_cases(cs);
    add_block_loading_cases(cs);
    add_contrast_cases(cs);
    return cs;
}

/// The notes column of a row.
std::string notes_of(ExtremesFields& f) {
    std::string notes = f.count("diagnosis") ? f["diagnosis"] : "";
    auto add = [&](const std::string& s) { notes += (notes.empty() ? "" : "; ") + s; };
    if (f.count("statuses")) add("gap/stick/slip " + f["statuses"]);
    if (f.count("cycling")) add(f["cycling"] + " level step(s) with status cycling, damped");
    if (f.count("inexact")) add(f["inexact"] + " Newton step(s) from a GMRES solve at its cap");
    return notes;
}

} // namespace

int study_extremes3(const ExtremesOptions& opt, std::ostream& os) {
    MLC_CHECK(opt.levels >= 0 && opt.levels <= 4,
              "the 3D extremes study needs --levels between 0 and 4, found " << opt.levels);
    MLC_CHECK(opt.seconds_per_case > 0,
              "--seconds must be positive, found " << opt.seconds_per_case);
    const std::string why = " does not apply to the 3D extremes study: its levels are solved by "
                            "schur or lu on level 0 and GMRES + mg above, or exactly on every "
                            "level with --linear schur|lu";
    MLC_CHECK(!opt.krylov, "--krylov" << why);
    MLC_CHECK(!opt.pc, "--pc" << why);
    MLC_CHECK(!opt.linear_rel_tol, "--linear-tol" << why);
    MLC_CHECK(!opt.linear || *opt.linear == "schur" || *opt.linear == "lu",
              "--linear " << *opt.linear << why);
    const auto dir = opt.out.empty() ? std::filesystem::path("out/studies/extremes3") : opt.out;
    std::filesystem::create_directories(dir);
    // The solvers: the one asked for, or the run's plan and the exact lu on every level.
    std::vector<std::optional<Method3>> solvers;
    if (opt.linear)
        solvers.push_back(*opt.linear == "lu" ? Method3::lu : Method3::schur);
    else
        solvers = {std::nullopt, Method3::lu};
    auto solver_name = [](const std::optional<Method3>& m) {
        return m ? std::string(levels::to_string(*m)) + " (every level)"
                 : std::string("plan (schur|lu on level 0, gmres + mg above)");
    };
    os << "stability study (3D): block3d- and stack3d-based cases on levels 0.." << opt.levels
       << " (coarse-to-fine), " << opt.seconds_per_case << " s per case, " << solvers.size()
       << " Newton-system solver(s)\n";
    AtomicOfstream csv(dir / "extremes.csv");
    csv << "solver,case,description,result,exit,newton,krylov,krylov_per_newton,residual,"
           "penetration,coulomb,seconds,notes\n";
    toml::array jrows;
    bool bad = false;
    for (const auto& solver : solvers) {
        const std::string sname = solver_name(solver);
        os << "\nsolver: " << sname << "\n"
           << std::left << std::setw(26) << "case" << std::setw(11) << "result" << std::setw(6)
           << "exit" << std::setw(9) << "newton" << std::setw(11) << "residual" << std::setw(12)
           << "penetration" << std::setw(10) << "Coulomb" << std::setw(9) << "seconds"
           << std::setw(12) << "krylov/newt"
           << "notes\n"
           << std::right << std::flush;
        for (const auto& c : make_cases3()) {
            if (!opt.only.empty() && c.name.find(opt.only) == std::string::npos) continue;
            ExtremesFields f = run_isolated(
                [&] {
                    ExtremesFields g = solve_case3(c.problem(), opt.levels, solver);
                    if (c.expect && g["status"] == "converged") c.expect(g);
                    return g;
                },
                opt.seconds_per_case);
            auto get = [&](const std::string& k) { return f.count(k) ? f[k] : std::string("-"); };
            const std::string notes = notes_of(f);
            os << std::left << std::setw(26) << c.name << std::setw(11) << get("status")
               << std::setw(6) << get("exit") << std::setw(9) << get("newton") << std::setw(11)
               << get("residual") << std::setw(12) << get("penetration") << std::setw(10)
               << get("coulomb") << std::setw(9) << get("seconds") << std::setw(12)
               << get("krylov_per_newton") << notes << std::right << "\n"
               << std::flush;
            csv << '"' << sname << "\",\"" << c.name << "\",\"" << c.what << "\"," << get("status")
                << "," << get("exit") << "," << get("newton") << "," << get("krylov") << ","
                << get("krylov_per_newton") << "," << get("residual") << "," << get("penetration")
                << "," << get("coulomb") << "," << get("seconds") << ",\"" << notes << "\"\n";
            toml::table row;
            row.insert("solver", sname);
            row.insert("case", c.name);
            row.insert("description", c.what);
            for (const auto& [k, v] : f)
                row.insert(k, v);
            jrows.push_back(row);
            const std::string st = get("status");
            bad = bad || st == "crash" || st == "timeout" || st == "NaN" || st == "error" ||
                  st == "wrong";
        }
    }
    toml::table root;
    root.insert("dimension", 3);
    root.insert("levels", static_cast<int64_t>(opt.levels));
    root.insert("cases", jrows);
    AtomicOfstream js(dir / "extremes.json");
    js << toml::json_formatter{root} << "\n";
    csv.close();
    js.close();
    MLC_CHECK(csv.good() && js.good(), "cannot write the study's files in " << dir.string());
    os << "\nwrote " << (dir / "extremes.csv").string() << ", extremes.json\n";
    return bad ? 3 : 0;
}

} // namespace mlc::apps
