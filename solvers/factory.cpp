// SPDX-License-Identifier: MIT
// The preconditioner registry: one row per name with its options, capabilities and builder.
#include "solvers/factory.hpp"

#include "core/check.hpp"
#include "smoothers/block_sor.hpp"
#include "smoothers/iluk.hpp"
#include "smoothers/jacobi.hpp"
#include "solvers/direct.hpp"
#include "solvers/hypre/boomeramg.hpp"
#include "solvers/hypre/mgr.hpp"
#include "solvers/sorcf.hpp"

#include <sstream>

namespace mlc::solvers {

namespace {

std::unique_ptr<Preconditioner> build_none(const PcOptions&, const LevelData*) {
    return std::make_unique<IdentityPreconditioner>();
}

std::unique_ptr<Preconditioner> build_diag(const PcOptions&, const LevelData*) {
    return std::make_unique<smoothers::Jacobi>();
}

std::unique_ptr<Preconditioner> build_ilu(const PcOptions& o, const LevelData*) {
    smoothers::ILUKParams p;
    p.fill_level = std::get<IluOptions>(o).k;
    return std::make_unique<smoothers::ILUK>(p);
}

std::unique_ptr<Preconditioner> build_sor_with(const PcOptions& o, smoothers::Sweep sweep) {
    const SorOptions& s = std::get<SorOptions>(o);
    smoothers::BlockSORParams p;
    p.sweep = sweep;
    p.omega = s.omega;
    p.n_sweeps = s.sweeps;
    p.block_size = s.block;
    return std::make_unique<smoothers::BlockSOR>(p);
}

std::unique_ptr<Preconditioner> build_sor(const PcOptions& o, const LevelData*) {
    return build_sor_with(o, smoothers::Sweep::forward);
}

std::unique_ptr<Preconditioner> build_ssor(const PcOptions& o, const LevelData*) {
    return build_sor_with(o, smoothers::Sweep::symmetric);
}

std::unique_ptr<Preconditioner> build_lu(const PcOptions&, const LevelData*) {
    return std::make_unique<SparseLUPreconditioner>();
}

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

CoarseFineInputs coarse_fine_inputs(MultiplierScale scale, CoarseSource coarse,
                                    const LevelData& level) {
    CoarseFineInputs in;
    in.coarse = coarse == CoarseSource::lu ? level.coarse_lu() : level.coarse_solver;
    in.split = level.coarse_fine_split(scale);
    return in;
}

std::unique_ptr<Preconditioner> build_cf(const PcOptions& o, const LevelData* level) {
    const LevelData& L = require_level(level, "cf", true);
    const CfOptions& c = std::get<CfOptions>(o);
    CoarseFineInputs in = coarse_fine_inputs(c.scale, c.coarse, L);
    return make_coarse_fine(std::move(in.split), std::move(in.coarse), c.params);
}

std::unique_ptr<Preconditioner> build_sorcf(const PcOptions& o, const LevelData* level) {
    const LevelData& L = require_level(level, "sorcf", true);
    const SorcfOptions& c = std::get<SorcfOptions>(o);
    CoarseFineInputs in = coarse_fine_inputs(c.scale, c.coarse, L);
    return make_sorcf(std::move(in.split), std::move(in.coarse), c.params);
}

std::unique_ptr<Preconditioner> build_ebe(const PcOptions& o, const LevelData* level) {
    const LevelData& L = require_level(level, "ebe", false);
    return std::make_unique<smoothers::EBE>(*L.elements(), std::get<EbeOptions>(o).params);
}

std::unique_ptr<Preconditioner> build_mg(const PcOptions& o, const LevelData* level) {
    const LevelData& L = require_level(level, "mg", false);
    const MgOptions& m = std::get<MgOptions>(o);
    const MultigridParams p = m.cycle();
    p.validate();
    // Without the level below, the algebraic hierarchy (aggregation) is the only one there is.
    const bool below = L.has_level_below;
    const MgCoarse coarse = m.coarse != MgCoarse::automatic ? m.coarse
                            : below                         ? MgCoarse::rediscretize
                                                            : MgCoarse::aggregation;
    MultigridLevelData top = L.top;
    if (p.smoother == MultigridParams::Smoother::lattice) {
        MLC_CHECK(coarse != MgCoarse::aggregation,
                  "mg:smoother=lattice needs the refined levels (their macro triangles); an "
                  "algebraic hierarchy (coarse=aggregation, or a mesh without levels) has none");
        // Levels below 4 (or not refined from level 0) keep the block smoother; the planner
        // refuses the option when the finest level is below 4.
        if (L.top_lattice) top.lattice = L.top_lattice();
    }
    if (coarse == MgCoarse::aggregation) {
        m.aggregation.validate();
        MLC_CHECK(L.aggregation != nullptr,
                  "mg needs the level below (use with --levels >= 1 and the coarse-to-fine "
                  "solve) or the level's unknowns for its algebraic hierarchy, and the level "
                  "data gives neither");
        const AggregationInput in = L.aggregation();
        return std::make_unique<Multigrid>(aggregation_levels(in, m.aggregation), p,
                                           CoarseOperators::galerkin);
    }
    MLC_CHECK(below, "mg needs the level below for coarse="
                         << (coarse == MgCoarse::galerkin ? "galerkin" : "rediscretize")
                         << ": use with --levels >= 1 and the coarse-to-fine solve, or "
                            "coarse=aggregation");
    if (coarse == MgCoarse::galerkin) {
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

std::unique_ptr<Preconditioner> build_amg(const PcOptions& o, const LevelData* level) {
    MLC_CHECK(level == nullptr || !level->has_multipliers,
              "amg (hypre BoomerAMG) preconditions the elastic block only (symmetric "
              "positive definite); the contact Jacobian has zero multiplier "
              "diagonals: use --pc mg, or compare on the elastic block with "
              "`mlcontact bench elastic`");
    const AmgOptions& p = std::get<AmgOptions>(o);
    p.validate();
    return std::make_unique<BoomerAMGPreconditioner>(p);
}

// hypre MGR on the whole Newton system: F = displacements (AMG on A_FF), C = multipliers.
std::unique_ptr<Preconditioner> build_mgr(const PcOptions& o, const LevelData* level) {
    const LevelData& L = require_level(level, "mgr", false);
    const MgrOptions& p = std::get<MgrOptions>(o);
    p.validate();
    MLC_CHECK(L.unknown_functions != nullptr,
              "mgr: the level data gives no unknown functions (C/F split)");
    return std::make_unique<MGRPreconditioner>(L.unknown_functions(), p);
}

// The option keys of each entry, in the order of its usage line and canonical text.
void sor_fields(PcOptions& o, PcFields& f) {
    SorOptions& s = std::get<SorOptions>(o);
    f.real("omega", s.omega);
    f.integer("sweeps", s.sweeps);
    f.integer("block", s.block, "B");
}

void coarse_fine_fields(MultiplierScale& scale, CoarseSource& coarse, PcFields& f) {
    f.choice("scale", scale, {"q", "none", "qt", "qinv"});
    f.choice("coarse", coarse, {"lu", "solver"});
}

void cf_fields(PcOptions& o, PcFields& f) {
    CfOptions& c = std::get<CfOptions>(o);
    coarse_fine_fields(c.scale, c.coarse, f);
    f.choice("inner", c.params.inner, {"lu", "cgs"});
    f.real("tol", c.params.inner_tol, "T");
    f.integer("maxit", c.params.inner_max_iter);
}

void sorcf_fields(PcOptions& o, PcFields& f) {
    SorcfOptions& c = std::get<SorcfOptions>(o);
    coarse_fine_fields(c.scale, c.coarse, f);
    f.real("omega", c.params.omega);
    f.flag("block", c.params.block);
}

void ebe_fields(PcOptions& o, PcFields& f) {
    smoothers::EBEParams& p = std::get<EbeOptions>(o).params;
    f.choice("variant", p.variant, {"c1", "c4", "c5"});
    f.choice("unit", p.unit_scaling, {"contact", "multipliers"});
}

void mg_fields(PcOptions& o, PcFields& f) {
    MgOptions& m = std::get<MgOptions>(o);
    f.real("omega", m.omega);
    f.integer("pre", m.pre);
    f.integer("post", m.post);
    // automatic has no name: it prints nothing and is what an absent key means.
    int coarse = static_cast<int>(m.coarse);
    f.choice("coarse", coarse,
             {{"rediscretize", static_cast<int>(MgCoarse::rediscretize)},
              {"galerkin", static_cast<int>(MgCoarse::galerkin)},
              {"aggregation", static_cast<int>(MgCoarse::aggregation)}});
    m.coarse = static_cast<MgCoarse>(coarse);
    f.integer("csize", m.aggregation.coarse_size);
    f.real("smooth", m.aggregation.smoothing, "S");
    f.choice("precision", m.precision, {"double", "single"});
    f.choice("smoother", m.smoother, {"block", "lattice"});
}

void amg_fields(PcOptions& o, PcFields& f) {
    AmgOptions& p = std::get<AmgOptions>(o);
    f.integer("fn", p.num_functions);
    f.integer("nodal", p.nodal);
    f.real("theta", p.strong_threshold);
    f.integer("agg", p.agg_num_levels);
}

void mgr_fields(PcOptions& o, PcFields& f) {
    MgrOptions& p = std::get<MgrOptions>(o);
    f.choice("frelax", p.f_relax, {{"amg", 2}, {"jacobi", 0}, {"gs", 3}});
    f.integer("fsweeps", p.f_sweeps);
    f.real("theta", p.f_amg.strong_threshold);
    f.integer("interp", p.interp_type);
    f.integer("restrict", p.restrict_type);
    f.integer("cg", p.coarse_method);
    f.integer("smooth", p.global_smooth_iters);
    f.integer("smoother", p.global_smooth_type);
}

// Runs on each process's diagonal block: a preconditioner of the matrix alone, or ebe.
std::string everywhere(const PcOptions&) {
    return {};
}

// What of mg runs on several processes: the rediscretized V-cycle with any pre, post and omega,
// block or lattice sweeps, double or single precision on each process's diagonal block (not
// lattice and single together, which one process refuses as well). Widen here as the
// distributed multigrid grows.
std::string mg_distributed(const PcOptions& o) {
    const MgOptions& m = std::get<MgOptions>(o);
    const MgOptions d;
    if (m.coarse != MgCoarse::automatic && m.coarse != MgCoarse::rediscretize)
        return "mg:coarse=" +
               std::string(m.coarse == MgCoarse::galerkin ? "galerkin" : "aggregation") +
               " has no distributed form; on several processes mg rediscretizes "
               "(coarse=rediscretize)";
    if (m.aggregation.coarse_size != d.aggregation.coarse_size ||
        m.aggregation.smoothing != d.aggregation.smoothing)
        return "mg:csize and mg:smooth shape the aggregation hierarchy, which has no distributed "
               "form; on several processes mg rediscretizes (drop them)";
    if (m.precision == Precision::float32 && m.smoother == MultigridParams::Smoother::lattice)
        return "mg: smoother=lattice keeps double data; precision=single is for smoother=block";
    return {};
}

std::string mg_dimensions(const PcOptions& o, int dim) {
    if (dim == 3 && std::get<MgOptions>(o).smoother == MultigridParams::Smoother::lattice)
        return "mg:smoother=lattice sweeps the lattices of 2D macro triangles (2D-only); a 3D "
               "level is swept by vertex blocks (smoother=block, the default)";
    return "";
}

std::string ebe_dimensions(const PcOptions&, int dim) {
    if (dim == 3)
        return "ebe factors the element matrices of triangles (2D-only); on a 3D level use mg, or "
               "a preconditioner of the matrix alone (ilu, sor, ...)";
    return "";
}

std::string amg_dimensions(const PcOptions& o, int dim) {
    const int fn = std::get<AmgOptions>(o).num_functions;
    if (fn != 1 && fn != dim)
        return "amg:fn=" + std::to_string(fn) + " groups " + std::to_string(fn) +
               " interleaved components per vertex, but a level of " + std::to_string(dim) +
               " dimensions has " + std::to_string(dim) + ": amg:fn=" + std::to_string(dim);
    return "";
}

bool mg_lattice(const PcOptions& o) {
    return std::get<MgOptions>(o).smoother == MultigridParams::Smoother::lattice;
}

// Each row names only what differs from PreconditionerEntry's defaults; GCC 12 warns about
// the members a designated initializer leaves to their default values.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
std::deque<PreconditionerEntry> builtin_entries() {
    std::deque<PreconditionerEntry> t;
    t.push_back({.name = "none",
                 .summary = "identity",
                 .defaults = NoOptions{},
                 .fields = [](PcOptions&, PcFields&) {},
                 .build = &build_none,
                 .distributed = &everywhere});
    t.push_back({.name = "diag",
                 .summary = "Jacobi; zero diagonals patched",
                 .defaults = NoOptions{},
                 .fields = [](PcOptions&, PcFields&) {},
                 .build = &build_diag,
                 .distributed = &everywhere});
    t.push_back({.name = "ilu",
                 .summary = "ILU(K), fill level K >= 0, default 0",
                 .positional_key = "k",
                 .defaults = IluOptions{},
                 .fields = [](PcOptions& o,
                              PcFields& f) { f.integer("k", std::get<IluOptions>(o).k, "K"); },
                 .build = &build_ilu,
                 .distributed = &everywhere});
    t.push_back({.name = "sor",
                 .summary = "forward SOR, 0 < W < 2, defaults 1, 1, 1",
                 .defaults = SorOptions{},
                 .fields = &sor_fields,
                 .build = &build_sor,
                 .distributed = &everywhere});
    t.push_back({.name = "ssor",
                 .summary = "symmetric SOR, same options",
                 .defaults = SorOptions{},
                 .fields = &sor_fields,
                 .build = &build_ssor,
                 .distributed = &everywhere});
    t.push_back({.name = "lu",
                 .summary = "sparse direct LU",
                 .defaults = NoOptions{},
                 .fields = [](PcOptions&, PcFields&) {},
                 .build = &build_lu,
                 .distributed = &everywhere});
    t.push_back({.name = "cf",
                 .summary = "coarse/fine, 1995; needs the level below",
                 .defaults = CfOptions{},
                 .fields = &cf_fields,
                 .build = &build_cf,
                 .level_aware = true,
                 .needs_level_below = true});
    t.push_back({.name = "sorcf",
                 .summary = "SOR coarse/fine, 1995; needs the level below",
                 .defaults = SorcfOptions{},
                 .fields = &sorcf_fields,
                 .build = &build_sorcf,
                 .level_aware = true,
                 .needs_level_below = true});
    t.push_back({.name = "ebe",
                 .summary = "element-by-element, 1997",
                 .defaults = EbeOptions{},
                 .fields = &ebe_fields,
                 .build = &build_ebe,
                 .level_aware = true,
                 .element_matrices = true,
                 .distributed = &everywhere,
                 .dimensions = &ebe_dimensions});
    t.push_back(
        {.name = "mg",
         .summary =
             "multilevel V-cycle over all levels, vertex-block Gauss-Seidel; on a single level, "
             "or with coarse=aggregation, over an algebraic hierarchy of vertex aggregates "
             "coarsened to at most N = 3000 unknowns, prolongation smoothing S = 4/3; "
             "precision=single stores the smoother's matrices, block inverses and transfers as "
             "float, vectors stay double; smoother=lattice sweeps the interiors of the level-0 "
             "triangles of levels 4 and finer with structured kernels on levels numbered by "
             "lattices, --numbering lattice, which it takes when no numbering is given; the "
             "default from level 4 on",
         .defaults = MgOptions{},
         .fields = &mg_fields,
         .build = &build_mg,
         .level_aware = true,
         .needs_level_below = true,
         .single_level_too = true,
         .lattice_numbering = &mg_lattice,
         .distributed = &mg_distributed,
         .dimensions = &mg_dimensions});
    t.push_back({.name = "amg",
                 .summary = "hypre BoomerAMG V-cycle, for the elastic block: symmetric positive "
                            "definite, fn interleaved components per vertex",
                 .defaults = AmgOptions{},
                 .fields = &amg_fields,
                 .build = &build_amg,
                 .distributed = &everywhere,
                 .dimensions = &amg_dimensions});
    t.push_back({.name = "mgr",
                 .summary = "hypre MGR on the whole Newton system: global ILU(0) sweep, F = "
                            "displacements relaxed by a BoomerAMG V-cycle, C = multipliers, "
                            "reduced system by BoomerAMG; any level",
                 .defaults = MgrOptions{},
                 .fields = &mgr_fields,
                 .build = &build_mgr,
                 .level_aware = true});
    return t;
}
#pragma GCC diagnostic pop

std::deque<PreconditionerEntry>& registry() {
    static std::deque<PreconditionerEntry> table = builtin_entries();
    return table;
}

} // namespace

const std::deque<PreconditionerEntry>& preconditioner_registry() {
    return registry();
}

const PreconditionerEntry& register_preconditioner(PreconditionerEntry entry) {
    MLC_CHECK(!entry.name.empty(), "register_preconditioner: an entry without a name");
    for (char c : entry.name)
        MLC_CHECK(!(c >= 'A' && c <= 'Z') && c != ':' && c != ',' && c != '=' && c != ' ',
                  "register_preconditioner: the name '"
                      << entry.name << "' must be lower case without ':', ',', '=' or spaces");
    MLC_CHECK(preconditioner_entry(entry.name) == nullptr,
              "register_preconditioner: the name '" << entry.name << "' is taken");
    MLC_CHECK(!entry.summary.empty() && entry.fields && entry.build,
              "register_preconditioner: '" << entry.name
                                           << "' needs a summary, a fields function (its parser "
                                              "and usage) and a build function");
    registry().push_back(std::move(entry));
    return registry().back();
}

std::unique_ptr<Preconditioner> make_preconditioner(const PcSpec& spec, const LevelData* level) {
    MLC_CHECK(spec.entry != nullptr, "make_preconditioner: an empty preconditioner spec");
    return spec.entry->build(spec.options, level);
}

std::unique_ptr<Preconditioner> make_preconditioner(std::string_view text, const LevelData* level) {
    return make_preconditioner(parse_pc(text), level);
}

} // namespace mlc::solvers
