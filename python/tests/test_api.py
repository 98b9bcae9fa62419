# SPDX-License-Identifier: MIT
"""The Python module's API: scenes, parameters and their validation, solve() and its result
(numpy views of the C++ result, reports, checks), write(), the exception types, the studies."""
import json
import math
import os
import re

import numpy as np
import pytest

import mlcontact
from conftest import CLI, DATA, read_contact_csv, run_cli

SQUARE_TOML = mlcontact.Scene.builtin("square")  # parsed once; tests copy it


def square():
    return SQUARE_TOML.copy()


def test_version_is_the_drivers():
    out = run_cli("--version").stdout.strip()
    assert re.fullmatch(r"mlcontact \d+\.\d+\.\d+", out), out
    assert mlcontact.__version__ == out.split()[-1]


def test_builtin_scenes_and_parameters():
    names = mlcontact.Scene.builtin_names()
    assert "square" in names and "hertz" in names
    s = square()
    assert s.name == "square" and s.origin == "builtin:square"
    assert s.load_steps >= 1 and s.levels >= 0
    assert isinstance(s.mu, float) and s.mu == s.contacts[0]["mu"]
    assert s.r > 0
    assert s.materials[0]["E"] > 0 and 0 < s.materials[0]["nu"] < 0.5
    s.mu, s.r, s.levels, s.load_steps = 0.25, 1234.5, 2, 3
    assert (s.mu, s.r, s.levels, s.load_steps) == (0.25, 1234.5, 2, 3)
    assert s.contacts[0]["mu"] == 0.25 and s.contacts[0]["r"] == 1234.5
    s.set_material(0, E=2.0e5, nu=0.25)
    assert s.materials[0]["E"] == 2.0e5 and s.materials[0]["nu"] == 0.25
    s.set_contact(0, mu=0.4)
    assert s.mu == 0.4
    assert SQUARE_TOML.mu != 0.4  # copies are independent


def test_unknown_builtin_names_the_choices():
    with pytest.raises(ValueError, match=r"no_such_scene.*square"):
        mlcontact.Scene.builtin("no_such_scene")


@pytest.mark.parametrize("key, value, pattern", [
    ("mu", -0.1, r"^mu: .*mu must be >= 0"),
    ("mu", float("nan"), r"^mu must be a finite number"),
    ("r", 0.0, r"^r: .*r must be > 0"),
    ("levels", 13, r"^levels: .*levels must lie in \[0, 12\]"),
    ("levels", -1, r"^levels: "),
    ("load_steps", 0, r"^load_steps: .*at least 1"),
])
def test_bad_parameter_value_names_the_key_and_changes_nothing(key, value, pattern):
    s = square()
    before = getattr(s, key)
    with pytest.raises(ValueError, match=pattern):
        setattr(s, key, value)
    assert getattr(s, key) == before


def test_bad_material_names_e_or_nu():
    s = square()
    with pytest.raises(ValueError, match=r"^nu: .*Poisson's ratio nu"):
        s.set_material(0, nu=0.6)
    with pytest.raises(ValueError, match=r"^E: .*Young's modulus E"):
        s.set_material(0, E=-1.0)
    assert s.materials == SQUARE_TOML.materials
    with pytest.raises(ValueError, match="no body named 'nope'"):
        s.set_material("nope", E=1.0)


def test_wrong_types_are_value_errors_naming_the_key():
    s = square()
    with pytest.raises(ValueError, match=r"^mu: 'high' is not a number"):
        s.mu = "high"
    with pytest.raises(ValueError, match=r"^levels: 2.5 is not a whole number"):
        s.levels = 2.5
    with pytest.raises(ValueError, match=r"^levels: .3. is not an int"):
        mlcontact.solve(s, levels="3")
    with pytest.raises(ValueError, match=r"^pc: 3 is not a str"):
        mlcontact.solve(s, pc=3)
    r = mlcontact.solve(s, levels=np.int64(0), mu=np.float64(0.25), load_steps=np.int32(2))
    assert r.level == 0 and len(r.steps) == 2
    with pytest.raises(AttributeError):  # read-only
        s.name = "other"
    assert s.mu == SQUARE_TOML.mu and s.levels == SQUARE_TOML.levels


def test_unknown_parameter_is_a_value_error_naming_it():
    s = square()
    with pytest.raises(ValueError, match=r"unknown scene parameter 'friction'"):
        s.friction = 0.3
    with pytest.raises(AttributeError):  # the same exception, also an AttributeError
        s.friction = 0.3


def test_toml_errors_name_key_file_and_line(tmp):
    text = mlcontact.Scene.builtin("square")  # noqa: F841 (the text of the built-in is valid)
    bad_key = '[scene]\nname = "x"\nfriction = 0.3\n'
    with pytest.raises(ValueError, match=r"<string>:3: unknown key 'friction' in \[scene\]"):
        mlcontact.Scene.from_toml(bad_key)
    path = tmp / "bad_mu.toml"
    lines = open(os.path.join(DATA, "nonconvergent.toml")).read().splitlines()
    n = next(i for i, line in enumerate(lines) if line.startswith("mu = "))
    lines[n] = "mu = -1.0"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError) as e:
        mlcontact.Scene.from_file(str(path))
    assert str(e.value).startswith(f"{path}:{n + 1}: "), str(e.value)
    assert "mu must be >= 0" in str(e.value)
    with pytest.raises(ValueError, match="cannot open scene file"):
        mlcontact.Scene.from_file(str(tmp / "missing.toml"))


def test_from_file_and_from_toml_agree_with_builtin(tmp):
    text = run_cli("show", "square").stdout
    path = tmp / "square.toml"
    path.write_text(text)
    a, b = mlcontact.Scene.from_file(str(path)), mlcontact.Scene.from_toml(text)
    for s in (a, b):
        assert (s.name, s.mu, s.r, s.load_steps, s.levels) == (
            SQUARE_TOML.name, SQUARE_TOML.mu, SQUARE_TOML.r, SQUARE_TOML.load_steps, SQUARE_TOML.levels)
    assert a.origin == str(path)


@pytest.fixture(scope="module")
def result():
    return mlcontact.solve(square(), levels=1)


def test_result_arrays_are_views_of_the_library_result(result):
    r = result
    nv = r.vertices.shape[0]
    assert r.vertices.shape == (nv, 2) and r.displacement.shape == (nv, 2)
    assert r.triangles.shape[1] == 3 and r.triangles.dtype == np.int32
    assert r.triangles.min() == 0 and r.triangles.max() == nv - 1
    k = r.lambda_n.shape[0]
    assert k > 0 and r.contact_x.shape == (k, 2) and r.status.shape == (k,) and r.lambda_t.shape == (k,)
    for name in ["vertices", "triangles", "displacement", "contact_x", "lambda_t", "lambda_n", "status"]:
        a, b = getattr(r, name), getattr(r, name)
        # Two reads are two views of one buffer (a copy would not share), owned by the Result.
        assert np.shares_memory(a, b), name
        assert a.base is r, name
        assert not a.flags.writeable, name
    # The contact arrays are strided views into the same C++ node states.
    assert np.may_share_memory(r.contact_x, r.lambda_n)
    assert not np.shares_memory(r.contact_x, r.lambda_n)
    v = r.vertices
    del r  # the views keep the result alive
    assert np.isfinite(v).all()


def test_result_equals_the_driver_and_write_writes_its_files(result, tmp):
    cli = tmp / "cli"
    run_cli("run", "square", "--levels", "1", "--quiet", "--out", str(cli))
    py = tmp / "py"
    result.write(str(py))
    assert sorted(os.listdir(py)) == sorted(os.listdir(cli))
    for name in os.listdir(cli):  # every file but summary.json (times, peak memory) is identical
        if name != "summary.json":
            assert (py / name).read_bytes() == (cli / name).read_bytes(), name
    c = read_contact_csv(cli / "contact.csv")
    assert np.array_equal(result.lambda_n, c["lambda_n"]) and np.array_equal(result.lambda_t, c["lambda_t"])
    assert np.array_equal(result.contact_x[:, 0], c["x"]) and np.array_equal(result.contact_u[:, 1], c["uy"])
    assert [mlcontact.STATUS_NAMES[s] for s in result.status] == c["status"]
    a, b = json.load(open(py / "summary.json")), json.load(open(cli / "summary.json"))
    for key in ["scene", "level", "unknowns", "contact_nodes", "checks", "contacts", "solver", "total_newton_iterations"]:
        assert a[key] == b[key], key
    for sa, sb in zip(a["steps"], b["steps"]):
        for key in ["newton_iterations", "linear_iterations", "residuals", "statuses", "load_factor"]:
            assert sa[key] == sb[key], key
    assert [tuple(d["force"]) for d in result.resultants] == [tuple(d["resultant"]) for d in b["contacts"]]


def test_reports_and_checks(result):
    r = result
    assert r.converged and r.failure == "" and r.level == 1
    steps = r.steps
    assert len(steps) == SQUARE_TOML.load_steps
    for k, s in enumerate(steps):
        # The square's statuses do not change after step 1: steps 2.. are linear, and the
        # extrapolated state is already converged (SolveOptions::extrapolate).
        assert s["converged"] and (s["newton_iterations"] >= 1) == (k == 0)
        assert s["residuals"][-1] <= 1e-10 and len(s["residuals"]) == s["newton_iterations"] + 1
        assert sum(s["statuses"].values()) == r.lambda_n.shape[0]
        assert s["seconds"] > 0
    assert [lv["level"] for lv in r.levels] == [0, 1]
    fine = r.levels[1]
    assert fine["contact_nodes"] == r.lambda_n.shape[0]
    for k, st in enumerate(fine["steps"]):
        # Steps 2.. start from the extrapolated state, not from the coarse prediction.
        assert st["predicted"] == (k == 0) and st["confusion"].shape == (4, 4)
        if not st["predicted"]:
            assert st["confusion"].sum() == 0
            continue
        assert st["confusion"].sum() == fine["contact_nodes"]
        assert 0 <= st["agreement"] <= 1
        assert st["agreement"] == pytest.approx(np.trace(st["confusion"]) / fine["contact_nodes"])
    ch = r.checks
    assert ch["force_balance"] < 1e-8 and ch["coulomb_excess"] < 1e-8
    assert r.solver["method"] in ("schur", "lu", "krylov") and r.solver["reason"]
    assert "newton/linear_solve" in r.timings
    assert "checks (relative)" in r.report()


def test_tractions_along_the_contact_boundary(result):
    t = result.tractions()
    assert list(t) == result.contact_pair_names
    d = t[result.contact_pair_names[0]]
    assert len(d["nodes"]) == result.lambda_n.shape[0]
    assert np.all(np.diff(d["s"]) > 0) and d["s"][0] == 0
    # The pressure integrates to the normal force: sum p l = -sum lambda_n, l = tributary length.
    x = d["x"][:, 0]
    l = np.zeros(len(x))
    l[1:] += 0.5 * np.diff(x)
    l[:-1] += 0.5 * np.diff(x)
    assert np.sum(d["pressure"] * l) == pytest.approx(-np.sum(result.lambda_n), rel=1e-12)
    gap = d["status"] == mlcontact.GAP
    assert np.all(d["pressure"][~gap] > 0)


def test_bad_solve_options_raise_value_error():
    s = square()
    with pytest.raises(ValueError, match="solver must be schur, lu or krylov, found 'cholesky'"):
        mlcontact.solve(s, solver="cholesky")
    with pytest.raises(ValueError, match="^levels= must lie in"):
        mlcontact.solve(s, levels=-1)
    with pytest.raises(ValueError, match="^mu= must be >= 0"):
        mlcontact.solve(s, mu=-1.0)
    with pytest.raises(ValueError, match="mg needs the level below"):
        mlcontact.solve(s, levels=0, solver="krylov", pc="mg:coarse=galerkin")
    with pytest.raises(TypeError):
        mlcontact.solve("square")
    with pytest.raises(ValueError, match="numbering= must be hilbert or lattice, found 'spiral'"):
        mlcontact.solve(s, numbering="spiral")


def test_default_solver_sweeps_by_lattices_from_level_4_and_numbering_hilbert_keeps_blocks():
    # The default at level 4: mg with the lattice sweep on levels numbered by macro triangle;
    # numbering="hilbert" keeps the block sweep. Same contact solution to 1e-8 (the Newton
    # statuses and the discrete solution do not depend on the numbering or the smoother).
    s = square()
    a = mlcontact.solve(s, levels=4)
    b = mlcontact.solve(s, levels=4, numbering="hilbert")
    assert a.solver["automatic"] and b.solver["automatic"]
    assert a.solver["numbering"] == "lattice" and a.solver["pc"] == "mg:pre=0,post=2,smoother=lattice"
    assert b.solver["numbering"] == "hilbert" and b.solver["pc"] == "mg:pre=0,post=2"
    assert (a.vertices == b.vertices).all()  # the mesh's vertex order, whatever the numbering
    umax = abs(b.displacement).max()
    assert abs(a.displacement - b.displacement).max() < 1e-8 * umax
    assert abs(a.lambda_n - b.lambda_n).max() < 1e-8 * abs(b.lambda_n).max()
    assert (a.status == b.status).all()
    # Level 3: no lattice levels, the Hilbert numbering and the block sweep.
    c = mlcontact.solve(s, levels=3)
    assert c.solver["numbering"] == "hilbert" and c.solver["pc"] == "mg:pre=0,post=2"


def test_not_converged_carries_the_report():
    s = mlcontact.Scene.from_file(os.path.join(DATA, "nonconvergent.toml"))
    assert issubclass(mlcontact.NotConverged, RuntimeError)
    assert issubclass(mlcontact.SolverBreakdown, RuntimeError)
    with pytest.raises(mlcontact.NotConverged, match=r"load step 1 .*did not converge") as e:
        mlcontact.solve(s)
    r = e.value.result
    assert not r.converged and not r.steps[-1]["converged"] and r.checks is None
    assert "no conv" in e.value.report
    r2 = mlcontact.solve(s, raise_on_failure=False)
    assert not r2.converged and r2.failure == r.failure
    with pytest.raises(ValueError, match="did not converge"):
        r2.write("unused")


def test_step_states_and_accuracy_of_patch():
    r = mlcontact.solve(mlcontact.Scene.builtin("patch"), levels=1, keep_steps=True)
    st = r.step_state(len(r.steps))
    assert np.array_equal(st["lambda_n"], r.lambda_n)
    with pytest.raises(ValueError, match="step must lie in"):
        r.step_state(0)
    acc = {v["name"]: v for v in r.accuracy()}
    study = mlcontact.study_accuracy(mlcontact.Scene.builtin("patch"), levels=1, compare_integration=False)
    table = study["accuracy_csv"]
    assert study["exit_code"] == 0 and "pressure_max" in study["report"]
    rows = [i for i, lv in enumerate(table["level"]) if lv == 1]
    assert rows
    for i in rows:
        q = table["quantity"][i]
        assert q in acc
        if math.isfinite(acc[q]["value"]):
            assert table["value"][i] == pytest.approx(acc[q]["value"], rel=1e-12, abs=1e-300)
    with pytest.raises(ValueError, match="closed forms"):
        mlcontact.solve(square(), levels=0).accuracy()


def test_status_transfer_study_tables(tmp):
    st = mlcontact.study_status_transfer(square(), levels=1, out=str(tmp / "st"))
    assert st["exit_code"] == 0 and "newton/step warm" in st["report"]
    t = st["status_transfer_csv"]
    assert set(t["level"]) == {0.0, 1.0}
    assert len(t["step"]) == 2 * SQUARE_TOML.load_steps
    assert np.all(t["newton_warm"] >= 1) and np.all(t["newton_cold"] >= 1)
    assert "levels" in st["status_transfer_json"] or st["status_transfer_json"]
    assert os.path.exists(tmp / "st" / "statuses.csv")
    with pytest.raises(ValueError, match="q_rule must be"):
        mlcontact.study_status_transfer(square(), levels=1, q_rule="nope")


def test_extrapolation_off_solves_every_step_by_newton_to_the_same_state(result):
    plain = mlcontact.solve(square(), levels=1, extrapolate=False)
    assert all(s["newton_iterations"] >= 1 for s in plain.steps)
    assert result.steps[0]["newton_iterations"] == plain.steps[0]["newton_iterations"]
    assert sum(s["newton_iterations"] for s in result.steps[1:]) == 0
    scale = np.abs(plain.displacement).max()
    assert np.abs(result.displacement - plain.displacement).max() <= 1e-12 * scale
    assert np.abs(result.lambda_n - plain.lambda_n).max() <= 1e-9 * np.abs(plain.lambda_n).max()
