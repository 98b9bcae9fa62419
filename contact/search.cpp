// SPDX-License-Identifier: MIT
// Contact search on the reference configuration: closest facets (node on facet) and coincident
// vertices (node on node), with the point search of mesh/cgal/point_search.hpp (a CGAL Kd-tree).
#include "contact/search.hpp"

#include "core/check.hpp"
#include "mesh/cgal/point_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace mlc::contact {

std::vector<Facet> target_facets(const mesh::Mesh& m, int tag) {
    std::vector<Facet> out;
    for (const auto& e : m.boundary)
        if (e.tag == tag) out.push_back({e.v0, e.v1});
    return out;
}

FacetProjection project_on_facet(const Vec2& x, const Vec2& xa, const Vec2& xb) {
    const Vec2 d = xb - xa;
    const double len2 = d.squaredNorm();
    MLC_CHECK(len2 > 0, "contact search: a target facet has zero length at (" << xa.x() << ", "
                                                                              << xa.y() << ")");
    FacetProjection p;
    p.alpha = std::clamp((x - xa).dot(d) / len2, 0.0, 1.0);
    p.n = Vec2(d.y(), -d.x()) / std::sqrt(len2);
    p.g0 = p.n.dot(x - xa);
    p.distance = (x - (xa + p.alpha * d)).norm();
    return p;
}

// ---------------------------------------------------------------------------------------------
struct FacetIndex::Impl {
    std::vector<Facet> facets;
    std::map<int, int> degree; ///< number of facets at each vertex
    std::vector<std::array<Vec2, 2>> ends;
    double max_length = 0.0;
    std::vector<double> length;
    mesh::PointSearch midpoints;
    Impl(std::vector<Facet> f, std::vector<std::array<Vec2, 2>> e, std::vector<Vec2> mid)
        : facets(std::move(f)), ends(std::move(e)), midpoints(mid) {
        for (const auto& p : ends) {
            length.push_back((p[1] - p[0]).norm());
            max_length = std::max(max_length, length.back());
        }
    }
};

FacetIndex::FacetIndex(const std::vector<Vec2>& vertices, std::vector<Facet> facets) {
    MLC_CHECK(!facets.empty(), "contact search: no target facet to search");
    std::vector<std::array<Vec2, 2>> ends;
    std::vector<Vec2> mid;
    const int nv = static_cast<int>(vertices.size());
    for (const auto& f : facets) {
        MLC_CHECK(f.a >= 0 && f.a < nv && f.b >= 0 && f.b < nv,
                  "contact search: facet (" << f.a << ", " << f.b << ") refers to a vertex out of "
                                            << "range (" << nv << " vertices)");
        const Vec2 xa = vertices[static_cast<size_t>(f.a)], xb = vertices[static_cast<size_t>(f.b)];
        MLC_CHECK((xb - xa).norm() > 0,
                  "contact search: facet (" << f.a << ", " << f.b << ") has zero length");
        ends.push_back({xa, xb});
        mid.push_back(0.5 * (xa + xb));
    }
    impl_ = std::make_unique<Impl>(std::move(facets), std::move(ends), std::move(mid));
    for (const auto& f : impl_->facets) {
        ++impl_->degree[f.a];
        ++impl_->degree[f.b];
    }
}

FacetIndex::~FacetIndex() = default;
FacetIndex::FacetIndex(FacetIndex&&) noexcept = default;
FacetIndex& FacetIndex::operator=(FacetIndex&&) noexcept = default;

const std::vector<Facet>& FacetIndex::facets() const {
    return impl_->facets;
}

double FacetIndex::max_length() const {
    return impl_->max_length;
}

double FacetIndex::local_size(const Vec2& x) const {
    return impl_->length[static_cast<size_t>(impl_->midpoints.nearest(x))];
}

const std::array<Vec2, 2>& FacetIndex::ends(int i) const {
    MLC_CHECK(i >= 0 && i < static_cast<int>(impl_->ends.size()),
              "FacetIndex::ends: facet " << i << " out of range");
    return impl_->ends[static_cast<size_t>(i)];
}

std::vector<int> FacetIndex::within(const Vec2& x, double radius) const {
    const Impl& I = *impl_;
    std::vector<int> cand = I.midpoints.within(x, radius + 0.5 * I.max_length);
    std::sort(cand.begin(), cand.end());
    std::vector<int> out;
    for (int i : cand) {
        const auto& e = I.ends[static_cast<size_t>(i)];
        if (project_on_facet(x, e[0], e[1]).distance <= radius) out.push_back(i);
    }
    return out;
}

std::optional<FacetProjection> FacetIndex::closest(const Vec2& x, double radius, int skip) const {
    const Impl& I = *impl_;
    std::vector<int> cand = I.midpoints.within(x, radius + 0.5 * I.max_length);
    std::sort(cand.begin(), cand.end());
    std::optional<FacetProjection> best;
    bool best_inside = false;
    double best_raw = 0.0;
    // Two distances closer than this (relative to the facet size) are a tie.
    const double tie = 1e-12 * I.max_length;
    for (int i : cand) {
        const Facet& f = I.facets[static_cast<size_t>(i)];
        if (f.a == skip || f.b == skip) continue;
        const auto& e = I.ends[static_cast<size_t>(i)];
        FacetProjection p = project_on_facet(x, e[0], e[1]);
        if (p.distance > radius) continue;
        p.facet = i;
        const Vec2 d = e[1] - e[0];
        const double a_raw = (x - e[0]).dot(d) / d.squaredNorm();
        const bool inside = a_raw >= 0.0 && a_raw <= 1.0;
        if (!best || p.distance < best->distance - tie ||
            (std::abs(p.distance - best->distance) <= tie && inside && !best_inside)) {
            best = p;
            best_inside = inside;
            best_raw = a_raw;
        }
    }
    // The closest point is an end of the whole target boundary (no other facet there), reached
    // from beyond: x is over no facet. Round-off (a node at the very end) counts as inside.
    if (best) {
        constexpr double end_tol = 1e-9;
        const Facet& f = I.facets[static_cast<size_t>(best->facet)];
        if ((best_raw < -end_tol && I.degree.at(f.a) < 2) ||
            (best_raw > 1.0 + end_tol && I.degree.at(f.b) < 2))
            return std::nullopt;
    }
    return best;
}

// ---------------------------------------------------------------------------------------------
namespace {

/// Segment-integrated node-on-facet element of contactor vertex c (search.hpp): `nbrs` are the
/// other ends of the contactor edges at c, `hit` the closest facet (normal, gap, and the nodal
/// fallback), `reach` the largest distance from a contactor piece to a facet that counts.
/// `dual`: test with the dual (biorthogonal) function psi_i = 3 N_i - 1 per edge instead of N_i,
/// unless the support of N_i is only partly over the target.
ContactElement segment_element(const mesh::Mesh& m, int c, const std::vector<int>& nbrs,
                               const FacetIndex& index, const FacetProjection& hit, double reach,
                               double mu, double r, int pair, bool dual) {
    const Vec2 xc = m.vertices[static_cast<size_t>(c)];
    struct Piece {
        int a, b;      // facet ends
        double lo, hi; // facet coordinates of the overlap
        double sc, ds; // contactor tau = (s - sc) / ds
        double jac;    // ds(contactor) per unit of s, times (hi - lo) / 2
    };
    std::vector<Piece> pieces;
    double D = 0.0;
    for (int d : nbrs) {
        const Vec2 xd = m.vertices[static_cast<size_t>(d)];
        const double L = (xd - xc).norm();
        if (!(L > 0.0)) continue;
        D += 0.5 * L; // int of the hat N_i over the edge
        for (int i : index.within(0.5 * (xc + xd), 0.5 * L + reach)) {
            const Facet& f = index.facets()[static_cast<size_t>(i)];
            if (f.a == c || f.b == c || f.a == d || f.b == d) continue;
            const auto& e = index.ends(i);
            const Vec2 dv = e[1] - e[0];
            const double len2 = dv.squaredNorm();
            const Vec2 nf = Vec2(dv.y(), -dv.x()) / std::sqrt(len2);
            if (nf.dot(hit.n) <= 0.0) continue; // a facet facing another way
            // Facet coordinates s of the orthogonal projections of the edge ends (s in [0, 1]
            // on the facet); the contactor point over s is at tau = (s - sc) / (sd - sc).
            const double sc = (xc - e[0]).dot(dv) / len2;
            const double sd = (xd - e[0]).dot(dv) / len2;
            const double ds = sd - sc;
            if (std::abs(ds) < 1e-12) continue; // the edge is perpendicular to the facet
            const double lo = std::max(0.0, std::min(sc, sd));
            const double hi = std::min(1.0, std::max(sc, sd));
            if (hi - lo <= 1e-12) continue; // no overlap
            auto x_at = [&](double s) { return Vec2(xc + (s - sc) / ds * (xd - xc)); };
            const double gap =
                std::min(std::abs(nf.dot(x_at(lo) - e[0])), std::abs(nf.dot(x_at(hi) - e[0])));
            if (gap > reach) continue;
            // ds along the contactor = L |dtau/ds| ds(facet coordinate).
            pieces.push_back({f.a, f.b, lo, hi, sc, ds, 0.5 * (hi - lo) * L / std::abs(ds)});
        }
    }
    // 2-point Gauss on [-1, 1]: exact for the quadratic integrands.
    const double xi = 1.0 / std::sqrt(3.0);
    auto integrate = [&](bool use_dual, std::map<int, double>& M) {
        double covered = 0.0;
        for (const Piece& p : pieces)
            for (double g : {-xi, xi}) {
                const double s = 0.5 * (p.lo + p.hi) + 0.5 * (p.hi - p.lo) * g;
                const double Nc = 1.0 - (s - p.sc) / p.ds;
                const double test = use_dual ? 3.0 * Nc - 1.0 : Nc;
                covered += p.jac * test;
                M[p.a] += p.jac * test * (1.0 - s);
                M[p.b] += p.jac * test * s;
            }
        return covered;
    };
    std::map<int, double> M;
    double covered = integrate(false, M);
    const Facet& fh = index.facets()[static_cast<size_t>(hit.facet)];
    if (!(covered > 1e-12 * D)) // nothing covered (degenerate): the nodal weights
        return node_on_facet(c, fh.a, fh.b, hit.alpha, hit.n, hit.g0, mu, r, pair);
    if (dual && covered > (1.0 - 1e-9) * D) {
        M.clear();
        covered = integrate(true, M);
    }
    std::vector<int> targets;
    std::vector<double> weights;
    for (const auto& [k, Mk] : M)
        if (Mk != 0.0) {
            targets.push_back(k);
            weights.push_back(-Mk / covered);
        }
    return node_on_facet_weighted(c, targets, weights, hit.n, hit.g0, mu, r, pair);
}

} // namespace

SearchResult node_on_facet_search(const mesh::Mesh& m, const std::vector<int>& contactors,
                                  int target_tag, const FacetIndex& reference, double search_radius,
                                  double mu, double r, int pair, FacetIntegration integration,
                                  int contactor_tag) {
    std::vector<Facet> facets = target_facets(m, target_tag);
    MLC_CHECK(!facets.empty(), "contact search: the mesh has no boundary edge tagged '"
                                   << m.tag_name(target_tag) << "' to search");
    const FacetIndex index(m.vertices, facets);
    // Segment integration: the contactor edges at each vertex (the support of its hat function).
    std::map<int, std::vector<int>> neighbours;
    if (integration != FacetIntegration::nodal) {
        MLC_CHECK(contactor_tag >= 0,
                  "contact search: segment integration needs the contactor boundary's tag");
        for (const auto& e : m.boundary)
            if (e.tag == contactor_tag) {
                neighbours[e.v0].push_back(e.v1);
                neighbours[e.v1].push_back(e.v0);
            }
    }
    SearchResult res;
    res.elements.reserve(contactors.size());
    for (int c : contactors) {
        const Vec2& x = m.vertices[static_cast<size_t>(c)];
        // Whether c is a contact node is decided on the reference facets, so that the decision
        // does not depend on the level (a curved target's polygon moves under refinement).
        const double radius = search_radius * reference.local_size(x);
        const auto on_reference = reference.closest(x, radius, c);
        // The element itself uses this level's facets; the closest one lies within the
        // reference distance plus the polygons' difference (less than a reference facet).
        const auto hit =
            on_reference ? index.closest(x, radius + reference.max_length(), c) : std::nullopt;
        if (!hit) {
            res.not_found.push_back(c);
            continue;
        }
        if (integration != FacetIntegration::nodal) {
            const auto it = neighbours.find(c);
            MLC_CHECK(it != neighbours.end(),
                      "contact search: contactor vertex "
                          << c << " (" << x.x() << ", " << x.y() << ") is on no edge tagged '"
                          << m.tag_name(contactor_tag)
                          << "': segment integration needs the contactor boundary edges");
            res.elements.push_back(segment_element(m, c, it->second, index, *hit,
                                                   radius + reference.max_length(), mu, r, pair,
                                                   integration == FacetIntegration::dual));
            continue;
        }
        const Facet& f = index.facets()[static_cast<size_t>(hit->facet)];
        res.elements.push_back(
            node_on_facet(c, f.a, f.b, hit->alpha, hit->n, hit->g0, mu, r, pair));
    }
    return res;
}

SearchResult node_on_node_search(const mesh::Mesh& m, const std::vector<int>& contactors,
                                 int target_tag, double match_tolerance, double mu, double r,
                                 int pair) {
    const std::vector<Facet> facets = target_facets(m, target_tag);
    MLC_CHECK(!facets.empty(), "contact search: the mesh has no boundary edge tagged '"
                                   << m.tag_name(target_tag) << "' to search");
    // Target vertices with the sum of the outward normals and lengths of their facets.
    std::map<int, size_t> slot;
    std::vector<int> verts;
    std::vector<Vec2> pos, normal_sum;
    std::vector<double> length_sum;
    std::vector<int> n_facets;
    for (const auto& f : facets) {
        const Vec2 xa = m.vertices[static_cast<size_t>(f.a)];
        const Vec2 xb = m.vertices[static_cast<size_t>(f.b)];
        const FacetProjection p = project_on_facet(xa, xa, xb);
        for (int v : {f.a, f.b}) {
            auto [it, inserted] = slot.try_emplace(v, verts.size());
            if (inserted) {
                verts.push_back(v);
                pos.push_back(m.vertices[static_cast<size_t>(v)]);
                normal_sum.push_back(Vec2::Zero());
                length_sum.push_back(0.0);
                n_facets.push_back(0);
            }
            normal_sum[it->second] += p.n;
            length_sum[it->second] += (xb - xa).norm();
            ++n_facets[it->second];
        }
    }
    const mesh::PointSearch index(pos);
    SearchResult res;
    for (int c : contactors) {
        const Vec2& x = m.vertices[static_cast<size_t>(c)];
        const size_t k = static_cast<size_t>(index.nearest(x));
        const double h = length_sum[k] / n_facets[k];
        if (verts[k] == c || (pos[k] - x).norm() > match_tolerance * h) {
            res.not_found.push_back(c);
            continue;
        }
        // Average direction of the adjacent facet normals; at a corner where the normals
        // cancel (a facet and its reverse) there is no meaningful normal.
        MLC_CHECK(normal_sum[k].norm() > 1e-6 * n_facets[k],
                  "contact search: the target normals cancel at vertex "
                      << verts[k] << " (" << pos[k].x() << ", " << pos[k].y() << ")");
        const Vec2 n = normal_sum[k].normalized();
        res.elements.push_back(node_on_node(c, verts[k], n, n.dot(x - pos[k]), mu, r, pair));
    }
    return res;
}

} // namespace mlc::contact
