// SPDX-License-Identifier: MIT
// Files written under a temporary name and renamed when complete.
#include "core/atomic_file.hpp"
#include "core/check.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace mlc;

namespace {

fs::path fresh_dir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    const fs::path d = fs::path(::testing::TempDir()) / ("mlc_atomic_" + std::string(info->name()) +
                                                         "_" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

std::string slurp(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

} // namespace

TEST(AtomicFile, WritesCompleteFileAndNoTemporary) {
    const fs::path d = fresh_dir();
    write_file_atomically(d / "a.csv", [](std::ostream& os) { os << "x,y\n1,2\n"; });
    EXPECT_EQ(slurp(d / "a.csv"), "x,y\n1,2\n");
    EXPECT_FALSE(fs::exists(temporary_path(d / "a.csv")));
    EXPECT_EQ(temporary_path(d / "a.csv"), d / "a.csv.tmp");
    fs::remove_all(d);
}

TEST(AtomicFile, FailingWriterLeavesTheOldFile) {
    const fs::path d = fresh_dir();
    write_file_atomically(d / "a.csv", [](std::ostream& os) { os << "old\n"; });
    EXPECT_THROW(write_file_atomically(d / "a.csv",
                                       [](std::ostream& os) {
                                           os << "half";
                                           throw std::runtime_error("interrupted");
                                       }),
                 std::runtime_error);
    EXPECT_EQ(slurp(d / "a.csv"), "old\n");
    EXPECT_FALSE(fs::exists(d / "a.csv.tmp"));
    EXPECT_THROW(write_file_atomically(d / "missing" / "b.csv", [](std::ostream&) {}),
                 InvalidInput);
    fs::remove_all(d);
}

TEST(AtomicFile, StreamRenamesOnCloseAndDropsOnException) {
    const fs::path d = fresh_dir();
    {
        AtomicOfstream f(d / "s.json");
        f << "{\"a\": 1}";
        EXPECT_FALSE(fs::exists(d / "s.json")); // not before it is complete
        EXPECT_TRUE(fs::exists(d / "s.json.tmp"));
        f.close();
        EXPECT_TRUE(f.good());
        EXPECT_FALSE(fs::exists(d / "s.json.tmp"));
    }
    EXPECT_EQ(slurp(d / "s.json"), "{\"a\": 1}");
    { // closed by the destructor at the end of a normal scope
        AtomicOfstream f(d / "t.csv");
        f << "t\n";
    }
    EXPECT_EQ(slurp(d / "t.csv"), "t\n");
    try {
        AtomicOfstream f(d / "s.json");
        f << "{\"a\": ";
        throw std::runtime_error("stop");
    } catch (const std::runtime_error&) {
    }
    EXPECT_EQ(slurp(d / "s.json"), "{\"a\": 1}");
    EXPECT_FALSE(fs::exists(d / "s.json.tmp"));
    fs::remove_all(d);
}
