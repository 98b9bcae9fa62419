# SPDX-License-Identifier: MIT
"""`mlcontact run` on several processes: mpirun -np 2 and 3 give the one-process
answer (displacements and multipliers to 1e-8 relative, the same status at every contact node)
with the Newton and Krylov tolerances at 1e-12; solution.pvtu opens in VTK's own parallel reader
(python3-vtk9) as one mesh whose displacements are the one-process solution.vtu's; summary.json
records the processes; what has no distributed form is refused with a message. `bench elastic`
on two processes solves the one-process bench's elastic block. Two-body scenes: patch
and dovetail on 2 and 3 processes give the one-process answer with the interface cut.

Run by ctest as `/usr/bin/python3 -m pytest`; MLCONTACT is the driver, MPIEXEC the launcher.
"""
import csv
import json
import os
import re
import subprocess

import numpy as np
import pytest
from mpi_runs import ENV, MLCONTACT, MPIEXEC, run_processes
from mpi_runs import read_grid as read
from mpi_runs import tight_scene as scene_file
from vtk.util.numpy_support import vtk_to_numpy


def run(tmp_path, scene, levels, np_, *extra, expect=0):
    out = tmp_path / f"out_np{np_}"
    pc = [] if "--pc" in extra else ["--pc", "mg"]
    p = run_processes(["run", str(scene), "--levels", str(levels), *pc, "--linear-tol", "1e-12",
                       "--quiet", "--out", str(out), *extra], np_, expect)
    return out, p


def contact_rows(path):
    with open(path) as f:
        return {(round(float(r["x"]), 12), round(float(r["y"]), 12)): r for r in csv.DictReader(f)}


def points_and_displacements(grid):
    """Displacements by point: a list per position (two bodies may touch at coincident vertices;
    a vertex on a cut appears in the piece of every process around it)."""
    pts = vtk_to_numpy(grid.GetPoints().GetData())[:, :2]
    u = vtk_to_numpy(grid.GetPointData().GetArray("displacement"))[:, :2]
    out = {}
    for (x, y), d in zip(pts, u):
        out.setdefault((round(x, 12), round(y, 12)), []).append(d)
    return out


def compare(serial, dist):
    a, b = contact_rows(serial / "contact.csv"), contact_rows(dist / "contact.csv")
    assert a.keys() == b.keys()
    u_scale = max(abs(float(r[c])) for r in a.values() for c in ("ux", "uy"))
    l_scale = max(abs(float(r[c])) for r in a.values() for c in ("lambda_t", "lambda_n"))
    assert u_scale > 0 and l_scale > 0
    for k, r in a.items():
        s = b[k]
        assert r["status"] == s["status"], (k, r["status"], s["status"])
        for c in ("ux", "uy"):
            assert abs(float(r[c]) - float(s[c])) <= 1e-8 * u_scale, (k, c, r[c], s[c])
        for c in ("lambda_t", "lambda_n"):
            assert abs(float(r[c]) - float(s[c])) <= 1e-8 * l_scale, (k, c, r[c], s[c])
    # contact_steps.csv: the same rows (tributary and arc lengths from the gathered boundary).
    def steps(d):
        with open(d / "contact_steps.csv") as f:
            return {(r["step"], round(float(r["x"]), 12), round(float(r["y"]), 12)): r
                    for r in csv.DictReader(f)}
    sa, sb = steps(serial), steps(dist)
    assert sa.keys() == sb.keys()
    for k, r in sa.items():
        assert r["status"] == sb[k]["status"]
        for c in ("length", "arc"):
            assert abs(float(r[c]) - float(sb[k][c])) <= 1e-12 * (1 + abs(float(r[c]))), (k, c)
    p_scale = max(abs(float(r["pressure"])) for r in sa.values())
    assert max(abs(float(sa[k]["pressure"]) - float(sb[k]["pressure"])) for k in sa) <= 1e-8 * p_scale
    # Every vertex's displacement, read by VTK's readers.
    g1 = read(serial / "solution.vtu", parallel=False)
    gp = read(dist / "solution.pvtu", parallel=True)
    u1, up = points_and_displacements(g1), points_and_displacements(gp)
    assert u1.keys() == up.keys()
    scale = max(np.abs(d).max() for v in u1.values() for d in v)
    # Every displacement at a position matches one of the other run's there, both ways.
    worst = max(max(min(np.abs(a - b).max() for b in y) for a in x)
                for k in u1 for x, y in ((u1[k], up[k]), (up[k], u1[k])))
    assert worst <= 1e-8 * scale, worst / scale
    return gp


@pytest.mark.parametrize("scene,levels", [("square", 3), ("hertz", 2)])
def test_several_processes_give_the_one_process_answer(tmp_path, scene, levels):
    f = scene_file(tmp_path, scene)
    serial, _ = run(tmp_path, f, levels, 1)
    s1 = json.loads((serial / "summary.json").read_text())
    for np_ in (2, 3):
        dist, p = run(tmp_path, f, levels, np_)
        gp = compare(serial, dist)
        assert gp.GetNumberOfCells() == s1["triangles"]
        pieces = sorted(x.name for x in dist.glob("solution_*.vtu"))
        assert pieces == [f"solution_{r}.vtu" for r in range(np_)]
        s = json.loads((dist / "summary.json").read_text())
        assert s["processes"] == np_ and len(s["per_process"]) == np_
        for key in ("unknowns", "contact_nodes", "vertices", "triangles", "displacement_unknowns",
                    "blas"):
            assert s[key] == s1[key], key
        assert "OpenBLAS" in s["blas"] and s["threads"] >= 1  # what the timings ran on
        assert sum(q["owned_unknowns"] for q in s["per_process"]) == s1["unknowns"]
        assert sum(q["contact_nodes"] for q in s["per_process"]) == s1["contact_nodes"]
        assert s["converged"] and s["completed_steps"] == s1["load_steps"]
        # The checks and resultants, reduced over the processes, are the one-process ones.
        for c1, c in zip(s1["contacts"], s["contacts"]):
            r1, rn = np.array(c1["resultant"]), np.array(c["resultant"])
            assert np.abs(rn - r1).max() <= 1e-8 * np.abs(r1).max()
            assert c["nodes_in_contact"] == c1["nodes_in_contact"]
        assert s["checks"]["force_balance"] <= max(10 * s1["checks"]["force_balance"], 1e-11)
        assert s["checks"]["penetration"] <= max(10 * s1["checks"]["penetration"], 1e-12)
        # The report: every process and what it owns, once.
        assert len(re.findall(r"^processes: %d$" % np_, p.stdout, re.M)) == 1


def test_a_partition_level_given_on_the_command_line_gives_the_same_answer(tmp_path):
    f = scene_file(tmp_path, "square")
    serial, _ = run(tmp_path, f, 3, 1)
    dist, p = run(tmp_path, f, 3, 2, "--partition-level", "1")
    assert "partition level 1 (--partition-level)" in p.stdout
    compare(serial, dist)
    s = json.loads((dist / "summary.json").read_text())
    assert s["partition_level"] == 1
    assert [lv["level"] for lv in s["levels"]] == [2, 3]


@pytest.mark.parametrize("krylov", ["bicgstab", "gmres"])
def test_the_other_krylov_methods_give_the_one_process_answer(tmp_path, krylov):
    f = scene_file(tmp_path, "square")
    serial, _ = run(tmp_path, f, 3, 1)
    dist, p = run(tmp_path, f, 3, 2, "--krylov", krylov)
    assert f"Newton-system solver: {krylov} + mg" in p.stdout
    compare(serial, dist)


def test_a_preconditioner_of_the_matrix_alone_runs_on_each_process_block(tmp_path):
    # ILU(0) on each process's diagonal block (Jacobi across the cuts): the one-process answer.
    # BiCGStab (30 and about 400 iterations on level 2): CGS needs about 1 300 iterations on the
    # second Newton system on 2 processes and stalls at 5 000 when the level-1 solution differs
    # in its last digits (OpenBLAS against the reference BLAS behind level 0's schur).
    f = scene_file(tmp_path, "square")
    out1 = tmp_path / "one"
    p1 = subprocess.run([MLCONTACT, "run", str(f), "--levels", "2", "--pc", "ilu:0",
                         "--krylov", "bicgstab", "--linear-tol", "1e-12", "--quiet",
                         "--out", str(out1)],
                        capture_output=True, text=True, timeout=600,
                        env=dict(ENV, OMPI_MCA_ess_singleton_isolated="1"))
    assert p1.returncode == 0, p1.stdout + p1.stderr
    dist, p = run(tmp_path, f, 2, 2, "--pc", "ilu:0", "--krylov", "bicgstab")
    assert "Krylov + ilu on each process's diagonal block" in p.stdout  # the canonical text
    compare(out1, dist)


def ebe_on_processes(tmp_path, np_):
    # EBE (C1) from each process's elements restricted to its owned unknowns, coloured within the
    # process, Jacobi across the cuts: the one-process answer on np_ processes.
    f = scene_file(tmp_path, "square")
    out1 = tmp_path / "one"
    # BiCGStab: CGS with EBE on 2 processes stalls at 5000 iterations here
    # (docs/parallel.md, "Other preconditioners").
    p1 = subprocess.run([MLCONTACT, "run", str(f), "--levels", "2", "--pc", "ebe",
                         "--krylov", "bicgstab", "--linear-tol", "1e-12", "--quiet",
                         "--out", str(out1)],
                        capture_output=True, text=True, timeout=600,
                        env=dict(ENV, OMPI_MCA_ess_singleton_isolated="1"))
    assert p1.returncode == 0, p1.stdout + p1.stderr
    dist, p = run(tmp_path, f, 2, np_, "--pc", "ebe", "--krylov", "bicgstab")
    assert "ebe on each process's diagonal block" in p.stdout
    compare(out1, dist)
    # The finest level was distributed (iterations.csv says so) and EBE converged there.
    with open(dist / "iterations.csv") as fh:
        rows = [r for r in csv.DictReader(fh) if r["level"] == "2"]
    assert rows and all(r["distributed"] == "1" and int(r["krylov"]) > 0 for r in rows)


def test_ebe_runs_on_each_process_block(tmp_path):
    ebe_on_processes(tmp_path, 2)


@pytest.mark.parametrize("args,message", [
    (["--linear", "schur"], "--linear schur has no distributed form"),
    (["--pc", "sorcf"], "'sorcf' has no distributed form"),
    (["--cold"], "--cold is one process only"),
    (["--pc", "mg:coarse=galerkin"], "mg:coarse=galerkin has no distributed form"),
    (["--partition-level", "3"], "--partition-level must lie in [0, 2] for --levels 3"),
])
def test_what_has_no_distributed_form_is_refused_once(tmp_path, args, message):
    out = tmp_path / "o"
    cmd = [MPIEXEC, "-n", "2", "--oversubscribe", MLCONTACT, "run", "square", "--levels", "3",
           "--quiet", "--out", str(out), *args]
    p = subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=300)
    assert p.returncode == 1, p.stdout + p.stderr
    assert p.stderr.count("mlcontact: error:") == 1, p.stderr
    assert message in p.stderr, p.stderr
    assert not out.exists() or not any(out.iterdir())


TWO_BODY = ("--krylov", "bicgstab", "--pc", "mg:omega=0.8,pre=0,post=2")  # the two-body default


def expect_interface_cut(dist, stdout, np_):
    """The report and summary.json show the partition cutting the contact interface: contact
    elements with targets owned by another process, and as many elements of other processes
    reaching owned vertices."""
    s = json.loads((dist / "summary.json").read_text())
    cut = sum(q["cut_contact_elements"] for q in s["per_process"])
    assert cut > 0, s["per_process"]
    assert sum(q["ghost_contact_elements"] for q in s["per_process"]) >= cut
    assert re.search(r"the partition cuts the interface \(%d of %d contact elements\)"
                     % (cut, s["contact_nodes"]), stdout), stdout
    assert s["solver"]["krylov"] == "bicgstab" and s["solver"]["pc"] == "mg:omega=0.8,pre=0,post=2"


@pytest.mark.parametrize("scene,levels,plevel", [("patch", 2, 0), ("dovetail", 1, 0)])
def test_a_two_body_scene_gives_the_one_process_answer(tmp_path, scene, levels, plevel):
    """Two bodies, node on facet, the interface cut by the partition; np 2 and
    3 run with the two-body default (BiCGStab + mg:omega=0.8,pre=0,post=2, chosen without
    asking)."""
    f = scene_file(tmp_path, scene)
    serial, _ = run(tmp_path, f, levels, 1, *TWO_BODY)
    s1 = json.loads((serial / "summary.json").read_text())
    for np_ in (2, 3):
        cmd = [MPIEXEC, "-n", str(np_), "--oversubscribe", MLCONTACT, "run", str(f), "--levels",
               str(levels), "--partition-level", str(plevel), "--linear-tol", "1e-12",
               "--out", str(tmp_path / f"out_np{np_}")]
        p = subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=600)
        assert p.returncode == 0, p.stdout + p.stderr
        dist = tmp_path / f"out_np{np_}"
        compare(serial, dist)
        expect_interface_cut(dist, p.stdout, np_)
        s = json.loads((dist / "summary.json").read_text())
        for c1, c in zip(s1["contacts"], s["contacts"]):
            r1, rn = np.array(c1["resultant"]), np.array(c["resultant"])
            assert np.abs(rn - r1).max() <= 1e-8 * np.abs(r1).max()
            assert c["nodes_in_contact"] == c1["nodes_in_contact"]
        assert s["checks"]["force_balance"] <= max(10 * s1["checks"]["force_balance"], 1e-11)


def test_partition_level_is_refused_on_one_process(tmp_path):
    p = subprocess.run([MLCONTACT, "run", "square", "--levels", "2", "--partition-level", "1",
                        "--quiet", "--out", str(tmp_path / "o")], capture_output=True,
                       text=True, env=dict(ENV, OMPI_MCA_ess_singleton_isolated="1"),
                       timeout=300)
    assert p.returncode == 1
    assert "--partition-level applies to runs on several processes" in p.stderr


def bench_elastic(tmp_path, np_):
    out = tmp_path / f"elastic_np{np_}.json"
    cmd = [MLCONTACT, "bench", "elastic", "square", "--levels", "3", "--tol", "1e-10",
           "--out", str(out)]
    env = dict(ENV)
    if np_ > 1:
        cmd = [MPIEXEC, "-n", str(np_), "--oversubscribe", *cmd]
    else:
        env["OMPI_MCA_ess_singleton_isolated"] = "1"
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=600)
    assert p.returncode == 0, p.stdout + p.stderr
    return json.loads(out.read_text()), p


def test_bench_elastic_on_two_processes_solves_the_one_process_block(tmp_path):
    """`mpirun -np 2 mlcontact bench elastic`: hypre's ParCSR BoomerAMG-PCG and the distributed
    V-cycle in CG, GMRES and CGS solve the same elastic block as the one-process bench, to 1e-10."""
    s1, _ = bench_elastic(tmp_path, 1)
    s2, p = bench_elastic(tmp_path, 2)
    assert p.stdout.count("wrote ") == 1, p.stdout  # rank 0 reports alone
    assert s2["processes"] == 2 and len(s2["per_process"]) == 2
    assert s2["unknowns"] == s1["unknowns"] > 0
    assert sum(q["owned_unknowns"] for q in s2["per_process"]) == s1["unknowns"]
    assert all(q["owned_unknowns"] > 0 and q["peak_rss_bytes"] > 0 for q in s2["per_process"])
    solvers = {r["solver"]: r for r in s2["solvers"]}
    assert sorted(solvers) == ["boomeramg-pcg", "mg-cg", "mg-cgs", "mg-gmres"]
    for r in s2["solvers"] + s1["solvers"]:
        assert r["converged"] and r["relative_residual"] <= 1e-10, r
        assert r["iterations"] >= 1 and r["x_norm"] > 0 and r["x_max_norm"] > 0, r
    # The solutions: the distributed ones agree with each other and with the one-process ones.
    ref = {r["solver"]: r for r in s1["solvers"]}["boomeramg-pcg"]
    for r in s2["solvers"]:
        assert abs(r["x_norm"] - ref["x_norm"]) <= 1e-7 * ref["x_norm"], (r, ref)
        assert abs(r["x_max_norm"] - ref["x_max_norm"]) <= 1e-7 * ref["x_max_norm"], (r, ref)
    assert s2["solution_difference"] <= 1e-7
    # The V-cycle stays a good preconditioner across the cut (one process: mg-gmres's count).
    mg1 = {r["solver"]: r for r in s1["solvers"]}["mg-gmres"]["iterations"]
    assert solvers["mg-gmres"]["iterations"] <= 2 * mg1 + 5
    # CG with the distributed V-cycle (symmetric: forward sweeps before, backward after), like the
    # one-process mg-cg.
    cg1 = {r["solver"]: r for r in s1["solvers"]}["mg-cg"]["iterations"]
    assert solvers["mg-cg"]["iterations"] <= 2 * cg1 + 5


@pytest.mark.parametrize("scene,levels", [("square", 4), ("hertz", 3)])
def test_ladder_one_to_four_processes_agree(tmp_path, scene, levels):
    """The ladder (ctest label slow: `ctest -L slow -R ladder`): N = 2, 3, 4 against
    one process on square level 4 and hertz level 3, to 1e-8 with tolerances 1e-12."""
    f = scene_file(tmp_path, scene)
    serial, _ = run(tmp_path, f, levels, 1)
    for np_ in (2, 3, 4):
        dist, _ = run(tmp_path, f, levels, np_)
        compare(serial, dist)


@pytest.mark.parametrize("scene", ["dovetail", "patch"])
def test_ladder_two_bodies_one_to_four_processes_agree(tmp_path, scene):
    """Two bodies: dovetail and patch level 2, N = 2, 3, 4 against one process
    (BiCGStab + mg:omega=0.8), tolerances 1e-12, with the default partition level and with
    every level distributed (--partition-level 0); the interface cut by the partition."""
    f = scene_file(tmp_path, scene)
    serial, _ = run(tmp_path, f, 2, 1, *TWO_BODY)
    for np_ in (2, 3, 4):
        for plevel in ([], ["--partition-level", "0"]):
            dist, p = run(tmp_path, f, 2, np_, *TWO_BODY, *plevel)
            compare(serial, dist)
            expect_interface_cut(dist, p.stdout, np_)


def test_a_run_that_cannot_fit_in_memory_is_refused(tmp_path):
    # Square level 9: about 180 GiB for one process, so about 90 GiB for each of two processes
    # on this machine, far beyond its memory: refused before anything is built.
    cmd = [MPIEXEC, "-n", "2", "--oversubscribe", MLCONTACT, "run", "square", "--levels", "9",
           "--quiet", "--out", str(tmp_path / "o")]
    p = subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=300)
    assert p.returncode == 1, p.stdout + p.stderr
    assert p.stderr.count("mlcontact: error:") == 1, p.stderr
    assert "use fewer --levels (the 2 processes on this machine together" in p.stderr, p.stderr
    assert not (tmp_path / "o").exists()


def test_the_rotation_warning_is_the_one_process_runs(tmp_path):
    """A half-disc that rolls on a rigid floor: two processes warn of the same largest rotation as
    one process (report and summary.json "warnings")."""
    scene = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "data",
                         "hostile", "half_cylinder_rolls.toml")
    rotation = {}
    for np_ in (1, 2):
        out, p = run(tmp_path, scene, 2, np_)
        warnings = json.load(open(out / "summary.json"))["warnings"]
        assert len(warnings) == 1 and warnings[0].startswith("large rotation: "), warnings
        assert "warning: " + warnings[0] in p.stdout
        rotation[np_] = float(re.search(r"rotates by ([0-9.]+) rad", warnings[0]).group(1))
    assert rotation[1] == rotation[2] and rotation[1] > 0.1
