// SPDX-License-Identifier: MIT
/// @file Scene files (TOML) -> levels::Problem, with strict validation: unknown keys, wrong types
/// and out-of-range values are rejected with the file, line and key.
#pragma once

#include "levels/problem.hpp"

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace mlc::scene {

/// Polled while a scene's domains are meshed (mesh::mesh_domain, a few milliseconds apart): true
/// stops the meshing, and parse_scene throws mlc::Interrupted. It may also throw itself.
using StopPoll = std::function<bool()>;

/// Parses a scene from TOML text. `origin` names the source in messages (a file path or
/// "builtin:square"); relative mesh file paths are resolved against `base_dir`.
/// Throws InvalidInput with "origin:line: message" on any defect. Before meshing a "domain", its
/// triangles are predicted (mesh::predict_mesh_size) and a mesh that cannot be meshed and solved
/// as one level in the memory this process may use is refused (levels::check_meshing_fits); the
/// meshing polls `stop`.
levels::Problem parse_scene(const std::string& text, const std::string& origin,
                            const std::filesystem::path& base_dir = {}, const StopPoll& stop = {});

/// Loads a scene by file path (anything ending in .toml or naming an existing file) or by the
/// name of a built-in scene. Throws InvalidInput for a missing file or an unknown name. `stop`:
/// as for parse_scene.
levels::Problem load_scene(const std::string& name_or_path, const StopPoll& stop = {});

/// Names of the built-in scenes (compiled from scenes/*.toml).
std::vector<std::string> builtin_scene_names();

/// TOML text of a built-in scene, or empty if there is none with that name.
std::string builtin_scene_text(const std::string& name);

/// Text of a file the built-in scenes read (scenes/*.msh, by file name, e.g. "hertz_gmsh.msh"),
/// or empty if there is none with that name.
std::string builtin_file_text(const std::string& name);

} // namespace mlc::scene
