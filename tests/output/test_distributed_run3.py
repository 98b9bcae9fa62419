# SPDX-License-Identifier: MIT
"""`mlcontact run` on a 3D scene on several processes: mpirun -np 2 and 3 give the one-process
answer on block3d (rigid plane, friction) and stack3d (two bodies, non-matching meshes), with the
Newton and Krylov tolerances at 1e-12: displacements and multipliers at every contact node to 1e-8
of their largest magnitude and the same status; solution.pvtu opens in VTK's parallel reader as
one mesh whose displacements are the one-process solution.vtu's; summary.json records the
processes; what has no distributed form is refused with a message.

Run by ctest as `/usr/bin/python3 -m pytest`; MLCONTACT is the driver, MPIEXEC the launcher.
"""
import csv
import json

import numpy as np
import pytest
from mpi_runs import read_grid, run_processes, tight_scene
from vtk.util.numpy_support import vtk_to_numpy


def run(tmp_path, scene, np_, *extra, expect=0, tag="", levels=1):
    out = tmp_path / f"out_np{np_}{tag}"
    p = run_processes(["run", str(scene), "--levels", str(levels), "--quiet", "--out", str(out),
                       *extra], np_, expect)
    return out, p


def contact_rows(path):
    """Rows by (pair, position): the vertex column numbers differ between the runs."""
    with open(path) as f:
        return {(r["pair"],) + tuple(round(float(r[c]), 12) for c in "xyz"): r
                for r in csv.DictReader(f)}


def displacements(grid):
    """Displacements by position (a list: a vertex on a cut appears in several pieces, and two
    bodies' vertices may coincide)."""
    pts = vtk_to_numpy(grid.GetPoints().GetData())
    u = vtk_to_numpy(grid.GetPointData().GetArray("displacement"))
    out = {}
    for p, d in zip(pts, u):
        out.setdefault(tuple(round(float(x), 12) for x in p), []).append(d)
    return out


def compare(serial, dist):
    a, b = contact_rows(serial / "contact.csv"), contact_rows(dist / "contact.csv")
    assert a.keys() == b.keys() and len(a) > 0
    u_scale = max(abs(float(r[c])) for r in a.values() for c in ("ux", "uy", "uz"))
    l_scale = max(abs(float(r[c])) for r in a.values()
                  for c in ("lambda_n", "lambda_t1", "lambda_t2"))
    assert u_scale > 0 and l_scale > 0
    for k, r in a.items():
        s = b[k]
        assert s["status"] == r["status"], (k, r["status"], s["status"])
        for c in ("ux", "uy", "uz"):
            assert abs(float(s[c]) - float(r[c])) <= 1e-8 * u_scale, (k, c, r[c], s[c])
        for c in ("lambda_n", "lambda_t1", "lambda_t2"):
            assert abs(float(s[c]) - float(r[c])) <= 1e-8 * l_scale, (k, c, r[c], s[c])
    assert any(r["status"] != "gap" for r in a.values())


@pytest.mark.parametrize("scene", ["block3d", "stack3d"])
def test_two_and_three_processes_give_the_one_process_answer(tmp_path, scene):
    f = tight_scene(tmp_path, scene)
    serial, _ = run(tmp_path, f, 1, "--linear-tol", "1e-12")
    for np_ in (2, 3):
        dist, p = run(tmp_path, f, np_, "--linear-tol", "1e-12", "--partition-level", "0")
        assert f"on {np_} processes" in p.stdout
        compare(serial, dist)
        summary = json.load(open(dist / "summary.json"))
        assert summary["processes"] == np_ and summary["converged"]
        assert summary["dimension"] == 3 and summary["partition_level"] == 0
        assert "distributed mg" in summary["solver_upper"]
        # One mesh in VTK's parallel reader, with the one-process displacements at every point.
        one = displacements(read_grid(serial / "solution.vtu", False))
        many = displacements(read_grid(dist / "solution.pvtu", True))
        assert one.keys() == many.keys()
        scale = max(np.abs(d).max() for v in one.values() for d in v)
        for k, ds in many.items():
            for d in ds:
                assert min(np.abs(d - e).max() for e in one[k]) <= 1e-8 * scale, k
        # Every distributed level's Krylov iterations are written (distributed = 1).
        with open(dist / "iterations.csv") as g:
            rows = list(csv.DictReader(g))
        assert any(r["distributed"] == "1" and r["level"] == "1" for r in rows)
        assert all(int(r["krylov"]) <= 60 for r in rows if r["distributed"] == "1")


def test_what_has_no_distributed_form_is_refused(tmp_path):
    for levels, extra, message in ((1, ["--linear", "lu"], "needs a whole level on one process"),
                                   (1, ["--cold"], "--cold is one process only"),
                                   (0, [], "needs --levels >= 1")):
        _, p = run(tmp_path, "block3d", 2, *extra, expect=1, tag=str(len(message)), levels=levels)
        assert p.stderr.count("mlcontact: error:") == 1 and message in p.stderr, p.stderr


def test_a_preconditioner_of_the_matrix_alone_runs_on_each_process_block(tmp_path):
    """--pc ilu:0 on block3d: GMRES with ILU(0) on each process's diagonal block (Jacobi across
    the cuts) gives the one-process ILU(0) answer, which the one-process run names."""
    f = tight_scene(tmp_path, "block3d")
    serial, _ = run(tmp_path, f, 1, "--pc", "ilu:0", "--linear-tol", "1e-12")
    assert json.load(open(serial / "summary.json"))["solver_upper"] == "gmres + ilu"
    dist, _ = run(tmp_path, f, 2, "--pc", "ilu:0", "--linear-tol", "1e-12", "--partition-level",
                  "0")
    compare(serial, dist)
    summary = json.load(open(dist / "summary.json"))
    assert summary["solver_upper"] == "gmres + ilu on each process's diagonal block", summary


def test_what_needs_a_whole_level_or_has_no_3d_form_is_refused(tmp_path):
    for np_, pc, message in ((2, "sorcf", "has no distributed form"),
                             (2, "mgr", "has no distributed form"),
                             (1, "ebe", "2D-only"),
                             (2, "mg:pre=3", "the 3D multigrid's cycle is fixed")):
        _, p = run(tmp_path, "block3d", np_, "--pc", pc, expect=1, tag=pc.replace(":", "_"))
        assert p.stderr.count("mlcontact: error:") == 1 and message in p.stderr, p.stderr


def newton_per_level(out):
    with open(out / "iterations.csv") as g:
        rows = list(csv.DictReader(g))
    return {l: sum(1 for r in rows if r["level"] == l) for l in {r["level"] for r in rows}}


@pytest.mark.parametrize("scene", ["block3d", "shear3d"])
def test_the_secant_predictor_and_a_loading_path_on_distributed_levels(tmp_path, scene):
    """block3d (proportional loading) and shear3d (pressed, then pushed: a loading path) on two
    processes with level 1 distributed give the one-process answer, and the distributed level
    starts every step from the secant predictor as one process does: the same Newton iterations
    per level (block3d's steps 2 to 5 take none)."""
    f = tight_scene(tmp_path, scene)
    serial, _ = run(tmp_path, f, 1, "--linear-tol", "1e-12")
    dist, _ = run(tmp_path, f, 2, "--linear-tol", "1e-12", "--partition-level", "0")
    compare(serial, dist)
    assert newton_per_level(dist) == newton_per_level(serial)
