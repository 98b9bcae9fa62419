// SPDX-License-Identifier: MIT
// 3D elastic levels: sizes and memory predicted from level 0, the levels and transfers, and the
// multigrid on them.
#include "levels/elastic3d_levels.hpp"

#include "core/check.hpp"
#include "fem/assembly.hpp"
#include "mesh/tet_refine.hpp"
#include "solvers/pc_spec.hpp"
#include "transfer/prolongation.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

namespace mlc::levels {

namespace {

/// Relative distance under which a support point is a vertex, or a vertex on a support line.
constexpr double kPointTol = 1e-9;

/// The support's vertices on mesh m (a tag's faces and lines, the line's, or the point's
/// level-0 vertex).
std::vector<int> support_vertices(const ElasticProblem3& p, const Support3& s,
                                  const mesh::TetMesh& m) {
    if (!s.tag.empty()) return m.vertices_on_tag(m.tag(s.tag)); // its faces' and lines'

    if (s.line) {
        std::vector<int> v = line_vertices(m, *s.line);
        std::sort(v.begin(), v.end());
        return v;
    }
    return {p.mesh0.nearest_vertex(*s.point)};
}

/// "(x, y, z)".
std::string point_text(const Vec3& x) {
    std::ostringstream os;
    os << "(" << x.x() << ", " << x.y() << ", " << x.z() << ")";
    return os.str();
}

/// The edges of m (mesh::tet_edges, smaller vertex first), sorted.
std::vector<std::array<int, 2>> sorted_edges(const mesh::TetMesh& m) {
    std::vector<std::array<int, 2>> e = mesh::tet_edges(m).edges;
    std::sort(e.begin(), e.end());
    return e;
}

/// Throws InvalidInput unless x is a vertex of the level-0 mesh m0 (within kPointTol of its
/// diameter); `what` names x in the message ("support point", "support line: its end").
void check_vertex0(const mesh::TetMesh& m0, const Vec3& x, const std::string& what) {
    const int v = m0.nearest_vertex(x);
    const double d = (m0.vertices[static_cast<size_t>(v)] - x).norm();
    MLC_CHECK(d <= kPointTol * m0.diameter(),
              what << " " << point_text(x) << " is no vertex of the level-0 mesh (the nearest "
                   << "vertex lies " << d << " away)");
}

/// The level-0 edges of a line support (pairs of vertices, smaller first), after checking that
/// its ends are level-0 vertices and its segment runs along level-0 edges (`edges`: those of
/// sorted_edges(m0)).
std::vector<std::pair<int, int>> line_edges0(const mesh::TetMesh& m0,
                                             const std::vector<std::array<int, 2>>& edges,
                                             const std::array<Vec3, 2>& line) {
    for (const Vec3& x : line)
        check_vertex0(m0, x, "support line: its end");
    MLC_CHECK((line[1] - line[0]).norm() > kPointTol * m0.diameter(),
              "support line: its two ends are the same point " << point_text(line[0]));
    const std::vector<int> on = line_vertices(m0, line);
    std::vector<std::pair<int, int>> out;
    for (size_t k = 0; k + 1 < on.size(); ++k) {
        const auto [a, b] = std::minmax(on[k], on[k + 1]);
        MLC_CHECK(std::binary_search(edges.begin(), edges.end(), std::array<int, 2>{a, b}),
                  "support line from "
                      << point_text(line[0]) << " to " << point_text(line[1])
                      << " does not run along edges of the level-0 mesh: its vertices "
                      << point_text(m0.vertices[static_cast<size_t>(on[k])]) << " and "
                      << point_text(m0.vertices[static_cast<size_t>(on[k + 1])])
                      << " are not joined by an edge");
        out.emplace_back(a, b);
    }
    return out;
}

} // namespace

std::vector<int> line_vertices(const mesh::TetMesh& m, const std::array<Vec3, 2>& line) {
    const double tol = kPointTol * m.diameter();
    const Vec3 d = line[1] - line[0];
    const double len2 = d.squaredNorm();
    std::vector<std::pair<double, int>> on;
    for (int v = 0; v < m.n_vertices(); ++v) {
        const Vec3 x = m.vertices[static_cast<size_t>(v)] - line[0];
        const double s = len2 > 0 ? x.dot(d) / len2 : 0.0;
        if (s < -tol || s > 1 + tol) continue;
        if ((x - s * d).norm() <= tol) on.push_back({s, v});
    }
    std::sort(on.begin(), on.end());
    std::vector<int> out;
    for (const auto& [s, v] : on)
        out.push_back(v);
    return out;
}

void ElasticProblem3::validate() const {
    MLC_CHECK(!bodies.empty(), "the 3D problem has no body");
    MLC_CHECK(levels >= 0 && levels <= kMaxLevels3,
              "levels must lie in [0, " << kMaxLevels3 << "], found " << levels);
    MLC_CHECK(mesh0.n_cells() > 0, "the 3D problem's mesh has no tetrahedra");
    for (size_t t = 0; t < mesh0.attribute.size(); ++t)
        MLC_CHECK(mesh0.attribute[t] >= 0 && mesh0.attribute[t] < static_cast<int>(bodies.size()),
                  "tetrahedron " << t << " belongs to body " << mesh0.attribute[t] << ", but "
                                 << bodies.size() << " bodies are given");
    for (const Body3& b : bodies) {
        b.material.validate();
        MLC_CHECK(b.material.plane == fem::Plane::strain,
                  "body '" << b.name << "': plane stress is a 2D reduction");
        MLC_CHECK(b.body_force.allFinite(), "body '" << b.name << "': body force not finite");
    }
    for (const FaceLoad3& l : loads) {
        MLC_CHECK(mesh0.find_tag(l.tag) && mesh0.is_boundary_tag(mesh0.tag(l.tag)),
                  "load: no boundary face carries the tag '" << l.tag << "'");
        MLC_CHECK(std::isfinite(l.pressure) && l.traction.allFinite(),
                  "load on '" << l.tag << "' is not finite");
    }
    for (const Support3& s : supports) {
        MLC_CHECK(s.u[0] || s.u[1] || s.u[2], "a support fixes nothing: give ux, uy and/or uz");
        MLC_CHECK(int(!s.tag.empty()) + int(s.point.has_value()) + int(s.line.has_value()) == 1,
                  "a support takes one of a tag, a line or a point");
        if (s.line) {
            line_edges0(mesh0, sorted_edges(mesh0), *s.line);
        } else if (!s.tag.empty()) {
            const auto id = mesh0.find_tag(s.tag);
            MLC_CHECK(id && !mesh0.vertices_on_tag(*id).empty(),
                      "support: no boundary face or line carries the tag '" << s.tag << "'");
        } else {
            check_vertex0(mesh0, *s.point, "support point");
        }
    }
}

// ------------------------------------------------------------------------------------------

Level3 build_level(const ElasticProblem3& p, mesh::TetMesh m) {
    Level3 L;
    std::vector<fem::VertexSupport3> vs;
    for (const Support3& s : p.supports) {
        fem::VertexSupport3 v;
        v.vertices = support_vertices(p, s, m);
        for (int c = 0; c < 3; ++c) {
            v.components[static_cast<size_t>(c)] = s.u[static_cast<size_t>(c)].has_value();
            v.value[c] = s.u[static_cast<size_t>(c)].value_or(0.0);
        }
        vs.push_back(std::move(v));
    }
    fem::Supports3 sup = fem::collect_supports(m, vs);
    L.fixed = std::move(sup.fixed);
    L.dofs = fem::DofMap3(L.fixed, std::vector<int>(static_cast<size_t>(m.n_vertices()), 0));
    L.u_fixed = std::move(sup.u_fixed);
    std::vector<fem::Traction3> tr;
    for (const FaceLoad3& l : p.loads)
        tr.push_back({m.tag(l.tag), l.pressure, l.traction});
    std::vector<Vec3> bf;
    bool any_force = false;
    for (const Body3& b : p.bodies) {
        bf.push_back(b.body_force);
        L.materials.push_back(b.material);
        any_force = any_force || !b.body_force.isZero(0.0);
    }
    const Vector F = fem::nodal_loads(m, tr, any_force ? bf : std::vector<Vec3>{});
    L.elastic = fem::assemble_elastic(m, L.materials, L.dofs, F, L.u_fixed);
    L.mesh = std::move(m);
    return L;
}

Hierarchy3 build_hierarchy(const ElasticProblem3& p, int levels) {
    p.validate();
    MLC_CHECK(levels >= 0 && levels <= kMaxLevels3,
              "levels must lie in [0, " << kMaxLevels3 << "], found " << levels);
    Hierarchy3 h;
    h.levels.push_back(build_level(p, p.mesh0));
    for (int l = 1; l <= levels; ++l) {
        mesh::TetMesh fine = mesh::refine(h.levels.back().mesh);
        mesh::check_refined_quality(fine);
        transfer::LevelTransfer t;
        t.P_vertex = transfer::vertex_prolongation(fine);
        Level3 L = build_level(p, std::move(fine));
        const Level3& C = h.levels.back();
        t.T = transfer::restrict_to_unknowns(
            t.P_vertex, 3, transfer::vertex_unknowns(C.dofs, 3), static_cast<int>(C.dofs.n_dofs()),
            transfer::vertex_unknowns(L.dofs, 3), static_cast<int>(L.dofs.n_dofs()));
        t.R = SparseMatrix(t.T.transpose());
        h.transfers.push_back(std::move(t));
        h.levels.push_back(std::move(L));
    }
    return h;
}

std::unique_ptr<solvers::Multigrid> elastic3_multigrid(const Hierarchy3& h,
                                                       solvers::MultigridParams params) {
    MLC_CHECK(h.levels.size() >= 2,
              "the 3D multigrid needs at least two levels (levels >= 1), found "
                  << h.levels.size());
    // What runs in 3D is the registry's to say (PreconditionerEntry::dimensions).
    solvers::MgOptions as_mg;
    as_mg.smoother = params.smoother;
    const std::string why = solvers::preconditioner_entry("mg")->dimension_reason(as_mg, 3);
    MLC_CHECK(why.empty(), why);
    const size_t n = h.levels.size();
    std::vector<solvers::MultigridLevelData> data(n);
    for (size_t l = 0; l < n; ++l) {
        if (l > 0) {
            data[l].T = &h.transfers[l - 1].T;
            data[l].R = &h.transfers[l - 1].R;
        }
        data[l].block_starts = solvers::vertex_block_starts(h.levels[l].vertex_of_dof());
    }
    auto mg = std::make_unique<solvers::Multigrid>(std::move(data), params);
    for (size_t l = 0; l + 1 < n; ++l)
        mg->set_operator(static_cast<int>(l), h.levels[l].elastic.K);
    mg->setup(h.levels[n - 1].elastic.K);
    return mg;
}

solvers::MultigridParams elastic3_mg_params() {
    solvers::MultigridParams p;
    p.pre_sweeps = 2;
    p.post_sweeps = 2;
    p.cycles = 2;
    return p;
}

std::unique_ptr<solvers::Multigrid> elastic3_multigrid(const Hierarchy3& h) {
    return elastic3_multigrid(h, elastic3_mg_params());
}

std::vector<Vector> rigid_body_modes3(const Level3& L) {
    const mesh::TetMesh& m = L.mesh;
    Vec3 lo = m.vertices.front(), hi = m.vertices.front();
    for (const Vec3& x : m.vertices) {
        lo = lo.cwiseMin(x);
        hi = hi.cwiseMax(x);
    }
    const Vec3 c = 0.5 * (lo + hi);
    std::vector<Vector> modes(6, Vector::Zero(L.dofs.n_dofs()));
    for (int v = 0; v < m.n_vertices(); ++v) {
        const Vec3 r = m.vertices[static_cast<size_t>(v)] - c;
        for (int k = 0; k < 3; ++k) {
            // Rotation about axis k: e_k x r.
            const Vec3 rot = Vec3::Unit(k).cross(r);
            for (int comp = 0; comp < 3; ++comp) {
                const int d = L.dofs.u_dof(v, comp);
                if (d < 0) continue;
                modes[static_cast<size_t>(k)][d] = comp == k ? 1.0 : 0.0;
                modes[static_cast<size_t>(3 + k)][d] = rot[comp];
            }
        }
    }
    return modes;
}

// ------------------------------------------------------------------------------------------
// Sizes and memory.

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

/// Fixed components on level l: per component, the vertices of the faces whose tags hold it and
/// of the lines that hold it, line supports and the tags' tagged lines (V' = V + E + E_l,
/// E' = 2 E + 3 F, F' = 4 F over those faces, E_l' = 2 E_l over the line edges that are no edges
/// of those faces), and the point supports' vertices (kept by refinement) off them.
std::vector<double> predict_fixed_components(const ElasticProblem3& p, int levels) {
    std::vector<double> fixed(static_cast<size_t>(levels) + 1, 0.0);
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
        std::set<int> tags;
        std::set<int> points;
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
                points.insert(p.mesh0.nearest_vertex(*s.point));
        }
        std::set<std::array<int, 3>> faces;
        std::set<std::pair<int, int>> edges;
        std::set<int> verts;
        for (const mesh::BoundaryFace& f : p.mesh0.boundary) {
            if (!tags.count(f.tag)) continue;
            std::array<int, 3> k = f.v;
            std::sort(k.begin(), k.end());
            if (!faces.insert(k).second) continue;
            edges.insert({k[0], k[1]});
            edges.insert({k[0], k[2]});
            edges.insert({k[1], k[2]});
            verts.insert(k.begin(), k.end());
        }
        double El = 0;
        for (const auto& e : line_edges) {
            if (edges.count(e)) continue;
            El += 1;
            verts.insert(e.first);
            verts.insert(e.second);
        }
        double off = 0;
        for (int v : points)
            off += verts.count(v) ? 0.0 : 1.0;
        double V = static_cast<double>(verts.size()), E = static_cast<double>(edges.size()),
               F = static_cast<double>(faces.size());
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

} // namespace

std::vector<ElasticLevelSize3> predict_elastic3_sizes(const ElasticProblem3& p, int levels) {
    MLC_CHECK(levels >= 0 && levels <= kMaxLevels3,
              "levels must lie in [0, " << kMaxLevels3 << "], found " << levels);
    const std::vector<mesh::TetLevelSize> ms = mesh::predict_tet_level_sizes(p.mesh0, levels);
    const Level3 L0 = build_level(p, p.mesh0);
    const std::vector<double> fixed = predict_fixed_components(p, levels);
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
        e.k_nonzeros = std::max(0.0, 9 * (s.vertices + 2 * s.edges) - per_fixed * f);
        out.push_back(e);
    }
    out[0].unknowns = static_cast<double>(L0.dofs.n_dofs());
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
