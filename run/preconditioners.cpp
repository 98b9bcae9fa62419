// SPDX-License-Identifier: MIT
// The driver's view of the preconditioner registry.
#include "run/preconditioners.hpp"

#include "core/check.hpp"
#include "solvers/factory.hpp"

#include <cctype>

namespace mlc::apps {

std::string pc_option_help(const std::string& lead) {
    return lead + "; one of " + solvers::preconditioner_names(", ") +
           " with NAME:key=value options (`mlcontact preconditioners` lists them)";
}

void print_preconditioners(std::ostream& os) {
    os << "preconditioners (--pc NAME[:key=value,...]; each implies a Krylov solve):\n";
    for (const auto& e : solvers::preconditioner_registry()) {
        os << "  " << e.usage() << "\n";
        os << "      options: ";
        const std::vector<solvers::PcKey> keys = e.keys();
        if (keys.empty()) os << "none";
        for (size_t i = 0; i < keys.size(); ++i)
            os << (i ? ", " : "") << keys[i].name;
        if (!e.positional_key.empty()) os << " (a bare value is " << e.positional_key << ")";
        os << "\n      built from: "
           << (e.needs_level_below && e.single_level_too
                   ? "this level and the level below; on a single level (--levels 0) this "
                     "level's K and unknowns (aggregation hierarchy)"
               : e.needs_level_below ? "this level and the level below (--levels >= 1)"
               : e.level_aware       ? "this level's element matrices"
                                     : "the assembled Jacobian")
           << "\n";
    }
}

void check_preconditioner_names(const std::vector<std::string>& specs, bool direct) {
    for (const auto& s : specs) {
        if (direct && (s == "schur" || s == "lu")) continue;
        std::string name = s.substr(0, s.find(':'));
        name.erase(0, name.find_first_not_of(" \t"));
        name.erase(name.find_last_not_of(" \t") + 1);
        for (char& c : name)
            c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        MLC_CHECK(solvers::preconditioner_entry(name) != nullptr,
                  "unknown preconditioner '"
                      << s << "'; valid: " << (direct ? "schur, lu (direct), " : "")
                      << solvers::preconditioner_names(", "));
        (void)solvers::parse_pc(s); // its options too
    }
}

} // namespace mlc::apps
