// SPDX-License-Identifier: MIT
/// @file What the driver says about preconditioners, read from the registry
/// (solvers::preconditioner_registry): the `--pc` help of run, study and bench, the list printed
/// by `mlcontact preconditioners`, and the check of a list of names given on the command line.
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace mlc::apps {

/// The help of a `--pc` option: `lead` followed by every registered name.
std::string pc_option_help(const std::string& lead);

/// `mlcontact preconditioners`: one block per registry entry (usage line, options, whether it
/// is built from the level hierarchy and needs the level below).
void print_preconditioners(std::ostream& os);

/// Throws mlc::InvalidInput naming the first spec of `specs` whose name is not registered
/// (`direct` also accepts the direct Newton-system solvers "schur" and "lu"), listing the names.
void check_preconditioner_names(const std::vector<std::string>& specs, bool direct = false);

} // namespace mlc::apps
