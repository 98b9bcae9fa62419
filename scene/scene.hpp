// SPDX-License-Identifier: MIT
/// @file Scene files (TOML) -> levels::Problem, with strict validation: unknown keys, wrong types
/// and out-of-range values are rejected with the file, line and key.
#pragma once

#include "levels/problem.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace mlc::scene {

/// Parses a scene from TOML text. `origin` names the source in messages (a file path or
/// "builtin:square"); relative mesh file paths are resolved against `base_dir`.
/// Throws InvalidInput with "origin:line: message" on any defect.
levels::Problem parse_scene(const std::string& text, const std::string& origin,
                            const std::filesystem::path& base_dir = {});

/// Loads a scene by file path (anything ending in .toml or naming an existing file) or by the
/// name of a built-in scene. Throws InvalidInput for a missing file or an unknown name.
levels::Problem load_scene(const std::string& name_or_path);

/// Names of the built-in scenes (compiled from scenes/*.toml).
std::vector<std::string> builtin_scene_names();

/// TOML text of a built-in scene, or empty if there is none with that name.
std::string builtin_scene_text(const std::string& name);

/// Text of a file the built-in scenes read (scenes/*.msh, by file name, e.g. "hertz_gmsh.msh"),
/// or empty if there is none with that name.
std::string builtin_file_text(const std::string& name);

} // namespace mlc::scene
