// SPDX-License-Identifier: MIT
// Files written under a temporary name and renamed when complete.
#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "core/stop.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
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

/// The names in a folder.
std::set<std::string> names(const fs::path& d) {
    std::set<std::string> out;
    for (const auto& e : fs::directory_iterator(d))
        out.insert(e.path().filename().string());
    return out;
}

} // namespace

TEST(AtomicFile, WritesCompleteFileAndNoTemporary) {
    const fs::path d = fresh_dir();
    write_file_atomically(d / "a.csv", [](std::ostream& os) { os << "x,y\n1,2\n"; });
    EXPECT_EQ(slurp(d / "a.csv"), "x,y\n1,2\n");
    EXPECT_EQ(names(d), std::set<std::string>{"a.csv"});
    fs::remove_all(d);
}

TEST(AtomicFile, TemporaryNamesAreUniqueToTheProcessAndTheCall) {
    const fs::path f = fs::path("out") / "a.csv";
    const fs::path t1 = temporary_path(f), t2 = temporary_path(f);
    EXPECT_NE(t1, t2);
    EXPECT_EQ(t1.parent_path(), f.parent_path());
    const std::string pid = "a.csv." + std::to_string(::getpid()) + ".";
    for (const auto& t : {t1, t2}) {
        const std::string n = t.filename().string();
        EXPECT_EQ(n.rfind(pid, 0), 0u) << n;
        EXPECT_TRUE(n.ends_with(".tmp")) << n;
    }
}

TEST(AtomicFile, AStopRequestAbandonsAStoppableWriteOnly) {
    const fs::path d = fresh_dir();
    write_file_atomically(d / "a.csv", [](std::ostream& os) { os << "old\n"; });
    request_stop(15);
    // Not stoppable: the request does not concern writes (a run stopped during its solve writes
    // the files of its completed steps).
    write_file_atomically(d / "b.csv", [](std::ostream& os) { os << "b\n"; });
    EXPECT_EQ(slurp(d / "b.csv"), "b\n");
    set_writes_stoppable(true);
    long rows = 0;
    EXPECT_THROW(write_file_atomically(d / "a.csv",
                                       [&](std::ostream& os) {
                                           for (int i = 0; i < 100000 && os; ++i, ++rows)
                                               os << i << ",0.5\n";
                                       }),
                 Interrupted);
    EXPECT_LT(rows, 2000); // the stream failed within one buffer (8 KiB), not after 100000 rows
    set_writes_stoppable(false);
    clear_stop_request();
    EXPECT_FALSE(stop_requested());
    EXPECT_EQ(slurp(d / "a.csv"), "old\n");
    EXPECT_EQ(names(d), (std::set<std::string>{"a.csv", "b.csv"}));
    fs::remove_all(d);
}

TEST(AtomicFile, RegisteredTemporariesAreRemovedOnRequest) {
    const fs::path d = fresh_dir();
    const fs::path t = temporary_path(d / "v.vtu");
    std::ofstream(t) << "half";
    {
        RegisteredTemporary r(t);
        remove_registered_temporaries();
        EXPECT_FALSE(fs::exists(t));
    }
    std::ofstream(t) << "half";
    remove_registered_temporaries(); // deregistered: left alone
    EXPECT_TRUE(fs::exists(t));
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
    EXPECT_EQ(names(d), std::set<std::string>{"a.csv"});
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
        EXPECT_EQ(names(d).size(), 1u);
        f.close();
        EXPECT_TRUE(f.good());
        EXPECT_EQ(names(d), std::set<std::string>{"s.json"});
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
    EXPECT_EQ(names(d), (std::set<std::string>{"s.json", "t.csv"}));
    fs::remove_all(d);
}
