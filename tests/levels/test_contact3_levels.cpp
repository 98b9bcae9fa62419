// SPDX-License-Identifier: MIT
// 3D contact problems before the solve: the [[contact]] pairs, [newton] and load_steps of 3D
// scenes and their refusals, the contact elements and multipliers of 3D levels (frictional and
// frictionless, held components pinned or refused as ambiguous), the predicted multipliers against
// the built levels, the transfers of a hierarchy with multipliers, and the built-in 3D contact
// scenes (punch3d, sphere_punch, block3d, hertz3d).
#include "fem/assembly.hpp"
#include "levels/elastic3d_levels.hpp"
#include "scene/scene3.hpp"
#include "tests/mesh/tet_test_meshes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

namespace mlc {
namespace {

using mesh::Vec3;

// A unit box of 2 x 2 x 2 cubes on the plane z = 0 (normal +z), `contact` the body of its
// [[contact]] table after the name, `tail` appended (supports, [newton], ...).
std::string contact3_box(const std::string& contact, const std::string& tail = "",
                         const std::string& scene_extra = "") {
    return "[scene]\nname = \"c\"\ndimension = 3\n" + scene_extra +
           "[[body]]\nE = 2.0\nnu = 0.3\nmesh = { type = \"box\", corner = [0, 0, 0], size = [1, "
           "1, 1], divisions = [2, 2, 2] }\n[[load]]\ntag = \"zmax\"\npressure = 0.01\n"
           "[[contact]]\nname = \"floor\"\n" +
           contact + tail;
}

const std::string kPlane =
    "obstacle = { type = \"plane\", point = [0, 0, 0], normal = [0, 0, 1] }\n";

levels::ElasticProblem3 contact3_parse(const std::string& text) {
    return scene::parse_scene3(text, "t.toml");
}

void contact3_error(const std::string& text, const std::vector<std::string>& parts) {
    mesh::testing::expect_invalid([&] { contact3_parse(text); }, parts);
}

// The vertices of the boundary faces of m tagged `tag`.
std::set<int> contact3_tag_vertices(const mesh::TetMesh& m, const std::string& tag) {
    const std::vector<int> v = m.vertices_with_tag(m.tag(tag));
    return {v.begin(), v.end()};
}

// Checks the bookkeeping of a 3D contact level: one element per contact node, contact_of_vertex
// its inverse, each element's multipliers right after its vertex's displacements (lambda_dof),
// and the unknowns the displacements and the multipliers; returns the multipliers.
Index contact3_check_level(const levels::Level3& L, size_t n_pairs) {
    EXPECT_EQ(L.lambda_dof.size(), L.contacts.size());
    EXPECT_EQ(L.not_found.size(), n_pairs);
    for (const auto& nf : L.not_found)
        EXPECT_TRUE(nf.empty());
    Index multipliers = 0;
    std::vector<int> element_of(static_cast<size_t>(L.mesh.n_vertices()), -1);
    for (size_t k = 0; k < L.contacts.size(); ++k) {
        const auto& e = L.contacts[k];
        const int v = e.vertex[0];
        EXPECT_EQ(e.n_nodes(), 1);
        EXPECT_EQ(element_of[static_cast<size_t>(v)], -1) << "vertex " << v << " twice";
        element_of[static_cast<size_t>(v)] = static_cast<int>(k);
        EXPECT_EQ(L.lambda_dof[k], L.dofs.extra_dof(v));
        int last_u = -1;
        for (int c = 0; c < 3; ++c)
            last_u = std::max(last_u, L.dofs.u_dof(v, c));
        EXPECT_EQ(L.lambda_dof[k], last_u + 1) << "vertex " << v;
        for (int q = 0; q < e.n_multipliers(); ++q) {
            EXPECT_FALSE(L.dofs.is_displacement(L.lambda_dof[k] + q));
            EXPECT_EQ(L.dofs.vertex_of(L.lambda_dof[k] + q), v);
        }
        multipliers += e.n_multipliers();
    }
    for (int v = 0; v < L.mesh.n_vertices(); ++v)
        EXPECT_EQ(L.contact_of_vertex[static_cast<size_t>(v)], element_of[static_cast<size_t>(v)]);
    EXPECT_EQ(L.dofs.n_dofs(), L.dofs.n_displacement_dofs() + multipliers);
    // K is square on all unknowns, its multiplier rows empty.
    EXPECT_EQ(L.elastic.K.rows(), L.dofs.n_dofs());
    return multipliers;
}

// ---------------------------------------------------------------------------------------------
// The built-in scenes.

TEST(Contact3Scenes, EveryNewSceneParsesAndBuildsLevel0WithContactElements) {
    for (const char* name : {"punch3d", "sphere_punch", "block3d", "hertz3d"}) {
        SCOPED_TRACE(name);
        EXPECT_EQ(scene::scene_dimension(name), 3);
        const levels::ElasticProblem3 p = scene::load_scene3(name);
        EXPECT_EQ(p.name, name);
        ASSERT_EQ(p.contacts.size(), 1u);
        const levels::Level3 L = levels::build_level(p, p.mesh0);
        EXPECT_GT(L.n_contact_nodes(), 0);
        const Index multipliers = contact3_check_level(L, 1);
        EXPECT_EQ(multipliers, (p.contacts[0].mu > 0 ? 3 : 1) * L.n_contact_nodes());
        const auto sizes = levels::predict_elastic3_sizes(p, 0);
        EXPECT_EQ(sizes[0].multipliers, static_cast<double>(multipliers));
        EXPECT_EQ(sizes[0].unknowns, static_cast<double>(L.dofs.n_displacement_dofs()));
        // r = 0.1 E h0 (the default r_over_E), E = the body's modulus.
        EXPECT_DOUBLE_EQ(p.contacts[0].r,
                         0.1 * p.bodies[0].material.E *
                             levels::mean_face_edge_length(p.mesh0, p.contacts[0].contactor));
        for (const auto& e : L.contacts) {
            EXPECT_EQ(e.pinned, 0);
            EXPECT_GE(e.g0, -1e-15);
        }
    }
}

TEST(Contact3Scenes, Punch3dContactNodesAreTheBottomVerticesNotFullyFixed) {
    const levels::ElasticProblem3 p = scene::load_scene3("punch3d");
    EXPECT_EQ(p.contacts[0].mu, 0.0);
    // h0: the bottom's 40 axis edges of 0.25 and 16 diagonals of 0.25 sqrt(2).
    const double h0 = (40 * 0.25 + 16 * 0.25 * std::sqrt(2.0)) / 56;
    EXPECT_NEAR(levels::mean_face_edge_length(p.mesh0, "zmin"), h0, 1e-15);
    EXPECT_NEAR(p.contacts[0].r, 0.1 * h0, 1e-15);
    const levels::Hierarchy3 h = levels::build_hierarchy(p, 1);
    const auto sizes = levels::predict_elastic3_sizes(p, 1);
    for (int l = 0; l <= 1; ++l) {
        const levels::Level3& L = h.levels[static_cast<size_t>(l)];
        std::set<int> expected;
        for (int v : contact3_tag_vertices(L.mesh, "zmin")) {
            const auto& f = L.fixed[static_cast<size_t>(v)];
            if (!(f[0] && f[1] && f[2])) expected.insert(v);
        }
        const int n = 4 << l; // cells along a side
        EXPECT_EQ(expected.size(), static_cast<size_t>((n + 1) * (n + 1)));
        std::set<int> got;
        for (const auto& e : L.contacts) {
            got.insert(e.vertex[0]);
            EXPECT_EQ(e.n, Vec3(0, 0, 1));
            EXPECT_EQ(e.g0, 0.0);
            EXPECT_EQ(e.n_multipliers(), 1);
            EXPECT_EQ(e.r, p.contacts[0].r);
        }
        EXPECT_EQ(got, expected) << "level " << l;
        EXPECT_EQ(contact3_check_level(L, 1), (n + 1) * (n + 1));
        EXPECT_EQ(sizes[static_cast<size_t>(l)].multipliers, (n + 1) * (n + 1));
    }
}

TEST(Contact3Scenes, Punch3dExactSolutionIsInEquilibriumWithAUniformContactPressure) {
    // u = (nu p x, nu p y, -p z) / E: the internal forces less the loads vanish but at the bottom
    // nodes' z components, the floor's nodal forces: all pushing (> 0), summing to p x 1.
    const levels::ElasticProblem3 p = scene::load_scene3("punch3d");
    const double pressure = 0.01, E = 1.0, nu = 0.3;
    for (int l = 0; l <= 1; ++l) {
        const levels::Hierarchy3 h = levels::build_hierarchy(p, l);
        const levels::Level3& L = h.finest();
        Vector u(3 * L.mesh.n_vertices());
        for (int v = 0; v < L.mesh.n_vertices(); ++v) {
            const Vec3& x = L.mesh.vertices[static_cast<size_t>(v)];
            u.segment<3>(3 * v) = Vec3(nu * x.x(), nu * x.y(), -x.z()) * pressure / E;
        }
        const Vector r = fem::internal_forces(L.mesh, L.materials, u) - L.elastic.f_nodal_full;
        double floor = 0.0;
        for (int v = 0; v < L.mesh.n_vertices(); ++v)
            for (int c = 0; c < 3; ++c) {
                const double rc = r[3 * v + c];
                if (L.dofs.u_dof(v, c) < 0) continue; // a support's reaction
                if (c == 2 && L.contact_of_vertex[static_cast<size_t>(v)] >= 0) {
                    EXPECT_GT(rc, 0.0) << "vertex " << v;
                    floor += rc;
                } else {
                    EXPECT_NEAR(rc, 0.0, 1e-15) << "vertex " << v << " component " << c;
                }
            }
        EXPECT_NEAR(floor, pressure, 1e-15) << "level " << l;
    }
}

TEST(Contact3Scenes, Block3dHasThreeMultipliersPerNodeAndNoneOnTheHeldEdge) {
    const levels::ElasticProblem3 p = scene::load_scene3("block3d");
    EXPECT_EQ(p.load_steps, 5);
    EXPECT_EQ(p.contacts[0].mu, 1.0);
    const levels::Level3 L = levels::build_level(p, p.mesh0);
    // 5 x 5 bottom vertices less the 5 on the held edge x = 40, z = 0.
    ASSERT_EQ(L.n_contact_nodes(), 20);
    for (const auto& e : L.contacts) {
        EXPECT_LT(L.mesh.vertices[static_cast<size_t>(e.vertex[0])].x(), 40.0);
        EXPECT_EQ(e.n_multipliers(), 3);
    }
    EXPECT_EQ(contact3_check_level(L, 1), 60);
}

TEST(Contact3Scenes, Hertz3dSphereIsAttachedAndRefinementPutsItsVerticesOnIt) {
    const levels::ElasticProblem3 p = scene::load_scene3("hertz3d");
    ASSERT_EQ(p.mesh0.shapes.size(), 1u);
    EXPECT_EQ(p.mesh0.shapes[0].kind, mesh::CurvedSurface::Kind::sphere);
    const levels::Hierarchy3 h = levels::build_hierarchy(p, 1);
    const levels::Level3& L = h.levels[1];
    const int sphere = L.mesh.tag("sphere");
    for (int v : L.mesh.vertices_with_tag(sphere))
        EXPECT_NEAR((L.mesh.vertices[static_cast<size_t>(v)] - Vec3(0, 0, 1)).norm(), 1.0, 1e-12)
            << "vertex " << v;
    // Contact nodes: the sphere's vertices with z <= 0.05, their gap z (the plane z = 0).
    std::set<int> expected;
    for (int v : L.mesh.vertices_with_tag(sphere))
        if (L.mesh.vertices[static_cast<size_t>(v)].z() <= 0.05) expected.insert(v);
    std::set<int> got;
    for (const auto& e : L.contacts) {
        got.insert(e.vertex[0]);
        EXPECT_DOUBLE_EQ(e.g0, L.mesh.vertices[static_cast<size_t>(e.vertex[0])].z());
    }
    EXPECT_EQ(got, expected);
    // The pole is a contact node with zero gap.
    const int pole = L.mesh.nearest_vertex(Vec3::Zero());
    EXPECT_LT(L.mesh.vertices[static_cast<size_t>(pole)].norm(), 1e-12);
    EXPECT_GE(L.contact_of_vertex[static_cast<size_t>(pole)], 0);
    // The predicted multipliers: the region z <= 0.05 cuts the curved sphere, where refined
    // points are counted on the level-0 faces: within 5 % of the built level.
    const auto sizes = levels::predict_elastic3_sizes(p, 1);
    EXPECT_NEAR(sizes[1].multipliers, static_cast<double>(L.n_contact_nodes()),
                0.05 * L.n_contact_nodes());
}

TEST(Contact3Scenes, SpherePunchBlockGradingClosedFormAndRegion) {
    const levels::ElasticProblem3 p = scene::load_scene3("sphere_punch");
    const mesh::TetMesh& m = p.mesh0;
    // sphere_punch.msh: the quarter [0, 2] x [0, 2] x [-4, 0], 2185 vertices; each physical
    // surface on its plane.
    EXPECT_EQ(m.n_vertices(), 2185);
    Vec3 lo = m.vertices[0], hi = m.vertices[0];
    for (const Vec3& x : m.vertices) {
        lo = lo.cwiseMin(x);
        hi = hi.cwiseMax(x);
    }
    EXPECT_EQ(lo, Vec3(0, 0, -4));
    EXPECT_EQ(hi, Vec3(2, 2, 0));
    struct Plane {
        std::string tag;
        int axis;
        double value;
    };
    for (const Plane& pl : {Plane{"sym_x", 0, 0.0}, Plane{"sym_y", 1, 0.0},
                            Plane{"bottom", 2, -4.0}, Plane{"top", 2, 0.0}}) {
        SCOPED_TRACE(pl.tag);
        const std::vector<int> vs = m.vertices_with_tag(m.tag(pl.tag));
        EXPECT_GT(vs.size(), 10u);
        for (int v : vs)
            EXPECT_EQ(m.vertices[static_cast<size_t>(v)][pl.axis], pl.value) << "vertex " << v;
    }
    // The scene comment's closed form: P = 4 p (2 x 2) (the quarter's bottom), a = 0.0994
    // (a / R <= 0.1), p0; the block is more than 40 a wide and deep.
    ASSERT_EQ(p.loads.size(), 1u);
    EXPECT_EQ(p.loads[0].tag, "bottom");
    const double E_star = 1.0 / (1 - 0.3 * 0.3), P = 4 * p.loads[0].pressure * hi.x() * hi.y();
    EXPECT_NEAR(P, 1.44e-3, 1e-15);
    const double a = std::cbrt(3 * P * 1.0 / (4 * E_star));
    EXPECT_NEAR(a, 0.09942, 1e-5);
    EXPECT_NEAR(3 * P / (2 * M_PI * a * a), 0.06955, 1e-5);
    EXPECT_GT(2 * hi.x() / a, 40.0);
    EXPECT_GT(-lo.z() / a, 40.0);
    // Graded: the top face's edges within 1.5 a of the origin between a / 8 and a / 6 on
    // average, none longer than a / 5; those beyond 1 from it longer than a.
    std::set<std::pair<int, int>> edges;
    const int top = m.tag("top");
    for (const auto& f : m.boundary)
        if (f.tag == top)
            for (int i = 0; i < 3; ++i)
                edges.insert(std::minmax(f.v[static_cast<size_t>(i)],
                                         f.v[static_cast<size_t>((i + 1) % 3)]));
    double near_sum = 0.0, near_max = 0.0, far_min = 1e300;
    int near_count = 0;
    for (const auto& [u, w] : edges) {
        const Vec3& xu = m.vertices[static_cast<size_t>(u)];
        const Vec3& xw = m.vertices[static_cast<size_t>(w)];
        const double len = (xu - xw).norm(), r = (0.5 * (xu + xw)).norm();
        if (r < 1.5 * a) {
            near_sum += len;
            near_max = std::max(near_max, len);
            ++near_count;
        } else if (r > 1.0) {
            far_min = std::min(far_min, len);
        }
    }
    ASSERT_GT(near_count, 0);
    EXPECT_GT(near_sum / near_count, a / 8);
    EXPECT_LT(near_sum / near_count, a / 6);
    EXPECT_LT(near_max, a / 5);
    EXPECT_GT(far_min, a);
    // The contact nodes: the top face's vertices with x, y <= 0.3 (3 a), with the origin; gaps
    // sqrt(1 + x^2 + y^2) - 1 along the sphere's normal.
    const levels::Level3 L = levels::build_level(p, m);
    std::set<int> expected;
    for (int v : m.vertices_with_tag(top))
        if (m.vertices[static_cast<size_t>(v)].x() <= 0.3 &&
            m.vertices[static_cast<size_t>(v)].y() <= 0.3)
            expected.insert(v);
    std::set<int> got;
    for (const auto& e : L.contacts) {
        got.insert(e.vertex[0]);
        const Vec3& x = L.mesh.vertices[static_cast<size_t>(e.vertex[0])];
        EXPECT_NEAR(e.g0, std::sqrt(1 + x.x() * x.x() + x.y() * x.y()) - 1, 1e-14);
        EXPECT_NEAR((e.n - (x - Vec3(0, 0, 1)).normalized()).norm(), 0.0, 1e-14);
    }
    EXPECT_EQ(got, expected);
    const int origin = m.nearest_vertex(Vec3::Zero());
    EXPECT_EQ(m.vertices[static_cast<size_t>(origin)], Vec3::Zero());
    EXPECT_TRUE(got.count(origin));
}

// ---------------------------------------------------------------------------------------------
// Predicted multipliers and the transfers of a hierarchy with multipliers.

TEST(Contact3Levels, PredictedMultipliersAreThoseOfTheBuiltLevels) {
    // Frictional, a region whose planes x = 0.5 and y = 0.75 are lattice planes of every level,
    // supports holding the edge y = z = 0 fully (no contact nodes there) and the face xmin in ux:
    // the prediction is exact. A second pair claims the bottom's vertices the first leaves.
    const std::string tail =
        "[[support]]\nline = [[0, 0, 0], [1, 0, 0]]\nux = 0.0\nuy = 0.0\nuz = 0.0\n"
        "[[support]]\ntag = \"xmax\"\nux = 0.0\nuy = 0.0\nuz = 0.0\n"
        "[[contact]]\nname = \"rest\"\ncontactor = \"zmin\"\nmu = 0.0\n" +
        kPlane;
    const levels::ElasticProblem3 p = contact3_parse(contact3_box(
        "contactor = \"zmin\"\nmu = 0.5\nregion = { max = [0.5, 0.75, 1] }\n" + kPlane, tail));
    const auto sizes = levels::predict_elastic3_sizes(p, 3);
    const levels::Hierarchy3 h = levels::build_hierarchy(p, 3);
    for (int l = 0; l <= 3; ++l) {
        const levels::Level3& L = h.levels[static_cast<size_t>(l)];
        const Index m = contact3_check_level(L, 2);
        EXPECT_EQ(sizes[static_cast<size_t>(l)].multipliers, static_cast<double>(m))
            << "level " << l;
        EXPECT_EQ(sizes[static_cast<size_t>(l)].unknowns,
                  static_cast<double>(L.dofs.n_displacement_dofs()))
            << "level " << l;
        // By hand: n cells per side; the first pair holds x <= 0.5, y <= 0.75 less y = 0
        // (held), the second the rest less y = 0 and x = 1 (held).
        const int n = 2 << l;
        const int first = (n / 2 + 1) * (3 * n / 4), second = (n + 1) * n - first - n;
        int frictional = 0, frictionless = 0;
        for (const auto& e : L.contacts)
            (e.frictional() ? frictional : frictionless) += 1;
        EXPECT_EQ(frictional, first) << "level " << l;
        EXPECT_EQ(frictionless, second) << "level " << l;
    }
}

// Component c at x of a linear field that vanishes where punch3d's supports hold (u_x on x = 0,
// u_y on y = 0).
double contact3_linear(const Vec3& x, int c) {
    return c == 0 ? 2 * x.x() : c == 1 ? 3 * x.y() : x.dot(Vec3(1, 2, 3));
}

TEST(Contact3Levels, TheTransfersOfAHierarchyWithMultipliersInterpolateTheDisplacements) {
    const levels::ElasticProblem3 p = scene::load_scene3("punch3d");
    const levels::Hierarchy3 h = levels::build_hierarchy(p, 2);
    for (int l = 1; l <= 2; ++l) {
        const auto& C = h.levels[static_cast<size_t>(l - 1)];
        const auto& F = h.levels[static_cast<size_t>(l)];
        const SparseMatrix& T = h.transfers[static_cast<size_t>(l - 1)].T;
        ASSERT_EQ(T.rows(), F.dofs.n_dofs());
        ASSERT_EQ(T.cols(), C.dofs.n_dofs());
        // A linear field that vanishes where supports hold (T maps corrections) on the coarse
        // displacements, ones on its multipliers: T gives the field on the fine displacements
        // and zero on the fine multipliers.
        Vector uc = Vector::Ones(C.dofs.n_dofs());
        for (int v = 0; v < C.mesh.n_vertices(); ++v)
            for (int c = 0; c < 3; ++c)
                if (const int d = C.dofs.u_dof(v, c); d >= 0)
                    uc[d] = contact3_linear(C.mesh.vertices[static_cast<size_t>(v)], c);
        Vector only_u = uc;
        for (Index d = 0; d < C.dofs.n_dofs(); ++d)
            if (!C.dofs.is_displacement(d)) only_u[d] = 0;
        const Vector uf = T * uc;
        EXPECT_EQ((T * only_u - uf).norm(), 0.0) << "a multiplier column is not empty";
        for (Index d = 0; d < F.dofs.n_dofs(); ++d) {
            if (F.dofs.is_displacement(d)) continue;
            EXPECT_EQ(uf[d], 0.0) << "multiplier row " << d;
        }
        for (int v = 0; v < F.mesh.n_vertices(); ++v)
            for (int c = 0; c < 3; ++c)
                if (const int d = F.dofs.u_dof(v, c); d >= 0) {
                    EXPECT_NEAR(uf[d], contact3_linear(F.mesh.vertices[static_cast<size_t>(v)], c),
                                1e-12);
                }
    }
}

// ---------------------------------------------------------------------------------------------
// Held components.

TEST(Contact3Levels, ASymmetryPlaneAcrossFrictionalNodesPinsTheirTangentAlongItsNormal) {
    // ux = 0 on xmin, uy = 0 on ymin: the bottom vertices on x = 0 (but not y = 0) have u_x held,
    // those on y = 0 (but not x = 0) u_y; the normal (0, 0, 1) lies across either axis. Their
    // frame turns its first tangent onto the held axis, and that tangent alone is pinned; the
    // vertex at the corner (both held) has both tangents pinned.
    const std::string text =
        contact3_box("contactor = \"zmin\"\nmu = 0.5\n" + kPlane,
                     "[[support]]\ntag = \"xmin\"\nux = 0.0\n[[support]]\ntag = \"ymin\"\nuy = "
                     "0.0\n[[support]]\ntag = \"zmax\"\nuz = 0.0\n");
    const levels::ElasticProblem3 p = contact3_parse(text);
    const levels::Level3 L = levels::build_level(p, p.mesh0);
    ASSERT_EQ(L.n_contact_nodes(), 9);
    int one = 0, both = 0;
    for (const auto& e : L.contacts) {
        const Vec3 x = L.mesh.vertices[static_cast<size_t>(e.vertex[0])];
        const bool hx = x.x() == 0.0, hy = x.y() == 0.0;
        if (hx && hy) {
            EXPECT_EQ(e.pinned, contact::ContactElement3::kPinnedT);
            ++both;
        } else if (hx || hy) {
            EXPECT_EQ(e.pinned, contact::ContactElement3::kPinnedT1);
            const Vec3 axis = hx ? Vec3::UnitX() : Vec3::UnitY();
            EXPECT_LE((e.t.col(0) - axis).norm(), 1e-15);
            EXPECT_LE((e.t.col(1) - e.n.cross(axis)).norm(), 1e-15);
            ++one;
        } else {
            EXPECT_EQ(e.pinned, 0);
        }
    }
    EXPECT_EQ(both, 1);
    EXPECT_EQ(one, 4);
    // A plane inclined across y: the normal has a part along the held u_y, so the support and
    // the contact would share a force direction: refused.
    const levels::ElasticProblem3 q = contact3_parse(contact3_box(
        "contactor = \"zmin\"\nmu = 0.5\nobstacle = { type = \"plane\", point = [0, 0, 0], "
        "normal = [0, 0.6, 0.8] }\n",
        "[[support]]\ntag = \"ymin\"\nuy = 0.0\n[[support]]\ntag = \"zmax\"\nuz = 0.0\n"));
    mesh::testing::expect_invalid(
        [&] { levels::build_level(q, q.mesh0); },
        {"contact 'floor': contactor vertex 0 at (0, 0, 0) has u_y prescribed by a support",
         "normal (0, 0.6, 0.8)", "meets the held directions only in part",
         "Prescribe all three components of that vertex", "mu = 0", "region"});
    // Frictionless, the same supports pin nothing and build.
    const levels::ElasticProblem3 f = contact3_parse(
        contact3_box("contactor = \"zmin\"\nmu = 0.0\n" + kPlane,
                     "[[support]]\ntag = \"xmin\"\nux = 0.0\n[[support]]\ntag = \"ymin\"\nuy = "
                     "0.0\n"));
    const levels::Level3 F = levels::build_level(f, f.mesh0);
    EXPECT_EQ(F.n_contact_nodes(), 9);
    for (const auto& e : F.contacts)
        EXPECT_EQ(e.pinned, 0);
}

TEST(Contact3Levels, SupportsAlongTheWholeFramePinItsMultipliers) {
    // A frictional pair on a plane whose normal is +z: held u_x and u_y pin the tangential
    // multipliers, held u_z pins the normal (and with it every multiplier).
    const levels::ElasticProblem3 p = contact3_parse(
        contact3_box("contactor = \"zmin\"\nmu = 0.5\n" + kPlane,
                     "[[support]]\ntag = \"ymin\"\nux = 0.0\nuy = 0.0\n[[support]]\ntag = "
                     "\"xmin\"\nuz = 0.0\n"));
    const levels::Level3 L = levels::build_level(p, p.mesh0);
    using E = contact::ContactElement3;
    int pinned_t = 0, pinned_n = 0;
    for (const auto& e : L.contacts) {
        const Vec3& x = L.mesh.vertices[static_cast<size_t>(e.vertex[0])];
        const bool on_ymin = x.y() == 0.0, on_xmin = x.x() == 0.0;
        const unsigned char expected = on_xmin   ? (E::kPinnedN | E::kPinnedT)
                                       : on_ymin ? E::kPinnedT
                                                 : 0;
        EXPECT_EQ(e.pinned, expected) << "at " << x.transpose();
        pinned_t += e.pinned == E::kPinnedT;
        pinned_n += (e.pinned & E::kPinnedN) != 0;
        EXPECT_EQ(e.n_multipliers(), 3);
    }
    // (0, 0, 0) is fully fixed: not a contact node; x = 0 holds two more, y = 0 two more.
    EXPECT_EQ(L.n_contact_nodes(), 8);
    EXPECT_EQ(pinned_n, 2);
    EXPECT_EQ(pinned_t, 2);
}

// ---------------------------------------------------------------------------------------------
// Refusals.

TEST(Contact3Scene, ContactKeysAreReadAndBadValuesRefusedNamingThem) {
    const levels::ElasticProblem3 p = contact3_parse(contact3_box(
        "contactor = \"zmin\"\nmu = 0.3\nr = 0.05\nregion = { min = [0, 0, -1], max = [0.5, 1, "
        "1] }\n" +
            kPlane,
        "[newton]\nrel_tol = 1e-9\nmax_iter = 30\nforcing = 0.0\n", "load_steps = 4\n"));
    EXPECT_EQ(p.load_steps, 4);
    EXPECT_EQ(p.newton.rel_tol, 1e-9);
    EXPECT_EQ(p.newton.max_iter, 30);
    EXPECT_EQ(p.newton.forcing, 0.0);
    ASSERT_EQ(p.contacts.size(), 1u);
    const auto& c = p.contacts[0];
    EXPECT_EQ(c.name, "floor");
    EXPECT_EQ(c.mu, 0.3);
    EXPECT_EQ(c.r, 0.05);
    ASSERT_TRUE(c.region.has_value());
    EXPECT_EQ(c.region->hi, Vec3(0.5, 1, 1));
    EXPECT_EQ(c.obstacle.kind, contact::BasicObstacle<3>::Kind::plane);
    // r_over_E gives r = r_over_E E h0: E = 2, h0 the bottom's mean edge ((12 x 0.5 + 4 x 0.5
    // sqrt 2) / 16).
    const levels::ElasticProblem3 q =
        contact3_parse(contact3_box("contactor = \"zmin\"\nmu = 0.0\nr_over_E = 0.2\n" + kPlane));
    EXPECT_NEAR(q.contacts[0].r, 0.2 * 2.0 * (12 * 0.5 + 4 * 0.5 * std::sqrt(2.0)) / 16, 1e-15);

    const std::string plane = kPlane;
    contact3_error(contact3_box("contactor = \"top\"\nmu = 0.0\n" + plane),
                   {"t.toml:13", "unknown contactor tag 'top'", "xmax, xmin, ymax, ymin, zmax"});
    contact3_error(contact3_box("contactor = \"zmin\"\nmu = -0.1\n" + plane),
                   {"t.toml:14", "mu must be >= 0"});
    contact3_error(
        contact3_box("contactor = \"zmin\"\nmu = 0.0\nr = 0.0\n" + plane),
        {"t.toml:15", "augmentation parameter r must be > 0", "force per length", "r_over_E E h0"});
    contact3_error(contact3_box("contactor = \"zmin\"\nmu = 0.0\nr_over_E = 1e9\n" + plane),
                   {"t.toml:15", "times E h0", "outside [1e-06, 1e+06] E h0"});
    contact3_error(
        contact3_box("contactor = \"zmin\"\nmu = 0.0\nr = 1.0\nr_over_E = 0.1\n" + plane),
        {"takes r or r_over_E, not both"});
    contact3_error(
        contact3_box("contactor = \"zmin\"\nmu = 0.0\nregion = { min = [1, 0, 0], max = [0, 1, "
                     "1] }\n" +
                     plane),
        {"t.toml:15", "region: its min exceeds its max"});
    // A pair with no contact node parses, and its level is refused.
    const levels::ElasticProblem3 none = contact3_parse(
        contact3_box("contactor = \"zmin\"\nmu = 0.0\nregion = { max = [-1, 1, 1] }\n" + plane));
    mesh::testing::expect_invalid(
        [&] { levels::build_level(none, none.mesh0); },
        {"contact 'floor' has no contactor node on 'zmin': of its 9 vertices, 9 lie outside the "
         "region, 0 have all three components fixed"});
    contact3_error(contact3_box("contactor = \"zmin\"\nmu = 0.0\n"),
                   {"needs an obstacle (rigid) or a target tag (two bodies)"});
    contact3_error(contact3_box("contactor = \"zmin\"\nmu = 0.0\n" + plane, "", "load_steps = 0\n"),
                   {"t.toml:4", "[scene].load_steps must be at least 1, found 0"});
    contact3_error(
        contact3_box("contactor = \"zmin\"\nmu = 0.0\n" + plane, "[newton]\nrel_tol = 2.0\n"),
        {"newton.rel_tol must lie in (0, 1)"});
    contact3_error(
        contact3_box("contactor = \"zmin\"\nmu = 0.0\n" + plane, "[newton]\ntolerance = 2.0\n"),
        {"unknown key 'tolerance' in [newton]", "rel_tol, max_iter, forcing"});
}

TEST(Contact3Scene, TwoBodyKeysBesideAnObstacleAndTwoDimensionalObstaclesAreRefused) {
    for (const std::string key : {"element = \"node_on_facet\"", "integration = \"segment\"",
                                  "search_radius = 2.0", "match_tolerance = 1e-6"}) {
        const std::string name = key.substr(0, key.find(' '));
        contact3_error(contact3_box("contactor = \"zmin\"\nmu = 0.0\n" + key + "\n" + kPlane),
                       {"t.toml:15", "[[contact]]." + name + " applies to two-body pairs"});
    }
    contact3_error(contact3_box("contactor = \"zmin\"\nmu = 0.0\ntarget = \"zmax\"\n" + kPlane),
                   {"takes an obstacle (rigid) or a target tag (two bodies), not both"});
    contact3_error(contact3_box("contactor = \"zmin\"\nmu = 0.0\nobstacle = { type = \"line\", "
                                "point = [0, 0], normal = [0, 1] }\n"),
                   {"t.toml:15", "obstacle.type \"line\" is 2D-only", "\"plane\""});
    contact3_error(contact3_box("contactor = \"zmin\"\nmu = 0.0\nobstacle = { type = \"circle\", "
                                "center = [0, 0], radius = 1.0 }\n"),
                   {"obstacle.type \"circle\" is 2D-only", "\"sphere\" or a \"cylinder\""});
    contact3_error(contact3_box("contactor = \"zmin\"\nmu = 0.0\nobstacle = { type = \"cone\" }\n"),
                   {"must be \"plane\", \"sphere\" or \"cylinder\", found \"cone\""});
}

TEST(Contact3Scene, DegenerateObstaclesAndObstaclesFacingAwayAreRefusedWithTheirLine) {
    const std::string head = "contactor = \"zmin\"\nmu = 0.0\n";
    contact3_error(
        contact3_box(head + "obstacle = { type = \"sphere\", center = [0.5, 0.5, -2], "
                            "radius = -2.0 }\n"),
        {"t.toml:15", "sphere obstacle needs a positive radius", "a negative radius, -2"});
    contact3_error(contact3_box(head + "obstacle = { type = \"cylinder\", center = [0, 0.5, -1], "
                                       "axis = [0, 0, 0], radius = 1.0 }\n"),
                   {"t.toml:15", "cylinder obstacle needs an axis of non-zero length"});
    contact3_error(contact3_box(head + "obstacle = { type = \"plane\", point = [0, 0, 0], "
                                       "normal = [0, 0, 0] }\n"),
                   {"t.toml:15", "plane obstacle needs a non-zero normal"});
    contact3_error(contact3_box(head + "obstacle = { type = \"sphere\", center = [0.5, 0.5, -1], "
                                       "radius = 1.0, side = \"above\" }\n"),
                   {"side must be \"outside\" or \"inside\", found \"above\""});
    // Facing away: the plane's normal into the floor, the body inside a sphere it should be
    // outside of.
    contact3_error(contact3_box(head + "obstacle = { type = \"plane\", point = [0, 0, 0], "
                                       "normal = [0, 0, -1] }\n"),
                   {"t.toml:15", "100% of the volume of body 'body1' lies behind the plane",
                    "normal = [0, 0, 1]"});
    contact3_error(contact3_box(head + "obstacle = { type = \"sphere\", center = [0.5, 0.5, 0.5], "
                                       "radius = 5.0 }\n"),
                   {"lies inside the sphere", "use side = \"inside\""});
    contact3_error(contact3_box(head + "obstacle = { type = \"cylinder\", center = [0.5, 0.5, 0], "
                                       "axis = [1, 0, 0], radius = 3.0, side = \"outside\" }\n"),
                   {"lies inside the cylinder", "use side = \"inside\""});
    // Inside a large sphere the body should be inside of: accepted, normals toward the centre.
    const levels::ElasticProblem3 p = contact3_parse(
        contact3_box(head + "obstacle = { type = \"cylinder\", center = [0.5, 0.5, 3.0], axis = "
                            "[1, 0, 0], radius = 3.0, side = \"inside\" }\n"));
    const levels::Level3 L = levels::build_level(p, p.mesh0);
    for (const auto& e : L.contacts) {
        const Vec3& x = L.mesh.vertices[static_cast<size_t>(e.vertex[0])];
        Vec3 d = Vec3(0.5, 0.5, 3.0) - x;
        d.x() = 0;
        EXPECT_NEAR((e.n - d.normalized()).norm(), 0.0, 1e-14);
        EXPECT_NEAR(e.g0, 3.0 - d.norm(), 1e-14);
    }
}

TEST(Contact3Levels, AContactorTagOnNoBoundaryFaceIsRefusedNamingTheFaceTags) {
    levels::ElasticProblem3 p = contact3_parse(
        contact3_box("contactor = \"zmin\"\nmu = 0.0\n" + kPlane,
                     "[[support]]\ntag = \"xmin\"\nux = 0.0\n[[support]]\ntag = \"ymin\"\nuy = "
                     "0.0\n"));
    p.validate();
    p.contacts[0].contactor = "nowhere";
    mesh::testing::expect_invalid(
        [&] { p.validate(); },
        {"contact 'floor': the contactor tag 'nowhere' is a tag of no boundary face",
         "(the boundary face tags are: xmax, xmin, ymax, ymin, zmax, zmin)"});
    p.mesh0.add_tag("nowhere"); // a tag without faces
    mesh::testing::expect_invalid([&] { p.validate(); },
                                  {"contactor tag 'nowhere' is a tag of no boundary face"});
    p.contacts[0].contactor = "zmin";
    p.contacts[0].r = 0.0;
    mesh::testing::expect_invalid([&] { p.validate(); }, {"r must be > 0, found 0"});
    p.contacts[0].r = 1.0;
    p.contacts[0].mu = -1.0;
    mesh::testing::expect_invalid([&] { p.validate(); }, {"mu must be >= 0, found -1"});
    p.contacts[0].mu = 0.0;
    p.contacts[0].obstacle.radius = -1.0;
    p.contacts[0].obstacle.kind = contact::BasicObstacle<3>::Kind::sphere;
    mesh::testing::expect_invalid([&] { p.validate(); },
                                  {"contact 'floor': a sphere obstacle needs a positive radius"});
    p.contacts[0].obstacle = contact::BasicObstacle<3>{};
    p.load_steps = 0;
    mesh::testing::expect_invalid([&] { p.validate(); }, {"load_steps must be at least 1"});
    p.load_steps = 1;
    p.newton.max_iter = 0;
    mesh::testing::expect_invalid([&] { p.validate(); }, {"newton.max_iter must be at least 1"});
}

TEST(Contact3Scene, CurvedSurfacesOfAGmshMeshAreDeclaredOrRefused) {
    // hertz3d's mesh, read as a built-in scene reads it.
    const auto parse = [](const std::string& surface) {
        return scene::parse_scene3(
            "[scene]\nname = \"s\"\ndimension = 3\n[[body]]\nE = 1.0\nnu = 0.3\n[body.mesh]\n"
            "type = \"gmsh\"\nfile = \"hertz3d.msh\"\n" +
                surface + "[[support]]\ntag = \"sym_x\"\nux = 0.0\n",
            "builtin:s");
    };
    const levels::ElasticProblem3 p = parse("");
    EXPECT_TRUE(p.mesh0.shapes.empty());
    const auto refused = [&](const std::string& surface, const std::vector<std::string>& parts) {
        mesh::testing::expect_invalid([&] { parse(surface); }, parts);
    };
    refused("surface = \"hemisphere\"\n",
            {"builtin:s:10", "surface declares the curved faces of a 3D mesh", "`volume`"});
    refused("surface = [{ tag = \"sphere\", type = \"sphere\", center = [0, 0, 1], radius = 1.1 "
            "}]\n",
            {"builtin:s:10", "of tag 'sphere' lies", "off the sphere"});
    refused("surface = [{ tag = \"rim\", type = \"sphere\", center = [0, 0, 1], radius = 1.0 }]\n",
            {"builtin:s:10", "no boundary tag 'rim'", "sphere"});
    refused("surface = [{ tag = \"sphere\", type = \"cone\", center = [0, 0, 1], radius = 1.0 }]\n",
            {"builtin:s:10", "must be \"sphere\" or \"cylinder\", found \"cone\""});
    refused("surface = [{ tag = \"sphere\", type = \"sphere\", center = [0, 0, 1], radius = -1.0 "
            "}]\n",
            {"builtin:s:10", "radius must be > 0"});
    refused("surface = [{ tag = \"sphere\", type = \"cylinder\", center = [0, 0, 1], radius = 1.0 "
            "}]\n",
            {"builtin:s:10", "missing key 'axis'"});
    refused("surface = [{ tag = \"sphere\", type = \"sphere\", center = [0, 0, 1], radius = 1.0, "
            "axis = [0, 0, 1] }]\n",
            {"unknown key 'axis'", "allowed: tag, type, center, radius"});
    // A cylinder through the pole along y holds the rim of the symmetry plane x = 0 only: the
    // sphere's other vertices are refused.
    refused("surface = [{ tag = \"sym_y\", type = \"cylinder\", center = [0, 0, 1], axis = [0, 1, "
            "0], radius = 1.0 }]\n",
            {"of tag 'sym_y' lies", "off the cylinder"});
}

} // namespace
} // namespace mlc
