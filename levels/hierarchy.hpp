// SPDX-License-Identifier: MIT
/// @file The level hierarchy: levels 0..L by uniform 1->4 refinement, with the transfer operators
/// (P, Q) between consecutive levels.
#pragma once

#include "core/timer.hpp"
#include "levels/level.hpp"
#include "levels/problem.hpp"
#include "transfer/transfer.hpp"

#include <ostream>
#include <vector>

namespace mlc::levels {

/// Levels 0..L of a problem and the transfers between them, in `dim` dimensions (`Hierarchy`
/// in 2D, `Hierarchy3` in 3D).
template <int dim> struct BasicHierarchy {
    std::vector<BasicLevel<dim>> levels;            ///< levels[0] coarsest
    std::vector<transfer::LevelTransfer> transfers; ///< transfers[l]: level l -> level l+1
    int n_levels() const { return static_cast<int>(levels.size()); }
    const BasicLevel<dim>& finest() const { return levels.back(); }
    /// One line per level: vertices, cells, unknowns, contact nodes, nonzeros of K, and the
    /// operator complexity (sum of nonzeros over the finest's).
    void report(std::ostream& os) const;
};

extern template struct BasicHierarchy<2>;
extern template struct BasicHierarchy<3>;

using Hierarchy = BasicHierarchy<2>;
using Hierarchy3 = BasicHierarchy<3>;

/// Contact nodes of a level as plain data for transfer/.
transfer::ContactNodes contact_nodes(const Level& level);

/// Builds levels 0..problem.levels (mesh0 refined) and the transfers. `timings` may be null.
Hierarchy build_hierarchy(const Problem& problem, transfer::QRule rule = transfer::QRule::paper,
                          Timings* timings = nullptr);

} // namespace mlc::levels
