// SPDX-License-Identifier: MIT
// What the binding files share: arrays and dictionaries of results, scene lookups, messages.
#include "python/common.hpp"

#include "core/user_message.hpp"

#include <cmath>
#include <cstdlib>
#include <regex>

namespace mlc::python {

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
        d["triangles"] = L.mesh.n_cells();
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

} // namespace mlc::python
