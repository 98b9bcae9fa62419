// SPDX-License-Identifier: MIT
// mlcontact._core: the library for Python (pybind11). The package python/mlcontact/__init__.py
// re-exports it and adds what is easier in Python (exceptions carrying results, studies' tables,
// tractions along the contact boundary). Arrays of a result are numpy views of the C++ result
// (the Python Result object is their base and keeps it alive), read-only.
#include "python/common.hpp"
#include "levels/solve3.hpp"

PYBIND11_MODULE(_core, m) {
    using namespace mlc;
    m.doc() = "mlcontact: multilevel frictional contact in 2D linear elasticity (C++ core)";
    m.attr("__version__") = MLC_VERSION;
    m.attr("status_names") = py::make_tuple("gap", "stick", "slip_forward", "slip_backward");
    m.attr("status_names_3d") = py::make_tuple(mlc::levels::kStatusNames3[0],
                                               mlc::levels::kStatusNames3[1],
                                               mlc::levels::kStatusNames3[2]);

    static py::exception<SolverBreakdown> breakdown(m, "SolverBreakdown", PyExc_RuntimeError);
    static py::exception<Interrupted> interrupted(m, "Interrupted", PyExc_RuntimeError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InvalidInput& e) {
            python::raise_python(PyExc_ValueError, e.what());
        } catch (const SolverBreakdown& e) {
            python::raise_python(breakdown.ptr(), e.what());
        } catch (const Interrupted& e) {
            python::raise_python(interrupted.ptr(), e.what());
        }
    });
    python::bind_scene(m);
    python::bind_result(m);
    python::bind_run(m);
    python::bind_tet_mesh(m);
}
