# SPDX-License-Identifier: MIT
"""Meshing that cannot be bounded or stopped, and meshes that lie (tests/data/mesh): a size field
of some 10^10 triangles is refused before meshing; SIGTERM or SIGINT while a scene's domain is
meshed stops `mlcontact run` within 5 s (exit 143 / 130, nothing written), and Ctrl-C raises
KeyboardInterrupt in Scene.from_file; meshes with a duplicated element or a hanging node are a
ValueError naming the elements; an initial penetration of a third of a body is a warning in
summary.json."""
import json
import os
import signal
import subprocess
import time

import pytest

import mlcontact
from conftest import CLI, DATA, ENV, PYTHON, run_cli

MESH = os.path.join(DATA, "mesh")
LONG = os.path.join(MESH, "hertz_long.toml")


def test_size_prediction_refuses_at_once():
    t0 = time.monotonic()
    with pytest.raises(ValueError) as e:
        mlcontact.Scene.from_file(os.path.join(MESH, "hertz_fine.toml"))
    msg = str(e.value)
    assert "the mesh is predicted at about" in msg and "e+10 triangles" in msg, msg
    assert "max_size = 1e-05, min_size = 1e-05" in msg and "raise min_size and max_size" in msg, msg
    assert time.monotonic() - t0 < 5


@pytest.mark.parametrize("sig,code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_signal_stops_the_meshing_of_a_run(tmp, sig, code):
    out = tmp / "out"
    p = subprocess.Popen([CLI, "run", LONG, "--out", str(out)], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=ENV)
    try:
        time.sleep(2.0)
        assert p.poll() is None, "the meshing ended before the signal: make it longer"
        sent = time.monotonic()
        p.send_signal(sig)
        stdout, stderr = p.communicate(timeout=30)
        elapsed = time.monotonic() - sent
    finally:
        if p.poll() is None:
            p.kill()
    assert p.returncode == code, f"exit {p.returncode}\n{stdout}\n{stderr}"
    assert elapsed < 5.0, f"stopped {elapsed:.1f} s after the signal"
    name = "SIGTERM" if sig == signal.SIGTERM else "SIGINT"
    assert f"stopped by {name} while meshing the scene (meshing stopped on request after" in stdout
    assert not out.exists()


CHILD = r"""
import sys, time
import mlcontact
print("meshing", flush=True)
t0 = time.monotonic()
try:
    mlcontact.Scene.from_file(sys.argv[1])
    print("finished after", time.monotonic() - t0, flush=True)
    sys.exit(0)
except KeyboardInterrupt:
    print("KeyboardInterrupt after", time.monotonic() - t0, flush=True)
    s = mlcontact.Scene.builtin("hertz")  # the module is usable afterwards
    print("then meshed", s.origin, flush=True)
    sys.exit(42)
"""


def test_ctrl_c_in_scene_from_file():
    p = subprocess.Popen([PYTHON, "-c", CHILD, LONG], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True, env=ENV)
    try:
        assert p.stdout.readline().strip() == "meshing"
        time.sleep(2.0)
        assert p.poll() is None, "the meshing ended before the signal: make it longer"
        sent = time.monotonic()
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=30)
        elapsed = time.monotonic() - sent
    finally:
        if p.poll() is None:
            p.kill()
    assert p.returncode == 42, f"exit {p.returncode}\n{out}\n{err}"
    assert elapsed < 5.0, f"KeyboardInterrupt came {elapsed:.1f} s after SIGINT"
    assert "then meshed builtin:hertz" in out


@pytest.mark.parametrize("name,text", [
    ("hertz_gmsh_duplicate.toml", "hertz_gmsh_duplicate.msh: duplicated element: triangle"),
    ("t_junction.toml", "t_junction.msh: hanging node (T-junction): vertex 9 (1, 0.5) lies inside the edge"),
])
def test_meshes_that_lie_are_refused(name, text):
    with pytest.raises(ValueError) as e:
        mlcontact.Scene.from_file(os.path.join(MESH, name))
    assert text in str(e.value)


def test_initial_penetration_is_a_warning_in_summary_json(tmp):
    scene = os.path.join(DATA, "hostile", "bodies_overlap_half.toml")
    p = run_cli("run", scene, "--quiet", "--out", str(tmp / "overlap"))
    assert "warning: contact 'interface': initial penetration 0.5" in p.stdout
    summary = json.load(open(tmp / "overlap" / "summary.json"))
    # The penetration warning first (it is found on level 0, before the solve); pushed out by
    # half its height, the body also strains by 0.3, which the large-strain warning names.
    assert len(summary["warnings"]) == 2, summary["warnings"]
    assert summary["warnings"][0].startswith("contact 'interface': initial penetration 0.5 at the contact node")
    assert summary["warnings"][1].startswith("large strain: triangle ")
    # A scene that starts in contact has none.
    run_cli("run", "square", "--quiet", "--out", str(tmp / "square"))
    assert json.load(open(tmp / "square" / "summary.json"))["warnings"] == []
