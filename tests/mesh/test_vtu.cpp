// SPDX-License-Identifier: MIT
// Tests of the .vtu/.pvd writers: parse the XML back and compare sizes, connectivity and values.
#include "core/check.hpp"
#include "core/stop.hpp"
#include "mesh/io/vtu.hpp"
#include "mesh/mesh.hpp"

#include "tests/common/files.hpp"
#include "tests/mesh/vtu_read.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <unistd.h>
#include <zlib.h>

using namespace mlc;
using namespace mlc::mesh;
namespace fs = std::filesystem;

namespace {

/// The names in a folder that are temporaries (written by a writer and not renamed).
std::vector<std::string> temporaries(const fs::path& dir) {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().filename().string().ends_with(".tmp"))
            out.push_back(e.path().filename().string());
    return out;
}

/// Numbers of a DataArray: the one whose opening tag contains `marker` (e.g. Name="u"), or,
/// for a marker that is an element such as "<Points>", the first DataArray inside it.
std::vector<double> data_array(const std::string& xml, const std::string& marker) {
    std::size_t at = xml.find(marker);
    EXPECT_NE(at, std::string::npos) << marker;
    if (at == std::string::npos) return {};
    if (marker.back() == '>') at = xml.find("<DataArray", at);
    const std::size_t begin = xml.find('>', at) + 1;
    const std::size_t end = xml.find("</DataArray>", begin);
    std::istringstream in(xml.substr(begin, end - begin));
    std::vector<double> v;
    for (double x; in >> x;)
        v.push_back(x);
    return v;
}

/// Two triangles of a unit square with coordinates that do not print exactly in decimal.
Mesh small_mesh() {
    Mesh m;
    m.vertices = {Vec2(0.1, 1.0 / 3), Vec2(1e-300, -2.5e17), Vec2(std::sqrt(2.0), std::acos(-1.0)),
                  Vec2(-7.0 / 9, 0)};
    m.cells = {{0, 1, 2}, {0, 2, 3}};
    return m;
}

void expect_close(double expected, double found, const std::string& what) {
    EXPECT_LE(std::abs(found - expected), 1e-15 * std::abs(expected)) << what;
}

} // namespace

class Vtu : public ::testing::Test {
protected:
    void TearDown() override { fs::remove_all(testutil::scratch_path("mlc_vtu")); }
};

TEST_F(Vtu, RoundTripsMeshAndFields) {
    const fs::path file = testutil::scratch_dir("mlc_vtu") / "out.vtu";
    const Mesh m = small_mesh();
    Field u{"displacement", 2, {}};
    for (int i = 0; i < 4; ++i) {
        u.values.push_back(std::sin(i + 1.0) / 3);
        u.values.push_back(1e-20 * (i - 1.5));
    }
    const Field p{"pressure", 1, {std::acos(-1.0), -1.0 / 7}};
    const Field s{"stress <xx>", 3, {1, 2, 3, 4, 5, 6}};
    write_vtu(file, m, {u}, {p, s}, VtuFormat::ascii);
    ASSERT_TRUE(fs::exists(file));
    EXPECT_TRUE(temporaries(file.parent_path()).empty());

    const std::string xml = testutil::slurp(file);
    EXPECT_EQ(xml.rfind("<?xml", 0), 0u);
    EXPECT_NE(xml.find("type=\"UnstructuredGrid\""), std::string::npos);
    EXPECT_EQ(testutil::xml_attribute(xml, "NumberOfPoints"), "4");
    EXPECT_EQ(testutil::xml_attribute(xml, "NumberOfCells"), "2");

    const auto points = data_array(xml, "<Points>");
    ASSERT_EQ(points.size(), 12u);
    for (int v = 0; v < 4; ++v) {
        expect_close(m.vertices[v].x(), points[3 * v], "x of vertex " + std::to_string(v));
        expect_close(m.vertices[v].y(), points[3 * v + 1], "y of vertex " + std::to_string(v));
        EXPECT_EQ(points[3 * v + 2], 0.0);
    }
    EXPECT_EQ(data_array(xml, "Name=\"connectivity\""), (std::vector<double>{0, 1, 2, 0, 2, 3}));
    EXPECT_EQ(data_array(xml, "Name=\"offsets\""), (std::vector<double>{3, 6}));
    EXPECT_EQ(data_array(xml, "Name=\"types\""), (std::vector<double>{5, 5}));

    // The 2-vector is written as a 3-vector with z = 0, inside PointData.
    const std::size_t point_data = xml.find("<PointData>");
    const std::size_t u_at = xml.find("Name=\"displacement\"");
    EXPECT_LT(point_data, u_at);
    EXPECT_LT(u_at, xml.find("</PointData>"));
    EXPECT_EQ(testutil::xml_attribute(xml, "NumberOfComponents", u_at), "3");
    const auto uu = data_array(xml, "Name=\"displacement\"");
    ASSERT_EQ(uu.size(), 12u);
    for (int v = 0; v < 4; ++v) {
        expect_close(u.values[2 * v], uu[3 * v], "u_x");
        expect_close(u.values[2 * v + 1], uu[3 * v + 1], "u_y");
        EXPECT_EQ(uu[3 * v + 2], 0.0);
    }
    // Cell fields inside CellData; the name is XML-escaped.
    const std::size_t p_at = xml.find("Name=\"pressure\"");
    EXPECT_LT(xml.find("<CellData>"), p_at);
    EXPECT_LT(p_at, xml.find("</CellData>"));
    const auto pp = data_array(xml, "Name=\"pressure\"");
    ASSERT_EQ(pp.size(), 2u);
    expect_close(p.values[0], pp[0], "pressure 0");
    expect_close(p.values[1], pp[1], "pressure 1");
    EXPECT_EQ(data_array(xml, "Name=\"stress &lt;xx&gt;\""), s.values);
}

TEST_F(Vtu, BinaryHoldsTheSameArraysBitForBit) {
    const fs::path dir = testutil::scratch_dir("mlc_vtu");
    // Large enough for several 1 MiB compression blocks: 90601 points (2.2 MB of coordinates),
    // 180000 triangles (a 4.3 MB stress field), none a whole number of blocks.
    const Mesh m = structured_rectangle(Vec2(0, 0), Vec2(2, 1), 300, 300);
    const std::size_t nv = m.vertices.size(), nt = m.cells.size();
    Field u{"displacement", 2, {}};
    for (std::size_t v = 0; v < nv; ++v) {
        u.values.push_back(std::sin(1.0 + v) / 3);
        u.values.push_back(1e-300 * v);
    }
    Field s{"stress <xx>", 3, {}};
    for (std::size_t t = 0; t < 3 * nt; ++t)
        s.values.push_back(std::cos(0.1 * t) * 1e5);
    const Field zero{"zero", 1, std::vector<double>(nt, 0.0)};
    write_vtu(dir / "b.vtu", m, {u}, {s, zero});
    write_vtu(dir / "a.vtu", m, {u}, {s, zero}, VtuFormat::ascii);
    EXPECT_TRUE(temporaries(dir).empty());
    const std::string xml = testutil::slurp(dir / "b.vtu");
    EXPECT_NE(xml.find("header_type=\"UInt64\""), std::string::npos);
    EXPECT_NE(xml.find("compressor=\"vtkZLibDataCompressor\""), std::string::npos);
    EXPECT_EQ(testutil::xml_attribute(xml, "NumberOfPoints"), std::to_string(nv));
    EXPECT_EQ(testutil::xml_attribute(xml, "NumberOfCells"), std::to_string(nt));
    EXPECT_LT(fs::file_size(dir / "b.vtu"), fs::file_size(dir / "a.vtu"));

    const auto points = testutil::as<double>(testutil::appended_array(xml, "<Points>"));
    ASSERT_EQ(points.size(), 3 * nv);
    for (std::size_t v = 0; v < nv; v += 37) {
        EXPECT_EQ(points[3 * v], m.vertices[v].x());
        EXPECT_EQ(points[3 * v + 1], m.vertices[v].y());
        EXPECT_EQ(points[3 * v + 2], 0.0);
    }
    const auto uu = testutil::as<double>(testutil::appended_array(xml, "Name=\"displacement\""));
    ASSERT_EQ(uu.size(), 3 * nv);
    for (std::size_t v = 0; v < nv; ++v) {
        ASSERT_EQ(uu[3 * v], u.values[2 * v]) << v;
        ASSERT_EQ(uu[3 * v + 1], u.values[2 * v + 1]) << v;
        ASSERT_EQ(uu[3 * v + 2], 0.0) << v;
    }
    EXPECT_EQ(testutil::as<double>(testutil::appended_array(xml, "Name=\"stress &lt;xx&gt;\"")),
              s.values);
    EXPECT_EQ(testutil::as<double>(testutil::appended_array(xml, "Name=\"zero\"")), zero.values);
    const auto conn =
        testutil::as<std::int32_t>(testutil::appended_array(xml, "Name=\"connectivity\""));
    ASSERT_EQ(conn.size(), 3 * nt);
    for (std::size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k)
            ASSERT_EQ(conn[3 * t + k], m.cells[t][k]);
    const auto offsets =
        testutil::as<std::int64_t>(testutil::appended_array(xml, "Name=\"offsets\""));
    ASSERT_EQ(offsets.size(), nt);
    EXPECT_EQ(offsets.front(), 3);
    EXPECT_EQ(offsets.back(), static_cast<std::int64_t>(3 * nt));
    EXPECT_EQ(testutil::appended_array(xml, "Name=\"types\""), std::vector<unsigned char>(nt, 5));
}

TEST_F(Vtu, NonFiniteValueThrowsAndLeavesNoFile) {
    const fs::path dir = testutil::scratch_dir("mlc_vtu");
    const fs::path file = dir / "bad.vtu";
    const Mesh m = small_mesh();
    Field u{"u", 2, std::vector<double>(8, 1.0)};
    u.values[3] = std::numeric_limits<double>::quiet_NaN(); // vertex 1, component 1
    try {
        write_vtu(file, m, {u}, {});
        ADD_FAILURE() << "NaN accepted";
    } catch (const InvalidInput& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("'u'"), std::string::npos) << msg;
        EXPECT_NE(msg.find("vertex 1, component 1"), std::string::npos) << msg;
    }
    Field c{"damage", 1, {0.5, std::numeric_limits<double>::infinity()}};
    try {
        write_vtu(file, m, {}, {c});
        ADD_FAILURE() << "Inf accepted";
    } catch (const InvalidInput& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("'damage'"), std::string::npos) << msg;
        EXPECT_NE(msg.find("triangle 1"), std::string::npos) << msg;
    }
    Mesh nan_mesh = m;
    nan_mesh.vertices[2].x() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(write_vtu(file, nan_mesh, {}, {}), InvalidInput);
    EXPECT_TRUE(fs::is_empty(dir)) << "a file was left behind";
}

TEST_F(Vtu, InconsistentSizesThrow) {
    const fs::path dir = testutil::scratch_dir("mlc_vtu");
    const fs::path file = dir / "bad.vtu";
    const Mesh m = small_mesh();
    EXPECT_THROW(write_vtu(file, m, {Field{"u", 2, std::vector<double>(7, 0.0)}}, {}),
                 InvalidInput);
    EXPECT_THROW(write_vtu(file, m, {Field{"s", 1, std::vector<double>(2, 0.0)}}, {}),
                 InvalidInput);
    EXPECT_THROW(write_vtu(file, m, {}, {Field{"c", 1, std::vector<double>(4, 0.0)}}),
                 InvalidInput);
    EXPECT_THROW(write_vtu(file, m, {}, {Field{"c", 0, {}}}), InvalidInput);
    EXPECT_THROW(write_vtu(file, m, {}, {Field{"", 1, {1, 2}}}), InvalidInput);
    EXPECT_THROW(write_vtu(file, m, {}, {Field{"c", 1, {1, 2}}, Field{"c", 1, {1, 2}}}),
                 InvalidInput);
    Mesh broken = m;
    broken.cells[1][2] = 4;
    EXPECT_THROW(write_vtu(file, broken, {}, {}), InvalidInput);
    EXPECT_TRUE(fs::is_empty(dir));
    // A directory that does not exist.
    EXPECT_THROW(write_vtu(dir / "missing" / "a.vtu", m, {}, {}), InvalidInput);
}

TEST_F(Vtu, OverwritesAndWritesLargerMeshes) {
    const fs::path file = testutil::scratch_dir("mlc_vtu") / "grid.vtu";
    const Mesh m = structured_rectangle(Vec2(0, 0), Vec2(2, 1), 40, 20);
    write_vtu(file, small_mesh(), {}, {});
    std::vector<double> x(m.vertices.size());
    for (std::size_t v = 0; v < x.size(); ++v)
        x[v] = m.vertices[v].x() * m.vertices[v].y();
    write_vtu(file, m, {Field{"xy", 1, x}}, {}, VtuFormat::ascii);
    const std::string xml = testutil::slurp(file);
    EXPECT_EQ(testutil::xml_attribute(xml, "NumberOfPoints"), std::to_string(41 * 21));
    EXPECT_EQ(testutil::xml_attribute(xml, "NumberOfCells"), std::to_string(2 * 40 * 20));
    const auto conn = data_array(xml, "Name=\"connectivity\"");
    ASSERT_EQ(conn.size(), 3u * m.cells.size());
    for (std::size_t t = 0; t < m.cells.size(); ++t)
        for (int k = 0; k < 3; ++k)
            EXPECT_EQ(conn[3 * t + k], m.cells[t][k]);
    const auto offsets = data_array(xml, "Name=\"offsets\"");
    ASSERT_EQ(offsets.size(), m.cells.size());
    EXPECT_EQ(offsets.back(), 3.0 * m.cells.size());
    EXPECT_EQ(data_array(xml, "Name=\"types\"").size(), m.cells.size());
    const auto xy = data_array(xml, "Name=\"xy\"");
    ASSERT_EQ(xy.size(), x.size());
    for (std::size_t v = 0; v < x.size(); ++v)
        EXPECT_EQ(xy[v], x[v]);
}

TEST_F(Vtu, PvdListsSteps) {
    const fs::path dir = testutil::scratch_dir("mlc_vtu");
    const fs::path file = dir / "series.pvd";
    write_pvd(file, {{0.0, "step_0.vtu"}, {0.25, "step_1.vtu"}, {1.0 / 3, "out/step_2.vtu"}});
    const std::string xml = testutil::slurp(file);
    EXPECT_NE(xml.find("type=\"Collection\""), std::string::npos);
    std::size_t at = 0;
    const std::vector<std::pair<double, std::string>> expected = {
        {0.0, "step_0.vtu"}, {0.25, "step_1.vtu"}, {1.0 / 3, "out/step_2.vtu"}};
    for (const auto& [time, name] : expected) {
        at = xml.find("<DataSet", at);
        ASSERT_NE(at, std::string::npos);
        EXPECT_EQ(std::stod(testutil::xml_attribute(xml, "timestep", at)), time);
        EXPECT_EQ(testutil::xml_attribute(xml, "file", at), name);
        ++at;
    }
    EXPECT_EQ(xml.find("<DataSet", at), std::string::npos);
    EXPECT_THROW(write_pvd(dir / "bad.pvd", {{std::nan(""), "a.vtu"}}), InvalidInput);
    EXPECT_THROW(write_pvd(dir / "bad.pvd", {{1.0, ""}}), InvalidInput);
    EXPECT_FALSE(fs::exists(dir / "bad.pvd"));
}

TEST_F(Vtu, AStopRequestWhileWritesAreStoppableAbandonsTheFile) {
    const fs::path dir = testutil::scratch_dir("mlc_vtu");
    const Mesh m = structured_rectangle(Vec2(0, 0), Vec2(1, 1), 200, 200);
    Field u{"displacement", 2, std::vector<double>(2 * m.vertices.size(), 0.25)};
    write_vtu(dir / "a.vtu", m, {u}, {}, VtuFormat::ascii);
    const std::string before = testutil::slurp(dir / "a.vtu");
    request_stop(2);
    set_writes_stoppable(true);
    for (const auto format : {VtuFormat::ascii, VtuFormat::binary}) {
        EXPECT_THROW(write_vtu(dir / "a.vtu", m, {u}, {}, format), Interrupted);
        EXPECT_THROW(write_vtu(dir / "b.vtu", m, {u}, {}, format), Interrupted);
    }
    set_writes_stoppable(false);
    clear_stop_request();
    EXPECT_EQ(testutil::slurp(dir / "a.vtu"), before); // left as it was
    EXPECT_FALSE(fs::exists(dir / "b.vtu"));
    EXPECT_TRUE(temporaries(dir).empty());
    write_vtu(dir / "b.vtu", m, {u}, {}, VtuFormat::ascii); // no request: written
    EXPECT_EQ(testutil::slurp(dir / "b.vtu"), before);
    fs::remove_all(dir);
}
