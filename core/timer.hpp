// SPDX-License-Identifier: MIT
/// @file Wall-clock timing: a Timings table owned by the driver and RAII ScopedTimer sections.
#pragma once

#include <chrono>
#include <map>
#include <ostream>
#include <string>

namespace mlc {

/// Seconds since an arbitrary epoch (steady clock).
inline double wall_seconds() {
    using namespace std::chrono;
    return duration<double>(steady_clock::now().time_since_epoch()).count();
}

/// Accumulated seconds and call counts per named section. Not thread-safe.
class Timings {
public:
    void add(const std::string& section, double seconds) {
        auto& e = table_[section];
        e.seconds += seconds;
        ++e.calls;
    }
    double seconds(const std::string& section) const {
        auto it = table_.find(section);
        return it == table_.end() ? 0.0 : it->second.seconds;
    }
    /// One section of the table: its accumulated seconds and how often it was timed.
    struct Entry {
        double seconds = 0.0;
        long calls = 0;
    };
    const std::map<std::string, Entry>& table() const { return table_; }
    /// Prints one line per section: name, calls, total seconds.
    void print(std::ostream& os) const;

private:
    std::map<std::string, Entry> table_;
};

/// Adds the lifetime of this object to `timings[section]`. `timings` may be null (no timing).
class ScopedTimer {
public:
    ScopedTimer(Timings* timings, std::string section)
        : timings_(timings), section_(std::move(section)), start_(wall_seconds()) {}
    ~ScopedTimer() {
        if (timings_) timings_->add(section_, wall_seconds() - start_);
    }
    ScopedTimer(const ScopedTimer&) = delete;
    ScopedTimer& operator=(const ScopedTimer&) = delete;

private:
    Timings* timings_;
    std::string section_;
    double start_;
};

} // namespace mlc
