// SPDX-License-Identifier: MIT
// 3D segment-integrated and dual contact weights (contact/mortar3.hpp): the clipping of convex
// polygons and the integral of linear products against closed forms, the weights on matching
// meshes (the consistent mass row; the identity for the dual ones), on non-matching flat meshes
// (sum zero, linear fields, the patch test), on curved surfaces, on a partly covered patch, and
// the refusals; a node-on-facet element built from the weights of a node with many target
// vertices, exact for rigid translations and linear fields.
#include "contact/mortar3.hpp"
#include "core/check.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <numbers>
#include <string>

using namespace mlc;

namespace mortar3_tests {

using contact::FacetIntegration;
using contact::SurfaceTriangle;
using mesh::Vec3;

/// The message of the InvalidInput `f` throws, without the " [check ...]" place that follows.
std::string refusal(const std::function<void()>& f) {
    try {
        f();
    } catch (const InvalidInput& e) {
        const std::string what = e.what();
        return what.substr(0, what.find(" [check `"));
    }
    return "(no InvalidInput thrown)";
}

/// A structured triangulated grid of nx x ny square cells of side h: vertex (i, j) at
/// origin + R(angle) (i h, j h) in the plane, lifted to height z(x, y); each cell cut along its
/// diagonal (i, j)-(i+1, j+1). Vertex ids first + i + (nx + 1) j. `up`: the triangles' normal
/// points up (+z, a body below); otherwise down.
struct Grid {
    int nx = 0, ny = 0, first = 0;
    std::vector<Vec3> x; ///< by local index i + (nx + 1) j
    std::vector<SurfaceTriangle> tris;
    int id(int i, int j) const { return first + i + (nx + 1) * j; }
    const Vec3& at(int id) const { return x[static_cast<size_t>(id - first)]; }
    /// The triangles that have vertex `id`.
    std::vector<SurfaceTriangle> patch(int id) const {
        std::vector<SurfaceTriangle> out;
        for (const auto& t : tris)
            if (t.v[0] == id || t.v[1] == id || t.v[2] == id) out.push_back(t);
        return out;
    }
};

Grid make_grid(int nx, int ny, double h, Vec2 origin, double angle,
               const std::function<double(double, double)>& z, int first, bool up) {
    Grid g;
    g.nx = nx;
    g.ny = ny;
    g.first = first;
    const double c = std::cos(angle), s = std::sin(angle);
    for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i) {
            const Vec2 p = origin + Vec2(c * i * h - s * j * h, s * i * h + c * j * h);
            g.x.emplace_back(p.x(), p.y(), z(p.x(), p.y()));
        }
    auto tri = [&](int a, int b, int d) {
        SurfaceTriangle t;
        t.v = up ? std::array<int, 3>{a, b, d} : std::array<int, 3>{a, d, b};
        for (size_t k = 0; k < 3; ++k)
            t.x[k] = g.at(t.v[k]);
        g.tris.push_back(t);
    };
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            tri(g.id(i, j), g.id(i + 1, j), g.id(i + 1, j + 1));
            tri(g.id(i, j), g.id(i + 1, j + 1), g.id(i, j + 1));
        }
    return g;
}

double flat(double, double) {
    return 0.0;
}

/// The weights as a map target vertex -> weight.
std::map<int, double> weight_map(const contact::MortarWeights3& w) {
    EXPECT_EQ(w.targets.size(), w.weights.size());
    std::map<int, double> out;
    for (size_t k = 0; k < w.targets.size(); ++k)
        out[w.targets[k]] = w.weights[k];
    return out;
}

double weight_sum(const contact::MortarWeights3& w) {
    double s = 1.0;
    for (double v : w.weights)
        s += v;
    return s;
}

/// Area of a 3D triangle.
double area(const SurfaceTriangle& t) {
    return 0.5 * (t.x[1] - t.x[0]).cross(t.x[2] - t.x[0]).norm();
}

/// sum_k w_k f(x_k) over the target vertices of `w`.
double apply(const contact::MortarWeights3& w, const Grid& target,
             const std::function<double(const Vec3&)>& f) {
    double s = 0.0;
    for (size_t k = 0; k < w.targets.size(); ++k)
        s += w.weights[k] * f(target.at(w.targets[k]));
    return s;
}

/// `g` turned by R and shifted: x -> R x + shift.
Grid moved(Grid g, const Eigen::Matrix3d& R, const Vec3& shift) {
    for (Vec3& x : g.x)
        x = R * x + shift;
    for (auto& t : g.tris)
        for (size_t k = 0; k < 3; ++k)
            t.x[k] = g.at(t.v[k]);
    return g;
}

} // namespace mortar3_tests

using namespace mortar3_tests;

// ---------------------------------------------------------------------------------------------
// Building blocks.

TEST(Mortar3Clip, TwoUnitSquaresOffsetOverlapInARectangle) {
    const std::vector<Vec2> a = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    const std::vector<Vec2> b = {{0.5, 0.25}, {1.5, 0.25}, {1.5, 1.25}, {0.5, 1.25}};
    const auto p = contact::clip_convex_polygons(a, b);
    ASSERT_EQ(p.size(), 4u);
    EXPECT_DOUBLE_EQ(contact::polygon_area(p), 0.5 * 0.75);
    for (const Vec2& q : p) {
        EXPECT_TRUE(q.x() == 0.5 || q.x() == 1.0) << q.transpose();
        EXPECT_TRUE(q.y() == 0.25 || q.y() == 1.0) << q.transpose();
    }
    // Clockwise inputs: the same overlap, counter-clockwise.
    const std::vector<Vec2> a_cw(a.rbegin(), a.rend()), b_cw(b.rbegin(), b.rend());
    EXPECT_DOUBLE_EQ(contact::polygon_area(contact::clip_convex_polygons(a_cw, b_cw)), 0.375);
    EXPECT_DOUBLE_EQ(contact::polygon_area(contact::clip_convex_polygons(b, a_cw)), 0.375);
    EXPECT_DOUBLE_EQ(contact::polygon_area(a_cw), -1.0);
}

TEST(Mortar3Clip, TriangleInsideTriangleIsTheInnerOne) {
    const std::vector<Vec2> big = {{0, 0}, {4, 0}, {0, 4}};
    const std::vector<Vec2> small = {{0.5, 0.5}, {1.5, 0.5}, {0.5, 1.5}};
    for (const auto& p :
         {contact::clip_convex_polygons(small, big), contact::clip_convex_polygons(big, small)}) {
        ASSERT_EQ(p.size(), 3u);
        EXPECT_DOUBLE_EQ(contact::polygon_area(p), 0.5);
        for (const Vec2& q : p)
            EXPECT_TRUE(q == small[0] || q == small[1] || q == small[2]) << q.transpose();
    }
}

TEST(Mortar3Clip, KnownAreasOfPartialOverlaps) {
    // The square [0.5, 1.5]^2 cut by x + y <= 2: the triangle below its diagonal.
    const std::vector<Vec2> tri = {{0, 0}, {2, 0}, {0, 2}};
    const std::vector<Vec2> sq = {{0.5, 0.5}, {1.5, 0.5}, {1.5, 1.5}, {0.5, 1.5}};
    const auto p = contact::clip_convex_polygons(sq, tri);
    EXPECT_EQ(p.size(), 3u);
    EXPECT_DOUBLE_EQ(contact::polygon_area(p), 0.5);
    // Star of David: two equilateral triangles inscribed in the unit circle meet in a regular
    // hexagon of 2/3 of a triangle's area 3 sqrt(3) / 4, i.e. sqrt(3) / 2.
    std::vector<Vec2> up, down;
    for (int k = 0; k < 3; ++k) {
        const double t = std::numbers::pi / 2 + 2 * std::numbers::pi * k / 3;
        up.emplace_back(std::cos(t), std::sin(t));
        down.emplace_back(-std::cos(t), -std::sin(t));
    }
    const auto hex = contact::clip_convex_polygons(up, down);
    EXPECT_EQ(hex.size(), 6u);
    EXPECT_NEAR(contact::polygon_area(hex), std::sqrt(3.0) / 2, 1e-15);
}

TEST(Mortar3Clip, DisjointOrTouchingPolygonsGiveNothing) {
    const std::vector<Vec2> a = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    EXPECT_TRUE(contact::clip_convex_polygons(a, {{2, 0}, {3, 0}, {2, 1}}).empty());
    // Along an edge, and at a corner.
    EXPECT_TRUE(contact::clip_convex_polygons(a, {{1, 0}, {2, 0}, {2, 1}, {1, 1}}).empty());
    EXPECT_TRUE(contact::clip_convex_polygons(a, {{1, 1}, {2, 1}, {1, 2}}).empty());
    // A degenerate polygon clips to nothing.
    EXPECT_TRUE(contact::clip_convex_polygons(a, {{0.2, 0.2}, {0.4, 0.4}, {0.6, 0.6}}).empty());
}

TEST(Mortar3Integrals, ConsistentMassMatrixAndThreePointRule) {
    const double A = 0.7;
    for (size_t i = 0; i < 3; ++i)
        for (size_t j = 0; j < 3; ++j) {
            std::array<double, 3> Ni{}, Nj{};
            Ni[i] = 1.0;
            Nj[j] = 1.0;
            EXPECT_DOUBLE_EQ(contact::integrate_linear_products_on_triangle(A, Ni, Nj),
                             A / 12 * (1.0 + (i == j ? 1.0 : 0.0)));
        }
    // Arbitrary linear f, g against the edge-midpoint rule (exact for quadratics).
    const std::array<double, 3> f{1.3, -0.4, 2.9}, g{-0.7, 0.25, 1.1};
    double mid = 0.0;
    for (size_t a = 0; a < 3; ++a) {
        const size_t b = (a + 1) % 3;
        mid += A / 3 * 0.5 * (f[a] + f[b]) * 0.5 * (g[a] + g[b]);
    }
    EXPECT_NEAR(contact::integrate_linear_products_on_triangle(A, f, g), mid, 1e-15);
    EXPECT_DOUBLE_EQ(contact::integrate_linear_products_on_triangle(A, {1, 1, 1}, {1, 1, 1}), A);
}

TEST(Mortar3Integrals, DualFunctionsAreBiorthogonal) {
    const double A = 0.37;
    for (size_t i = 0; i < 3; ++i) {
        std::array<double, 3> psi{-1.0, -1.0, -1.0};
        psi[i] = 3.0; // 4 N_i - 1 at the vertices
        for (size_t j = 0; j < 3; ++j) {
            std::array<double, 3> Nj{};
            Nj[j] = 1.0;
            EXPECT_NEAR(contact::integrate_linear_products_on_triangle(A, psi, Nj),
                        i == j ? A / 3 : 0.0, 1e-14);
        }
        EXPECT_NEAR(contact::integrate_linear_products_on_triangle(A, psi, {1, 1, 1}), A / 3,
                    1e-14);
    }
}

// ---------------------------------------------------------------------------------------------
// Weights of a node.

TEST(Mortar3Weights, MatchingMeshesGiveTheMassRowAndTheDualIdentity) {
    const double h = 0.25;
    // Contactor above (normal down) 0.02 over the target (normal up), the same grid.
    const Grid c = make_grid(
        4, 4, h, Vec2(0, 0), 0.0, [](double, double) { return 0.02; }, 0, false);
    const Grid t = make_grid(4, 4, h, Vec2(0, 0), 0.0, flat, 100, true);
    const Vec3 n = Vec3::UnitZ();
    // Interior node (2, 2): D = 6 (h^2 / 2) / 3, M_ii = 6 h^2 / 24 * 2, M_ik = 2 h^2 / 24 on the
    // six neighbours along the edges, so the weights -1/2 and -1/12.
    const int i = c.id(2, 2);
    const auto seg = contact::mortar_weights3(i, c.patch(i), n, t.tris, FacetIntegration::segment);
    EXPECT_EQ(seg.pieces, 6);
    EXPECT_NEAR(seg.D, h * h, 1e-15);
    EXPECT_NEAR(seg.D_covered, h * h, 1e-15);
    EXPECT_FALSE(seg.dual);
    const auto ws = weight_map(seg);
    ASSERT_EQ(ws.size(), 7u);
    EXPECT_NEAR(ws.at(t.id(2, 2)), -0.5, 1e-15);
    for (auto [di, dj] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, -1}})
        EXPECT_NEAR(ws.at(t.id(2 + di, 2 + dj)), -1.0 / 12, 1e-15) << di << " " << dj;
    // Dual: (1, -1) on the coincident vertex, nothing elsewhere.
    const auto dual = contact::mortar_weights3(i, c.patch(i), n, t.tris, FacetIntegration::dual);
    EXPECT_TRUE(dual.dual);
    EXPECT_EQ(dual.pieces, 6);
    EXPECT_NEAR(dual.D_covered, h * h, 1e-15);
    for (const auto& [k, w] : weight_map(dual))
        EXPECT_NEAR(w, k == t.id(2, 2) ? -1.0 : 0.0, 1e-14) << k;
    // Corner node (0, 0) on two triangles: D = h^2 / 3; M_ii = 2 h^2 / 12, M to (1, 1)
    // 2 h^2 / 24, to (1, 0) and (0, 1) h^2 / 24: weights -1/2, -1/4, -1/8, -1/8.
    const int o = c.id(0, 0);
    const auto corner =
        contact::mortar_weights3(o, c.patch(o), n, t.tris, FacetIntegration::segment);
    EXPECT_EQ(corner.pieces, 2);
    EXPECT_NEAR(corner.D, h * h / 3, 1e-15);
    const auto wc = weight_map(corner);
    ASSERT_EQ(wc.size(), 4u);
    EXPECT_NEAR(wc.at(t.id(0, 0)), -0.5, 1e-15);
    EXPECT_NEAR(wc.at(t.id(1, 1)), -0.25, 1e-15);
    EXPECT_NEAR(wc.at(t.id(1, 0)), -0.125, 1e-15);
    EXPECT_NEAR(wc.at(t.id(0, 1)), -0.125, 1e-15);
}

TEST(Mortar3Weights, MatchingMeshesInGeneralPositionHaveNoRoundOffPieces) {
    // The matching pair of the test above turned out of the coordinate planes, so that the
    // projections coincide to round-off only: overlaps of neighbouring triangles that meet in an
    // edge (slivers of round-off area) must not count.
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    const Vec3 n = R * Vec3::UnitZ();
    const Grid c = moved(make_grid(4, 4, 0.25, Vec2(0, 0), 0.3, flat, 0, false), R, 0.02 * n);
    const Grid t = moved(make_grid(4, 4, 0.25, Vec2(0, 0), 0.3, flat, 100, true), R, Vec3::Zero());
    const int i = c.id(2, 2);
    const auto seg = contact::mortar_weights3(i, c.patch(i), n, t.tris, FacetIntegration::segment);
    EXPECT_EQ(seg.pieces, 6);
    const auto ws = weight_map(seg);
    ASSERT_EQ(ws.size(), 7u);
    EXPECT_NEAR(ws.at(t.id(2, 2)), -0.5, 1e-14);
    for (auto [di, dj] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, -1}})
        EXPECT_NEAR(ws.at(t.id(2 + di, 2 + dj)), -1.0 / 12, 1e-14) << di << " " << dj;
    const auto dual = contact::mortar_weights3(i, c.patch(i), n, t.tris, FacetIntegration::dual);
    EXPECT_EQ(dual.pieces, 6);
    EXPECT_TRUE(dual.dual);
    EXPECT_LE(dual.targets.size(), 7u);
    for (const auto& [k, w] : weight_map(dual))
        EXPECT_NEAR(w, k == t.id(2, 2) ? -1.0 : 0.0, 1e-14) << k;
    const int o = c.id(0, 0);
    EXPECT_EQ(contact::mortar_weights3(o, c.patch(o), n, t.tris, FacetIntegration::dual).pieces, 2);
    // The target moved by 3e-14 in the plane: the neighbours' overlaps, slivers of that width,
    // lie below 1e-12 of a triangle's area and do not count either.
    const Grid shifted = moved(t, Eigen::Matrix3d::Identity(), R * Vec3(3e-14, 1.5e-14, 0));
    const auto near =
        contact::mortar_weights3(i, c.patch(i), n, shifted.tris, FacetIntegration::segment);
    EXPECT_EQ(near.pieces, 6);
    EXPECT_EQ(near.targets, seg.targets);
    for (size_t k = 0; k < seg.weights.size(); ++k)
        EXPECT_NEAR(near.weights[k], seg.weights[k], 1e-12);
}

namespace mortar3_tests {

/// The checks on a flat contactor grid over [0, 1]^2 (normal down) and a larger flat target
/// grid `t` under it, for every contactor node: weights summing to 0, the whole patch covered,
/// the dual weights reproducing a linear field, the segment ones its N_i-weighted mean over the
/// patch (f(x_i) / 4 + 3/4 f(patch centroid): f(x_i) on the symmetric interior patches), and the
/// patch test on the target vertices whose support lies inside [0, 1]^2.
void check_flat_non_matching(const Grid& c, const Grid& t) {
    const Vec3 n = Vec3::UnitZ();
    const auto f = [](const Vec3& x) { return 1.0 + 2.0 * x.x() - 3.0 * x.y() + 5.0 * x.z(); };
    const double p = 2.5; // uniform pressure
    std::map<int, double> load_seg, load_dual;
    double total = 0.0;
    for (int j = 0; j <= c.ny; ++j)
        for (int i = 0; i <= c.nx; ++i) {
            const int id = c.id(i, j);
            const auto patch = c.patch(id);
            const auto seg =
                contact::mortar_weights3(id, patch, n, t.tris, FacetIntegration::segment);
            const auto dual =
                contact::mortar_weights3(id, patch, n, t.tris, FacetIntegration::dual);
            SCOPED_TRACE("contactor vertex (" + std::to_string(i) + ", " + std::to_string(j) + ")");
            EXPECT_NEAR(weight_sum(seg), 0.0, 1e-14);
            EXPECT_NEAR(weight_sum(dual), 0.0, 1e-14);
            EXPECT_NEAR(seg.D_covered / seg.D, 1.0, 1e-13);
            EXPECT_TRUE(dual.dual);
            EXPECT_GT(seg.pieces, 0);
            // Linear fields.
            const Vec3& xi = c.at(id);
            EXPECT_NEAR(apply(dual, t, f), -f(xi), 1e-13);
            Vec3 centroid = Vec3::Zero();
            double patch_area = 0.0;
            for (const auto& tri : patch) {
                centroid += area(tri) * (tri.x[0] + tri.x[1] + tri.x[2]) / 3.0;
                patch_area += area(tri);
            }
            centroid /= patch_area;
            EXPECT_NEAR(apply(seg, t, f), -(0.25 * f(xi) + 0.75 * f(centroid)), 1e-13);
            if (i > 0 && j > 0 && i < c.nx && j < c.ny) {
                EXPECT_NEAR(apply(seg, t, f), -f(xi), 1e-13);
            }
            // Loads on the target from lambda_i = p D_i.
            for (size_t k = 0; k < seg.targets.size(); ++k)
                load_seg[seg.targets[k]] -= p * seg.D * seg.weights[k];
            for (size_t k = 0; k < dual.targets.size(); ++k)
                load_dual[dual.targets[k]] -= p * dual.D * dual.weights[k];
            total += p * seg.D;
        }
    // The whole load arrives, p times the contactor's area.
    double sum_seg = 0.0, sum_dual = 0.0;
    for (const auto& [k, F] : load_seg)
        sum_seg += F;
    for (const auto& [k, F] : load_dual)
        sum_dual += F;
    EXPECT_NEAR(total, p, 1e-13);
    EXPECT_NEAR(sum_seg, p, 1e-13);
    EXPECT_NEAR(sum_dual, p, 1e-13);
    // The patch test: p int N_k dA on the target vertices whose support is inside [0, 1]^2.
    int inside = 0;
    for (int k = t.first; k < t.first + static_cast<int>(t.x.size()); ++k) {
        const auto support = t.patch(k);
        bool in = support.size() == 6;
        double Nk = 0.0;
        for (const auto& tri : support) {
            Nk += area(tri) / 3.0;
            for (const Vec3& x : tri.x)
                in = in && x.x() >= 0.0 && x.x() <= 1.0 && x.y() >= 0.0 && x.y() <= 1.0;
        }
        if (!in) continue;
        ++inside;
        EXPECT_NEAR(load_seg[k], p * Nk, 1e-14) << "target vertex " << k;
        EXPECT_NEAR(load_dual[k], p * Nk, 1e-14) << "target vertex " << k;
    }
    EXPECT_GE(inside, 9);
}

} // namespace mortar3_tests

TEST(Mortar3Weights, NonMatchingRotatedFlatMeshes) {
    // Contactor: 8 x 8 cells of [0, 1]^2; target: 20 x 20 cells of 0.11 turned by 17 degrees about
    // (0.5, 0.5), which covers the contactor.
    const Grid c = make_grid(8, 8, 0.125, Vec2(0, 0), 0.0, flat, 0, false);
    const double a = 17.0 * std::numbers::pi / 180, h = 0.11;
    const Vec2 origin = Vec2(0.5, 0.5) - Vec2(std::cos(a) * 10 * h - std::sin(a) * 10 * h,
                                              std::sin(a) * 10 * h + std::cos(a) * 10 * h);
    const Grid t = make_grid(20, 20, h, origin, a, flat, 1000, true);
    check_flat_non_matching(c, t);
}

TEST(Mortar3Weights, NonMatchingFlatMeshesOfDifferentSpacing) {
    // Spacings 1/6 and 1/4: grid lines coincide at x, y = 0, 1/2, 1 (overlaps meeting in edges).
    const Grid c = make_grid(6, 6, 1.0 / 6, Vec2(0, 0), 0.0, flat, 0, false);
    const Grid t = make_grid(6, 6, 0.25, Vec2(-0.25, -0.25), 0.0, flat, 1000, true);
    check_flat_non_matching(c, t);
}

TEST(Mortar3Weights, CurvedSurfacesSumToZeroAndKeepInPlaneLinearFields) {
    // Target: the paraboloid z = 0.1 (x^2 + y^2) - 0.05 (normal up); contactor over it on a
    // wavy surface (normal down), non-matching; n the target's normal under the node.
    const Grid c = make_grid(
        8, 8, 0.125, Vec2(0, 0), 0.0,
        [](double x, double y) { return 0.02 + 0.03 * std::sin(3 * x) * std::cos(2 * y); }, 0,
        false);
    const auto zt = [](double x, double y) { return 0.1 * (x * x + y * y) - 0.05; };
    const Grid t = make_grid(10, 10, 0.15, Vec2(-0.25, -0.25), 0.0, zt, 1000, true);
    for (int j = 0; j <= c.ny; ++j)
        for (int i = 0; i <= c.nx; ++i) {
            const int id = c.id(i, j);
            const Vec3& xi = c.at(id);
            const Vec3 n = Vec3(-0.2 * xi.x(), -0.2 * xi.y(), 1.0).normalized();
            const auto patch = c.patch(id);
            SCOPED_TRACE("contactor vertex (" + std::to_string(i) + ", " + std::to_string(j) + ")");
            const auto seg =
                contact::mortar_weights3(id, patch, n, t.tris, FacetIntegration::segment);
            const auto dual =
                contact::mortar_weights3(id, patch, n, t.tris, FacetIntegration::dual);
            EXPECT_NEAR(weight_sum(seg), 0.0, 1e-14);
            EXPECT_NEAR(weight_sum(dual), 0.0, 1e-14);
            double D = 0.0;
            Vec3 centroid = Vec3::Zero();
            for (const auto& tri : patch) {
                D += area(tri) / 3.0;
                centroid += area(tri) * (tri.x[0] + tri.x[1] + tri.x[2]) / 3.0;
            }
            centroid /= 3.0 * D;
            EXPECT_NEAR(seg.D, D, 1e-15);
            EXPECT_NEAR(seg.D_covered / D, 1.0, 1e-13);
            EXPECT_TRUE(dual.dual);
            // A field linear in the plane's coordinates is the same on both surfaces along n.
            const Eigen::Matrix<double, 3, 2> tb = contact::tangent_basis<3>(n);
            const auto f = [&](const Vec3& x) {
                return 1.0 + 2.0 * tb.col(0).dot(x) - 3.0 * tb.col(1).dot(x);
            };
            EXPECT_NEAR(apply(dual, t, f), -f(xi), 1e-13);
            EXPECT_NEAR(apply(seg, t, f), -(0.25 * f(xi) + 0.75 * f(centroid)), 1e-13);
        }
}

TEST(Mortar3Weights, PartlyCoveredPatchKeepsTheSegmentForm) {
    // Contactor [0, 1]^2 (h = 1/4) over a target that ends at x = 1/2 (h = 1/8).
    const Grid c = make_grid(4, 4, 0.25, Vec2(0, 0), 0.0, flat, 0, false);
    const Grid t = make_grid(8, 16, 0.125, Vec2(-0.5, -0.5), 0.0, flat, 1000, true);
    const Vec3 n = Vec3::UnitZ();
    // Node (1/2, 1/2): half of its (centrally symmetric) patch is covered.
    const int half = c.id(2, 2);
    const auto seg =
        contact::mortar_weights3(half, c.patch(half), n, t.tris, FacetIntegration::segment);
    const auto dual =
        contact::mortar_weights3(half, c.patch(half), n, t.tris, FacetIntegration::dual);
    EXPECT_NEAR(seg.D, 0.0625, 1e-16);
    EXPECT_NEAR(seg.D_covered, 0.5 * seg.D, 1e-16);
    EXPECT_FALSE(dual.dual);
    EXPECT_EQ(dual.targets, seg.targets);
    EXPECT_EQ(dual.weights, seg.weights);
    EXPECT_EQ(dual.D_covered, seg.D_covered);
    EXPECT_NEAR(weight_sum(seg), 0.0, 1e-14);
    // Node (3/4, 1/2): its patch lies beyond the target, touching it along x = 1/2.
    const int off = c.id(3, 2);
    const auto none =
        contact::mortar_weights3(off, c.patch(off), n, t.tris, FacetIntegration::dual);
    EXPECT_EQ(none.pieces, 0);
    EXPECT_TRUE(none.targets.empty());
    EXPECT_EQ(none.D_covered, 0.0);
    EXPECT_NEAR(none.D, 0.0625, 1e-16);
    // Node (1/4, 1/2): entirely covered, dual.
    const int in = c.id(1, 2);
    const auto full = contact::mortar_weights3(in, c.patch(in), n, t.tris, FacetIntegration::dual);
    EXPECT_TRUE(full.dual);
    EXPECT_NEAR(full.D_covered, full.D, 1e-15);
}

TEST(Mortar3Weights, TrianglesFacingAwaySharingAVertexOrOutOfReachDoNotCount) {
    const Grid c = make_grid(4, 4, 0.25, Vec2(0, 0), 0.0, flat, 0, false);
    const Grid t = make_grid(
        6, 6, 0.2, Vec2(-0.1, -0.1), 0.0, [](double, double) { return -1.0; }, 1000, true);
    const Vec3 n = Vec3::UnitZ();
    const int i = c.id(2, 2);
    const auto patch = c.patch(i);
    const auto base = contact::mortar_weights3(i, patch, n, t.tris, FacetIntegration::segment);
    EXPECT_GT(base.pieces, 6);
    EXPECT_NEAR(base.D_covered, base.D, 1e-15);
    // Within reach 1.5 of the gap 1, but not 0.5.
    const auto near = contact::mortar_weights3(i, patch, n, t.tris, FacetIntegration::segment, 1.5);
    EXPECT_EQ(near.pieces, base.pieces);
    EXPECT_EQ(near.weights, base.weights);
    EXPECT_EQ(contact::mortar_weights3(i, patch, n, t.tris, FacetIntegration::segment, 0.5).pieces,
              0);
    // The target's back (normal down) nearer than the front: ignored.
    const Grid back = make_grid(
        6, 6, 0.2, Vec2(-0.1, -0.1), 0.0, [](double, double) { return -0.5; }, 2000, false);
    std::vector<SurfaceTriangle> both = back.tris;
    both.insert(both.end(), t.tris.begin(), t.tris.end());
    const auto with_back = contact::mortar_weights3(i, patch, n, both, FacetIntegration::segment);
    EXPECT_EQ(with_back.pieces, base.pieces);
    EXPECT_EQ(with_back.targets, base.targets);
    EXPECT_EQ(with_back.weights, base.weights);
    EXPECT_EQ(contact::mortar_weights3(i, patch, n, back.tris, FacetIntegration::segment).pieces,
              0);
    // The contactor's own triangles turned to face n share its vertices: ignored.
    std::vector<SurfaceTriangle> own = patch;
    for (auto& tri : own) {
        std::swap(tri.v[1], tri.v[2]);
        std::swap(tri.x[1], tri.x[2]);
    }
    EXPECT_EQ(contact::mortar_weights3(i, patch, n, own, FacetIntegration::dual).pieces, 0);
}

TEST(Mortar3Weights, RefusesDegenerateTrianglesAndBadArguments) {
    SurfaceTriangle good;
    good.v = {0, 2, 1};
    good.x = {Vec3(0, 0, 0), Vec3(0, 1, 0), Vec3(1, 0, 0)};
    SurfaceTriangle flat_tri;
    flat_tri.v = {0, 1, 2};
    flat_tri.x = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)};
    SurfaceTriangle target;
    target.v = {7, 8, 9};
    target.x = {Vec3(0, 0, -0.1), Vec3(1, 0, -0.1), Vec3(0, 1, -0.1)};
    SurfaceTriangle target_flat = target;
    target_flat.x[2] = Vec3(0.5, 0, -0.1);
    const Vec3 n = Vec3::UnitZ();
    const auto seg = FacetIntegration::segment;
    EXPECT_EQ(refusal([&] { contact::mortar_weights3(0, {flat_tri}, n, {target}, seg); }),
              "mortar weights of contactor node 0: the contactor triangle (0, 1, 2) (vertices "
              "(0, 0, 0) (1, 0, 0) (2, 0, 0)) has zero area");
    EXPECT_EQ(refusal([&] {
                  contact::mortar_weights3(0, {good}, n, {target, target_flat}, seg);
              }),
              "mortar weights of contactor node 0: the target triangle (7, 8, 9) (vertices "
              "(0, 0, -0.1) (1, 0, -0.1) (0.5, 0, -0.1)) has zero area");
    EXPECT_EQ(refusal([&] { contact::mortar_weights3(5, {good}, n, {target}, seg); }),
              "mortar weights of contactor node 5: the patch triangle (0, 2, 1) does not have it");
    EXPECT_EQ(refusal([&] { contact::mortar_weights3(0, {}, n, {target}, seg); }),
              "mortar weights of contactor node 0: the patch has no triangle (the node is on no "
              "contactor boundary triangle)");
    EXPECT_EQ(refusal([&] { contact::mortar_weights3(0, {good}, Vec3::Zero(), {target}, seg); }),
              "mortar weights of contactor node 0: the normal (0, 0, 0) is zero or not finite");
    EXPECT_EQ(
        refusal([&] { contact::mortar_weights3(0, {good}, n, {target}, FacetIntegration::nodal); }),
        "mortar weights of contactor node 0: the integration must be segment or dual, found "
        "nodal");
    // The good pair itself: one piece, the overlap of the two unit right triangles.
    const auto w = contact::mortar_weights3(0, {good}, n, {target}, seg);
    EXPECT_EQ(w.pieces, 1);
    EXPECT_NEAR(w.D, 1.0 / 6, 1e-16);
    // N_0 of the contactor and N_7 of the target coincide on the same triangle: M = 1/12.
    EXPECT_NEAR(weight_map(w).at(7), -0.5, 1e-15);
}

TEST(Mortar3Weights, ElementWithManyTargetsIsExactForRigidAndLinearFields) {
    // A coarse contactor (2 x 2 cells of 0.5 over [0, 1]^2 at height h, normal down) over a fine
    // target (cells of 0.15 turned by 17 degrees about (0.5, 0.5), at z = 0): the middle node
    // (0.5, 0.5, h), whose patch is symmetric about it, gets many target vertices, and a
    // node-on-facet element is built from its segment weights.
    const double h = 0.01;
    const Grid c = make_grid(
        2, 2, 0.5, Vec2(0, 0), 0.0, [&](double, double) { return h; }, 0, false);
    const double a = 17.0 * std::numbers::pi / 180, ht = 0.15;
    const Vec2 origin = Vec2(0.5, 0.5) - Vec2(std::cos(a) * 7 * ht - std::sin(a) * 7 * ht,
                                              std::sin(a) * 7 * ht + std::cos(a) * 7 * ht);
    const Grid t = make_grid(14, 14, ht, origin, a, flat, 1000, true);
    const int node = c.id(1, 1);
    const Vec3 n = Vec3::UnitZ();
    const auto w =
        contact::mortar_weights3(node, c.patch(node), n, t.tris, FacetIntegration::segment);
    ASSERT_NEAR(w.D_covered / w.D, 1.0, 1e-13); // the whole patch lies over the target
    const double mu = 0.3, r = 5.0;
    const auto e = contact::node_on_facet_weighted<3>(node, w.targets, w.weights, n, h, mu, r, 0);
    ASSERT_EQ(e.n_nodes(), 1 + static_cast<int>(w.targets.size()));
    EXPECT_GE(e.n_nodes(), 13); // more than twelve target vertices
    EXPECT_EQ(e.vertex[0], node);
    double sum = 0.0;
    for (int j = 1; j < e.n_nodes(); ++j)
        sum += e.weight[static_cast<size_t>(j)];
    EXPECT_NEAR(sum, -1.0, 1e-14);
    EXPECT_EQ(e.t, contact::tangent_basis<3>(n));

    // Nodal displacements of the field u on every vertex; the previous step at rest.
    const int n_vertices = t.first + static_cast<int>(t.x.size());
    auto nodal = [&](const std::function<Vec3(const Vec3&)>& u) {
        Vector out = Vector::Zero(3 * n_vertices);
        for (int id = 0; id < static_cast<int>(c.x.size()); ++id)
            out.segment<3>(3 * (c.first + id)) = u(c.x[static_cast<size_t>(id)]);
        for (int id = 0; id < static_cast<int>(t.x.size()); ++id)
            out.segment<3>(3 * (t.first + id)) = u(t.x[static_cast<size_t>(id)]);
        return out;
    };
    const Vector rest = Vector::Zero(3 * n_vertices);
    const Vector lambda = Vector::Zero(3);

    // A rigid translation opens no gap and slips nothing.
    const Vec3 b(0.3, -0.7, 0.2);
    const auto s0 = contact::evaluate(e, nodal([&](const Vec3&) { return b; }), rest, lambda, 0);
    EXPECT_NEAR(s0.d_n, h, 1e-14);
    EXPECT_NEAR(s0.d_t.norm(), 0.0, 1e-14);

    // A linear field u = A x + b: u_rel = A (x_c - p), p = (0.5, 0.5, 0) the projection of the
    // node on the target (the N_i-weighted mean of the symmetric patch is the node itself):
    // the relative displacement of the two material points, d_n = h + n . A (h e_z).
    Eigen::Matrix3d A;
    A << 0.3, -0.2, 0.5, 0.1, 0.4, -0.6, -0.7, 0.2, 0.9;
    const auto s1 = contact::evaluate(e, nodal([&](const Vec3& x) { return Vec3(A * x + b); }),
                                      rest, lambda, 0);
    const Vec3 du = A * Vec3(0, 0, h);
    EXPECT_NEAR(s1.d_n, h + n.dot(du), 1e-14);
    EXPECT_NEAR(s1.d_t[0], e.t.col(0).dot(du), 1e-14);
    EXPECT_NEAR(s1.d_t[1], e.t.col(1).dot(du), 1e-14);
    EXPECT_GT(std::abs(s1.d_t[0]) + std::abs(s1.d_t[1]), 1e-3); // the field does slip
}
