// SPDX-License-Identifier: MIT
/// @file What the benches share: medians, JSON strings and files, memory, Jacobian sizes.
#pragma once

#include "core/atomic_file.hpp"
#include "levels/level.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace mlc::apps {

/// Peak resident set size of this process, MiB.
double peak_rss_mib();

/// Median of `v` (0 when empty).
double median(std::vector<double> v);

/// `s` as a JSON string (quotes and backslashes escaped).
std::string json_string(const std::string& s);

/// The JSON a bench writes: `given`, or out/bench/<prefix><scene>_L<levels>.json.
std::filesystem::path bench_json_path(const std::string& given, const std::string& prefix,
                                      const std::string& scene, int levels);

/// `file` opened for writing (its folder created), 6 significant digits.
AtomicOfstream open_json(const std::filesystem::path& file);

/// Nonzeros of the Jacobian pattern of a level: K plus the contact tangent entries outside it.
long jacobian_nonzeros(const levels::Level& L);

} // namespace mlc::apps
