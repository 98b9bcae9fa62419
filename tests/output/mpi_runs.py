# SPDX-License-Identifier: MIT
"""What the tests of `mlcontact run` under mpirun share: the driver and launcher from the
environment (MLCONTACT, MPIEXEC), a built-in scene with the Newton tolerance at 1e-12, one run on
one or several processes, and VTK's readers."""
import os
import subprocess

import vtk

MLCONTACT = os.environ["MLCONTACT"]
MPIEXEC = os.environ.get("MPIEXEC", "mpiexec")
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def tight_scene(tmp_path, name):
    """The built-in scene `name` written to tmp_path with the Newton tolerance at 1e-12."""
    text = subprocess.run([MLCONTACT, "show", name], capture_output=True, text=True,
                          env=dict(ENV, OMPI_MCA_ess_singleton_isolated="1"), check=True).stdout
    assert "[newton]" not in text
    f = tmp_path / f"{name}.toml"
    f.write_text(text + "\n[newton]\nrel_tol = 1e-12\n")
    return f


def run_processes(args, np_, expect=0):
    """`mlcontact ARGS` on one process (np_ = 1, without mpirun) or under mpirun -n np_; asserts
    its exit code and returns the completed process."""
    cmd = [MLCONTACT, *args]
    env = dict(ENV)
    if np_ > 1:
        cmd = [MPIEXEC, "-n", str(np_), "--oversubscribe", *cmd]
    else:
        env["OMPI_MCA_ess_singleton_isolated"] = "1"
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=600)
    assert p.returncode == expect, p.stdout + p.stderr
    return p


def read_grid(path, parallel):
    """The unstructured grid of a .vtu (parallel False) or .pvtu (True), read by VTK."""
    r = vtk.vtkXMLPUnstructuredGridReader() if parallel else vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(str(path))
    r.Update()
    assert r.GetErrorCode() == 0, f"VTK could not read {path}"
    return r.GetOutput()
