# SPDX-License-Identifier: MIT
"""The output folder of `mlcontact run` under mpirun with two processes: process 0 locks it (a
second run, on one process or two, is refused at once naming the folder and process 0), writes
summary.json last with "complete": true and the list of files; SIGTERM to mpirun ends the run
with summary.json saying "stopped": true, no temporary and no lock left.

Run by ctest as `/usr/bin/python3 -m pytest`; MLCONTACT is the driver, MPIEXEC the launcher.
"""
import json
import os
import signal
import subprocess
import time

MLCONTACT = os.environ["MLCONTACT"]
MPIEXEC = os.environ.get("MPIEXEC", "mpiexec")
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
LOCK = ".mlcontact.lock"


def mpirun(*args):
    return [MPIEXEC, "-n", "2", "--oversubscribe", MLCONTACT, "run", *args]


def lock_pid(d):
    try:
        text = (d / LOCK).read_text()
    except FileNotFoundError:
        return 0
    return int(text) if text.strip() else 0


def test_two_processes_lock_and_complete_the_folder(tmp_path):
    p = subprocess.run(mpirun("square", "--levels", "1", "--quiet", "--out", str(tmp_path)),
                       capture_output=True, text=True, env=ENV, timeout=600)
    assert p.returncode == 0, p.stdout + p.stderr
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["complete"] is True and s["stopped"] is False and s["processes"] == 2
    assert set(s["files"]) == set(os.listdir(tmp_path))
    assert "solution_0.vtu" in s["files"] and "solution_1.vtu" in s["files"]


def test_sigterm_under_mpirun(tmp_path):
    # Level 6, so that the run is still solving when the signal comes after the second run's
    # refusal; a smaller scene can finish first on a fast machine.
    a = subprocess.Popen(mpirun("square", "--levels", "6", "--quiet", "--out", str(tmp_path)),
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=ENV)
    t0 = time.time()
    while lock_pid(tmp_path) == 0:
        assert a.poll() is None, a.communicate()[0]
        assert time.time() - t0 < 300
        time.sleep(0.01)
    holder = lock_pid(tmp_path)
    # A second run, on one process, is refused at once, naming process 0 of the first.
    b = subprocess.run([MLCONTACT, "run", "square", "--levels", "0", "--out", str(tmp_path)],
                       capture_output=True, text=True,
                       env=dict(ENV, OMPI_MCA_ess_singleton_isolated="1"))
    assert b.returncode == 1 and f"is in use by another mlcontact run (process {holder}," in b.stderr
    a.send_signal(signal.SIGTERM)
    out, _ = a.communicate(timeout=60)
    assert a.returncode != 0, out
    assert (tmp_path / "summary.json").exists(), (out, os.listdir(tmp_path))
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["stopped"] is True and s["complete"] is False, s
    assert s["signal"] == "SIGTERM" and s["processes"] == 2
    names = os.listdir(tmp_path)
    assert not [n for n in names if n.endswith(".tmp")] and LOCK not in names, names
