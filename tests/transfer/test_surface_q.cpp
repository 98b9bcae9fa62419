// SPDX-License-Identifier: MIT
// Tests of Q on contact surfaces in mass form (transfer/surface_q.hpp): the surface numbering and
// lumped masses, force conservation on a flat square, a non-planar graded surface and an octant of
// a sphere refined with its midpoints moved onto the sphere, exactness on linear tractions, the
// paper's weights on a uniform line, and the transfer of multipliers in per-node frames.
#include "core/check.hpp"
#include "mesh/tet_refine.hpp"
#include "tests/common/random.hpp"
#include "transfer/surface_q.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <string>

using namespace mlc;
using namespace mlc::transfer;
using Eigen::Vector3d;

namespace surface_q_testing {
namespace {

/// One level: all mesh vertices (some on no facet, standing for a body's inner vertices), the
/// surface facets, and the parents of the vertices added by the refinement that made it.
template <int F> struct Level {
    SurfacePoints x;
    SurfaceFacets<F> facets;
    VertexParents parents;
};

using Move = std::function<Vector3d(const Vector3d&)>;

/// Refines a level as mesh/tet_refine.hpp numbers things: coarse vertices keep their indices;
/// every surface edge and one edge from each vertex on no facet to the lowest surface vertex
/// (an inner edge of the body) gets a new vertex, numbered n + k in the order of the sorted
/// edges; segments split 1->2, triangles 1->4 (mesh::kFaceChildrenOf). New vertices of surface
/// edges are moved by `onto` when given.
template <int F> Level<F> refine_level(const Level<F>& c, const Move& onto = nullptr) {
    const int n = static_cast<int>(c.x.size());
    std::set<std::array<int, 2>> surface_edges, edges;
    std::vector<char> on_surface(c.x.size(), 0);
    for (const auto& f : c.facets)
        for (int a = 0; a < F; ++a) {
            const int u = f[static_cast<size_t>(a)], w = f[static_cast<size_t>((a + 1) % F)];
            surface_edges.insert({std::min(u, w), std::max(u, w)});
            on_surface[static_cast<size_t>(u)] = 1;
        }
    edges = surface_edges;
    const int lowest =
        static_cast<int>(std::find(on_surface.begin(), on_surface.end(), 1) - on_surface.begin());
    for (int v = 0; v < n; ++v)
        if (!on_surface[static_cast<size_t>(v)])
            edges.insert({std::min(v, lowest), std::max(v, lowest)});
    Level<F> f;
    f.x = c.x;
    std::map<std::array<int, 2>, int> mid;
    for (const auto& e : edges) {
        mid[e] = static_cast<int>(f.x.size());
        f.parents.push_back(e);
        Vector3d m = 0.5 * (c.x[static_cast<size_t>(e[0])] + c.x[static_cast<size_t>(e[1])]);
        if (onto && surface_edges.count(e)) m = onto(m);
        f.x.push_back(m);
    }
    auto m_of = [&](int u, int w) { return mid.at({std::min(u, w), std::max(u, w)}); };
    for (const auto& t : c.facets) {
        if constexpr (F == 2) {
            const int m = m_of(t[0], t[1]);
            f.facets.push_back({t[0], m});
            f.facets.push_back({m, t[1]});
        } else {
            const std::array<int, 6> local{
                t[0], t[1], t[2], m_of(t[0], t[1]), m_of(t[1], t[2]), m_of(t[2], t[0])};
            for (const auto& ch : mesh::kFaceChildrenOf)
                f.facets.push_back({local[static_cast<size_t>(ch[0])],
                                    local[static_cast<size_t>(ch[1])],
                                    local[static_cast<size_t>(ch[2])]});
        }
    }
    return f;
}

/// Renumbers a level-0 surface by a random permutation and inserts `extra` vertices on no
/// facet, so that surface indices and mesh vertices differ.
template <int F> Level<F> scramble(const Level<F>& s, int extra, unsigned seed) {
    const int n = static_cast<int>(s.x.size()) + extra;
    std::vector<int> perm(static_cast<size_t>(n));
    std::iota(perm.begin(), perm.end(), 0);
    std::shuffle(perm.begin(), perm.end(), std::mt19937(seed));
    Level<F> out;
    out.x.assign(static_cast<size_t>(n), Vector3d(7.0, 8.0, 9.0)); // extras: far from the surface
    for (size_t v = 0; v < s.x.size(); ++v)
        out.x[static_cast<size_t>(perm[v])] = s.x[v];
    for (auto f : s.facets) {
        for (auto& v : f)
            v = perm[static_cast<size_t>(v)];
        out.facets.push_back(f);
    }
    return out;
}

/// A structured nx x ny grid of triangles on [0, lx] x [0, ly] (diagonals alternating), mapped
/// by `place`.
Level<3> grid(int nx, int ny, double lx, double ly, const Move& place) {
    Level<3> s;
    for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i)
            s.x.push_back(place(Vector3d(lx * i / nx, ly * j / ny, 0.0)));
    auto id = [&](int i, int j) { return j * (nx + 1) + i; };
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
            if ((i + j) % 2 == 0) {
                s.facets.push_back({a, b, c});
                s.facets.push_back({a, c, d});
            } else {
                s.facets.push_back({a, b, d});
                s.facets.push_back({b, c, d});
            }
        }
    return s;
}

const Eigen::Matrix3d& rotation() {
    static const Eigen::Matrix3d R =
        (Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix());
    return R;
}

/// The unit square, rotated and shifted into a general plane.
Level<3> flat_square() {
    return grid(2, 2, 1.0, 1.0,
                [](const Vector3d& p) { return Vector3d(rotation() * p + Vector3d(0.5, -1, 2)); });
}

/// A 4 x 3 grid on [0, 2] x [0, 1] with its inner vertices moved at random in the plane and every
/// vertex lifted to a random height: graded, and not planar (flat facets).
Level<3> graded_surface() {
    Level<3> s = grid(4, 3, 2.0, 1.0, [](const Vector3d& p) { return p; });
    std::mt19937 gen(5);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    for (auto& p : s.x) {
        const bool inner = p.x() > 0 && p.x() < 2 && p.y() > 0 && p.y() < 1;
        if (inner) p += Vector3d(0.2 * U(gen), 0.1 * U(gen), 0.0);
        p.z() = 0.3 * U(gen);
    }
    return s;
}

const Vector3d kCentre(0.3, -0.2, 0.1);
constexpr double kRadius = 2.0;

Vector3d onto_sphere(const Vector3d& p) {
    return kCentre + kRadius * (p - kCentre).normalized();
}

/// An octant of the sphere (centre kCentre, radius kRadius): its octahedron face refined twice
/// with the midpoints moved onto the sphere (16 triangles), as level 0.
Level<3> sphere_octant() {
    Level<3> s;
    s.x = {kCentre + kRadius * Vector3d::UnitX(), kCentre + kRadius * Vector3d::UnitY(),
           kCentre + kRadius * Vector3d::UnitZ()};
    s.facets = {{0, 1, 2}};
    s = refine_level(refine_level(s, onto_sphere), onto_sphere);
    s.parents.clear();
    return s;
}

template <int F> SurfaceQ make_q(const Level<F>& c, const Level<F>& f, CoarseMass rule) {
    return build_surface_q<F>(c.x, c.facets, f.x, f.facets, f.parents, rule);
}

/// Nodal forces m_i t(x_i) of a traction field t at the surface vertices.
SurfaceForces nodal_forces(const SurfaceVertices& s, const SurfacePoints& x, const Vector& mass,
                           const std::function<Vector3d(const Vector3d&)>& t) {
    SurfaceForces out(s.size(), 3);
    for (int i = 0; i < s.size(); ++i)
        out.row(i) =
            mass[i] * t(x[static_cast<size_t>(s.vertex[static_cast<size_t>(i)])]).transpose();
    return out;
}

/// A linear traction t(x) = A x + b.
Vector3d linear_traction(const Vector3d& x) {
    Eigen::Matrix3d A;
    A << 1.0, -0.5, 0.25, 0.3, 2.0, -1.1, -0.7, 0.6, 1.4;
    return A * x + Vector3d(0.1, -0.2, 0.3);
}

double max_abs(const SurfaceForces& f) {
    return f.cwiseAbs().maxCoeff();
}

/// The tangent frame of the contact law: t1 = normalize(e x n), e the coordinate axis least
/// aligned with n, t2 = n x t1.
NodeFrame frame_of(const Vector3d& n) {
    Eigen::Index axis = 0;
    n.cwiseAbs().minCoeff(&axis);
    const Vector3d t1 = Vector3d::Unit(axis).cross(n).normalized();
    return {t1, n.cross(t1), n};
}

std::vector<NodeFrame> sphere_frames(const SurfaceVertices& s, const SurfacePoints& x) {
    std::vector<NodeFrame> out;
    for (int v : s.vertex)
        out.push_back(frame_of((x[static_cast<size_t>(v)] - kCentre).normalized()));
    return out;
}

struct Case {
    std::string name;
    std::vector<Level<3>> levels; // 0, 1, 2
    bool curved;
};

std::vector<Case> cases() {
    std::vector<Case> out;
    auto ladder = [](Level<3> l0, const Move& onto) {
        std::vector<Level<3>> l{std::move(l0)};
        for (int k = 1; k <= 2; ++k)
            l.push_back(refine_level(l.back(), onto));
        return l;
    };
    out.push_back({"flat square", ladder(scramble(flat_square(), 3, 1u), nullptr), false});
    out.push_back({"graded surface", ladder(scramble(graded_surface(), 5, 2u), nullptr), false});
    out.push_back({"sphere octant", ladder(scramble(sphere_octant(), 4, 3u), onto_sphere), true});
    return out;
}

} // namespace
} // namespace surface_q_testing

using namespace surface_q_testing;

TEST(SurfaceQ, SurfaceNumberingAndLumpedMasses) {
    const Level<3> s = scramble(flat_square(), 3, 1u);
    const SurfaceVertices sv = surface_vertices<3>(s.facets, static_cast<int>(s.x.size()));
    ASSERT_EQ(sv.size(), 9);
    ASSERT_EQ(sv.index.size(), 12u);
    EXPECT_TRUE(std::is_sorted(sv.vertex.begin(), sv.vertex.end()));
    int off = 0;
    for (size_t v = 0; v < s.x.size(); ++v) {
        const int i = sv.index[v];
        if (i < 0) {
            ++off;
            EXPECT_EQ(s.x[v], Vector3d(7.0, 8.0, 9.0));
        } else {
            EXPECT_EQ(sv.vertex[static_cast<size_t>(i)], static_cast<int>(v));
        }
    }
    EXPECT_EQ(off, 3);
    // The unit square in 2 x 2 cells of 2 triangles of area 1/8, the diagonals alternating so
    // that all four go through the centre: it touches 8 triangles, every other vertex 2.
    const Vector m = lumped_surface_masses<3>(s.x, s.facets, sv);
    EXPECT_NEAR(m.sum(), 1.0, 1e-15);
    std::multiset<long> counts; // m_i / (area / 3) = number of triangles touching i
    for (int i = 0; i < sv.size(); ++i)
        counts.insert(std::lround(m[i] * 24.0));
    EXPECT_EQ(counts, (std::multiset<long>{2, 2, 2, 2, 2, 2, 2, 2, 8}));
    for (int i = 0; i < sv.size(); ++i)
        EXPECT_NEAR(m[i] * 24.0, static_cast<double>(std::lround(m[i] * 24.0)), 1e-13);
}

TEST(SurfaceQ, ConservesTheTotalForceOfRandomForces) {
    for (const Case& c : cases())
        for (int l = 1; l <= 2; ++l) {
            SCOPED_TRACE(c.name + " level " + std::to_string(l));
            const auto& coarse = c.levels[static_cast<size_t>(l - 1)];
            const auto& fine = c.levels[static_cast<size_t>(l)];
            const SurfaceQ q = make_q(coarse, fine, CoarseMass::on_fine_surface);
            ASSERT_EQ(q.Q.cols(), q.coarse.size());
            ASSERT_EQ(q.Q.rows(), q.fine.size());
            EXPECT_EQ(q.Q.nonZeros(), q.P.nonZeros());
            SurfaceForces lambda(q.coarse.size(), 3);
            for (int k = 0; k < 3; ++k)
                lambda.col(k) = testutil::random_vector(
                    q.coarse.size(), 10u * static_cast<unsigned>(l) + static_cast<unsigned>(k));
            const SurfaceForces out = transfer_forces(q, lambda);
            const double scale = lambda.rowwise().norm().sum();
            EXPECT_LE((out.colwise().sum() - lambda.colwise().sum()).norm(), 1e-12 * scale);
            // Every column of Q sums to one.
            const Vector ones = Vector::Ones(q.Q.rows());
            EXPECT_LE((q.Q.transpose() * ones - Vector::Ones(q.Q.cols())).lpNorm<Eigen::Infinity>(),
                      1e-14);
            // The coarse level's own masses: the same Q where the fine surface lies on the coarse
            // one; on the sphere, a uniform traction's total grows with the area.
            const SurfaceQ own = make_q(coarse, fine, CoarseMass::own);
            const double area_ratio = q.fine_mass.sum() / q.coarse_mass.sum();
            if (!c.curved) {
                EXPECT_NEAR(area_ratio, 1.0, 1e-14);
                EXPECT_LE((q.coarse_mass - q.coarse_mass_on_fine).lpNorm<Eigen::Infinity>(),
                          1e-14 * q.coarse_mass.sum());
                const SurfaceForces out_own = transfer_forces(own, lambda);
                EXPECT_LE((out_own.colwise().sum() - lambda.colwise().sum()).norm(), 1e-12 * scale);
            } else {
                EXPECT_GT(area_ratio, 1.0 + 1e-3);
                const SurfaceForces uniform =
                    nodal_forces(q.coarse, coarse.x, q.coarse_mass,
                                 [](const Vector3d&) { return Vector3d(0.5, -1.0, 2.0); });
                const Eigen::RowVector3d total_h = transfer_forces(own, uniform).colwise().sum();
                const Eigen::RowVector3d total_H = uniform.colwise().sum();
                EXPECT_LE((total_h - area_ratio * total_H).norm(), 1e-13 * total_H.norm());
            }
        }
}

TEST(SurfaceQ, ExactOnLinearTractions) {
    for (const Case& c : cases())
        for (int l = 1; l <= 2; ++l)
            for (CoarseMass rule : {CoarseMass::on_fine_surface, CoarseMass::own}) {
                const bool own = rule == CoarseMass::own;
                SCOPED_TRACE(c.name + " level " + std::to_string(l) + (own ? " own" : " on fine"));
                const auto& coarse = c.levels[static_cast<size_t>(l - 1)];
                const auto& fine = c.levels[static_cast<size_t>(l)];
                const SurfaceQ q = make_q(coarse, fine, rule);
                const Vector& mH = own ? q.coarse_mass : q.coarse_mass_on_fine;
                const SurfaceForces out =
                    transfer_forces(q, nodal_forces(q.coarse, coarse.x, mH, linear_traction));
                const SurfaceForces at_vertices =
                    nodal_forces(q.fine, fine.x, q.fine_mass, linear_traction);
                if (!c.curved) {
                    // m_H,i t(x_i) -> m_h,j t(x_j).
                    EXPECT_LE(max_abs(out - at_vertices), 1e-13 * max_abs(at_vertices));
                    continue;
                }
                // Curved: the coarse traction is interpolated linearly, so a moved midpoint gets
                // t at its chord midpoint (the mean of its parents), not at itself.
                SurfacePoints chord = fine.x;
                for (size_t k = 0; k < fine.parents.size(); ++k)
                    chord[coarse.x.size() + k] =
                        0.5 * (coarse.x[static_cast<size_t>(fine.parents[k][0])] +
                               coarse.x[static_cast<size_t>(fine.parents[k][1])]);
                const SurfaceForces at_chords =
                    nodal_forces(q.fine, chord, q.fine_mass, linear_traction);
                EXPECT_LE(max_abs(out - at_chords), 1e-13 * max_abs(at_chords));
                EXPECT_GT(max_abs(out - at_vertices), 1e-4 * max_abs(at_vertices));
            }
}

TEST(SurfaceQ, UniformLineGivesThePapersWeights) {
    // Five vertices on a line with four segments of length 0.5, in the 1D form (segments).
    Level<2> line;
    for (int i = 0; i <= 4; ++i)
        line.x.emplace_back(0.5 * i, 0.0, 0.0);
    for (int i = 0; i < 4; ++i)
        line.facets.push_back({i, i + 1});
    const Level<2> fine = refine_level(line);
    const SurfaceQ q = make_q(line, fine, CoarseMass::on_fine_surface);
    ASSERT_EQ(q.coarse.size(), 5);
    ASSERT_EQ(q.fine.size(), 9);
    EXPECT_EQ(q.coarse.vertex, (std::vector<int>{0, 1, 2, 3, 4}));
    EXPECT_NEAR(q.coarse_mass[0], 0.25, 1e-15);
    EXPECT_NEAR(q.coarse_mass[2], 0.5, 1e-15);
    const Eigen::MatrixXd Q(q.Q);
    for (int i = 0; i < 5; ++i) // coarse vertex i keeps half of its force, ends included
        EXPECT_NEAR(Q(i, i), 0.5, 1e-15) << "coarse vertex " << i;
    for (int k = 0; k < 4; ++k) { // the midpoint of (k, k + 1) is fine vertex 5 + k
        const int m = 5 + k;
        for (int p : {k, k + 1}) {
            const bool end = p == 0 || p == 4;
            EXPECT_NEAR(Q(m, p), end ? 0.5 : 0.25, 1e-15) << "midpoint " << m << " parent " << p;
        }
        EXPECT_EQ((Q.row(m).array() != 0).count(), 2);
    }
    // Inner columns: the paper's Q = P / 2.
    const Eigen::MatrixXd P(q.P);
    for (int i = 1; i <= 3; ++i)
        EXPECT_LE((Q.col(i) - 0.5 * P.col(i)).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(SurfaceQ, GradedLineKeepsHalfAtCoarseVertices) {
    Level<2> line;
    const std::vector<double> x{0.0, 0.3, 1.0, 1.2, 2.0};
    for (double xi : x)
        line.x.emplace_back(xi, 0.0, 0.0);
    for (int i = 0; i < 4; ++i)
        line.facets.push_back({i, i + 1});
    const Level<2> fine = refine_level(line);
    const SurfaceQ q = make_q(line, fine, CoarseMass::on_fine_surface);
    const Eigen::MatrixXd Q(q.Q);
    for (int i = 0; i < 5; ++i) {
        EXPECT_NEAR(Q(i, i), 0.5, 1e-14);
        EXPECT_NEAR(Q.col(i).sum(), 1.0, 1e-14);
    }
    for (int k = 0; k < 4; ++k) {
        const double len = x[static_cast<size_t>(k + 1)] - x[static_cast<size_t>(k)];
        for (int p : {k, k + 1})
            EXPECT_NEAR(Q(5 + k, p), len / (4.0 * q.coarse_mass[p]), 1e-14);
    }
}

TEST(SurfaceQ, FrictionalMultipliersTravelInGlobalComponents) {
    const auto levels = cases()[2].levels;
    const Vector3d g(0.5, -1.0, 2.0); // a uniform traction in global components
    for (int l = 1; l <= 2; ++l) {
        SCOPED_TRACE("level " + std::to_string(l));
        const auto& coarse = levels[static_cast<size_t>(l - 1)];
        const auto& fine = levels[static_cast<size_t>(l)];
        const SurfaceQ q = make_q(coarse, fine, CoarseMass::on_fine_surface);
        const auto fc = sphere_frames(q.coarse, coarse.x), ff = sphere_frames(q.fine, fine.x);
        SurfaceForces local(q.coarse.size(), 3);
        for (int i = 0; i < q.coarse.size(); ++i)
            local.row(i) =
                to_local(fc[static_cast<size_t>(i)], q.coarse_mass_on_fine[i] * g).transpose();
        const SurfaceForces out = transfer_local_forces(q, local, fc, ff);
        SurfaceForces global(q.fine.size(), 3), naive(q.fine.size(), 3);
        const SurfaceForces naive_local = q.Q * local; // component by component: wrong
        for (int j = 0; j < q.fine.size(); ++j) {
            global.row(j) =
                to_global(ff[static_cast<size_t>(j)], out.row(j).transpose()).transpose();
            naive.row(j) =
                to_global(ff[static_cast<size_t>(j)], naive_local.row(j).transpose()).transpose();
        }
        const SurfaceForces expected = q.fine_mass * g.transpose();
        EXPECT_LE(max_abs(global - expected), 1e-14 * max_abs(expected));
        EXPECT_GT(max_abs(naive - expected), 1e-2 * max_abs(expected));
        // The frames of neighbouring nodes differ: a node's frame is not the same as its parents'.
        double frame_change = 0;
        for (size_t k = 0; k < fine.parents.size(); ++k) {
            const int j = q.fine.index[coarse.x.size() + k];
            if (j < 0) continue;
            const int a = q.coarse.index[static_cast<size_t>(fine.parents[k][0])];
            frame_change =
                std::max(frame_change,
                         (ff[static_cast<size_t>(j)].t1 - fc[static_cast<size_t>(a)].t1).norm());
        }
        EXPECT_GT(frame_change, 0.03);
    }
}

TEST(SurfaceQ, RefusesSurfacesThatDoNotNest) {
    Level<3> c = grid(1, 1, 1.0, 1.0, [](const Vector3d& p) { return p; });
    const Level<3> f = refine_level(c);
    // A coarse surface vertex missing from the fine surface.
    Level<3> f_missing = f;
    f_missing.facets.resize(4); // the children of the first coarse triangle only
    EXPECT_THROW(make_q(c, f_missing, CoarseMass::on_fine_surface), InvalidInput);
    // A fine midpoint whose parent is off the coarse surface: the coarse surface is the first
    // triangle, the fine one its children and the middle child of the second triangle.
    Level<3> c_half = c, f_beyond = f;
    c_half.facets.resize(1);
    f_beyond.facets = {f.facets[0], f.facets[1], f.facets[2], f.facets[3], f.facets[7]};
    EXPECT_THROW(make_q(c_half, f_beyond, CoarseMass::on_fine_surface), InvalidInput);
    EXPECT_NO_THROW(make_q(c_half, f_missing, CoarseMass::on_fine_surface));
    // Sizes that do not match the parents, a degenerate facet.
    Level<3> f_short = f;
    f_short.parents.pop_back();
    EXPECT_THROW(make_q(c, f_short, CoarseMass::on_fine_surface), InvalidInput);
    Level<3> c_flat = c;
    c_flat.x[2] = 0.5 * (c.x[0] + c.x[1]);
    c_flat.facets = {{0, 1, 2}};
    EXPECT_THROW(
        lumped_surface_masses<3>(c_flat.x, c_flat.facets, surface_vertices<3>(c_flat.facets, 4)),
        InvalidInput);
    // Frames that are not orthonormal.
    const SurfaceQ q = make_q(c, f, CoarseMass::on_fine_surface);
    std::vector<NodeFrame> fc(static_cast<size_t>(q.coarse.size()),
                              NodeFrame{Vector3d::UnitX(), Vector3d::UnitY(), Vector3d::UnitZ()});
    std::vector<NodeFrame> ff(static_cast<size_t>(q.fine.size()), fc[0]);
    const SurfaceForces local = SurfaceForces::Ones(q.coarse.size(), 3);
    EXPECT_NO_THROW(transfer_local_forces(q, local, fc, ff));
    ff[3].t2 = Vector3d(0, 1, 1e-3);
    EXPECT_THROW(transfer_local_forces(q, local, fc, ff), InvalidInput);
}
