// SPDX-License-Identifier: MIT
#include "tests/common/scene_text.hpp"

#include "core/check.hpp"
#include "scene/scene.hpp"

#include <gtest/gtest.h>

namespace mlc::test {

std::string replace(std::string s, const std::string& from, const std::string& to) {
    const auto pos = s.find(from);
    EXPECT_NE(pos, std::string::npos) << from;
    if (pos != std::string::npos) s.replace(pos, from.size(), to);
    return s;
}

std::string error_of(const std::string& text) {
    try {
        scene::parse_scene(text, "test.toml");
    } catch (const InvalidInput& e) {
        return e.what();
    }
    return "";
}

} // namespace mlc::test
