// SPDX-License-Identifier: MIT
// Scene parsing: every bad input of the foundation issue gets an InvalidInput naming it.
#include "core/check.hpp"
#include "scene/scene.hpp"
#include "tests/common/scene_text.hpp"

#include <gtest/gtest.h>
#include <regex>

using namespace mlc;

namespace {

std::string square_text() {
    return scene::builtin_scene_text("square");
}

using test::error_of;
using test::replace;

} // namespace

TEST(Scene, BuiltinSquareParses) {
    const auto p = scene::load_scene("square");
    EXPECT_EQ(p.name, "square");
    EXPECT_EQ(p.load_steps, 5);
    ASSERT_EQ(p.contacts.size(), 1u);
    EXPECT_DOUBLE_EQ(p.contacts[0].mu, 1.0);
    EXPECT_DOUBLE_EQ(p.contacts[0].r, 1.3e4);
    EXPECT_EQ(p.mesh0.n_cells(), 512);
}

TEST(Scene, UnknownKeyIsNamedWithItsLine) {
    const auto msg = error_of(replace(square_text(), "nu = 0.2", "nu = 0.2\nyoung = 3"));
    EXPECT_NE(msg.find("unknown key 'young'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("test.toml:"), std::string::npos) << msg;
}

TEST(Scene, MalformedTomlIsRejected) {
    const auto msg = error_of("[scene\nname = 1");
    EXPECT_NE(msg.find("malformed TOML"), std::string::npos) << msg;
}

TEST(Scene, WrongTypeIsRejected) {
    const auto msg = error_of(replace(square_text(), "E = 1.3e5", "E = \"stiff\""));
    EXPECT_NE(msg.find("must be a number"), std::string::npos) << msg;
}

TEST(Scene, NonPositiveYoungModulusIsRejected) {
    for (const char* bad : {"E = 0.0", "E = -1.3e5"}) {
        const auto msg = error_of(replace(square_text(), "E = 1.3e5", bad));
        EXPECT_NE(msg.find("Young's modulus E must be positive"), std::string::npos) << msg;
    }
}

TEST(Scene, PoissonRatioOutOfRangeIsRejected) {
    for (const char* bad : {"nu = 0.5", "nu = -1.0", "nu = 0.7"}) {
        const auto msg = error_of(replace(square_text(), "nu = 0.2", bad));
        EXPECT_NE(msg.find("Poisson's ratio nu must lie in (-1, 0.5)"), std::string::npos) << msg;
    }
}

TEST(Scene, NegativeFrictionIsRejected) {
    const auto msg = error_of(replace(square_text(), "mu = 1.0", "mu = -0.1"));
    EXPECT_NE(msg.find("mu must be >= 0"), std::string::npos) << msg;
}

TEST(Scene, NonPositiveAugmentationIsRejected) {
    for (const char* bad : {"r_over_E = 0.0", "r_over_E = -2.0"}) {
        const auto msg = error_of(replace(square_text(), "r_over_E = 0.1", bad));
        EXPECT_NE(msg.find("augmentation parameter r must be > 0"), std::string::npos) << msg;
    }
    const auto msg = error_of(replace(square_text(), "r_over_E = 0.1", "r = 0"));
    EXPECT_NE(msg.find("augmentation parameter r must be > 0"), std::string::npos) << msg;
}

TEST(Scene, LoadStepCountBelowOneIsRejected) {
    const auto msg = error_of(replace(square_text(), "load_steps = 5", "load_steps = 0"));
    EXPECT_NE(msg.find("load_steps must be at least 1"), std::string::npos) << msg;
}

TEST(Scene, DegenerateMeshIsRejected) {
    const auto msg = error_of(replace(square_text(), "size = [40.0, 40.0]", "size = [40.0, 0.0]"));
    EXPECT_NE(msg.find("positive size"), std::string::npos) << msg;
}

TEST(Scene, UnknownTagIsRejected) {
    const auto msg = error_of(replace(square_text(), "tag = \"top\"", "tag = \"roof\""));
    EXPECT_NE(msg.find("unknown boundary tag 'roof'"), std::string::npos) << msg;
}

TEST(Scene, MissingFileAndUnknownBuiltinAreRejected) {
    EXPECT_THROW(scene::load_scene("/nonexistent/scene.toml"), InvalidInput);
    EXPECT_THROW(scene::load_scene("no_such_scene"), InvalidInput);
}
