# SPDX-License-Identifier: MIT
"""Ctrl-C during mlcontact.solve(): the GIL is released while solving and Python's signal
handlers run between Newton iterations, so SIGINT raises KeyboardInterrupt within a few seconds
(not at the end of the solve), and the module is usable afterwards."""
import os
import signal
import subprocess
import time

from conftest import ENV, PYTHON

CHILD = r"""
import sys, time, threading
import mlcontact
s = mlcontact.Scene.builtin("square")
ticks = []
threading.Thread(target=lambda: [ticks.append(time.sleep(0.05)) for _ in range(1000)], daemon=True).start()
print("solving", flush=True)
t0 = time.monotonic()
try:
    # Many short Newton iterations (a direct solve on level 3): minutes in all.
    mlcontact.solve(s, levels=3, load_steps=5000, solver="schur")
    print("finished after", time.monotonic() - t0, flush=True)
    sys.exit(0)
except KeyboardInterrupt:
    # Another Python thread ran during the solve: the GIL was released.
    print("KeyboardInterrupt after", time.monotonic() - t0, "ticks", len(ticks), flush=True)
    r = mlcontact.solve(s, levels=0)
    print("then solved", r.converged, flush=True)
    sys.exit(42)
"""


def test_ctrl_c_raises_keyboard_interrupt_promptly():
    p = subprocess.Popen([PYTHON, "-c", CHILD], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         env=ENV)
    try:
        assert p.stdout.readline().strip() == "solving"
        time.sleep(4.0)
        assert p.poll() is None, "the solve ended before the signal: make it longer"
        sent = time.monotonic()
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=30)
        elapsed = time.monotonic() - sent
    finally:
        if p.poll() is None:
            p.kill()
    assert p.returncode == 42, f"exit {p.returncode}\n{out}\n{err}"
    print(f"KeyboardInterrupt {elapsed:.2f} s after SIGINT; child: {out.strip()}")
    assert elapsed < 3.0, f"KeyboardInterrupt came {elapsed:.1f} s after SIGINT"
    ticks = int(out.split("ticks")[1].split()[0])
    assert ticks >= 40, f"only {ticks} ticks of another thread during 4 s of solving: GIL held?"
    assert "then solved True" in out
