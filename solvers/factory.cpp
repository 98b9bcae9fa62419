// SPDX-License-Identifier: MIT
// Preconditioner registry and the `name:key=value,...` spec parser.
#include "solvers/factory.hpp"

#include "core/check.hpp"
#include "smoothers/block_sor.hpp"
#include "smoothers/iluk.hpp"
#include "smoothers/jacobi.hpp"
#include "solvers/direct.hpp"
#include "solvers/hypre/boomeramg.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <sstream>

namespace mlc::solvers {

namespace {

std::string_view trim(std::string_view s) {
    const auto first = s.find_first_not_of(" \t");
    if (first == std::string_view::npos) return {};
    const auto last = s.find_last_not_of(" \t");
    return s.substr(first, last - first + 1);
}

std::string valid_names() {
    std::ostringstream os;
    for (const auto& e : preconditioner_registry())
        os << "\n  " << e.usage;
    return os.str();
}

const PreconditionerEntry* find_entry(std::string_view name) {
    for (const auto& e : preconditioner_registry())
        if (e.name == name) return &e;
    return nullptr;
}

std::unique_ptr<Preconditioner> build_none(SpecOptions& o) {
    o.finish();
    return std::make_unique<IdentityPreconditioner>();
}

std::unique_ptr<Preconditioner> build_diag(SpecOptions& o) {
    o.finish();
    return std::make_unique<smoothers::Jacobi>();
}

std::unique_ptr<Preconditioner> build_ilu(SpecOptions& o) {
    smoothers::ILUKParams p;
    p.fill_level = o.get_int("k", 0);
    o.finish();
    return std::make_unique<smoothers::ILUK>(p);
}

std::unique_ptr<Preconditioner> build_sor_with(SpecOptions& o, smoothers::Sweep sweep) {
    smoothers::BlockSORParams p;
    p.sweep = sweep;
    p.omega = o.get_double("omega", 1.0);
    p.n_sweeps = o.get_int("sweeps", 1);
    p.block_size = o.get_int("block", 1);
    o.finish();
    return std::make_unique<smoothers::BlockSOR>(p);
}

std::unique_ptr<Preconditioner> build_sor(SpecOptions& o) {
    return build_sor_with(o, smoothers::Sweep::forward);
}

std::unique_ptr<Preconditioner> build_ssor(SpecOptions& o) {
    return build_sor_with(o, smoothers::Sweep::symmetric);
}

std::unique_ptr<Preconditioner> build_lu(SpecOptions& o) {
    o.finish();
    return std::make_unique<SparseLUPreconditioner>();
}

// The level-aware preconditioners are built by levels::make_krylov_system_solver from the level
// data; they are listed here so that error messages name them.
[[noreturn]] void throw_level_aware(const char* name) {
    std::ostringstream os;
    os << "preconditioner '" << name
       << "' is built from the level hierarchy, not from a matrix alone: use it as a "
          "Newton-system preconditioner (--linear krylov --pc "
       << name << "; cf and sorcf need --levels >= 1 and the coarse-to-fine solve)";
    throw InvalidInput(os.str());
}

std::unique_ptr<Preconditioner> build_cf(SpecOptions&) {
    throw_level_aware("cf");
}

std::unique_ptr<Preconditioner> build_sorcf(SpecOptions&) {
    throw_level_aware("sorcf");
}

std::unique_ptr<Preconditioner> build_ebe(SpecOptions&) {
    throw_level_aware("ebe");
}

std::unique_ptr<Preconditioner> build_mg(SpecOptions&) {
    throw_level_aware("mg");
}

std::unique_ptr<Preconditioner> build_amg(SpecOptions& o) {
    BoomerAMGParams p;
    p.num_functions = o.get_int("fn", p.num_functions);
    p.nodal = o.get_int("nodal", p.nodal);
    p.strong_threshold = o.get_double("theta", p.strong_threshold);
    p.agg_num_levels = o.get_int("agg", p.agg_num_levels);
    o.finish();
    p.validate();
    return std::make_unique<BoomerAMGPreconditioner>(p);
}

} // namespace

const std::vector<PreconditionerEntry>& preconditioner_registry() {
    // One row per name; builders read their options through SpecOptions and call finish().
    static const std::vector<PreconditionerEntry> table = {
        {"none", "none (identity)", "", &build_none},
        {"diag", "diag (Jacobi; zero diagonals patched)", "", &build_diag},
        {"ilu", "ilu[:K] or ilu:k=K (ILU(K), fill level K >= 0, default 0)", "k", &build_ilu},
        {"sor", "sor[:omega=W,sweeps=N,block=B] (forward SOR, 0 < W < 2, defaults 1, 1, 1)", "",
         &build_sor},
        {"ssor", "ssor[:omega=W,sweeps=N,block=B] (symmetric SOR, same options)", "", &build_ssor},
        {"lu", "lu (sparse direct LU)", "", &build_lu},
        {"cf",
         "cf[:inner=lu|cgs,tol=T,maxit=N,scale=q|none|qt|qinv,coarse=lu|solver] (coarse/fine, "
         "1995; needs the level below)",
         "", &build_cf},
        {"sorcf",
         "sorcf[:omega=W,block=0|1,scale=...,coarse=...] (SOR coarse/fine, 1995; needs the "
         "level below)",
         "", &build_sorcf},
        {"ebe", "ebe[:variant=c1|c4|c5,unit=multipliers|contact] (element-by-element, 1997)", "",
         &build_ebe},
        {"mg",
         "mg[:pre=N,post=N,omega=W] (multilevel V-cycle over all levels, vertex-block "
         "Gauss-Seidel; needs the level below)",
         "", &build_mg},
        {"amg",
         "amg[:fn=2,nodal=0,theta=0.25,agg=0] (hypre BoomerAMG V-cycle, for the elastic "
         "block: symmetric positive definite, fn interleaved components per vertex)",
         "", &build_amg},
    };
    return table;
}

PreconditionerSpec parse_preconditioner_spec(std::string_view spec) {
    PreconditionerSpec out;
    const auto colon = spec.find(':');
    const std::string_view name = trim(spec.substr(0, colon));
    MLC_CHECK(!name.empty(),
              "empty preconditioner name in spec '" << spec << "'; valid specs:" << valid_names());
    out.name = std::string(name);
    std::transform(out.name.begin(), out.name.end(), out.name.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (colon == std::string_view::npos) return out;

    const PreconditionerEntry* entry = find_entry(out.name);
    std::string_view rest = spec.substr(colon + 1);
    MLC_CHECK(!trim(rest).empty(),
              "empty option list after ':' in preconditioner spec '" << spec << "'");
    while (true) {
        const auto comma = rest.find(',');
        const std::string_view tok = trim(rest.substr(0, comma));
        const auto eq = tok.find('=');
        std::string key, value;
        if (eq == std::string_view::npos) {
            MLC_CHECK(entry != nullptr && !entry->positional_key.empty(),
                      "option '" << tok << "' in preconditioner spec '" << spec
                                 << "' needs the form key=value; valid specs:" << valid_names());
            key = entry->positional_key;
            value = std::string(tok);
        } else {
            key = std::string(trim(tok.substr(0, eq)));
            value = std::string(trim(tok.substr(eq + 1)));
        }
        MLC_CHECK(!key.empty() && !value.empty(), "empty key or value in option '"
                                                      << tok << "' of preconditioner spec '" << spec
                                                      << "'");
        MLC_CHECK(out.options.emplace(key, value).second,
                  "option '" << key << "' given twice in preconditioner spec '" << spec << "'");
        if (comma == std::string_view::npos) break;
        rest = rest.substr(comma + 1);
    }
    return out;
}

SpecOptions::SpecOptions(const PreconditionerSpec& spec) : spec_(spec) {}

double SpecOptions::get_double(const std::string& key, double fallback) {
    used_.push_back(key);
    const auto it = spec_.options.find(key);
    if (it == spec_.options.end()) return fallback;
    double v = 0.0;
    const char* first = it->second.data();
    const char* last = first + it->second.size();
    const auto [ptr, ec] = std::from_chars(first, last, v);
    MLC_CHECK(ec == std::errc() && ptr == last && std::isfinite(v),
              "option " << key << "=" << it->second << " of preconditioner '" << spec_.name
                        << "' is not a number");
    return v;
}

int SpecOptions::get_int(const std::string& key, int fallback) {
    used_.push_back(key);
    const auto it = spec_.options.find(key);
    if (it == spec_.options.end()) return fallback;
    int v = 0;
    const char* first = it->second.data();
    const char* last = first + it->second.size();
    const auto [ptr, ec] = std::from_chars(first, last, v);
    MLC_CHECK(ec == std::errc() && ptr == last, "option " << key << "=" << it->second
                                                          << " of preconditioner '" << spec_.name
                                                          << "' is not an integer");
    return v;
}

void SpecOptions::finish() const {
    for (const auto& [key, value] : spec_.options) {
        if (std::find(used_.begin(), used_.end(), key) != used_.end()) continue;
        // The keys read before finish() are exactly the valid ones.
        std::ostringstream keys;
        for (size_t i = 0; i < used_.size(); ++i)
            keys << (i ? ", " : "") << used_[i];
        MLC_CHECK(false, "unknown option '"
                             << key << "' for preconditioner '" << spec_.name
                             << "'; valid options: " << (used_.empty() ? "none" : keys.str()));
    }
}

std::unique_ptr<Preconditioner> make_preconditioner(std::string_view spec) {
    const PreconditionerSpec parsed = parse_preconditioner_spec(spec);
    const PreconditionerEntry* entry = find_entry(parsed.name);
    MLC_CHECK(entry != nullptr, "unknown preconditioner '" << parsed.name << "' in spec '" << spec
                                                           << "'; valid specs:" << valid_names());
    SpecOptions options(parsed);
    return entry->build(options);
}

} // namespace mlc::solvers
