// SPDX-License-Identifier: MIT
// `mlcontact run` on a 3D scene on several processes: options, report and files.
#include "run/run_distributed.hpp"

#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "core/parallel.hpp"
#include "levels/distributed_solve3.hpp"
#include "levels/resources.hpp"
#include "run/interrupt.hpp"
#include "run/run3_detail.hpp"
#include "scene/scene3.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <span>

namespace mlc::apps {

namespace {

using namespace detail3;
using levels::ContactNodeState3;
using levels::DistributedRunResult3;
using levels::ElasticProblem3;
using mesh::Vec3;

/// The level a 3D run is partitioned on by default: the coarsest with at least this many
/// tetrahedra per process, at most --levels - 1.
constexpr std::int64_t kTetrahedraPerProcess = 2000;

int partition_level3(std::int64_t level0_tets, int finest, int n_processes) {
    int p = 0;
    for (std::int64_t t = level0_tets; p < finest - 1 && t < kTetrahedraPerProcess * n_processes;
         t *= 8)
        ++p;
    return p;
}

/// One contact node as it travels to process 0: pair, global vertex, area, then the state.
constexpr size_t kNodeRecord = 3 + 3 + 3 + 2 + 1 + 1 + 2 + 2 + 1 + 3 + 6;

void pack_node(const ContactNodeState3& n, int pair, double global_vertex, double area,
               std::vector<double>& out) {
    out.insert(out.end(), {static_cast<double>(pair),
                           global_vertex,
                           area,
                           n.x.x(),
                           n.x.y(),
                           n.x.z(),
                           n.u.x(),
                           n.u.y(),
                           n.u.z(),
                           n.lambda_t[0],
                           n.lambda_t[1],
                           n.lambda_n,
                           n.d_n,
                           n.d_t[0],
                           n.d_t[1],
                           n.slip_direction[0],
                           n.slip_direction[1],
                           static_cast<double>(levels::status_code3(n.status)),
                           n.n.x(),
                           n.n.y(),
                           n.n.z(),
                           n.t(0, 0),
                           n.t(1, 0),
                           n.t(2, 0),
                           n.t(0, 1),
                           n.t(1, 1),
                           n.t(2, 1)});
}

struct GatheredNode {
    int pair = 0;
    double area = 0.0;
    ContactNodeState3 n;
};

/// The contact nodes of every process (process 0; empty elsewhere), in the order of their pair
/// and global vertex number.
std::vector<GatheredNode> gather_nodes(const std::vector<ContactNodeState3>& nodes,
                                       const levels::DistributedLevel3& F,
                                       const std::vector<double>& areas, const Communicator& comm) {
    std::vector<double> rec;
    for (size_t e = 0; e < nodes.size(); ++e)
        pack_node(nodes[e], F.local.contacts[e].pair,
                  static_cast<double>(F.part.global_vertex[static_cast<size_t>(nodes[e].vertex)]),
                  areas[e], rec);
    const std::vector<double> all = comm.gather(std::span<const double>(rec), 0);
    std::vector<GatheredNode> out;
    for (size_t i = 0; i + kNodeRecord <= all.size(); i += kNodeRecord) {
        const double* r = all.data() + i;
        GatheredNode g;
        g.pair = static_cast<int>(r[0]);
        g.n.vertex = static_cast<int>(r[1]);
        g.area = r[2];
        g.n.x = Vec3(r[3], r[4], r[5]);
        g.n.u = Vec3(r[6], r[7], r[8]);
        g.n.lambda_t = Eigen::Vector2d(r[9], r[10]);
        g.n.lambda_n = r[11];
        g.n.d_n = r[12];
        g.n.d_t = Eigen::Vector2d(r[13], r[14]);
        g.n.slip_direction = Eigen::Vector2d(r[15], r[16]);
        const int code = static_cast<int>(r[17]);
        g.n.status = code == 0   ? contact::Status::gap
                     : code == 1 ? contact::Status::stick
                                 : contact::Status::slip;
        g.n.n = Vec3(r[18], r[19], r[20]);
        g.n.t << r[21], r[24], r[22], r[25], r[23], r[26];
        out.push_back(g);
    }
    std::sort(out.begin(), out.end(), [](const GatheredNode& a, const GatheredNode& b) {
        return std::pair(a.pair, a.n.vertex) < std::pair(b.pair, b.n.vertex);
    });
    return out;
}

/// solution.pvtu and this process's piece: displacement, contact_status, contact_force and
/// pressure, the ghost vertices' values from their owners.
void write_solution_pvtu3(const std::filesystem::path& file, const levels::DistributedLevel3& F,
                          const DistributedRunResult3& r, const std::vector<double>& areas,
                          const Communicator& comm) {
    const auto nv = static_cast<size_t>(F.local.mesh.n_vertices());
    constexpr int w = 8; // displacement 3, status, force 3, pressure
    std::vector<double> rec(w * nv, 0.0);
    for (size_t v = 0; v < nv; ++v) {
        for (int c = 0; c < 3; ++c)
            rec[w * v + static_cast<size_t>(c)] = r.u_full[3 * static_cast<Index>(v) + c];
        rec[w * v + 3] = -1.0;
    }
    for (size_t e = 0; e < r.nodes.size(); ++e) {
        const auto& n = r.nodes[e];
        const auto v = static_cast<size_t>(n.vertex);
        rec[w * v + 3] = levels::status_code3(n.status);
        const Vec3 lg = global_lambda(n);
        for (int c = 0; c < 3; ++c)
            rec[w * v + 4 + static_cast<size_t>(c)] = -lg[c] + 0.0;
        rec[w * v + 7] = areas[e] > 0 ? -n.lambda_n / areas[e] + 0.0 : 0.0;
    }
    F.ghosts.vertex_records(rec, w);
    mesh::Field disp{"displacement", 3, std::vector<double>(3 * nv)};
    mesh::Field status{"contact_status", 1, std::vector<double>(nv)};
    mesh::Field force{"contact_force", 3, std::vector<double>(3 * nv)};
    mesh::Field pressure{"pressure", 1, std::vector<double>(nv)};
    for (size_t v = 0; v < nv; ++v) {
        for (size_t c = 0; c < 3; ++c) {
            disp.values[3 * v + c] = rec[w * v + c];
            force.values[3 * v + c] = rec[w * v + 4 + c];
        }
        status.values[v] = rec[w * v + 3];
        pressure.values[v] = rec[w * v + 7];
    }
    mesh::LocalTetLevel part = F.part;
    part.mesh = F.local.mesh;
    mesh::write_distributed_vtu(file, part, {disp, status, force, pressure}, {}, comm);
}

void write_iterations(const std::filesystem::path& file, const DistributedRunResult3& r) {
    write_file_atomically(file, [&](std::ostream& f) {
        f << "level,unknowns,distributed,step,newton,krylov\n";
        auto rows = [&](const std::vector<levels::LevelStep3>& steps, int level,
                        std::int64_t unknowns, int distributed) {
            for (const auto& st : steps)
                for (size_t i = 0; i < st.report.linear_iterations_per_newton.size(); ++i)
                    f << level << "," << unknowns << "," << distributed << "," << st.report.step
                      << "," << i + 1 << "," << st.report.linear_iterations_per_newton[i] << "\n";
        };
        for (size_t l = 0; l < r.serial.level_steps.size(); ++l)
            rows(r.serial.level_steps[l], static_cast<int>(l),
                 r.serial.hierarchy.levels[l].n_unknowns(), 0);
        for (size_t k = 1; k < r.level_steps.size(); ++k)
            rows(r.level_steps[k], r.partition_level + static_cast<int>(k),
                 r.parts.levels[k].n_global_dofs, 1);
    });
}

void print_steps(std::ostream& os, const DistributedRunResult3& r) {
    os << "\n step   load  newton  residual    gap  stick   slip  krylov(max)\n";
    for (const auto& s : r.steps) {
        const int kmax = s.linear_iterations_per_newton.empty()
                             ? 0
                             : *std::max_element(s.linear_iterations_per_newton.begin(),
                                                 s.linear_iterations_per_newton.end());
        os << std::setw(5) << s.step << std::setw(7) << std::fixed << std::setprecision(3)
           << s.load_factor << std::setw(8) << s.iterations << std::setw(10) << std::scientific
           << std::setprecision(2) << (s.residuals.empty() ? 0.0 : s.residuals.back())
           << std::setw(7) << s.counts.gap << std::setw(7) << s.counts.stick << std::setw(7)
           << s.counts.slip + s.counts.slip_forward + s.counts.slip_backward << std::setw(8) << kmax
           << "\n";
        os.unsetf(std::ios::floatfield);
        os << std::setprecision(6);
    }
}

/// The solve's options: the secant predictor, the Krylov solve of the distributed levels (mg, or
/// --pc on each process's block), its tolerance, and level 0's exact solver by the plan of levels
/// 0..p (they run whole on every process).
levels::SolveOptions3 distributed_solve_options3(const RunOptions& opt, const ElasticProblem3& p,
                                                 int plevel) {
    levels::SolveOptions3 so;
    so.extrapolate = !opt.no_extrapolation;
    so.upper = levels::Method3::mg;
    if (const auto spec = krylov_spec3(opt, true)) {
        so.upper = levels::Method3::krylov;
        so.krylov = *spec;
    }
    if (opt.linear_rel_tol) so.krylov_rel_tol = *opt.linear_rel_tol;
    so.level0 = levels::plan_contact3(levels::predict_elastic3_sizes(p, plevel), std::nullopt,
                                      levels::process_memory_limit())
                    .level0;
    return so;
}

} // namespace

int run_scene3_distributed(const RunOptions& opt, const Communicator& comm, std::ostream& out) {
    std::ostream null_stream(nullptr);
    const bool root = comm.rank() == 0;
    std::ostream& os = root ? out : null_stream;
    refuse_2d_options(opt, true);
    ElasticProblem3 p = scene::load_scene3(opt.scene);
    apply_overrides3(p, opt);
    MLC_CHECK(!p.contacts.empty(),
              "scene '" << p.name << "' has no contact: a 3D scene without contact runs with "
                        << "`mlcontact bench elastic " << opt.scene << "`");
    MLC_CHECK(opt.vtu == "binary", "--vtu ascii is 2D-only: 3D runs write binary VTU");
    MLC_CHECK(!opt.cold, "--cold is one process only: on several processes the levels are solved "
                         "coarse to fine");
    MLC_CHECK(!opt.linear || *opt.linear == "krylov",
              "--linear " << *opt.linear
                          << " needs a whole level on one process: on several "
                             "processes the levels above the partition level are "
                             "solved by GMRES with the distributed multigrid");
    MLC_CHECK(p.levels >= 1, "a run on several processes needs --levels >= 1 (level 0 is solved "
                             "on every process; the levels above it are distributed)");
    const int finest = p.levels;
    const int plevel = opt.partition_level
                           ? *opt.partition_level
                           : partition_level3(p.mesh0.n_cells(), finest, comm.size());
    MLC_CHECK(plevel >= 0 && plevel < finest, "--partition-level must lie in [0, "
                                                  << finest - 1 << "] for --levels " << finest
                                                  << ", found " << plevel);
    // One thread per process: the processes are the parallelism.
    parallel::set_num_threads(1);
    levels::SolveOptions3 so = distributed_solve_options3(opt, p, plevel);
    const std::filesystem::path dir = opt.out.empty() ? "out/" + p.name : opt.out;
    std::optional<OutputFolder> folder;
    open_output_folder(folder, dir, p.name, comm, os);
    if (!opt.quiet) so.progress = progress_lines(os);
    os << "mlcontact: solving '" << p.name << "' (3D) on " << comm.size() << " processes\n";
    os << "partition level " << plevel
       << (opt.partition_level ? " (--partition-level)"
                               : " (the coarsest with " + std::to_string(kTetrahedraPerProcess) +
                                     " tetrahedra per process, at most --levels - 1)")
       << ": levels 0-" << plevel << " on every process (level 0 " << levels::to_string(so.level0)
       << "), " << plevel + 1 << "-" << finest << " distributed\n";
    const DistributedRunResult3 r = levels::solve_distributed3(p, so, comm, plevel);
    const auto& F = r.finest();
    os << "Newton-system solver above level " << plevel << ": " << r.solver << "\n";
    os << "\nlevel " << finest << ": " << F.n_global_dofs << " unknowns, " << F.n_global_contacts
       << " contact nodes\n";
    print_steps(os, r);
    if (!r.converged) {
        os << "\nerror: " << r.failure << "\n";
        return 2;
    }
    // Contact areas of the owned nodes (their faces are all local), resultants summed.
    const std::vector<double> areas = levels::contact_areas(p, F.local);
    std::vector<double> sums(4 * p.contacts.size(), 0.0);
    for (size_t e = 0; e < r.nodes.size(); ++e) {
        const auto k = static_cast<size_t>(F.local.contacts[e].pair);
        const Vec3 lg = global_lambda(r.nodes[e]);
        for (size_t c = 0; c < 3; ++c)
            sums[4 * k + c] -= lg[static_cast<Index>(c)];
        sums[4 * k + 3] += r.nodes[e].status != contact::Status::gap;
    }
    comm.allreduce(std::span<double>(sums), ReduceOp::sum);
    for (size_t c = 0; c < p.contacts.size(); ++c)
        os << "contact '" << p.contacts[c].name << "': resultant on the contactor (" << sums[4 * c]
           << ", " << sums[4 * c + 1] << ", " << sums[4 * c + 2] << "), "
           << std::lround(sums[4 * c + 3]) << " nodes in contact\n";
    int bad = 0;
    try {
        for (const auto& nodes : r.step_nodes)
            check_nodes(nodes);
        for (Index i = 0; i < r.u_full.size(); ++i)
            require_finite3(r.u_full[i], "displacement");
    } catch (const SolverBreakdown&) {
        bad = 1;
    }
    if (comm.max(bad) > 0)
        throw SolverBreakdown("refusing to write non-finite values: the solve produced NaN/Inf");
    os << "\ntimings of process 0:\n";
    if (root) r.timings.print(os);
    os << "\ntime: " << std::fixed << std::setprecision(2) << r.seconds << " s" << std::defaultfloat
       << std::setprecision(6) << "\n";

    if (root) folder->begin_writing(p.name);
    comm.barrier();
    write_solution_pvtu3(dir / "solution.pvtu", F, r, areas, comm);
    std::vector<std::vector<GatheredNode>> steps;
    for (const auto& nodes : r.step_nodes)
        steps.push_back(gather_nodes(nodes, F, areas, comm));
    std::vector<std::string> files{"solution.pvtu", "solution_<rank>.vtu (" +
                                                        std::to_string(comm.size()) + " pieces)"};
    if (root) {
        auto name = [&](int pair) { return p.contacts[static_cast<size_t>(pair)].name; };
        write_file_atomically(dir / "contact.csv", [&](std::ostream& f) {
            f << kNodeColumns << "\n" << std::setprecision(17);
            if (!steps.empty())
                for (const auto& g : steps.back())
                    write_node(f, name(g.pair), g.n, g.area);
        });
        write_file_atomically(dir / "contact_steps.csv", [&](std::ostream& f) {
            f << "step,s," << kNodeColumns << "\n" << std::setprecision(17);
            for (size_t k = 0; k < steps.size(); ++k)
                for (const auto& g : steps[k]) {
                    f << k + 1 << "," << static_cast<double>(k + 1) / p.load_steps << ",";
                    write_node(f, name(g.pair), g.n, g.area);
                }
        });
        write_iterations(dir / "iterations.csv", r);
        files.insert(files.end(), {"contact.csv", "contact_steps.csv", "iterations.csv"});
        toml::table t;
        t.insert("complete", true);
        t.insert("scene", p.name);
        t.insert("dimension", 3);
        t.insert("processes", static_cast<int64_t>(comm.size()));
        t.insert("partition_level", static_cast<int64_t>(plevel));
        t.insert("converged", r.converged);
        t.insert("levels", static_cast<int64_t>(p.levels));
        t.insert("load_steps", static_cast<int64_t>(p.load_steps));
        t.insert("completed_steps", static_cast<int64_t>(r.completed_steps));
        t.insert("solver_level0", std::string(levels::to_string(so.level0)));
        t.insert("solver_upper", r.solver);
        t.insert("unknowns", static_cast<int64_t>(F.n_global_dofs));
        t.insert("contact_nodes", static_cast<int64_t>(F.n_global_contacts));
        toml::array contacts;
        for (size_t c = 0; c < p.contacts.size(); ++c) {
            toml::table ct;
            ct.insert("name", p.contacts[c].name);
            ct.insert("resultant", toml::array{sums[4 * c], sums[4 * c + 1], sums[4 * c + 2]});
            ct.insert("in_contact", static_cast<int64_t>(std::lround(sums[4 * c + 3])));
            contacts.push_back(std::move(ct));
        }
        t.insert("contacts", std::move(contacts));
        toml::array fl;
        for (const auto& f : files)
            fl.push_back(f);
        fl.push_back("summary.json");
        t.insert("files", std::move(fl));
        t.insert("stopped", false);
        write_summary_last(dir, t, files);
    }
    print_written(os, comm, dir, files);
    return 0;
}

} // namespace mlc::apps
