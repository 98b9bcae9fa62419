// SPDX-License-Identifier: MIT
// The result files of a run: VTU/PVD, CSV and JSON.
#include "run/output.hpp"
#include "run/summary_json.hpp"

#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "core/memory.hpp"
#include "core/parallel.hpp"
#include "levels/checks.hpp"
#include "mesh/io/vtu.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <sys/file.h>
#include <sys/stat.h>
#include <toml++/toml.h>
#include <unistd.h>

namespace mlc::apps {

namespace {

void require_finite(double v, const std::string& what) {
    if (!std::isfinite(v))
        throw SolverBreakdown("refusing to write a non-finite value (" + what +
                              "): the solve produced NaN/Inf");
}

} // namespace

SolutionFields solution_fields(const levels::Level& L, const Vector& u_full,
                               const std::vector<levels::ContactNodeState>& nodes) {
    const auto stresses = fem::cell_stresses(L.mesh, L.materials, u_full);
    for (double v : stresses)
        require_finite(v, "stress");
    const int nv = L.mesh.n_vertices();
    mesh::Field disp{"displacement", 2,
                     std::vector<double>(u_full.data(), u_full.data() + u_full.size())};
    mesh::Field status{"contact_status", 1, std::vector<double>(static_cast<size_t>(nv), -1.0)};
    mesh::Field force{"contact_force", 2, std::vector<double>(static_cast<size_t>(2 * nv), 0.0)};
    mesh::Field lt{"lambda_t", 1, std::vector<double>(static_cast<size_t>(nv), 0.0)};
    mesh::Field ln{"lambda_n", 1, std::vector<double>(static_cast<size_t>(nv), 0.0)};
    for (size_t e = 0; e < nodes.size(); ++e) {
        const auto& n = nodes[e];
        const auto& el = L.contacts[e];
        const size_t v = static_cast<size_t>(n.vertex);
        status.values[v] = static_cast<double>(static_cast<int>(n.status));
        // Force the obstacle/target exerts on the body: -(lambda_t t + lambda_n n).
        const Vec2 f = -(n.lambda_t * el.t + n.lambda_n * el.n);
        force.values[2 * v] = f.x() + 0.0; // + 0.0: no -0 for the zero force of a gap node
        force.values[2 * v + 1] = f.y() + 0.0;
        lt.values[v] = n.lambda_t;
        ln.values[v] = n.lambda_n;
    }
    mesh::Field stress{"stress", 3, stresses};
    mesh::Field vm{"von_mises", 1, std::vector<double>(static_cast<size_t>(L.mesh.n_cells()))};
    mesh::Field body{"body", 1, std::vector<double>(static_cast<size_t>(L.mesh.n_cells()), 0.0)};
    for (int t = 0; t < L.mesh.n_cells(); ++t) {
        const double sx = stresses[static_cast<size_t>(3 * t)],
                     sy = stresses[static_cast<size_t>(3 * t + 1)],
                     sxy = stresses[static_cast<size_t>(3 * t + 2)];
        const auto& m = fem::material_of(L.mesh, L.materials, t);
        // Plane strain: sigma_zz = nu (sx + sy); plane stress: 0.
        const double sz = m.plane == fem::Plane::strain ? m.nu * (sx + sy) : 0.0;
        vm.values[static_cast<size_t>(t)] = std::sqrt(
            0.5 * ((sx - sy) * (sx - sy) + (sy - sz) * (sy - sz) + (sz - sx) * (sz - sx)) +
            3.0 * sxy * sxy);
        if (!L.mesh.attribute.empty())
            body.values[static_cast<size_t>(t)] = L.mesh.attribute[static_cast<size_t>(t)];
    }
    return {{disp, status, force, lt, ln}, {stress, vm, body}};
}

void write_solution_vtu(const std::filesystem::path& file, const levels::Level& L,
                        const Vector& u_full, const std::vector<levels::ContactNodeState>& nodes,
                        mesh::VtuFormat format) {
    for (Index i = 0; i < u_full.size(); ++i)
        require_finite(u_full[i], "displacement");
    for (const auto& n : nodes) {
        require_finite(n.lambda_t, "lambda_t");
        require_finite(n.lambda_n, "lambda_n");
    }
    const auto f = solution_fields(L, u_full, nodes);
    mesh::write_vtu(file, L.mesh, f.point, f.cell, format);
}

ContactGeometry contact_geometry(const levels::Problem& p, const levels::Level& L) {
    const size_t ne = L.contacts.size();
    ContactGeometry g;
    g.length.assign(ne, 0.0);
    g.arc.assign(ne, 0.0);
    const auto& verts = L.mesh.vertices;
    for (size_t k = 0; k < p.contacts.size(); ++k) {
        const auto& pair = p.contacts[k];
        const auto tag = L.mesh.find_tag(pair.contactor);
        if (!tag) continue;
        // The pair's contact-boundary edges, oriented with the body on the left.
        std::map<int, int> next, prev;
        for (const auto& be : L.mesh.boundary) {
            if (be.tag != *tag) continue;
            const Vec2& a = verts[static_cast<size_t>(be.v0)];
            const Vec2& b = verts[static_cast<size_t>(be.v1)];
            if (pair.region && !(pair.region->contains(a) && pair.region->contains(b))) continue;
            next[be.v0] = be.v1;
            prev[be.v1] = be.v0;
            const double h = (b - a).norm();
            for (int v : {be.v0, be.v1})
                if (const int e = L.contact_of_vertex[static_cast<size_t>(v)];
                    e >= 0 && L.contacts[static_cast<size_t>(e)].pair == static_cast<int>(k))
                    g.length[static_cast<size_t>(e)] += 0.5 * h;
        }
        // Walk the pieces: open ones from their start (no incoming edge), in the order of their
        // first contact node; then closed loops from their first contact node.
        std::vector<int> order; // contact elements of the pair, in element order
        for (size_t e = 0; e < ne; ++e)
            if (L.contacts[e].pair == static_cast<int>(k)) order.push_back(static_cast<int>(e));
        std::map<int, bool> visited;
        double arc = 0.0;
        bool any = false;
        Vec2 last = Vec2::Zero();
        auto walk = [&](int v) {
            if (any) arc += (verts[static_cast<size_t>(v)] - last).norm();
            any = true;
            while (true) {
                visited[v] = true;
                if (const int e = L.contact_of_vertex[static_cast<size_t>(v)];
                    e >= 0 && L.contacts[static_cast<size_t>(e)].pair == static_cast<int>(k))
                    g.arc[static_cast<size_t>(e)] = arc;
                last = verts[static_cast<size_t>(v)];
                const auto it = next.find(v);
                if (it == next.end() || visited[it->second]) break;
                arc += (verts[static_cast<size_t>(it->second)] - last).norm();
                v = it->second;
            }
        };
        // Start of the piece holding vertex v (its first vertex, or v itself on a loop).
        auto start_of = [&](int v) {
            std::map<int, bool> seen;
            while (prev.count(v) && !seen[v]) {
                seen[v] = true;
                v = prev[v];
            }
            return v; // on a loop: back at a vertex already seen, which has a predecessor
        };
        for (bool loops : {false, true})
            for (int e : order) {
                const int v = L.contacts[static_cast<size_t>(e)].vertex[0];
                if (visited[v]) continue;
                int s0 = start_of(v);
                const bool loop = prev.count(s0) > 0;
                if (loop != loops) continue;
                if (loop) s0 = v;
                walk(s0);
            }
    }
    return g;
}

namespace {

/// A CSV field: quoted when it holds a comma, quote or line break.
std::string csv_field(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s)
        q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
}

/// Pressure or traction per unit length of a nodal multiplier: -lambda / length (0 for a node
/// with no contact-boundary edge, length 0).
double per_length(double lambda, double length) {
    return length > 0.0 ? -lambda / length + 0.0 : 0.0;
}

} // namespace

void write_contact_steps(const std::filesystem::path& file, const levels::Problem& p,
                         const levels::Level& L,
                         const std::vector<std::vector<levels::ContactNodeState>>& step_nodes,
                         int completed_steps) {
    const ContactGeometry g = contact_geometry(p, L);
    write_file_atomically(file, [&](std::ostream& f) {
        f << "step,s,pair,x,y,ux,uy,lambda_t,lambda_n,length,arc,pressure,traction_t,status\n"
          << std::setprecision(17);
        for (int k = 0; k < completed_steps && k < static_cast<int>(step_nodes.size()); ++k) {
            const double s = static_cast<double>(k + 1) / p.load_steps;
            const auto& nodes = step_nodes[static_cast<size_t>(k)];
            for (size_t e = 0; e < nodes.size(); ++e) {
                const auto& n = nodes[e];
                const double len = g.length[e];
                f << k + 1 << "," << s << ","
                  << csv_field(p.contacts[static_cast<size_t>(L.contacts[e].pair)].name) << ","
                  << n.x.x() << "," << n.x.y() << "," << n.u.x() << "," << n.u.y() << ","
                  << n.lambda_t << "," << n.lambda_n << "," << len << "," << g.arc[e] << ","
                  << per_length(n.lambda_n, len) << "," << per_length(n.lambda_t, len) << ","
                  << contact::to_string(n.status) << "\n";
            }
        }
    });
}

toml::array steps_json(const std::vector<levels::StepReport>& steps, int* total_newton) {
    toml::array out;
    int total = 0;
    for (const auto& s : steps) {
        toml::table t;
        t.insert("step", static_cast<int64_t>(s.step));
        t.insert("load_factor", s.load_factor);
        t.insert("converged", s.converged);
        t.insert("newton_iterations", static_cast<int64_t>(s.iterations));
        t.insert("linear_iterations", static_cast<int64_t>(s.linear_iterations));
        toml::array res;
        for (double v : s.residuals) {
            if (std::isfinite(v))
                res.push_back(v);
            else // JSON has no NaN/Inf (a failed run's summary)
                res.push_back(std::string(v != v ? "NaN" : v > 0 ? "Infinity" : "-Infinity"));
        }
        t.insert("residuals", res);
        toml::array ch;
        for (int v : s.status_changes)
            ch.push_back(static_cast<int64_t>(v));
        t.insert("status_changes", ch);
        toml::table st;
        st.insert("gap", static_cast<int64_t>(s.counts.gap));
        st.insert("stick", static_cast<int64_t>(s.counts.stick));
        st.insert("slip_forward", static_cast<int64_t>(s.counts.slip_forward));
        st.insert("slip_backward", static_cast<int64_t>(s.counts.slip_backward));
        t.insert("statuses", st);
        t.insert("seconds", s.seconds);
        if (!s.message.empty()) t.insert("message", s.message);
        out.push_back(t);
        total += s.iterations;
    }
    if (total_newton) *total_newton = total;
    return out;
}

toml::table level_json(int level, std::int64_t unknowns, std::int64_t contact_nodes,
                       const std::vector<levels::LevelStep>& steps) {
    toml::table t;
    t.insert("level", static_cast<int64_t>(level));
    t.insert("unknowns", static_cast<int64_t>(unknowns));
    t.insert("contact_nodes", static_cast<int64_t>(contact_nodes));
    toml::array ls;
    for (const auto& st : steps) {
        toml::table u;
        u.insert("step", static_cast<int64_t>(st.report.step));
        u.insert("newton_iterations", static_cast<int64_t>(st.report.iterations));
        u.insert("linear_iterations", static_cast<int64_t>(st.report.linear_iterations));
        u.insert("predicted_status_agreement", st.agreement());
        u.insert("initial_guess", st.predicted      ? "interpolated"
                                  : st.extrapolated ? "extrapolated"
                                                    : "previous step");
        u.insert("seconds", st.report.seconds);
        ls.push_back(u);
    }
    t.insert("steps", ls);
    return t;
}

toml::array contacts_json(const levels::Problem& p, const std::vector<PairResultant>& resultants) {
    toml::array cs;
    for (size_t k = 0; k < p.contacts.size() && k < resultants.size(); ++k) {
        toml::table c;
        c.insert("name", p.contacts[k].name);
        c.insert("resultant", toml::array{resultants[k].force.x(), resultants[k].force.y()});
        c.insert("nodes_in_contact", static_cast<int64_t>(resultants[k].in_contact));
        cs.push_back(c);
    }
    return cs;
}

toml::table checks_json(const levels::StateChecks& c) {
    toml::table ct;
    // Not applicable (no force to balance): left out, and said so.
    if (c.force_balance_applicable) ct.insert("force_balance", c.force_balance);
    ct.insert("force_balance_applicable", c.force_balance_applicable);
    ct.insert("coulomb_excess", c.coulomb_excess);
    ct.insert("slip_equality", c.slip_equality);
    ct.insert("complementarity", c.complementarity);
    ct.insert("penetration", c.penetration);
    return ct;
}

void write_iterations_csv(const std::filesystem::path& file,
                          const std::vector<LevelIterations>& levels) {
    write_file_atomically(file, [&](std::ostream& f) {
        f << "level,unknowns,distributed,step,newton,krylov\n";
        for (const auto& lv : levels)
            for (const auto& st : *lv.steps)
                for (size_t i = 0; i < st.report.linear_iterations_per_newton.size(); ++i)
                    f << lv.level << "," << lv.unknowns << "," << (lv.distributed ? 1 : 0) << ","
                      << st.report.step << "," << i + 1 << ","
                      << st.report.linear_iterations_per_newton[i] << "\n";
    });
}

void write_result_files(const std::filesystem::path& dir, const levels::Problem& p,
                        const levels::RunResult& r, const OutputOptions& options,
                        std::vector<std::string>& written) {
    const auto& L = r.finest();
    std::filesystem::create_directories(dir);
    if (!r.converged && !r.stopped) return;
    // Check everything first so that no partial result set is left behind.
    for (const auto& nodes : r.step_nodes)
        for (const auto& n : nodes) {
            require_finite(n.lambda_t, "lambda_t");
            require_finite(n.lambda_n, "lambda_n");
        }
    for (const auto& s : r.steps)
        for (double v : s.residuals)
            require_finite(v, "Newton residual");
    if (r.converged) {
        write_solution_vtu(dir / "solution.vtu", L, r.u_full, r.nodes, options.vtu);
        written.push_back("solution.vtu");
        // contact.csv: one row per contact node of the final state.
        write_file_atomically(dir / "contact.csv", [&](std::ostream& f) {
            f << "x,y,ux,uy,lambda_t,lambda_n,status\n" << std::setprecision(17);
            for (const auto& n : r.nodes)
                f << n.x.x() << "," << n.x.y() << "," << n.u.x() << "," << n.u.y() << ","
                  << n.lambda_t << "," << n.lambda_n << "," << contact::to_string(n.status) << "\n";
        });
        written.push_back("contact.csv");
    }
    write_contact_steps(dir / "contact_steps.csv", p, L, r.step_nodes, r.completed_steps);
    written.push_back("contact_steps.csv");
    {
        std::vector<LevelIterations> its;
        for (size_t l = 0; l < r.level_steps.size(); ++l)
            if (!r.level_steps[l].empty())
                its.push_back({static_cast<int>(l), r.levels()[l].n_unknowns(), &r.level_steps[l]});
        write_iterations_csv(dir / "iterations.csv", its);
        written.push_back("iterations.csv");
    }
}

void write_summary(const std::filesystem::path& dir, const levels::Problem& p,
                   const levels::RunResult& r, const OutputOptions& options,
                   const SummaryStatus& status) {
    const auto& L = r.finest();
    std::filesystem::create_directories(dir);
    {
        toml::table root;
        root.insert("complete", status.complete);
        root.insert("scene", p.name);
        root.insert("units", p.units);
        root.insert("level", static_cast<int64_t>(r.levels().size() - 1));
        root.insert("unknowns", static_cast<int64_t>(L.n_unknowns()));
        root.insert("displacement_unknowns", static_cast<int64_t>(L.dofs.n_displacement_dofs()));
        root.insert("contact_nodes", static_cast<int64_t>(L.n_contact_nodes()));
        root.insert("vertices", static_cast<int64_t>(L.mesh.n_vertices()));
        root.insert("triangles", static_cast<int64_t>(L.mesh.n_cells()));
        root.insert("converged", r.converged);
        root.insert("stopped", status.stopped);
        if (status.stopped) root.insert("stopped_at", status.stopped_at);
        if (!r.converged && !r.stopped) root.insert("failure", r.failure);
        {
            toml::array files;
            for (const auto& f : status.files)
                files.push_back(f);
            files.push_back("summary.json");
            root.insert("files", files);
        }
        if (!status.plot.empty()) root.insert("plot", status.plot);
        root.insert("load_steps", static_cast<int64_t>(p.load_steps));
        root.insert("recovered_levels", static_cast<int64_t>(p.recovered_levels));
        root.insert("completed_steps", static_cast<int64_t>(r.completed_steps));
        root.insert("vtu_format", mesh::to_string(options.vtu));
        int total_newton = 0;
        root.insert("steps", steps_json(r.steps, &total_newton));
        toml::array lv;
        for (size_t l = 0; l < r.level_steps.size(); ++l) {
            if (r.level_steps[l].empty()) continue;
            const auto& Ll = r.levels()[l];
            lv.push_back(level_json(static_cast<int>(l), Ll.n_unknowns(), Ll.n_contact_nodes(),
                                    r.level_steps[l]));
        }
        root.insert("levels", lv);
        root.insert("total_newton_iterations", static_cast<int64_t>(total_newton));
        if (r.completed_steps > 0) { // per pair, at the last completed step
            std::vector<PairResultant> res;
            for (size_t k = 0; k < p.contacts.size(); ++k) {
                PairResultant q;
                q.force = levels::contact_resultant(r, static_cast<int>(k), &q.in_contact);
                res.push_back(q);
            }
            root.insert("contacts", contacts_json(p, res));
        }
        if (r.converged) root.insert("checks", checks_json(levels::check_state(p, r)));
        {
            toml::array w;
            for (const auto& s : r.warnings)
                w.push_back(s);
            root.insert("warnings", std::move(w));
        }
        {
            const auto& sp = r.solver.spec;
            toml::table sv;
            sv.insert("method", std::string(solvers::to_string(sp.method)));
            if (sp.method == solvers::Method::krylov) {
                sv.insert("krylov", std::string(solvers::to_string(sp.krylov)));
                sv.insert("pc", sp.pc.text());
                sv.insert("rel_tol", sp.rel_tol);
            }
            sv.insert("automatic", r.solver.automatic);
            sv.insert("numbering", std::string(levels::to_string(p.numbering)));
            sv.insert("reason", r.solver.reason);
            int fallbacks = 0;
            for (const auto& ls : r.level_steps)
                for (const auto& st : ls)
                    fallbacks += st.report.fallback_solves;
            sv.insert("fallback_solves", fallbacks);
            int continuations = 0;
            for (const auto& ls : r.level_steps)
                for (const auto& st : ls)
                    continuations += st.report.continuation_factor > 0;
            sv.insert("r_continuations", continuations);
            root.insert("solver", sv);
            if (r.multigrid) {
                const solvers::MultigridReport& m = *r.multigrid;
                toml::table mg;
                toml::array rows;
                for (const auto& ml : m.levels) {
                    toml::table row;
                    row.insert("level", ml.level);
                    row.insert("rows", static_cast<int64_t>(ml.rows));
                    row.insert("nonzeros", static_cast<int64_t>(ml.nonzeros));
                    row.insert("solve", ml.solve);
                    rows.push_back(std::move(row));
                }
                mg.insert("levels", std::move(rows));
                mg.insert("operator_complexity", m.operator_complexity);
                mg.insert("grid_complexity", m.grid_complexity);
                mg.insert("cycle", m.cycle);
                mg.insert("smoother", m.smoother);
                mg.insert("coarse_solver", m.coarse_solver);
                mg.insert("coarse_operators", m.coarse_operators);
                root.insert("multigrid", std::move(mg));
            }
            toml::table mt;
            mt.insert("estimate_bytes", r.memory.bytes);
            mt.insert("estimate_hierarchy_bytes", r.memory.hierarchy_bytes);
            mt.insert("estimate_solver_bytes", r.memory.solver_bytes);
            mt.insert("limit_bytes",
                      std::isfinite(r.memory_limit.bytes) ? r.memory_limit.bytes : -1.0);
            mt.insert("limit_source", r.memory_limit.source);
            mt.insert("peak_rss_bytes", peak_rss_bytes());
            root.insert("memory", mt);
        }
        toml::table tt;
        for (const auto& [name, e] : r.timings.table())
            tt.insert(name, e.seconds);
        root.insert("timings_seconds", tt);
        // What the timings ran on: our threads and the BLAS that schur's factorization calls.
        root.insert("threads", static_cast<int64_t>(parallel::num_threads()));
        root.insert("blas", parallel::blas_library());
        write_file_atomically(dir / "summary.json",
                              [&](std::ostream& f) { f << toml::json_formatter{root} << "\n"; });
    }
}

std::vector<std::string> write_outputs(const std::filesystem::path& dir, const levels::Problem& p,
                                       const levels::RunResult& r, const OutputOptions& options) {
    std::vector<std::string> written;
    write_result_files(dir, p, r, options, written);
    SummaryStatus st;
    st.stopped = r.stopped;
    if (r.stopped) st.stopped_at = r.failure;
    st.files = written;
    write_summary(dir, p, r, options, st);
    written.push_back("summary.json");
    return written;
}

StepFiles::StepFiles(OutputFolder& folder, const levels::Problem& p, bool every_level,
                     mesh::VtuFormat format)
    : folder_(&folder), dir_(folder.dir()), scene_(p.name), finest_(p.levels),
      every_level_(every_level), format_(format), series_(static_cast<size_t>(p.levels) + 1) {
    digits_ = std::max(4, static_cast<int>(std::to_string(p.load_steps).size()));
}

void StepFiles::operator()(const levels::LevelStepState& s) {
    if (s.level != finest_ && !every_level_) return;
    std::ostringstream step;
    step << std::setw(digits_) << std::setfill('0') << s.step;
    const std::string prefix =
        s.level == finest_ ? "solution" : "solution_level_" + std::to_string(s.level);
    const std::string name = prefix + "_step_" + step.str() + ".vtu";
    folder_->begin_writing(scene_);
    write_solution_vtu(dir_ / name, *s.L, *s.u_full, s.nodes(), format_);
    folder_->add(name);
    auto& series = series_[static_cast<size_t>(s.level)];
    series.emplace_back(s.s, name);
    mesh::write_pvd(dir_ / (prefix + ".pvd"), series);
    folder_->add(prefix + ".pvd");
}

int StepFiles::finest_steps() const {
    return static_cast<int>(series_[static_cast<size_t>(finest_)].size());
}

std::vector<std::string> StepFiles::collections() const {
    std::vector<std::string> out;
    for (size_t l = 0; l < series_.size(); ++l)
        if (!series_[l].empty())
            out.push_back(static_cast<int>(l) == finest_
                              ? std::string("solution.pvd")
                              : "solution_level_" + std::to_string(l) + ".pvd");
    return out;
}

} // namespace mlc::apps
