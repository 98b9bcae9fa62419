// SPDX-License-Identifier: MIT
// Preconditioner registry and the `name:key=value,...` spec parser.
#include "solvers/factory.hpp"

#include "core/check.hpp"
#include "smoothers/block_sor.hpp"
#include "smoothers/iluk.hpp"
#include "smoothers/jacobi.hpp"
#include "solvers/direct.hpp"
#include "solvers/hypre/boomeramg.hpp"
#include "solvers/hypre/mgr.hpp"
#include "solvers/sorcf.hpp"

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

std::unique_ptr<Preconditioner> build_none(SpecOptions& o, const LevelData*) {
    o.finish();
    return std::make_unique<IdentityPreconditioner>();
}

std::unique_ptr<Preconditioner> build_diag(SpecOptions& o, const LevelData*) {
    o.finish();
    return std::make_unique<smoothers::Jacobi>();
}

std::unique_ptr<Preconditioner> build_ilu(SpecOptions& o, const LevelData*) {
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

std::unique_ptr<Preconditioner> build_sor(SpecOptions& o, const LevelData*) {
    return build_sor_with(o, smoothers::Sweep::forward);
}

std::unique_ptr<Preconditioner> build_ssor(SpecOptions& o, const LevelData*) {
    return build_sor_with(o, smoothers::Sweep::symmetric);
}

std::unique_ptr<Preconditioner> build_lu(SpecOptions& o, const LevelData*) {
    o.finish();
    return std::make_unique<SparseLUPreconditioner>();
}

// The level-aware preconditioners: built from the level data of the Newton-system driver.
const LevelData& require_level(const LevelData* level, const char* name, bool needs_below) {
    if (level == nullptr) {
        std::ostringstream os;
        os << "preconditioner '" << name
           << "' is built from the level hierarchy, not from a matrix alone: use it as a "
              "Newton-system preconditioner (--pc "
           << name << (needs_below ? ", with --levels >= 1" : "") << ")";
        throw InvalidInput(os.str());
    }
    MLC_CHECK(!needs_below || level->has_level_below,
              name << " needs the level below: use with --levels >= 1 and the coarse-to-fine "
                      "solve");
    return *level;
}

// CF and SORCF: the split with the multiplier factors, and the coarse solve.
struct CoarseFineInputs {
    CoarseFineSplit split;
    CoarseSolve coarse;
};

CoarseFineInputs coarse_fine_inputs(SpecOptions& o, const LevelData& level, const char* name) {
    const MultiplierScale scale = parse_multiplier_scale(o.get_string("scale", "q"));
    const std::string coarse = o.get_string("coarse", "lu");
    MLC_CHECK(coarse == "solver" || coarse == "lu",
              "option coarse=" << coarse << " of " << name << ": valid solver, lu");
    CoarseFineInputs in;
    in.coarse = coarse == "lu" ? level.coarse_lu() : level.coarse_solver;
    in.split = level.coarse_fine_split(scale);
    return in;
}

std::unique_ptr<Preconditioner> build_cf(SpecOptions& o, const LevelData* level) {
    const LevelData& L = require_level(level, "cf", true);
    CoarseFineInputs in = coarse_fine_inputs(o, L, "cf");
    CoarseFineParams p;
    p.inner = parse_inner_solve(o.get_string("inner", "lu"));
    p.inner_tol = o.get_double("tol", p.inner_tol);
    p.inner_max_iter = o.get_int("maxit", p.inner_max_iter);
    o.finish();
    return make_coarse_fine(std::move(in.split), std::move(in.coarse), p);
}

std::unique_ptr<Preconditioner> build_sorcf(SpecOptions& o, const LevelData* level) {
    const LevelData& L = require_level(level, "sorcf", true);
    CoarseFineInputs in = coarse_fine_inputs(o, L, "sorcf");
    SorcfParams p;
    p.omega = o.get_double("omega", p.omega);
    const int block = o.get_int("block", 0);
    MLC_CHECK(block == 0 || block == 1,
              "option block=" << block << " of sorcf: valid 0 (scalar D*), 1 (blocks)");
    p.block = block == 1;
    o.finish();
    return make_sorcf(std::move(in.split), std::move(in.coarse), p);
}

std::unique_ptr<Preconditioner> build_ebe(SpecOptions& o, const LevelData* level) {
    const LevelData& L = require_level(level, "ebe", false);
    smoothers::EBEParams p;
    p.variant = smoothers::parse_ebe_variant(o.get_string("variant", "c1"));
    const std::string unit = o.get_string("unit", "multipliers");
    MLC_CHECK(unit == "contact" || unit == "multipliers",
              "option unit=" << unit << " of ebe: valid contact, multipliers");
    p.unit_scaling = unit == "contact" ? smoothers::UnitScaling::contact_unknowns
                                       : smoothers::UnitScaling::multipliers;
    o.finish();
    return std::make_unique<smoothers::EBE>(*L.elements(), p);
}

std::unique_ptr<Preconditioner> build_mg(SpecOptions& o, const LevelData* level) {
    const LevelData& L = require_level(level, "mg", false);
    MultigridParams p;
    p.pre_sweeps = o.get_int("pre", p.pre_sweeps);
    p.post_sweeps = o.get_int("post", p.post_sweeps);
    p.omega = o.get_double("omega", p.omega);
    // Without the level below, the algebraic hierarchy (aggregation) is the only one there is.
    const bool below = L.has_level_below;
    const std::string coarse = o.get_string("coarse", below ? "rediscretize" : "aggregation");
    MLC_CHECK(coarse == "rediscretize" || coarse == "galerkin" || coarse == "aggregation",
              "option coarse=" << coarse << " of mg: valid rediscretize, galerkin, aggregation");
    AggregationParams ap;
    ap.coarse_size = o.get_int("csize", ap.coarse_size);
    ap.smoothing = o.get_double("smooth", ap.smoothing);
    const std::string precision = o.get_string("precision", "double");
    MLC_CHECK(precision == "double" || precision == "single",
              "option precision=" << precision << " of mg: valid double, single");
    p.precision = precision == "single" ? Precision::float32 : Precision::float64;
    const std::string smoother = o.get_string("smoother", "block");
    MLC_CHECK(smoother == "block" || smoother == "lattice",
              "option smoother=" << smoother << " of mg: valid block, lattice");
    p.smoother = smoother == "lattice" ? MultigridParams::Smoother::lattice
                                       : MultigridParams::Smoother::block;
    o.finish();
    p.validate();
    MultigridLevelData top = L.top;
    if (p.smoother == MultigridParams::Smoother::lattice) {
        MLC_CHECK(coarse != "aggregation",
                  "mg:smoother=lattice needs the refined levels (their macro triangles); an "
                  "algebraic hierarchy (coarse=aggregation, or a mesh without levels) has none");
        // Levels below 4 (or not refined from level 0) keep the block smoother; the driver
        // refuses the option when the finest level is below 4 (levels::choose_solver).
        if (L.top_lattice) top.lattice = L.top_lattice();
    }
    if (coarse == "aggregation") {
        ap.validate();
        MLC_CHECK(L.aggregation != nullptr,
                  "mg needs the level below (use with --levels >= 1 and the coarse-to-fine "
                  "solve) or the level's unknowns for its algebraic hierarchy, and the level "
                  "data gives neither");
        const AggregationInput in = L.aggregation();
        return std::make_unique<Multigrid>(aggregation_levels(in, ap), p,
                                           CoarseOperators::galerkin);
    }
    MLC_CHECK(below, "mg needs the level below for coarse=" << coarse
                                                            << ": use with --levels >= 1 and the "
                                                               "coarse-to-fine solve, or "
                                                               "coarse=aggregation");
    if (coarse == "galerkin") {
        MLC_CHECK(L.hierarchy_from_level0,
                  "mg:coarse=galerkin needs every level below in the coarse-to-fine solve");
        std::vector<MultigridLevelData> h = L.hierarchy();
        h.back().lattice = top.lattice;
        return std::make_unique<Multigrid>(std::move(h), p, CoarseOperators::galerkin);
    }
    if (L.below_multigrid != nullptr) return Multigrid::above(*L.below_multigrid, top, p);
    // Two levels: the level below (its operator set by the caller, factored) and this one.
    std::vector<MultigridLevelData> h = L.hierarchy();
    MLC_CHECK(h.size() >= 2, "mg: the level data holds " << h.size() << " level(s), at least two");
    MultigridLevelData below_level = std::move(h[h.size() - 2]);
    below_level.T = below_level.R = nullptr;
    return std::make_unique<Multigrid>(
        std::vector<MultigridLevelData>{std::move(below_level), std::move(top)}, p);
}

std::unique_ptr<Preconditioner> build_amg(SpecOptions& o, const LevelData* level) {
    MLC_CHECK(level == nullptr || !level->has_multipliers,
              "amg (hypre BoomerAMG) preconditions the elastic block only (symmetric "
              "positive definite); the contact Jacobian has zero multiplier "
              "diagonals: use --pc mg, or compare on the elastic block with "
              "`mlcontact bench elastic`");
    BoomerAMGParams p;
    p.num_functions = o.get_int("fn", p.num_functions);
    p.nodal = o.get_int("nodal", p.nodal);
    p.strong_threshold = o.get_double("theta", p.strong_threshold);
    p.agg_num_levels = o.get_int("agg", p.agg_num_levels);
    o.finish();
    p.validate();
    return std::make_unique<BoomerAMGPreconditioner>(p);
}

// hypre MGR on the whole Newton system: F = displacements (AMG on A_FF), C = multipliers.
std::unique_ptr<Preconditioner> build_mgr(SpecOptions& o, const LevelData* level) {
    const LevelData& L = require_level(level, "mgr", false);
    MGRParams p;
    const std::string frelax = o.get_string("frelax", "amg");
    MLC_CHECK(frelax == "amg" || frelax == "jacobi" || frelax == "gs",
              "option frelax=" << frelax << " of mgr: valid amg, jacobi, gs");
    p.f_relax = frelax == "amg" ? 2 : frelax == "jacobi" ? 0 : 3;
    p.f_sweeps = o.get_int("fsweeps", p.f_sweeps);
    p.f_amg.strong_threshold = o.get_double("theta", p.f_amg.strong_threshold);
    p.interp_type = o.get_int("interp", p.interp_type);
    p.restrict_type = o.get_int("restrict", p.restrict_type);
    p.coarse_method = o.get_int("cg", p.coarse_method);
    p.global_smooth_iters = o.get_int("smooth", p.global_smooth_iters);
    p.global_smooth_type = o.get_int("smoother", p.global_smooth_type);
    o.finish();
    p.validate();
    MLC_CHECK(L.unknown_functions != nullptr,
              "mgr: the level data gives no unknown functions (C/F split)");
    return std::make_unique<MGRPreconditioner>(L.unknown_functions(), p);
}

} // namespace

const std::vector<PreconditionerEntry>& preconditioner_registry() {
    // One row per name; builders read their options through SpecOptions and call finish().
    static const std::vector<PreconditionerEntry> table = {
        {"none", "none (identity)", "", {}, false, false, &build_none},
        {"diag", "diag (Jacobi; zero diagonals patched)", "", {}, false, false, &build_diag},
        {"ilu",
         "ilu[:K] or ilu:k=K (ILU(K), fill level K >= 0, default 0)",
         "k",
         {"k"},
         false,
         false,
         &build_ilu},
        {"sor",
         "sor[:omega=W,sweeps=N,block=B] (forward SOR, 0 < W < 2, defaults 1, 1, 1)",
         "",
         {"omega", "sweeps", "block"},
         false,
         false,
         &build_sor},
        {"ssor",
         "ssor[:omega=W,sweeps=N,block=B] (symmetric SOR, same options)",
         "",
         {"omega", "sweeps", "block"},
         false,
         false,
         &build_ssor},
        {"lu", "lu (sparse direct LU)", "", {}, false, false, &build_lu},
        {"cf",
         "cf[:scale=q|none|qt|qinv,coarse=lu|solver,inner=lu|cgs,tol=T,maxit=N] (coarse/fine, "
         "1995; needs the level below)",
         "",
         {"scale", "coarse", "inner", "tol", "maxit"},
         true,
         true,
         &build_cf},
        {"sorcf",
         "sorcf[:scale=...,coarse=...,omega=W,block=0|1] (SOR coarse/fine, 1995; needs the "
         "level below)",
         "",
         {"scale", "coarse", "omega", "block"},
         true,
         true,
         &build_sorcf},
        {"ebe",
         "ebe[:variant=c1|c4|c5,unit=multipliers|contact] (element-by-element, 1997)",
         "",
         {"variant", "unit"},
         true,
         false,
         &build_ebe},
        {"mg",
         "mg[:pre=N,post=N,omega=W,coarse=rediscretize|galerkin|aggregation,csize=N,smooth=S,"
         "precision=double|single,smoother=block|lattice] "
         "(multilevel V-cycle over all levels, vertex-block Gauss-Seidel; on a single level, "
         "or with coarse=aggregation, over an algebraic hierarchy of vertex aggregates coarsened "
         "to at most N = 3000 unknowns, prolongation smoothing S = 4/3; precision=single stores "
         "the smoother's matrices, block inverses and transfers as float, vectors stay double; "
         "smoother=lattice sweeps the interiors of the level-0 triangles of levels 4 and finer "
         "with structured kernels on levels numbered by lattices, --numbering lattice, which it "
         "takes when no numbering is given; the default from level 4 on)",
         "",
         {"pre", "post", "omega", "coarse", "csize", "smooth", "precision", "smoother"},
         true,
         true,
         &build_mg,
         true},
        {"amg",
         "amg[:fn=2,nodal=0,theta=0.25,agg=0] (hypre BoomerAMG V-cycle, for the elastic "
         "block: symmetric positive definite, fn interleaved components per vertex)",
         "",
         {"fn", "nodal", "theta", "agg"},
         false,
         false,
         &build_amg},
        {"mgr",
         "mgr[:frelax=amg|jacobi|gs,fsweeps=N,theta=0.25,interp=2,restrict=0,cg=0,smooth=1,"
         "smoother=16] (hypre MGR on the whole Newton system: global ILU(0) sweep, F = "
         "displacements relaxed by a BoomerAMG V-cycle, C = multipliers, reduced system by "
         "BoomerAMG; any level)",
         "",
         {"frelax", "fsweeps", "theta", "interp", "restrict", "cg", "smooth", "smoother"},
         true,
         false,
         &build_mgr},
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

std::string SpecOptions::get_string(const std::string& key, const std::string& fallback) {
    used_.push_back(key);
    const auto it = spec_.options.find(key);
    return it == spec_.options.end() ? fallback : it->second;
}

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

const PreconditionerEntry* find_preconditioner(std::string_view spec) {
    std::string name(trim(spec.substr(0, spec.find(':'))));
    std::transform(name.begin(), name.end(), name.begin(),
                   [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
    return find_entry(name);
}

std::string preconditioner_names(std::string_view separator) {
    std::string out;
    for (const auto& e : preconditioner_registry())
        out += (out.empty() ? "" : std::string(separator)) + e.name;
    return out;
}

std::unique_ptr<Preconditioner> make_preconditioner(std::string_view spec, const LevelData* level) {
    const PreconditionerSpec parsed = parse_preconditioner_spec(spec);
    const PreconditionerEntry* entry = find_entry(parsed.name);
    MLC_CHECK(entry != nullptr, "unknown preconditioner '" << parsed.name << "' in spec '" << spec
                                                           << "'; valid specs:" << valid_names());
    SpecOptions options(parsed);
    return entry->build(options, level);
}

} // namespace mlc::solvers
