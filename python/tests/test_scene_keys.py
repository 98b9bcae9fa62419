# SPDX-License-Identifier: MIT
"""The scene keys of issue 16 from Python: the Scene reads them through the C++ parser, exposes
the supports with their activity per load step and the mesh's tags (boundary and interior lines),
and solves the built-in scenes that use them."""
import pytest

import mlcontact


def test_axis_release_supports_and_interior_line_tags():
    s = mlcontact.Scene.builtin("axis_release")
    axis = [d for d in s.supports if d["tag"] == "cylinder_axis"]
    assert len(axis) == 1 and axis[0]["ux"] == 0.0 and axis[0]["uy"] is None
    assert axis[0]["active"] == [True, False]
    bottom = [d for d in s.supports if d["tag"] == "block_bottom"][0]
    assert bottom["active"] == [True, True]
    tags = s.mesh_tags
    assert "cylinder_axis" in tags["line_tags"] and "block_axis" in tags["line_tags"]
    assert "cylinder_axis" not in tags["boundary_tags"] and "surface" in tags["boundary_tags"]
    # active is per point of the loading path: 4 steps on the 2-point path hold it in 1 and 2.
    s.load_steps = 4
    assert [d for d in s.supports if d["tag"] == "cylinder_axis"][0]["active"] == [
        True, True, False, False]


def test_axis_release_and_incline_solve():
    r = mlcontact.solve(mlcontact.Scene.builtin("axis_release"), levels=0)
    assert r.converged
    fx, fy = r.resultants[0]["force"]
    # Step 2: the contact holds the pressure (P = 4.32e-3) and the traction (Q = 6.48e-4).
    assert fx == pytest.approx(-6.48e-4, rel=1e-9) and fy == pytest.approx(4.32e-3, rel=1e-9)
    r = mlcontact.solve(mlcontact.Scene.builtin("incline"), levels=1)
    fx, fy = r.resultants[0]["force"]
    assert fx == pytest.approx(-0.5 * 2e-3 * 0.8191520442889918, rel=1e-9)
    assert fy == pytest.approx(2e-3 * 0.8191520442889918, rel=1e-9)


def test_hertz_gmsh_has_its_arc_and_runs_without_the_source_tree():
    s = mlcontact.Scene.builtin("hertz_gmsh")
    assert s.n_vertices == 171 and s.mesh_tags["circles"] == 1
    r = mlcontact.solve(s, levels=1)
    assert r.converged


def test_new_keys_are_validated():
    base = """
[scene]
name = "x"
[[body]]
E = 1.0
nu = 0.3
mesh = { type = "rectangle", corner = [0, 0], size = [1, 1], divisions = [2, 2], transform = T }
"""
    with pytest.raises(ValueError, match=r"transform must be a table, found a string"):
        mlcontact.Scene.from_toml(base.replace("T", '"rotate"'))
    with pytest.raises(ValueError, match=r"unknown key 'shear'"):
        mlcontact.Scene.from_toml(base.replace("T", "{ shear = 1.0 }"))
    s = mlcontact.Scene.from_toml(base.replace("T", "{ rotate_deg = 90.0, translate = [1, 0] }"))
    assert s.n_vertices == 9
