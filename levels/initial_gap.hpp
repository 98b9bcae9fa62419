// SPDX-License-Identifier: MIT
/// @file Warnings about the initial configuration of the contact pairs: a contactor that starts
/// deep inside its target, or far from it, is legal input but most often a scene mistake (an
/// obstacle line through the middle of a body, two bodies overlapping by half their height).
#pragma once

#include "levels/level.hpp"
#include "levels/problem.hpp"

#include <string>
#include <vector>

namespace mlc::levels {

/// Fraction of a body's size (the diagonal of its bounding box) beyond which an initial
/// penetration or gap of a contact pair is reported.
inline constexpr double kInitialGapWarningFraction = 0.01;

/// One sentence per contact pair of `level` (normally level 0) whose contact nodes start too far
/// in or too far out: its deepest initial penetration (the most negative initial gap g0) exceeds
/// kInitialGapWarningFraction of the contactor body's bounding-box diagonal, or every contact
/// node starts apart by more than that (the smallest g0). Each names the pair, the node, the
/// gap, the fraction and what it usually means. Empty when nothing is out of the ordinary.
std::vector<std::string> initial_gap_warnings(const Problem& problem, const Level& level);

} // namespace mlc::levels
