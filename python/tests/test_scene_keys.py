# SPDX-License-Identifier: MIT
"""The scene keys of transformed and tagged scenes from Python: the Scene reads them through the
C++ parser, exposes the supports with their activity per load step and the mesh's tags (boundary
and interior lines), and solves the built-in scenes that use them."""
import json

import pytest

import mlcontact
from conftest import run_cli


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


def _refined_square_msh(n):
    """A Gmsh 2.2 file of the unit square in n x n squares cut along "/" (n = 2^k: k uniform
    refinements of one square cut in two), boundary lines in physical groups."""
    nodes = [(i / n, j / n) for j in range(n + 1) for i in range(n + 1)]
    vid = lambda i, j: j * (n + 1) + i + 1
    lines = []
    for i in range(n):
        lines += [(1, vid(i, 0), vid(i + 1, 0)), (3, vid(i + 1, n), vid(i, n))]
        lines += [(2, vid(n, i), vid(n, i + 1)), (4, vid(0, i + 1), vid(0, i))]
    tris = []
    for j in range(n):
        for i in range(n):
            a, b, c, d = vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)
            tris += [(a, b, c), (a, c, d)]
    out = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$PhysicalNames", "5",
           '1 1 "bottom"', '1 2 "right"', '1 3 "top"', '1 4 "left"', '2 5 "body"',
           "$EndPhysicalNames", "$Nodes", str(len(nodes))]
    out += [f"{k + 1} {x!r} {y!r} 0" for k, (x, y) in enumerate(nodes)]
    out += ["$EndNodes", "$Elements", str(len(lines) + len(tris))]
    e = 0
    for tag, v0, v1 in lines:
        e += 1
        out.append(f"{e} 1 2 {tag} {tag} {v0} {v1}")
    for a, b, c in tris:
        e += 1
        out.append(f"{e} 2 2 5 1 {a} {b} {c}")
    out.append("$EndElements")
    return "\n".join(out) + "\n"


def _by_position(x, values):
    order = sorted(range(len(x)), key=lambda i: (x[i][0], x[i][1]))
    return [tuple(x[i]) for i in order], [values[i] for i in order]


def test_a_gmsh_mesh_that_is_a_uniform_refinement_is_read_with_its_levels(tmp_path):
    (tmp_path / "sq.msh").write_text(_refined_square_msh(16))
    text = """
[scene]
name = "pressed square"
load_steps = 2
[[body]]
E = 1.0
nu = 0.3
mesh = { type = "gmsh", file = "sq.msh" }
[[load]]
tag = "top"
pressure = 1e-3
[[load]]
tag = "left"
pressure = 3e-4
[[support]]
tag = "right"
ux = 0.0
[[contact]]
contactor = "bottom"
mu = 0.3
obstacle = { type = "line", point = [0.0, 0.0], normal = [0.0, 1.0] }
"""
    s = mlcontact.Scene.from_toml(text, "sq.toml", str(tmp_path))
    # 16 x 16 squares = four refinements of one square cut in two; levels count the file's
    # refinements (0 here), recovered_levels the ones found below it.
    assert s.recovered_levels == 4 and s.levels == 0 and s.n_triangles == 2
    flat = mlcontact.Scene.from_toml(text.replace("[scene]\n", "[scene]\nrecover_levels = false\n"),
                                     "sq.toml", str(tmp_path))
    assert flat.recovered_levels == 0 and flat.levels == 0 and flat.n_triangles == 512
    a, b = mlcontact.solve(s), mlcontact.solve(flat)
    assert a.converged and b.converged and a.level == 4 and b.level == 0
    # The same finest mesh in another numbering: every vertex's displacement and every contact
    # node's multipliers agree, matched by position.
    xa, ua = _by_position(a.vertices.tolist(), a.displacement.tolist())
    xb, ub = _by_position(b.vertices.tolist(), b.displacement.tolist())
    assert xa == xb
    umax = max(abs(c) for u in ub for c in u)
    assert max(abs(p - q) for u, v in zip(ua, ub) for p, q in zip(u, v)) < 1e-8 * umax
    ca, la = _by_position(a.contact_x.tolist(), a.lambda_n.tolist())
    cb, lb = _by_position(b.contact_x.tolist(), b.lambda_n.tolist())
    assert ca == cb and max(abs(p - q) for p, q in zip(la, lb)) < 1e-8 * max(abs(q) for q in lb)
    # The command line says so in its report and summary.json; --levels counts from the file.
    (tmp_path / "sq.toml").write_text(text)
    out = run_cli("run", str(tmp_path / "sq.toml"), "--out", str(tmp_path / "out")).stdout
    assert "the Gmsh file's mesh is level 4, a uniform refinement of a 2-triangle mesh" in out
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["recovered_levels"] == 4 and summary["levels"][-1]["level"] == 4
    run_cli("run", str(tmp_path / "sq.toml"), "--levels", "1", "--out", str(tmp_path / "out1"))
    summary = json.loads((tmp_path / "out1" / "summary.json").read_text())
    assert summary["levels"][-1]["level"] == 5
