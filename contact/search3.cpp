// SPDX-License-Identifier: MIT
// 3D contact search on the reference configuration: closest target triangles (node on facet)
// and coincident target vertices (node on node), the triangles in CGAL's AABB tree (or scanned
// linearly in a build without CGAL).
#include "contact/search3.hpp"

#include "contact/mortar3.hpp"

#include "core/check.hpp"

#include <Eigen/Geometry>

#ifdef MLC_HAVE_CGAL
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <iterator>
#endif

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <unordered_map>

namespace mlc::contact {

using mesh::Vec3;

namespace {

/// "(x, y, z)".
std::string search3_point(const Vec3& p) {
    std::ostringstream os;
    os << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
    return os.str();
}

/// The key of the unoriented edge (a, b).
std::uint64_t search3_edge_key(int a, int b) {
    if (a > b) std::swap(a, b);
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
           static_cast<std::uint32_t>(b);
}

/// Longest edge of the triangle (a, b, c).
double search3_longest_edge(const Vec3& a, const Vec3& b, const Vec3& c) {
    return std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
}

/// Whether the triangle (a, b, c) is degenerate (kDegenerateTriangleTol).
bool search3_degenerate(const Vec3& a, const Vec3& b, const Vec3& c) {
    const double L = search3_longest_edge(a, b, c);
    return !((b - a).cross(c - a).norm() > kDegenerateTriangleTol * L * L);
}

/// The closest point of the triangle (a, b, c) to x (Ericson 2005, 5.1.5), with the unit
/// normal n of the triangle; the triangle is not degenerate.
TriangleProjection search3_project(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& c,
                                   const Vec3& n) {
    TriangleProjection p;
    p.n = n;
    auto at_vertex = [&](int k) {
        p.where = TriangleFeature::vertex;
        p.feature = k;
        p.bary = {0.0, 0.0, 0.0};
        p.bary[static_cast<size_t>(k)] = 1.0;
    };
    // On the edge opposite vertex k, at s from its first end (k + 1) toward its second (k + 2).
    auto on_edge = [&](int k, double s) {
        p.where = TriangleFeature::edge;
        p.feature = k;
        p.bary[static_cast<size_t>(k)] = 0.0;
        p.bary[static_cast<size_t>((k + 1) % 3)] = 1.0 - s;
        p.bary[static_cast<size_t>((k + 2) % 3)] = s;
    };
    const Vec3 ab = b - a, ac = c - a, ap = x - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    const Vec3 bp = x - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    const Vec3 cp = x - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    const double vc = d1 * d4 - d3 * d2;
    const double vb = d5 * d2 - d1 * d6;
    const double va = d3 * d6 - d5 * d4;
    if (d1 <= 0.0 && d2 <= 0.0) {
        at_vertex(0);
    } else if (d3 >= 0.0 && d4 <= d3) {
        at_vertex(1);
    } else if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        // Edge ab, opposite c: the point a + s ab, its ends a (vertex 0) and b (vertex 1); the
        // edge opposite vertex 2 runs from vertex 0 to vertex 1.
        on_edge(2, d1 / (d1 - d3));
    } else if (d6 >= 0.0 && d5 <= d6) {
        at_vertex(2);
    } else if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        // Edge ac, opposite b: runs from vertex 2 to vertex 0, a + w ac = c + (1 - w) (a - c).
        on_edge(1, 1.0 - d2 / (d2 - d6));
    } else if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
        on_edge(0, (d4 - d3) / ((d4 - d3) + (d5 - d6)));
    } else {
        const double s = va + vb + vc;
        p.where = TriangleFeature::interior;
        p.feature = -1;
        p.bary = {va / s, vb / s, vc / s};
    }
    p.point = p.bary[0] * a + p.bary[1] * b + p.bary[2] * c;
    p.distance = (x - p.point).norm();
    p.g0 = n.dot(x - p.point);
    return p;
}

/// Barycentric coordinates of the orthogonal projection of x onto the plane of (a, b, c)
/// (negative outside the triangle).
std::array<double, 3> search3_plane_bary(const Vec3& x, const Vec3& a, const Vec3& b,
                                         const Vec3& c) {
    const Vec3 N = (b - a).cross(c - a);
    const double N2 = N.squaredNorm();
    const double la = (b - x).cross(c - x).dot(N) / N2;
    const double lb = (c - x).cross(a - x).dot(N) / N2;
    return {la, lb, 1.0 - la - lb};
}

} // namespace

std::vector<Facet3> target_facets3(const mesh::TetMesh& m, int tag) {
    std::vector<Facet3> out;
    for (const auto& f : m.boundary)
        if (f.tag == tag) out.push_back({f.v});
    return out;
}

TriangleProjection project_on_triangle(const Vec3& x, const Vec3& xa, const Vec3& xb,
                                       const Vec3& xc) {
    MLC_CHECK(!search3_degenerate(xa, xb, xc),
              "contact search: a target triangle has zero area, its corners "
                  << search3_point(xa) << ", " << search3_point(xb) << ", " << search3_point(xc));
    return search3_project(x, xa, xb, xc, (xb - xa).cross(xc - xa).normalized());
}

// ---------------------------------------------------------------------------------------------
struct FacetIndex3::Impl {
    std::vector<Facet3> facets;
    std::vector<std::array<Vec3, 3>> corners;
    std::vector<Vec3> normal;             ///< unit facet normals
    std::vector<double> size;             ///< longest edge per facet
    std::vector<std::array<Vec3, 2>> box; ///< bounding box (low, high) per facet
    double max_size = 0.0;
    std::unordered_map<std::uint64_t, std::pair<Vec3, int>> edges; ///< normal sum, facets
    std::unordered_map<int, std::pair<Vec3, double>> vertices;     ///< angle-weighted sum, angles
    /// The rim edges at each vertex on the rim: (facet, the corner of the facet opposite them).
    std::unordered_map<int, std::vector<std::pair<int, int>>> rim;
#ifdef MLC_HAVE_CGAL
    using K = CGAL::Simple_cartesian<double>;
    using Triangles = std::vector<K::Triangle_3>;
    using Primitive = CGAL::AABB_triangle_primitive<K, Triangles::const_iterator>;
    using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;
    Triangles triangles; ///< the tree refers to them: filled before it, never resized
    Tree tree;
#endif

    /// Facets (ascending) whose bounding box meets the cube of half side `half` around x: a
    /// superset of those within distance `half` (the caller filters them).
    std::vector<int> candidates(const Vec3& x, double half) const;
    /// The smallest distance of x to a facet (to round-off).
    double nearest_distance(const Vec3& x) const;
};

std::vector<int> FacetIndex3::Impl::candidates(const Vec3& x, double half) const {
    // Enlarged so that round-off in the box tests (relative to the facets' size and to the
    // coordinates) loses no facet at distance `half`.
    const double h = half * (1.0 + 1e-9) + 1e-12 * max_size + 1e-13 * x.lpNorm<Eigen::Infinity>();
    std::vector<int> out;
#ifdef MLC_HAVE_CGAL
    const K::Iso_cuboid_3 query(x.x() - h, x.y() - h, x.z() - h, x.x() + h, x.y() + h, x.z() + h);
    std::vector<Primitive::Id> ids;
    tree.all_intersected_primitives(query, std::back_inserter(ids));
    out.reserve(ids.size());
    for (const auto& id : ids)
        out.push_back(static_cast<int>(std::distance(triangles.cbegin(), id)));
    std::sort(out.begin(), out.end());
#else
    const Vec3 lo = x.array() - h, hi = x.array() + h;
    for (size_t i = 0; i < box.size(); ++i)
        if ((box[i][0].array() <= hi.array()).all() && (box[i][1].array() >= lo.array()).all())
            out.push_back(static_cast<int>(i));
#endif
    return out;
}

double FacetIndex3::Impl::nearest_distance(const Vec3& x) const {
#ifdef MLC_HAVE_CGAL
    return std::sqrt(tree.squared_distance(K::Point_3(x.x(), x.y(), x.z())));
#else
    double best = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < facets.size(); ++i) {
        const auto& e = corners[i];
        best = std::min(best, search3_project(x, e[0], e[1], e[2], normal[i]).distance);
    }
    return best;
#endif
}

FacetIndex3::FacetIndex3(const std::vector<Vec3>& vertices, std::vector<Facet3> facets)
    : impl_(std::make_unique<Impl>()) {
    MLC_CHECK(!facets.empty(), "contact search: no target facet to search");
    Impl& I = *impl_;
    const int nv = static_cast<int>(vertices.size());
    for (const auto& f : facets) {
        for (int v : f.v)
            MLC_CHECK(v >= 0 && v < nv, "contact search: facet ("
                                            << f.v[0] << ", " << f.v[1] << ", " << f.v[2]
                                            << ") refers to a vertex out of range (" << nv
                                            << " vertices)");
        const std::array<Vec3, 3> e{vertices[static_cast<size_t>(f.v[0])],
                                    vertices[static_cast<size_t>(f.v[1])],
                                    vertices[static_cast<size_t>(f.v[2])]};
        MLC_CHECK(!search3_degenerate(e[0], e[1], e[2]),
                  "contact search: target facet ("
                      << f.v[0] << ", " << f.v[1] << ", " << f.v[2]
                      << ") is degenerate (zero area): vertex " << f.v[0] << " at "
                      << search3_point(e[0]) << ", vertex " << f.v[1] << " at "
                      << search3_point(e[1]) << ", vertex " << f.v[2] << " at "
                      << search3_point(e[2]));
        const Vec3 n = (e[1] - e[0]).cross(e[2] - e[0]).normalized();
        I.corners.push_back(e);
        I.normal.push_back(n);
        I.size.push_back(search3_longest_edge(e[0], e[1], e[2]));
        I.max_size = std::max(I.max_size, I.size.back());
        I.box.push_back({e[0].cwiseMin(e[1]).cwiseMin(e[2]), e[0].cwiseMax(e[1]).cwiseMax(e[2])});
        for (size_t k = 0; k < 3; ++k) {
            // Edge opposite corner k, and the angle at corner k.
            auto& edge = I.edges
                             .try_emplace(search3_edge_key(f.v[(k + 1) % 3], f.v[(k + 2) % 3]),
                                          Vec3::Zero(), 0)
                             .first->second;
            edge.first += n;
            ++edge.second;
            const Vec3 u = e[(k + 1) % 3] - e[k], w = e[(k + 2) % 3] - e[k];
            const double angle = std::atan2(u.cross(w).norm(), u.dot(w));
            auto& vert = I.vertices.try_emplace(f.v[k], Vec3::Zero(), 0.0).first->second;
            vert.first += angle * n;
            vert.second += angle;
        }
    }
    for (int i = 0; i < static_cast<int>(facets.size()); ++i) {
        const auto& v = facets[static_cast<size_t>(i)].v;
        for (int k = 0; k < 3; ++k) {
            const int a = v[static_cast<size_t>((k + 1) % 3)],
                      b = v[static_cast<size_t>((k + 2) % 3)];
            if (I.edges.at(search3_edge_key(a, b)).second != 1) continue;
            I.rim[a].emplace_back(i, k);
            I.rim[b].emplace_back(i, k);
        }
    }
    I.facets = std::move(facets);
#ifdef MLC_HAVE_CGAL
    I.triangles.reserve(I.corners.size());
    for (const auto& e : I.corners)
        I.triangles.emplace_back(Impl::K::Point_3(e[0].x(), e[0].y(), e[0].z()),
                                 Impl::K::Point_3(e[1].x(), e[1].y(), e[1].z()),
                                 Impl::K::Point_3(e[2].x(), e[2].y(), e[2].z()));
    I.tree.insert(I.triangles.cbegin(), I.triangles.cend());
    // Built now, with the search tree of the distance queries, so that the const queries
    // modify nothing (CGAL builds both lazily otherwise).
    I.tree.build();
    I.tree.accelerate_distance_queries();
#endif
}

FacetIndex3::~FacetIndex3() = default;
FacetIndex3::FacetIndex3(FacetIndex3&&) noexcept = default;
FacetIndex3& FacetIndex3::operator=(FacetIndex3&&) noexcept = default;

const std::vector<Facet3>& FacetIndex3::facets() const {
    return impl_->facets;
}

double FacetIndex3::max_size() const {
    return impl_->max_size;
}

const std::array<Vec3, 3>& FacetIndex3::corners(int i) const {
    MLC_CHECK(i >= 0 && i < static_cast<int>(impl_->corners.size()),
              "FacetIndex3::corners: facet " << i << " out of range");
    return impl_->corners[static_cast<size_t>(i)];
}

const Vec3& FacetIndex3::facet_normal(int i) const {
    MLC_CHECK(i >= 0 && i < static_cast<int>(impl_->normal.size()),
              "FacetIndex3::facet_normal: facet " << i << " out of range");
    return impl_->normal[static_cast<size_t>(i)];
}

bool FacetIndex3::is_rim_edge(int a, int b) const {
    const auto it = impl_->edges.find(search3_edge_key(a, b));
    MLC_CHECK(it != impl_->edges.end(),
              "FacetIndex3: (" << a << ", " << b << ") is no edge of a target facet");
    return it->second.second == 1;
}

Vec3 FacetIndex3::edge_normal(int a, int b) const {
    const auto it = impl_->edges.find(search3_edge_key(a, b));
    MLC_CHECK(it != impl_->edges.end(),
              "FacetIndex3: (" << a << ", " << b << ") is no edge of a target facet");
    const auto& [sum, count] = it->second;
    MLC_CHECK(sum.norm() > 1e-6 * count, "contact search: the target normals cancel on the edge ("
                                             << a << ", " << b << ") (facets back to back)");
    return sum.normalized();
}

Vec3 FacetIndex3::vertex_normal(int v) const {
    const auto it = impl_->vertices.find(v);
    MLC_CHECK(it != impl_->vertices.end(),
              "FacetIndex3: vertex " << v << " is no corner of a target facet");
    const auto& [sum, angles] = it->second;
    MLC_CHECK(sum.norm() > 1e-6 * angles, "contact search: the target normals cancel at vertex "
                                              << v << " (facets back to back)");
    return sum.normalized();
}

std::vector<int> FacetIndex3::within(const Vec3& x, double radius) const {
    const Impl& I = *impl_;
    std::vector<int> out;
    for (int i : I.candidates(x, radius)) {
        const auto& e = I.corners[static_cast<size_t>(i)];
        if (search3_project(x, e[0], e[1], e[2], I.normal[static_cast<size_t>(i)]).distance <=
            radius)
            out.push_back(i);
    }
    return out;
}

double FacetIndex3::local_size(const Vec3& x) const {
    const Impl& I = *impl_;
    const double d = I.nearest_distance(x);
    // The facets at the smallest distance (to round-off and the tie tolerance): the largest.
    const double tie = 1e-12 * I.max_size;
    std::vector<int> cand = I.candidates(x, d * (1.0 + 1e-9) + 2.0 * tie);
    if (cand.empty()) // the tree's distance and ours differ beyond round-off: never seen
        for (int i = 0; i < static_cast<int>(I.facets.size()); ++i)
            cand.push_back(i);
    std::vector<std::pair<double, int>> near;
    for (int i : cand) {
        const auto& e = I.corners[static_cast<size_t>(i)];
        near.emplace_back(
            search3_project(x, e[0], e[1], e[2], I.normal[static_cast<size_t>(i)]).distance, i);
    }
    const double dmin = std::min_element(near.begin(), near.end())->first;
    double h = 0.0;
    for (const auto& [dist, i] : near)
        if (dist <= dmin + tie) h = std::max(h, I.size[static_cast<size_t>(i)]);
    return h;
}

std::optional<TriangleProjection> FacetIndex3::closest(const Vec3& x, double radius,
                                                       int skip) const {
    const Impl& I = *impl_;
    std::optional<TriangleProjection> best;
    double best_inside = 0.0;
    std::array<double, 3> best_plane{}; // barycentric coordinates of x's projection on its plane
    // Two distances closer than this (relative to the facet size) are a tie; so are two
    // insides closer than 1e-12.
    const double tie = 1e-12 * I.max_size;
    for (int i : I.candidates(x, radius)) {
        const auto ui = static_cast<size_t>(i);
        const Facet3& f = I.facets[ui];
        if (f.v[0] == skip || f.v[1] == skip || f.v[2] == skip) continue;
        const auto& e = I.corners[ui];
        TriangleProjection p = search3_project(x, e[0], e[1], e[2], I.normal[ui]);
        if (p.distance > radius) continue;
        p.facet = i;
        const auto plane = search3_plane_bary(x, e[0], e[1], e[2]);
        const double inside = std::min({0.0, plane[0], plane[1], plane[2]});
        if (!best || p.distance < best->distance - tie ||
            (std::abs(p.distance - best->distance) <= tie && inside > best_inside + 1e-12)) {
            best = p;
            best_inside = inside;
            best_plane = plane;
        }
    }
    if (!best) return best;
    const Facet3& f = I.facets[static_cast<size_t>(best->facet)];
    // Beyond the rim: the closest point on a rim edge (or at an end of one) and x outside the
    // edge's wall, i.e. the projection of x onto the plane of the edge's facet outside it across
    // the edge. Round-off (a node on the rim itself) counts as inside.
    constexpr double rim_tol = 1e-9;
    if (best->where == TriangleFeature::edge) {
        const auto k = static_cast<size_t>(best->feature);
        if (best_plane[k] < -rim_tol && is_rim_edge(f.v[(k + 1) % 3], f.v[(k + 2) % 3]))
            return std::nullopt;
    } else if (best->where == TriangleFeature::vertex) {
        const auto it = I.rim.find(f.v[static_cast<size_t>(best->feature)]);
        if (it != I.rim.end())
            for (const auto& [g, k] : it->second) {
                const auto& e = I.corners[static_cast<size_t>(g)];
                if (search3_plane_bary(x, e[0], e[1], e[2])[static_cast<size_t>(k)] < -rim_tol)
                    return std::nullopt;
            }
    }
    if (best->where == TriangleFeature::edge) {
        const auto k = static_cast<size_t>(best->feature);
        best->n = edge_normal(f.v[(k + 1) % 3], f.v[(k + 2) % 3]);
    } else if (best->where == TriangleFeature::vertex) {
        best->n = vertex_normal(f.v[static_cast<size_t>(best->feature)]);
    }
    best->g0 = best->n.dot(x - best->point);
    return best;
}

// ---------------------------------------------------------------------------------------------

ContactElement3 node_on_facet3(int c, const Facet3& f, const std::array<double, 3>& bary,
                               const Vec3& n, double g0, double mu, double r, int pair) {
    for (double b : bary)
        MLC_CHECK(b >= 0.0 && b <= 1.0,
                  "node_on_facet3: barycentric coordinates must lie in [0, 1], found ("
                      << bary[0] << ", " << bary[1] << ", " << bary[2] << ")");
    MLC_CHECK(std::abs(bary[0] + bary[1] + bary[2] - 1.0) < 1e-10,
              "node_on_facet3: the barycentric coordinates sum to " << bary[0] + bary[1] + bary[2]
                                                                    << ", not 1");
    MLC_CHECK(std::abs(n.norm() - 1.0) < 1e-12,
              "node_on_facet3: the normal must have unit length, found |n| = " << n.norm());
    MLC_CHECK(c != f.v[0] && c != f.v[1] && c != f.v[2],
              "node_on_facet3: contactor vertex " << c << " is a corner of its facet");
    return node_on_facet_weighted<3>(c, {f.v[0], f.v[1], f.v[2]}, {-bary[0], -bary[1], -bary[2]}, n,
                                     g0, mu, r, pair);
}

namespace {

/// The facets of `m` tagged `target_tag`, refused when there are none.
std::vector<Facet3> search3_targets(const mesh::TetMesh& m, int target_tag) {
    std::vector<Facet3> facets = target_facets3(m, target_tag);
    MLC_CHECK(!facets.empty(), "contact search: the mesh has no boundary face tagged '"
                                   << m.tag_name(target_tag) << "' to search");
    return facets;
}

} // namespace

SearchResult3 node_on_facet_search3(const mesh::TetMesh& m, const std::vector<int>& contactors,
                                    int target_tag, const FacetIndex3& reference,
                                    double search_radius, double mu, double r, int pair,
                                    FacetIntegration integration, int contactor_tag) {
    const FacetIndex3 index(m.vertices, search3_targets(m, target_tag));
    // Segment and dual weights: the contactor faces at each vertex (the support of its shape
    // function on the contactor surface).
    std::unordered_map<int, std::vector<SurfaceTriangle>> patch;
    if (integration != FacetIntegration::nodal) {
        MLC_CHECK(contactor_tag >= 0,
                  "contact search: segment integration needs the contactor faces' tag");
        for (const auto& f : m.boundary) {
            if (f.tag != contactor_tag) continue;
            SurfaceTriangle t;
            t.v = f.v;
            for (size_t k = 0; k < 3; ++k)
                t.x[k] = m.vertices[static_cast<size_t>(f.v[k])];
            for (int v : f.v)
                patch[v].push_back(t);
        }
    }
    SearchResult3 res;
    res.elements.reserve(contactors.size());
    for (int c : contactors) {
        const Vec3& x = m.vertices[static_cast<size_t>(c)];
        // Whether c is a contact node is decided on the reference facets, so that the decision
        // does not depend on the level (a curved target's facets move under refinement).
        const double radius = search_radius * reference.local_size(x);
        const auto on_reference = reference.closest(x, radius, c);
        // The element itself uses this level's facets; the closest one lies within the
        // reference distance plus the surfaces' difference (less than a reference facet).
        const auto hit =
            on_reference ? index.closest(x, radius + reference.max_size(), c) : std::nullopt;
        if (!hit) {
            res.not_found.push_back(c);
            continue;
        }
        auto e = node_on_facet3(c, index.facets()[static_cast<size_t>(hit->facet)], hit->bary,
                                hit->n, hit->g0, mu, r, pair);
        if (integration != FacetIntegration::nodal) {
            const auto it = patch.find(c);
            MLC_CHECK(it != patch.end(),
                      "contact search: contactor vertex "
                          << c << " (" << x.x() << ", " << x.y() << ", " << x.z()
                          << ") is on no face tagged '" << m.tag_name(contactor_tag)
                          << "': segment integration needs the contactor faces");
            e = segment_element3(m, e, it->second, index, radius + reference.max_size(),
                                 integration);
        }
        res.elements.push_back(std::move(e));
    }
    return res;
}

SearchResult3 node_on_node_search3(const mesh::TetMesh& m, const std::vector<int>& contactors,
                                   int target_tag, double match_tolerance, double mu, double r,
                                   int pair) {
    const FacetIndex3 index(m.vertices, search3_targets(m, target_tag));
    // The mean length of the target edges at each target vertex (each edge once).
    std::unordered_map<int, std::pair<double, int>> lengths;
    std::unordered_map<std::uint64_t, bool> seen;
    for (const auto& f : index.facets())
        for (size_t k = 0; k < 3; ++k) {
            const int a = f.v[k], b = f.v[(k + 1) % 3];
            if (!seen.try_emplace(search3_edge_key(a, b), true).second) continue;
            const double L =
                (m.vertices[static_cast<size_t>(a)] - m.vertices[static_cast<size_t>(b)]).norm();
            for (int v : {a, b}) {
                auto& [sum, count] = lengths[v];
                sum += L;
                ++count;
            }
        }
    double h_max = 0.0;
    for (const auto& [v, l] : lengths)
        h_max = std::max(h_max, l.first / l.second);
    SearchResult3 res;
    for (int c : contactors) {
        const Vec3& x = m.vertices[static_cast<size_t>(c)];
        // Every target vertex within the largest tolerance is a corner of a facet within it.
        int best = -1;
        double best_d = std::numeric_limits<double>::infinity();
        for (int i : index.within(x, match_tolerance * h_max))
            for (int v : index.facets()[static_cast<size_t>(i)].v) {
                const double d = (m.vertices[static_cast<size_t>(v)] - x).norm();
                if (d < best_d || (d == best_d && v < best)) {
                    best = v;
                    best_d = d;
                }
            }
        if (best < 0 || best == c) {
            res.not_found.push_back(c);
            continue;
        }
        const auto& [sum, count] = lengths.at(best);
        if (best_d > match_tolerance * sum / count) {
            res.not_found.push_back(c);
            continue;
        }
        const Vec3 n = index.vertex_normal(best);
        res.elements.push_back(node_on_node<3>(
            c, best, n, n.dot(x - m.vertices[static_cast<size_t>(best)]), mu, r, pair));
    }
    return res;
}

} // namespace mlc::contact
