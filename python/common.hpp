// SPDX-License-Identifier: MIT
/// @file What the binding files of mlcontact._core share: the Scene and Result objects, numpy
/// views and copies, the error messages as Python users read them.
#pragma once

#include "core/check.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <sstream>
#include <string>

namespace py = pybind11;

namespace mlc::python {

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

py::array status_array(const std::vector<contact::Status>& v);
py::dict counts_dict(const levels::StatusCounts& c);
py::dict step_dict(const levels::StepReport& s);
py::list level_reports(const Result& r);

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

double finite_value(const std::string& key, double v);
size_t pair_index(const Scene& s, const py::object& which);
size_t body_index(const Scene& s, const py::object& which);
/// One value when every pair has the same, else the list per pair.
py::object per_pair(const levels::Problem& p, double levels::ContactPair::*field);

/// An error message as Python users read it: without the internal check locations
/// (core/user_message.hpp; returned in `locations`) and with the driver's options named as the
/// Python parameters that set them (`--levels 13` -> `levels=13`, `--pc mg` -> `pc='mg'`).
std::string python_message(const std::string& what, std::string* locations);

/// Raises a Python exception of type `type` with python_message(what); the check locations, if
/// any, go to its attribute `check_location` (and into the message too when the environment
/// variable MLC_CHECK_LOCATIONS is set, for debugging).
void raise_python(PyObject* type, const std::string& what);

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

using SceneClass = py::class_<Scene, std::shared_ptr<Scene>>;
using ResultClass = py::class_<Result, std::shared_ptr<Result>>;

/// The class Scene.
void bind_scene(py::module_& m);
/// The class Result.
void bind_result(py::module_& m);
/// solve() and the studies.
void bind_run(py::module_& m);
/// The class TetMesh and write_pvd.
void bind_tet_mesh(py::module_& m);

} // namespace mlc::python
