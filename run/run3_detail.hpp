// SPDX-License-Identifier: MIT
/// @file What `mlcontact run` on a 3D scene shares between one process (run/run3.cpp) and
/// several (run/run3_distributed.cpp): the options it takes, the overrides and the rows of
/// contact.csv.
#pragma once

#include "levels/newton.hpp"
#include "levels/solve3.hpp"
#include "run/run.hpp"

#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace mlc::apps::detail3 {

/// The options of `run` that have no effect on a 3D scene (yet): refused, naming why
/// (--partition-level only on one process).
void refuse_2d_options(const RunOptions& opt, bool distributed);
/// The levels above level 0 by a Krylov method with a preconditioner of the registry
/// (Method3::krylov), from --pc and --krylov; empty: the Galerkin multigrid with GMRES (no
/// --pc, --pc mg). Refused: --pc or --krylov with --linear schur|lu, mg with options (the 3D
/// multigrid's cycle is fixed) or with another Krylov method than GMRES, a preconditioner
/// with no 3D form (ebe, ...), and on several processes (`distributed`) one with no
/// distributed form (cf, sorcf, mgr, ...).
std::optional<levels::LinearSolverSpec> krylov_spec3(const RunOptions& opt, bool distributed);
/// The solver of the levels above level 0: "gmres + ilu:0", "gmres + mg", "schur", ...
std::string upper_solver_text(const levels::SolveOptions3& so);
/// --levels, --steps, --mu and --r, checked as in 2D.
void apply_overrides3(levels::ElasticProblem3& p, const RunOptions& opt);
/// s quoted for a CSV field when it holds a comma, a quote or a newline.
std::string csv_name(const std::string& s);
/// Throws SolverBreakdown naming `what` when v is not finite.
void require_finite3(double v, const char* what);
/// The multiplier of a node in global components: lambda_t1 t1 + lambda_t2 t2 + lambda_n n.
mesh::Vec3 global_lambda(const levels::ContactNodeState3& n);
/// One row of contact.csv (kNodeColumns) for node n of pair `pair` with contact area `area`.
void write_node(std::ostream& f, const std::string& pair, const levels::ContactNodeState3& n,
                double area);
/// The header of contact.csv.
extern const char* const kNodeColumns;
/// The progress line of each solved level's load step ("level l step k: ...") on `os`.
std::function<void(int, int, const levels::StepReport&)> progress_lines(std::ostream& os);
/// Throws SolverBreakdown when a node's multipliers or displacement are not finite.
void check_nodes(const std::vector<levels::ContactNodeState3>& nodes);

} // namespace mlc::apps::detail3
