# SPDX-License-Identifier: MIT
"""The output folder of `mlcontact run`: the lock (a second run on a folder in use is refused at
once, naming the folder and the other process; a lock whose process is gone is taken over),
summary.json written last with "complete" and the list of the run's files, the files of an
earlier run removed only when its complete summary lists them, --out checked before the solve,
a failed --plot (exit 4, the real cause, no stale plot), and SIGTERM while the files are written
(exit 143, "stopped": true, every file complete or absent).

Run by ctest as `/usr/bin/python3 -m pytest`; MLCONTACT is the driver to test.
"""
import csv
import json
import os
import signal
import subprocess
import time

import pytest
import vtk

MLCONTACT = os.environ.get("MLCONTACT", "mlcontact")
ENV = dict(os.environ, OMPI_MCA_ess_singleton_isolated="1")
LOCK = ".mlcontact.lock"


def run(*args, env=ENV):
    return subprocess.run([MLCONTACT, "run", *args], capture_output=True, text=True, env=env)


def start(*args):
    return subprocess.Popen([MLCONTACT, "run", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, env=ENV)


def wait_for(predicate, p, what):
    t0 = time.time()
    while not predicate():
        assert p.poll() is None, f"the run ended before {what}"
        assert time.time() - t0 < 300, f"no {what} after 300 s"
        time.sleep(0.002)


def lock_pid(d):
    try:
        text = (d / LOCK).read_text()
    except FileNotFoundError:
        return 0
    return int(text) if text.strip() else 0


def summary(d):
    return json.loads((d / "summary.json").read_text())


def readable(d, name):
    """A file of a run: VTU files open in VTK with points, CSV files parse with a header."""
    path = d / name
    if name.endswith(".vtu"):
        r = vtk.vtkXMLUnstructuredGridReader()
        r.SetFileName(str(path))
        r.Update()
        assert r.GetErrorCode() == 0 and r.GetOutput().GetNumberOfPoints() > 0, name
    elif name.endswith(".csv"):
        with open(path) as f:
            rows = list(csv.DictReader(f))
        assert rows and None not in rows[-1].values(), name
    elif name.endswith((".json", ".pvd")):
        text = path.read_text()
        if name.endswith(".json"):
            json.loads(text)
        else:
            assert text.rstrip().endswith("</VTKFile>"), name
    elif name.endswith(".png"):
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name


def check_folder(d):
    """Every file summary.json lists is there and readable; nothing else of the run's is there
    (no temporary, no lock); returns the summary."""
    s = summary(d)
    names = set(os.listdir(d))
    assert not [n for n in names if n.endswith(".tmp")], names
    assert LOCK not in names
    assert set(s["files"]) <= names, (s["files"], names)
    for n in s["files"]:
        readable(d, n)
    return s


def test_a_second_run_on_a_folder_in_use_is_refused_at_once(tmp_path):
    a = start("square", "--levels", "3", "--steps", "60", "--every-step", "--no-extrapolation",
              "--quiet", "--out", str(tmp_path))
    wait_for(lambda: lock_pid(tmp_path) == a.pid, a, "the lock of run A")
    b = run("square", "--levels", "1", "--mu", "0.8", "--every-step", "--vtu", "ascii", "--out",
            str(tmp_path))
    assert b.returncode == 1, b.stdout + b.stderr
    assert b.stdout == ""  # refused before the solve
    assert b.stderr == (f"mlcontact: error: the output folder '{tmp_path}' is in use by another "
                        f"mlcontact run (process {a.pid}, lock file {tmp_path / LOCK}); wait for "
                        f"it to end, or choose another folder with --out\n")
    assert lock_pid(tmp_path) == a.pid  # B left A's lock alone
    wait_for(lambda: (tmp_path / "solution_step_0002.vtu").exists(), a, "two step files")
    a.send_signal(signal.SIGTERM)
    out, _ = a.communicate(timeout=300)
    assert a.returncode == 143, out
    s = check_folder(tmp_path)
    assert s["complete"] is True and s["stopped"] is True and s["converged"] is False
    steps = sorted(n for n in os.listdir(tmp_path) if n.startswith("solution_step_"))
    assert len(steps) == s["completed_steps"] >= 2
    assert set(s["files"]) == set(os.listdir(tmp_path))


def test_a_lock_whose_process_is_gone_is_taken_over(tmp_path):
    gone = subprocess.Popen(["true"])
    gone.wait()
    (tmp_path / LOCK).write_text(f"{gone.pid}\n")
    p = run("square", "--levels", "0", "--quiet", "--out", str(tmp_path))
    assert p.returncode == 0, p.stdout + p.stderr
    assert (f"note: the output folder's lock was left by process {gone.pid}, which has ended; "
            "taken over") in p.stdout
    s = check_folder(tmp_path)
    assert s["complete"] is True and s["stopped"] is False
    assert set(s["files"]) == set(os.listdir(tmp_path))


def test_only_the_files_a_complete_earlier_run_listed_are_removed(tmp_path):
    (tmp_path / "notes.txt").write_text("mine\n")
    (tmp_path / "solution_step_0099.vtu").write_text("not the driver's\n")
    p = run("square", "--levels", "0", "--steps", "6", "--every-step", "--no-extrapolation",
            "--quiet", "--out", str(tmp_path))
    assert p.returncode == 0, p.stdout + p.stderr
    first = summary(tmp_path)["files"]
    assert "solution_step_0006.vtu" in first and "notes.txt" not in first
    p = run("square", "--levels", "0", "--steps", "3", "--every-step", "--no-extrapolation",
            "--quiet", "--out", str(tmp_path))
    assert p.returncode == 0, p.stdout + p.stderr
    s = check_folder(tmp_path)
    assert s["complete"] is True
    names = set(os.listdir(tmp_path))
    assert names == set(s["files"]) | {"notes.txt", "solution_step_0099.vtu"}
    assert "solution_step_0004.vtu" not in names and "solution_step_0003.vtu" in names
    # An earlier run that did not complete its folder: nothing of it is removed.
    (tmp_path / "summary.json").write_text('{"complete": false, "files": ["solution_step_0003.vtu"]}\n')
    p = run("square", "--levels", "0", "--steps", "2", "--quiet", "--out", str(tmp_path))
    assert p.returncode == 0, p.stdout + p.stderr
    assert (tmp_path / "solution_step_0003.vtu").exists()


@pytest.mark.parametrize("out,message", [
    ("", "--out needs a folder name, found an empty one"),
    ("/dev/full", "the output folder '/dev/full' is not a folder"),
    ("/sys", "the output folder '/sys' is not writable: cannot create its lock file"),
    ("/proc/self/x/y", "the output folder '/proc/self/x/y' cannot be created"),
])
def test_out_is_checked_before_the_solve(out, message):
    p = run("square", "--levels", "0", "--out", out)
    assert p.returncode == 1, p.stdout + p.stderr
    assert p.stdout == ""  # before the solve
    assert p.stderr.startswith("mlcontact: error: " + message), p.stderr


def test_a_failed_plot_exits_4_with_its_cause_and_leaves_no_plot(tmp_path):
    d = tmp_path / "out"
    p = run("square", "--levels", "0", "--plot", "--quiet", "--out", str(d))
    assert p.returncode == 0, p.stdout + p.stderr
    readable(d, "contact.png")
    assert "contact.png" in summary(d)["files"]
    broken = tmp_path / "site" / "matplotlib"
    broken.mkdir(parents=True)
    (broken / "__init__.py").write_text('raise RuntimeError("this matplotlib is broken")\n')
    p = run("square", "--levels", "0", "--plot", "--quiet", "--out", str(d),
            env=dict(ENV, PYTHONPATH=str(tmp_path / "site")))
    assert p.returncode == 4, p.stdout + p.stderr
    assert p.stderr.startswith("mlcontact: error: the results were written, but the plot failed: ")
    assert "RuntimeError: this matplotlib is broken" in p.stderr, p.stderr
    s = check_folder(d)
    assert not (d / "contact.png").exists()
    assert s["complete"] is True and s["plot"].startswith("failed: ")
    assert "RuntimeError: this matplotlib is broken" in s["plot"]
    assert set(s["files"]) == set(os.listdir(d)) and "contact.csv" in s["files"]


def test_sigterm_while_the_files_are_written_stops_the_run(tmp_path):
    """The signal is sent once summary.json says "in progress" (the run's first write); the
    writing lasts at least as long as the plot script (a second or more)."""
    def writing():
        try:
            return summary(tmp_path)["complete"] is False
        except (FileNotFoundError, json.JSONDecodeError):
            return False

    for attempt in range(3):  # again only if this machine let the whole writing pass unseen
        p = start("square", "--levels", "2", "--plot", "--quiet", "--out", str(tmp_path))
        wait_for(lambda: writing() or p.poll() is not None, p, "the writing phase")
        if p.poll() is None:
            break
        p.communicate()
    p.send_signal(signal.SIGTERM)
    out, _ = p.communicate(timeout=300)
    assert p.returncode == 143, out
    assert "stopped by SIGTERM" in out, out
    s = check_folder(tmp_path)
    assert s["stopped"] is True and s["converged"] is True
    assert set(s["files"]) == set(os.listdir(tmp_path))
