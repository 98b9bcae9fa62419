// SPDX-License-Identifier: MIT
/// @file The parts of summary.json that one-process and distributed runs share (run/output.cpp,
/// run/run_distributed.cpp), so that both write them alike.
#pragma once

#include "run/output.hpp"
#include "levels/checks.hpp"
#include "levels/newton.hpp"
#include "levels/solve.hpp"

#include <toml++/toml.h>

#include <cstdint>
#include <vector>

namespace mlc::apps {

/// "steps": one table per load step of the finest level (iterations, residuals, status changes
/// and counts, seconds, message); `total_newton` receives the sum of the Newton iterations.
toml::array steps_json(const std::vector<levels::StepReport>& steps, int* total_newton);
/// One entry of "levels": the level, its unknowns and contact nodes, and per load step its
/// iterations, predicted-status agreement, initial guess and seconds.
toml::table level_json(int level, std::int64_t unknowns, std::int64_t contact_nodes,
                       const std::vector<levels::LevelStep>& steps);
/// "contacts": per pair its name, resultant and nodes in contact.
toml::array contacts_json(const levels::Problem& p, const std::vector<PairResultant>& resultants);
/// "checks": the relative figures of StateChecks.
toml::table checks_json(const levels::StateChecks& c);

} // namespace mlc::apps
