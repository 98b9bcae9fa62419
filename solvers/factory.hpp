// SPDX-License-Identifier: MIT
/// @file The preconditioner registry's builders: what the level-aware preconditioners are built
/// from (LevelData) and make_preconditioner, which builds a typed spec (solvers/pc_spec.hpp).
/// The rows of the registry, one per name with its options and capabilities, are in
/// factory.cpp.
#pragma once

#include "core/linear_operator.hpp"
#include "smoothers/ebe.hpp"
#include "solvers/aggregation.hpp"
#include "solvers/coarse_fine.hpp"
#include "solvers/mg.hpp"
#include "solvers/pc_spec.hpp"

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace mlc::solvers {

/// What the level-aware preconditioners are built from: plain data of one level of the
/// hierarchy and of the level below, filled by the Newton-system driver (levels/, which this
/// folder does not include). The callables let a builder ask only for what it uses; what it
/// asks for, the caller keeps current.
struct LevelData {
    /// The level's Jacobian has contact multipliers (zero diagonals): amg refuses it.
    bool has_multipliers = false;
    /// EBE: the element matrices of the level (elastic, then one per contact element); asking
    /// builds them, and the caller refreshes the contact ones before each setup/update_values.
    std::function<const std::vector<smoothers::ElementMatrix>*()> elements;
    /// mgr: the function of every unknown of the level, 0 / 1 / 2 the x / y / z displacement
    /// component, kMultiplierFunction a contact multiplier; asking computes it.
    std::function<std::vector<int>()> unknown_functions;
    /// mg without the level below (or with coarse=aggregation): the level's elastic operator
    /// and the owner and kind of each unknown, for the algebraic hierarchy
    /// (solvers/aggregation.hpp); asking computes it (K is borrowed from the level: it must
    /// outlive the preconditioner). Empty: mg needs the level below.
    std::function<AggregationInput()> aggregation;

    // The level below (for the entries that need it).
    bool has_level_below = false; ///< the fields below are set
    /// CF/SORCF: the coarse/fine split of this level with the multiplier factors of a scale.
    std::function<CoarseFineSplit(MultiplierScale)> coarse_fine_split;
    /// The exact coarse solve by sparse LU of the level below's Jacobian at its converged
    /// statuses; asking for it makes the caller keep that LU factored (or, when it is
    /// singular, solve by the level below's own exact solver).
    std::function<CoarseSolve()> coarse_lu;
    /// The level below's own Newton-system solver at its converged statuses.
    CoarseSolve coarse_solver;
    /// mg: this level's multigrid data (the transfer from the level below, its smoother blocks).
    MultigridLevelData top;
    /// mg: the levels from the lowest one solved up to this one (coarsest first; the lowest
    /// entry has no T or R), their transfers and smoother blocks; computed when asked.
    /// The lattice rows of this level (MultigridLevelData::lattice, for mg:smoother=lattice),
    /// computed on request; null (or an empty function) when the level has none.
    std::function<std::shared_ptr<const smoothers::LatticeRows>()> top_lattice;
    std::function<std::vector<MultigridLevelData>()> hierarchy;
    /// hierarchy() starts at level 0 (mg:coarse=galerkin needs it).
    bool hierarchy_from_level0 = false;
    /// mg: the level below's own multigrid when it has one (the rediscretized mg extends it,
    /// Multigrid::above); else null: a two-level multigrid whose coarse operator (the level
    /// below's Jacobian at its converged statuses) the caller sets.
    const Multigrid* below_multigrid = nullptr;
};

/// Builds the preconditioner of `spec` (not yet set up: call `setup(A)` before `apply`); the
/// level-aware entries (cf, sorcf, ebe, mg, mgr) read `level` and throw InvalidInput without
/// it. A value out of range throws InvalidInput.
std::unique_ptr<Preconditioner> make_preconditioner(const PcSpec& spec,
                                                    const LevelData* level = nullptr);

/// make_preconditioner(parse_pc(text), level): for tests and tools holding a spec's text.
std::unique_ptr<Preconditioner> make_preconditioner(std::string_view text,
                                                    const LevelData* level = nullptr);

} // namespace mlc::solvers
