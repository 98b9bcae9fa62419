// SPDX-License-Identifier: MIT
/// @file What a run writes: the readable report, contact.csv, summary.json and solution.vtu.
/// Every number is checked finite before a file is written; a NaN/Inf aborts with a diagnosis.
#pragma once

#include "levels/problem.hpp"
#include "levels/solve.hpp"

#include <filesystem>
#include <ostream>

namespace mlc::apps {

/// Prints, per two-body contact pair of level L, the contactor nodes the search left out:
/// "contact 'name': N contactor nodes found no facet: (x,y) ..." (or "no target node" for
/// node_on_node), listing at most `max_listed` positions (all when negative). Nothing when
/// every contactor node found its target.
void print_not_found(std::ostream& os, const levels::Problem& p, const levels::Level& L,
                     int max_listed = 20);

/// Prints the report header (scene, mesh, unknowns, contact pairs, and the contactor nodes that
/// found no target on the finest level).
void print_header(std::ostream& os, const levels::Problem& p, const levels::RunResult& r);
/// Prints the per-step table, checks (force balance, Coulomb, complementarity) and timings.
void print_summary(std::ostream& os, const levels::Problem& p, const levels::RunResult& r);

/// Writes contact.csv, summary.json and solution.vtu into dir (created if needed).
void write_outputs(const std::filesystem::path& dir, const levels::Problem& p,
                   const levels::RunResult& r);

} // namespace mlc::apps
