// SPDX-License-Identifier: MIT
// 3D levels before they are built: their sizes predicted from level 0 (unknowns, multipliers,
// nonzeros), the memory of the elastic bench and of a direct solve, and the plan.
#include "core/check.hpp"
#include "levels/elastic3d_detail.hpp"
#include "levels/elastic3d_levels.hpp"
#include "mesh/tet_refine.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

namespace mlc::levels {

using detail::line_edges0;
using detail::sorted_edges;

namespace {

/// Bytes per unit, fitted on the peak resident memory of `bench elastic` on box3d (levels 3
/// and 4) and rounded up.
constexpr double kBaseline3 = 16.0 * (1 << 20);
// The hierarchy: per nonzero of K (its CSR) and per unknown (the DofMap3, loads, the two
// transfers T and R, mesh arrays per vertex folded in).
constexpr double kHierarchyPerNonzero3 = 12.5;
constexpr double kHierarchyPerUnknown3 = 150.0;
// The multigrid over all levels: smoother data and work vectors per unknown and nonzero.
constexpr double kMgPerNonzero3 = 5.0;
constexpr double kMgPerUnknown3 = 50.0;
// BoomerAMG-PCG on the finest level (solvers::boomeramg_elasticity3d): hypre's copy of K and its
// AMG hierarchy.
constexpr double kAmgPerNonzero3 = 40.0;
constexpr double kAmgPerUnknown3 = 0.0;

} // namespace

namespace {

/// What the supports of one displacement component hold on level 0: the supported faces (sorted
/// vertex triples), their edges, the line edges off them (line supports and the tags' tagged
/// lines), every vertex of those, and the point supports' vertices.
struct HeldCells {
    std::set<std::array<int, 3>> faces;
    std::set<std::pair<int, int>> edges;      ///< edges of the faces
    std::set<std::pair<int, int>> line_edges; ///< line edges that are no edges of the faces
    std::set<int> verts;                      ///< vertices of faces and line edges
    std::set<int> points;                     ///< point supports' vertices
    /// Whether the points refinement puts inside level-0 edge (a, b), a < b, are held.
    bool holds_edge(const std::pair<int, int>& e) const {
        return edges.count(e) > 0 || line_edges.count(e) > 0;
    }
};

/// The HeldCells of the components x, y, z.
std::array<HeldCells, 3> held_cells(const ElasticProblem3& p) {
    std::array<HeldCells, 3> out;
    // The level-0 edges of each line support, found once for the three components.
    std::vector<std::vector<std::pair<int, int>>> line_edges_of(p.supports.size());
    const auto has_line = [](const Support3& s) { return s.line.has_value(); };
    if (std::any_of(p.supports.begin(), p.supports.end(), has_line)) {
        const std::vector<std::array<int, 2>> edges0 = sorted_edges(p.mesh0);
        for (size_t k = 0; k < p.supports.size(); ++k)
            if (p.supports[k].line)
                line_edges_of[k] = line_edges0(p.mesh0, edges0, *p.supports[k].line);
    }
    for (int c = 0; c < 3; ++c) {
        HeldCells& h = out[static_cast<size_t>(c)];
        std::set<int> tags;
        std::set<std::pair<int, int>> line_edges;
        for (size_t k = 0; k < p.supports.size(); ++k) {
            const Support3& s = p.supports[k];
            if (!s.u[static_cast<size_t>(c)]) continue;
            if (!s.tag.empty()) {
                const int tag = p.mesh0.tag(s.tag);
                tags.insert(tag);
                for (const mesh::BoundaryEdge& l : p.mesh0.lines) // the tag's lines
                    if (l.tag == tag)
                        line_edges.insert({std::min(l.v0, l.v1), std::max(l.v0, l.v1)});
            } else if (s.line)
                line_edges.insert(line_edges_of[k].begin(), line_edges_of[k].end());
            else
                h.points.insert(p.mesh0.nearest_vertex(*s.point));
        }
        for (const mesh::BoundaryFace& f : p.mesh0.boundary) {
            if (!tags.count(f.tag)) continue;
            std::array<int, 3> k = f.v;
            std::sort(k.begin(), k.end());
            if (!h.faces.insert(k).second) continue;
            h.edges.insert({k[0], k[1]});
            h.edges.insert({k[0], k[2]});
            h.edges.insert({k[1], k[2]});
            h.verts.insert(k.begin(), k.end());
        }
        for (const auto& e : line_edges) {
            if (h.edges.count(e)) continue;
            h.line_edges.insert(e);
            h.verts.insert(e.first);
            h.verts.insert(e.second);
        }
    }
    return out;
}

/// Fixed components on level l: per component, the vertices of the faces whose tags hold it and
/// of the lines that hold it, line supports and the tags' tagged lines (V' = V + E + E_l,
/// E' = 2 E + 3 F, F' = 4 F over those faces, E_l' = 2 E_l over the line edges that are no edges
/// of those faces), and the point supports' vertices (kept by refinement) off them.
std::vector<double> predict_fixed_components(const std::array<HeldCells, 3>& held, int levels) {
    std::vector<double> fixed(static_cast<size_t>(levels) + 1, 0.0);
    for (const HeldCells& h : held) {
        double off = 0;
        for (int v : h.points)
            off += h.verts.count(v) ? 0.0 : 1.0;
        double V = static_cast<double>(h.verts.size()), E = static_cast<double>(h.edges.size()),
               F = static_cast<double>(h.faces.size()),
               El = static_cast<double>(h.line_edges.size());
        for (int l = 0; l <= levels; ++l) {
            fixed[static_cast<size_t>(l)] += V + off;
            const double V1 = V + E + El, E1 = 2 * E + 3 * F, F1 = 4 * F;
            V = V1;
            E = E1;
            F = F1;
            El = 2 * El;
        }
    }
    return fixed;
}

/// Lattice size above which the points of a face cut by a region are counted on this lattice
/// and scaled (predict_multipliers).
constexpr long kMaxCutLattice = 256;

/// A pair's claim on the points of a level-0 edge or face: those inside `region` (every point
/// when null) and outside the regions of the earlier pairs that cut the cell (`earlier`; the
/// points inside them are theirs).
struct Claim {
    const Box3* region = nullptr;
    std::vector<const Box3*> earlier;
    bool holds(const Vec3& x) const {
        if (region && !region->contains(x)) return false;
        for (const Box3* e : earlier)
            if (e->contains(x)) return false;
        return true;
    }
};

/// The points of the n-lattice inside the level-0 edge (a, b) (k = 1 .. n - 1) that `claim`
/// holds.
double edge_points_in(const Vec3& a, const Vec3& b, long n, const Claim& claim) {
    double in = 0;
    for (long k = 1; k < n; ++k) {
        const double t = static_cast<double>(k), u = static_cast<double>(n - k);
        in += claim.holds((u * a + t * b) / static_cast<double>(n)) ? 1.0 : 0.0;
    }
    return in;
}

/// The points of the n-lattice inside the level-0 face (a, b, c) (i, j >= 1, i + j <= n - 1)
/// that `claim` holds: counted on the lattice itself up to kMaxCutLattice, above it on that
/// lattice and scaled to (n - 1)(n - 2) / 2.
double face_points_in(const Vec3& a, const Vec3& b, const Vec3& c, long n, const Claim& claim) {
    const long m = std::min(n, kMaxCutLattice);
    double in = 0;
    for (long i = 1; i < m; ++i)
        for (long j = 1; i + j < m; ++j) {
            const double di = static_cast<double>(i), dj = static_cast<double>(j),
                         dk = static_cast<double>(m - i - j);
            in += claim.holds((dk * a + di * b + dj * c) / static_cast<double>(m)) ? 1.0 : 0.0;
        }
    if (m == n) return in;
    const double total_m = static_cast<double>((m - 1) * (m - 2)) / 2;
    const double total_n = static_cast<double>(n - 1) * static_cast<double>(n - 2) / 2;
    return total_m > 0 ? in / total_m * total_n : 0.0;
}

/// Whether the bounding box of points x misses `box`.
bool misses(const std::vector<Vec3>& x, const Box3& box) {
    Vec3 lo = x.front(), hi = x.front();
    for (const Vec3& q : x) {
        lo = lo.cwiseMin(q);
        hi = hi.cwiseMax(q);
    }
    return (hi.array() < box.lo.array()).any() || (lo.array() > box.hi.array()).any();
}

/// What the pairs so far claimed of a level-0 cell (edge or face): all of it (`whole`: a pair
/// without a region, or whose region holds its vertices), or the points inside the regions
/// that cut it.
struct CellClaims {
    bool whole = false;
    std::vector<const Box3*> cut_by;
};

/// The contact nodes a pair claims inside level-0 cells (edges or faces) with the given
/// vertices, per level 0..levels: `inner(n)` points inside a cell on the n-lattice (n = 2^l),
/// `count(n, claim)` those a claim holds. Cells whose points are all fixed are skipped
/// (`all_fixed`); `claims` records what this pair takes.
template <size_t k, class Inner, class Count, class AllFixed>
void claim_cells(const std::set<std::array<int, k>>& cells, const ContactPair3& pair,
                 const mesh::TetMesh& m0, std::map<std::array<int, k>, CellClaims>& claims,
                 Inner&& inner, Count&& count, AllFixed&& all_fixed, double per_node,
                 std::vector<double>& out) {
    const Box3* region = pair.region ? &*pair.region : nullptr;
    for (const auto& cell : cells) {
        CellClaims& cc = claims[cell];
        if (cc.whole || all_fixed(cell)) continue;
        std::vector<Vec3> x;
        bool all_in = true;
        for (int v : cell) {
            x.push_back(m0.vertices[static_cast<size_t>(v)]);
            all_in = all_in && (!region || region->contains(x.back()));
        }
        if (!all_in && misses(x, *region)) continue;
        const Claim claim{all_in ? nullptr : region, cc.cut_by};
        for (size_t l = 1; l < out.size(); ++l) {
            const long n = 1L << l;
            out[l] +=
                per_node * (claim.region || !claim.earlier.empty() ? count(x, n, claim) : inner(n));
        }
        if (all_in)
            cc.whole = true;
        else
            cc.cut_by.push_back(region);
    }
}

/// Contact multipliers of levels 0..levels (predict_elastic3_sizes): the points of the refined
/// contactor faces, level-0 vertices, edge and face interiors counted apart.
std::vector<double> predict_multipliers(const ElasticProblem3& p, const Level3& L0,
                                        const std::array<HeldCells, 3>& held, int levels) {
    std::vector<double> out(static_cast<size_t>(levels) + 1, 0.0);
    const mesh::TetMesh& m0 = p.mesh0;
    std::map<std::array<int, 2>, CellClaims> edge_claims;
    std::map<std::array<int, 3>, CellClaims> face_claims;
    std::vector<char> taken_vertex(static_cast<size_t>(m0.n_vertices()), 0);
    const auto edge_fixed = [&](const std::array<int, 2>& e) {
        const std::pair<int, int> q{e[0], e[1]};
        return held[0].holds_edge(q) && held[1].holds_edge(q) && held[2].holds_edge(q);
    };
    const auto face_fixed = [&](const std::array<int, 3>& f) {
        return held[0].faces.count(f) && held[1].faces.count(f) && held[2].faces.count(f);
    };
    const auto edge_inner = [](long n) { return static_cast<double>(n - 1); };
    const auto face_inner = [](long n) {
        return static_cast<double>(n - 1) * static_cast<double>(n - 2) / 2;
    };
    const auto edge_count = [](const std::vector<Vec3>& x, long n, const Claim& c) {
        return edge_points_in(x[0], x[1], n, c);
    };
    const auto face_count = [](const std::vector<Vec3>& x, long n, const Claim& c) {
        return face_points_in(x[0], x[1], x[2], n, c);
    };
    for (const ContactPair3& pair : p.contacts) {
        const double per_node = pair.mu > 0 ? 3.0 : 1.0;
        const int tag = m0.tag(pair.contactor);
        std::set<std::array<int, 3>> faces;
        std::set<std::array<int, 2>> edges;
        std::set<int> verts;
        for (const mesh::BoundaryFace& f : m0.boundary) {
            if (f.tag != tag) continue;
            std::array<int, 3> k = f.v;
            std::sort(k.begin(), k.end());
            faces.insert(k);
            edges.insert({k[0], k[1]});
            edges.insert({k[0], k[2]});
            edges.insert({k[1], k[2]});
            verts.insert(k.begin(), k.end());
        }
        // Level-0 vertices: the same on every level.
        double nodes0 = 0;
        for (int v : verts) {
            const std::array<bool, 3>& f = L0.fixed[static_cast<size_t>(v)];
            const bool inside =
                !pair.region || pair.region->contains(m0.vertices[static_cast<size_t>(v)]);
            if (!inside || (f[0] && f[1] && f[2]) || taken_vertex[static_cast<size_t>(v)]) continue;
            taken_vertex[static_cast<size_t>(v)] = 1;
            nodes0 += 1;
        }
        for (double& o : out)
            o += per_node * nodes0;
        claim_cells(edges, pair, m0, edge_claims, edge_inner, edge_count, edge_fixed, per_node,
                    out);
        claim_cells(faces, pair, m0, face_claims, face_inner, face_count, face_fixed, per_node,
                    out);
    }
    return out;
}

} // namespace

std::vector<ElasticLevelSize3> predict_elastic3_sizes(const ElasticProblem3& p, int levels) {
    MLC_CHECK(levels >= 0 && levels <= kMaxLevels3,
              "levels must lie in [0, " << kMaxLevels3 << "], found " << levels);
    const std::vector<mesh::TetLevelSize> ms = mesh::predict_tet_level_sizes(p.mesh0, levels);
    const Level3 L0 = build_level(p, p.mesh0);
    const std::array<HeldCells, 3> held = held_cells(p);
    const std::vector<double> fixed = predict_fixed_components(held, levels);
    const std::vector<double> multipliers = predict_multipliers(p, L0, held, levels);
    const double V0 = ms[0].vertices, E0 = ms[0].edges;
    // The nonzeros the fixed components remove, per fixed component (level 0's ratio).
    const double deficit0 = 9 * (V0 + 2 * E0) - static_cast<double>(L0.elastic.K.nonZeros());
    const double per_fixed = fixed[0] > 0 ? deficit0 / fixed[0] : 0.0;
    std::vector<ElasticLevelSize3> out;
    for (const mesh::TetLevelSize& s : ms) {
        ElasticLevelSize3 e;
        e.level = s.level;
        e.vertices = s.vertices;
        e.edges = s.edges;
        e.tetrahedra = s.tetrahedra;
        const double f = fixed[static_cast<size_t>(s.level)];
        e.unknowns = std::max(0.0, 3 * s.vertices - f);
        e.multipliers = multipliers[static_cast<size_t>(s.level)];
        e.k_nonzeros = std::max(0.0, 9 * (s.vertices + 2 * s.edges) - per_fixed * f);
        out.push_back(e);
    }
    out[0].unknowns = static_cast<double>(L0.dofs.n_displacement_dofs());
    out[0].multipliers = static_cast<double>(L0.dofs.n_dofs() - L0.dofs.n_displacement_dofs());
    out[0].k_nonzeros = static_cast<double>(L0.elastic.K.nonZeros());
    return out;
}

ElasticMemory3 estimate_elastic3_memory(const std::vector<ElasticLevelSize3>& sizes) {
    MLC_CHECK(!sizes.empty(), "estimate_elastic3_memory: no levels");
    ElasticMemory3 e;
    e.baseline_bytes = kBaseline3;
    for (const ElasticLevelSize3& s : sizes) {
        e.hierarchy_bytes +=
            kHierarchyPerNonzero3 * s.k_nonzeros + kHierarchyPerUnknown3 * s.unknowns;
        e.mg_bytes += kMgPerNonzero3 * s.k_nonzeros + kMgPerUnknown3 * s.unknowns;
    }
    // The coarse LU of level 0 (a small multiple of its nonzeros).
    e.mg_bytes += 120.0 * sizes.front().k_nonzeros;
    const ElasticLevelSize3& f = sizes.back();
    e.amg_bytes = kAmgPerNonzero3 * f.k_nonzeros + kAmgPerUnknown3 * f.unknowns;
    return e;
}

ElasticPlan3 plan_elastic3(int finest_level) {
    MLC_CHECK(finest_level >= 0, "a level is >= 0, found " << finest_level);
    ElasticPlan3 p;
    p.multigrid = finest_level >= 1;
    p.reason = p.multigrid ? "mg-CG: in 3D the multigrid beats the direct factor from the first "
                             "refinement on"
                           : "the direct factor: level 0 has no level below for the multigrid";
    return p;
}

double estimate_direct3_bytes(const ElasticLevelSize3& finest) {
    // Factor nonzeros: box3d level 4's, scaled by (n / n4)^1.394, the exponent of levels 3 to 4.
    constexpr double kFactorNonzeros4 = 5.4e8, kUnknowns4 = 405600, kExponent = 1.394;
    constexpr double kBytesPerFactorNonzero = 12, kBytesPerKNonzero = 24;
    const double factor =
        kFactorNonzeros4 * std::pow(std::max(finest.unknowns, 1.0) / kUnknowns4, kExponent);
    return kBytesPerFactorNonzero * factor + kBytesPerKNonzero * finest.k_nonzeros;
}

void check_elastic3_fits(const ElasticMemory3& e, const MemoryLimit& limit,
                         const std::vector<ElasticLevelSize3>& sizes) {
    if (e.bytes() <= limit.bytes) return;
    const ElasticLevelSize3& f = sizes.back();
    std::ostringstream os;
    os << std::setprecision(3) << "the 3D elastic bench needs an estimated "
       << format_bytes(e.bytes()) << " (finest level " << f.level << ": " << f.unknowns
       << " unknowns, " << f.k_nonzeros << " nonzeros of K; multigrid " << format_bytes(e.mg_peak())
       << ", BoomerAMG-PCG " << format_bytes(e.amg_peak()) << ") but this process may use "
       << format_bytes(std::max(0.0, limit.bytes)) << " (" << limit.source
       << "): use fewer --levels";
    throw InvalidInput(os.str());
}

} // namespace mlc::levels
