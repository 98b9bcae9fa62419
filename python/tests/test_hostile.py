# SPDX-License-Identifier: MIT
"""Hostile input from Python: every hostile scene of the C++ tests (tests/data/hostile/*.toml, read
by tests/apps/test_hostile_scene.cpp too, with its "# expect:" line), the bad scenes of
tests/data and the fuzz seed corpus give a ValueError (or parse, when valid; or, for the scenes
whose solve must name a cause, "not converged: text" / "solves: text", are solved and give that
failure or report text) - in a child process with a time limit, so that a crash or a hang fails
the test instead of the suite."""
import glob
import json
import os
import subprocess
import sys

import pytest

from conftest import DATA, ENV, SOURCE

HOSTILE = sorted(glob.glob(os.path.join(DATA, "hostile", "*.toml")))
CORPUS = sorted(glob.glob(os.path.join(SOURCE, "tests", "fuzz", "corpus", "scene", "*")))

CHILD = r"""
import json, sys, time
import mlcontact
path, how = sys.argv[1], sys.argv[2]
t0 = time.monotonic()
try:
    if how == "file":
        s = mlcontact.Scene.from_file(path)
    else:
        s = mlcontact.Scene.from_toml(open(path, errors="replace").read(), origin=path)
    out = {"outcome": "valid", "triangles": s.n_triangles}
    if len(sys.argv) > 3:  # solve it too
        r = mlcontact.solve(s, raise_on_failure=False)
        out.update(converged=r.converged, failure=r.failure, report=r.report(),
                   warnings=list(r.warnings), checks=r.checks)
except ValueError as e:
    out = {"outcome": "ValueError", "message": str(e)}
except Exception as e:
    out = {"outcome": type(e).__name__, "message": str(e)}
out["seconds"] = time.monotonic() - t0
print(json.dumps(out))
"""


def parse_in_child(path, how, solve=False):
    p = subprocess.run([sys.executable, "-c", CHILD, path, how] + (["solve"] if solve else []),
                       capture_output=True, text=True, env=ENV, timeout=60)
    assert p.returncode == 0, f"the child crashed ({p.returncode}): {p.stderr[-2000:]}"
    return json.loads(p.stdout.strip().splitlines()[-1])


def expectation(path):
    for line in open(path):
        if line.startswith("# expect: "):
            what = line[len("# expect: "):].strip()
            if what.startswith("valid: "):
                return "valid", int(what[len("valid: "):].split()[0])
            for kind in ("not converged", "solves"):  # parses; the solve names the cause
                if what.startswith(kind + ": "):
                    return kind, what[len(kind) + 2:]
            assert what.startswith("invalid"), line
            return "invalid", what[len("invalid: "):] if what.startswith("invalid: ") else ""
    raise AssertionError(f"{path} has no '# expect:' line")


def test_the_shared_files_are_there():
    names = {os.path.basename(p) for p in HOSTILE}
    assert {"rectangle_too_large.toml", "gmsh_from_a_device.toml", "thin_strip.toml"} <= names
    assert CORPUS


@pytest.mark.parametrize("how", ["file", "toml"])
@pytest.mark.parametrize("path", HOSTILE, ids=os.path.basename)
def test_hostile_scene(path, how):
    kind, detail = expectation(path)
    out = parse_in_child(path, how, solve=kind in ("not converged", "solves"))
    if kind == "valid":
        assert out["outcome"] == "valid", out
        assert out["triangles"] == detail
    elif kind == "not converged":
        assert out["outcome"] == "valid" and not out["converged"], out
        assert detail in out["failure"], out["failure"]
    elif kind == "solves":
        assert out["outcome"] == "valid" and out["converged"], out
        assert detail in out["report"], out["report"]
        if detail.startswith("warning: "):
            assert any(detail[len("warning: "):] in w for w in out["warnings"]), out["warnings"]
        if "n/a (no force to balance)" in detail:
            assert out["checks"]["force_balance"] is None
    else:
        assert out["outcome"] == "ValueError", out
        assert detail in out["message"]
        assert path in out["message"], out["message"]  # names the file
    assert out["seconds"] < 10


def test_bad_poisson_names_nu_file_and_line():
    path = os.path.join(DATA, "bad_poisson.toml")
    out = parse_in_child(path, "file")
    assert out["outcome"] == "ValueError"
    assert out["message"].startswith(path + ":") and "Poisson's ratio nu must lie in" in out["message"]


@pytest.mark.parametrize("path", CORPUS, ids=os.path.basename)
def test_fuzz_seed_parses_or_is_a_value_error(path):
    out = parse_in_child(path, "file")
    assert out["outcome"] in ("valid", "ValueError"), out
    assert out["seconds"] < 10


def test_warnings_and_not_applicable_checks_reach_summary_json(tmp):
    import mlcontact
    rolls = mlcontact.solve(mlcontact.Scene.from_file(os.path.join(DATA, "hostile", "half_cylinder_rolls.toml")))
    assert len(rolls.warnings) == 1 and rolls.warnings[0].startswith("large rotation: triangle ")
    rolls.write(str(tmp / "rolls"))
    summary = json.load(open(tmp / "rolls" / "summary.json"))
    assert summary["warnings"] == rolls.warnings
    assert summary["checks"]["force_balance_applicable"] is True
    apart = mlcontact.solve(mlcontact.Scene.from_file(os.path.join(DATA, "hostile", "bodies_apart.toml")))
    # Apart by 0.5, a fifth of the lid's size: the initial-gap warning, and no other.
    assert len(apart.warnings) == 1 and apart.warnings[0].startswith("contact 'contact1': initial gap 0.5")
    assert apart.checks["force_balance"] is None
    apart.write(str(tmp / "apart"))
    summary = json.load(open(tmp / "apart" / "summary.json"))
    assert summary["warnings"] == apart.warnings
    assert summary["checks"]["force_balance_applicable"] is False and "force_balance" not in summary["checks"]
