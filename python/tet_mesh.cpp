// SPDX-License-Identifier: MIT
// mlcontact._core.TetMesh: tetrahedral meshes (Kuhn box, Gmsh files, Bey's refinement) as numpy
// arrays, their quality checks and their VTU output.
#include "python/common.hpp"

#include "mesh/io/gmsh_tet.hpp"
#include "mesh/io/vtu_tet.hpp"
#include "mesh/tet_refine.hpp"

#include <array>
#include <memory>

namespace mlc::python {

namespace {

using mesh::TetMesh;
using TetMeshClass = py::class_<TetMesh, std::shared_ptr<TetMesh>>;

mesh::Vec3 vec3(const std::array<double, 3>& a) {
    return {a[0], a[1], a[2]};
}

/// The fields of a dict name -> array of shape (n,) or (n, k), as mesh::Field (k components).
std::vector<mesh::Field> fields_of(const py::dict& data, const char* kind) {
    std::vector<mesh::Field> out;
    for (const auto& [key, value] : data) {
        const std::string name = py::str(key);
        const auto a =
            py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
        if (!a)
            throw InvalidInput(std::string(kind) + " '" + name +
                               "': expected an array of numbers of shape (n,) or (n, k)");
        if (a.ndim() != 1 && a.ndim() != 2)
            throw InvalidInput(std::string(kind) + " '" + name + "' has " +
                               std::to_string(a.ndim()) +
                               " dimensions; expected an array of shape (n,) or (n, k)");
        const int nc = a.ndim() == 1 ? 1 : static_cast<int>(a.shape(1));
        out.push_back({name, nc, std::vector<double>(a.data(), a.data() + a.size())});
    }
    return out;
}

/// A mesh from arrays (n, 3) points, (m, 4) tetrahedra and optionally (m,) attributes; indices
/// and shapes are checked here, the geometry by check().
std::shared_ptr<TetMesh> from_arrays(
    const py::array_t<double, py::array::c_style | py::array::forcecast>& points,
    const py::array_t<int, py::array::c_style | py::array::forcecast>& tets,
    const std::optional<py::array_t<int, py::array::c_style | py::array::forcecast>>& attributes) {
    if (points.ndim() != 2 || points.shape(1) != 3)
        throw InvalidInput("TetMesh: points must have shape (n, 3)");
    if (tets.ndim() != 2 || tets.shape(1) != 4)
        throw InvalidInput("TetMesh: tetrahedra must have shape (m, 4)");
    auto m = std::make_shared<TetMesh>();
    for (py::ssize_t i = 0; i < points.shape(0); ++i)
        m->vertices.emplace_back(points.at(i, 0), points.at(i, 1), points.at(i, 2));
    for (py::ssize_t t = 0; t < tets.shape(0); ++t)
        m->cells.push_back({tets.at(t, 0), tets.at(t, 1), tets.at(t, 2), tets.at(t, 3)});
    if (attributes) {
        if (attributes->ndim() != 1 || attributes->shape(0) != tets.shape(0))
            throw InvalidInput("TetMesh: attributes must have shape (m,), one per tetrahedron");
        m->attribute.assign(attributes->data(), attributes->data() + attributes->size());
    }
    for (std::size_t t = 0; t < m->cells.size(); ++t)
        for (int v : m->cells[t])
            if (v < 0 || v >= m->n_vertices())
                throw InvalidInput("TetMesh: tetrahedron " + std::to_string(t) +
                                   " refers to vertex " + std::to_string(v) + " but there are " +
                                   std::to_string(m->n_vertices()) + " points");
    return m;
}

// Where a mesh comes from: arrays, the box, a Gmsh file, refinement.
void bind_tet_sources(TetMeshClass& cls) {
    cls.def(py::init(&from_arrays), py::arg("points"), py::arg("tetrahedra"),
            py::arg("attributes") = py::none(),
            "A mesh from (n, 3) points, (m, 4) vertex indices and optionally (m,) bodies, "
            "without boundary tags; check() checks it");
    cls.def_static(
           "box",
           [](const std::array<double, 3>& corner, const std::array<double, 3>& size,
              const std::array<int, 3>& divisions) {
               return std::make_shared<TetMesh>(mesh::structured_box(
                   vec3(corner), vec3(size), divisions[0], divisions[1], divisions[2]));
           },
           py::arg("corner"), py::arg("size"), py::arg("divisions"),
           "The box [corner, corner + size] with divisions (nx, ny, nz) cells, each cut into six "
           "Kuhn tetrahedra around its main diagonal; boundary tags xmin, xmax, ymin, ymax, zmin, "
           "zmax")
        .def_static(
            "read_gmsh",
            [](const std::string& path, const std::string& volume) {
                return std::make_shared<TetMesh>(mesh::read_gmsh_tet(path, volume));
            },
            py::arg("path"), py::arg("volume") = "",
            "The 4-node tetrahedra of a Gmsh .msh file (ASCII 2.2 or 4.1): physical surfaces "
            "become boundary tags, physical volumes bodies (attributes); `volume` selects one "
            "physical volume by name. The mesh is checked (check()); errors name the file, line "
            "and element")
        .def(
            "refine",
            [](const TetMesh& m, int times) {
                if (times < 0)
                    throw InvalidInput("refine: times=" + std::to_string(times) +
                                       "; expected >= 0");
                auto out = std::make_shared<TetMesh>(m);
                for (int i = 0; i < times; ++i)
                    *out = mesh::refine(*out);
                return out;
            },
            py::arg("times") = 1,
            "A new mesh: this one refined `times` times 1 -> 8 by Bey's rule (coarse vertices "
            "keep their indices, the midpoint of edge e of the last coarse mesh is vertex "
            "n_coarse_vertices + e, `parents` its two coarse vertices; children of tetrahedron t "
            "are 8 t .. 8 t + 7, of boundary face f 4 f .. 4 f + 3)")
        .def(
            "predict_sizes",
            [](const TetMesh& m, int levels) {
                py::list out;
                for (const auto& s : mesh::predict_tet_level_sizes(m, levels)) {
                    py::dict d;
                    d["level"] = s.level;
                    d["vertices"] = s.vertices;
                    d["edges"] = s.edges;
                    d["faces"] = s.faces;
                    d["tetrahedra"] = s.tetrahedra;
                    d["boundary_faces"] = s.boundary_faces;
                    d["tagged_faces"] = s.tagged_faces;
                    d["bytes"] = s.bytes;
                    out.append(d);
                }
                return out;
            },
            py::arg("levels"),
            "Sizes of levels 0..levels of this mesh's hierarchy, predicted without building them "
            "(a list of dicts: level, vertices, edges, faces, tetrahedra, boundary_faces, "
            "tagged_faces, bytes)");
}

// The arrays: numpy views of the mesh (read-only; the mesh object is their base).
void bind_tet_arrays(TetMeshClass& cls) {
    cls.def_property_readonly(
           "points",
           [](py::object self) {
               const auto& v = self.cast<const TetMesh&>().vertices;
               return view<double>(self, v.empty() ? nullptr : v[0].data(),
                                   {static_cast<py::ssize_t>(v.size()), 3},
                                   {sizeof(mesh::Vec3), sizeof(double)});
           },
           "(n, 3) vertex positions")
        .def_property_readonly(
            "tetrahedra",
            [](py::object self) {
                const auto& t = self.cast<const TetMesh&>().cells;
                return view<int>(self, t.empty() ? nullptr : t[0].data(),
                                 {static_cast<py::ssize_t>(t.size()), 4},
                                 {sizeof(t[0]), sizeof(int)});
            },
            "(m, 4) vertex indices of the tetrahedra")
        .def_property_readonly(
            "boundary_faces",
            [](py::object self) {
                const auto& b = self.cast<const TetMesh&>().boundary;
                return view<int>(self, b.empty() ? nullptr : b[0].v.data(),
                                 {static_cast<py::ssize_t>(b.size()), 3},
                                 {sizeof(mesh::BoundaryFace), sizeof(int)});
            },
            "(k, 3) vertex indices of the tagged boundary faces, each oriented with its normal "
            "out of the body")
        .def_property_readonly(
            "face_tags",
            [](py::object self) {
                const auto& b = self.cast<const TetMesh&>().boundary;
                return view<int>(self, b.empty() ? nullptr : &b[0].tag,
                                 {static_cast<py::ssize_t>(b.size())},
                                 {sizeof(mesh::BoundaryFace)});
            },
            "(k,) tag id of each boundary face (names: tag_names)")
        .def_property_readonly(
            "attributes",
            [](const TetMesh& m) {
                if (m.attribute.empty()) return copy_array(std::vector<int>(m.cells.size(), 0));
                return copy_array(m.attribute);
            },
            "(m,) body (Gmsh physical volume) of each tetrahedron, 0 when none is given (a copy)")
        .def_property_readonly(
            "parents",
            [](py::object self) {
                const auto& p = self.cast<const TetMesh&>().parents;
                return view<int>(self, p.empty() ? nullptr : p[0].data(),
                                 {static_cast<py::ssize_t>(p.size()), 2},
                                 {sizeof(p[0]), sizeof(int)});
            },
            "(n - n_coarse_vertices, 2) the two coarse vertices of each vertex made by refine() "
            "(empty for a mesh not refined)")
        .def_property_readonly(
            "n_coarse_vertices", [](const TetMesh& m) { return m.n_coarse_vertices; },
            "vertices of the mesh this one was refined from (0 if not refined)")
        .def_property_readonly(
            "tag_names", [](const TetMesh& m) { return m.tag_names; },
            "dict boundary tag name -> tag id")
        .def_property_readonly("n_vertices", &TetMesh::n_vertices, "number of vertices")
        .def_property_readonly("n_tetrahedra", &TetMesh::n_cells, "number of tetrahedra")
        .def(
            "signed_volumes",
            [](const TetMesh& m) {
                std::vector<double> v(m.cells.size());
                for (int t = 0; t < m.n_cells(); ++t)
                    v[static_cast<size_t>(t)] = m.signed_measure(t);
                return copy_array(v);
            },
            "(m,) signed volume of each tetrahedron (its sign: the vertex order's orientation)")
        .def(
            "vertices_with_tag",
            [](const TetMesh& m, const std::string& tag) {
                return copy_array(m.vertices_with_tag(m.tag(tag)));
            },
            py::arg("tag"), "sorted indices of the vertices on the boundary faces tagged `tag`")
        .def("__repr__", [](const TetMesh& m) {
            return "<mlcontact.TetMesh " + std::to_string(m.n_vertices()) + " vertices, " +
                   std::to_string(m.n_cells()) + " tetrahedra, " +
                   std::to_string(m.boundary.size()) + " tagged boundary faces>";
        });
}

// Checks, curved surfaces and files.
void bind_tet_checks_and_output(TetMeshClass& cls) {
    cls.def(
           "check", [](const TetMesh& m) { mesh::check_quality(m); },
           "Checks the mesh (flat or inverted tetrahedra, duplicated elements, faces of over two "
           "tetrahedra, non-manifold boundaries, bad boundary faces); raises ValueError naming "
           "the first defect")
        .def(
            "attach_sphere",
            [](TetMesh& m, const std::string& tag, const std::array<double, 3>& center,
               double radius) {
                mesh::CurvedSurface s;
                s.kind = mesh::CurvedSurface::Kind::sphere;
                s.center = vec3(center);
                s.radius = radius;
                mesh::attach_surface(m, tag, s);
            },
            py::arg("tag"), py::arg("center"), py::arg("radius"),
            "Declares that the faces tagged `tag` lie on a sphere, so that refine() puts the "
            "vertices it creates there on it; ValueError names a vertex off the sphere")
        .def(
            "attach_cylinder",
            [](TetMesh& m, const std::string& tag, const std::array<double, 3>& point,
               const std::array<double, 3>& axis, double radius) {
                mesh::CurvedSurface s;
                s.kind = mesh::CurvedSurface::Kind::cylinder;
                s.center = vec3(point);
                s.axis = vec3(axis);
                s.radius = radius;
                mesh::attach_surface(m, tag, s);
            },
            py::arg("tag"), py::arg("point"), py::arg("axis"), py::arg("radius"),
            "As attach_sphere, for a circular cylinder through `point` along `axis`")
        .def(
            "write_vtu",
            [](const TetMesh& m, const std::string& path, const py::dict& point_data,
               const py::dict& cell_data) {
                mesh::write_vtu(path, m, fields_of(point_data, "point_data"),
                                fields_of(cell_data, "cell_data"));
            },
            py::arg("path"), py::arg("point_data") = py::dict(), py::arg("cell_data") = py::dict(),
            "Writes a binary VTU: the tetrahedra (VTK_TETRA), point_data and cell_data as dicts "
            "name -> array of shape (n,) or (n, k) (a displacement: (n, 3)), and the cell field "
            "body (attributes)")
        .def(
            "write_boundary_vtu",
            [](const TetMesh& m, const std::string& path, const py::dict& point_data,
               const py::dict& cell_data) {
                mesh::write_boundary_vtu(path, m, fields_of(point_data, "point_data"),
                                         fields_of(cell_data, "cell_data"));
            },
            py::arg("path"), py::arg("point_data") = py::dict(), py::arg("cell_data") = py::dict(),
            "Writes the tagged boundary faces as a binary VTU of triangles over all the mesh's "
            "points, with the cell fields tag and surface (then cell_data, one row per face)");
}

} // namespace

void bind_tet_mesh(py::module_& m) {
    TetMeshClass cls(m, "TetMesh",
                     "A tetrahedral mesh: a Kuhn box, a Gmsh file, or a refinement of one");
    bind_tet_sources(cls);
    bind_tet_arrays(cls);
    bind_tet_checks_and_output(cls);
    m.def(
        "write_pvd",
        [](const std::string& path, const std::vector<std::pair<double, std::string>>& steps) {
            mesh::write_pvd(path, steps);
        },
        py::arg("path"), py::arg("steps"),
        "Writes a ParaView collection (.pvd) of steps [(time, vtu path relative to the .pvd's "
        "folder), ...]");
}

} // namespace mlc::python
