# SPDX-License-Identifier: MIT
"""The parallel VTU output read by VTK's own parallel reader: write_pvtu
(tests/output/write_pvtu.cpp) run alone and under mpirun -np 2 and 3 writes solution.pvtu and
one piece per process; vtkXMLPUnstructuredGridReader (Debian python3-vtk9) opens it as one mesh
with the serial mesh's triangles and vertices and the fields' closed forms.

Run by ctest as `/usr/bin/python3 -m pytest`; WRITE_PVTU is the helper, MPIEXEC the launcher.
"""
import os
import subprocess

import numpy as np
import pytest
import vtk
from vtk.util.numpy_support import vtk_to_numpy

WRITE_PVTU = os.environ["WRITE_PVTU"]
MPIEXEC = os.environ.get("MPIEXEC", "mpiexec")
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
NX, NY, LX, LY = 5, 3, 1.0, 0.6  # the helper's rectangle


def write(tmp_path, np_, refinements, fmt="binary"):
    out = tmp_path / "solution.pvtu"
    cmd = [WRITE_PVTU, str(out), str(refinements), fmt]
    if np_ > 1:
        cmd = [MPIEXEC, "-n", str(np_), "--oversubscribe", *cmd]
    env = dict(ENV)
    if np_ == 1:
        env["OMPI_MCA_ess_singleton_isolated"] = "1"
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=120)
    assert p.returncode == 0, p.stdout + p.stderr
    return out


def read_pvtu(path):
    r = vtk.vtkXMLPUnstructuredGridReader()
    r.SetFileName(str(path))
    r.Update()
    assert r.GetErrorCode() == 0, f"VTK could not read {path}"
    return r, r.GetOutput()


@pytest.mark.parametrize("np_", [1, 2, 3])
@pytest.mark.parametrize("fmt", ["binary", "ascii"])
def test_pvtu_is_one_mesh_with_the_serial_counts_and_fields(tmp_path, np_, fmt):
    refinements = 2
    out = write(tmp_path, np_, refinements, fmt)
    pieces = sorted(p.name for p in tmp_path.glob("solution_*.vtu"))
    assert pieces == [f"solution_{r}.vtu" for r in range(np_)]
    assert not list(tmp_path.glob("*.tmp"))
    reader, g = read_pvtu(out)
    assert reader.GetNumberOfPieces() == np_
    k = 2**refinements
    n_tri = 2 * NX * NY * k * k
    n_vert = (NX * k + 1) * (NY * k + 1)
    assert g.GetNumberOfCells() == n_tri
    pts = vtk_to_numpy(g.GetPoints().GetData())
    pd, cd = g.GetPointData(), g.GetCellData()
    f = vtk_to_numpy(pd.GetArray("f"))
    u = vtk_to_numpy(pd.GetArray("u"))
    gid = vtk_to_numpy(pd.GetArray("global_vertex")).astype(np.int64)
    owner = vtk_to_numpy(cd.GetArray("owner"))
    area = vtk_to_numpy(cd.GetArray("area"))
    x, y = pts[:, 0], pts[:, 1]
    # Every vertex once by its global number, and once more per extra piece it appears in
    # (cut vertices), always with the same coordinates.
    assert sorted(set(gid.tolist())) == list(range(n_vert))
    assert len(gid) >= n_vert and (len(gid) > n_vert) == (np_ > 1)
    first = {}
    for i, v in enumerate(gid):
        j = first.setdefault(v, i)
        assert np.array_equal(pts[i], pts[j]), f"vertex {v} at {pts[i]} and {pts[j]}"
    assert np.allclose(pts[:, 2], 0.0)
    assert np.allclose(f, x + 2 * y, rtol=0, atol=1e-14)
    assert u.shape == (len(x), 3)
    assert np.allclose(u[:, 0], x * y, rtol=0, atol=1e-14)
    assert np.allclose(u[:, 1], x - y, rtol=0, atol=1e-14)
    assert np.all(u[:, 2] == 0.0)
    # Every process owns part of the mesh; the areas add up to the curved rectangle's (the top
    # corners lie just outside the circle, which touches y = 0.6 at x = 0.5 and falls below it
    # by 1.2e-2 at the corners, so the midpoints moved onto it lower the top a little).
    assert sorted(set(owner.astype(int).tolist())) == list(range(np_))
    assert np.all(area > 0)
    assert LX * (LY - 0.012) < area.sum() < LX * LY


def test_one_process_and_three_give_the_same_mesh(tmp_path):
    a = tmp_path / "one"
    b = tmp_path / "three"
    a.mkdir()
    b.mkdir()
    ga = read_pvtu(write(a, 1, 2))[1]
    gb = read_pvtu(write(b, 3, 2))[1]
    # Triangles as sorted coordinate triples: the same set, and the same total area.
    def triangles(g):
        pts = vtk_to_numpy(g.GetPoints().GetData())
        conn = vtk_to_numpy(g.GetCells().GetConnectivityArray()).reshape(-1, 3)
        return sorted(tuple(sorted(map(tuple, pts[c]))) for c in conn)

    assert triangles(ga) == triangles(gb)
    aa = vtk_to_numpy(ga.GetCellData().GetArray("area")).sum()
    ab = vtk_to_numpy(gb.GetCellData().GetArray("area")).sum()
    assert abs(aa - ab) <= 1e-14 * aa
