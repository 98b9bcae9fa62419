// SPDX-License-Identifier: MIT
// `mlcontact run` under mpirun with several processes.
#include "run/run_distributed.hpp"

#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "core/memory.hpp"
#include "core/parallel.hpp"
#include "levels/checks.hpp"
#include "levels/diagnoses.hpp"
#include "levels/distributed_solve.hpp"
#include "levels/resources.hpp"
#include "mesh/distributed.hpp"
#include "run/interrupt.hpp"
#include "run/output.hpp"
#include "run/summary_json.hpp"
#include "scene/scene.hpp"
#include "scene/scene3.hpp"
#include "solvers/factory.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <csignal>
#include <iomanip>
#include <map>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>
#include <tuple>

namespace mlc::apps {

namespace {

/// The contact boundary of a distributed run's finest level, gathered on rank 0 (empty
/// elsewhere): a Level holding only the contact nodes (sorted by pair, then as on one process
/// where the vertex is born on level p or below, then by x and y) and the
/// boundary edges carrying a contactor tag, which is what contact_geometry reads, and the node
/// states of every completed step in the same order.
struct ContactBoundary {
    levels::Level level;
    std::vector<std::vector<levels::ContactNodeState>> step_nodes;
};

// pair, birth, index, x, y, ux, uy, lambda_t, lambda_n, d_n, d_t, status
constexpr size_t kNodeWidth = 12;
constexpr size_t kEdgeWidth = 5; // tag, x0, y0, x1, y1

ContactBoundary gather_contact_boundary(const levels::Problem& p,
                                        const levels::DistributedRunResult& r,
                                        const Communicator& comm) {
    const auto& F = r.finest();
    const auto& mesh = F.local.mesh;
    std::set<int> tags;
    for (const auto& c : p.contacts)
        if (const auto t = mesh.find_tag(c.contactor)) tags.insert(*t);
    std::vector<double> edges;
    for (const auto& be : mesh.boundary)
        if (tags.count(be.tag) && F.part.vertex_owner[static_cast<size_t>(be.v0)] == comm.rank()) {
            const Vec2& a = mesh.vertices[static_cast<size_t>(be.v0)];
            const Vec2& b = mesh.vertices[static_cast<size_t>(be.v1)];
            edges.insert(edges.end(), {static_cast<double>(be.tag), a.x(), a.y(), b.x(), b.y()});
        }
    // The one-process order of the contact nodes (what contact_geometry walks the pieces of the
    // contact boundary in): by pair, then by vertex index, which refinement keeps, so a vertex
    // born on a coarser level comes first. Born on level p or below: its level-p index is its
    // one-process index; born above p: after those, by coordinates (the one-process index
    // among the vertices born on one level needs the whole level).
    auto birth = [&](int v) {
        for (size_t k = 0; k < r.levels.size(); ++k)
            if (v < r.levels[k].local.mesh.n_vertices()) return static_cast<double>(k);
        return static_cast<double>(r.levels.size());
    };
    std::vector<double> nodes;
    for (const auto& step : r.step_nodes)
        for (const auto& n : step) {
            const int e = F.local.contact_of_vertex[static_cast<size_t>(n.vertex)];
            const double b = birth(n.vertex);
            const double index =
                b == 0 ? F.part.vertex_location[static_cast<size_t>(n.vertex)].id : 0.0;
            nodes.insert(nodes.end(),
                         {static_cast<double>(F.local.contacts[static_cast<size_t>(e)].pair), b,
                          index, n.x.x(), n.x.y(), n.u.x(), n.u.y(), n.lambda_t, n.lambda_n, n.d_n,
                          n.d_t, static_cast<double>(static_cast<int>(n.status))});
        }
    const auto all_edges = comm.gather(std::span<const double>(edges), 0);
    // Every process holds the same number of steps; its nodes per step are contiguous.
    const std::int64_t mine = static_cast<std::int64_t>(r.nodes.size());
    const auto counts = comm.allgather(std::span<const std::int64_t>(&mine, 1));
    const auto all_nodes = comm.gather(std::span<const double>(nodes), 0);
    ContactBoundary cb;
    if (comm.rank() != 0) return cb;
    levels::Level& L = cb.level;
    L.mesh.tag_names = mesh.tag_names;
    std::map<std::pair<double, double>, int> vertex_at;
    auto vertex = [&](double x, double y) {
        const auto [it, added] = vertex_at.emplace(std::pair{x, y}, L.mesh.n_vertices());
        if (added) L.mesh.vertices.emplace_back(x, y);
        return it->second;
    };
    for (size_t i = 0; i + kEdgeWidth <= all_edges.size(); i += kEdgeWidth) {
        mesh::BoundaryEdge be;
        be.tag = static_cast<int>(all_edges[i]);
        be.v0 = vertex(all_edges[i + 1], all_edges[i + 2]);
        be.v1 = vertex(all_edges[i + 3], all_edges[i + 4]);
        L.mesh.boundary.push_back(be);
    }
    // Per process: steps x its nodes, in rank order; regroup by step.
    const size_t n_steps = r.step_nodes.size();
    std::vector<std::vector<const double*>> rows(n_steps);
    size_t at = 0;
    for (const std::int64_t c : counts)
        for (size_t k = 0; k < n_steps; ++k)
            for (std::int64_t j = 0; j < c; ++j, at += kNodeWidth)
                rows[k].push_back(all_nodes.data() + at);
    for (auto& step : rows)
        std::sort(step.begin(), step.end(), [](const double* a, const double* b) {
            return std::tie(a[0], a[1], a[2], a[3], a[4]) < std::tie(b[0], b[1], b[2], b[3], b[4]);
        });
    if (!rows.empty())
        for (const double* a : rows.front()) {
            contact::ContactElement e;
            e.pair = static_cast<int>(a[0]);
            e.vertex[0] = vertex(a[3], a[4]);
            L.contacts.push_back(e);
        }
    L.contact_of_vertex.assign(static_cast<size_t>(L.mesh.n_vertices()), -1);
    for (size_t e = 0; e < L.contacts.size(); ++e)
        L.contact_of_vertex[static_cast<size_t>(L.contacts[e].vertex[0])] = static_cast<int>(e);
    for (const auto& step : rows) {
        std::vector<levels::ContactNodeState> out;
        for (const double* a : step) {
            levels::ContactNodeState n;
            n.vertex = vertex(a[3], a[4]);
            n.x = Vec2(a[3], a[4]);
            n.u = Vec2(a[5], a[6]);
            n.lambda_t = a[7];
            n.lambda_n = a[8];
            n.d_n = a[9];
            n.d_t = a[10];
            n.status = static_cast<contact::Status>(static_cast<int>(a[11]));
            out.push_back(n);
        }
        cb.step_nodes.push_back(std::move(out));
    }
    return cb;
}

/// This process's contact elements with a target vertex owned by another process.
std::int64_t cut_elements(const levels::DistributedLevel& F) {
    std::int64_t n = 0;
    for (const auto& e : F.local.contacts) {
        bool cut = false;
        for (int j = 1; j < e.n_nodes(); ++j)
            cut =
                cut || F.part.vertex_owner[static_cast<size_t>(e.vertex[static_cast<size_t>(j)])] !=
                           F.part.vertex_owner[static_cast<size_t>(e.vertex[0])];
        n += cut;
    }
    return n;
}

/// What every process owns on the finest level, summed (totals: triangles, displacement
/// unknowns, vertices) and per process (all: `w` values per rank).
struct ProcessFigures {
    std::array<std::int64_t, 3> totals{};
    std::vector<double> all;
    size_t w = 0;
};

/// Gathers the figures of every process and prints their table.
ProcessFigures process_figures(std::ostream& os, const levels::DistributedRunResult& r,
                               const Communicator& comm, int finest) {
    const auto& F = r.finest();
    ProcessFigures pf;
    std::int64_t owned_triangles = 0, owned_displacements = 0;
    for (const char o : F.part.triangle_owned)
        owned_triangles += o != 0;
    for (Index i = 0; i < F.n_owned; ++i)
        owned_displacements += F.local.dofs.is_displacement(i);
    pf.totals = {owned_triangles, owned_displacements, F.part.n_owned_vertices()};
    comm.allreduce(std::span<std::int64_t>(pf.totals), ReduceOp::sum);
    std::vector<double> mine{
        static_cast<double>(F.n_owned),
        static_cast<double>(F.local.n_contact_nodes()),
        static_cast<double>(F.part.n_owned_vertices()),
        static_cast<double>(F.local.mesh.n_vertices() - F.part.n_owned_vertices()),
        static_cast<double>(F.local.mesh.n_cells()),
        r.distributed_seconds,
        static_cast<double>(peak_rss_bytes()),
        static_cast<double>(cut_elements(F)),
        static_cast<double>(F.local.ghost_contacts.size())};
    pf.all = comm.allgather(std::span<const double>(mine));
    pf.w = mine.size();
    const auto& all = pf.all;
    const size_t w = pf.w;
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
    return pf;
}

/// The contact interface across the cuts: elements whose contactor and targets are owned by
/// different processes (their Jacobian rows couple the processes).
void print_contact_interface(std::ostream& os, const Communicator& comm,
                             const levels::DistributedLevel& F, const ProcessFigures& pf) {
    const auto& all = pf.all;
    const size_t w = pf.w;
    os << "contact interface on the finest level (two-body elements):\n"
       << "  rank  contact nodes  with targets owned elsewhere  other processes' elements "
          "reaching owned vertices\n";
    std::int64_t cut = 0;
    for (int q = 0; q < comm.size(); ++q) {
        const double* a = all.data() + static_cast<size_t>(q) * w;
        cut += static_cast<std::int64_t>(a[7]);
        os << "  " << std::setw(4) << q << std::setw(15) << static_cast<std::int64_t>(a[1])
           << std::setw(30) << static_cast<std::int64_t>(a[7]) << std::setw(43)
           << static_cast<std::int64_t>(a[8]) << "\n";
    }
    os << "  the partition " << (cut > 0 ? "cuts" : "does not cut") << " the interface (" << cut
       << " of " << F.n_global_contacts << " contact elements)\n";
}

/// Newton and Krylov iterations and statuses per distributed level and load step.
void print_level_steps(std::ostream& os, const levels::DistributedRunResult& r) {
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
}

/// Small-displacement theory on the finest level's final state (one process also names the
/// element and the load step: levels::RunResult::warnings); printed and returned.
std::vector<std::string> deformation_warnings(std::ostream& os, const levels::DistributedLevel& F,
                                              const levels::DistributedRunResult& r,
                                              const Communicator& comm) {
    std::vector<std::string> warnings;
    const levels::Deformation d = levels::max_deformation(F.local, r.u_full);
    std::array<double, 2> m{d.rotation, d.strain};
    comm.allreduce(std::span<double>(m), ReduceOp::max);
    std::ostringstream w;
    w << std::setprecision(3);
    if (m[0] > levels::kSmallRotationLimit) {
        w << "large rotation: an element of the finest level rotates by " << m[0]
          << " rad in the final state, above " << levels::kSmallRotationLimit
          << " rad: small-displacement theory does not hold there and the results are not "
             "reliable";
        warnings.push_back(w.str());
        w.str("");
    }
    if (m[1] > levels::kSmallStrainLimit) {
        w << "large strain: an element of the finest level has a principal strain of " << m[1]
          << " in the final state, above " << levels::kSmallStrainLimit
          << ": small-displacement theory does not hold there and the results are not "
             "reliable";
        warnings.push_back(w.str());
    }
    for (const auto& x : warnings)
        os << "warning: " << x << "\n";
    return warnings;
}

/// solution.pvtu and this process's piece, the contact values of ghost vertices taken from their
/// owners so that every piece shows them.
void write_solution_pvtu(const std::filesystem::path& file, const levels::DistributedLevel& F,
                         const levels::DistributedRunResult& r, const Communicator& comm,
                         mesh::VtuFormat vtu) {
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
    mesh::write_distributed_vtu(file, part, fields.point, fields.cell, comm, vtu);
}

/// contact.csv, contact_steps.csv and iterations.csv (process 0); their names added to `files`.
void write_contact_tables(const std::filesystem::path& dir, const levels::Problem& p,
                          const levels::DistributedRunResult& r, const ContactBoundary& cb,
                          int plevel, std::vector<std::string>& files) {
    write_file_atomically(dir / "contact.csv", [&](std::ostream& f) {
        f << "x,y,ux,uy,lambda_t,lambda_n,status\n" << std::setprecision(17);
        if (!cb.step_nodes.empty())
            for (const auto& n : cb.step_nodes.back())
                f << n.x.x() << "," << n.x.y() << "," << n.u.x() << "," << n.u.y() << ","
                  << n.lambda_t << "," << n.lambda_n << "," << contact::to_string(n.status) << "\n";
    });
    files.push_back("contact.csv");
    write_contact_steps(dir / "contact_steps.csv", p, cb.level, cb.step_nodes, r.completed_steps);
    files.push_back("contact_steps.csv");
    {
        // Levels 0..p as one process solves them, then the distributed ones.
        std::vector<LevelIterations> its;
        for (size_t l = 0; l < r.serial.level_steps.size(); ++l)
            if (!r.serial.level_steps[l].empty())
                its.push_back({static_cast<int>(l), r.serial.levels()[l].n_unknowns(),
                               &r.serial.level_steps[l]});
        for (size_t k = 1; k < r.level_steps.size(); ++k)
            its.push_back(
                {plevel + static_cast<int>(k), r.levels[k].n_global_dofs, &r.level_steps[k], true});
        write_iterations_csv(dir / "iterations.csv", its);
        files.push_back("iterations.csv");
    }
}

/// summary.json of a distributed run but for its solver (process 0).
toml::table distributed_summary(const levels::Problem& p, const levels::DistributedRunResult& r,
                                const Communicator& comm, const ProcessFigures& pf,
                                const std::filesystem::path& dir, mesh::VtuFormat vtu, int plevel,
                                const std::vector<PairResultant>& resultants,
                                const levels::StateChecks& checks,
                                const std::vector<std::string>& warnings) {
    const auto& F = r.finest();
    const int finest = p.levels;
    const auto& totals = pf.totals;
    const auto& all = pf.all;
    const size_t w = pf.w;
    toml::table root_t;
    root_t.insert("complete", true);
    root_t.insert("scene", p.name);
    root_t.insert("units", p.units);
    root_t.insert("level", static_cast<int64_t>(finest));
    root_t.insert("unknowns", static_cast<int64_t>(F.n_global_dofs));
    root_t.insert("contact_nodes", static_cast<int64_t>(F.n_global_contacts));
    root_t.insert("displacement_unknowns", static_cast<int64_t>(totals[1]));
    root_t.insert("vertices", static_cast<int64_t>(totals[2]));
    root_t.insert("triangles", static_cast<int64_t>(totals[0]));
    root_t.insert("converged", r.converged);
    root_t.insert("stopped", false); // a signal ends the processes (main.cpp)
    {
        toml::array fl;
        fl.push_back("solution.pvtu");
        for (int q = 0; q < comm.size(); ++q)
            fl.push_back(mesh::piece_path(dir / "solution.pvtu", q).filename().string());
        for (const char* f : {"contact.csv", "contact_steps.csv", "iterations.csv"})
            fl.push_back(f);
        fl.push_back("summary.json");
        root_t.insert("files", fl);
    }
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
        t.insert("cut_contact_elements", static_cast<int64_t>(a[7]));
        t.insert("ghost_contact_elements", static_cast<int64_t>(a[8]));
        procs.push_back(std::move(t));
    }
    root_t.insert("per_process", std::move(procs));
    int total_newton = 0;
    root_t.insert("steps", steps_json(r.steps, &total_newton));
    root_t.insert("total_newton_iterations", static_cast<int64_t>(total_newton));
    toml::array lv;
    for (size_t k = 1; k < r.level_steps.size(); ++k)
        lv.push_back(level_json(plevel + static_cast<int>(k), r.levels[k].n_global_dofs,
                                r.levels[k].n_global_contacts, r.level_steps[k]));
    root_t.insert("levels", lv);
    root_t.insert("recovered_levels", static_cast<int64_t>(p.recovered_levels));
    root_t.insert("contacts", contacts_json(p, resultants));
    root_t.insert("checks", checks_json(checks));
    {
        toml::array list;
        for (const auto& x : warnings)
            list.push_back(x);
        root_t.insert("warnings", std::move(list));
    }
    double rss_max = 0;
    for (int q = 0; q < comm.size(); ++q)
        rss_max = std::max(rss_max, all[static_cast<size_t>(q) * w + 6]);
    toml::table mt;
    mt.insert("peak_rss_bytes", rss_max); // the largest process's
    root_t.insert("memory", mt);
    toml::table tt; // rank 0's
    for (const auto& [name, e] : r.timings.table())
        tt.insert(name, e.seconds);
    root_t.insert("timings_seconds", tt);
    // What the timings ran on (rank 0): threads per process and the BLAS behind level 0's
    // schur.
    root_t.insert("threads", static_cast<int64_t>(parallel::num_threads()));
    root_t.insert("blas", parallel::blas_library());
    return root_t;
}

/// The resultant of every contact pair on the finest level, summed over the processes.
std::vector<PairResultant> pair_resultants(const levels::Problem& p,
                                           const levels::DistributedRunResult& r,
                                           const Communicator& comm) {
    const auto& F = r.finest();
    std::vector<PairResultant> resultants(p.contacts.size());
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
    return resultants;
}

} // namespace

void write_summary_last(const std::filesystem::path& dir, const toml::table& summary,
                        std::vector<std::string>& files) {
    write_file_atomically(dir / "summary.json",
                          [&](std::ostream& f) { f << toml::json_formatter{summary} << "\n"; });
    files.push_back("summary.json");
    set_stop_summary({}, {}, {});
}

void print_written(std::ostream& os, const Communicator& comm, const std::filesystem::path& dir,
                   const std::vector<std::string>& files) {
    comm.barrier();
    os << "\nwrote";
    for (size_t i = 0; i < files.size(); ++i)
        os << (i ? ", " : " ") << (dir / files[i]).string();
    os << "\n";
}

void open_output_folder(std::optional<OutputFolder>& folder, const std::filesystem::path& dir,
                        const std::string& scene, const Communicator& comm, std::ostream& os) {
    // Process 0 checks and locks the output folder before the solve (OutputFolder) and alone
    // writes in it but for the .vtu pieces; every process learns whether it may go on.
    const bool root = comm.rank() == 0;
    int refused = 0;
    std::string why;
    if (root) try {
            folder.emplace(dir);
            set_stop_summary(dir / "summary.json", killed_summary(scene, SIGINT, comm.size()),
                             killed_summary(scene, SIGTERM, comm.size()));
        } catch (const InvalidInput& e) {
            refused = 1;
            why = e.what();
        }
    comm.broadcast(std::span<int>(&refused, 1), 0);
    if (refused)
        throw InvalidInput(root ? why : "the output folder was refused (process 0 says why)");
    if (folder && folder->took_over_from() > 0)
        os << "note: the output folder's lock was left by process " << folder->took_over_from()
           << ", which has ended; taken over\n";
}

int run_scene_distributed(const RunOptions& opt, const Communicator& comm, std::ostream& out) {
    std::ostream null_stream(nullptr);
    const bool root = comm.rank() == 0;
    std::ostream& os = root ? out : null_stream;
    if (scene::scene_dimension(opt.scene) == 3) return run_scene3_distributed(opt, comm, out);
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
    const bool two_body = levels::has_two_body_pair(p);
    const levels::SolverPlan plan = levels::plan_solver(p, solver_request(opt), comm.size());
    const levels::LinearSolverSpec& spec = plan.spec;
    p.numbering = plan.numbering(); // mg:smoother=lattice: each part numbered by lattices
    const int finest = p.levels;
    int plevel = opt.partition_level
                     ? *opt.partition_level
                     : levels::partition_level(p.mesh0.n_cells(), finest, comm.size());
    MLC_CHECK(plevel >= 0 && plevel < finest, "--partition-level must lie in [0, "
                                                  << finest - 1 << "] for --levels " << finest
                                                  << ", found " << plevel);
    // One thread per process: the processes are the parallelism (hybrid runs are not measured).
    parallel::set_num_threads(1);
    const mesh::VtuFormat vtu =
        opt.vtu == "ascii" ? mesh::VtuFormat::ascii : mesh::VtuFormat::binary;
    const std::filesystem::path dir = opt.out.empty() ? "out/" + p.name : opt.out;
    std::optional<OutputFolder> folder;
    open_output_folder(folder, dir, p.name, comm, os);

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
    so.extrapolate = !opt.no_extrapolation;
    MLC_CHECK(!opt.stop, "internal error: a distributed run has no stop flag");
    os << "mlcontact: solving '" << p.name << "' on " << comm.size() << " processes\n";
    const bool mg = spec.pc.name() == "mg";
    os << "Newton-system solver: " << spec << " (" << comm.size() << " processes: "
       << (mg ? std::string("Krylov + distributed mg")
              : "Krylov + " + spec.pc.text() +
                    " on each process's diagonal block, Jacobi across the cuts; levels 0-p on "
                    "every process")
       << ")\n";
    os << "partition level " << plevel
       << (opt.partition_level
               ? " (--partition-level)"
               : " (the coarsest with " + std::to_string(levels::kTrianglesPerProcess) +
                     " triangles per process, at most --levels - 1)")
       << ": levels 0-" << plevel << " on every process, " << plevel + 1 << "-" << finest
       << " distributed\n";
    levels::ProgressLines progress(opt.quiet ? nullptr : &out);
    levels::DistributedRunResult r = levels::solve_distributed(p, so, comm, plevel, &progress);

    const auto& F = r.finest();
    const ProcessFigures pf = process_figures(os, r, comm, finest);
    if (two_body) print_contact_interface(os, comm, F, pf);
    print_level_steps(os, r);
    levels::StateChecks checks;
    std::vector<PairResultant> resultants(p.contacts.size());
    if (r.converged) {
        checks = levels::check_state(p, r, comm);
        resultants = pair_resultants(p, r, comm);
        print_checks(os, p, checks, resultants);
    }
    const std::vector<std::string> warnings =
        r.converged ? deformation_warnings(os, F, r, comm) : std::vector<std::string>();
    os << "\ntimings of process 0 (the distributed levels):\n";
    if (root) r.timings.print(os);
    os << "\ntime: " << std::fixed << std::setprecision(2) << r.seconds << " s" << std::defaultfloat
       << std::setprecision(6) << "\n";
    if (!r.converged) {
        os << "\nerror: " << r.failure << "\n";
        for (const auto& st : r.steps)
            for (double v : st.residuals)
                if (!std::isfinite(v)) throw SolverBreakdown(r.failure);
        return 2;
    }

    // Files: solution.pvtu and its pieces, contact.csv and summary.json (last).
    if (root) folder->begin_writing(p.name);
    comm.barrier();
    write_solution_pvtu(dir / "solution.pvtu", F, r, comm, vtu);
    // The contact boundary on rank 0: every process sends the contact-boundary edges that start
    // at a vertex it owns and its contact nodes after every step.
    const ContactBoundary cb = gather_contact_boundary(p, r, comm);
    std::vector<std::string> files{"solution.pvtu", "solution_<rank>.vtu (" +
                                                        std::to_string(comm.size()) + " pieces)"};
    if (root) {
        write_contact_tables(dir, p, r, cb, plevel, files);
        toml::table root_t =
            distributed_summary(p, r, comm, pf, dir, vtu, plevel, resultants, checks, warnings);
        toml::table sv;
        sv.insert("method", std::string(solvers::to_string(spec.method)));
        sv.insert("krylov", std::string(solvers::to_string(spec.krylov)));
        sv.insert("pc", spec.pc.text());
        sv.insert("rel_tol", spec.rel_tol);
        sv.insert("distributed", true);
        root_t.insert("solver", sv);
        write_summary_last(dir, root_t, files);
    }
    print_written(os, comm, dir, files);
    return 0;
}

} // namespace mlc::apps
