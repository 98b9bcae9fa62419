// SPDX-License-Identifier: MIT
/// @file Run-time choice of a preconditioner from a PETSc-like text spec such as "ilu:1" or
/// "ssor:omega=1.2,sweeps=2".
#pragma once

#include "core/linear_operator.hpp"

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
    /// The value of `key` parsed as a finite double, or `fallback` when absent.
    double get_double(const std::string& key, double fallback);
    /// The value of `key` parsed as an integer (the whole text), or `fallback` when absent.
    int get_int(const std::string& key, int fallback);
    /// Throws mlc::InvalidInput for any option not read by a get_* call.
    void finish() const;

private:
    const PreconditionerSpec& spec_;
    std::vector<std::string> used_;
};

/// One registered preconditioner name.
struct PreconditionerEntry {
    std::string name;           ///< e.g. "ilu"
    std::string usage;          ///< e.g. "ilu[:K] (K = fill level >= 0, default 0)"
    std::string positional_key; ///< key bound to a bare value ("k" for ilu), or empty
    /// Builds the (not yet set up) preconditioner from the parsed options.
    std::unique_ptr<Preconditioner> (*build)(SpecOptions& options);
};

/// All registered names, in the order they are listed in error messages. To add one, append
/// an entry to the table in factory.cpp (name, usage, positional key, builder function).
const std::vector<PreconditionerEntry>& preconditioner_registry();

/// Builds a preconditioner from `spec` (not yet set up: call `setup(A)` before `apply`).
///
/// Valid specs:
/// - "none": identity;
/// - "diag": Jacobi (zero diagonals patched, see smoothers/jacobi.hpp);
/// - "ilu", "ilu:K", "ilu:k=K": ILU(K), K >= 0 (default 0);
/// - "sor[:omega=W][,sweeps=N][,block=B]": forward (block) SOR, W in (0, 2) (default 1),
///   N >= 1 sweeps (default 1), uniform B x B diagonal blocks (default 1: point);
/// - "ssor[:...]": the same options, symmetric sweeps;
/// - "lu": sparse LU (exact).
/// An unknown name or option, or a bad value, throws mlc::InvalidInput listing the valid ones.
std::unique_ptr<Preconditioner> make_preconditioner(std::string_view spec);

} // namespace mlc::solvers
