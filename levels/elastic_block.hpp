// SPDX-License-Identifier: MIT
/// @file The elastic block of a level: K restricted to the free displacement unknowns, in a
/// compact numbering (the BoomerAMG reference and the elastic benchmarks solve with it).
#pragma once

#include "core/types.hpp"
#include "levels/hierarchy.hpp"
#include "levels/level.hpp"
#include "solvers/direct.hpp"
#include "solvers/mg.hpp"

#include <memory>
#include <vector>

namespace mlc::levels {

/// K on the displacement unknowns of one level, numbered compactly in the level's order.
struct ElasticBlock {
    SparseMatrix K;
    std::vector<int> compact;   ///< per level unknown: its compact index, -1 for multipliers
    std::vector<int> vertex;    ///< per compact unknown: its vertex
    std::vector<int> component; ///< per compact unknown: 0 (x) or 1 (y)

    /// The entries of a level vector (all unknowns) on the compact unknowns.
    Vector restrict(const Vector& full) const;
};

/// Builds the elastic block of a level.
ElasticBlock elastic_block(const Level& L);

/// The level transfer T (fine unknowns x coarse unknowns) restricted to the displacement
/// unknowns of the two blocks: P (fine compact x coarse compact).
SparseMatrix displacement_prolongation(const SparseMatrix& T, const ElasticBlock& fine,
                                       const ElasticBlock& coarse);

/// The geometric V-cycle on the elastic blocks of all levels, a third client of
/// solvers::Multigrid (rediscretized: each level's stiffness): P = displacement_prolongation of
/// each transfer, R = P^T, vertex-block Gauss–Seidel, sparse LU on level 0. `blocks[l]` is the
/// elastic block of h.levels[l]; both must outlive this object (the multigrid keeps references).
struct ElasticMultigrid {
    std::vector<SparseMatrix> P, R; ///< per level >= 1: from / to the level below
    std::unique_ptr<solvers::Multigrid> mg;
    /// Builds and sets up the multigrid over levels 0..L (at least two levels).
    ElasticMultigrid(const Hierarchy& h, const std::vector<ElasticBlock>& blocks,
                     solvers::MultigridParams params = {});
    /// The V-cycle from the finest level.
    const solvers::Multigrid& finest() const { return *mg; }
};

} // namespace mlc::levels
