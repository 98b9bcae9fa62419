// SPDX-License-Identifier: MIT
// Hostile input: inputs that once crashed, hung or invoked undefined behaviour in the
// mesh code (found while fuzzing with tests/fuzz, or by review) now get an InvalidInput, or are
// checked in reasonable time when they are valid.
#include "core/check.hpp"
#include "mesh/io/gmsh.hpp"
#include "mesh/mesh.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

using namespace mlc;

// Found by review of the fuzz budget: divisions = [100000, 100000] passes the scene parser's
// per-direction limit, and (nx + 1) * (ny + 1) overflowed int (UBSan: "signed integer overflow:
// 100001 * 100001"), followed by a reserve of the wrapped count.
TEST(StructuredRectangle, CountsBeyondIntIndicesAreRejectedBeforeAllocating) {
    const Vec2 o(0, 0), s(1, 1);
    EXPECT_THROW(mesh::structured_rectangle(o, s, 100000, 100000), InvalidInput);
    // 2 * 46341^2 triangles > 2^31 - 1 although (46341 + 1)^2 vertices < 2^31 - 1.
    EXPECT_THROW(mesh::structured_rectangle(o, s, 46341, 46341), InvalidInput);
    EXPECT_THROW(mesh::structured_rectangle(o, s, 1, std::numeric_limits<int>::max()),
                 InvalidInput);
    try {
        mesh::structured_rectangle(o, s, 100000, 100000);
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("100000 x 100000 squares"), std::string::npos)
            << e.what();
    }
}

// Found while bounding the scene fuzz target: a scene may name any file as its Gmsh mesh, and
// read_gmsh read a character device such as /dev/zero into memory until the allocation failed
// (std::bad_alloc, or the OOM killer) instead of rejecting it; a FIFO would block.
TEST(GmshHostile, NonRegularFilesAreRejected) {
    EXPECT_THROW(mesh::read_gmsh("/dev/zero"), InvalidInput);
    EXPECT_THROW(mesh::read_gmsh("/dev/null"), InvalidInput);
    EXPECT_THROW(mesh::read_gmsh(MLC_TEST_DATA_DIR), InvalidInput); // a directory
    try {
        mesh::read_gmsh("/dev/zero");
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
    }
}

// Found while bounding the scene fuzz target: the duplicate-vertex check of check_quality sorted
// the vertices by x and compared every pair within tol in x, which is quadratic in the number of
// vertices sharing an x. A valid scene with divisions = [1, 100000] (a thin strip) spent 35 s
// there (Release; minutes under ASan), and every level of a structured mesh paid n^1.5.
// The bound is 40 times the check's Release time and 5 times its time under AddressSanitizer
// beside other tests; the quadratic check took 35 s in Release and minutes under ASan.
#if defined(__SANITIZE_ADDRESS__)
constexpr double kCheckQualitySeconds = 60.0;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr double kCheckQualitySeconds = 60.0;
#else
constexpr double kCheckQualitySeconds = 10.0;
#endif
#else
constexpr double kCheckQualitySeconds = 10.0;
#endif

TEST(CheckQuality, ColumnsOfVerticesSharingAnXAreChecked_Fast) {
    const auto strip = mesh::structured_rectangle(Vec2(0, 0), Vec2(0.01, 1000), 1, 100000);
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_NO_THROW(mesh::check_quality(strip));
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_LT(seconds, kCheckQualitySeconds);
}

TEST(CheckQuality, EveryPairCloserThanTheToleranceIsADuplicate) {
    const auto m = mesh::structured_rectangle(Vec2(0, 0), Vec2(1, 1), 2, 2);
    const double tol = 1e-10 * std::sqrt(2.0);
    // Near vertex 4 = (0.5, 0.5), in a triangle with vertices 0 and 2 (positive area), at offsets
    // in every direction, so that some pairs straddle the cells of the check.
    for (int k = 0; k < 16; ++k) {
        const double angle = 2 * std::numbers::pi * k / 16;
        const Vec2 dir(std::cos(angle), std::sin(angle));
        for (const double r : {0.0, 0.3 * tol, 0.9 * tol}) {
            auto dup = m;
            dup.vertices.push_back(m.vertices[4] + r * dir);
            dup.cells.push_back({0, 2, dup.n_vertices() - 1});
            try {
                mesh::check_quality(dup);
                ADD_FAILURE() << "no duplicate found at distance " << r << " in direction " << k;
            } catch (const InvalidInput& e) {
                EXPECT_NE(std::string(e.what()).find("duplicate vertices 4 and 9"),
                          std::string::npos)
                    << e.what();
            }
        }
        // Farther than the tolerance: no duplicate. The added triangle overlaps the mesh, with
        // vertex 1 = (0.5, 0) inside its edge (0, 2), which the topology check (after the
        // duplicate-vertex one) refuses as a hanging node.
        auto apart = m;
        apart.vertices.push_back(m.vertices[4] + 3 * tol * dir);
        apart.cells.push_back({0, 2, apart.n_vertices() - 1});
        try {
            mesh::check_quality(apart);
            ADD_FAILURE() << "the overlapping triangle was accepted in direction " << k;
        } catch (const InvalidInput& e) {
            EXPECT_NE(std::string(e.what()).find("hanging node (T-junction): vertex 1 (0.5, 0)"),
                      std::string::npos)
                << "direction " << k << ": " << e.what();
        }
    }
}
