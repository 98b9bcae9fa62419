# SPDX-License-Identifier: MIT
"""Supports that hold a contact node's tangential displacement (tests/data/redundant): the square
with its contact corner held in u_x, the frictional Hertz half-model (`hertz --mu 0.3`, its axis
support reaching the contact point) and a block on a floor with its left face held. On 2 and 3
processes `mlcontact run` gives the one-process answer (displacements and multipliers to 1e-8 of
their scale, every status equal) with the Newton and Krylov tolerances at 1e-12, the multigrid
needs no exact fallback, and the held node's lambda_t is zero.

Run by ctest as `/usr/bin/python3 -m pytest -k <scene>`; MLCONTACT is the driver, MPIEXEC the
launcher.
"""
import csv
import json
import os
import subprocess

import pytest
from mpi_runs import ENV, MLCONTACT, run_processes

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "redundant")

# scene file (or built-in name), extra flags, the held contact node
SCENES = {
    "square_held_corner": ("square_held_corner.toml", [], (40.0, 0.0)),
    "hertz_mu": ("hertz", ["--mu", "0.3"], (0.0, 0.0)),
    "block_floor": ("block_floor.toml", [], (0.0, 0.0)),
}


def scene_file(tmp_path, name):
    """The scene with the Newton tolerance at 1e-12."""
    if name.endswith(".toml"):
        with open(os.path.join(DATA, name)) as src:
            text = src.read()
    else:
        text = subprocess.run([MLCONTACT, "show", name], capture_output=True, text=True,
                              env=dict(ENV, OMPI_MCA_ess_singleton_isolated="1"),
                              check=True).stdout
    assert "[newton]" not in text
    f = tmp_path / (name if name.endswith(".toml") else name + ".toml")
    f.write_text(text + "\n[newton]\nrel_tol = 1e-12\n")
    return f


def run(tmp_path, scene, levels, np_, extra):
    out = tmp_path / f"out_np{np_}"
    run_processes(["run", str(scene), "--levels", str(levels), "--pc", "mg", "--no-fallback",
                   "--linear-tol", "1e-12", "--quiet", "--out", str(out), *extra], np_)
    return out


def contact_rows(path):
    with open(path) as f:
        return {(round(float(r["x"]), 12), round(float(r["y"]), 12)): r for r in csv.DictReader(f)}


@pytest.mark.parametrize("name", sorted(SCENES))
def test_several_processes_give_the_one_process_answer(tmp_path, name):
    src, extra, held = SCENES[name]
    f = scene_file(tmp_path, src)
    serial = run(tmp_path, f, 2, 1, extra)
    a = contact_rows(serial / "contact.csv")
    assert a[held]["status"] == "stick"
    assert float(a[held]["lambda_t"]) == 0.0
    assert float(a[held]["lambda_n"]) < 0.0
    u_scale = max(abs(float(r[c])) for r in a.values() for c in ("ux", "uy"))
    l_scale = max(abs(float(r[c])) for r in a.values() for c in ("lambda_t", "lambda_n"))
    assert u_scale > 0 and l_scale > 0
    for np_ in (2, 3):
        dist = run(tmp_path, f, 2, np_, extra)
        s = json.loads((dist / "summary.json").read_text())
        assert s["processes"] == np_
        b = contact_rows(dist / "contact.csv")
        assert a.keys() == b.keys()
        for k, r in a.items():
            q = b[k]
            assert r["status"] == q["status"], (np_, k, r["status"], q["status"])
            for c in ("ux", "uy"):
                assert abs(float(r[c]) - float(q[c])) <= 1e-8 * u_scale, (np_, k, c, r[c], q[c])
            for c in ("lambda_t", "lambda_n"):
                assert abs(float(r[c]) - float(q[c])) <= 1e-8 * l_scale, (np_, k, c, r[c], q[c])
        assert abs(float(b[held]["lambda_t"])) <= 1e-12 * l_scale
