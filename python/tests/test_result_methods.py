# SPDX-License-Identifier: MIT
"""Every method and property of a Result solved without options (no keep_steps): none crashes the
interpreter; each returns a sane value or raises a Python exception whose message says what to
do. Run in a child interpreter first, so that a crash (SIGSEGV) fails the test instead of
ending pytest."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

import mlcontact

# The members of Result, by what they need.
ARGUMENTS = {"step_state": [(1,), (0,), (10 ** 6,)], "write": None, "accuracy": [()],
             "report": [()]}


@pytest.fixture(scope="module")
def result():
    return mlcontact.solve(mlcontact.Scene.builtin("square"))


def members():
    return sorted(n for n in dir(mlcontact.Result) if not n.startswith("_"))


def test_no_member_crashes_the_interpreter(tmp_path):
    """Every member, called (with in-range and out-of-range arguments) or read in a child
    interpreter, which prints a line per member before touching it: a crash names the member."""
    code = """
import sys, mlcontact
r = mlcontact.solve(mlcontact.Scene.builtin("square"))
calls = eval(sys.argv[1])
for name, args in calls:
    print("member", name, args, flush=True)
    m = getattr(r, name)
    try:
        v = m(*args) if callable(m) else m
    except (ValueError, RuntimeError) as e:
        assert str(e), name
        print("raised", type(e).__name__, e, flush=True)
    else:
        print("returned", type(v).__name__, flush=True)
print("done", flush=True)
"""
    calls = []
    for name in members():
        if name == "write":
            calls.append((name, (str(tmp_path / "w"),)))
        else:
            calls += [(name, a) for a in ARGUMENTS.get(name, [()])]
    env = dict(os.environ, OMPI_MCA_ess_singleton_isolated="1")
    p = subprocess.run([sys.executable, "-c", code, repr(calls)], capture_output=True, text=True,
                       env=env, timeout=300)
    last = [line for line in p.stdout.splitlines() if line.startswith("member")][-1:]
    assert p.returncode == 0, f"exit {p.returncode} at {last}\n{p.stderr}"
    assert p.stdout.rstrip().endswith("done"), p.stdout
    assert p.stdout.count("member ") == len(calls)


def test_step_state_without_keep_steps_names_keep_steps(result):
    with pytest.raises(ValueError, match=r"keep_steps=True"):
        result.step_state(1)
    with pytest.raises(ValueError, match=r"keep_steps=True"):
        result.step_state(result.steps[-1]["step"])


def test_step_state_with_keep_steps_and_its_range():
    r = mlcontact.solve(mlcontact.Scene.builtin("square"), keep_steps=True)
    n = len(r.steps)
    last = r.step_state(n)
    assert np.array_equal(last["lambda_n"], r.lambda_n)
    assert np.array_equal(last["displacement"], r.displacement)
    for k in (0, n + 1):
        with pytest.raises(ValueError, match=rf"step must lie in \[1, {n}\].*found {k}"):
            r.step_state(k)


def test_every_member_of_a_result_solved_without_options(result, tmp_path):
    seen = set()
    for name in members():
        seen.add(name)
        m = getattr(result, name)
        if name == "step_state":
            continue  # above
        if name == "write":
            result.write(str(tmp_path / "w"))
            s = json.load(open(tmp_path / "w" / "summary.json"))
            assert s["complete"] is True and s["stopped"] is False
            assert sorted(s["files"]) == sorted(os.listdir(tmp_path / "w"))
            continue
        if name == "accuracy":
            try:
                v = result.accuracy()
            except ValueError as e:
                assert "square" in str(e) or "closed" in str(e), str(e)
            else:
                assert isinstance(v, list)
            continue
        v = m() if callable(m) else m
        if isinstance(v, np.ndarray):
            if v.dtype.kind == "f":
                assert np.isfinite(v).all(), name
            assert v.shape[0] in (result.vertices.shape[0], len(result.triangles),
                                  len(result.lambda_n), len(result.boundary_edges)), (name, v.shape)
        elif isinstance(v, float):
            assert np.isfinite(v), name
        elif name == "report":
            assert "scene      square" in v and "checks" in v
        elif name == "checks":
            assert v["force_balance"] < 1e-8
        else:
            assert v is not None or name in ("checks",), name
    assert {"step_state", "write", "report", "displacement", "lambda_n"} <= seen
