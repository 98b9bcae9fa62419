// SPDX-License-Identifier: MIT
// Tests of the tetrahedral VTU writers: the binary file decoded back (sizes, cell types,
// connectivity, coordinates and values bit for bit), the boundary faces with their tags, a PVD
// series of steps, and the refusals.
#include "mesh/io/gmsh_tet.hpp"
#include "mesh/io/vtu_tet.hpp"
#include "mesh/tet_refine.hpp"
#include "tests/mesh/tet_test_meshes.hpp"

#include "tests/common/files.hpp"
#include "tests/mesh/vtu_read.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>
#include <zlib.h>

using namespace mlc;
using namespace mlc::mesh;
namespace fs = std::filesystem;
namespace tmesh = mlc::mesh::testing;

namespace {

/// The distorted cube of the Gmsh tests (two bodies, three tags), refined once.
TetMesh gmsh_mesh() {
    return refine(read_gmsh_tet_text(tmesh::msh41(tmesh::distorted_cube()), "cube.msh"));
}

/// A scalar and a 3-vector point field and a scalar cell field with values that do not print
/// exactly in decimal.
std::vector<Field> point_fields(const TetMesh& m) {
    Field phi{"phi", 1, {}}, u{"displacement", 3, {}};
    for (const Vec3& x : m.vertices) {
        phi.values.push_back(std::sin(x.x()) + x.y() / 3 - std::exp(x.z()));
        for (int c = 0; c < 3; ++c)
            u.values.push_back(1e-3 * std::cos(x[c] + c) / 7);
    }
    return {phi, u};
}

} // namespace

class VtuTet : public ::testing::Test {
protected:
    void TearDown() override { fs::remove_all(testutil::scratch_path("mlc_vtu_tet")); }
};

TEST_F(VtuTet, TetrahedraAndFieldsReadBackBitForBit) {
    const fs::path file = testutil::scratch_dir("mlc_vtu_tet") / "tets.vtu";
    const TetMesh m = gmsh_mesh();
    const auto pf = point_fields(m);
    Field vol{"volume", 1, {}};
    for (int t = 0; t < m.n_cells(); ++t)
        vol.values.push_back(m.signed_measure(t));
    write_vtu(file, m, pf, {vol});
    const std::string xml = testutil::slurp(file);
    EXPECT_EQ(testutil::xml_attribute(xml, "NumberOfPoints"), std::to_string(m.n_vertices()));
    EXPECT_EQ(testutil::xml_attribute(xml, "NumberOfCells"), std::to_string(m.n_cells()));
    EXPECT_EQ(testutil::xml_attribute(xml, "compressor"), "vtkZLibDataCompressor");
    const std::size_t nv = m.vertices.size(), nt = m.cells.size();

    const auto xyz = testutil::as<double>(testutil::appended_array(xml, "<Points>"));
    ASSERT_EQ(xyz.size(), 3 * nv);
    for (std::size_t v = 0; v < nv; ++v)
        for (int c = 0; c < 3; ++c)
            ASSERT_EQ(xyz[3 * v + static_cast<std::size_t>(c)], m.vertices[v][c]) << v;
    const auto conn =
        testutil::as<std::int32_t>(testutil::appended_array(xml, "Name=\"connectivity\""));
    const auto offsets =
        testutil::as<std::int64_t>(testutil::appended_array(xml, "Name=\"offsets\""));
    const auto types = testutil::appended_array(xml, "Name=\"types\"");
    ASSERT_EQ(conn.size(), 4 * nt);
    ASSERT_EQ(offsets.size(), nt);
    ASSERT_EQ(types.size(), nt);
    for (std::size_t t = 0; t < nt; ++t) {
        for (std::size_t k = 0; k < 4; ++k)
            ASSERT_EQ(conn[4 * t + k], m.cells[t][k]) << t;
        ASSERT_EQ(offsets[t], static_cast<std::int64_t>(4 * (t + 1)));
        ASSERT_EQ(types[t], 10); // VTK_TETRA
    }
    // Point fields in PointData, cell fields ("body" first) in CellData, bit for bit.
    const std::size_t point_data = xml.find("<PointData>"), cell_data = xml.find("<CellData>");
    for (const Field& f : pf) {
        const std::size_t at = xml.find("Name=\"" + f.name + "\"");
        EXPECT_LT(point_data, at);
        EXPECT_LT(at, cell_data);
        EXPECT_EQ(testutil::xml_attribute(xml, "NumberOfComponents", at),
                  std::to_string(f.n_components));
        EXPECT_EQ(testutil::as<double>(testutil::appended_array(xml, "Name=\"" + f.name + "\"")),
                  f.values)
            << f.name;
    }
    EXPECT_LT(xml.find("Name=\"body\""), xml.find("Name=\"volume\""));
    EXPECT_LT(cell_data, xml.find("Name=\"body\""));
    const auto body = testutil::as<double>(testutil::appended_array(xml, "Name=\"body\""));
    ASSERT_EQ(body.size(), nt);
    for (std::size_t t = 0; t < nt; ++t)
        ASSERT_EQ(body[t], m.attribute[t]); // physical volumes 3 (shell) and 4 (core)
    EXPECT_EQ(std::count(body.begin(), body.end(), 4.0), 8); // the core's eight children
    EXPECT_EQ(testutil::as<double>(testutil::appended_array(xml, "Name=\"volume\"")), vol.values);
}

TEST_F(VtuTet, BoundaryFacesWithTheirTags) {
    const fs::path file = testutil::scratch_dir("mlc_vtu_tet") / "boundary.vtu";
    const TetMesh m = structured_box(Vec3(0, 0, 0), Vec3(1, 2, 3), 2, 1, 1);
    const auto pf = point_fields(m);
    write_boundary_vtu(file, m, pf);
    const std::string xml = testutil::slurp(file);
    const std::size_t nf = m.boundary.size();
    ASSERT_EQ(nf, 2u * (2 * 1 + 2 * 1 + 1 * 1) * 2); // two triangles per square face
    EXPECT_EQ(testutil::xml_attribute(xml, "NumberOfPoints"), std::to_string(m.n_vertices()));
    EXPECT_EQ(testutil::xml_attribute(xml, "NumberOfCells"), std::to_string(nf));
    const auto conn =
        testutil::as<std::int32_t>(testutil::appended_array(xml, "Name=\"connectivity\""));
    const auto types = testutil::appended_array(xml, "Name=\"types\"");
    const auto tag = testutil::as<double>(testutil::appended_array(xml, "Name=\"tag\""));
    const auto surface = testutil::as<double>(testutil::appended_array(xml, "Name=\"surface\""));
    ASSERT_EQ(conn.size(), 3 * nf);
    ASSERT_EQ(tag.size(), nf);
    for (std::size_t f = 0; f < nf; ++f) {
        for (std::size_t k = 0; k < 3; ++k)
            ASSERT_EQ(conn[3 * f + k], m.boundary[f].v[k]);
        EXPECT_EQ(types[f], 5); // VTK_TRIANGLE
        EXPECT_EQ(tag[f], m.boundary[f].tag);
        EXPECT_EQ(surface[f], -1.0);
    }
    // Faces tagged zmax lie in z = 3.
    const auto xyz = testutil::as<double>(testutil::appended_array(xml, "<Points>"));
    for (std::size_t f = 0; f < nf; ++f) {
        if (tag[f] != m.tag("zmax")) continue;
        for (std::size_t k = 0; k < 3; ++k)
            EXPECT_EQ(xyz[3 * static_cast<std::size_t>(conn[3 * f + k]) + 2], 3.0);
    }
    EXPECT_EQ(testutil::as<double>(testutil::appended_array(xml, "Name=\"displacement\"")),
              pf[1].values);
}

TEST_F(VtuTet, SeriesOfStepsInAPvd) {
    const fs::path dir = testutil::scratch_dir("mlc_vtu_tet");
    const TetMesh m = structured_box(Vec3(0, 0, 0), Vec3(1, 1, 1), 1, 1, 1);
    std::vector<std::pair<double, std::string>> steps;
    for (int s = 0; s < 3; ++s) {
        Field u{"displacement", 3, std::vector<double>(3 * m.vertices.size(), 0.0)};
        for (std::size_t v = 0; v < m.vertices.size(); ++v)
            u.values[3 * v + 2] = -0.1 * s * m.vertices[v].z();
        const std::string name = "step_" + std::to_string(s) + ".vtu";
        write_vtu(dir / name, m, {u}, {});
        steps.emplace_back(s / 2.0, name);
        EXPECT_EQ(testutil::as<double>(testutil::appended_array(testutil::slurp(dir / name),
                                                                "Name=\"displacement\"")),
                  u.values);
    }
    write_pvd(dir / "series.pvd", steps);
    const std::string pvd = testutil::slurp(dir / "series.pvd");
    std::size_t at = 0;
    for (const auto& [time, name] : steps) {
        at = pvd.find("<DataSet", at);
        ASSERT_NE(at, std::string::npos);
        EXPECT_EQ(std::stod(testutil::xml_attribute(pvd, "timestep", at)), time);
        EXPECT_EQ(testutil::xml_attribute(pvd, "file", at), name);
        EXPECT_TRUE(fs::exists(dir / name));
        ++at;
    }
    EXPECT_EQ(pvd.find("<DataSet", at), std::string::npos);
}

TEST_F(VtuTet, BadInputIsRefusedBeforeAnyFileIsWritten) {
    const fs::path dir = testutil::scratch_dir("mlc_vtu_tet");
    TetMesh m = structured_box(Vec3(0, 0, 0), Vec3(1, 1, 1), 1, 1, 1);
    tmesh::expect_invalid(
        [&] {
            write_vtu(dir / "a.vtu", m, {{"u", 3, {1.0, 2.0}}}, {});
        },
        {"point field 'u' has 2 values", "8 vertexs x 3 components = 24"});
    tmesh::expect_invalid(
        [&] {
            write_vtu(dir / "a.vtu", m, {}, {{"body", 1, std::vector<double>(6, 0.0)}});
        },
        {"cell field 'body' is written by the library"});
    tmesh::expect_invalid(
        [&] {
            write_boundary_vtu(dir / "a.vtu", m, {}, {{"q", 1, {}}});
        },
        {"cell field 'q' has 0 values", "12 boundary faces"});
    Field nan{"phi", 1, std::vector<double>(8, 0.0)};
    nan.values[5] = std::nan("");
    tmesh::expect_invalid([&] { write_vtu(dir / "a.vtu", m, {nan}, {}); },
                          {"non-finite value", "vertex 5"});
    m.cells[4][2] = 8;
    tmesh::expect_invalid([&] { write_vtu(dir / "a.vtu", m, {}, {}); },
                          {"tetrahedron 4 refers to vertex 8", "8 vertices"});
    m.cells[4][2] = 1;
    m.vertices[3].y() = INFINITY;
    tmesh::expect_invalid([&] { write_boundary_vtu(dir / "a.vtu", m, {}); },
                          {"vertex 3 has a non-finite coordinate"});
    EXPECT_TRUE(fs::is_empty(dir));
}
