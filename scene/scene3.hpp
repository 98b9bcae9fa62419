// SPDX-License-Identifier: MIT
/// @file 3D scene files (TOML, `[scene] dimension = 3`) -> levels::ElasticProblem3, validated as
/// strictly as the 2D scenes (scene/scene.hpp): unknown keys, wrong types and out-of-range values
/// are refused with the file, line and key, and a key that only makes sense in 2D with a message
/// saying so. scene::parse_scene refuses them.
///
/// Beside the elastic keys: `[scene] load_steps`, `[newton]` (rel_tol, max_iter, forcing, as in
/// 2D), a Gmsh mesh's curved faces (`surface = [{ tag, type = "sphere", center, radius }, { tag,
/// type = "cylinder", center, axis, radius }]`, mesh::attach_surface), and `[[contact]]` pairs
/// against a rigid obstacle: name, contactor (a boundary face tag), region = { min = [x, y, z],
/// max = [x, y, z] }, mu, r or r_over_E, obstacle = { type = "plane", point, normal } |
/// { type = "sphere", center, radius, side = "outside" | "inside" } | { type = "cylinder",
/// center, axis, radius, side }. A 3D multiplier is a nodal force, so r is a force per length:
/// r_over_E (default 0.1) gives r = r_over_E E h0, E the smallest Young's modulus and h0 the mean
/// length of the level-0 edges of the contactor's faces (levels::mean_face_edge_length). The
/// two-body keys of 2D pairs (target, element, integration, search_radius, match_tolerance) and
/// the 2D obstacles (line, circle) are refused: two-body contact in 3D is not available yet.
///
/// The loading path, with the 2D syntax and meaning (docs/guide/scenes.md#scenes-loading-path): a
/// `[[load]]`'s `factors = [f_1, .., f_K]` and a `[[support]]`'s `ux`, `uy`, `uz` given as lists
/// of values per path point (`ux = [0.0, 1e-3]`) instead of numbers; path point k sits at
/// s = k / K, values are linear in between and 0 at s = 0, a number stays proportional to s.
/// Every list of a scene has the same length K; one that differs is refused at its line
/// (levels::check_path_length's message). A support's `active` (release along the path) is
/// 2D-only and refused.
#pragma once

#include "levels/elastic3d_levels.hpp"

#include <filesystem>
#include <string>

namespace mlc::scene {

/// The dimension a scene text declares: [scene].dimension when it is the integer 3, else 2
/// (also for malformed TOML, which the parsers then report).
int scene_text_dimension(const std::string& text);

/// The dimension of a scene by file path or built-in name (as load_scene finds it); 2 when
/// there is no such scene (load_scene then reports it).
int scene_dimension(const std::string& name_or_path);

/// Parses a 3D scene from TOML text (`origin` and `base_dir` as for parse_scene). Throws
/// InvalidInput with "origin:line: message" on any defect.
levels::ElasticProblem3 parse_scene3(const std::string& text, const std::string& origin,
                                     const std::filesystem::path& base_dir = {});

/// Loads a 3D scene by file path or built-in name (as load_scene).
levels::ElasticProblem3 load_scene3(const std::string& name_or_path);

} // namespace mlc::scene
