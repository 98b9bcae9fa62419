// SPDX-License-Identifier: MIT
// mlcontact._core.Scene: a scene from a built-in name, a file or TOML text; its settings.
#include "python/common.hpp"

#include <filesystem>
#include <fstream>

namespace mlc::python {

namespace {

// Where a scene comes from, copies, and what it is.
void bind_scene_sources(SceneClass& cls) {
    cls.def_static(
           "builtin",
           [](const std::string& name) {
               const std::string text = scene::builtin_scene_text(name);
               if (text.empty()) {
                   std::string list;
                   for (const auto& n : scene::builtin_scene_names())
                       list += (list.empty() ? "" : ", ") + n;
                   throw InvalidInput("no built-in scene named '" + name + "' (built-in: " + list +
                                      ")");
               }
               return std::make_shared<Scene>(Scene{scene::load_scene(name), "builtin:" + name});
           },
           py::arg("name"), "A built-in scene (Scene.builtin_names())")
        .def_static(
            "from_file",
            [](const std::string& path) {
                // As scene::load_scene reads a file (never a built-in name).
                const std::filesystem::path fp(path);
                if (!std::filesystem::exists(fp))
                    throw InvalidInput("cannot open scene file '" + path + "': no such file");
                if (!std::filesystem::is_regular_file(fp))
                    throw InvalidInput("scene file '" + path + "' is not a regular file");
                std::ifstream f(fp);
                if (!f) throw InvalidInput("cannot open scene file '" + path + "'");
                std::ostringstream text;
                text << f.rdbuf();
                return std::make_shared<Scene>(Scene{
                    parse_honouring_signals([&](const scene::StopPoll& poll) {
                        return scene::parse_scene(text.str(), fp.string(), fp.parent_path(), poll);
                    }),
                    path});
            },
            py::arg("path"),
            "A scene file (TOML); errors name the file and line. Ctrl-C while its domains are "
            "meshed raises KeyboardInterrupt")
        .def_static(
            "from_toml",
            [](const std::string& text, const std::string& origin, const std::string& base_dir) {
                return std::make_shared<Scene>(
                    Scene{parse_honouring_signals([&](const scene::StopPoll& poll) {
                              return scene::parse_scene(text, origin, base_dir, poll);
                          }),
                          origin});
            },
            py::arg("text"), py::arg("origin") = "<string>", py::arg("base_dir") = "",
            "A scene from TOML text; relative mesh files resolve against base_dir")
        .def_static("builtin_names", &scene::builtin_scene_names,
                    "The names of the built-in scenes (as `mlcontact scenes` lists them)")
        .def(
            "copy", [](const Scene& s) { return std::make_shared<Scene>(s); },
            "An independent copy of the scene (copy.copy and copy.deepcopy give the same)")
        .def("__copy__", [](const Scene& s) { return std::make_shared<Scene>(s); })
        .def("__deepcopy__", [](const Scene& s, py::dict) { return std::make_shared<Scene>(s); })
        .def_property_readonly(
            "origin", [](const Scene& s) { return s.origin; },
            "where the scene came from: builtin:NAME, a file path or the from_toml origin")
        .def_property_readonly(
            "name", [](const Scene& s) { return s.problem.name; }, "[scene].name")
        .def_property_readonly(
            "description", [](const Scene& s) { return s.problem.description; },
            "[scene].description (empty if not given)")
        .def_property_readonly(
            "units", [](const Scene& s) { return s.problem.units; },
            "[scene].units, free text (the code is unit-free)")
        .def_property_readonly(
            "n_vertices", [](const Scene& s) { return s.problem.mesh0.n_vertices(); },
            "vertices of the level-0 mesh")
        .def_property_readonly(
            "n_triangles", [](const Scene& s) { return s.problem.mesh0.n_cells(); },
            "triangles of the level-0 mesh")
        .def_property_readonly(
            "recovered_levels", [](const Scene& s) { return s.problem.recovered_levels; },
            "levels recovered from a Gmsh mesh that is a uniform refinement "
            "([scene].recover_levels): the file's mesh is this level, the level-0 mesh its "
            "coarsest ancestor; 0 otherwise");
}

// The settings of a scene that can be set.
void bind_scene_settings(SceneClass& cls) {
    cls.def_property(
           "levels", [](const Scene& s) { return s.problem.levels - s.problem.recovered_levels; },
           [](Scene& s, int v) {
               const int k = s.problem.recovered_levels;
               if (v < 0 || v > 12 - k)
                   throw InvalidInput("levels: [scene].levels must lie in [0, " +
                                      std::to_string(12 - k) + "], found " + std::to_string(v));
               set_checked(s, "levels", [&](levels::Problem& p) { p.levels = k + v; });
           },
           "number of 1->4 refinements of the scene's mesh ([scene].levels, 0..12; of the "
           "file's mesh when its levels were recovered, see recovered_levels)")
        .def_property(
            "load_steps", [](const Scene& s) { return s.problem.load_steps; },
            [](Scene& s, int v) {
                if (v < 1)
                    throw InvalidInput("load_steps: [scene].load_steps must be at least 1, found " +
                                       std::to_string(v));
                set_checked(s, "load_steps", [&](levels::Problem& p) { p.load_steps = v; });
            },
            "number of load steps ([scene].load_steps, >= 1)")
        .def_property(
            "mu", [](const Scene& s) { return per_pair(s.problem, &levels::ContactPair::mu); },
            [](Scene& s, double v) {
                finite_value("mu", v);
                if (v < 0)
                    throw InvalidInput("mu: friction coefficient mu must be >= 0, found " +
                                       std::to_string(v));
                set_checked(s, "mu", [&](levels::Problem& p) {
                    for (auto& c : p.contacts)
                        c.mu = v;
                });
            },
            "friction coefficient of every contact pair (a list when they differ)")
        .def_property(
            "r", [](const Scene& s) { return per_pair(s.problem, &levels::ContactPair::r); },
            [](Scene& s, double v) {
                finite_value("r", v);
                if (!(v > 0))
                    throw InvalidInput("r: augmentation parameter r must be > 0, found " +
                                       std::to_string(v));
                set_checked(s, "r", [&](levels::Problem& p) {
                    for (auto& c : p.contacts)
                        c.r = v;
                });
            },
            "augmentation parameter of every contact pair (a list when they differ)")
        .def_property(
            "newton_tol", [](const Scene& s) { return s.problem.newton.rel_tol; },
            [](Scene& s, double v) {
                finite_value("newton_tol", v);
                set_checked(s, "newton_tol", [&](levels::Problem& p) { p.newton.rel_tol = v; });
            },
            "relative Newton tolerance ([newton].rel_tol)")
        .def_property(
            "newton_max_iter", [](const Scene& s) { return s.problem.newton.max_iter; },
            [](Scene& s, int v) {
                set_checked(s, "newton_max_iter",
                            [&](levels::Problem& p) { p.newton.max_iter = v; });
            },
            "Newton iterations per load step ([newton].max_iter)")
        .def_property_readonly(
            "contacts",
            [](const Scene& s) {
                py::list out;
                for (const auto& c : s.problem.contacts) {
                    py::dict d;
                    d["name"] = c.name;
                    d["contactor"] = c.contactor;
                    d["target"] = c.target;
                    d["element"] = std::string(levels::to_string(c.element));
                    d["mu"] = c.mu;
                    d["r"] = c.r;
                    out.append(d);
                }
                return out;
            },
            "the contact pairs (copies; set with set_contact)");
}

// Its supports, tags and materials, and the edits of one pair or body.
void bind_scene_parts(SceneClass& cls) {
    cls.def_property_readonly(
           "supports",
           [](const Scene& s) {
               py::list out;
               for (const auto& sp : s.problem.supports) {
                   py::dict d;
                   d["tag"] = sp.tag;
                   d["point"] = sp.point ? py::object(py::make_tuple(sp.point->x(), sp.point->y()))
                                         : py::object(py::none());
                   for (int c = 0; c < 2; ++c) {
                       const auto& full = c == 0 ? sp.ux : sp.uy;
                       const auto& path = c == 0 ? sp.ux_path : sp.uy_path;
                       const char* key = c == 0 ? "ux" : "uy";
                       if (!full)
                           d[key] = py::none();
                       else if (path.empty())
                           d[key] = *full;
                       else
                           d[key] = path;
                   }
                   py::list active;
                   for (int k = 1; k <= s.problem.load_steps; ++k)
                       active.append(s.problem.support_active(sp, k));
                   d["active"] = active;
                   out.append(d);
               }
               return out;
           },
           "the supports (copies): tag or point, ux, uy (a number, a list per path point or "
           "None) and active, whether it holds in each load step ([[support]].active)")
        .def_property_readonly(
            "mesh_tags",
            [](const Scene& s) {
                py::dict d;
                d["vertices"] = s.problem.mesh0.n_vertices();
                d["boundary_tags"] = [&] {
                    py::list l;
                    for (const auto& [n, id] : s.problem.mesh0.tag_names)
                        if (s.problem.mesh0.is_boundary_tag(id)) l.append(n);
                    return l;
                }();
                d["line_tags"] = [&] {
                    py::list l;
                    for (const auto& [n, id] : s.problem.mesh0.tag_names)
                        for (const auto& e : s.problem.mesh0.lines)
                            if (e.tag == id) {
                                l.append(n);
                                break;
                            }
                    return l;
                }();
                d["circles"] = static_cast<int>(s.problem.mesh0.shapes.size());
                return d;
            },
            "the level-0 mesh's tags: boundary_tags, line_tags (tagged interior lines: mirror "
            "lines, Gmsh physical lines inside a body, a domain's lines) and the number of "
            "circles (arc segments and Gmsh arcs) refinement keeps vertices on")
        .def_property_readonly(
            "materials",
            [](const Scene& s) {
                py::list out;
                for (const auto& b : s.problem.bodies) {
                    py::dict d;
                    d["name"] = b.name;
                    d["E"] = b.material.E;
                    d["nu"] = b.material.nu;
                    d["plane"] = b.material.plane == fem::Plane::strain ? "strain" : "stress";
                    out.append(d);
                }
                return out;
            },
            "the bodies' materials (copies; set with set_material)")
        .def(
            "set_contact",
            [](Scene& s, const py::object& which, std::optional<double> mu,
               std::optional<double> r) {
                const size_t k = pair_index(s, which);
                const std::string w = "contact '" + s.problem.contacts[k].name + "'";
                if (mu) {
                    finite_value(w + " mu", *mu);
                    if (*mu < 0)
                        throw InvalidInput("mu: " + w +
                                           ": friction coefficient mu must be >= 0, found " +
                                           std::to_string(*mu));
                }
                if (r) {
                    finite_value(w + " r", *r);
                    if (!(*r > 0))
                        throw InvalidInput("r: " + w +
                                           ": augmentation parameter r must be > 0, found " +
                                           std::to_string(*r));
                }
                set_checked(s, mu ? "mu" : "r", [&](levels::Problem& p) {
                    if (mu) p.contacts[k].mu = *mu;
                    if (r) p.contacts[k].r = *r;
                });
            },
            py::arg("pair"), py::arg("mu") = py::none(), py::arg("r") = py::none(),
            "Sets mu and/or r of one contact pair (by index or name)")
        .def(
            "set_material",
            [](Scene& s, const py::object& which, std::optional<double> E,
               std::optional<double> nu) {
                const size_t k = body_index(s, which);
                set_checked(s, E ? "E" : "nu", [&](levels::Problem& p) {
                    auto& mat = p.bodies[k].material;
                    if (E) mat.E = *E;
                    if (nu) mat.nu = *nu;
                    mat.validate();
                });
            },
            py::arg("body"), py::arg("E") = py::none(), py::arg("nu") = py::none(),
            "Sets Young's modulus and/or Poisson's ratio of one body (by index or name)")
        .def("__repr__", [](const Scene& s) {
            const int k = s.problem.recovered_levels;
            return "<mlcontact.Scene '" + s.problem.name + "' from " + s.origin + ", levels " +
                   std::to_string(s.problem.levels - k) +
                   (k > 0 ? " (on " + std::to_string(k) + " recovered)" : std::string()) + ", " +
                   std::to_string(s.problem.load_steps) + " load steps>";
        });
}

} // namespace

void bind_scene(py::module_& m) {
    SceneClass c(m, "Scene", "A scene: the problem a TOML scene describes");
    bind_scene_sources(c);
    bind_scene_settings(c);
    bind_scene_parts(c);
}

} // namespace mlc::python
