// SPDX-License-Identifier: MIT
// mlcontact._core: the library for Python (pybind11). The package python/mlcontact/__init__.py
// re-exports it and adds what is easier in Python (exceptions carrying results, studies' tables,
// tractions along the contact boundary). Arrays of a result are numpy views of the C++ result
// (the Python Result object is their base and keeps it alive), read-only.
#include "apps/output.hpp"
#include "apps/run.hpp"
#include "apps/study_accuracy.hpp"
#include "apps/study_status_transfer.hpp"
#include "core/check.hpp"
#include "core/user_message.hpp"
#include "levels/checks.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <regex>
#include <sstream>

namespace py = pybind11;
using namespace mlc;

namespace {

/// A scene: the problem and where it came from (messages name it).
struct Scene {
    levels::Problem problem;
    std::string origin;
};

/// A run: the problem as solved (with the overrides of solve()) and the library's result.
struct Result {
    levels::Problem problem;
    levels::RunResult run;
};

/// Read-only numpy view of memory owned by `base`'s C++ object.
template <class T>
py::array view(py::handle base, const T* ptr, std::vector<py::ssize_t> shape,
               std::vector<py::ssize_t> strides) {
    py::ssize_t n = 1;
    for (auto s : shape)
        n *= s;
    if (n == 0) return py::array(py::dtype::of<T>(), shape); // nothing to share
    py::array a(py::dtype::of<T>(), std::move(shape), std::move(strides), ptr, base);
    py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
    return a;
}

template <class T> py::array copy_array(const std::vector<T>& v) {
    py::array_t<T> a(static_cast<py::ssize_t>(v.size()));
    std::copy(v.begin(), v.end(), a.mutable_data());
    return a;
}

py::array status_array(const std::vector<contact::Status>& v) {
    py::array_t<uint8_t> a(static_cast<py::ssize_t>(v.size()));
    for (size_t i = 0; i < v.size(); ++i)
        a.mutable_data()[i] = static_cast<uint8_t>(v[i]);
    return a;
}

py::dict counts_dict(const levels::StatusCounts& c) {
    py::dict d;
    d["gap"] = c.gap;
    d["stick"] = c.stick;
    d["slip_forward"] = c.slip_forward;
    d["slip_backward"] = c.slip_backward;
    return d;
}

py::dict step_dict(const levels::StepReport& s) {
    py::dict d;
    d["step"] = s.step;
    d["load_factor"] = s.load_factor;
    d["converged"] = s.converged;
    d["newton_iterations"] = s.iterations;
    d["linear_iterations"] = s.linear_iterations;
    d["linear_iterations_per_newton"] = copy_array(s.linear_iterations_per_newton);
    d["residuals"] = copy_array(s.residuals);
    d["status_changes"] = copy_array(s.status_changes);
    d["statuses"] = counts_dict(s.counts);
    d["seconds"] = s.seconds;
    d["linear_seconds"] = s.linear_seconds;
    d["linear_setup_seconds"] = s.linear_setup_seconds;
    d["inexact_steps"] = s.inexact_steps;
    d["cycling_detected_at"] = s.cycling_detected_at;
    d["damped_steps"] = s.damped_steps;
    d["message"] = s.message;
    return d;
}

py::list level_reports(const Result& r) {
    py::list out;
    for (size_t l = 0; l < r.run.level_steps.size(); ++l) {
        if (r.run.level_steps[l].empty()) continue;
        const levels::Level& L = r.run.levels()[l];
        py::dict d;
        d["level"] = static_cast<int>(l);
        d["unknowns"] = static_cast<long>(L.n_unknowns());
        d["contact_nodes"] = L.n_contact_nodes();
        d["vertices"] = L.mesh.n_vertices();
        d["triangles"] = L.mesh.n_triangles();
        py::list steps;
        for (const auto& st : r.run.level_steps[l]) {
            py::dict s = step_dict(st.report);
            s["predicted"] = st.predicted;
            s["extrapolated"] = st.extrapolated;
            s["agreement"] = st.agreement();
            py::array_t<int> conf({4, 4});
            for (int a = 0; a < 4; ++a)
                for (int b = 0; b < 4; ++b)
                    conf.mutable_at(a, b) =
                        st.confusion[static_cast<size_t>(a)][static_cast<size_t>(b)];
            s["confusion"] = conf;
            s["predicted_statuses"] = status_array(st.predicted_statuses);
            s["final_statuses"] = status_array(st.final_statuses);
            steps.append(s);
        }
        d["steps"] = steps;
        out.append(d);
    }
    return out;
}

/// Sets one field of a scene through a copy that must validate, so that a rejected value leaves
/// the scene as it was. The message names the key.
template <class F> void set_checked(Scene& s, const std::string& key, F&& edit) {
    levels::Problem p = s.problem;
    try {
        edit(p);
        p.validate();
    } catch (const InvalidInput& e) {
        throw InvalidInput(key + ": " + e.what());
    }
    s.problem = std::move(p);
}

double finite_value(const std::string& key, double v) {
    if (!std::isfinite(v))
        throw InvalidInput(key + " must be a finite number, found " + std::to_string(v));
    return v;
}

size_t pair_index(const Scene& s, const py::object& which) {
    const auto& cs = s.problem.contacts;
    if (py::isinstance<py::int_>(which)) {
        const long i = which.cast<long>();
        if (i < 0 || i >= static_cast<long>(cs.size()))
            throw InvalidInput("contact index " + std::to_string(i) +
                               " out of range (the scene has " + std::to_string(cs.size()) +
                               " contact pairs)");
        return static_cast<size_t>(i);
    }
    const std::string name = which.cast<std::string>();
    for (size_t k = 0; k < cs.size(); ++k)
        if (cs[k].name == name) return k;
    throw InvalidInput("no contact pair named '" + name + "'");
}

size_t body_index(const Scene& s, const py::object& which) {
    const auto& bs = s.problem.bodies;
    if (py::isinstance<py::int_>(which)) {
        const long i = which.cast<long>();
        if (i < 0 || i >= static_cast<long>(bs.size()))
            throw InvalidInput("body index " + std::to_string(i) + " out of range (the scene has " +
                               std::to_string(bs.size()) + " bodies)");
        return static_cast<size_t>(i);
    }
    const std::string name = which.cast<std::string>();
    for (size_t k = 0; k < bs.size(); ++k)
        if (bs[k].name == name) return k;
    throw InvalidInput("no body named '" + name + "'");
}

/// One value when every pair has the same, else the list per pair.
py::object per_pair(const levels::Problem& p, double levels::ContactPair::*field) {
    if (p.contacts.empty()) return py::none();
    std::vector<double> v;
    for (const auto& c : p.contacts)
        v.push_back(c.*field);
    for (double x : v)
        if (x != v.front()) return py::cast(v);
    return py::cast(v.front());
}

std::shared_ptr<Result> solve(const Scene& scene, std::optional<int> levels,
                              std::optional<double> mu, std::optional<double> r,
                              std::optional<int> load_steps, std::optional<std::string> linear,
                              std::optional<std::string> krylov, std::optional<std::string> pc,
                              std::optional<double> linear_tol,
                              std::optional<std::string> numbering, bool cold, bool keep_steps,
                              bool progress, bool extrapolate) {
    apps::RunOptions opt;
    opt.levels = levels;
    opt.numbering = numbering;
    opt.mu = mu;
    opt.r = r;
    opt.load_steps = load_steps;
    opt.linear = linear;
    opt.krylov = krylov;
    opt.pc = pc;
    opt.linear_rel_tol = linear_tol;
    opt.cold = cold;
    opt.no_extrapolation = !extrapolate;
    if (linear && *linear != "schur" && *linear != "lu" && *linear != "krylov")
        throw InvalidInput("solver must be schur, lu or krylov, found '" + *linear + "'");
    auto res = std::make_shared<Result>();
    res->problem = scene.problem;
    apps::apply_overrides(res->problem, opt);
    levels::SolverChoice choice;
    levels::SolveOptions so = apps::run_solve_options(res->problem, opt, choice);
    so.keep_step_states = keep_steps;
    // Ctrl-C: Python's handler only sets a flag while the GIL is released; it is run here,
    // between Newton iterations, and its exception (KeyboardInterrupt) re-raised after the solve.
    PyObject *etype = nullptr, *evalue = nullptr, *etrace = nullptr;
    struct PythonObserver final : levels::ProgressLines {
        using ProgressLines::ProgressLines;
        PyObject **type = nullptr, **value = nullptr, **trace = nullptr;
        bool interrupt_requested() override {
            py::gil_scoped_acquire gil;
            if (PyErr_CheckSignals() == 0) return false;
            PyErr_Fetch(type, value, trace);
            return true;
        }
    } observer(progress ? &std::cout : nullptr);
    observer.type = &etype;
    observer.value = &evalue;
    observer.trace = &etrace;
    try {
        py::gil_scoped_release nogil;
        res->run = levels::solve(res->problem, so, &observer);
    } catch (const Interrupted&) {
        if (etype) {
            PyErr_Restore(etype, evalue, etrace);
            throw py::error_already_set();
        }
        throw;
    }
    res->run.solver = choice;
    return res;
}

/// An error message as Python users read it: without the internal check locations
/// (core/user_message.hpp; returned in `locations`) and with the driver's options named as the
/// Python parameters that set them (`--levels 13` -> `levels=13`, `--pc mg` -> `pc='mg'`).
std::string python_message(const std::string& what, std::string* locations) {
    std::string m = user_message(what, locations);
    static const std::vector<std::pair<std::regex, std::string>> names = {
        {std::regex(R"(fewer --levels)"), "a smaller levels="},
        {std::regex(R"(--levels (>=|<=|>|<))"), "levels $1"},
        {std::regex(R"(--levels)"), "levels="},
        {std::regex(R"(--linear-tol)"), "linear_tol="},
        // A value follows the option, or a word of the sentence ("--numbering must be ...").
        {std::regex(R"(--linear (?!(?:must|needs|applies|is|and|or)\b)(\w+))"), "solver='$1'"},
        {std::regex(R"(--linear)"), "solver="},
        {std::regex(
             R"(--(pc|krylov|numbering) (?!(?:must|needs|applies|is|and|or)\b)([A-Za-z][^\s,;)]*))"),
         "$1='$2'"},
        {std::regex(R"(--(pc|krylov|numbering))"), "$1="},
        {std::regex(R"(--steps)"), "load_steps="},
        {std::regex(R"(--mu)"), "mu="},
        {std::regex(R"(--r(?![\w-]))"), "r="},
        {std::regex(R"(--cold)"), "cold=True"},
        {std::regex(R"(--no-extrapolation)"), "extrapolate=False"},
    };
    for (const auto& [re, py] : names)
        m = std::regex_replace(m, re, py);
    return m;
}

/// Raises a Python exception of type `type` with python_message(what); the check locations, if
/// any, go to its attribute `check_location` (and into the message too when the environment
/// variable MLC_CHECK_LOCATIONS is set, for debugging).
void raise_python(PyObject* type, const std::string& what) {
    std::string where;
    std::string msg = python_message(what, &where);
    const char* env = std::getenv("MLC_CHECK_LOCATIONS");
    if (env && *env && !where.empty()) msg += " [" + where + "]";
    PyObject* exc = PyObject_CallFunction(type, "s", msg.c_str());
    if (!exc) return; // the call set its own error
    if (!where.empty()) {
        PyObject* w = PyUnicode_FromString(where.c_str());
        if (w) {
            PyObject_SetAttrString(exc, "check_location", w);
            Py_DECREF(w);
        }
    }
    PyErr_SetObject(type, exc);
    Py_DECREF(exc);
}

/// Parses a scene with Ctrl-C honoured while its domains are meshed: the meshing polls Python's
/// signal handlers (the GIL is held), and their exception (KeyboardInterrupt) is raised.
template <class Parse> levels::Problem parse_honouring_signals(Parse&& parse) {
    PyObject *etype = nullptr, *evalue = nullptr, *etrace = nullptr;
    const scene::StopPoll poll = [&]() {
        if (PyErr_CheckSignals() == 0) return false;
        PyErr_Fetch(&etype, &evalue, &etrace);
        return true;
    };
    try {
        return parse(poll);
    } catch (const Interrupted&) {
        if (etype) {
            PyErr_Restore(etype, evalue, etrace);
            throw py::error_already_set();
        }
        throw;
    }
}

/// Runs a study writing into `out` without the plot; returns (exit code, report text).
template <class F> py::tuple run_study(F&& f) {
    std::ostringstream os;
    int code = 0;
    {
        py::gil_scoped_release nogil;
        code = f(os);
    }
    return py::make_tuple(code, os.str());
}

} // namespace

PYBIND11_MODULE(_core, m) {
    m.doc() = "mlcontact: multilevel frictional contact in 2D linear elasticity (C++ core)";
    m.attr("__version__") = MLC_VERSION;
    m.attr("status_names") = py::make_tuple("gap", "stick", "slip_forward", "slip_backward");

    static py::exception<SolverBreakdown> breakdown(m, "SolverBreakdown", PyExc_RuntimeError);
    static py::exception<Interrupted> interrupted(m, "Interrupted", PyExc_RuntimeError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InvalidInput& e) {
            raise_python(PyExc_ValueError, e.what());
        } catch (const SolverBreakdown& e) {
            raise_python(breakdown.ptr(), e.what());
        } catch (const Interrupted& e) {
            raise_python(interrupted.ptr(), e.what());
        }
    });

    py::class_<Scene, std::shared_ptr<Scene>>(m, "Scene",
                                              "A scene: the problem a TOML scene describes")
        .def_static(
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
            "n_triangles", [](const Scene& s) { return s.problem.mesh0.n_triangles(); },
            "triangles of the level-0 mesh")
        .def_property_readonly(
            "recovered_levels", [](const Scene& s) { return s.problem.recovered_levels; },
            "levels recovered from a Gmsh mesh that is a uniform refinement "
            "([scene].recover_levels): the file's mesh is this level, the level-0 mesh its "
            "coarsest ancestor; 0 otherwise")
        .def_property(
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
            "the contact pairs (copies; set with set_contact)")
        .def_property_readonly(
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
                d["circles"] = static_cast<int>(s.problem.mesh0.circles.size());
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

    py::class_<Result, std::shared_ptr<Result>>(m, "Result", "A solved scene")
        .def_property_readonly(
            "converged", [](const Result& r) { return r.run.converged; },
            "whether every load step converged on every level")
        .def_property_readonly(
            "failure", [](const Result& r) { return r.run.failure; },
            "the diagnosis of the step that did not converge (empty when converged)")
        .def_property_readonly(
            "scene_name", [](const Result& r) { return r.problem.name; },
            "the solved scene's [scene].name")
        .def_property_readonly(
            "level", [](const Result& r) { return static_cast<int>(r.run.levels().size()) - 1; },
            "the finest level solved (0 for the level-0 mesh)")
        .def_property_readonly(
            "unknowns",
            [](const Result& r) { return static_cast<long>(r.run.finest().n_unknowns()); },
            "unknowns of the finest level (free displacement components and multipliers)")
        .def_property_readonly(
            "vertices",
            [](py::object self) {
                const auto& v = self.cast<const Result&>().run.finest().mesh.vertices;
                return view<double>(self, v.empty() ? nullptr : v[0].data(),
                                    {static_cast<py::ssize_t>(v.size()), 2},
                                    {sizeof(Vec2), sizeof(double)});
            },
            "(n, 2) reference positions of the finest level's vertices")
        .def_property_readonly(
            "triangles",
            [](py::object self) {
                const auto& t = self.cast<const Result&>().run.finest().mesh.triangles;
                return view<int>(self, t.empty() ? nullptr : t[0].data(),
                                 {static_cast<py::ssize_t>(t.size()), 3},
                                 {sizeof(t[0]), sizeof(int)});
            },
            "(m, 3) vertex indices of the finest level's triangles")
        .def_property_readonly(
            "displacement",
            [](py::object self) {
                const Vector& u = self.cast<const Result&>().run.u_full;
                return view<double>(self, u.data(), {u.size() / 2, 2},
                                    {2 * sizeof(double), sizeof(double)});
            },
            "(n, 2) final nodal displacements")
        .def_property_readonly(
            "contact_x",
            [](py::object self) {
                const auto& n = self.cast<const Result&>().run.nodes;
                return view<double>(self, n.empty() ? nullptr : n[0].x.data(),
                                    {static_cast<py::ssize_t>(n.size()), 2},
                                    {sizeof(n[0]), sizeof(double)});
            },
            "(k, 2) reference positions of the contact nodes")
        .def_property_readonly(
            "contact_u",
            [](py::object self) {
                const auto& n = self.cast<const Result&>().run.nodes;
                return view<double>(self, n.empty() ? nullptr : n[0].u.data(),
                                    {static_cast<py::ssize_t>(n.size()), 2},
                                    {sizeof(n[0]), sizeof(double)});
            },
            "(k, 2) displacements of the contact nodes")
        .def_property_readonly(
            "lambda_t",
            [](py::object self) {
                const auto& n = self.cast<const Result&>().run.nodes;
                return view<double>(self, n.empty() ? nullptr : &n[0].lambda_t,
                                    {static_cast<py::ssize_t>(n.size())}, {sizeof(n[0])});
            },
            "(k,) tangential multipliers (forces) of the contact nodes")
        .def_property_readonly(
            "lambda_n",
            [](py::object self) {
                const auto& n = self.cast<const Result&>().run.nodes;
                return view<double>(self, n.empty() ? nullptr : &n[0].lambda_n,
                                    {static_cast<py::ssize_t>(n.size())}, {sizeof(n[0])});
            },
            "(k,) normal multipliers (forces; negative in compression)")
        .def_property_readonly(
            "gap",
            [](py::object self) {
                const auto& n = self.cast<const Result&>().run.nodes;
                return view<double>(self, n.empty() ? nullptr : &n[0].d_n,
                                    {static_cast<py::ssize_t>(n.size())}, {sizeof(n[0])});
            },
            "(k,) normal gaps d_n of the contact nodes")
        .def_property_readonly(
            "status",
            [](py::object self) {
                const auto& n = self.cast<const Result&>().run.nodes;
                static_assert(sizeof(contact::Status) == 1);
                return view<uint8_t>(
                    self, n.empty() ? nullptr : reinterpret_cast<const uint8_t*>(&n[0].status),
                    {static_cast<py::ssize_t>(n.size())}, {sizeof(n[0])});
            },
            "(k,) statuses: 0 gap, 1 stick, 2 slip_forward, 3 slip_backward")
        .def_property_readonly(
            "contact_vertex",
            [](py::object self) {
                const auto& n = self.cast<const Result&>().run.nodes;
                return view<int>(self, n.empty() ? nullptr : &n[0].vertex,
                                 {static_cast<py::ssize_t>(n.size())}, {sizeof(n[0])});
            },
            "(k,) vertex index of each contact node")
        .def_property_readonly(
            "contact_pair",
            [](py::object self) {
                const auto& c = self.cast<const Result&>().run.finest().contacts;
                return view<int>(self, c.empty() ? nullptr : &c[0].pair,
                                 {static_cast<py::ssize_t>(c.size())}, {sizeof(c[0])});
            },
            "(k,) contact pair index of each contact node")
        .def_property_readonly(
            "contact_normal",
            [](py::object self) {
                const auto& c = self.cast<const Result&>().run.finest().contacts;
                return view<double>(self, c.empty() ? nullptr : c[0].n.data(),
                                    {static_cast<py::ssize_t>(c.size()), 2},
                                    {sizeof(c[0]), sizeof(double)});
            },
            "(k, 2) unit normal of the target at each contact node")
        .def_property_readonly(
            "contact_tangent",
            [](py::object self) {
                const auto& c = self.cast<const Result&>().run.finest().contacts;
                return view<double>(self, c.empty() ? nullptr : c[0].t.data(),
                                    {static_cast<py::ssize_t>(c.size()), 2},
                                    {sizeof(c[0]), sizeof(double)});
            },
            "(k, 2) unit tangent t = (n_y, -n_x) at each contact node")
        .def_property_readonly(
            "boundary_edges",
            [](const Result& r) {
                const auto& b = r.run.finest().mesh.boundary;
                py::array_t<int> a({static_cast<py::ssize_t>(b.size()), py::ssize_t{2}});
                for (size_t i = 0; i < b.size(); ++i) {
                    a.mutable_at(i, 0) = b[i].v0;
                    a.mutable_at(i, 1) = b[i].v1;
                }
                return a;
            },
            "(e, 2) boundary edges of the finest mesh (a copy)")
        .def_property_readonly("contact_pair_names",
                               [](const Result& r) {
                                   std::vector<std::string> v;
                                   for (const auto& c : r.problem.contacts)
                                       v.push_back(c.name);
                                   return v;
                               },
                               "the contact pairs' names; contact_pair[i] indexes this list")
        .def_property_readonly(
            "resultants",
            [](const Result& r) {
                py::list out;
                for (size_t k = 0; k < r.problem.contacts.size(); ++k) {
                    int closed = 0;
                    const Vec2 f = levels::contact_resultant(r.run, static_cast<int>(k), &closed);
                    py::dict d;
                    d["pair"] = r.problem.contacts[k].name;
                    d["force"] = py::make_tuple(f.x(), f.y());
                    d["nodes_in_contact"] = closed;
                    out.append(d);
                }
                return out;
            },
            "per contact pair: the force the target exerts on the contactor nodes, as the report")
        .def_property_readonly(
            "steps",
            [](const Result& r) {
                py::list out;
                for (const auto& s : r.run.steps)
                    out.append(step_dict(s));
                return out;
            },
            "per load step of the finest level: Newton and Krylov iterations, "
            "residuals, statuses, times")
        .def_property_readonly("levels", &level_reports,
                               "per solved level: sizes and per load step reports with the "
                               "predicted statuses and their confusion table")
        .def_property_readonly(
            "checks",
            [](const Result& r) -> py::object {
                if (!r.run.converged) return py::none();
                const levels::StateChecks c = levels::check_state(r.problem, r.run);
                py::dict d;
                // None when there is no force to balance (StateChecks::force_balance_applicable).
                d["force_balance"] = c.force_balance_applicable
                                         ? py::object(py::float_(c.force_balance))
                                         : py::none();
                d["coulomb_excess"] = c.coulomb_excess;
                d["slip_equality"] = c.slip_equality;
                d["complementarity"] = c.complementarity;
                d["penetration"] = c.penetration;
                d["tension"] = c.tension;
                return d;
            },
            "relative physics checks of the final state (None if not converged; force_balance "
            "None when there is no force to balance)")
        .def_property_readonly(
            "warnings", [](const Result& r) { return r.run.warnings; },
            "what makes the solution doubtful though it converged: a rotation or strain too "
            "large for small-displacement theory, a solution that is not unique (the lines "
            "'warning: ...' of the report)")
        .def_property_readonly("timings",
                               [](const Result& r) {
                                   py::dict d;
                                   for (const auto& [name, e] : r.run.timings.table())
                                       d[py::str(name)] = e.seconds;
                                   return d;
                               },
                               "seconds per timed section of the run (as the report's table)")
        .def_property_readonly("solver",
                               [](const Result& r) {
                                   const auto& sp = r.run.solver.spec;
                                   py::dict d;
                                   d["method"] = sp.method;
                                   d["krylov"] = sp.krylov;
                                   d["pc"] = sp.pc;
                                   d["rel_tol"] = sp.rel_tol;
                                   d["automatic"] = r.run.solver.automatic;
                                   d["numbering"] =
                                       std::string(levels::to_string(r.problem.numbering));
                                   d["reason"] = r.run.solver.reason;
                                   return d;
                               },
                               "the Newton-system solver: method, krylov, pc, rel_tol, "
                               "automatic (chosen by the default), numbering, reason")
        .def(
            "step_state",
            [](const Result& r, int k) {
                const auto& st = r.run.step_nodes;
                // The contact states of every step are always kept, the displacements only with
                // keep_steps: both must hold step k.
                if (r.run.step_u_full.size() < st.size() || st.empty())
                    throw InvalidInput("step_state needs the states of every load step, which "
                                       "this result did not keep: solve it with "
                                       "mlcontact.solve(scene, ..., keep_steps=True)");
                if (k < 1 || k > static_cast<int>(st.size()))
                    throw InvalidInput("step must lie in [1, " + std::to_string(st.size()) +
                                       "] (the load steps completed), found " + std::to_string(k));
                const auto& n = st[static_cast<size_t>(k - 1)];
                const Vector& u = r.run.step_u_full[static_cast<size_t>(k - 1)];
                py::array_t<double> x({static_cast<py::ssize_t>(n.size()), py::ssize_t{2}});
                py::array_t<double> lt(static_cast<py::ssize_t>(n.size())),
                    ln(static_cast<py::ssize_t>(n.size()));
                std::vector<contact::Status> s;
                for (size_t i = 0; i < n.size(); ++i) {
                    x.mutable_at(i, 0) = n[i].x.x();
                    x.mutable_at(i, 1) = n[i].x.y();
                    lt.mutable_at(i) = n[i].lambda_t;
                    ln.mutable_at(i) = n[i].lambda_n;
                    s.push_back(n[i].status);
                }
                py::array_t<double> ua({u.size() / 2, Index{2}});
                std::copy(u.data(), u.data() + u.size(), ua.mutable_data());
                py::dict d;
                d["contact_x"] = x;
                d["lambda_t"] = lt;
                d["lambda_n"] = ln;
                d["status"] = status_array(s);
                d["displacement"] = ua;
                return d;
            },
            py::arg("step"), "State after load step k (1-based; copies), with keep_steps=True")
        .def(
            "accuracy",
            [](const Result& r) {
                py::list out;
                for (const auto& v : apps::accuracy_values(r.problem, r.run)) {
                    py::dict d;
                    d["name"] = v.name;
                    d["value"] = v.value;
                    d["reference"] = v.reference;
                    d["error"] = v.error;
                    d["note"] = v.note;
                    out.append(d);
                }
                return out;
            },
            "closed-form quantities of a benchmark scene (hertz, mindlin, patch; as study "
            "accuracy); mindlin needs keep_steps=True")
        .def(
            "report",
            [](const Result& r) {
                std::ostringstream os;
                apps::print_header(os, r.problem, r.run);
                apps::print_summary(os, r.problem, r.run);
                return os.str();
            },
            "the driver's report (header, per-step table, checks, resultants, timings)")
        .def(
            "write",
            [](const Result& r, const std::string& dir) {
                if (!r.run.converged)
                    throw InvalidInput(
                        "the run did not converge; the driver writes no files either");
                py::gil_scoped_release nogil;
                apps::write_outputs(dir, r.problem, r.run);
            },
            py::arg("folder"), "writes the files `mlcontact run --out folder` writes");

    m.def("solve", &solve, py::arg("scene"), py::arg("levels") = py::none(),
          py::arg("mu") = py::none(), py::arg("r") = py::none(), py::arg("load_steps") = py::none(),
          py::arg("solver") = py::none(), py::arg("krylov") = py::none(),
          py::arg("pc") = py::none(), py::arg("linear_tol") = py::none(),
          py::arg("numbering") = py::none(), py::arg("cold") = false, py::arg("keep_steps") = false,
          py::arg("progress") = false, py::arg("extrapolate") = true);

    m.def(
        "study_status_transfer",
        [](const Scene& s, int levels, const std::string& q_rule, bool increment,
           const std::string& out) {
            if (q_rule != "paper" && q_rule != "conservative")
                throw InvalidInput("q_rule must be paper or conservative, found '" + q_rule + "'");
            apps::StatusTransferOptions o;
            o.levels = levels;
            o.q_rule = q_rule == "paper" ? transfer::QRule::paper : transfer::QRule::conservative;
            o.increment = increment;
            o.out = out;
            o.plot = false;
            return run_study(
                [&](std::ostream& os) { return apps::study_status_transfer(s.problem, o, os); });
        },
        py::arg("scene"), py::arg("levels"), py::arg("q_rule"), py::arg("increment"),
        py::arg("out"));
    m.def(
        "study_accuracy",
        [](const Scene& s, int levels, bool compare, const std::string& out) {
            apps::AccuracyOptions o;
            o.levels = levels;
            o.out = out;
            o.plot = false;
            o.compare_integration = compare;
            return run_study(
                [&](std::ostream& os) { return apps::study_accuracy(s.problem, o, os); });
        },
        py::arg("scene"), py::arg("levels"), py::arg("compare"), py::arg("out"));
}
