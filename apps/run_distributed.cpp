// SPDX-License-Identifier: MIT
// `mlcontact run` under mpirun with several processes (issue 12).
#include "apps/run_distributed.hpp"

#include "apps/output.hpp"
#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "core/memory.hpp"
#include "core/parallel.hpp"
#include "levels/checks.hpp"
#include "levels/distributed_solve.hpp"
#include "mesh/distributed.hpp"
#include "scene/scene.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <numeric>

namespace mlc::apps {

levels::LinearSolverSpec distributed_solver_spec(const RunOptions& opt) {
    MLC_CHECK(!opt.linear || *opt.linear == "krylov",
              "--linear " << *opt.linear
                          << " has no distributed form (it needs the whole level on one "
                             "process); on several processes the Newton systems are solved by "
                             "a Krylov method with mg (--linear krylov, the default there)");
    levels::LinearSolverSpec s;
    s.method = "krylov";
    s.krylov = opt.krylov.value_or("cgs");
    s.pc = opt.pc.value_or("mg");
    if (opt.linear_rel_tol) s.rel_tol = *opt.linear_rel_tol;
    s.validate();
    return s;
}

namespace {

/// Entries per contact node in the gathered node table.
constexpr int kNodeWidth = 8; // pair, x, y, ux, uy, lambda_t, lambda_n, status

struct NodeRow {
    int pair;
    double x, y, ux, uy, lt, ln;
    int status;
};

} // namespace

int run_scene_distributed(const RunOptions& opt, const Communicator& comm, std::ostream& out) {
    std::ostream null_stream(nullptr);
    const bool root = comm.rank() == 0;
    std::ostream& os = root ? out : null_stream;
    levels::Problem p = scene::load_scene(opt.scene);
    apply_overrides(p, opt);
    MLC_CHECK(opt.vtu == "binary" || opt.vtu == "ascii",
              "--vtu must be binary or ascii, found '" << opt.vtu << "'");
    MLC_CHECK(!opt.cold, "--cold is one process only: on several processes the levels are solved "
                         "coarse to fine");
    MLC_CHECK(!opt.every_step && !opt.every_level,
              "--every-step and --every-level are written by one process only so far (a "
              "distributed run writes solution.pvtu of the final state)");
    MLC_CHECK(p.levels >= 1, "a run on several processes needs --levels >= 1 (level 0 is solved "
                             "on every process; the levels above it are distributed)");
    const levels::LinearSolverSpec spec = distributed_solver_spec(opt);
    const int finest = p.levels;
    int plevel = opt.partition_level
                     ? *opt.partition_level
                     : levels::partition_level(p.mesh0.n_triangles(), finest, comm.size());
    MLC_CHECK(plevel >= 0 && plevel < finest,
              "--partition-level must lie in [0, " << finest - 1 << "] for --levels " << finest
                                                   << ", found " << plevel);
    // One thread per process: the processes are the parallelism (hybrid runs are not measured).
    parallel::set_num_threads(1);
    const mesh::VtuFormat vtu = opt.vtu == "ascii" ? mesh::VtuFormat::ascii : mesh::VtuFormat::binary;
    const std::filesystem::path dir = opt.out.empty() ? "out/" + p.name : opt.out;

    levels::SolveOptions so;
    so.predicted_sizes = levels::predict_level_sizes([&] {
        levels::Problem sp = p;
        sp.levels = plevel;
        return sp;
    }());
    so.coarse_to_fine = true;
    so.linear = spec;
    so.exact_fallback = !opt.no_fallback;
    so.r_continuation = !opt.no_continuation;
    so.progress = opt.quiet ? nullptr : &out;
    so.stop = opt.stop;
    os << "mlcontact: solving '" << p.name << "' on " << comm.size() << " processes\n";
    os << "Newton-system solver: " << spec << " (" << comm.size()
       << " processes: Krylov + distributed mg)\n";
    os << "partition level " << plevel
       << (opt.partition_level ? " (--partition-level)"
                               : " (the coarsest with " +
                                     std::to_string(levels::kTrianglesPerProcess) +
                                     " triangles per process, at most --levels - 1)")
       << ": levels 0-" << plevel << " on every process, " << plevel + 1 << "-" << finest
       << " distributed\n";
    levels::DistributedRunResult r = levels::solve_distributed(p, so, comm, plevel);

    // Per process: what it owns on the finest level.
    const auto& F = r.finest();
    std::vector<double> mine{static_cast<double>(F.n_owned),
                             static_cast<double>(F.local.n_contact_nodes()),
                             static_cast<double>(F.part.n_owned_vertices()),
                             static_cast<double>(F.local.mesh.n_vertices() - F.part.n_owned_vertices()),
                             static_cast<double>(F.local.mesh.n_triangles()),
                             r.distributed_seconds,
                             static_cast<double>(peak_rss_bytes())};
    const auto all = comm.allgather(std::span<const double>(mine));
    const size_t w = mine.size();
    os << "\nprocesses: " << comm.size() << "\n"
       << "  rank  owned unknowns  contact nodes  owned vertices  ghost vertices  local "
          "triangles  distributed s  peak RSS\n";
    for (int q = 0; q < comm.size(); ++q) {
        const double* a = all.data() + static_cast<size_t>(q) * w;
        os << "  " << std::setw(4) << q << std::setw(16) << static_cast<std::int64_t>(a[0])
           << std::setw(15) << static_cast<std::int64_t>(a[1]) << std::setw(16)
           << static_cast<std::int64_t>(a[2]) << std::setw(16) << static_cast<std::int64_t>(a[3])
           << std::setw(17) << static_cast<std::int64_t>(a[4]) << std::setw(15) << std::fixed
           << std::setprecision(2) << a[5] << std::defaultfloat << std::setprecision(6) << "  "
           << levels::format_bytes(a[6]) << "\n";
    }
    os << "finest level " << finest << ": " << F.n_global_dofs << " unknowns, "
       << F.n_global_contacts << " contact nodes\n";
    os << "\n level  step  Newton  Krylov  Krylov/Newton  agreement  statuses (gap/stick/slip)\n";
    for (size_t k = 1; k < r.level_steps.size(); ++k)
        for (const auto& ls : r.level_steps[k]) {
            const auto& c = ls.report.counts;
            os << std::setw(6) << ls.level << std::setw(6) << ls.report.step << std::setw(8)
               << ls.report.iterations << std::setw(8) << ls.report.linear_iterations
               << std::setw(15) << std::fixed << std::setprecision(1)
               << (ls.report.iterations > 0
                       ? static_cast<double>(ls.report.linear_iterations) / ls.report.iterations
                       : 0.0)
               << std::setw(11) << std::setprecision(3) << ls.agreement() << std::defaultfloat
               << std::setprecision(6) << "  " << c.gap << "/" << c.stick << "/"
               << c.slip_forward + c.slip_backward << "\n";
        }
    levels::StateChecks checks;
    std::vector<PairResultant> resultants(p.contacts.size());
    if (r.converged) {
        checks = levels::check_state(p, r, comm);
        std::vector<double> sums;
        for (size_t k = 0; k < p.contacts.size(); ++k) {
            int closed = 0;
            const Vec2 f = levels::contact_resultant(F.local, r.nodes, static_cast<int>(k), &closed);
            sums.insert(sums.end(), {f.x(), f.y(), static_cast<double>(closed)});
        }
        comm.allreduce(std::span<double>(sums), ReduceOp::sum);
        for (size_t k = 0; k < p.contacts.size(); ++k)
            resultants[k] = {Vec2(sums[3 * k], sums[3 * k + 1]),
                             static_cast<int>(std::lround(sums[3 * k + 2]))};
        print_checks(os, p, checks, resultants);
    }
    os << "\ntimings of process 0 (the distributed levels):\n";
    if (root) r.timings.print(os);
    os << "\ntime: " << std::fixed << std::setprecision(2) << r.seconds << " s"
       << std::defaultfloat << std::setprecision(6) << "\n";
    if (!r.converged) {
        os << "\nerror: " << r.failure << "\n";
        return 2;
    }

    // Files: solution.pvtu and its pieces, contact.csv and summary.json.
    if (root) std::filesystem::create_directories(dir);
    comm.barrier();
    {
        // The contact values of ghost vertices from their owners, so that every piece shows them.
        const levels::Level& L = F.local;
        const int nv = L.mesh.n_vertices();
        auto fields = solution_fields(L, r.u_full, r.nodes);
        std::vector<double> rec(static_cast<size_t>(nv) * 5);
        for (int v = 0; v < nv; ++v) {
            rec[static_cast<size_t>(v) * 5] = fields.point[1].values[static_cast<size_t>(v)];
            for (int j = 0; j < 2; ++j)
                rec[static_cast<size_t>(v) * 5 + 1 + static_cast<size_t>(j)] =
                    fields.point[2].values[2 * static_cast<size_t>(v) + static_cast<size_t>(j)];
            rec[static_cast<size_t>(v) * 5 + 3] = fields.point[3].values[static_cast<size_t>(v)];
            rec[static_cast<size_t>(v) * 5 + 4] = fields.point[4].values[static_cast<size_t>(v)];
        }
        F.ghosts.vertex_records(rec, 5);
        for (int v = 0; v < nv; ++v) {
            fields.point[1].values[static_cast<size_t>(v)] = rec[static_cast<size_t>(v) * 5];
            for (int j = 0; j < 2; ++j)
                fields.point[2].values[2 * static_cast<size_t>(v) + static_cast<size_t>(j)] =
                    rec[static_cast<size_t>(v) * 5 + 1 + static_cast<size_t>(j)];
            fields.point[3].values[static_cast<size_t>(v)] = rec[static_cast<size_t>(v) * 5 + 3];
            fields.point[4].values[static_cast<size_t>(v)] = rec[static_cast<size_t>(v) * 5 + 4];
        }
        mesh::LocalLevel part = F.part;
        part.mesh = L.mesh;
        mesh::write_distributed_vtu(dir / "solution.pvtu", part, fields.point, fields.cell, comm,
                                    vtu);
    }
    std::vector<double> nodes;
    for (const auto& n : r.nodes) {
        const int e = F.local.contact_of_vertex[static_cast<size_t>(n.vertex)];
        nodes.insert(nodes.end(), {static_cast<double>(F.local.contacts[static_cast<size_t>(e)].pair),
                                   n.x.x(), n.x.y(), n.u.x(), n.u.y(), n.lambda_t, n.lambda_n,
                                   static_cast<double>(static_cast<int>(n.status))});
    }
    const auto gathered = comm.gather(std::span<const double>(nodes), 0);
    std::vector<std::string> files{"solution.pvtu", "solution_<rank>.vtu (" +
                                                        std::to_string(comm.size()) + " pieces)"};
    if (root) {
        std::vector<NodeRow> rows;
        for (size_t i = 0; i + kNodeWidth <= gathered.size(); i += kNodeWidth) {
            const double* a = gathered.data() + i;
            rows.push_back({static_cast<int>(a[0]), a[1], a[2], a[3], a[4], a[5], a[6],
                            static_cast<int>(a[7])});
        }
        std::sort(rows.begin(), rows.end(), [](const NodeRow& a, const NodeRow& b) {
            return std::tie(a.pair, a.x, a.y) < std::tie(b.pair, b.x, b.y);
        });
        write_file_atomically(dir / "contact.csv", [&](std::ostream& f) {
            f << "x,y,ux,uy,lambda_t,lambda_n,status\n" << std::setprecision(17);
            for (const auto& n : rows)
                f << n.x << "," << n.y << "," << n.ux << "," << n.uy << "," << n.lt << "," << n.ln
                  << "," << contact::to_string(static_cast<contact::Status>(n.status)) << "\n";
        });
        files.push_back("contact.csv");
        toml::table root_t;
        root_t.insert("scene", p.name);
        root_t.insert("units", p.units);
        root_t.insert("level", static_cast<int64_t>(finest));
        root_t.insert("unknowns", static_cast<int64_t>(F.n_global_dofs));
        root_t.insert("contact_nodes", static_cast<int64_t>(F.n_global_contacts));
        root_t.insert("converged", r.converged);
        root_t.insert("load_steps", static_cast<int64_t>(p.load_steps));
        root_t.insert("completed_steps", static_cast<int64_t>(r.completed_steps));
        root_t.insert("vtu_format", mesh::to_string(vtu));
        root_t.insert("processes", static_cast<int64_t>(comm.size()));
        root_t.insert("partition_level", static_cast<int64_t>(plevel));
        root_t.insert("seconds", r.seconds);
        toml::array procs;
        for (int q = 0; q < comm.size(); ++q) {
            const double* a = all.data() + static_cast<size_t>(q) * w;
            toml::table t;
            t.insert("rank", static_cast<int64_t>(q));
            t.insert("owned_unknowns", static_cast<int64_t>(a[0]));
            t.insert("contact_nodes", static_cast<int64_t>(a[1]));
            t.insert("owned_vertices", static_cast<int64_t>(a[2]));
            t.insert("ghost_vertices", static_cast<int64_t>(a[3]));
            t.insert("local_triangles", static_cast<int64_t>(a[4]));
            t.insert("distributed_seconds", a[5]);
            t.insert("peak_rss_bytes", a[6]);
            procs.push_back(std::move(t));
        }
        root_t.insert("per_process", std::move(procs));
        toml::array steps;
        int total_newton = 0;
        for (const auto& s : r.steps) {
            toml::table t;
            t.insert("step", static_cast<int64_t>(s.step));
            t.insert("load_factor", s.load_factor);
            t.insert("converged", s.converged);
            t.insert("newton_iterations", static_cast<int64_t>(s.iterations));
            t.insert("linear_iterations", static_cast<int64_t>(s.linear_iterations));
            toml::array res;
            for (double v : s.residuals)
                res.push_back(v);
            t.insert("residuals", res);
            toml::table st;
            st.insert("gap", static_cast<int64_t>(s.counts.gap));
            st.insert("stick", static_cast<int64_t>(s.counts.stick));
            st.insert("slip_forward", static_cast<int64_t>(s.counts.slip_forward));
            st.insert("slip_backward", static_cast<int64_t>(s.counts.slip_backward));
            t.insert("statuses", st);
            t.insert("seconds", s.seconds);
            steps.push_back(t);
            total_newton += s.iterations;
        }
        root_t.insert("steps", steps);
        root_t.insert("total_newton_iterations", static_cast<int64_t>(total_newton));
        toml::array lv;
        for (size_t k = 1; k < r.level_steps.size(); ++k) {
            toml::table t;
            t.insert("level", static_cast<int64_t>(plevel + static_cast<int>(k)));
            t.insert("unknowns", static_cast<int64_t>(r.levels[k].n_global_dofs));
            t.insert("contact_nodes", static_cast<int64_t>(r.levels[k].n_global_contacts));
            toml::array ls;
            for (const auto& st : r.level_steps[k]) {
                toml::table u;
                u.insert("step", static_cast<int64_t>(st.report.step));
                u.insert("newton_iterations", static_cast<int64_t>(st.report.iterations));
                u.insert("linear_iterations", static_cast<int64_t>(st.report.linear_iterations));
                u.insert("predicted_status_agreement", st.agreement());
                u.insert("seconds", st.report.seconds);
                ls.push_back(u);
            }
            t.insert("steps", ls);
            lv.push_back(t);
        }
        root_t.insert("levels", lv);
        toml::array cs;
        for (size_t k = 0; k < p.contacts.size(); ++k) {
            toml::table c;
            c.insert("name", p.contacts[k].name);
            c.insert("resultant", toml::array{resultants[k].force.x(), resultants[k].force.y()});
            c.insert("nodes_in_contact", static_cast<int64_t>(resultants[k].in_contact));
            cs.push_back(c);
        }
        root_t.insert("contacts", cs);
        toml::table ct;
        ct.insert("force_balance", checks.force_balance);
        ct.insert("coulomb_excess", checks.coulomb_excess);
        ct.insert("slip_equality", checks.slip_equality);
        ct.insert("complementarity", checks.complementarity);
        ct.insert("penetration", checks.penetration);
        root_t.insert("checks", ct);
        toml::table sv;
        sv.insert("method", spec.method);
        sv.insert("krylov", spec.krylov);
        sv.insert("pc", spec.pc);
        sv.insert("rel_tol", spec.rel_tol);
        sv.insert("distributed", true);
        root_t.insert("solver", sv);
        write_file_atomically(dir / "summary.json",
                              [&](std::ostream& f) { f << toml::json_formatter{root_t} << "\n"; });
        files.push_back("summary.json");
    }
    comm.barrier();
    os << "\nwrote";
    for (size_t i = 0; i < files.size(); ++i)
        os << (i ? ", " : " ") << (dir / files[i]).string();
    os << "\n";
    return 0;
}

} // namespace mlc::apps
