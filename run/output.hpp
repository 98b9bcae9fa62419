// SPDX-License-Identifier: MIT
/// @file What a run writes: the readable report, contact.csv, contact_steps.csv, summary.json,
/// solution.vtu and, per load step, the VTU series with their ParaView collections.
/// Every number is checked finite before a file is written; a NaN/Inf aborts with a diagnosis.
#pragma once

#include "core/atomic_file.hpp"
#include "levels/checks.hpp"
#include "levels/problem.hpp"
#include "levels/solve.hpp"
#include "mesh/io/vtu.hpp"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace mlc::apps {

/// The start of a run report's loading line (2D and 3D): "loading    N proportional load
/// step(s)" or "loading    N load step(s) along a K-point loading path".
template <class Problem> std::string loading_text(const Problem& p) {
    const int K = p.n_path_points();
    return "loading    " + std::to_string(p.load_steps) +
           (K == 1 ? std::string(" proportional load step(s)")
                   : " load step(s) along a " + std::to_string(K) + "-point loading path");
}

/// How the run reports (2D and 3D) name a two-body pair's target: "'tag' (node_on_facet, segment
/// integration)" or "'tag' (node_on_node)".
template <class Pair> std::string two_body_target_text(const Pair& c) {
    std::string s = "'" + c.target + "' (" + std::string(levels::to_string(c.element));
    if (c.element == levels::ContactElementKind::node_on_facet)
        s += ", " + std::string(contact::to_string(c.integration)) + " integration";
    return s + ")";
}

/// Prints, per two-body contact pair of level L, the contactor nodes the search left out:
/// "contact 'name': N contactor nodes found no facet: (x,y) ..." (or "no target node" for
/// node_on_node), listing at most `max_listed` positions (all when negative). Nothing when
/// every contactor node found its target.
void print_not_found(std::ostream& os, const levels::Problem& p, const levels::Level& L,
                     int max_listed = 20);

/// Prints the report header (scene, mesh, unknowns, contact pairs, and the contactor nodes that
/// found no target on the finest level).
void print_header(std::ostream& os, const levels::Problem& p, const levels::RunResult& r);
/// The resultant force the target exerts on a contact pair's contactor nodes, and how many of
/// them are in contact (levels::contact_resultant).
struct PairResultant {
    Vec2 force = Vec2::Zero();
    int in_contact = 0;
};
/// Prints the checks line and one resultant line per contact pair.
void print_checks(std::ostream& os, const levels::Problem& p, const levels::StateChecks& c,
                  const std::vector<PairResultant>& resultants);
/// Prints the per-step table, checks (force balance, Coulomb, complementarity) and timings.
void print_summary(std::ostream& os, const levels::Problem& p, const levels::RunResult& r);

/// How a run writes its files.
struct OutputOptions {
    mesh::VtuFormat vtu = mesh::VtuFormat::binary; ///< --vtu binary|ascii
};

/// The fields write_solution_vtu writes (see there), on the vertices and triangles of L.mesh.
struct SolutionFields {
    std::vector<mesh::Field> point, cell;
};
SolutionFields solution_fields(const levels::Level& L, const Vector& u_full,
                               const std::vector<levels::ContactNodeState>& nodes);

/// Writes one level's state as a VTU: point fields displacement, contact_status (-1 off the
/// contact boundary, else contact::Status), contact_force (the force the target exerts on the
/// node, -(lambda_t t + lambda_n n)), lambda_t, lambda_n; cell fields stress (xx, yy, xy),
/// von_mises, body. Non-finite values throw SolverBreakdown before anything is written.
void write_solution_vtu(const std::filesystem::path& file, const levels::Level& L,
                        const Vector& u_full, const std::vector<levels::ContactNodeState>& nodes,
                        mesh::VtuFormat format);

/// Per contact node of a level (L.contacts order): its tributary length, half the sum of the
/// lengths of the contact-boundary edges at the node (the boundary edges carrying the pair's
/// contactor tag, inside its region if it has one), and its arc length along that boundary from
/// the pair's first node (the boundary walked counter-clockwise around the body, i.e. with the
/// body on the left; separate pieces joined by the straight distance between them).
struct ContactGeometry {
    std::vector<double> length;
    std::vector<double> arc;
};
ContactGeometry contact_geometry(const levels::Problem& p, const levels::Level& L);

/// contact_steps.csv: one row per load step (1..completed_steps) and contact node of L (its
/// L.contacts order; step_nodes[k] in that order), with the node's tributary length and arc
/// length (contact_geometry), pressure and traction per unit length.
void write_contact_steps(const std::filesystem::path& file, const levels::Problem& p,
                         const levels::Level& L,
                         const std::vector<std::vector<levels::ContactNodeState>>& step_nodes,
                         int completed_steps);

/// One level's load steps, for iterations.csv.
struct LevelIterations {
    int level = 0;
    std::int64_t unknowns = 0;
    const std::vector<levels::LevelStep>* steps = nullptr;
    bool distributed = false; ///< solved by the processes each on its part (mpirun -np N, N > 1)
};

/// iterations.csv: one row per Newton system solved on every level listed, columns
/// `level,unknowns,distributed,step,newton,krylov`: the load step, the Newton iteration (1, 2, ...
/// within the step) and the Krylov iterations of its linear solve (0 for a direct solve).
void write_iterations_csv(const std::filesystem::path& file,
                          const std::vector<LevelIterations>& levels);

/// The output folder of one run of the driver, from before its solve to its exit.
///
/// Constructed before the solve, it checks the folder and locks it: creates it if needed, refuses
/// a path that is not a folder, and creates the lock file `.mlcontact.lock` in it holding this
/// process's id (flock, so a lock whose process is gone is free: it is taken over). Creating the
/// lock and writing the id (with fsync) is also the probe that files can be written there, so a
/// read-only or full file system is found before the solve. Another live run holding the lock:
/// refused at once. Every failure throws InvalidInput naming the folder. The lock file is removed
/// when the object is destroyed, and so is the folder when this run made it and wrote nothing.
///
/// begin_writing(), before this run's first file: removes the files listed in the folder's
/// summary.json when that summary is complete (a finished earlier run of this folder; only names
/// the driver writes, never anything else), then writes summary.json as in progress
/// ("complete": false), so that a folder left by a run killed while writing tells so.
class OutputFolder {
public:
    static constexpr const char* lock_name = ".mlcontact.lock";

    /// `lock` false (the Python module's Result.write): no lock, no check beyond creating dir.
    explicit OutputFolder(std::filesystem::path dir, bool lock = true);
    OutputFolder(const OutputFolder&) = delete;
    OutputFolder& operator=(const OutputFolder&) = delete;
    ~OutputFolder();

    const std::filesystem::path& dir() const { return dir_; }
    /// The process id found in a lock this run took over (its run ended without removing it),
    /// or 0.
    long took_over_from() const { return took_over_from_; }
    /// See the class comment; does its work once.
    void begin_writing(const std::string& scene);
    /// Records a file this run wrote (name in the folder).
    void add(const std::string& name);
    /// The files this run wrote, in order.
    const std::vector<std::string>& files() const { return files_; }
    /// The files of the earlier run that begin_writing removed.
    const std::vector<std::string>& removed() const { return removed_; }

private:
    std::filesystem::path dir_;
    int lock_fd_ = -1;
    /// The lock file, removed by a signal handler that ends the process at once.
    std::optional<RegisteredTemporary> lock_registered_;
    long took_over_from_ = 0;
    bool created_ = false; ///< this run made the folder (removed at the end if still empty)
    bool begun_ = false;
    std::vector<std::string> files_, removed_;
};

/// The state summary.json records besides the result: "complete" (every file the run meant to
/// write was written, summary.json last), "stopped" (a signal arrived; "stopped_at" says where),
/// "files" (this run's files in the folder) and the plot's outcome.
struct SummaryStatus {
    bool complete = true;
    bool stopped = false;
    std::string stopped_at;
    std::vector<std::string> files; ///< without summary.json, which is added
    std::string plot;               ///< "written", "failed: <cause>", or empty (not asked)
};

/// The files of a run but summary.json, into dir (created if needed), each under a temporary name
/// renamed when complete: when converged, solution.vtu, contact.csv, contact_steps.csv and
/// iterations.csv; when stopped on request, contact_steps.csv (the completed steps) and
/// iterations.csv; nothing else. Appends the names written to `written`. A stop requested while
/// writes are stoppable (core/stop.hpp) ends it with mlc::Interrupted after the files written so
/// far (the one being written is left as it was).
void write_result_files(const std::filesystem::path& dir, const levels::Problem& p,
                        const levels::RunResult& r, const OutputOptions& options,
                        std::vector<std::string>& written);

/// summary.json of a run (written atomically; never stopped by a signal).
void write_summary(const std::filesystem::path& dir, const levels::Problem& p,
                   const levels::RunResult& r, const OutputOptions& options,
                   const SummaryStatus& status);

/// write_result_files then write_summary (complete, not stopped unless r.stopped). Returns the
/// names of the files written.
std::vector<std::string> write_outputs(const std::filesystem::path& dir, const levels::Problem& p,
                                       const levels::RunResult& r,
                                       const OutputOptions& options = {});

/// The summary.json a run writes when it begins writing ("complete": false) and the one a signal
/// handler writes when it ends the process at once ("stopped": true, "complete": false).
std::string in_progress_summary(const std::string& scene);
std::string killed_summary(const std::string& scene, int sig, int processes);

/// --every-step / --every-level: writes each converged load step's VTU as soon as it is done
/// (solution_step_0001.vtu, ... for the finest level; solution_level_<l>_step_0001.vtu for
/// level l < finest with every_level) and rewrites the collection of that level after each
/// (solution.pvd, solution_level_<l>.pvd), with the load parameter s as the time. Use as
/// SolveObserver::level_step. Each file written is recorded in `folder`, whose
/// begin_writing() is called before the first.
class StepFiles {
public:
    StepFiles(OutputFolder& folder, const levels::Problem& p, bool every_level,
              mesh::VtuFormat format);
    void operator()(const levels::LevelStepState& s);
    /// Load steps written of the finest level.
    int finest_steps() const;
    /// The collections written so far.
    std::vector<std::string> collections() const;

private:
    OutputFolder* folder_;
    std::filesystem::path dir_;
    std::string scene_;
    int finest_ = 0;
    int digits_ = 4;
    bool every_level_ = false;
    mesh::VtuFormat format_;
    std::vector<std::vector<std::pair<double, std::string>>> series_; ///< per level
};

} // namespace mlc::apps
