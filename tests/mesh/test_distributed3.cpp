// SPDX-License-Identifier: MIT
// The distributed tetrahedral hierarchy (mesh/distributed3.hpp) and partition_tets against the
// serially refined mesh, on any number of processes: ctest runs these tests alone (one process)
// and under mpirun -np 1, 2 and 3 (label mpi). Midpoints, and their projections onto a curved
// surface, are computed by the same arithmetic on every process, so vertices are matched by their
// exact coordinates.
#include "comm/world.hpp"
#include "core/check.hpp"
#include "mesh/distributed3.hpp"
#include "mesh/tet_refine.hpp"
#include "tests/mesh/vtu_read.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

using namespace mlc;
using mesh::DistributedTetHierarchy;
using mesh::LocalTetLevel;
using mesh::TetMesh;
using mesh::Vec3;

namespace {

const Communicator& world3() {
    return comm::world();
}

using P3 = std::array<double, 3>;
P3 p3(const TetMesh& m, int v) {
    const Vec3& x = m.vertices[static_cast<size_t>(v)];
    return {x.x(), x.y(), x.z()};
}
using Tet3 = std::array<P3, 4>;
/// A tetrahedron by its sorted corner coordinates.
Tet3 tet3(const TetMesh& m, int t) {
    Tet3 c;
    for (size_t k = 0; k < 4; ++k)
        c[k] = p3(m, m.cells[static_cast<size_t>(t)][k]);
    std::sort(c.begin(), c.end());
    return c;
}

/// The centre and radius of the sphere the top of domed_box lies on.
const Vec3 kDomeCentre(0.5, 0.25, -1.5);
constexpr double kDomeRadius = 3.0;

/// A 2 x 1 x 3 box of cubes whose top (tag "zmax") is pushed up onto a sphere, which refinement
/// moves the midpoints of its faces' edges onto: the curved geometry must be the serial one
/// everywhere. Its partitions into 2 and 3 parts leave ghost tetrahedra that touch the dome by
/// an edge only (DomeEdgesOfGhostsAreOnTheSphere).
TetMesh domed_box() {
    TetMesh m = mesh::structured_box(Vec3::Zero(), Vec3(1, 0.5, 1.5), 2, 1, 3);
    for (Vec3& x : m.vertices)
        if (x.z() == 1.5) {
            const double dx = x.x() - kDomeCentre.x(), dy = x.y() - kDomeCentre.y();
            x.z() = kDomeCentre.z() + std::sqrt(kDomeRadius * kDomeRadius - dx * dx - dy * dy);
        }
    mesh::attach_surface(
        m, "zmax", {mesh::CurvedSurface::Kind::sphere, kDomeCentre, Vec3::UnitZ(), kDomeRadius});
    m.attribute.assign(m.cells.size(), 0);
    for (size_t t = 0; t < m.cells.size(); t += 5)
        m.attribute[t] = 1;
    return m;
}

std::vector<TetMesh> serial_tet_levels(const TetMesh& m0, int refinements) {
    std::vector<TetMesh> s = {m0};
    for (int k = 0; k < refinements; ++k)
        s.push_back(mesh::refine(s.back()));
    return s;
}

/// Every process's owned vertices (global number -> coordinates) on every process.
std::map<std::int64_t, P3> owned_table3(const LocalTetLevel& L) {
    std::vector<std::int64_t> ids;
    std::vector<double> xyz;
    for (int v : L.owned_vertices) {
        ids.push_back(L.global_vertex[static_cast<size_t>(v)]);
        for (double c : p3(L.mesh, v))
            xyz.push_back(c);
    }
    const auto all_ids = world3().allgather(std::span<const std::int64_t>(ids));
    const auto all_xyz = world3().allgather(std::span<const double>(xyz));
    std::map<std::int64_t, P3> table;
    for (size_t i = 0; i < all_ids.size(); ++i)
        EXPECT_TRUE(
            table.emplace(all_ids[i], P3{all_xyz[3 * i], all_xyz[3 * i + 1], all_xyz[3 * i + 2]})
                .second)
            << "global vertex " << all_ids[i] << " owned twice";
    return table;
}

constexpr int kTetRefinements = 2;

} // namespace

TEST(Distributed3, PartitionTetsIsBalancedDeterministicAndOwnsEveryVertex) {
    const TetMesh m = mesh::structured_box(Vec3::Zero(), Vec3(1, 1, 1), 3, 3, 3); // 162 tets
    for (int parts : {1, 2, 3, 5}) {
        SCOPED_TRACE("parts " + std::to_string(parts));
        const mesh::Partition P = mesh::partition_tets(m, parts);
        ASSERT_EQ(P.triangle_part.size(), m.cells.size());
        std::vector<int> count(static_cast<size_t>(parts), 0);
        for (int p : P.triangle_part) {
            ASSERT_GE(p, 0);
            ASSERT_LT(p, parts);
            ++count[static_cast<size_t>(p)];
        }
        for (int c : count)
            EXPECT_GT(c, 0);
        EXPECT_LE(P.imbalance(), 1.1);
        EXPECT_EQ(mesh::partition_tets(m, parts).triangle_part, P.triangle_part);
        // Cut faces: interior faces with tetrahedra of two parts beside them.
        std::map<std::array<int, 3>, std::vector<int>> beside;
        for (size_t t = 0; t < m.cells.size(); ++t)
            for (size_t k = 0; k < 4; ++k) {
                std::array<int, 3> f{m.cells[t][(k + 1) % 4], m.cells[t][(k + 2) % 4],
                                     m.cells[t][(k + 3) % 4]};
                std::sort(f.begin(), f.end());
                beside[f].push_back(P.triangle_part[t]);
            }
        int cut = 0;
        for (const auto& [f, parts_beside] : beside)
            cut += parts_beside.size() == 2 && parts_beside[0] != parts_beside[1];
        EXPECT_EQ(P.cut_edges, cut);
        if (parts == 1) {
            EXPECT_EQ(cut, 0);
        }
        // The owner of a vertex is the part with most tetrahedra around it (ties: lower part).
        std::vector<std::map<int, int>> around(static_cast<size_t>(m.n_vertices()));
        for (size_t t = 0; t < m.cells.size(); ++t)
            for (int v : m.cells[t])
                ++around[static_cast<size_t>(v)][P.triangle_part[t]];
        for (int v = 0; v < m.n_vertices(); ++v) {
            int best = -1, most = 0;
            for (const auto& [p, c] : around[static_cast<size_t>(v)])
                if (c > most) {
                    best = p;
                    most = c;
                }
            EXPECT_EQ(P.vertex_owner[static_cast<size_t>(v)], best) << "vertex " << v;
        }
    }
    // Weights: a heavy half pulls the balance.
    std::vector<int> w(m.cells.size(), 1);
    for (size_t t = 0; t < w.size() / 2; ++t)
        w[t] = 3;
    const mesh::Partition W2 = mesh::partition_tets(m, 2, w);
    EXPECT_NEAR(W2.part_work[0] + W2.part_work[1], 3.0 * 81 + 81, 1e-12);
    EXPECT_LE(W2.imbalance(), 1.1);
    EXPECT_THROW(mesh::partition_tets(m, 0), InvalidInput);
    EXPECT_THROW(mesh::partition_tets(m, 163), InvalidInput);
    EXPECT_THROW(mesh::partition_tets(m, 2, {1, 2}), InvalidInput);
    EXPECT_THROW(mesh::partition_tets(m, 2, std::vector<int>(m.cells.size(), 0)), InvalidInput);
}

TEST(Distributed3, OneProcessIsTheSerialHierarchy) {
    const mlc::SerialCommunicator one;
    const TetMesh m0 = domed_box();
    const auto serial = serial_tet_levels(m0, kTetRefinements);
    const DistributedTetHierarchy H = mesh::distribute(m0, kTetRefinements, one);
    ASSERT_EQ(H.levels.size(), serial.size());
    for (size_t l = 0; l < H.levels.size(); ++l) {
        SCOPED_TRACE("level " + std::to_string(l));
        const LocalTetLevel& L = H.levels[l];
        const TetMesh& S = serial[l];
        EXPECT_EQ(L.mesh.vertices, S.vertices);
        EXPECT_EQ(L.mesh.cells, S.cells);
        EXPECT_EQ(L.mesh.attribute, S.attribute);
        ASSERT_EQ(L.mesh.boundary.size(), S.boundary.size());
        for (size_t b = 0; b < S.boundary.size(); ++b) {
            EXPECT_EQ(L.mesh.boundary[b].v, S.boundary[b].v);
            EXPECT_EQ(L.mesh.boundary[b].tag, S.boundary[b].tag);
            EXPECT_EQ(L.mesh.boundary[b].shape, S.boundary[b].shape);
        }
        if (l > 0) {
            EXPECT_EQ(L.mesh.parents, S.parents);
        }
        EXPECT_EQ(L.n_ghost_vertices(), 0);
        EXPECT_EQ(L.n_global_vertices, S.n_vertices());
        EXPECT_EQ(L.n_global_tets, S.n_cells());
        EXPECT_EQ(L.first_row(), 0);
        for (int v = 0; v < L.mesh.n_vertices(); ++v)
            EXPECT_EQ(L.global_vertex[static_cast<size_t>(v)], v);
        EXPECT_TRUE(std::all_of(L.tet_owned.begin(), L.tet_owned.end(), [](char o) { return o; }));
    }
    // The domed top's new vertices are on the sphere (the serial refinement moved them).
    const TetMesh& fine = H.levels.back().mesh;
    const int zmax = fine.tag("zmax");
    for (int v : fine.vertices_with_tag(zmax))
        EXPECT_NEAR((fine.vertices[static_cast<size_t>(v)] - kDomeCentre).norm(), kDomeRadius,
                    1e-12);
}

TEST(Distributed3, EveryVertexOwnedOnceWithContiguousNumbers) {
    const TetMesh m0 = domed_box();
    const auto serial = serial_tet_levels(m0, kTetRefinements);
    const DistributedTetHierarchy H = mesh::distribute(m0, kTetRefinements, world3());
    ASSERT_EQ(H.levels.size(), serial.size());
    EXPECT_EQ(H.n_processes, world3().size());
    EXPECT_EQ(H.rank, world3().rank());
    for (size_t l = 0; l < H.levels.size(); ++l) {
        SCOPED_TRACE("level " + std::to_string(l));
        const LocalTetLevel& L = H.levels[l];
        const TetMesh& S = serial[l];
        if (world3().size() == 1) {
            EXPECT_EQ(L.mesh.vertices, S.vertices);
            EXPECT_EQ(L.mesh.cells, S.cells);
        }
        EXPECT_EQ(L.n_global_vertices, S.n_vertices());
        EXPECT_EQ(L.n_global_tets, S.n_cells());
        const auto firsts = world3().allgather(std::span<const std::int64_t>(&L.first_vertex, 1));
        const std::int64_t n_owned = L.n_owned_vertices();
        const auto counts = world3().allgather(std::span<const std::int64_t>(&n_owned, 1));
        std::int64_t next = 0;
        for (size_t q = 0; q < firsts.size(); ++q) {
            EXPECT_EQ(firsts[q], next);
            EXPECT_GT(counts[q], 0);
            next += counts[q];
        }
        EXPECT_EQ(next, S.n_vertices());
        EXPECT_EQ(L.first_row(), 3 * L.first_vertex);
        for (int i = 0; i < L.n_owned_vertices(); ++i) {
            const auto v = static_cast<size_t>(L.owned_vertices[static_cast<size_t>(i)]);
            EXPECT_EQ(L.global_vertex[v], L.first_vertex + i);
            EXPECT_EQ(L.vertex_owner[v], world3().rank());
            if (i > 0) {
                EXPECT_GT(L.owned_vertices[static_cast<size_t>(i)],
                          L.owned_vertices[static_cast<size_t>(i) - 1]);
            }
        }
        // The owned vertices of all processes are the serial mesh's vertices, each once.
        const auto table = owned_table3(L);
        ASSERT_EQ(table.size(), static_cast<size_t>(S.n_vertices()));
        EXPECT_EQ(table.begin()->first, 0);
        EXPECT_EQ(table.rbegin()->first, S.n_vertices() - 1);
        std::set<P3> serial_points, owned_points;
        for (int v = 0; v < S.n_vertices(); ++v)
            serial_points.insert(p3(S, v));
        for (const auto& [g, p] : table)
            owned_points.insert(p);
        EXPECT_EQ(owned_points, serial_points);
        // Ghost vertices carry their owner's number: the same coordinates on every process.
        int ghosts = 0;
        for (int v = 0; v < L.mesh.n_vertices(); ++v) {
            const std::int64_t g = L.global_vertex[static_cast<size_t>(v)];
            ASSERT_TRUE(table.count(g)) << "local vertex " << v << " has global number " << g;
            EXPECT_EQ(table.at(g), p3(L.mesh, v)) << "local vertex " << v;
            ghosts += L.vertex_owner[static_cast<size_t>(v)] != world3().rank();
        }
        EXPECT_EQ(ghosts, L.n_ghost_vertices());
        if (world3().size() > 1) {
            EXPECT_GT(world3().sum(ghosts), 0);
        }
    }
}

// Every tetrahedron owned by one process, and every serial tetrahedron around an owned vertex
// local: the rows of the owned unknowns can be assembled from the local tetrahedra.
TEST(Distributed3, OwnedTetsTileTheMeshAndGhostsCompleteTheRows) {
    const TetMesh m0 = domed_box();
    const auto serial = serial_tet_levels(m0, kTetRefinements);
    const DistributedTetHierarchy H = mesh::distribute(m0, kTetRefinements, world3());
    for (size_t l = 0; l < H.levels.size(); ++l) {
        SCOPED_TRACE("level " + std::to_string(l));
        const LocalTetLevel& L = H.levels[l];
        const TetMesh& S = serial[l];
        ASSERT_EQ(L.tet_owned.size(), L.mesh.cells.size());
        ASSERT_EQ(L.tet_ancestor.size(), L.mesh.cells.size());
        // Owned tetrahedra as sorted coordinates, gathered: each serial tetrahedron once.
        std::vector<double> mine;
        double volume = 0;
        std::set<Tet3> local;
        for (int t = 0; t < L.mesh.n_cells(); ++t) {
            const Tet3 c = tet3(L.mesh, t);
            local.insert(c);
            if (!L.tet_owned[static_cast<size_t>(t)]) continue;
            for (const P3& p : c)
                mine.insert(mine.end(), p.begin(), p.end());
            volume += std::abs(L.mesh.signed_measure(t));
        }
        EXPECT_EQ(local.size(), L.mesh.cells.size()) << "a local tetrahedron twice";
        const auto all = world3().allgather(std::span<const double>(mine));
        ASSERT_EQ(all.size(), 12 * static_cast<size_t>(S.n_cells()));
        std::set<Tet3> owned, expected;
        for (size_t i = 0; i < all.size(); i += 12) {
            Tet3 c;
            for (size_t k = 0; k < 4; ++k)
                c[k] = {all[i + 3 * k], all[i + 3 * k + 1], all[i + 3 * k + 2]};
            owned.insert(c);
        }
        double serial_volume = 0;
        std::map<P3, std::vector<int>> serial_around;
        for (int t = 0; t < S.n_cells(); ++t) {
            expected.insert(tet3(S, t));
            serial_volume += std::abs(S.signed_measure(t));
            for (int v : S.cells[static_cast<size_t>(t)])
                serial_around[p3(S, v)].push_back(t);
        }
        EXPECT_EQ(owned, expected);
        EXPECT_NEAR(world3().sum(volume), serial_volume, 1e-12 * serial_volume);
        for (const Tet3& c : local)
            EXPECT_TRUE(expected.count(c)) << "a local tetrahedron is none of the serial level";
        int missing = 0;
        for (int v : L.owned_vertices)
            for (int t : serial_around.at(p3(L.mesh, v)))
                missing += local.count(tet3(S, t)) == 0;
        EXPECT_EQ(missing, 0) << "serial tetrahedra around owned vertices are not local";
    }
}

// Finer levels are nested per process, and the ancestors, owners and locations agree with it.
TEST(Distributed3, LevelsAreNestedPerProcess) {
    const TetMesh m0 = domed_box();
    const DistributedTetHierarchy H = mesh::distribute(m0, kTetRefinements, world3());
    const LocalTetLevel& L0 = H.levels[0];
    for (size_t t = 0; t < L0.mesh.cells.size(); ++t) {
        EXPECT_EQ(tet3(L0.mesh, static_cast<int>(t)), tet3(m0, L0.tet_ancestor[t]));
        EXPECT_EQ(L0.tet_owned[t],
                  H.partition.triangle_part[static_cast<size_t>(L0.tet_ancestor[t])] == H.rank);
    }
    for (size_t l = 1; l < H.levels.size(); ++l) {
        const LocalTetLevel& c = H.levels[l - 1];
        const LocalTetLevel& f = H.levels[l];
        ASSERT_EQ(f.mesh.n_coarse_vertices, c.mesh.n_vertices());
        for (int v = 0; v < c.mesh.n_vertices(); ++v) {
            EXPECT_EQ(p3(f.mesh, v), p3(c.mesh, v));
            EXPECT_EQ(f.global_vertex[static_cast<size_t>(v)] >= 0, true);
        }
        ASSERT_EQ(f.mesh.cells.size(), 8 * c.mesh.cells.size());
        for (size_t t = 0; t < f.mesh.cells.size(); ++t) {
            EXPECT_EQ(f.tet_owned[t], c.tet_owned[t / 8]);
            EXPECT_EQ(f.tet_ancestor[t], c.tet_ancestor[t / 8]);
        }
        // A new vertex inside a level-p face is owned by the lower part beside it, one inside a
        // tetrahedron by its part, and a vertex inside an edge by the lowest part around it.
        for (size_t v = static_cast<size_t>(c.mesh.n_vertices()); v < f.vertex_owner.size(); ++v) {
            const mesh::TetLocation& loc = f.vertex_location[v];
            ASSERT_NE(loc.kind, mesh::TetLocation::Kind::vertex);
            std::vector<int> ends;
            if (loc.kind == mesh::TetLocation::Kind::edge)
                ends.assign(H.edges[static_cast<size_t>(loc.id)].begin(),
                            H.edges[static_cast<size_t>(loc.id)].end());
            else if (loc.kind == mesh::TetLocation::Kind::face)
                ends.assign(H.faces[static_cast<size_t>(loc.id)].begin(),
                            H.faces[static_cast<size_t>(loc.id)].end());
            else
                ends.assign(m0.cells[static_cast<size_t>(loc.id)].begin(),
                            m0.cells[static_cast<size_t>(loc.id)].end());
            int lowest = H.n_processes;
            for (size_t t = 0; t < m0.cells.size(); ++t) {
                const auto& k = m0.cells[t];
                if (std::all_of(ends.begin(), ends.end(),
                                [&](int e) { return std::find(k.begin(), k.end(), e) != k.end(); }))
                    lowest = std::min(lowest, H.partition.triangle_part[t]);
            }
            EXPECT_EQ(f.vertex_owner[v], lowest) << "vertex " << v;
        }
    }
}

// A ghost tetrahedron may touch the dome by an edge only, with the dome's face on that edge in a
// tetrahedron that is not local: the vertices refinement makes on the edge are still moved onto
// the sphere, as the serial refinement moves them (the other tests compare the coordinates).
TEST(Distributed3, DomeEdgesOfGhostsAreOnTheSphere) {
    const TetMesh m0 = domed_box();
    const DistributedTetHierarchy H = mesh::distribute(m0, kTetRefinements, world3());
    const int zmax = m0.tag("zmax");
    const std::vector<int> top = m0.vertices_with_tag(zmax);
    auto on_top = [&](int v) { return std::binary_search(top.begin(), top.end(), v); };
    const LocalTetLevel& L0 = H.levels[0];
    std::set<std::pair<int, int>> dome_edges; // level-p edges of local dome faces
    for (const auto& f : L0.mesh.boundary)
        if (f.tag == zmax)
            for (size_t k = 0; k < 3; ++k) {
                const int a = L0.vertex_location[static_cast<size_t>(f.v[k])].id;
                const int b = L0.vertex_location[static_cast<size_t>(f.v[(k + 1) % 3])].id;
                dome_edges.insert(std::minmax(a, b));
            }
    int edge_only = 0; // dome edges of local tetrahedra on no local dome face
    for (const auto& e : H.edges)
        if (on_top(e[0]) && on_top(e[1]) && !dome_edges.count({e[0], e[1]}))
            for (size_t t = 0; t < L0.mesh.cells.size(); ++t) {
                const auto& k = m0.cells[static_cast<size_t>(L0.tet_ancestor[t])];
                if (std::find(k.begin(), k.end(), e[0]) != k.end() &&
                    std::find(k.begin(), k.end(), e[1]) != k.end()) {
                    ++edge_only;
                    break;
                }
            }
    if (world3().size() > 1) {
        EXPECT_GT(world3().sum(edge_only), 0) << "the case this test is for does not occur";
    }
    // Every vertex of every level inside a level-p dome edge or face is on the sphere.
    for (const LocalTetLevel& L : H.levels)
        for (size_t v = 0; v < L.vertex_location.size(); ++v) {
            const mesh::TetLocation& loc = L.vertex_location[v];
            std::vector<int> ends;
            if (loc.kind == mesh::TetLocation::Kind::edge)
                ends.assign(H.edges[static_cast<size_t>(loc.id)].begin(),
                            H.edges[static_cast<size_t>(loc.id)].end());
            else if (loc.kind == mesh::TetLocation::Kind::face)
                ends.assign(H.faces[static_cast<size_t>(loc.id)].begin(),
                            H.faces[static_cast<size_t>(loc.id)].end());
            if (ends.empty() || !std::all_of(ends.begin(), ends.end(), on_top)) continue;
            EXPECT_NEAR((L.mesh.vertices[v] - kDomeCentre).norm(), kDomeRadius, 1e-12)
                << "local vertex " << v;
        }
}

namespace {

/// Two boxes, one above the other 0.01 apart, with non-matching meshes: the lower one's top
/// tagged "lower_top", the upper one's bottom "upper_bottom" (a contact interface).
TetMesh two_tet_blocks() {
    TetMesh m = mesh::structured_box(Vec3::Zero(), Vec3(1, 1, 0.5), 4, 4, 2);
    const TetMesh up = mesh::structured_box(Vec3(0, 0, 0.51), Vec3(1, 1, 0.5), 3, 3, 2);
    const int lower_top = m.add_tag("lower_top");
    const int upper_bottom = m.add_tag("upper_bottom");
    const int zmax = m.tag("zmax");
    for (auto& f : m.boundary)
        if (f.tag == zmax) f.tag = lower_top;
    const int off = m.n_vertices();
    m.vertices.insert(m.vertices.end(), up.vertices.begin(), up.vertices.end());
    for (auto t : up.cells) {
        for (int& v : t)
            v += off;
        m.cells.push_back(t);
    }
    for (auto f : up.boundary) {
        const std::string name = up.tag_name(f.tag);
        f.tag = name == "zmin" ? upper_bottom : m.add_tag("upper_" + name);
        for (int& v : f.v)
            v += off;
        m.boundary.push_back(f);
    }
    m.attribute.assign(m.cells.size(), 0);
    for (size_t t = m.cells.size() - up.cells.size(); t < m.cells.size(); ++t)
        m.attribute[t] = 1;
    return m;
}

} // namespace

// A ghost layer widened along a contact interface (GhostReach): on every level, every interface
// face of the serial mesh with a corner within the reach of an owned interface vertex is local.
TEST(Distributed3, GhostReachHoldsEveryInterfaceFaceWithinReach) {
    const TetMesh m0 = two_tet_blocks();
    mesh::check_quality(m0);
    const int tags[2] = {m0.tag("lower_top"), m0.tag("upper_bottom")};
    const double reach = 0.3;
    const auto serial = serial_tet_levels(m0, kTetRefinements);
    const DistributedTetHierarchy H =
        mesh::distribute(m0, kTetRefinements, world3(), {}, {{{tags[0], tags[1]}, reach}});
    const DistributedTetHierarchy H1 = mesh::distribute(m0, kTetRefinements, world3());
    // The widened layer holds the one-layer tetrahedra and more (somewhere, on several processes).
    std::set<int> narrow_set(H1.levels[0].tet_ancestor.begin(), H1.levels[0].tet_ancestor.end());
    std::set<int> wide_set(H.levels[0].tet_ancestor.begin(), H.levels[0].tet_ancestor.end());
    EXPECT_TRUE(
        std::includes(wide_set.begin(), wide_set.end(), narrow_set.begin(), narrow_set.end()));
    EXPECT_EQ(H.levels[0].tet_owned.size() - H1.levels[0].tet_owned.size(),
              wide_set.size() - narrow_set.size());
    const std::int64_t added = world3().sum(static_cast<std::int64_t>(wide_set.size()) -
                                            static_cast<std::int64_t>(narrow_set.size()));
    if (world3().size() > 1) {
        EXPECT_GT(added, 0);
    } else {
        EXPECT_EQ(added, 0);
    }
    // Level p against bounds of the face-to-face distance: a tetrahedron with an interface face
    // having a corner within the reach of a corner of an interface face of the one-layer mesh must
    // be added; one whose interface faces' bounding boxes are all farther than the reach from
    // those faces' boxes must not.
    std::vector<int> face_tet(m0.boundary.size(), -1);
    {
        std::map<std::array<int, 3>, int> tet_of_face;
        for (size_t t = 0; t < m0.cells.size(); ++t)
            for (size_t k = 0; k < 4; ++k) {
                std::array<int, 3> f{m0.cells[t][(k + 1) % 4], m0.cells[t][(k + 2) % 4],
                                     m0.cells[t][(k + 3) % 4]};
                std::sort(f.begin(), f.end());
                tet_of_face[f] = static_cast<int>(t);
            }
        for (size_t b = 0; b < m0.boundary.size(); ++b) {
            std::array<int, 3> f = m0.boundary[b].v;
            std::sort(f.begin(), f.end());
            face_tet[b] = tet_of_face.at(f);
        }
    }
    auto box_gap = [&](const mesh::BoundaryFace& f, const mesh::BoundaryFace& g) {
        double gap2 = 0;
        for (int d = 0; d < 3; ++d) {
            double flo = 1e300, fhi = -1e300, glo = 1e300, ghi = -1e300;
            for (int v : f.v) {
                flo = std::min(flo, m0.vertices[static_cast<size_t>(v)][d]);
                fhi = std::max(fhi, m0.vertices[static_cast<size_t>(v)][d]);
            }
            for (int v : g.v) {
                glo = std::min(glo, m0.vertices[static_cast<size_t>(v)][d]);
                ghi = std::max(ghi, m0.vertices[static_cast<size_t>(v)][d]);
            }
            const double gap = std::max({0.0, glo - fhi, flo - ghi});
            gap2 += gap * gap;
        }
        return std::sqrt(gap2);
    };
    auto corner_gap = [&](const mesh::BoundaryFace& f, const mesh::BoundaryFace& g) {
        double d = 1e300;
        for (int v : f.v)
            for (int w : g.v)
                d = std::min(
                    d, (m0.vertices[static_cast<size_t>(v)] - m0.vertices[static_cast<size_t>(w)])
                           .norm());
        return d;
    };
    std::vector<char> must(m0.cells.size(), 0), may(m0.cells.size(), 0);
    for (size_t c = 0; c < m0.boundary.size(); ++c) {
        const auto& fc = m0.boundary[c];
        if ((fc.tag != tags[0] && fc.tag != tags[1]) || narrow_set.count(face_tet[c])) continue;
        for (size_t s = 0; s < m0.boundary.size(); ++s) {
            const auto& fs = m0.boundary[s];
            if ((fs.tag != tags[0] && fs.tag != tags[1]) || !narrow_set.count(face_tet[s]))
                continue;
            if (corner_gap(fc, fs) <= reach) must[static_cast<size_t>(face_tet[c])] = 1;
            if (box_gap(fc, fs) <= reach) may[static_cast<size_t>(face_tet[c])] = 1;
        }
    }
    int n_must = 0;
    for (size_t t = 0; t < m0.cells.size(); ++t) {
        if (narrow_set.count(static_cast<int>(t))) continue;
        n_must += must[t];
        if (must[t]) {
            EXPECT_TRUE(wide_set.count(static_cast<int>(t))) << "tetrahedron " << t;
        }
        if (!may[t]) {
            EXPECT_FALSE(wide_set.count(static_cast<int>(t))) << "tetrahedron " << t;
        }
    }
    if (world3().size() > 1) {
        EXPECT_GT(world3().sum(n_must), 0);
    }
    // The numbering does not depend on the ghosts: the same owned vertices, the same numbers.
    EXPECT_EQ(H.levels.back().n_owned_vertices(), H1.levels.back().n_owned_vertices());
    EXPECT_EQ(H.levels.back().first_vertex, H1.levels.back().first_vertex);
    for (size_t l = 0; l < H.levels.size(); ++l) {
        SCOPED_TRACE("level " + std::to_string(l));
        const LocalTetLevel& L = H.levels[l];
        const TetMesh& S = serial[l];
        std::set<std::array<P3, 3>> local;
        std::vector<char> on_interface(static_cast<size_t>(L.mesh.n_vertices()), 0);
        for (const auto& f : L.mesh.boundary) {
            std::array<P3, 3> c{p3(L.mesh, f.v[0]), p3(L.mesh, f.v[1]), p3(L.mesh, f.v[2])};
            std::sort(c.begin(), c.end());
            local.insert(c);
            if (f.tag == tags[0] || f.tag == tags[1])
                for (int v : f.v)
                    on_interface[static_cast<size_t>(v)] = 1;
        }
        int checked = 0;
        for (int v : L.owned_vertices) {
            if (!on_interface[static_cast<size_t>(v)]) continue;
            const Vec3& x = L.mesh.vertices[static_cast<size_t>(v)];
            for (const auto& f : S.boundary) {
                if (f.tag != tags[0] && f.tag != tags[1]) continue;
                double nearest = 1e300;
                for (int w : f.v)
                    nearest = std::min(nearest, (S.vertices[static_cast<size_t>(w)] - x).norm());
                if (nearest > reach) continue;
                ++checked;
                std::array<P3, 3> c{p3(S, f.v[0]), p3(S, f.v[1]), p3(S, f.v[2])};
                std::sort(c.begin(), c.end());
                EXPECT_TRUE(local.count(c))
                    << "interface face at (" << c[0][0] << ", " << c[0][1] << ", " << c[0][2]
                    << ") within " << reach << " of owned vertex (" << x.x() << ", " << x.y()
                    << ", " << x.z() << ") is not local";
            }
        }
        EXPECT_GT(world3().sum(checked), 0);
    }
}

TEST(Distributed3, RejectsNegativeRefinementsAndTooManyProcesses) {
    EXPECT_THROW(mesh::distribute(domed_box(), -1, world3()), InvalidInput);
    TetMesh one;
    one.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
    one.cells = {{0, 1, 2, 3}};
    if (world3().size() > 1) {
        EXPECT_THROW(mesh::distribute(one, 1, world3()), InvalidInput);
    } else {
        EXPECT_EQ(mesh::distribute(one, 1, world3()).levels.back().mesh.n_cells(), 8);
    }
}

// One piece per process with its owned tetrahedra, listed by the .pvtu: the pieces' cells add up
// to the serial level's, their points are its vertices (those on cuts in several pieces).
TEST(Distributed3, WritesOnePieceOfOwnedTetsPerProcess) {
    const TetMesh m0 = domed_box();
    const DistributedTetHierarchy H = mesh::distribute(m0, 1, world3());
    const LocalTetLevel& L = H.levels.back();
    const TetMesh S = mesh::refine(m0);
    const auto dir = std::filesystem::temp_directory_path() / "mlc_test_distributed3_write";
    if (world3().rank() == 0) std::filesystem::create_directories(dir);
    world3().barrier();
    const auto file = dir / ("box_np" + std::to_string(world3().size()) + ".pvtu");
    if (world3().rank() == 0) std::filesystem::remove(file);
    world3().barrier();
    std::vector<double> u, owner;
    for (int v = 0; v < L.mesh.n_vertices(); ++v) {
        const Vec3& x = L.mesh.vertices[static_cast<size_t>(v)];
        u.insert(u.end(), {x.x(), 2 * x.y(), 3 * x.z()});
    }
    for (char o : L.tet_owned)
        owner.push_back(o ? world3().rank() : -1);
    mesh::write_distributed_vtu(file, L, {{"u", 3, u}}, {{"rank", 1, owner}}, world3());
    world3().barrier();
    ASSERT_TRUE(std::filesystem::exists(file));
    const std::string pvtu = testutil::slurp(file);
    EXPECT_NE(pvtu.find("Name=\"body\""), std::string::npos);
    EXPECT_NE(pvtu.find("Name=\"rank\""), std::string::npos);
    std::int64_t cells = 0;
    std::set<P3> points;
    for (int r = 0; r < world3().size(); ++r) {
        const auto piece = mesh::piece_path(file, r);
        ASSERT_TRUE(std::filesystem::exists(piece)) << piece;
        EXPECT_NE(pvtu.find(piece.filename().string()), std::string::npos);
        const std::string xml = testutil::slurp(piece);
        const auto n_points = std::stoll(testutil::xml_attribute(xml, "NumberOfPoints"));
        const auto n_cells = std::stoll(testutil::xml_attribute(xml, "NumberOfCells"));
        cells += n_cells;
        const auto xyz = testutil::as<double>(testutil::appended_array(xml, "<Points>"));
        ASSERT_EQ(xyz.size(), 3 * static_cast<size_t>(n_points));
        for (size_t i = 0; i < xyz.size(); i += 3)
            points.insert({xyz[i], xyz[i + 1], xyz[i + 2]});
        const auto ranks = testutil::as<double>(testutil::appended_array(xml, "Name=\"rank\""));
        ASSERT_EQ(ranks.size(), static_cast<size_t>(n_cells));
        for (double q : ranks)
            EXPECT_EQ(q, r);
        if (r == world3().rank()) {
            EXPECT_EQ(n_cells, std::count(L.tet_owned.begin(), L.tet_owned.end(), 1));
        }
    }
    EXPECT_EQ(cells, S.n_cells());
    std::set<P3> serial_points;
    for (int v = 0; v < S.n_vertices(); ++v)
        serial_points.insert(p3(S, v));
    EXPECT_EQ(points, serial_points);
    // A bad field on the last process fails the write everywhere, and no .pvtu appears.
    const auto bad = dir / ("bad_np" + std::to_string(world3().size()) + ".pvtu");
    const size_t n = u.size() - (world3().rank() + 1 == world3().size());
    EXPECT_ANY_THROW(
        mesh::write_distributed_vtu(bad, L, {{"u", 3, std::vector<double>(n, 0.0)}}, {}, world3()));
    world3().barrier();
    EXPECT_FALSE(std::filesystem::exists(bad));
}
