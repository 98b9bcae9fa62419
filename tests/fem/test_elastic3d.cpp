// SPDX-License-Identifier: MIT
// P1 elasticity on tetrahedra: patch tests (linear fields, constant-stress tractions), supports
// on faces, lines and points, load resultants, the rigid-body kernel of K and bad input.
#include "core/check.hpp"
#include "fem/assembly.hpp"
#include "fem/simplex.hpp"
#include "mesh/tet_refine.hpp"
#include "tests/fem/elastic3d_test_util.hpp"
#include "tests/mesh/tet_test_meshes.hpp"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <cmath>

using namespace mlc;
using fem::testing::box_boundary_vertices;
using fem::testing::kBoxTags;
using fem::testing::solve_elastic;
using mesh::Vec3;
using mesh::testing::expect_invalid;

namespace {

/// The linear field u(x) = c + A x of the patch tests.
struct LinearField {
    Eigen::Matrix3d A;
    Vec3 c{0.3, -0.2, 0.1};
    LinearField() { A << 1e-3, 2e-3, -1e-3, 0.5e-3, -3e-3, 2e-3, 1.5e-3, 0.2e-3, 0.7e-3; }
    Vec3 operator()(const Vec3& x) const { return c + A * x; }
};

/// Imposes `field` on every vertex of `boundary`, solves with no load, and checks every vertex
/// and every tetrahedron's stress against the field's.
void expect_linear_field_reproduced(const mesh::TetMesh& m, const std::vector<int>& boundary,
                                    const std::vector<fem::Material>& materials) {
    const LinearField field;
    std::vector<fem::VertexSupport3> supports;
    for (int v : boundary)
        supports.push_back({{v}, {true, true, true}, field(m.vertices[static_cast<size_t>(v)])});
    const Vector u = solve_elastic(m, materials, supports, Vector::Zero(3 * m.n_vertices()));
    const double scale = (field.A.norm() + field.c.norm()) * m.diameter();
    int interior = 0;
    for (int v = 0; v < m.n_vertices(); ++v) {
        const Vec3 exact = field(m.vertices[static_cast<size_t>(v)]);
        EXPECT_LE((u.segment<3>(3 * v) - exact).norm(), 1e-10 * scale) << "vertex " << v;
        interior += !std::binary_search(boundary.begin(), boundary.end(), v);
    }
    EXPECT_GE(interior, 8);
    const Eigen::Matrix3d eps = 0.5 * (field.A + field.A.transpose());
    Eigen::Matrix<double, 6, 1> voigt;
    voigt << eps(0, 0), eps(1, 1), eps(2, 2), 2 * eps(0, 1), 2 * eps(1, 2), 2 * eps(0, 2);
    const Eigen::Matrix<double, 6, 1> sigma = fem::elasticity_matrix<3>(materials.back()) * voigt;
    const std::vector<double> s = fem::cell_stresses(m, materials, u);
    ASSERT_EQ(s.size(), 6 * m.cells.size());
    for (size_t t = 0; t < m.cells.size(); ++t)
        for (int k = 0; k < 6; ++k)
            ASSERT_NEAR(s[6 * t + static_cast<size_t>(k)], sigma[k], 1e-9 * sigma.norm()) << t;
}

} // namespace

TEST(Elastic3dPatch, LinearFieldOnTheBoundaryOfAKuhnBoxIsReproduced) {
    // Non-cubic cells, refined once: interior vertices of both kinds (box and Bey midpoints).
    const mesh::TetMesh m =
        mesh::refine(mesh::structured_box({0.2, -0.1, 0.3}, {1.3, 0.9, 1.1}, 3, 2, 2));
    expect_linear_field_reproduced(m, box_boundary_vertices(m), {{.E = 210e3, .nu = 0.3}});
}

TEST(Elastic3dPatch, LinearFieldOnTheBoundaryOfAGmshMeshIsReproduced) {
    for (const char* version : {"2.2", "4.1"}) {
        const mesh::TetMesh m = fem::testing::perturbed_gmsh_box(3, version);
        ASSERT_EQ(m.attribute.front(), 1); // the physical volume: materials 0 and 1
        const std::vector<fem::Material> materials(2, fem::Material{.E = 3.5, .nu = 0.41});
        expect_linear_field_reproduced(m, box_boundary_vertices(m), materials);
        expect_linear_field_reproduced(mesh::refine(m), box_boundary_vertices(mesh::refine(m)),
                                       materials);
    }
}

TEST(Elastic3dPatch, ConstantStressFromTractionsAndPressureIsReproduced) {
    // Tractions sigma n plus a pressure p on all six faces of a perturbed box: the exact solution
    // is linear with stress sigma - p I. Held: vertex 0 fully, then two more vertices on the
    // components that remove the rotations (values from the exact field).
    const mesh::TetMesh m = fem::testing::perturbed_gmsh_box(2, "4.1");
    const std::vector<fem::Material> materials(2, fem::Material{.E = 7.0, .nu = 0.2});
    Eigen::Matrix3d sigma;
    sigma << 1.0, 0.3, -0.2, 0.3, -0.5, 0.4, -0.2, 0.4, 0.8;
    const double p = 0.7;
    const Vec3 normals[6] = {-Vec3::UnitX(), Vec3::UnitX(),  -Vec3::UnitY(),
                             Vec3::UnitY(),  -Vec3::UnitZ(), Vec3::UnitZ()};
    std::vector<fem::Traction3> tractions;
    for (int k = 0; k < 6; ++k)
        tractions.push_back({m.tag(kBoxTags[k]), p, sigma * normals[k]});
    const Vector F = fem::nodal_loads(m, tractions, {});
    // Exact strain from the stress: eps = ((1 + nu) s - nu tr(s) I) / E.
    const Eigen::Matrix3d s = sigma - p * Eigen::Matrix3d::Identity();
    const double E = 7.0, nu = 0.2;
    const Eigen::Matrix3d eps = ((1 + nu) * s - nu * s.trace() * Eigen::Matrix3d::Identity()) / E;
    auto exact = [&](const Vec3& x) { return Vec3(eps * x); }; // u(0) = 0, no rotation
    const int a = m.nearest_vertex({0, 0, 0}), b = m.nearest_vertex({1.2, 0, 0}),
              c = m.nearest_vertex({0, 1, 0});
    const std::vector<fem::VertexSupport3> supports = {
        {{a}, {true, true, true}, exact(m.vertices[static_cast<size_t>(a)])},
        {{b}, {false, true, true}, exact(m.vertices[static_cast<size_t>(b)])},
        {{c}, {false, false, true}, exact(m.vertices[static_cast<size_t>(c)])}};
    const Vector u = solve_elastic(m, materials, supports, F);
    for (int v = 0; v < m.n_vertices(); ++v)
        EXPECT_LE((u.segment<3>(3 * v) - exact(m.vertices[static_cast<size_t>(v)])).norm(),
                  1e-10 * eps.norm())
            << v;
    // Reactions vanish: the internal forces balance the loads at every vertex.
    const Vector r = fem::internal_forces(m, materials, u) - F;
    EXPECT_LE(r.lpNorm<Eigen::Infinity>(), 1e-10 * F.lpNorm<Eigen::Infinity>());
}

TEST(Elastic3dSupports, FacesLinesAndPointsWithComponentMasks) {
    // Uniaxial compression of a box by a pressure p on zmax: a roller (uz) on zmin, ux held on
    // the line x = 0, z = 0 (xmin meets zmin), uy held at two points of the line y = 0, z = 0.
    // Exact: u = (nu p x / E, nu p y / E, -p z / E).
    const mesh::TetMesh m = mesh::structured_box({0, 0, 0}, {2.0, 1.0, 1.5}, 4, 2, 3);
    const auto zmin = fem::facet_vertices(m, m.tag("zmin"));
    EXPECT_EQ(zmin.size(), 5u * 3u);
    const auto line = fem::line_vertices(m, m.tag("xmin"), m.tag("zmin"));
    EXPECT_EQ(line, fem::segment_vertices(m, {0, 0, 0}, {0, 1, 0}, 1e-9));
    EXPECT_EQ(line.size(), 3u);
    EXPECT_EQ(fem::segment_vertices(m, {0, 0, 0}, {2, 0, 0}, 1e-9).size(), 5u);
    const double E = 10.0, nu = 0.3, p = 0.5;
    const std::vector<fem::VertexSupport3> supports = {
        {zmin, {false, false, true}, Vec3::Zero()},
        {line, {true, false, false}, Vec3::Zero()},
        {{m.nearest_vertex({0, 0, 0}), m.nearest_vertex({2, 0, 0})},
         {false, true, false},
         Vec3::Zero()}};
    const Vector F = fem::nodal_loads(m, {{m.tag("zmax"), p, Vec3::Zero()}}, {});
    const Vector u = solve_elastic(m, {{.E = E, .nu = nu}}, supports, F);
    for (int v = 0; v < m.n_vertices(); ++v) {
        const Vec3& x = m.vertices[static_cast<size_t>(v)];
        const Vec3 exact(nu * p * x.x() / E, nu * p * x.y() / E, -p * x.z() / E);
        EXPECT_LE((u.segment<3>(3 * v) - exact).norm(), 1e-12) << v;
    }
    // The last support of a component sets its value.
    const auto s = fem::collect_supports(
        m, {{{7}, {true, true, false}, Vec3(1, 2, 3)}, {{7}, {false, true, true}, Vec3(4, 5, 6)}});
    EXPECT_EQ(s.fixed[7], (fem::Components3{true, true, true}));
    EXPECT_EQ(Vec3(s.u_fixed.segment<3>(21)), Vec3(1, 5, 6));
    EXPECT_EQ(s.fixed[6], (fem::Components3{false, false, false}));
}

TEST(Elastic3dLoads, ResultantsOfPressureTractionAndBodyForce) {
    // A box warped by a smooth map that moves points within the planes x = 0, 1 and z = 0, 1
    // (the faces' triangles no longer regular, ymin and ymax no longer planar): a uniform pressure
    // over the closed boundary has zero resultant and zero moment (exact for P1 thirds on flat
    // triangles); on the planar unit square xmax its resultant is -p e_x.
    mesh::TetMesh m = mesh::refine(mesh::structured_box({0, 0, 0}, {1, 1, 1}, 2, 2, 2));
    for (auto& x : m.vertices)
        x += 0.05 * Vec3(std::sin(3 * x.y()) * x.x() * (1 - x.x()),
                         std::sin(2 * x.z() + x.x()) * x.y() * (1 - x.y()), 0.0);
    const double p = 2.5;
    std::vector<fem::Traction3> all;
    for (const char* tag : kBoxTags)
        all.push_back({m.tag(tag), p, Vec3::Zero()});
    const Vector F = fem::nodal_loads(m, all, {});
    Vec3 force = Vec3::Zero(), moment = Vec3::Zero();
    for (int v = 0; v < m.n_vertices(); ++v) {
        force += F.segment<3>(3 * v);
        moment += m.vertices[static_cast<size_t>(v)].cross(Vec3(F.segment<3>(3 * v)));
    }
    EXPECT_LE(force.norm(), 1e-13 * p);
    EXPECT_LE(moment.norm(), 1e-13 * p);
    auto resultant = [&](const Vector& G) {
        Vec3 r = Vec3::Zero();
        for (int v = 0; v < m.n_vertices(); ++v)
            r += G.segment<3>(3 * v);
        return r;
    };
    const Vec3 on_xmax = resultant(fem::nodal_loads(m, {{m.tag("xmax"), p, Vec3::Zero()}}, {}));
    EXPECT_LE((on_xmax - Vec3(-p, 0, 0)).norm(), 1e-14 * p);
    // A traction vector on zmin (the unit square z = 0): its resultant is t.
    const Vec3 t(0.3, -1.2, 0.4);
    const Vec3 on_zmin = resultant(fem::nodal_loads(m, {{m.tag("zmin"), 0.0, t}}, {}));
    EXPECT_LE((on_zmin - t).norm(), 1e-14 * t.norm());
    // Body force: b times the volume, constant per attribute or as a function.
    double volume = 0;
    for (int k = 0; k < m.n_cells(); ++k)
        volume += std::abs(m.signed_measure(k));
    const Vec3 b(0.0, 0.0, -9.81);
    EXPECT_LE((resultant(fem::nodal_loads(m, {}, {b})) - volume * b).norm(), 1e-13 * b.norm());
    EXPECT_LE(
        (resultant(fem::body_force_loads(m, [&](const Vec3&) { return b; })) - volume * b).norm(),
        1e-13 * b.norm());
}

TEST(Elastic3dLoads, SharesOfOneFaceAndOneTetrahedron) {
    // One tetrahedron with one tagged face: each face vertex receives a third of the face's
    // resultant, each vertex a quarter of V b.
    mesh::TetMesh m;
    m.vertices = {{0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {0, 0, 1}};
    m.cells = {{0, 1, 2, 3}};
    m.boundary = {{{0, 2, 1}, m.add_tag("bottom"), -1}}; // normal -z, area 3
    mesh::check_quality(m);
    const double p = 1.5;
    const Vector F = fem::nodal_loads(m, {{m.tag("bottom"), p, Vec3(0.3, 0, 0)}}, {Vec3(0, 6, 0)});
    for (int v = 0; v < 4; ++v) {
        const Vec3 face = v < 3 ? Vec3(3 * 0.3 / 3, 0, p * 3 / 3) : Vec3::Zero();
        const Vec3 body(0, 1.0 / 4.0 * 6, 0); // V = 1
        EXPECT_LE((F.segment<3>(3 * v) - face - body).norm(), 1e-15) << v;
    }
}

TEST(Elastic3dStiffness, RigidBodyModesAreInTheKernelOfAnUnsupportedBody) {
    const mesh::TetMesh meshes[2] = {
        mesh::refine(mesh::read_gmsh_tet_text(mesh::testing::msh41(mesh::testing::distorted_cube()),
                                              "cube.msh")),
        fem::testing::perturbed_gmsh_box(2, "2.2")};
    for (const auto& m : meshes) {
        int max_attr = 0;
        for (int a : m.attribute)
            max_attr = std::max(max_attr, a);
        std::vector<fem::Material> materials(static_cast<size_t>(max_attr) + 1,
                                             fem::Material{.E = 210e3, .nu = 0.3});
        materials.back().E = 70e3; // two materials on the distorted cube
        const int nv = m.n_vertices();
        const fem::DofMap3 dofs(std::vector<fem::Components3>(static_cast<size_t>(nv)),
                                std::vector<int>(static_cast<size_t>(nv), 0));
        const Vector zero = Vector::Zero(3 * nv);
        const auto sys = fem::assemble_elastic(m, materials, dofs, zero, zero);
        ASSERT_EQ(sys.K.rows(), 3 * nv);
        const SparseMatrix Kt = sys.K.transpose();
        EXPECT_LE((sys.K - Kt).norm(), 1e-14 * sys.K.norm());
        for (int mode = 0; mode < 6; ++mode) {
            Vector r(3 * nv);
            for (int v = 0; v < nv; ++v) {
                const Vec3& x = m.vertices[static_cast<size_t>(v)];
                r.segment<3>(3 * v) =
                    mode < 3 ? Vec3(Vec3::Unit(mode)) : Vec3(Vec3::Unit(mode - 3).cross(x));
            }
            EXPECT_LE((sys.K * r).norm(), 1e-12 * sys.K.norm() * r.norm()) << mode;
            // internal_forces is K_full u.
            EXPECT_LE((fem::internal_forces(m, materials, r) - sys.K * r).norm(),
                      1e-12 * sys.K.norm() * r.norm());
        }
        // Exactly six zero eigenvalues on the small mesh.
        if (nv <= 40) {
            Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(sys.K));
            const auto ev = es.eigenvalues();
            for (int i = 0; i < 6; ++i)
                EXPECT_LT(std::abs(ev[i]), 1e-10 * ev[ev.size() - 1]);
            EXPECT_GT(ev[6], 1e-6 * ev[ev.size() - 1]);
        }
    }
}

TEST(Elastic3dInput, BadInputIsNamed) {
    mesh::TetMesh m = mesh::structured_box({0, 0, 0}, {1, 1, 1}, 1, 1, 1);
    const int nv = m.n_vertices();
    const Vector zero = Vector::Zero(3 * nv);
    const fem::DofMap3 dofs(std::vector<fem::Components3>(static_cast<size_t>(nv)),
                            std::vector<int>(static_cast<size_t>(nv), 0));
    const int top = m.add_tag("top"); // a name with no face
    // A traction on a tag no face carries adds nothing (the problem's checks name it: a
    // process's part of a mesh may lack a tag's faces).
    EXPECT_EQ(fem::nodal_loads(m, {{top, 1.0, Vec3::Zero()}}, {}).norm(), 0.0);
    expect_invalid(
        [&] {
            fem::nodal_loads(m, {{top, std::nan(""), Vec3::Zero()}}, {});
        },
        {"traction on 'top' is not finite"});
    expect_invalid([&] { fem::facet_vertices(m, top); },
                   {"face support", "no boundary face carries the tag 'top'", "'xmin'", "'zmax'"});
    expect_invalid([&] { fem::line_vertices(m, m.tag("xmin"), top); }, {"line support", "'top'"});
    expect_invalid(
        [&] {
            fem::collect_supports(m, {{{nv}, {true, true, true}, Vec3::Zero()}});
        },
        {"support 0 names vertex 8", "8 vertices"});
    m.attribute.assign(6, 0);
    m.attribute[4] = 2;
    expect_invalid(
        [&] {
            fem::assemble_elastic(m, {{}, {}}, dofs, zero, zero);
        },
        {"tetrahedron 4 has attribute 2, which has no material (2 given"});
    expect_invalid([&] { fem::nodal_loads(m, {}, {Vec3::Zero()}); },
                   {"tetrahedron 4 has attribute 2, which has no body force"});
    m.attribute.clear();
    expect_invalid(
        [&] {
            fem::assemble_elastic(m, {{.E = 1, .nu = 0.3, .plane = fem::Plane::stress}}, dofs, zero,
                                  zero);
        },
        {"plane stress"});
    expect_invalid([&] { fem::assemble_elastic(m, {{.E = -1}}, dofs, zero, zero); },
                   {"Young's modulus"});
    expect_invalid([&] { fem::assemble_elastic(m, {{}}, dofs, Vector::Zero(3), zero); },
                   {"3 values per vertex"});
    // A flat tetrahedron is the mesh checks' to refuse.
    m.vertices[7] = {1, 1, 0};
    EXPECT_THROW(mesh::check_quality(m), InvalidInput);
}
