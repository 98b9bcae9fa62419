// SPDX-License-Identifier: MIT
// The driver's error reports: a bad command line, and what a command throws.
#include "apps/driver.hpp"

#include "core/check.hpp"
#include "run/interrupt.hpp"

#include <iostream>

namespace mlc::apps {

int report_parse_error(CLI::App& app, const CLI::ParseError& e, int argc, char** argv) {
    // Bad command lines are bad input: exit 1 with the usual prefix, and where to look.
    if (e.get_exit_code() == 0) return app.exit(e);
    // The deepest command parsed, e.g. `mlcontact study`.
    CLI::App* at = &app;
    std::string where = "mlcontact";
    for (bool deeper = true; deeper;) {
        deeper = false;
        for (auto* sub : at->get_subcommands([](CLI::App*) { return true; }))
            if (sub->parsed()) {
                at = sub;
                where += " " + sub->get_name();
                deeper = true;
                break;
            }
    }
    std::string what = e.what();
    const auto subs = at->get_subcommands([](CLI::App*) { return true; });
    if (!subs.empty() && at->get_subcommands().empty()) {
        // A command that needs a subcommand got none it knows: name the word it got.
        std::string word;
        for (int i = 1; i < argc; ++i) {
            const std::string a = argv[i];
            if (a.empty() || a[0] == '-' || a == at->get_name()) continue;
            bool known = false;
            for (CLI::App* c = &app; c; c = c->get_parent())
                known = known || c->get_name() == a;
            for (const char* n : {"run", "study", "bench", "show", "scenes", "preconditioners"})
                known = known || a == n;
            if (!known) {
                word = a;
                break;
            }
        }
        std::string names;
        for (const auto* sub : subs)
            names += (names.empty() ? "" : ", ") + sub->get_name();
        what = (word.empty() ? "`" + where + "` needs a command"
                             : "unknown command '" + word + "' for `" + where + "`") +
               " (one of: " + names + ")";
    }
    std::cerr << "mlcontact: error: " << what << " (see `" << where << " --help`)\n";
    return 1;
}

int run_reporting_errors(const AddedCommand& command, const Launch& at) {
    const bool distributed = at.distributed;
    const int rank = at.rank;
    try {
        return command.action(at);
    } catch (const InvalidInput& e) {
        // Several processes: input errors are found by every process alike; rank 0 says it.
        if (rank == 0) std::cerr << "mlcontact: error: " << e.what() << "\n";
        return 1;
    } catch (const Interrupted& e) {
        // A stop request seen outside the solve (e.g. while meshing): nothing was written.
        const int sig = stop_signal();
        if (rank == 0)
            std::cerr << "mlcontact: stopped by " << signal_name(sig) << ": " << e.what() << "\n";
        return 128 + (sig > 0 ? sig : 2);
    } catch (const SolverBreakdown& e) {
        std::cerr << "mlcontact: numerical breakdown"
                  << (distributed ? " (process " + std::to_string(rank) + ")" : "") << ": "
                  << e.what() << "\n";
        if (distributed) comm::abort_all(3); // the others may wait in a collective
        return 3;
    } catch (const std::exception& e) {
        std::cerr << "mlcontact: error"
                  << (distributed ? " (process " + std::to_string(rank) + ")" : "") << ": "
                  << e.what() << "\n";
        if (distributed) comm::abort_all(1);
        return 1;
    }
}

} // namespace mlc::apps
