# SPDX-License-Identifier: MIT
"""The files of `mlcontact run` read by a reader written by nobody here: VTK's own Python
module (Debian python3-vtk9) opens the binary solution.vtu, every step of solution.pvd and the
per-level collections, and finds the arrays, sizes and values of contact.csv and
contact_steps.csv. Also: gap multipliers are exactly 0 everywhere, contact_steps.csv's pressure
and traction against the multipliers and the summary's resultant, and SIGTERM / SIGINT during a
run (exit 143 / 130, the step named, every file left readable, no temporary).

Run by ctest as `/usr/bin/python3 -m pytest`; MLCONTACT is the driver to test.
"""
import csv
import glob
import json
import os
import signal
import subprocess
import time
import xml.etree.ElementTree as ET

import pytest
import vtk
from vtk.util.numpy_support import vtk_to_numpy

MLCONTACT = os.environ.get("MLCONTACT", "mlcontact")
STATUS_CODE = {"gap": 0, "stick": 1, "slip_forward": 2, "slip_backward": 3}
ENV = dict(os.environ, OMPI_MCA_ess_singleton_isolated="1")


def run(*args, check=True):
    p = subprocess.run([MLCONTACT, "run", *args], capture_output=True, text=True, env=ENV)
    if check:
        assert p.returncode == 0, p.stdout + p.stderr
    return p


def read_vtu(path):
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(str(path))
    r.Update()
    assert r.GetErrorCode() == 0, f"VTK could not read {path}"
    g = r.GetOutput()
    assert g.GetNumberOfPoints() > 0, f"{path}: no points"
    return g


def arrays(g):
    out = {}
    for data in (g.GetPointData(), g.GetCellData()):
        for i in range(data.GetNumberOfArrays()):
            out[data.GetArrayName(i)] = vtk_to_numpy(data.GetArray(i))
    out["points"] = vtk_to_numpy(g.GetPoints().GetData())
    return out


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def point_index(a):
    """(x, y) of each point -> index (coordinates are written bit for bit)."""
    return {(float(p[0]), float(p[1])): i for i, p in enumerate(a["points"])}


def check_state(a, rows):
    """The VTU arrays hold, at each contact node of `rows` (contact.csv or one step of
    contact_steps.csv), exactly the row's displacement, multipliers and status."""
    at = point_index(a)
    assert len(rows) > 0
    for r in rows:
        v = at[(float(r["x"]), float(r["y"]))]
        assert a["displacement"][v][0] == float(r["ux"])
        assert a["displacement"][v][1] == float(r["uy"])
        assert a["displacement"][v][2] == 0.0
        assert a["lambda_t"][v] == float(r["lambda_t"])
        assert a["lambda_n"][v] == float(r["lambda_n"])
        assert a["contact_status"][v] == STATUS_CODE[r["status"]]
        if r["status"] == "gap":
            assert float(r["lambda_t"]) == 0.0 and float(r["lambda_n"]) == 0.0
            assert a["contact_force"][v][0] == 0.0 and a["contact_force"][v][1] == 0.0
    # Off the contact boundary: status -1, no multipliers.
    contact = {at[(float(r["x"]), float(r["y"]))] for r in rows}
    others = [i for i in range(len(a["lambda_n"])) if i not in contact]
    assert all(a["contact_status"][i] == -1 for i in others)
    assert all(a["lambda_n"][i] == 0.0 for i in others)


def pvd_entries(path):
    root = ET.parse(path).getroot()
    assert root.get("type") == "Collection"
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


@pytest.fixture(scope="module")
def square(tmp_path_factory):
    """The square on level 2 with 5 load steps, binary, every step and every level."""
    d = tmp_path_factory.mktemp("square")
    p = run("square", "--levels", "2", "--every-step", "--every-level", "--plot", "--out", str(d))
    return d, p.stdout


def test_binary_vtu_read_by_vtk_has_the_values_of_contact_csv(square):
    d, _ = square
    head = open(d / "solution.vtu", "rb").read(400).decode("ascii", "replace")
    assert 'header_type="UInt64"' in head and 'compressor="vtkZLibDataCompressor"' in head
    assert 'format="appended"' in head and 'format="ascii"' not in head
    summary = json.load(open(d / "summary.json"))
    g = read_vtu(d / "solution.vtu")
    assert g.GetNumberOfPoints() == summary["vertices"] == 65 * 65
    assert g.GetNumberOfCells() == summary["triangles"] == 2 * 64 * 64
    a = arrays(g)
    nv, nt = summary["vertices"], summary["triangles"]
    assert a["displacement"].shape == (nv, 3)
    assert a["contact_force"].shape == (nv, 3)
    for name in ("contact_status", "lambda_t", "lambda_n"):
        assert a[name].shape == (nv,)
    assert a["stress"].shape == (nt, 3)
    assert a["von_mises"].shape == (nt,) and a["body"].shape == (nt,)
    rows = read_csv(d / "contact.csv")
    assert len(rows) == summary["contact_nodes"] == 64  # 65 bottom vertices, the corner fixed
    check_state(a, rows)
    statuses = {r["status"] for r in rows}
    assert "gap" in statuses and "slip_forward" in statuses  # the square lifts off at its left
    assert a["stress"][:, 1].min() < 0  # compressed vertically


def test_ascii_holds_the_same_arrays(square, tmp_path):
    d, _ = square
    run("square", "--levels", "2", "--vtu", "ascii", "--quiet", "--out", str(tmp_path))
    head = open(tmp_path / "solution.vtu").read(2000)
    assert 'format="ascii"' in head and "appended" not in head
    b, t = arrays(read_vtu(d / "solution.vtu")), arrays(read_vtu(tmp_path / "solution.vtu"))
    assert b.keys() == t.keys()
    for k in b:
        assert (b[k] == t[k]).all(), k
    assert os.path.getsize(d / "solution.vtu") < os.path.getsize(tmp_path / "solution.vtu")


def test_every_step_of_the_pvd_has_the_values_of_contact_steps_csv(square):
    d, _ = square
    steps = read_csv(d / "contact_steps.csv")
    entries = pvd_entries(d / "solution.pvd")
    assert [t for t, _ in entries] == [k / 5 for k in range(1, 6)]
    assert [f for _, f in entries] == [f"solution_step_{k:04d}.vtu" for k in range(1, 6)]
    for k, (s, f) in enumerate(entries, start=1):
        a = arrays(read_vtu(d / f))
        rows = [r for r in steps if int(r["step"]) == k]
        assert len(rows) == 64 and all(float(r["s"]) == s for r in rows)
        check_state(a, rows)
    # The last step is the final state: the same arrays as solution.vtu.
    last, final = arrays(read_vtu(d / entries[-1][1])), arrays(read_vtu(d / "solution.vtu"))
    for k in final:
        assert (last[k] == final[k]).all(), k
    # The states differ between steps (the load grows).
    first = arrays(read_vtu(d / entries[0][1]))
    assert abs(first["displacement"]).max() < abs(last["displacement"]).max()


def test_every_level_writes_a_collection_per_level(square):
    d, _ = square
    for level, n in ((0, 17 * 17), (1, 33 * 33)):
        entries = pvd_entries(d / f"solution_level_{level}.pvd")
        assert [t for t, _ in entries] == [k / 5 for k in range(1, 6)]
        for _, f in entries:
            g = read_vtu(d / f)
            assert g.GetNumberOfPoints() == n
            a = arrays(g)
            assert (a["contact_status"] >= 0).sum() == (n ** 0.5) - 1  # bottom minus the corner


def test_contact_steps_pressure_traction_and_resultant(square):
    d, _ = square
    rows = read_csv(d / "contact_steps.csv")
    summary = json.load(open(d / "summary.json"))
    assert {int(r["step"]) for r in rows} == {1, 2, 3, 4, 5}
    for r in rows:
        length, ln, lt = float(r["length"]), float(r["lambda_n"]), float(r["lambda_t"])
        assert length > 0
        assert float(r["pressure"]) * length == pytest.approx(-ln, rel=1e-12, abs=1e-300)
        assert float(r["traction_t"]) * length == pytest.approx(-lt, rel=1e-12, abs=1e-300)
        if r["status"] == "gap":
            assert ln == 0.0 and lt == 0.0
            assert float(r["pressure"]) == 0.0 and float(r["traction_t"]) == 0.0
        else:
            assert float(r["pressure"]) > 0  # compression is positive
    final = [r for r in rows if int(r["step"]) == 5]
    # Tributary lengths cover the 40 mm bottom edge but the half edge of the fixed corner (not a
    # contact node); nodes 0.625 mm apart on level 2; arc length = x on the bottom edge.
    assert sum(float(r["length"]) for r in final) == pytest.approx(40.0 - 0.3125, rel=1e-13)
    for r in final:
        assert float(r["arc"]) == pytest.approx(float(r["x"]), abs=1e-12)
        x = float(r["x"])
        assert float(r["length"]) == pytest.approx(0.3125 if x == 0.0 else 0.625, rel=1e-12)
    # Sum of pressure x length = the normal resultant (n = +y), traction x length along t = +x.
    (fx, fy) = summary["contacts"][0]["resultant"]
    assert sum(float(r["pressure"]) * float(r["length"]) for r in final) == pytest.approx(
        fy, rel=1e-12)
    assert sum(float(r["traction_t"]) * float(r["length"]) for r in final) == pytest.approx(
        fx, rel=1e-12)
    # Most of the vertical load (50 MPa on the 40 mm top edge); the fixed corner takes the rest.
    assert 0.95 * 50.0 * 40.0 < fy < 50.0 * 40.0
    # The final step equals contact.csv.
    last = read_csv(d / "contact.csv")
    assert [(r["x"], r["lambda_n"], r["status"]) for r in last] == [
        (r["x"], r["lambda_n"], r["status"]) for r in final]


def test_gap_multipliers_are_exactly_zero_in_every_file(square):
    d, _ = square
    for name in ("contact.csv", "contact_steps.csv"):
        rows = read_csv(d / name)
        gaps = [r for r in rows if r["status"] == "gap"]
        assert gaps, name
        assert all(r["lambda_t"] == "0" and r["lambda_n"] == "0" for r in gaps), name
    for f in glob.glob(str(d / "*.vtu")):
        a = arrays(read_vtu(f))
        gap = a["contact_status"] == 0
        assert (a["lambda_t"][gap] == 0).all() and (a["lambda_n"][gap] == 0).all(), f


def test_plot_written(square):
    d, out = square
    png = d / "contact.png"
    assert open(png, "rb").read(8) == b"\x89PNG\r\n\x1a\n"
    assert os.path.getsize(png) > 10000
    assert str(png) in out


def test_no_temporary_left(square):
    d, _ = square
    assert not [f for f in os.listdir(d) if f.endswith(".tmp")]


def interrupted_run(tmp_path, sig, wait_for_step):
    """Starts a long run with --every-step (every load step solved by Newton: with the square's
    extrapolation, steps 2.. would take no time), waits until the files of step `wait_for_step`
    exist, sends `sig` and returns (exit code, output)."""
    p = subprocess.Popen([MLCONTACT, "run", "square", "--levels", "3", "--steps", "60",
                          "--every-step", "--no-extrapolation", "--out", str(tmp_path)], stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, text=True, env=ENV)
    want = tmp_path / f"solution_step_{wait_for_step:04d}.vtu"
    t0 = time.time()
    while not want.exists():
        assert p.poll() is None, "the run ended before the step files existed"
        assert time.time() - t0 < 300, "no step files after 300 s"
        time.sleep(0.02)
    p.send_signal(sig)
    out, _ = p.communicate(timeout=300)
    return p.returncode, out


def check_left_files(d):
    names = os.listdir(d)
    assert not [f for f in names if f.endswith(".tmp")], names
    entries = pvd_entries(d / "solution.pvd")
    vtus = sorted(f for f in names if f.endswith(".vtu"))
    assert [f for _, f in entries] == vtus  # the PVD lists exactly the step files left
    for k, (s, f) in enumerate(entries, start=1):
        assert s == pytest.approx(k / 60, rel=1e-15)
        g = read_vtu(d / f)
        assert g.GetNumberOfPoints() == 129 * 129
        assert arrays(g)["displacement"].shape == (129 * 129, 3)
    summary = json.load(open(d / "summary.json"))
    assert summary["stopped"] is True and summary["converged"] is False
    assert summary["completed_steps"] == len(entries)
    rows = read_csv(d / "contact_steps.csv")
    assert {int(r["step"]) for r in rows} == set(range(1, len(entries) + 1))
    assert not os.path.exists(d / "solution.vtu")  # no final state: the run did not end
    return len(entries)


def test_sigterm_stops_cleanly_after_the_current_newton_step(tmp_path):
    rc, out = interrupted_run(tmp_path, signal.SIGTERM, 3)
    assert rc == 143, out
    assert "stopped by SIGTERM: stopped during load step " in out, out
    done = check_left_files(tmp_path)
    assert 3 <= done < 60
    assert f"during load step {done + 1} of 60" in out, out
    assert f"the files above hold load steps 1-{done}" in out, out


def test_sigint_exits_130(tmp_path):
    rc, out = interrupted_run(tmp_path, signal.SIGINT, 1)
    assert rc == 130, out
    assert "stopped by SIGINT" in out, out
    check_left_files(tmp_path)


def progress_lines(text):
    return [line.strip() for line in text.splitlines() if line.strip().startswith("step ")
            and " level " in line]


def test_progress_gives_the_time_left_on_a_terminal_only(tmp_path):
    import pty
    import re
    master, slave = pty.openpty()
    p = subprocess.Popen([MLCONTACT, "run", "square", "--levels", "2", "--out", str(tmp_path)],
                         stdout=slave, stderr=slave, env=ENV)
    os.close(slave)
    out = b""
    while True:
        try:
            chunk = os.read(master, 65536)
        except OSError:  # the child closed the terminal
            break
        if not chunk:
            break
        out += chunk
    assert p.wait() == 0
    os.close(master)
    lines = progress_lines(out.decode())
    assert len(lines) == 15, out  # 3 levels x 5 load steps, one line each
    eta = re.compile(r"\[(\d+\.\d|\d+) s elapsed, ~(\d+\.\d|\d+) s left\]$")
    assert all(eta.search(line) for line in lines), lines
    assert lines[-1].endswith("~0.0 s left]")
    piped = progress_lines(run("square", "--levels", "2", "--out", str(tmp_path)).stdout)
    assert len(piped) == 15 and not any("left]" in line for line in piped)
