// SPDX-License-Identifier: MIT
// mlcontact._core.solve and the studies: the run of run/ with Python's Ctrl-C honoured.
#include "python/common.hpp"

#include "run/run.hpp"
#include "studies/accuracy.hpp"
#include "studies/status_transfer.hpp"

#include <iostream>

namespace mlc::python {

namespace {

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
    levels::SolverPlan choice;
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

} // namespace

void bind_run(py::module_& m) {
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

} // namespace mlc::python
