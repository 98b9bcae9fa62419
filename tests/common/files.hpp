// SPDX-License-Identifier: MIT
/// @file Scratch folders and whole-file reads for the tests that write files.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace mlc::testutil {

/// The running test's own folder under GoogleTest's temporary directory: `prefix`, the test's
/// name and the process id (tests of one executable may run in parallel processes).
inline std::filesystem::path scratch_path(const std::string& prefix) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    return std::filesystem::path(::testing::TempDir()) /
           (prefix + "_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
}

/// scratch_path(prefix), emptied and created.
inline std::filesystem::path scratch_dir(const std::string& prefix) {
    const std::filesystem::path dir = scratch_path(prefix);
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

/// The bytes of a file.
inline std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

/// Value of the first XML attribute `name="..."` after position `from` ("" when there is none).
inline std::string xml_attribute(const std::string& xml, const std::string& name,
                                 std::size_t from = 0) {
    const std::string key = " " + name + "=\"";
    const std::size_t a = xml.find(key, from);
    if (a == std::string::npos) return "";
    const std::size_t b = xml.find('"', a + key.size());
    return xml.substr(a + key.size(), b - a - key.size());
}

} // namespace mlc::testutil
