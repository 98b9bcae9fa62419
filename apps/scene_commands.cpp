// SPDX-License-Identifier: MIT
// `mlcontact preconditioners`, `mlcontact scenes` and `mlcontact show`.
#include "apps/driver.hpp"

#include "core/check.hpp"
#include "mesh/io/gmsh.hpp"
#include "run/preconditioners.hpp"
#include "scene/scene.hpp"

#include <memory>

namespace mlc::apps {

namespace {

Action add_show(CLI::App& show) {
    struct Args {
        std::string name;
        int msh_level = -1;
    };
    auto a = std::make_shared<Args>();
    show.add_option("name", a->name,
                    "built-in scene name, or a mesh file name such as hertz_gmsh.msh")
        ->required();
    show.add_option("--msh-level", a->msh_level,
                    "print the scene's mesh refined L times as a Gmsh 2.2 file instead "
                    "(`show square --msh-level 4 > square_L4.msh`; a scene reading it recovers "
                    "its levels unless [scene].recover_levels = false)")
        ->check(CLI::NonNegativeNumber);
    return [a](const Launch& at) {
        if (a->msh_level >= 0) {
            // The scene's level-L mesh as a level-0 Gmsh file (its tags as physical curves).
            mesh::Mesh m = scene::load_scene(a->name).mesh0;
            for (int l = 0; l < a->msh_level; ++l)
                m = mesh::refine(m);
            mesh::write_gmsh(m, at.os);
            return 0;
        }
        // A scene, or a mesh file a built-in scene reads (`show hertz_gmsh.msh`).
        std::string t = scene::builtin_scene_text(a->name);
        if (t.empty()) t = scene::builtin_file_text(a->name);
        if (t.empty()) throw InvalidInput("no built-in scene named '" + a->name + "'");
        at.os << t;
        return 0;
    };
}

} // namespace

Command preconditioners_command() {
    return {.name = "preconditioners",
            .usage = "list the preconditioners, their options and what they need",
            .add = [](CLI::App&) -> Action {
                return [](const Launch& at) {
                    print_preconditioners(at.os);
                    return 0;
                };
            }};
}

Command scenes_command() {
    return {.name = "scenes", .usage = "list the built-in scenes", .add = [](CLI::App&) -> Action {
                return [](const Launch& at) {
                    for (const auto& n : scene::builtin_scene_names())
                        at.os << n << "\n";
                    return 0;
                };
            }};
}

Command show_command() {
    return {.name = "show",
            .usage = "print a built-in scene's TOML (or a mesh file it reads)",
            .add = add_show};
}

} // namespace mlc::apps
