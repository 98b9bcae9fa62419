// SPDX-License-Identifier: MIT
/// @file Typed preconditioner specs: the options struct of every registered preconditioner, the
/// one parser of a PETSc-like text spec (`parse_pc("mg:pre=0,post=2")`), the canonical text of
/// a spec, the registry entry that declares what a preconditioner needs, and the Newton-system
/// method names (schur, lu, krylov) as an enum.
///
/// Text is read once, at the edge (the command line, a Python argument, a scene file): from
/// there on a preconditioner travels as a PcSpec. Adding a preconditioner is one registry row
/// (solvers/factory.cpp, or register_preconditioner from user code) plus its options struct.
#pragma once

#include "core/linear_operator.hpp"
#include "smoothers/ebe.hpp"
#include "solvers/aggregation.hpp"
#include "solvers/coarse_fine.hpp"
#include "solvers/hypre/boomeramg.hpp"
#include "solvers/hypre/mgr.hpp"
#include "solvers/krylov.hpp"
#include "solvers/mg.hpp"
#include "solvers/sorcf.hpp"

#include <deque>
#include <functional>
#include <initializer_list>
#include <map>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace mlc::solvers {

/// How each Newton system is solved: exactly by condensation on the contact set, by sparse LU
/// of the assembled Jacobian, or by a preconditioned Krylov method.
enum class Method { schur, lu, krylov };
/// "schur", "lu" or "krylov".
std::string_view to_string(Method m);
std::ostream& operator<<(std::ostream& os, Method m);
/// Parses one of the names printed by to_string; anything else throws mlc::InvalidInput.
Method parse_method(std::string_view name);

// ------------------------------------------------------------------------------------------
// The options of each registered preconditioner.

/// A preconditioner without options (none, diag, lu).
struct NoOptions {};

/// ilu: ILU(k).
struct IluOptions {
    int k = 0; ///< fill level, >= 0
};

/// sor and ssor: (block) SOR sweeps.
struct SorOptions {
    double omega = 1.0; ///< relaxation, in (0, 2)
    int sweeps = 1;     ///< sweeps per application, >= 1
    int block = 1;      ///< uniform diagonal block size (1: point SOR)
};

/// Where the coarse solve of cf and sorcf comes from.
enum class CoarseSource {
    lu,    ///< sparse LU of the level below's Jacobian at its converged statuses
    solver ///< the level below's own Newton-system solver
};

/// cf: the coarse/fine preconditioner (solvers/coarse_fine.hpp).
struct CfOptions {
    MultiplierScale scale = MultiplierScale::q;
    CoarseSource coarse = CoarseSource::lu;
    CoarseFineParams params{}; ///< inner solve, its tolerance and iteration limit
};

/// sorcf: SOR coarse/fine (solvers/sorcf.hpp).
struct SorcfOptions {
    MultiplierScale scale = MultiplierScale::q;
    CoarseSource coarse = CoarseSource::lu;
    SorcfParams params{}; ///< omega and scalar (block = 0) or block (1) generalized diagonal
};

/// ebe: element-by-element (smoothers/ebe.hpp).
struct EbeOptions {
    smoothers::EBEParams params{};
};

/// The hierarchy of mg.
enum class MgCoarse {
    automatic,    ///< rediscretize with the level below, aggregation without it
    rediscretize, ///< every level's own operator at the level's converged statuses
    galerkin,     ///< R A P from the finest level down
    aggregation   ///< an algebraic hierarchy of vertex aggregates (solvers/aggregation.hpp)
};

/// mg: the multilevel V-cycle (solvers/mg.hpp). The keys print in this order (omega first), the
/// order of the driver's default specs such as "mg:omega=0.8,pre=0,post=2".
struct MgOptions {
    double omega = 1.0; ///< relaxation of the block Gauss-Seidel sweeps
    int pre = 1;        ///< forward sweeps before the coarse correction
    int post = 1;       ///< backward sweeps after it
    MgCoarse coarse = MgCoarse::automatic;
    AggregationParams aggregation{}; ///< csize and smooth (coarse=aggregation)
    Precision precision = Precision::float64;
    MultigridParams::Smoother smoother = MultigridParams::Smoother::block;
    /// The V-cycle parameters (sweeps, omega, precision, smoother).
    MultigridParams cycle() const;
};

/// amg: hypre BoomerAMG (its own parameter struct).
using AmgOptions = BoomerAMGParams;
/// mgr: hypre MGR (its own parameter struct).
using MgrOptions = MGRParams;

/// A preconditioner registered from user code: its numeric options by key (the defaults are
/// the entry's; PreconditionerEntry::fields binds each key to one of them).
struct UserOptions {
    std::map<std::string, double> values;
};

/// The options of any registered preconditioner.
using PcOptions = std::variant<NoOptions, IluOptions, SorOptions, CfOptions, SorcfOptions,
                               EbeOptions, MgOptions, AmgOptions, MgrOptions, UserOptions>;

/// What an entry's `fields` function binds its options to, one key at a time: the same function
/// parses a spec, prints it and writes its usage line, so the three cannot disagree.
class PcFields {
public:
    virtual ~PcFields() = default;
    /// An integer option; `placeholder` names it in the usage line ("N").
    virtual void integer(std::string_view key, int& value, std::string_view placeholder = "N") = 0;
    /// A finite real option ("W").
    virtual void real(std::string_view key, double& value, std::string_view placeholder = "W") = 0;
    /// One of named values: `names` pairs each name with the integer it stands for.
    virtual void choice(std::string_view key, int& value,
                        std::initializer_list<std::pair<std::string_view, int>> names) = 0;
    /// An enumeration given by its names in the order of its values (0, 1, ...).
    template <class E>
    void choice(std::string_view key, E& value, std::initializer_list<std::string_view> names) {
        int v = static_cast<int>(value);
        std::vector<std::pair<std::string_view, int>> pairs;
        int i = 0;
        for (std::string_view n : names)
            pairs.emplace_back(n, i++);
        choice_list(key, v, pairs);
        value = static_cast<E>(v);
    }
    /// A bool given as 0 or 1 (with its meaning in the usage line).
    void flag(std::string_view key, bool& value) {
        int v = value ? 1 : 0;
        choice(key, v, {{"0", 0}, {"1", 1}});
        value = v != 0;
    }

protected:
    /// `choice` with a runtime list (what the enum template forwards to).
    virtual void choice_list(std::string_view key, int& value,
                             const std::vector<std::pair<std::string_view, int>>& names) = 0;
};

struct LevelData; // solvers/factory.hpp

/// One key of an entry, as its `fields` function declares it.
struct PcKey {
    std::string name;        ///< "omega"
    std::string placeholder; ///< "W", "N" or the valid names "block|lattice"
    std::string value;       ///< the default's value as text ("" where there is none)
    /// A valid value other than the default (the next name, the next integer, half the real):
    /// what the round-trip test sets the key to.
    std::string other;
};

/// One registered preconditioner: its name, options and what it needs. Rows are written with
/// designated initializers (solvers/factory.cpp).
struct PreconditionerEntry {
    std::string name;           ///< e.g. "ilu"
    std::string summary;        ///< what it is, the usage line's text in parentheses
    std::string positional_key; ///< key a bare value binds to ("k" for "ilu:1"), or empty
    PcOptions defaults{};       ///< the options of the bare name
    /// Binds every option key to its field of `options` (which holds `defaults`' alternative),
    /// in the order of the usage line and of the canonical text.
    std::function<void(PcOptions& options, PcFields& fields)> fields;
    /// Builds the (not yet set up) preconditioner; the level-aware entries read `level` (null
    /// when there is none: they throw InvalidInput saying where they apply).
    std::function<std::unique_ptr<Preconditioner>(const PcOptions& options, const LevelData* level)>
        build;

    // What the entry needs (the planner and the hierarchy read these, not the name).
    /// Built from the level hierarchy (LevelData), not from a matrix alone.
    bool level_aware = false;
    /// Needs the level below (--levels >= 1, every level solved from level 0 up).
    bool needs_level_below = false;
    /// Uses the level below when there is one and builds without it on a single level.
    bool single_level_too = false;
    /// Built from the element matrices of the level (LevelData::elements).
    bool element_matrices = false;
    /// Whether these options sweep by lattices: the levels must be numbered macro triangle by
    /// macro triangle before the hierarchy is built (Problem::Numbering::lattice). Empty: never.
    std::function<bool(const PcOptions&)> lattice_numbering;
    /// Whether these options run on several processes: "" when they do, else the reason they
    /// do not, naming what does. Empty function: the entry has no distributed form at all.
    std::function<std::string(const PcOptions&)> distributed;
    /// Whether these options run on a level of `dim` dimensions (2 or 3): "" when they do, else
    /// the reason, naming what does. Empty function: both (an entry that reads only the matrix,
    /// its vertex blocks and the transfers). What is 2D-only says so here: the lattice sweep of
    /// macro triangles, EBE's triangle element matrices.
    std::function<std::string(const PcOptions&, int dim)> dimensions;

    /// Its keys with their placeholders, defaults and alternative values, in order.
    std::vector<PcKey> keys() const;
    /// "name[:key=V,...] (summary)", generated from `keys()`.
    std::string usage() const;
    /// The distributed capability of `options` ("" = ok).
    std::string distributed_reason(const PcOptions& options) const;
    /// The dimension capability of `options` on a level of `dim` dimensions ("" = ok). Throws
    /// InvalidInput for a dim other than 2 or 3.
    std::string dimension_reason(const PcOptions& options, int dim) const;
};

/// A preconditioner with its typed options.
struct PcSpec {
    const PreconditionerEntry* entry = nullptr;
    PcOptions options{};

    /// The registered name ("" for an empty spec).
    const std::string& name() const;
    /// The canonical text: the name, then ':' and only the keys whose value differs from the
    /// default, in the entry's order (a positional key bare): "mg:omega=0.8,pre=0,post=2",
    /// "ilu:1", "mg". parse_pc(text()) == *this.
    std::string text() const;
    /// The options as the entry's struct (throws std::bad_variant_access for another entry's).
    template <class T> const T& get() const { return std::get<T>(options); }
    /// The entry sweeps by lattices with these options (the levels must be numbered for it).
    bool lattice_numbering() const;
    /// "" when it runs on several processes, else why not.
    std::string distributed() const;
    /// "" when it runs on a level of `dim` dimensions, else why not.
    std::string dimension_reason(int dim) const;
    /// Same entry and every option equal (compared on their text, key by key).
    bool operator==(const PcSpec& other) const;
};

std::ostream& operator<<(std::ostream& os, const PcSpec& spec);

/// Parses `name[:opt,opt,...]` where each opt is `key=value`, or a bare value bound to the
/// entry's positional key ("ilu:2"). Whitespace around tokens is ignored; the name is case
/// insensitive. An unknown name or key, a repeated or empty key or value, or a value that is
/// not a number or not one of the valid names throws mlc::InvalidInput listing the valid ones.
PcSpec parse_pc(std::string_view text);

/// The registered entries in the order of help and error messages. Entries are never removed,
/// so a PcSpec's entry pointer stays valid.
const std::deque<PreconditionerEntry>& preconditioner_registry();

/// Adds `entry` (from user code: a preconditioner the library does not know). Throws
/// InvalidInput when the name is taken or empty, or the entry has no summary, fields or build.
/// Register before parsing specs that name it; not thread-safe against concurrent parses.
const PreconditionerEntry& register_preconditioner(PreconditionerEntry entry);

/// The entry named `name` (lower case), or null.
const PreconditionerEntry* preconditioner_entry(std::string_view name);

/// The registered names separated by `separator`.
std::string preconditioner_names(std::string_view separator = ", ");

/// Every entry's usage line, one per line, each after "\n  " (for error messages).
std::string preconditioner_usages();

} // namespace mlc::solvers
