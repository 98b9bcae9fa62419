# SPDX-License-Identifier: MIT
"""Tetrahedral meshes from Python: the Kuhn box, Gmsh files, Bey's refinement, the numpy arrays,
the quality checks as ValueError, and the VTU files read back by VTK's own reader
(python3-vtk9)."""
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import mlcontact

# A slightly distorted cube cut into five tetrahedra: four corners (physical volume 3 "shell")
# around a central one (4 "core"); cube vertex v = x + 2 y + 4 z is node v + 1.
NODES = [(0, 0, 0), (1.1, 0, 0.05), (0, 0.9, 0), (1.05, 1.0, 0.1),
         (0, 0.1, 1.2), (1, 0, 1), (0.1, 1, 0.95), (1.2, 1.1, 1.05)]
TETS = [(0, 1, 2, 4), (3, 1, 2, 7), (5, 1, 4, 7), (6, 2, 4, 7), (1, 2, 4, 7)]
BOTTOM = [(1, 2, 3), (2, 4, 3)]  # physical surface 1 "bottom" (node ids)


def positive(t):
    x = np.array([NODES[i] for i in t], dtype=float)
    if np.linalg.det(x[1:] - x[0]) < 0:
        return (t[0], t[1], t[3], t[2])
    return t


def msh22(tets=None, names=True):
    tets = [positive(t) for t in TETS] if tets is None else tets
    lines = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat"]
    if names:
        lines += ["$PhysicalNames", "3", '2 1 "bottom"', '3 3 "shell"', '3 4 "core"',
                  "$EndPhysicalNames"]
    lines += ["$Nodes", str(len(NODES))]
    lines += [f"{i + 1} {x} {y} {z}" for i, (x, y, z) in enumerate(NODES)]
    lines += ["$EndNodes", "$Elements", str(len(BOTTOM) + len(tets))]
    k = 1
    for t in BOTTOM:
        lines.append(f"{k} 2 2 1 1 {t[0]} {t[1]} {t[2]}")
        k += 1
    for i, t in enumerate(tets):
        p = 3 if i < 4 else 4
        lines.append(f"{k} 4 2 {p} {p} " + " ".join(str(v + 1) for v in t))
        k += 1
    lines += ["$EndElements", ""]
    return "\n".join(lines)


def read_vtu(path):
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(str(path))
    r.Update()
    assert r.GetErrorCode() == 0, f"VTK could not read {path}"
    g = r.GetOutput()
    out = {"points": vtk_to_numpy(g.GetPoints().GetData()),
           "types": np.array([g.GetCellType(i) for i in range(g.GetNumberOfCells())]),
           "cells": [[g.GetCell(i).GetPointId(k) for k in range(g.GetCell(i).GetNumberOfPoints())]
                     for i in range(g.GetNumberOfCells())]}
    for data in (g.GetPointData(), g.GetCellData()):
        for i in range(data.GetNumberOfArrays()):
            out[data.GetArrayName(i)] = vtk_to_numpy(data.GetArray(i))
    return out


def test_box_arrays_and_volumes():
    m = mlcontact.TetMesh.box((1, 0, -1), (2, 1, 3), (2, 3, 4))
    assert m.n_vertices == 3 * 4 * 5 and m.n_tetrahedra == 6 * 2 * 3 * 4
    assert m.points.shape == (60, 3) and m.points.dtype == np.float64
    assert m.tetrahedra.shape == (144, 4)
    with pytest.raises(ValueError):
        m.points[0, 0] = 5.0  # read-only views of the mesh
    # Vertex (i, j, k) has index (k (ny + 1) + j) (nx + 1) + i.
    assert np.array_equal(m.points[(2 * 4 + 1) * 3 + 2], [1 + 2.0, 1 / 3, -1 + 3 * 2 / 4])
    assert np.isclose(np.abs(m.signed_volumes()).sum(), 6.0, rtol=1e-14)
    assert set(m.tag_names) == {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"}
    # Two triangles per boundary square, each with its normal out of the box.
    assert m.boundary_faces.shape == (2 * 2 * (2 * 3 + 3 * 4 + 2 * 4), 3)
    assert m.face_tags.shape == (m.boundary_faces.shape[0],)
    centre = m.points.mean(axis=0)
    for f, tag in zip(m.boundary_faces, m.face_tags):
        a, b, c = m.points[f]
        assert np.dot(np.cross(b - a, c - a), a - centre) > 0
    zmax = m.boundary_faces[m.face_tags == m.tag_names["zmax"]]
    assert len(zmax) == 2 * 2 * 3 and np.all(m.points[zmax][:, :, 2] == 2.0)
    assert np.array_equal(m.vertices_with_tag("xmin"), np.flatnonzero(m.points[:, 0] == 1.0))
    assert np.array_equal(m.attributes, np.zeros(144))


def test_refine_keeps_coarse_vertices_and_puts_new_ones_at_midpoints():
    m = mlcontact.TetMesh.box((0, 0, 0), (1, 1, 1), (1, 2, 1))
    f = m.refine()
    assert f.n_tetrahedra == 8 * m.n_tetrahedra
    assert f.n_coarse_vertices == m.n_vertices
    assert np.array_equal(f.points[:m.n_vertices], m.points)
    assert f.parents.shape == (f.n_vertices - m.n_vertices, 2)
    assert np.allclose(f.points[m.n_vertices:], m.points[f.parents].mean(axis=1), rtol=0, atol=0)
    assert len(f.boundary_faces) == 4 * len(m.boundary_faces)
    assert np.array_equal(f.face_tags, np.repeat(m.face_tags, 4))
    sizes = m.predict_sizes(3)
    f3 = m.refine(3)
    assert (sizes[3]["vertices"], sizes[3]["tetrahedra"]) == (f3.n_vertices, f3.n_tetrahedra)
    assert m.parents.shape == (0, 2) and m.n_coarse_vertices == 0


def test_read_gmsh_bodies_and_tags(tmp):
    path = tmp / "cube.msh"
    path.write_text(msh22())
    m = mlcontact.TetMesh.read_gmsh(str(path))
    assert m.n_vertices == 8 and m.n_tetrahedra == 5
    assert np.array_equal(m.points, np.array(NODES, dtype=float))
    assert sorted(m.attributes) == [3, 3, 3, 3, 4]
    assert m.tag_names == {"bottom": 0}
    assert m.boundary_faces.shape == (2, 3) and np.all(m.face_tags == 0)
    assert np.all(m.signed_volumes() > 0)
    core = mlcontact.TetMesh.read_gmsh(str(path), volume="core")
    assert core.n_tetrahedra == 1 and core.n_vertices == 4
    with pytest.raises(ValueError, match=r"no physical volume 'hull'.*'shell'.*'core'"):
        mlcontact.TetMesh.read_gmsh(str(path), volume="hull")


def test_bad_meshes_raise_value_errors_naming_the_element(tmp):
    tets = [positive(t) for t in TETS]
    inverted = tets[:]
    inverted[2] = (inverted[2][0], inverted[2][1], inverted[2][3], inverted[2][2])
    path = tmp / "inverted.msh"
    path.write_text(msh22(inverted))
    # The third tetrahedron: the seventh element, on line 27 of the file.
    with pytest.raises(ValueError, match=r"inverted.msh:27: inverted tetrahedron 2 \(the "
                       r"element on line 27, nodes 6 2 8 5\)"):
        mlcontact.TetMesh.read_gmsh(str(path))
    path = tmp / "duplicated.msh"
    path.write_text(msh22(tets + [tets[4]]))
    with pytest.raises(ValueError, match=r"duplicate") as e:
        mlcontact.TetMesh.read_gmsh(str(path))
    assert "line 29" in str(e.value) and "line 30" in str(e.value), str(e.value)
    path = tmp / "missing.msh"
    path.write_text("nothing here")
    with pytest.raises(ValueError, match="missing.msh"):
        mlcontact.TetMesh.read_gmsh(str(path))


def test_a_sphere_tag_whose_vertices_are_off_the_sphere_is_refused():
    m = mlcontact.TetMesh.box((-1, -1, -1), (2, 2, 2), (2, 2, 2))
    # The first vertex of zmax, (-1, -1, 1), lies sqrt(3) - 1 off the unit sphere.
    with pytest.raises(ValueError, match=r"vertex 18 at \(-1, -1, 1\) of tag 'zmax' lies "
                       r"0\.732051 off the sphere \(center \(0, 0, 0\), radius 1\)"):
        m.attach_sphere("zmax", (0, 0, 0), 1.0)
    with pytest.raises(ValueError, match=r"vertex 0 at \(-1, -1, -1\) of tag 'xmin' lies "
                       r"0\.414214 off the cylinder"):
        m.attach_cylinder("xmin", (0, 0, 0), (0, 0, 1), 1.0)
    with pytest.raises(ValueError, match="no boundary tag 'top'"):
        m.attach_sphere("top", (0, 0, 0), 1.0)
    m.check()  # the box itself is fine


def test_vtu_read_back_by_vtk(tmp):
    m = mlcontact.TetMesh.box((0, 0, 0), (1, 1, 2), (2, 2, 3)).refine()
    u = np.column_stack([0.1 * m.points[:, 2], -0.05 * m.points[:, 0], np.sin(m.points[:, 1])])
    phi = m.points @ [1.0, -2.0, 0.5]
    vol = m.signed_volumes()
    m.write_vtu(str(tmp / "m.vtu"), point_data={"displacement": u, "phi": phi},
                cell_data={"volume": vol})
    g = read_vtu(tmp / "m.vtu")
    assert g["points"].shape == (m.n_vertices, 3)
    assert np.array_equal(g["points"], m.points)
    assert np.all(g["types"] == 10)  # VTK_TETRA
    assert np.array_equal(np.array(g["cells"]), m.tetrahedra)
    assert np.array_equal(g["displacement"], u) and np.array_equal(g["phi"], phi)
    assert np.array_equal(g["volume"], vol) and np.array_equal(g["body"], np.zeros(m.n_tetrahedra))
    m.write_boundary_vtu(str(tmp / "b.vtu"), point_data={"displacement": u})
    b = read_vtu(tmp / "b.vtu")
    assert np.all(b["types"] == 5)  # VTK_TRIANGLE
    assert np.array_equal(np.array(b["cells"]), m.boundary_faces)
    assert np.array_equal(b["tag"], m.face_tags) and np.all(b["surface"] == -1)
    assert np.array_equal(b["displacement"], u)
    with pytest.raises(ValueError, match=r"point field 'u' has 3 values"):
        m.write_vtu(str(tmp / "bad.vtu"), point_data={"u": [1.0, 2.0, 3.0]})
    assert not (tmp / "bad.vtu").exists()


def test_pvd_series_of_steps(tmp):
    m = mlcontact.TetMesh.box((0, 0, 0), (1, 1, 1), (1, 1, 1))
    steps = []
    for s in range(3):
        u = np.zeros((m.n_vertices, 3))
        u[:, 2] = -0.1 * s * m.points[:, 2]
        name = f"step_{s}.vtu"
        m.write_vtu(str(tmp / name), point_data={"displacement": u})
        steps.append((s / 2, name))
    mlcontact.write_pvd(str(tmp / "series.pvd"), steps)
    sets = ET.parse(tmp / "series.pvd").getroot().findall("./Collection/DataSet")
    assert [(float(d.get("timestep")), d.get("file")) for d in sets] == steps
    for s, (_, name) in enumerate(steps):
        assert np.array_equal(read_vtu(tmp / name)["displacement"][:, 2], -0.1 * s * m.points[:, 2])


def test_check_names_the_bad_element():
    box = mlcontact.TetMesh.box((0, 0, 0), (1, 1, 1), (1, 1, 1))
    same = mlcontact.TetMesh(box.points, box.tetrahedra, attributes=np.arange(6))
    same.check()
    assert np.array_equal(same.tetrahedra, box.tetrahedra) and list(same.attributes) == list(range(6))
    flat = box.tetrahedra.copy()
    flat[4] = (0, 1, 2, 3)  # four corners of the bottom face
    with pytest.raises(ValueError, match=r"flat tetrahedron: tetrahedron 4 \(vertices 0, 1, 2, 3 at "
                       r"\(0, 0, 0\), \(1, 0, 0\), \(0, 1, 0\), \(1, 1, 0\)\) has volume 0"):
        mlcontact.TetMesh(box.points, flat).check()
    three = mlcontact.TetMesh([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (0.2, 0.2, 2),
                               (0, 0, -1)], [(0, 1, 2, 3), (0, 1, 2, 4), (0, 1, 2, 5)])
    with pytest.raises(ValueError, match=r"a face shared by 3 tetrahedra: the face \(0, 1, 2\)"):
        three.check()
    with pytest.raises(ValueError, match="tetrahedron 1 refers to vertex 9 but there are 4 points"):
        mlcontact.TetMesh(box.points[:4], [(0, 1, 2, 3), (0, 1, 2, 9)])
    with pytest.raises(ValueError, match=r"points must have shape \(n, 3\)"):
        mlcontact.TetMesh(np.zeros((4, 2)), [(0, 1, 2, 3)])
