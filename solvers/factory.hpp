// SPDX-License-Identifier: MIT
/// @file The preconditioner registry: every preconditioner name the code knows, its usage line,
/// options and whether it needs the level below, and its builder, chosen at run time from a
/// PETSc-like text spec such as "ilu:1", "ssor:omega=1.2,sweeps=2" or "mg:pre=2". The CLI help,
/// `study preconditioners`, `bench` and the Newton-system driver all read the names from here.
#pragma once

#include "core/linear_operator.hpp"
#include "smoothers/ebe.hpp"
#include "solvers/aggregation.hpp"
#include "solvers/coarse_fine.hpp"
#include "solvers/mg.hpp"

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace mlc::solvers {

/// A parsed spec `name[:opt,opt,...]` where each opt is `key=value`, or a bare value bound to
/// the name's positional key (for "ilu:2" the key is "k"). Whitespace around tokens is ignored.
struct PreconditionerSpec {
    std::string name;                           ///< lower-case name before ':'
    std::map<std::string, std::string> options; ///< key -> value text, keys unique
};

/// Splits `spec` into a lower-cased name and its options. A bare value is bound to the
/// registered positional key of the name; a bare value for a name without one (or an unknown
/// name), an empty key or value, or a repeated key throws mlc::InvalidInput. Does not check
/// that the name or the keys are valid (make_preconditioner does).
PreconditionerSpec parse_preconditioner_spec(std::string_view spec);

/// Typed access to the options of one spec, for the builder functions of the registry.
/// Every `get_*` marks its key as valid and used; `finish()` throws mlc::InvalidInput when the
/// spec holds a key no `get_*` asked for (an unknown key is an error, not a warning), listing
/// the keys that were asked for. Builders therefore read every key they accept before
/// calling `finish()`.
class SpecOptions {
public:
    /// `spec` must outlive this object.
    explicit SpecOptions(const PreconditionerSpec& spec);
    /// The value of `key` as text, or `fallback` when absent.
    std::string get_string(const std::string& key, const std::string& fallback);
    /// The value of `key` parsed as a finite double, or `fallback` when absent.
    double get_double(const std::string& key, double fallback);
    /// The value of `key` parsed as an integer (the whole text), or `fallback` when absent.
    int get_int(const std::string& key, int fallback);
    /// Throws mlc::InvalidInput for any option not read by a get_* call.
    void finish() const;
    /// The keys read so far, in order.
    const std::vector<std::string>& keys_read() const { return used_; }

private:
    const PreconditionerSpec& spec_;
    std::vector<std::string> used_;
};

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
    /// mgr: the function of every unknown of the level, 0 / 1 the x / y displacement component,
    /// 2 (kMultiplierFunction) a contact multiplier; asking computes it.
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

/// One registered preconditioner name.
struct PreconditionerEntry {
    std::string name;                 ///< e.g. "ilu"
    std::string usage;                ///< e.g. "ilu[:K] (K = fill level >= 0, default 0)"
    std::string positional_key;       ///< key bound to a bare value ("k" for ilu), or empty
    std::vector<std::string> options; ///< every option key it accepts, in usage order
    /// Built from the level hierarchy (LevelData), not from a matrix alone.
    bool level_aware = false;
    /// Needs the level below (--levels >= 1, every level solved from level 0 up).
    bool needs_level_below = false;
    /// Builds the (not yet set up) preconditioner from the parsed options and, for the
    /// level-aware entries, the level data (null when there is none: they throw).
    std::unique_ptr<Preconditioner> (*build)(SpecOptions& options, const LevelData* level);
    /// Uses the level below when there is one, and builds without it on a single level (mg:
    /// the algebraic aggregation hierarchy): `--levels 0` accepts it.
    bool single_level_too = false;
};

/// All registered names, in the order they are listed in help and error messages. To add one,
/// append an entry to the table in factory.cpp (name, usage, positional key, options,
/// level-awareness, builder function).
const std::vector<PreconditionerEntry>& preconditioner_registry();

/// The entry of the name of `spec` ("mg" or "mg:pre=2" -> the mg entry), or null.
const PreconditionerEntry* find_preconditioner(std::string_view spec);

/// The registered names separated by `separator`.
std::string preconditioner_names(std::string_view separator = ", ");

/// Builds a preconditioner from `spec` (not yet set up: call `setup(A)` before `apply`).
///
/// Valid specs:
/// - "none": identity;
/// - "diag": Jacobi (zero diagonals patched, see smoothers/jacobi.hpp);
/// - "ilu", "ilu:K", "ilu:k=K": ILU(K), K >= 0 (default 0);
/// - "sor[:omega=W][,sweeps=N][,block=B]": forward (block) SOR, W in (0, 2) (default 1),
///   N >= 1 sweeps (default 1), uniform B x B diagonal blocks (default 1: point);
/// - "ssor[:...]": the same options, symmetric sweeps;
/// - "lu": sparse LU (exact);
/// - "amg[:...]": hypre BoomerAMG (symmetric positive definite matrices);
/// - with `level` (level-aware): "cf", "sorcf", "ebe", "mg", "mgr" (hypre MGR, solvers/hypre/
///   mgr.hpp; see their usage lines and levels/krylov_system.hpp).
/// An unknown name or option, or a bad value, throws mlc::InvalidInput listing the valid ones.
std::unique_ptr<Preconditioner> make_preconditioner(std::string_view spec,
                                                    const LevelData* level = nullptr);

} // namespace mlc::solvers
