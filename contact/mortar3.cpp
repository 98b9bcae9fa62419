// SPDX-License-Identifier: MIT
// 3D segment-integrated and dual contact weights of one contactor node (Puso & Laursen 2004):
// projection of the contactor patch and the target triangles on the node's plane, clipping of
// each pair (Sutherland–Hodgman), and the exact integrals of the products of the shape functions
// on the triangles of each overlap.
#include "contact/mortar3.hpp"

#include "contact/obstacle.hpp"
#include "core/check.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <utility>

namespace mlc::contact {

namespace {

double cross2(const Vec2& a, const Vec2& b) {
    return a.x() * b.y() - a.y() * b.x();
}

/// Extends the bounding box [lo, hi] by a polygon's vertices.
void extend_box(const std::vector<Vec2>& p, Vec2& lo, Vec2& hi) {
    for (const Vec2& q : p) {
        lo = lo.cwiseMin(q);
        hi = hi.cwiseMax(q);
    }
}

/// `p` counter-clockwise: reversed when its signed area is negative.
std::vector<Vec2> counter_clockwise(const std::vector<Vec2>& p, double signed_area) {
    std::vector<Vec2> out(p);
    if (signed_area < 0.0) std::reverse(out.begin(), out.end());
    return out;
}

/// One step of Sutherland–Hodgman: the part of the convex polygon `in` on the left of the
/// directed line a -> b (points on the line included).
std::vector<Vec2> clip_by_edge(const std::vector<Vec2>& in, const Vec2& a, const Vec2& b) {
    std::vector<Vec2> out;
    out.reserve(in.size() + 1);
    const Vec2 d = b - a;
    const size_t m = in.size();
    for (size_t j = 0; j < m; ++j) {
        const Vec2& s = in[(j + m - 1) % m]; // previous vertex
        const Vec2& e = in[j];
        const double ss = cross2(d, s - a);
        const double se = cross2(d, e - a);
        if (se >= 0.0) {
            if (ss < 0.0) out.push_back(s + (e - s) * (ss / (ss - se)));
            out.push_back(e);
        } else if (ss >= 0.0) {
            out.push_back(s + (e - s) * (ss / (ss - se)));
        }
    }
    return out;
}

/// "(v0, v1, v2) (vertices (x0) (x1) (x2))".
std::string describe_triangle(const SurfaceTriangle& t) {
    std::ostringstream os;
    os << "(" << t.v[0] << ", " << t.v[1] << ", " << t.v[2] << ") (vertices";
    for (const auto& x : t.x)
        os << " (" << x.x() << ", " << x.y() << ", " << x.z() << ")";
    os << ")";
    return os.str();
}

/// The triangle's unit normal (x1 - x0) x (x2 - x0) / |..| and its area; throws InvalidInput
/// for a triangle of zero area, naming it (`role`: "contactor" or "target").
std::pair<mesh::Vec3, double> normal_and_area(const SurfaceTriangle& t, const char* role,
                                              int node) {
    const mesh::Vec3 c = (t.x[1] - t.x[0]).cross(t.x[2] - t.x[0]);
    const double lmax2 = std::max({(t.x[1] - t.x[0]).squaredNorm(), (t.x[2] - t.x[1]).squaredNorm(),
                                   (t.x[0] - t.x[2]).squaredNorm()});
    const double twice = c.norm();
    const bool has_area = twice > 1e-14 * lmax2 && std::isfinite(twice);
    MLC_CHECK(has_area, "mortar weights of contactor node " << node << ": the " << role
                                                            << " triangle " << describe_triangle(t)
                                                            << " has zero area");
    return {c / twice, 0.5 * twice};
}

/// A triangle projected along n on the node's plane: its corners in the plane's coordinates,
/// the barycentric coordinates of a point of the plane, and its height along n over the plane.
struct Projected {
    std::array<Vec2, 3> p;
    std::array<double, 3> h{}; ///< n . (x_a - x_node)
    double det = 0.0;          ///< (p1 - p0) x (p2 - p0): twice the signed projected area

    std::array<double, 3> bary(const Vec2& q) const {
        const double l1 = cross2(q - p[0], p[2] - p[0]) / det;
        const double l2 = cross2(p[1] - p[0], q - p[0]) / det;
        return {1.0 - l1 - l2, l1, l2};
    }
    double height(const std::array<double, 3>& l) const {
        return l[0] * h[0] + l[1] * h[1] + l[2] * h[2];
    }
    std::vector<Vec2> polygon() const { return {p[0], p[1], p[2]}; }
};

/// The plane through the node orthogonal to n, with the tangents of tangent_basis(n).
struct Plane {
    mesh::Vec3 origin;
    mesh::Vec3 n;
    Eigen::Matrix<double, 3, 2> t;

    Projected project(const SurfaceTriangle& tri) const {
        Projected out;
        for (int a = 0; a < 3; ++a) {
            const mesh::Vec3 d = tri.x[static_cast<size_t>(a)] - origin;
            out.p[static_cast<size_t>(a)] = Vec2(t.col(0).dot(d), t.col(1).dot(d));
            out.h[static_cast<size_t>(a)] = n.dot(d);
        }
        out.det = cross2(out.p[1] - out.p[0], out.p[2] - out.p[0]);
        return out;
    }
};

/// One triangle of an overlap: its contactor area and the values at its three vertices of the
/// node's shape function N_i and of the target triangle's three shape functions.
struct SubTriangle {
    double dA = 0.0;
    std::array<double, 3> Ni{};
    std::array<int, 3> k{};                    ///< target vertex ids
    std::array<std::array<double, 3>, 3> Nk{}; ///< Nk[b][a]: N of target vertex b at vertex a
};

/// A contactor triangle of the patch, projected, with what the pieces need of it.
struct ContactorSide {
    const SurfaceTriangle* tri;
    Projected proj;
    int local = 0;      ///< the node's index in the triangle
    double inv_cos = 0; ///< 1 / |n_c . n|: contactor area per projected area
};

/// Cuts the overlap `poly` (counter-clockwise) of contactor triangle `c` and target triangle
/// `tt` (projected as `pt`) into triangles from its centroid and appends them to `out`.
void add_piece(const std::vector<Vec2>& poly, const ContactorSide& c, const SurfaceTriangle& tt,
               const Projected& pt, std::vector<SubTriangle>& out) {
    Vec2 centre = Vec2::Zero();
    for (const Vec2& q : poly)
        centre += q;
    centre /= static_cast<double>(poly.size());
    const auto bc0 = c.proj.bary(centre);
    const auto bt0 = pt.bary(centre);
    const size_t m = poly.size();
    for (size_t j = 0; j < m; ++j) {
        const Vec2& q1 = poly[j];
        const Vec2& q2 = poly[(j + 1) % m];
        const double A = 0.5 * cross2(q1 - centre, q2 - centre);
        if (!(A > 0.0)) continue;
        const std::array<std::array<double, 3>, 3> bc = {bc0, c.proj.bary(q1), c.proj.bary(q2)};
        const std::array<std::array<double, 3>, 3> bt = {bt0, pt.bary(q1), pt.bary(q2)};
        SubTriangle s;
        s.dA = A * c.inv_cos;
        for (size_t a = 0; a < 3; ++a) {
            s.Ni[a] = bc[a][static_cast<size_t>(c.local)];
            for (size_t b = 0; b < 3; ++b)
                s.Nk[b][a] = bt[a][b];
        }
        s.k = tt.v;
        out.push_back(s);
    }
}

/// Whether the two triangles come within `reach` of each other along n at a vertex of their
/// overlap.
bool within_reach(const std::vector<Vec2>& poly, const Projected& pc, const Projected& pt,
                  double reach) {
    if (!std::isfinite(reach)) return true;
    double gap = std::numeric_limits<double>::infinity();
    for (const Vec2& q : poly)
        gap = std::min(gap, std::abs(pc.height(pc.bary(q)) - pt.height(pt.bary(q))));
    return gap <= reach;
}

/// Covered part and M_ik with test function N_i or (dual) psi_i = 4 N_i - 1.
double integrate_pieces(const std::vector<SubTriangle>& subs, bool dual, std::map<int, double>& M) {
    double covered = 0.0;
    const std::array<double, 3> one{1.0, 1.0, 1.0};
    for (const SubTriangle& s : subs) {
        std::array<double, 3> test = s.Ni;
        if (dual)
            for (double& v : test)
                v = 4.0 * v - 1.0;
        covered += integrate_linear_products_on_triangle(s.dA, test, one);
        for (size_t b = 0; b < 3; ++b)
            M[s.k[b]] += integrate_linear_products_on_triangle(s.dA, test, s.Nk[b]);
    }
    return covered;
}

} // namespace

double polygon_area(const std::vector<Vec2>& polygon) {
    const size_t m = polygon.size();
    if (m < 3) return 0.0;
    double twice = 0.0;
    for (size_t j = 1; j + 1 < m; ++j)
        twice += cross2(polygon[j] - polygon[0], polygon[j + 1] - polygon[0]);
    return 0.5 * twice;
}

std::vector<Vec2> clip_convex_polygons(const std::vector<Vec2>& subject,
                                       const std::vector<Vec2>& clip) {
    const double as = polygon_area(subject);
    const double ac = polygon_area(clip);
    if (as == 0.0 || ac == 0.0) return {};
    const std::vector<Vec2> c = counter_clockwise(clip, ac);
    std::vector<Vec2> out = counter_clockwise(subject, as);
    for (size_t j = 0; j < c.size() && !out.empty(); ++j)
        out = clip_by_edge(out, c[j], c[(j + 1) % c.size()]);
    // Merge vertices that coincide to round-off (a vertex on an edge of `clip` comes back twice).
    Vec2 lo = subject[0], hi = subject[0];
    extend_box(subject, lo, hi);
    extend_box(clip, lo, hi);
    const double tol = 1e-14 * (hi - lo).maxCoeff();
    std::vector<Vec2> merged;
    for (const Vec2& q : out)
        if (merged.empty() || (q - merged.back()).lpNorm<Eigen::Infinity>() > tol)
            merged.push_back(q);
    while (merged.size() > 1 && (merged.back() - merged.front()).lpNorm<Eigen::Infinity>() <= tol)
        merged.pop_back();
    if (merged.size() < 3) return {};
    return merged;
}

double integrate_linear_products_on_triangle(double area, const std::array<double, 3>& f,
                                             const std::array<double, 3>& g) {
    const double fg = f[0] * g[0] + f[1] * g[1] + f[2] * g[2];
    return area / 12.0 * (fg + (f[0] + f[1] + f[2]) * (g[0] + g[1] + g[2]));
}

MortarWeights3 mortar_weights3(int node, const std::vector<SurfaceTriangle>& patch,
                               const mesh::Vec3& n, const std::vector<SurfaceTriangle>& targets,
                               FacetIntegration integration, double reach) {
    MLC_CHECK(integration == FacetIntegration::segment || integration == FacetIntegration::dual,
              "mortar weights of contactor node " << node << ": the integration must be segment "
                                                  << "or dual, found " << to_string(integration));
    MLC_CHECK(!patch.empty(), "mortar weights of contactor node "
                                  << node << ": the patch has no triangle (the node is on no "
                                  << "contactor boundary triangle)");
    const double nn = n.norm();
    MLC_CHECK(nn > 0.0 && std::isfinite(nn), "mortar weights of contactor node "
                                                 << node << ": the normal (" << n.x() << ", "
                                                 << n.y() << ", " << n.z()
                                                 << ") is zero or not finite");
    const mesh::Vec3 un = n / nn;
    MortarWeights3 res;
    std::vector<ContactorSide> sides;
    Plane plane{mesh::Vec3::Zero(), un, tangent_basis<3>(un)};
    for (size_t a = 0; a < 3; ++a)
        if (patch[0].v[a] == node) plane.origin = patch[0].x[a];
    for (const SurfaceTriangle& tc : patch) {
        const auto it = std::find(tc.v.begin(), tc.v.end(), node);
        MLC_CHECK(it != tc.v.end(), "mortar weights of contactor node "
                                        << node << ": the patch triangle (" << tc.v[0] << ", "
                                        << tc.v[1] << ", " << tc.v[2] << ") does not have it");
        const int local = static_cast<int>(it - tc.v.begin());
        const auto [nc, area] = normal_and_area(tc, "contactor", node);
        res.D += area / 3.0;
        const double cosc = std::abs(nc.dot(un));
        if (!(cosc > 1e-12)) continue; // parallel to n: no projection to speak of
        sides.push_back({&tc, {}, local, 1.0 / cosc});
    }
    for (ContactorSide& s : sides)
        s.proj = plane.project(*s.tri);
    std::vector<SubTriangle> subs;
    for (const SurfaceTriangle& tt : targets) {
        const auto [nt, area] = normal_and_area(tt, "target", node);
        if (!(nt.dot(un) > 1e-12)) continue; // facing another way, or parallel to n
        const Projected pt = plane.project(tt);
        for (const ContactorSide& s : sides) {
            const bool shared = std::any_of(tt.v.begin(), tt.v.end(), [&](int v) {
                return std::find(s.tri->v.begin(), s.tri->v.end(), v) != s.tri->v.end();
            });
            if (shared) continue; // a contactor triangle on the target surface itself
            const std::vector<Vec2> poly = clip_convex_polygons(s.proj.polygon(), pt.polygon());
            const double smaller = 0.5 * std::min(std::abs(s.proj.det), std::abs(pt.det));
            if (!(polygon_area(poly) > 1e-12 * smaller)) continue;
            if (!within_reach(poly, s.proj, pt, reach)) continue;
            ++res.pieces;
            add_piece(poly, s, tt, pt, subs);
        }
    }
    std::map<int, double> M;
    res.D_covered = integrate_pieces(subs, false, M);
    if (integration == FacetIntegration::dual && res.D_covered > (1.0 - 1e-9) * res.D) {
        M.clear();
        res.D_covered = integrate_pieces(subs, true, M);
        res.dual = true;
    }
    if (!(res.D_covered > 0.0)) return res;
    for (const auto& [k, Mk] : M)
        if (Mk != 0.0) {
            res.targets.push_back(k);
            res.weights.push_back(-Mk / res.D_covered);
        }
    return res;
}

ContactElement3 segment_element3(const mesh::TetMesh& m, const ContactElement3& nodal,
                                 const std::vector<SurfaceTriangle>& patch,
                                 const FacetIndex3& index, double reach,
                                 FacetIntegration integration) {
    const int c = nodal.vertex[0];
    const mesh::Vec3 xc = m.vertices[static_cast<size_t>(c)];
    double extent = 0.0; // the patch lies within this distance of c
    for (const SurfaceTriangle& t : patch)
        for (const mesh::Vec3& x : t.x)
            extent = std::max(extent, (x - xc).norm());
    std::vector<SurfaceTriangle> targets;
    for (int i : index.within(xc, extent + reach)) {
        SurfaceTriangle t;
        t.v = index.facets()[static_cast<size_t>(i)].v;
        t.x = index.corners(i);
        targets.push_back(t);
    }
    const MortarWeights3 w = mortar_weights3(c, patch, nodal.n, targets, integration, reach);
    if (w.pieces == 0 || !(w.D_covered > 1e-12 * w.D)) return nodal;
    ContactElement3 e = nodal;
    e.vertex.assign(1, c);
    e.weight.assign(1, 1.0);
    e.vertex.insert(e.vertex.end(), w.targets.begin(), w.targets.end());
    e.weight.insert(e.weight.end(), w.weights.begin(), w.weights.end());
    return e;
}

} // namespace mlc::contact
