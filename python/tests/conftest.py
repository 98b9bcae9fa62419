# SPDX-License-Identifier: MIT
"""Shared fixtures of the Python tests (run by ctest, label python, with PYTHONPATH=build/python
and MLC_CLI, MLC_TEST_DATA_DIR, MLC_SOURCE_DIR, MLC_TEST_TMP set; the defaults below let
`PYTHONPATH=build/python /usr/bin/python3 -m pytest python/tests` work from the source root)."""
import os
import subprocess
import sys

import pytest

SOURCE = os.environ.get("MLC_SOURCE_DIR", os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
DATA = os.environ.get("MLC_TEST_DATA_DIR", os.path.join(SOURCE, "tests", "data"))
CLI = os.environ.get("MLC_CLI", os.path.join(SOURCE, "build", "bin", "mlcontact"))
ENV = dict(os.environ, OMPI_MCA_ess_singleton_isolated="1")


@pytest.fixture
def tmp(tmp_path):
    return tmp_path


def run_cli(*args, check=True):
    p = subprocess.run([CLI, *args], capture_output=True, text=True, env=ENV)
    if check and p.returncode != 0:
        raise AssertionError(f"{CLI} {' '.join(args)} exited {p.returncode}\n{p.stdout}\n{p.stderr}")
    return p


def read_contact_csv(path):
    import numpy as np
    rows = open(path).read().strip().splitlines()
    assert rows[0] == "x,y,ux,uy,lambda_t,lambda_n,status", rows[0]
    cols = list(zip(*(r.split(",") for r in rows[1:])))
    out = {k: np.array([float(v) for v in cols[i]]) for i, k in enumerate(["x", "y", "ux", "uy", "lambda_t", "lambda_n"])}
    out["status"] = list(cols[6])
    return out


PYTHON = sys.executable
