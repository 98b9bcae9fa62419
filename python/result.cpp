// SPDX-License-Identifier: MIT
// mlcontact._core.Result: a solved scene as numpy views, reports, checks and files.
#include "python/common.hpp"

#include "levels/checks.hpp"
#include "run/output.hpp"
#include "studies/accuracy.hpp"

namespace mlc::python {

namespace {

// Convergence, the mesh, the solution and the contact state.
void bind_result_solution(ResultClass& cls) {
    cls.def_property_readonly(
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
                const auto& t = self.cast<const Result&>().run.finest().mesh.cells;
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
            "(k, 2) unit tangent t = (n_y, -n_x) at each contact node");
}

// The contact boundary, resultants, per-step reports, checks, timings and solver.
void bind_result_reports(ResultClass& cls) {
    cls.def_property_readonly(
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
        .def_property_readonly(
            "contact_pair_names",
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
        .def_property_readonly(
            "timings",
            [](const Result& r) {
                py::dict d;
                for (const auto& [name, e] : r.run.timings.table())
                    d[py::str(name)] = e.seconds;
                return d;
            },
            "seconds per timed section of the run (as the report's table)")
        .def_property_readonly(
            "solver",
            [](const Result& r) {
                const auto& sp = r.run.solver.spec;
                py::dict d;
                d["method"] = std::string(solvers::to_string(sp.method));
                d["krylov"] = std::string(solvers::to_string(sp.krylov));
                d["pc"] = sp.pc.text();
                d["rel_tol"] = sp.rel_tol;
                d["automatic"] = r.run.solver.automatic;
                d["numbering"] = std::string(levels::to_string(r.problem.numbering));
                d["reason"] = r.run.solver.reason;
                return d;
            },
            "the Newton-system solver: method, krylov, pc, rel_tol, "
            "automatic (chosen by the default), numbering, reason");
}

// The state of one step, the closed forms, the report and the files.
void bind_result_methods(ResultClass& cls) {
    cls.def(
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
}

} // namespace

void bind_result(py::module_& m) {
    ResultClass c(m, "Result", "A solved scene");
    bind_result_solution(c);
    bind_result_reports(c);
    bind_result_methods(c);
}

} // namespace mlc::python
