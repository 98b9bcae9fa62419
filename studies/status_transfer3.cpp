// SPDX-License-Identifier: MIT
// The status-transfer study of a 3D scene: coarse-to-fine against cold on every level.
#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "levels/solve3.hpp"
#include "studies/status_transfer.hpp"

#include <toml++/toml.h>

#include <iomanip>

namespace mlc::apps {

int study_status_transfer3(const levels::ElasticProblem3& problem_in,
                           const StatusTransferOptions& opt, std::ostream& os) {
    MLC_CHECK(opt.levels >= 1 && opt.levels <= 4,
              "the 3D status-transfer study needs --levels between 1 and 4, found " << opt.levels);
    levels::ElasticProblem3 problem = problem_in;
    problem.levels = opt.levels;
    const auto dir =
        opt.out.empty() ? std::filesystem::path("out") / problem.name / "status_transfer" : opt.out;
    std::filesystem::create_directories(dir);
    os << "status-transfer study: scene '" << problem.name << "' (3D), levels 0.." << opt.levels
       << ", " << problem.load_steps << " load steps, multipliers by the surface Q\n";
    levels::SolveOptions3 warm_opt, cold_opt;
    cold_opt.coarse_to_fine = false;
    cold_opt.solve_all_levels = true;
    os << "  solving coarse-to-fine ...\n" << std::flush;
    const levels::RunResult3 warm = levels::solve(problem, warm_opt);
    os << "  solving cold (every level from its own previous load steps) ...\n" << std::flush;
    const levels::RunResult3 cold = levels::solve(problem, cold_opt);
    if (!warm.converged) {
        os << "error: coarse-to-fine run failed: " << warm.failure << "\n";
        return 2;
    }
    if (!cold.converged) os << "note: the cold run failed: " << cold.failure << "\n";
    const auto& names = levels::kStatusNames3;
    AtomicOfstream csv(dir / "status_transfer.csv");
    csv << "level,step,unknowns,contact_nodes,newton_warm,newton_cold,agreement,mispredicted";
    for (auto p : names)
        for (auto f : names)
            csv << ",pred_" << p << "__final_" << f;
    csv << "\n";
    toml::array jlevels;
    os << "\n level  unknowns  contacts  newton/step warm  cold   agreement  mispredicted\n";
    for (int l = 0; l <= opt.levels; ++l) {
        const auto& L = warm.hierarchy.levels[static_cast<size_t>(l)];
        const auto& ws = warm.level_steps[static_cast<size_t>(l)];
        const auto& cs = cold.level_steps[static_cast<size_t>(l)];
        double w = 0, c = 0, agree = 0;
        int mis = 0;
        std::array<std::array<int, 3>, 3> total{};
        toml::array jsteps;
        for (size_t k = 0; k < ws.size(); ++k) {
            const auto& st = ws[k];
            const int cold_it = k < cs.size() ? cs[k].report.iterations : -1;
            int m = 0;
            if (st.predicted)
                for (size_t e = 0; e < st.final_statuses.size(); ++e)
                    m += levels::status_code3(st.predicted_statuses[e]) !=
                         levels::status_code3(st.final_statuses[e]);
            w += st.report.iterations;
            c += cold_it;
            agree += st.agreement();
            mis += m;
            csv << l << "," << st.report.step << "," << L.n_unknowns() << ","
                << L.n_contact_nodes() << "," << st.report.iterations << "," << cold_it << ","
                << st.agreement() << "," << m;
            for (size_t a = 0; a < 3; ++a)
                for (size_t b = 0; b < 3; ++b) {
                    csv << "," << st.confusion[a][b];
                    total[a][b] += st.confusion[a][b];
                }
            csv << "\n";
            toml::table js;
            js.insert("step", static_cast<int64_t>(st.report.step));
            js.insert("newton_iterations", static_cast<int64_t>(st.report.iterations));
            js.insert("newton_iterations_cold", static_cast<int64_t>(cold_it));
            js.insert("predicted_status_agreement", st.agreement());
            js.insert("mispredicted", static_cast<int64_t>(m));
            jsteps.push_back(js);
        }
        const double ns = static_cast<double>(ws.size());
        os << std::setw(6) << l << std::setw(10) << L.n_unknowns() << std::setw(10)
           << L.n_contact_nodes() << std::setw(18) << std::fixed << std::setprecision(2) << w / ns
           << std::setw(6) << c / ns << std::setw(12) << std::setprecision(4)
           << (l == 0 ? 1.0 : agree / ns) << std::setw(14) << mis << std::defaultfloat << "\n";
        toml::table jl;
        jl.insert("level", static_cast<int64_t>(l));
        jl.insert("unknowns", static_cast<int64_t>(L.n_unknowns()));
        jl.insert("contact_nodes", static_cast<int64_t>(L.n_contact_nodes()));
        jl.insert("newton_per_step_warm", w / ns);
        jl.insert("newton_per_step_cold", c / ns);
        jl.insert("predicted_status_agreement", l == 0 ? 1.0 : agree / ns);
        toml::array conf;
        for (size_t a = 0; a < 3; ++a) {
            toml::array row;
            for (size_t b = 0; b < 3; ++b)
                row.push_back(static_cast<int64_t>(total[a][b]));
            conf.push_back(row);
        }
        jl.insert("confusion_predicted_rows_final_cols", conf);
        jl.insert("steps", jsteps);
        jlevels.push_back(jl);
        if (l >= 1) {
            os << "        predicted \\ final      gap    stick     slip\n";
            for (size_t a = 0; a < 3; ++a) {
                os << "        " << std::left << std::setw(18) << names[a] << std::right;
                for (size_t b = 0; b < 3; ++b)
                    os << std::setw(9) << total[a][b];
                os << "\n";
            }
        }
    }
    toml::table root;
    root.insert("scene", problem.name);
    root.insert("dimension", 3);
    root.insert("levels", jlevels);
    AtomicOfstream js(dir / "status_transfer.json");
    js << toml::json_formatter{root} << "\n";
    csv.close();
    js.close();
    MLC_CHECK(csv.good() && js.good(), "cannot write the study's files in " << dir.string());
    os << "wrote " << (dir / "status_transfer.csv").string() << ", status_transfer.json"
       << (opt.plot ? " (the plot draws the 2D status lines: none in 3D)" : "") << "\n";
    return cold.converged ? 0 : 2;
}

} // namespace mlc::apps
