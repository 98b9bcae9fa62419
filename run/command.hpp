// SPDX-License-Identifier: MIT
/// @file The subcommand registry: the driver's commands as rows (name, usage, what declares
/// the options and returns the action), so that the studies and benches register their own
/// subcommands (studies/commands.hpp, bench/commands.hpp) and the driver's main() lists them.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace mlc::apps {

/// How a command was started. A command that needs the processes asks comm::world() for them
/// (its first call decides whether MPI is used, so the driver does not call it for every command).
struct Launch {
    bool distributed = false; ///< started by mpirun on several processes
    int rank = 0;             ///< this process among them (0 on one process)
    std::ostream& os;         ///< where the report goes
};

/// What runs a parsed command; returns the exit code.
using Action = std::function<int(const Launch&)>;

/// One subcommand.
struct Command {
    std::string name;  ///< the word on the command line
    std::string usage; ///< one line in `--help`
    /// Declares the command's options on the CLI11 command made for it; returns its action.
    std::function<Action(CLI::App&)> add;
    /// Runs on several processes too (mpirun -np N, N > 1); other commands are refused there.
    bool distributed = false;
};

/// A command added to a CLI11 parser.
struct AddedCommand {
    CLI::App* app = nullptr;
    Action action;
    bool distributed = false;
};

/// Adds every command of `commands` under `parent`, in order.
std::vector<AddedCommand> add_commands(CLI::App& parent, const std::vector<Command>& commands);

/// Adds the command `name` (its `usage` in `--help`) that needs one of `commands`, and those
/// under it.
std::vector<AddedCommand> add_command_group(CLI::App& parent, const std::string& name,
                                            const std::string& usage,
                                            const std::vector<Command>& commands);

/// The added command the command line chose (parsed), or nullptr.
const AddedCommand* chosen_command(const std::vector<AddedCommand>& added);

} // namespace mlc::apps
