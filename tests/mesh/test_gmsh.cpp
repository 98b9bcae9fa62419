// SPDX-License-Identifier: MIT
// Tests of the Gmsh reader on hand-written 2.2 and 4.1 files, and on every kind of broken file.
#include "core/check.hpp"
#include "mesh/io/gmsh.hpp"
#include "mesh/mesh.hpp"

#include "tests/common/files.hpp"
#include "tests/mesh/measures.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <unistd.h>

using namespace mlc;
using namespace mlc::mesh;
namespace fs = std::filesystem;

namespace {

fs::path data(const std::string& name) {
    return fs::path(MLC_TEST_DATA_DIR) / name;
}

/// Writes `text` to a file in the running test's directory (removed by the fixture).
fs::path scratch_file(const std::string& text, const std::string& name = "mesh.msh") {
    const fs::path dir = testutil::scratch_path("mlc_gmsh");
    fs::create_directories(dir);
    std::ofstream(dir / name) << text;
    return dir / name;
}

/// Replaces the first occurrence of `from` (which must occur) by `to`.
std::string replace(std::string s, const std::string& from, const std::string& to) {
    const std::size_t at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) s.replace(at, from.size(), to);
    return s;
}

/// The boundary edges as (from, to) coordinate pairs with their tag names.
std::set<std::tuple<double, double, double, double, std::string>> boundary_set(const Mesh& m) {
    std::set<std::tuple<double, double, double, double, std::string>> s;
    for (const BoundaryEdge& e : m.boundary) {
        EXPECT_EQ(e.shape, -1);
        const Vec2 a = m.vertices[e.v0], b = m.vertices[e.v1];
        s.insert({a.x(), a.y(), b.x(), b.y(), m.tag_name(e.tag)});
    }
    return s;
}

/// Checks the unit square of square_v22.msh / square_v41.msh.
void expect_unit_square(const Mesh& m) {
    // Node 99 is used by no triangle and is dropped; the others keep the file order.
    ASSERT_EQ(m.n_vertices(), 5);
    EXPECT_EQ(m.vertices[0], Vec2(0, 0));
    EXPECT_EQ(m.vertices[1], Vec2(1, 0));
    EXPECT_EQ(m.vertices[4], Vec2(0.5, 0.5));
    ASSERT_EQ(m.n_cells(), 4);
    for (int t = 0; t < 4; ++t)
        EXPECT_DOUBLE_EQ(m.signed_measure(t), 0.25) << "triangle " << t;
    EXPECT_DOUBLE_EQ(mesh::testing::total_area(m), 1.0);
    // Two clockwise triangles in the file were re-oriented, keeping their first vertex.
    EXPECT_EQ(m.cells[1], (std::array<int, 3>{1, 2, 4}));
    EXPECT_EQ(m.cells[3], (std::array<int, 3>{3, 0, 4}));
    // "top" is listed reversed in the file; the unnamed physical line 7 is "tag7"; the left side
    // has no physical line and is not listed.
    const std::set<std::tuple<double, double, double, double, std::string>> expected = {
        {0, 0, 1, 0, "bottom"}, {1, 0, 1, 1, "tag7"}, {1, 1, 0, 1, "top"}};
    EXPECT_EQ(boundary_set(m), expected);
    EXPECT_EQ(m.tag_names.size(), 3u);
    EXPECT_EQ(m.attribute, (std::vector<int>{3, 3, 3, 3}));
}

/// Expects read_gmsh to throw InvalidInput whose message contains every one of `parts`.
void expect_error(const std::string& text, const std::vector<std::string>& parts,
                  const std::string& surface = "") {
    const fs::path file = scratch_file(text);
    try {
        read_gmsh(file, surface);
        ADD_FAILURE() << "no exception; expected one mentioning '" << parts.front() << "'";
    } catch (const InvalidInput& e) {
        const std::string msg = e.what();
        for (const std::string& p : parts)
            EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
    } catch (const std::exception& e) {
        ADD_FAILURE() << "wrong exception type: " << e.what();
    }
}

} // namespace

class Gmsh : public ::testing::Test {
protected:
    void TearDown() override { fs::remove_all(testutil::scratch_path("mlc_gmsh")); }
};

TEST_F(Gmsh, ReadsFormat22) {
    expect_unit_square(read_gmsh(data("square_v22.msh")));
}

TEST_F(Gmsh, ReadsFormat41) {
    expect_unit_square(read_gmsh(data("square_v41.msh")));
}

TEST_F(Gmsh, SelectsPhysicalSurface) {
    expect_unit_square(read_gmsh(data("square_v22.msh"), "body"));
    expect_unit_square(read_gmsh(data("square_v41.msh"), "body"));

    const Mesh lower = read_gmsh(data("two_bodies_v22.msh"), "lower");
    ASSERT_EQ(lower.n_vertices(), 4);
    ASSERT_EQ(lower.n_cells(), 2);
    EXPECT_DOUBLE_EQ(mesh::testing::total_area(lower), 1.0);
    const std::set<std::tuple<double, double, double, double, std::string>> lower_edges = {
        {0, 0, 1, 0, "bottom"}, {1, 1, 0, 1, "contact_lower"}};
    EXPECT_EQ(boundary_set(lower), lower_edges);

    const Mesh upper = read_gmsh(data("two_bodies_v22.msh"), "upper");
    ASSERT_EQ(upper.n_vertices(), 4);
    ASSERT_EQ(upper.n_cells(), 2);
    EXPECT_DOUBLE_EQ(mesh::testing::total_area(upper), 1.0);
    for (const Vec2& v : upper.vertices)
        EXPECT_GE(v.y(), 1.1);
    const std::set<std::tuple<double, double, double, double, std::string>> upper_edges = {
        {0, 1.1, 1, 1.1, "contact_upper"}, {1, 2.1, 0, 2.1, "top"}};
    EXPECT_EQ(boundary_set(upper), upper_edges);
    for (int t = 0; t < upper.n_cells(); ++t)
        EXPECT_DOUBLE_EQ(upper.signed_measure(t), 0.5);

    // Everything: both bodies, told apart by the attribute.
    const Mesh both = read_gmsh(data("two_bodies_v22.msh"));
    EXPECT_EQ(both.n_vertices(), 8);
    EXPECT_EQ(both.attribute, (std::vector<int>{10, 10, 11, 11}));
    EXPECT_EQ(both.boundary.size(), 4u);
    EXPECT_DOUBLE_EQ(mesh::testing::total_area(both), 2.0);

    expect_error(testutil::slurp(data("two_bodies_v22.msh")),
                 {"no physical surface 'middle'", "'lower'", "'upper'"}, "middle");
    // An unnamed physical surface is selected as "tag<N>".
    const std::string unnamed = replace(testutil::slurp(data("two_bodies_v22.msh")),
                                        "2 11 \"upper\"\n", "2 12 \"other\"\n");
    const Mesh by_tag = read_gmsh(scratch_file(unnamed), "tag11");
    EXPECT_EQ(by_tag.n_cells(), 2);
    EXPECT_GE(by_tag.vertices[0].y(), 1.1);
}

TEST_F(Gmsh, UnsupportedElementsThrowNamingType) {
    const std::string v22 = testutil::slurp(data("square_v22.msh"));
    // A 6-node triangle in the selection.
    expect_error(replace(v22, "9 2 2 3 1 40 50 10", "9 9 2 3 1 40 50 10 10 20 30"),
                 {"mesh.msh:29:", "element type 9", "6-node triangle"});
    // A quadrangle.
    expect_error(replace(v22, "9 2 2 3 1 40 50 10", "9 3 2 3 1 40 50 10 20"),
                 {":29:", "element type 3", "4-node quadrangle"});
    // A tetrahedron when reading everything.
    expect_error(replace(v22, "9 2 2 3 1 40 50 10", "9 4 2 3 1 40 50 10 20"),
                 {"element type 4", "tetrahedron"});
    // ... but elements outside the selected surface are ignored.
    const std::string two = testutil::slurp(data("two_bodies_v22.msh"));
    const std::string quad_upper = replace(two, "8 2 2 11 2 5 8 7", "8 3 2 11 2 5 6 7 8");
    EXPECT_EQ(read_gmsh(scratch_file(quad_upper), "lower").n_cells(), 2);
    expect_error(quad_upper, {"element type 3"}, "upper");
    // An unknown element type.
    expect_error(replace(v22, "1 15 2 0 1 10", "1 999 2 0 1 10"),
                 {":21:", "unknown element type 999"});
}

TEST_F(Gmsh, MalformedFilesThrowNamingLine) {
    const std::string v22 = testutil::slurp(data("square_v22.msh"));
    const std::string v41 = testutil::slurp(data("square_v41.msh"));
    // Truncated inside $Nodes / at the end / inside $Entities.
    expect_error(v22.substr(0, v22.find("40 0 1 0")), {":14:", "unexpected end of file in $Nodes"});
    expect_error(v22.substr(0, v22.find("$EndElements")), {"unexpected end of file"});
    expect_error(v41.substr(0, v41.find("1 0 0 0 1 1 0 1 3")),
                 {"unexpected end of file in $Entities"});
    // Counts that disagree with the data.
    expect_error(replace(v22, "$Nodes\n6\n", "$Nodes\n7\n"), {":18:", "section ends early"});
    expect_error(replace(v22, "$Nodes\n6\n", "$Nodes\n5\n"), {":17:", "expected $EndNodes"});
    expect_error(replace(v22, "$Elements\n9\n", "$Elements\n10\n"), {"section ends early"});
    expect_error(replace(v22, "$Elements\n9\n", "$Elements\n-1\n"), {":20:", "invalid count"});
    expect_error(replace(v41, "3 6 10 99", "3 7 10 99"),
                 {"announces 7 nodes but its blocks hold 6"});
    expect_error(replace(v41, "6 9 1 9", "6 8 1 9"), {"announces 8 elements"});
    expect_error(replace(v41, "2 1 0 4\n", "2 1 0 5\n"), {"one node tag per line"});
    expect_error(replace(v22, "2 1 2 1 1 10 20", "2 1 2 1 1 10 20 30"),
                 {":22:", "needs 2 node ids but the line has 3"});
    // Unknown and duplicate node ids.
    expect_error(replace(v22, "6 2 2 3 1 10 20 50", "6 2 2 3 1 10 20 55"), {":26:", "node id 55"});
    expect_error(replace(v41, "6 10 20 50", "6 10 20 55"), {"node id 55"});
    expect_error(replace(v22, "99 5 5 0", "50 5 5 0"), {":17:", "node id 50 appears twice"});
    // Bad numbers.
    expect_error(replace(v22, "30 1 1 0", "30 1 abc 0"), {":14:", "'abc'"});
    expect_error(replace(v22, "30 1 1 0", "30 1 nan 0"), {":14:", "finite"});
    expect_error(replace(v22, "30 1 1 0", "30.5 1 1 0"), {":14:", "integer"});
    // Header problems.
    expect_error(replace(v22, "2.2 0 8", "2.2 1 8"), {":2:", "binary"});
    expect_error(replace(v22, "2.2 0 8", "4 0 8"), {"unsupported .msh version 4"});
    expect_error(replace(v22, "2.2 0 8", "3.0 0 8"), {"unsupported .msh version 3.0"});
    expect_error(v22.substr(v22.find("$PhysicalNames")), {":1:", "$MeshFormat"});
    expect_error("", {"no $MeshFormat"});
    expect_error("hello\n", {":1:", "expected a section"});
    expect_error(v22.substr(0, v22.find("$Elements")), {"no $Elements section"});
    // Sections.
    expect_error(replace(v22, "$EndNodes\n", ""), {"expected $EndNodes"});
    expect_error(replace(v22, "$EndElements\n", ""),
                 {":29:", "unexpected end of file in $Elements"});
    expect_error(replace(v22, "$Nodes", "$Comments\nsome text\n$Nodes"),
                 {":10:", "$Comments is not closed"});
    expect_error(replace(v22, "1 1 \"bottom\"", "1 1 bottom"), {":6:", "dim tag"});
    // Geometry.
    expect_error(replace(v22, "50 0.5 0.5 0", "50 0.5 0 0"), {":26:", "degenerate triangle"});
    expect_error(replace(v22, "50 0.5 0.5 0", "50 0.5 0.5 0.1"), {":16:", "z = 0.1"});
    std::string moved = v22;
    for (std::size_t at; (at = moved.find(" 2 2 3 1 ")) != std::string::npos;)
        moved.replace(at, 9, " 2 2 5 1 ");
    EXPECT_EQ(read_gmsh(scratch_file(moved)).n_cells(), 4);
    expect_error(moved, {"no 3-node triangles found in physical surface 'body'"}, "body");
    // A file that does not exist.
    EXPECT_THROW(read_gmsh(data("no_such_file.msh")), InvalidInput);
}

TEST_F(Gmsh, SkipsUnknownSectionsAndBlankLines) {
    std::string v41 = testutil::slurp(data("square_v41.msh"));
    v41 = replace(v41, "$Nodes", "$Comments\n$Nodes is not a section here\n$EndComments\n\n$Nodes");
    v41 = replace(v41, "$EndElements\n", "$EndElements\n$NodeData\n1\n\"u\"\n$EndNodeData\n\n");
    // Windows line ends.
    std::string crlf;
    for (char c : v41)
        crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    expect_unit_square(read_gmsh(scratch_file(crlf)));
}
