// SPDX-License-Identifier: MIT
// Status-transfer study (issue: level hierarchy and coarse-to-fine Newton).
#include "studies/status_transfer.hpp"

#include "run/plot_script.hpp"

#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "levels/solve.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <sys/wait.h>
#include <toml++/toml.h>

namespace mlc::apps {

namespace {

constexpr const char* kStatusNames[4] = {"gap", "stick", "slip_forward", "slip_backward"};

/// Distance, in contact nodes along the contact boundary, from every contact node to the
/// nearest zone boundary (a node whose final status differs from a neighbour's; distance 0).
std::vector<int> distance_to_zone_boundary(const levels::Level& L,
                                           const std::vector<contact::Status>& st) {
    const size_t n = L.contacts.size();
    std::vector<std::vector<int>> nb(n);
    for (const auto& e : L.mesh.boundary) {
        const int a = L.contact_of_vertex[static_cast<size_t>(e.v0)];
        const int b = L.contact_of_vertex[static_cast<size_t>(e.v1)];
        if (a >= 0 && b >= 0) {
            nb[static_cast<size_t>(a)].push_back(b);
            nb[static_cast<size_t>(b)].push_back(a);
        }
    }
    std::vector<int> dist(n, -1);
    std::deque<int> q;
    for (size_t i = 0; i < n; ++i)
        for (int j : nb[i])
            if (st[i] != st[static_cast<size_t>(j)]) {
                dist[i] = 0;
                q.push_back(static_cast<int>(i));
                break;
            }
    while (!q.empty()) {
        const int i = q.front();
        q.pop_front();
        for (int j : nb[static_cast<size_t>(i)])
            if (dist[static_cast<size_t>(j)] < 0) {
                dist[static_cast<size_t>(j)] = dist[static_cast<size_t>(i)] + 1;
                q.push_back(j);
            }
    }
    return dist;
}

/// Final statuses along the contact boundary per level (for the plot).
void write_final_statuses(const std::filesystem::path& file, const levels::RunResult& warm,
                          int levels) {
    AtomicOfstream sc(file);
    sc << "level,x,y,status\n" << std::setprecision(12);
    for (int l = 0; l <= levels; ++l) {
        const auto& L = warm.levels()[static_cast<size_t>(l)];
        const auto& st = warm.level_steps[static_cast<size_t>(l)].back().final_statuses;
        for (size_t e = 0; e < st.size(); ++e) {
            const Vec2 p = L.mesh.vertices[static_cast<size_t>(L.contacts[e].vertex[0])];
            sc << l << "," << p.x() << "," << p.y() << ","
               << kStatusNames[static_cast<size_t>(st[e])] << "\n";
        }
    }
}

/// The confusion table of one level, predicted statuses against final ones.
void print_confusion(std::ostream& os, const levels::Confusion& total) {
    os << "        confusion (rows predicted, cols final; gap stick slip+ slip-):";
    for (size_t a = 0; a < 4; ++a) {
        os << (a ? " |" : " ");
        for (size_t b = 0; b < 4; ++b)
            os << " " << total[a][b];
    }
    os << "\n";
}

} // namespace

int study_status_transfer(const levels::Problem& problem_in, const StatusTransferOptions& opt,
                          std::ostream& os) {
    MLC_CHECK(opt.levels >= 1 && opt.levels <= 8,
              "the status-transfer study needs --levels between 1 and 8, found " << opt.levels);
    levels::Problem problem = problem_in;
    problem.levels = opt.levels;
    const auto dir =
        opt.out.empty() ? std::filesystem::path("out") / problem.name / "status_transfer" : opt.out;
    std::filesystem::create_directories(dir);

    os << "status-transfer study: scene '" << problem.name << "', levels 0.." << opt.levels << ", "
       << problem.load_steps << " load steps, Q rule "
       << (opt.q_rule == transfer::QRule::paper ? "paper" : "conservative")
       << (opt.increment ? ", warm start from the interpolated increment" : "") << "\n";
    levels::SolveOptions warm_opt;
    warm_opt.coarse_to_fine = true;
    warm_opt.q_rule = opt.q_rule;
    warm_opt.transfer_increment = opt.increment;
    os << "  solving coarse-to-fine ...\n" << std::flush;
    const levels::RunResult warm = levels::solve(problem, warm_opt);
    levels::SolveOptions cold_opt;
    cold_opt.coarse_to_fine = false;
    cold_opt.solve_all_levels = true;
    os << "  solving cold (every level from its previous load step) ...\n" << std::flush;
    const levels::RunResult cold = levels::solve(problem, cold_opt);
    if (!warm.converged) {
        os << "error: coarse-to-fine run failed: " << warm.failure << "\n";
        return 2;
    }
    if (!cold.converged) os << "note: the cold run failed: " << cold.failure << "\n";

    // Per level and step rows.
    AtomicOfstream csv(dir / "status_transfer.csv");
    csv << "level,step,unknowns,contact_nodes,newton_warm,newton_cold,agreement,mispredicted,"
           "mispredicted_at_zone_boundary";
    for (auto p : kStatusNames)
        for (auto f : kStatusNames)
            csv << ",pred_" << p << "__final_" << f;
    csv << "\n";
    toml::array jlevels;
    os << "\n level  unknowns  contacts  newton/step warm  cold   agreement  mispredicted  at zone "
          "boundary (<=1 node)\n";
    double warm_sum = 0, cold_sum = 0, agree_min = 1.0;
    int n_avg = 0;
    for (int l = 0; l <= opt.levels; ++l) {
        const auto& L = warm.levels()[static_cast<size_t>(l)];
        const auto& ws = warm.level_steps[static_cast<size_t>(l)];
        const auto& cs = cold.level_steps[static_cast<size_t>(l)];
        double w = 0, c = 0, agree = 0;
        int mis = 0, mis_near = 0;
        levels::Confusion total{};
        toml::array jsteps;
        for (size_t k = 0; k < ws.size(); ++k) {
            const auto& st = ws[k];
            const int cold_it = k < cs.size() ? cs[k].report.iterations : -1;
            const auto dist = distance_to_zone_boundary(L, st.final_statuses);
            int m = 0, near = 0;
            if (st.predicted)
                for (size_t e = 0; e < dist.size(); ++e)
                    if (st.predicted_statuses[e] != st.final_statuses[e]) {
                        ++m;
                        near += dist[e] >= 0 && dist[e] <= 1;
                    }
            w += st.report.iterations;
            c += cold_it;
            agree += st.agreement();
            mis += m;
            mis_near += near;
            csv << l << "," << st.report.step << "," << L.n_unknowns() << "," << L.n_contact_nodes()
                << "," << st.report.iterations << "," << cold_it << "," << st.agreement() << ","
                << m << "," << near;
            for (size_t a = 0; a < 4; ++a)
                for (size_t b = 0; b < 4; ++b) {
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
            js.insert("mispredicted_at_zone_boundary", static_cast<int64_t>(near));
            jsteps.push_back(js);
        }
        const double ns = static_cast<double>(ws.size());
        os << std::setw(6) << l << std::setw(10) << L.n_unknowns() << std::setw(10)
           << L.n_contact_nodes() << std::setw(18) << std::fixed << std::setprecision(2) << w / ns
           << std::setw(6) << c / ns << std::setw(12) << std::setprecision(4)
           << (l == 0 ? 1.0 : agree / ns) << std::setw(14) << (l == 0 ? 0 : mis) << std::setw(14)
           << (l == 0 ? 0 : mis_near) << std::defaultfloat << "\n";
        if (l >= 2) {
            warm_sum += w / ns;
            cold_sum += c / ns;
            agree_min = std::min(agree_min, agree / ns);
            ++n_avg;
        }
        toml::table jl;
        jl.insert("level", static_cast<int64_t>(l));
        jl.insert("unknowns", static_cast<int64_t>(L.n_unknowns()));
        jl.insert("contact_nodes", static_cast<int64_t>(L.n_contact_nodes()));
        jl.insert("newton_per_step_warm", w / ns);
        jl.insert("newton_per_step_cold", c / ns);
        jl.insert("predicted_status_agreement", l == 0 ? 1.0 : agree / ns);
        toml::array conf;
        for (size_t a = 0; a < 4; ++a) {
            toml::array row;
            for (size_t b = 0; b < 4; ++b)
                row.push_back(static_cast<int64_t>(total[a][b]));
            conf.push_back(row);
        }
        jl.insert("confusion_predicted_rows_final_cols", conf);
        jl.insert("steps", jsteps);
        jlevels.push_back(jl);
        if (l >= 1) print_confusion(os, total);
    }
    if (n_avg > 0) {
        os << "\nlevels 2.." << opt.levels << ": Newton iterations per load step, coarse-to-fine "
           << std::setprecision(3) << warm_sum / n_avg << " vs cold " << cold_sum / n_avg
           << " (ratio " << warm_sum / cold_sum << "); lowest predicted status agreement "
           << agree_min << "\n";
    }
    write_final_statuses(dir / "statuses.csv", warm, opt.levels);
    toml::table root;
    root.insert("scene", problem.name);
    root.insert("levels", jlevels);
    if (n_avg > 0) {
        root.insert("newton_per_step_warm_levels_2_up", warm_sum / n_avg);
        root.insert("newton_per_step_cold_levels_2_up", cold_sum / n_avg);
        root.insert("min_predicted_status_agreement_levels_2_up", agree_min);
    }
    AtomicOfstream js(dir / "status_transfer.json");
    js << toml::json_formatter{root} << "\n";
    csv.close();
    js.close();
    os << "wrote " << (dir / "status_transfer.csv").string()
       << ", status_transfer.json, statuses.csv\n";
    if (opt.plot && run_plot_script("plot_status_transfer.py", dir, os))
        os << "wrote " << (dir / "status_transfer.png").string() << "\n";
    return cold.converged ? 0 : 2;
}

} // namespace mlc::apps
