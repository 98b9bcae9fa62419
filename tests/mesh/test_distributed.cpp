// SPDX-License-Identifier: MIT
// The distributed hierarchy against the serially refined mesh, on any number of processes: ctest
// runs these tests alone (one process) and under mpirun -np 2 and -np 3 (label mpi). Midpoints
// are computed by the same arithmetic on every process, so vertices are matched by their exact
// coordinates.
#include "comm/world.hpp"
#include "core/check.hpp"
#include "mesh/distributed.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>

using namespace mlc;
using mesh::DistributedHierarchy;
using mesh::LocalLevel;
using mesh::Mesh;

namespace {

const Communicator& W() {
    return comm::world();
}

using Point = std::pair<double, double>;
Point point(const Mesh& m, int v) {
    return {m.vertices[static_cast<size_t>(v)].x(), m.vertices[static_cast<size_t>(v)].y()};
}

/// A 5 x 3 rectangle whose top edge lies on a circle (refinement moves its midpoints onto it).
Mesh curved_rectangle() {
    Mesh m = mesh::structured_rectangle({0, 0}, {1, 0.6}, 5, 3, mesh::Diagonal::alternate);
    m.shapes.push_back({{0.5, -10.0}, 10.6});
    const int top = m.tag("top");
    for (auto& e : m.boundary)
        if (e.tag == top) e.shape = 0;
    return m;
}

/// The serial hierarchy: level 0 and its refinements.
std::vector<Mesh> serial_levels(const Mesh& m0, int n_refinements) {
    std::vector<Mesh> s = {m0};
    for (int k = 0; k < n_refinements; ++k)
        s.push_back(mesh::refine(s.back()));
    return s;
}

/// Every process's owned vertices (global number -> coordinates) on every process.
std::map<std::int64_t, Point> owned_table(const LocalLevel& L) {
    std::vector<std::int64_t> ids;
    std::vector<double> xy;
    for (int v : L.owned_vertices) {
        ids.push_back(L.global_vertex[static_cast<size_t>(v)]);
        const Point p = point(L.mesh, v);
        xy.push_back(p.first);
        xy.push_back(p.second);
    }
    const auto all_ids = W().allgather(std::span<const std::int64_t>(ids));
    const auto all_xy = W().allgather(std::span<const double>(xy));
    std::map<std::int64_t, Point> table;
    for (size_t i = 0; i < all_ids.size(); ++i)
        EXPECT_TRUE(table.emplace(all_ids[i], Point{all_xy[2 * i], all_xy[2 * i + 1]}).second)
            << "global vertex " << all_ids[i] << " owned twice";
    return table;
}

constexpr int n_refinements = 3;

} // namespace

TEST(Distributed, EveryVertexOwnedOnceWithContiguousNumbers) {
    const Mesh m0 = curved_rectangle();
    const auto serial = serial_levels(m0, n_refinements);
    const DistributedHierarchy H = mesh::distribute(m0, n_refinements, W());
    ASSERT_EQ(H.levels.size(), static_cast<size_t>(n_refinements + 1));
    EXPECT_EQ(H.n_processes, W().size());
    for (size_t l = 0; l < H.levels.size(); ++l) {
        SCOPED_TRACE("level " + std::to_string(l));
        const LocalLevel& L = H.levels[l];
        const Mesh& S = serial[l];
        EXPECT_EQ(L.n_global_vertices, S.n_vertices());
        EXPECT_EQ(L.n_global_triangles, S.n_cells());
        // Contiguous blocks in rank order: rank r starts where rank r - 1 ends.
        const auto firsts = W().allgather(std::span<const std::int64_t>(&L.first_vertex, 1));
        const std::int64_t n_owned = L.n_owned_vertices();
        const auto counts = W().allgather(std::span<const std::int64_t>(&n_owned, 1));
        std::int64_t next = 0;
        for (size_t q = 0; q < firsts.size(); ++q) {
            EXPECT_EQ(firsts[q], next);
            next += counts[q];
        }
        EXPECT_EQ(next, S.n_vertices());
        EXPECT_EQ(L.first_row(), 2 * L.first_vertex);
        for (int i = 0; i < L.n_owned_vertices(); ++i)
            EXPECT_EQ(
                L.global_vertex[static_cast<size_t>(L.owned_vertices[static_cast<size_t>(i)])],
                L.first_vertex + i);
        // The owned vertices of all processes are the serial mesh's vertices, each once.
        const auto table = owned_table(L);
        ASSERT_EQ(table.size(), static_cast<size_t>(S.n_vertices()));
        EXPECT_EQ(table.begin()->first, 0);
        EXPECT_EQ(table.rbegin()->first, S.n_vertices() - 1);
        std::set<Point> serial_points, owned_points;
        for (int v = 0; v < S.n_vertices(); ++v)
            serial_points.insert(point(S, v));
        for (const auto& [g, p] : table)
            owned_points.insert(p);
        EXPECT_EQ(owned_points, serial_points);
        // Ghost vertices carry their owner's number: the same coordinates.
        int ghosts = 0;
        for (int v = 0; v < L.mesh.n_vertices(); ++v) {
            const std::int64_t g = L.global_vertex[static_cast<size_t>(v)];
            ASSERT_TRUE(table.count(g)) << "local vertex " << v << " has global number " << g;
            EXPECT_EQ(table.at(g), point(L.mesh, v)) << "local vertex " << v;
            ghosts += L.vertex_owner[static_cast<size_t>(v)] != W().rank();
        }
        EXPECT_EQ(ghosts, L.n_ghost_vertices());
    }
}

// Every triangle owned by one process, and every triangle around an owned vertex local: the
// rows of the owned unknowns can be assembled from the local triangles.
TEST(Distributed, OwnedTrianglesTileTheMeshAndGhostsCompleteTheRows) {
    const Mesh m0 = curved_rectangle();
    const auto serial = serial_levels(m0, n_refinements);
    const DistributedHierarchy H = mesh::distribute(m0, n_refinements, W());
    for (size_t l = 0; l < H.levels.size(); ++l) {
        SCOPED_TRACE("level " + std::to_string(l));
        const LocalLevel& L = H.levels[l];
        const Mesh& S = serial[l];
        // Owned triangles as triples of global numbers, gathered: each serial triangle once.
        std::vector<std::int64_t> tri;
        double area = 0;
        for (int t = 0; t < L.mesh.n_cells(); ++t) {
            if (!L.triangle_owned[static_cast<size_t>(t)]) continue;
            std::array<std::int64_t, 3> g;
            for (int k = 0; k < 3; ++k)
                g[k] = L.global_vertex[static_cast<size_t>(L.mesh.cells[t][k])];
            std::sort(g.begin(), g.end());
            tri.insert(tri.end(), g.begin(), g.end());
            area += L.mesh.signed_measure(t);
        }
        const auto all = W().allgather(std::span<const std::int64_t>(tri));
        ASSERT_EQ(all.size(), 3 * static_cast<size_t>(S.n_cells()));
        const auto table = owned_table(L);
        std::set<std::array<Point, 3>> owned, expected;
        for (size_t i = 0; i < all.size(); i += 3)
            owned.insert({table.at(all[i]), table.at(all[i + 1]), table.at(all[i + 2])});
        double serial_area = 0;
        std::map<Point, int> serial_valence;
        for (int t = 0; t < S.n_cells(); ++t) {
            std::array<Point, 3> p;
            for (int k = 0; k < 3; ++k) {
                p[k] = point(S, S.cells[t][k]);
                ++serial_valence[p[k]];
            }
            std::sort(p.begin(), p.end());
            expected.insert(p);
            serial_area += S.signed_measure(t);
        }
        // Sorting by global number and by coordinates may differ: compare sorted coordinates.
        std::set<std::array<Point, 3>> owned_sorted;
        for (auto p : owned) {
            std::sort(p.begin(), p.end());
            owned_sorted.insert(p);
        }
        EXPECT_EQ(owned_sorted, expected);
        EXPECT_NEAR(W().sum(area), serial_area, 1e-12 * serial_area);
        std::vector<int> valence(static_cast<size_t>(L.mesh.n_vertices()), 0);
        for (const auto& t : L.mesh.cells)
            for (int v : t)
                ++valence[static_cast<size_t>(v)];
        for (int v : L.owned_vertices)
            EXPECT_EQ(valence[static_cast<size_t>(v)], serial_valence.at(point(L.mesh, v)))
                << "owned vertex " << v << " misses triangles around it";
    }
}

// Finer levels are nested per process: the coarse vertices keep their local indices, and the
// parents of a new vertex are local vertices of the level above at the two ends of its edge.
TEST(Distributed, LevelsAreNestedPerProcess) {
    const DistributedHierarchy H = mesh::distribute(curved_rectangle(), 2, W());
    for (size_t l = 1; l < H.levels.size(); ++l) {
        const Mesh& c = H.levels[l - 1].mesh;
        const Mesh& f = H.levels[l].mesh;
        ASSERT_EQ(f.n_coarse_vertices, c.n_vertices());
        for (int v = 0; v < c.n_vertices(); ++v)
            EXPECT_EQ(point(f, v), point(c, v));
        ASSERT_EQ(f.cells.size(), 4 * c.cells.size());
        for (size_t t = 0; t < f.cells.size(); ++t)
            EXPECT_EQ(H.levels[l].triangle_owned[t], H.levels[l - 1].triangle_owned[t / 4]);
    }
}

namespace {

/// Two stacked blocks, apart by 0.01, with non-matching meshes: the lower one's top tagged
/// "lower_top", the upper one's bottom "upper_bottom" (a contact interface).
Mesh two_blocks() {
    Mesh m = mesh::structured_rectangle({0, 0}, {1, 0.5}, 9, 5);
    const Mesh up = mesh::structured_rectangle({0, 0.51}, {1, 0.5}, 7, 4);
    const int lower_top = m.add_tag("lower_top");
    const int upper_bottom = m.add_tag("upper_bottom");
    for (auto& e : m.boundary)
        if (e.tag == m.tag("top")) e.tag = lower_top;
    const int off = m.n_vertices();
    for (const auto& x : up.vertices)
        m.vertices.push_back(x);
    for (auto t : up.cells) {
        for (int& v : t)
            v += off;
        m.cells.push_back(t);
    }
    for (auto e : up.boundary) {
        const std::string name = up.tag_name(e.tag);
        e.tag = name == "bottom" ? upper_bottom : m.add_tag("upper_" + name);
        e.v0 += off;
        e.v1 += off;
        m.boundary.push_back(e);
    }
    m.attribute.assign(static_cast<size_t>(m.n_cells()), 0);
    for (size_t t = m.cells.size() - up.cells.size(); t < m.cells.size(); ++t)
        m.attribute[t] = 1;
    return m;
}

double point_segment(const Vec2& x, const Vec2& a, const Vec2& b) {
    const Vec2 d = b - a;
    const double t = std::clamp((x - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
    return (x - (a + t * d)).norm();
}

} // namespace

// A ghost layer widened along a contact interface (mesh::GhostReach): on every level, every
// interface edge of the serial mesh within the reach of an owned interface vertex is local, so
// that the contact search of an owned node sees every facet it may need.
TEST(Distributed, GhostReachHoldsEveryInterfaceFacetWithinReach) {
    const Mesh m0 = two_blocks();
    const int tags[2] = {m0.tag("lower_top"), m0.tag("upper_bottom")};
    const double reach = 0.3;
    const auto serial = serial_levels(m0, 2);
    const DistributedHierarchy H = mesh::distribute(m0, 2, W(), {}, {{{tags[0], tags[1]}, reach}});
    const DistributedHierarchy H1 = mesh::distribute(m0, 2, W());
    // The widened layer holds more triangles (somewhere, on several processes).
    const std::int64_t wide = W().sum(static_cast<std::int64_t>(H.levels[0].mesh.n_cells()));
    const std::int64_t narrow = W().sum(static_cast<std::int64_t>(H1.levels[0].mesh.n_cells()));
    if (W().size() > 1) {
        EXPECT_GT(wide, narrow);
    }
    for (size_t l = 0; l < H.levels.size(); ++l) {
        SCOPED_TRACE("level " + std::to_string(l));
        const LocalLevel& L = H.levels[l];
        const Mesh& S = serial[l];
        std::set<std::pair<Point, Point>> local;
        for (const auto& e : L.mesh.boundary)
            local.insert(std::minmax(point(L.mesh, e.v0), point(L.mesh, e.v1)));
        std::vector<char> on_interface(static_cast<size_t>(L.mesh.n_vertices()), 0);
        for (const auto& e : L.mesh.boundary)
            if (e.tag == tags[0] || e.tag == tags[1])
                on_interface[static_cast<size_t>(e.v0)] = on_interface[static_cast<size_t>(e.v1)] =
                    1;
        int checked = 0;
        for (int v : L.owned_vertices) {
            if (!on_interface[static_cast<size_t>(v)]) continue;
            const Vec2& x = L.mesh.vertices[static_cast<size_t>(v)];
            for (const auto& e : S.boundary) {
                if (e.tag != tags[0] && e.tag != tags[1]) continue;
                if (point_segment(x, S.vertices[static_cast<size_t>(e.v0)],
                                  S.vertices[static_cast<size_t>(e.v1)]) > reach)
                    continue;
                ++checked;
                EXPECT_TRUE(local.count(std::minmax(point(S, e.v0), point(S, e.v1))))
                    << "interface edge at (" << S.vertices[static_cast<size_t>(e.v0)].x() << ", "
                    << S.vertices[static_cast<size_t>(e.v0)].y() << ") within " << reach
                    << " of owned vertex (" << x.x() << ", " << x.y() << ") is not local";
            }
        }
        EXPECT_GT(W().sum(checked), 0);
    }
}

TEST(Distributed, OneProcessIsTheSerialHierarchy) {
    const mlc::SerialCommunicator one;
    const Mesh m0 = curved_rectangle();
    const auto serial = serial_levels(m0, 2);
    const DistributedHierarchy H = mesh::distribute(m0, 2, one);
    for (size_t l = 0; l < H.levels.size(); ++l) {
        const LocalLevel& L = H.levels[l];
        EXPECT_EQ(L.mesh.vertices, serial[l].vertices);
        EXPECT_EQ(L.mesh.cells, serial[l].cells);
        EXPECT_EQ(L.mesh.boundary.size(), serial[l].boundary.size());
        EXPECT_EQ(L.n_ghost_vertices(), 0);
        for (int v = 0; v < L.mesh.n_vertices(); ++v)
            EXPECT_EQ(L.global_vertex[static_cast<size_t>(v)], v);
    }
}

TEST(Distributed, RejectsNegativeRefinementsAndTooManyProcesses) {
    EXPECT_THROW(mesh::distribute(curved_rectangle(), -1, W()), InvalidInput);
    Mesh two = mesh::structured_rectangle({0, 0}, {1, 1}, 1, 1);
    if (W().size() > 2) {
        EXPECT_THROW(mesh::distribute(two, 1, W()), InvalidInput);
    }
}

// A bad field on one process fails the write on every process, and no .pvtu appears.
TEST(Distributed, WriteFailsEverywhereWhenOneProcessFails) {
    const DistributedHierarchy H = mesh::distribute(curved_rectangle(), 1, W());
    const LocalLevel& L = H.levels.back();
    const auto dir = std::filesystem::temp_directory_path() / "mlc_test_distributed_write";
    if (W().rank() == 0) std::filesystem::create_directories(dir);
    W().barrier();
    const auto file = dir / ("bad_np" + std::to_string(W().size()) + ".pvtu");
    // The last process passes one value too few.
    const size_t n = static_cast<size_t>(L.mesh.n_vertices()) - (W().rank() + 1 == W().size());
    const mesh::Field f{"f", 1, std::vector<double>(n, 1.0)};
    EXPECT_ANY_THROW(mesh::write_distributed_vtu(file, L, {f}, {}, W()));
    W().barrier();
    EXPECT_FALSE(std::filesystem::exists(file));
    EXPECT_THROW(mesh::write_pvtu(dir / "x.pvtu", {}, {}, {}), InvalidInput);
    EXPECT_THROW(mesh::write_pvtu(dir / "x.pvtu", {"a.vtu"}, {mesh::Field{"", 1, {}}}, {}),
                 InvalidInput);
    EXPECT_THROW(mesh::write_pvtu(dir / "x.pvtu", {""}, {}, {}), InvalidInput);
    EXPECT_EQ(mesh::piece_path("out/solution.pvtu", 2),
              std::filesystem::path("out/solution_2.vtu"));
}
