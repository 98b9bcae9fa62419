# SPDX-License-Identifier: MIT
"""Python errors name the Python parameters, not the driver's options, and carry no internal check
location (that goes to the exception's attribute check_location, and into the message only with
MLC_CHECK_LOCATIONS set); the driver keeps both in its messages."""
import os
import re
import subprocess
import sys

import pytest

import mlcontact
from conftest import ENV, run_cli

LOCATION = re.compile(r"\[check `|\w+\.(cpp|hpp):\d+")


def raised(f, exc=ValueError):
    with pytest.raises(exc) as e:
        f()
    return e.value


@pytest.mark.parametrize("options, text", [
    ({"levels": -1}, "levels= must lie in [0, 12], found -1"),
    ({"levels": 13}, "levels= must lie in [0, 12], found 13"),
    ({"mu": -1.0}, "mu= must be >= 0, found -1"),
    ({"r": -1.0}, "r= must be > 0, found -1"),
    ({"load_steps": 0}, "load_steps= must be at least 1, found 0"),
    ({"numbering": "spiral"}, "numbering= must be hilbert or lattice, found 'spiral'"),
    ({"solver": "schur", "pc": "mg"},
     "solver='schur' is a direct solve, but pc='mg' applies to Krylov solves only: drop solver='schur'"),
    ({"levels": 0, "pc": "cf"}, "pc='cf' needs the level below: use levels >= 1"),
])
def test_solve_errors_name_python_parameters(options, text):
    e = raised(lambda: mlcontact.solve(mlcontact.Scene.builtin("square"), **options))
    assert text in str(e), str(e)
    assert "--" not in str(e) and not LOCATION.search(str(e)), str(e)


def test_the_check_location_is_kept_apart():
    e = raised(lambda: mlcontact.solve(mlcontact.Scene.builtin("square"), levels=13))
    assert re.search(r"^check `.*` in apply_overrides, run\.cpp:\d+$", e.check_location), e.check_location
    s = mlcontact.Scene.builtin("square")
    e = raised(lambda: s.set_material(0, E=1e-323))
    assert str(e).startswith("E: Young's modulus E = 9.88131e-324 is below 1e-100"), str(e)
    assert not LOCATION.search(str(e)) and "elasticity.cpp:" in e.check_location
    e = raised(lambda: setattr(s, "r", 1e-16))
    assert "r = 1e-16 is 7.69231e-22 times E = 130000" in str(e) and not LOCATION.search(str(e)), str(e)


def test_the_location_is_shown_on_request():
    code = ("import mlcontact\ntry:\n    mlcontact.solve(mlcontact.Scene.builtin('square'), levels=13)\n"
            "except ValueError as e:\n    print(e)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=dict(ENV, MLC_CHECK_LOCATIONS="1"), check=True).stdout
    assert re.search(r"levels= must lie in .*\[check `.*` in apply_overrides, run\.cpp:\d+\]", out), out


def test_the_driver_keeps_its_options_and_locations():
    p = run_cli("run", "--levels", "13", "--quiet", check=False)
    assert p.returncode == 1
    assert re.search(r"mlcontact: error: --levels must lie in \[0, 12\], found 13 \[check `.*run\.cpp:\d+\]",
                     p.stderr), p.stderr
