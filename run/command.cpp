// SPDX-License-Identifier: MIT
// The subcommand registry.
#include "run/command.hpp"

namespace mlc::apps {

std::vector<AddedCommand> add_commands(CLI::App& parent, const std::vector<Command>& commands) {
    std::vector<AddedCommand> added;
    for (const Command& c : commands) {
        CLI::App* app = parent.add_subcommand(c.name, c.usage);
        added.push_back({app, c.add(*app), c.distributed});
    }
    return added;
}

std::vector<AddedCommand> add_command_group(CLI::App& parent, const std::string& name,
                                            const std::string& usage,
                                            const std::vector<Command>& commands) {
    CLI::App* group = parent.add_subcommand(name, usage);
    group->require_subcommand(1);
    return add_commands(*group, commands);
}

const AddedCommand* chosen_command(const std::vector<AddedCommand>& added) {
    for (const AddedCommand& a : added)
        if (a.app->parsed()) return &a;
    return nullptr;
}

} // namespace mlc::apps
