# SPDX-License-Identifier: MIT
"""`mlcontact bench comm`: the PMPI library counts what the distributed mg sends,
and the counts follow the V-cycle's pattern in closed form:
- on 2 processes each has one neighbour, so a mat-vec sends 1 message, and a V-cycle from level
  p + j sends 4 j (per distributed level: the halo after the pre-sweep, R = T^T, T, the halo
  before the post-sweep);
- the coarse solve gathers level p's residual on every process: one Allgather of the counts (4
  bytes per process) and one Allgatherv of 8 bytes per unknown of level p, per V-cycle;
- a V-cycle and a mat-vec reduce nothing; CGS reduces a few scalars per iteration.
Without the library on N > 1 processes the bench refuses, naming the command; on one process it
measures times only.

Run by ctest as `/usr/bin/python3 -m pytest`; MLCONTACT is the driver, MPIEXEC the launcher,
PMPI_LIB the library.
"""
import json
import os
import subprocess

import pytest

MLCONTACT = os.environ["MLCONTACT"]
MPIEXEC = os.environ.get("MPIEXEC", "mpiexec")
PMPI_LIB = os.environ["PMPI_LIB"]
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def bench(tmp_path, np_, preload=True, levels=3, p=1, expect=0):
    out = tmp_path / f"comm_np{np_}.json"
    cmd = [MLCONTACT, "bench", "comm", "--levels", str(levels), "--partition-level", str(p),
           "--ops", "2", "--out", str(out)]
    env = dict(ENV)
    if np_ > 1:
        cmd = [MPIEXEC, "-n", str(np_), "--oversubscribe"] + (
            ["-x", f"LD_PRELOAD={PMPI_LIB}"] if preload else []) + cmd
    else:
        env["OMPI_MCA_ess_singleton_isolated"] = "1"
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == expect, r.stdout + r.stderr
    return (json.loads(out.read_text()) if expect == 0 else None), r


def ops(js):
    return {(o["name"], o["level"]): o for o in js["operations"]}


def test_two_processes_follow_the_v_cycle_pattern(tmp_path):
    js, _ = bench(tmp_path, 2, levels=3, p=1)
    assert js["counted"] and js["processes"] == 2 and js["partition_level"] == 1
    o = ops(js)
    assert o[("matvec", 3)]["max"]["p2p_messages"] == 1
    assert o[("matvec", 3)]["max"]["p2p_bytes"] > 0
    for level in (2, 3):
        v = o[("vcycle", level)]
        assert v["max"]["p2p_messages"] == 4 * (level - 1)
        assert v["mean"]["p2p_messages"] == 4 * (level - 1)
        assert v["max"]["reductions"] == 0
        assert v["max"]["gathers"] == 2
        assert v["max"]["gather_bytes"] == 8 * js["coarse_unknowns"] + 4 * 2
    # A finer level sends more bytes per halo than a coarser one.
    assert o[("vcycle", 3)]["max"]["p2p_bytes"] > 2 * o[("vcycle", 2)]["max"]["p2p_bytes"]
    assert o[("matvec", 3)]["max"]["reductions"] == 0
    assert o[("coarse_lu", 1)]["max"]["p2p_messages"] == 0
    cgs = o[("cgs", 3)]
    assert js["cgs_converged"] and 1 <= js["cgs_iterations"] <= 30
    # Per iteration: two V-cycles and two mat-vecs, and between 2 and 6 reductions.
    assert cgs["max"]["p2p_messages"] >= 2 * 8 + 2 * 1
    assert 2 <= cgs["max"]["reductions"] <= 6
    # Sizes: the level's unknowns are split between the processes.
    lv = {x["level"]: x for x in js["levels"]}
    assert lv[3]["owned_max"] < lv[3]["unknowns"] and 2 * lv[3]["owned_max"] >= lv[3]["unknowns"]


def test_three_processes_gather_the_coarse_level_once_per_cycle(tmp_path):
    js, _ = bench(tmp_path, 3, levels=3, p=1)
    o = ops(js)
    assert 1 <= o[("matvec", 3)]["max"]["p2p_messages"] <= 2
    v = o[("vcycle", 3)]
    assert v["max"]["gathers"] == 2
    assert v["max"]["gather_bytes"] == 8 * js["coarse_unknowns"] + 4 * 3
    assert v["max"]["reductions"] == 0


def test_without_the_library_several_processes_are_refused(tmp_path):
    _, r = bench(tmp_path, 2, preload=False, expect=1)
    assert "bench comm counts MPI traffic with the PMPI library" in r.stderr
    assert f"-x LD_PRELOAD={PMPI_LIB}" in r.stderr or "LD_PRELOAD=" in r.stderr


def test_one_process_measures_times_only(tmp_path):
    js, _ = bench(tmp_path, 1, levels=2, p=0)
    assert not js["counted"] and js["processes"] == 1
    o = ops(js)
    assert all(x["max"]["p2p_messages"] == 0 for x in js["operations"])
    assert o[("vcycle", 2)]["seconds"] > 0 and o[("matvec", 2)]["seconds"] > 0
