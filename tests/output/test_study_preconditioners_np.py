# SPDX-License-Identifier: MIT
"""`mlcontact study preconditioners --np-list`: the table has one row per
preconditioner, level and process count, every cell converged, level l distributed exactly when
N > 1, and its N = 1 column is what a plain one-process `mlcontact run` of the same cell reports
(Krylov iterations per Newton step, mean from summary.json and max from iterations.csv). What
cannot run is refused with a message: no MPI launcher, a preconditioner with no distributed form.

Run by ctest as `/usr/bin/python3 -m pytest`; MLCONTACT is the driver, MPIEXEC the launcher.
"""
import csv
import json
import os
import subprocess

import pytest

MLCONTACT = os.environ["MLCONTACT"]
MPIEXEC = os.environ.get("MPIEXEC", "mpiexec")
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
# The launcher's folder first on PATH, where the study looks for mpiexec.
ENV["PATH"] = os.path.dirname(MPIEXEC) + os.pathsep + ENV.get("PATH", "")
PCS = ["ilu:0", "ebe", "mg"]  # diag: thousands of iterations, too slow for the default suite
LEVELS = 2
NPS = [1, 2]
MU = "0.1"


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("np") / "study"
    p = subprocess.run([MLCONTACT, "study", "preconditioners", "square", "--levels", str(LEVELS),
                        "--np-list", ",".join(map(str, NPS)), "--mu", MU, "--pc", *PCS,
                        "--no-plot", "--out", str(out)],
                       capture_output=True, text=True, env=ENV, timeout=900)
    assert p.returncode == 0, p.stdout + p.stderr
    with open(out / "preconditioners_np.csv") as f:
        rows = list(csv.DictReader(f))
    return out, rows, p.stdout


def test_the_table_has_a_converged_row_per_preconditioner_level_and_process_count(study):
    out, rows, stdout = study
    assert sorted((r["pc"], int(r["level"]), int(r["processes"])) for r in rows) == sorted(
        (pc, l, n) for pc in PCS for l in range(1, LEVELS + 1) for n in NPS)
    for r in rows:
        assert r["result"] == "converged", r
        assert int(r["newton"]) >= 1 and int(r["unknowns"]) > 0, r
        mean, mx = float(r["krylov_per_newton_mean"]), float(r["krylov_per_newton_max"])
        assert 1 <= mean <= mx, r
        # Level l is the distributed one exactly on several processes.
        assert r["level_distributed"] == ("1" if int(r["processes"]) > 1 else "0"), r
    # The same unknowns for every N; more on the finer level.
    for pc in PCS:
        u = {(int(r["level"]), int(r["processes"])): int(r["unknowns"]) for r in rows if r["pc"] == pc}
        assert u[(1, 1)] == u[(1, 2)] < u[(2, 1)] == u[(2, 2)]
    js = json.loads((out / "preconditioners_np.json").read_text())
    assert js["processes"] == NPS and len(js["runs"]) == len(rows)
    # The pivot table: one line per preconditioner and level, with a column per N.
    assert "Krylov iterations per Newton step on level l, mean (max), by processes N:" in stdout
    assert all(f"N={n}" in stdout for n in NPS)


@pytest.mark.parametrize("pc", PCS)
def test_the_one_process_column_is_a_plain_run(study, tmp_path, pc):
    _, rows, _ = study
    for level in range(1, LEVELS + 1):
        out = tmp_path / f"L{level}"
        p = subprocess.run([MLCONTACT, "run", "square", "--levels", str(level), "--pc", pc,
                            "--linear-tol", "1e-8", "--mu", MU, "--no-fallback",
                            "--no-continuation", "--quiet", "--out", str(out)],
                           capture_output=True, text=True, timeout=600,
                           env=dict(ENV, OMPI_MCA_ess_singleton_isolated="1", OMP_NUM_THREADS="1"))
        assert p.returncode == 0, p.stdout + p.stderr
        s = json.loads((out / "summary.json").read_text())
        lv = [x for x in s["levels"] if x["level"] == level][0]
        newton = sum(st["newton_iterations"] for st in lv["steps"])
        krylov = sum(st["linear_iterations"] for st in lv["steps"])
        with open(out / "iterations.csv") as f:
            its = [int(r["krylov"]) for r in csv.DictReader(f) if int(r["level"]) == level]
        assert len(its) == newton and sum(its) == krylov
        row = [r for r in rows if r["pc"] == pc and int(r["level"]) == level
               and r["processes"] == "1"][0]
        assert int(row["newton"]) == newton
        assert int(row["unknowns"]) == lv["unknowns"]
        assert float(row["krylov_per_newton_mean"]) == pytest.approx(krylov / newton, rel=1e-9)
        assert float(row["krylov_per_newton_max"]) == max(its)


def test_no_launcher_is_refused(tmp_path):
    env = dict(ENV, PATH=str(tmp_path))  # no mpiexec, no mpirun
    p = subprocess.run([MLCONTACT, "study", "preconditioners", "--levels", "1", "--np-list", "1,2",
                        "--pc", "mg", "--no-plot", "--out", str(tmp_path / "o")],
                       capture_output=True, text=True, env=env, timeout=120)
    assert p.returncode == 1, p.stdout + p.stderr
    assert "neither mpiexec nor mpirun is on PATH" in p.stderr, p.stderr


def test_a_preconditioner_with_no_distributed_form_is_refused(tmp_path):
    p = subprocess.run([MLCONTACT, "study", "preconditioners", "--levels", "1", "--np-list", "1,2",
                        "--pc", "mg", "sorcf", "--no-plot", "--out", str(tmp_path / "o")],
                       capture_output=True, text=True, env=ENV, timeout=120)
    assert p.returncode == 1, p.stdout + p.stderr
    assert "'sorcf' has no distributed form" in p.stderr, p.stderr
    assert not (tmp_path / "o" / "runs").exists()


def iterations_by_level(out, level):
    with open(out / "iterations.csv") as f:
        return [int(r["krylov"]) for r in csv.DictReader(f) if int(r["level"]) == level]


def test_a_3d_scene_over_processes_and_its_one_process_family(tmp_path):
    """block3d, level 1: GMRES (the 3D default) with ilu:0 and mg on 1 and 2 processes, and the
    one-process family (cf, sorcf, mgr) without --np-list; every cell converged and each N = 1
    cell is a plain one-process `mlcontact run` with that preconditioner."""
    cells = {}
    for args, tag in ((["--np-list", "1,2", "--pc", "ilu:0", "mg"], "np"),
                      (["--pc", "cf", "sorcf", "mgr"], "one")):
        out = tmp_path / tag
        p = subprocess.run([MLCONTACT, "study", "preconditioners", "block3d", "--levels", "1",
                            *args, "--no-plot", "--out", str(out)],
                           capture_output=True, text=True, env=ENV, timeout=900)
        assert p.returncode == 0, p.stdout + p.stderr
        with open(out / "preconditioners_np.csv") as f:
            for r in csv.DictReader(f):
                cells[(r["pc"], int(r["processes"]))] = r
    assert sorted(cells) == sorted([("ilu:0", 1), ("ilu:0", 2), ("mg", 1), ("mg", 2), ("cf", 1),
                                    ("sorcf", 1), ("mgr", 1)])
    for (pc, n), r in cells.items():
        assert r["result"] == "converged" and r["krylov"] == "gmres", r
        assert r["level_distributed"] == ("1" if n > 1 else "0"), r
        if n > 1:
            continue
        # The study's friction and penalty (mu 1, r = E / 10 by default) given to a plain run.
        words = (tmp_path / ("np" if pc in ("ilu:0", "mg") else "one") / "runs" /
                 f"gmres_{pc.replace(':', '-')}_mu1_r0.1_L1_np1" / "command.txt").read_text().split()
        mu, r_ = words[words.index("--mu") + 1], words[words.index("--r") + 1]
        out = tmp_path / f"plain_{pc}"
        p = subprocess.run([MLCONTACT, "run", "block3d", "--levels", "1", "--pc", pc,
                            "--linear-tol", "1e-8", "--mu", mu, "--r", r_, "--quiet", "--out",
                            str(out)],
                           capture_output=True, text=True, timeout=600,
                           env=dict(ENV, OMPI_MCA_ess_singleton_isolated="1", OMP_NUM_THREADS="1"))
        assert p.returncode == 0, p.stdout + p.stderr
        its = iterations_by_level(out, 1)
        assert int(r["newton"]) == len(its) > 0, (r, its)
        assert float(r["krylov_per_newton_mean"]) == pytest.approx(sum(its) / len(its), rel=1e-7)
        assert float(r["krylov_per_newton_max"]) == max(its)
    # The multigrid needs fewer iterations than ILU(0) on every process count.
    for n in (1, 2):
        assert (float(cells[("mg", n)]["krylov_per_newton_mean"])
                < float(cells[("ilu:0", n)]["krylov_per_newton_mean"]))
