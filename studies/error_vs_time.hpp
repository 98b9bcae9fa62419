// SPDX-License-Identifier: MIT
/// @file `mlcontact study error-vs-time`: a work-precision study over levels and solver
/// configurations, with the Pareto front of error against wall time.
#pragma once

#include "levels/problem.hpp"
#include "levels/solve3.hpp"

#include <filesystem>
#include <ostream>
#include <string>

namespace mlc::apps {

/// Options of the work-precision study.
struct ErrorVsTimeOptions {
    int max_level = 3; ///< configurations run on levels 0..max_level
    /// The reference solution is computed on level max_level + reference_offset (exact solver,
    /// coarse-to-fine): 1 or 2 in 2D; 0, 1 or 2 in 3D (0: the reference level is the finest
    /// of the grid, whose reference row then measures the reference against itself).
    int reference_offset = 1;
    /// The ILU(0) configurations run on levels 0..min(max_level, ilu_max_level): their Krylov
    /// iterations grow with the level (the 5000-iteration cap near 30 000 unknowns), so above
    /// level 3 they cost minutes per run without a chance of the front.
    int ilu_max_level = 3;
    /// Only the configurations whose name contains this text (empty: all).
    std::string only;
    bool plot = true;
    std::filesystem::path out; ///< default out/studies/<scene>_error_vs_time
};

/// The preconditioner spec the configuration named `configuration` runs on level `level` of
/// `problem` ("c2f default bicgstab+mg": the run's default above the crossover, with the lattice
/// sweep from level 4). Throws InvalidInput for an unknown name.
std::string error_vs_time_pc(const levels::Problem& problem, const std::string& configuration,
                             int level);

/// Configurations: the run's default above the crossover (coarse-to-fine BiCGStab + `mg`,
/// levels 1..max_level), coarse-to-fine and cold CGS + `mg` (levels 1..max_level: mg needs a level
/// below), coarse-to-fine CGS + hypre MGR (`mgr`, in builds with hypre), coarse-to-fine and cold
/// `schur`, `schur` with Newton tolerance 1e-6, coarse-to-fine and cold `lu`, and GMRES / CGS +
/// ILU(0) (up to ilu_max_level). A run that throws is recorded as not converged.
/// Runs every configuration on every level and records the wall time of the solve and the errors
/// against the reference: displacement error in the energy norm and the L2 norm (along the
/// contact boundary) of the contact traction difference, both relative; for `hertz` also the
/// relative L2 error of the pressure against the closed form (the primary error there). Writes
/// error_vs_time.csv/json, marks the Pareto front, and draws error_vs_time.png.
int study_error_vs_time(const levels::Problem& problem, const ErrorVsTimeOptions& opt,
                        std::ostream& os);

/// The study of a 3D scene (levels 0..max_level, max_level <= 3; ilu_max_level unused).
/// Configurations: coarse-to-fine and cold, each with the run's plan (`gmres+mg`: schur or lu on
/// level 0 by levels::plan_contact3, GMRES + the Galerkin multigrid above; levels 1..max_level),
/// `schur` and `lu` on every level (levels 0..max_level). The reference is on level
/// max_level + reference_offset: `c2f lu` where it fits in the process's memory
/// (lu_reference_fits3), else the run's plan with the Newton and GMRES tolerances at 1e-12.
/// Errors of a run on level l: its nodal displacements and its
/// contact tractions (each node's multiplier in global components over its lumped area
/// levels::contact_areas, a vertex field zero off the contact nodes) are interpolated to the
/// reference level by the hierarchy's P_vertex (per component, through each refinement); the
/// displacement error is relative in the energy norm of the reference level's K on its
/// unknowns, the traction error the relative L2 norm (lumped areas) over the reference's
/// contact nodes. The energy error is the primary one (Pareto front, plot). A run that throws
/// (a refused memory plan) is a row that did not converge. Writes error_vs_time.csv (the 2D
/// columns, closed_form_error -1), error_vs_time.json and error_vs_time.png. Returns 0, or 2
/// when the reference did not converge; throws InvalidInput for max_level outside 0..3, a
/// reference offset outside 0..2 and a scene without contact.
int study_error_vs_time3(const levels::ElasticProblem3& problem, const ErrorVsTimeOptions& opt,
                         std::ostream& os);

/// Whether coarse-to-fine sparse LU on every level of `problem` up to `level` fits in `limit`
/// (levels::plan_contact3 with lu forced), as the 3D study's reference.
bool lu_reference_fits3(const levels::ElasticProblem3& problem, int level,
                        const levels::MemoryLimit& limit);

} // namespace mlc::apps
