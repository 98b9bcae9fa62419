# SPDX-License-Identifier: MIT
"""mlcontact: multilevel frictional contact in 2D linear elasticity, from Python.

Example::

    import mlcontact
    scene = mlcontact.Scene.builtin("square")
    scene.mu = 0.3
    result = mlcontact.solve(scene, levels=3)
    result.lambda_n, result.status          # numpy views of the C++ result
    result.write("out/square")              # the files `mlcontact run` writes

Errors: a bad scene key or value raises ValueError naming it (with file and line for scene
files); a load step that does not converge raises NotConverged (its .result holds the reports);
a numerical breakdown raises SolverBreakdown; Ctrl-C during solve() raises KeyboardInterrupt.
See docs/guide/python.md#python (the guide) and docs/api/python.md#api-python (the reference).
"""

import csv as _csv
import json as _json
import numbers as _numbers
import os as _os
import tempfile as _tempfile

import numpy as _np

from . import _core
from ._core import Result, Scene, SolverBreakdown, TetMesh, write_pvd

__version__ = _core.__version__
SolverBreakdown.__doc__ = """A numerical breakdown during solve(): a NaN or Inf, or a singular Newton
system (a RuntimeError; the driver exits 3 for the same condition)."""

#: Status codes of Result.status: STATUS_NAMES[code].
STATUS_NAMES = tuple(_core.status_names)
GAP, STICK, SLIP_FORWARD, SLIP_BACKWARD = range(4)
#: Status codes of a 3D run's files (contact.csv's status_code, the VTU's contact_status):
#: STATUS_NAMES_3D[code]; a 3D node slips in a direction, given apart.
STATUS_NAMES_3D = tuple(_core.status_names_3d)

__all__ = ["Scene", "Result", "TetMesh", "write_pvd", "solve", "NotConverged", "SolverBreakdown", "UnknownKey", "BadType",
           "study_status_transfer", "study_accuracy", "tractions", "STATUS_NAMES", "STATUS_NAMES_3D",
           "__version__"]


class NotConverged(RuntimeError):
    """A load step did not converge. `result` is the Result (reports of every step and level
    solved so far, result.failure the diagnosis); `report` the driver's report text."""

    def __init__(self, message, result):
        super().__init__(message)
        self.result = result
        self.report = result.report()


class UnknownKey(ValueError, AttributeError):
    """Setting a scene parameter that does not exist (a ValueError naming the key)."""


class BadType(ValueError, TypeError):
    """A parameter or option of the wrong type (a ValueError naming it)."""


_INT_KEYS = ("levels", "load_steps", "newton_max_iter")
_SCENE_KEYS = tuple(k for k in dir(Scene) if isinstance(getattr(Scene, k), property))


def _scene_setattr(self, name, value):
    if name not in _SCENE_KEYS:
        raise UnknownKey(f"unknown scene parameter '{name}' (known: {', '.join(_SCENE_KEYS)})")
    try:
        object.__setattr__(self, name, value)
    except TypeError as e:
        if "incompatible function arguments" not in str(e):  # read-only: an AttributeError
            raise
        raise BadType(f"{name}: {value!r} is not a {'whole ' if name in _INT_KEYS else ''}number") from None


Scene.__setattr__ = _scene_setattr


def solve(scene, *, levels=None, mu=None, r=None, load_steps=None, solver=None, krylov=None,
          pc=None, linear_tol=None, numbering=None, cold=False, keep_steps=False, progress=False,
          extrapolate=True, raise_on_failure=True):
    """Solves a Scene as `mlcontact run` does, with the same options and the same numbers.

    levels, mu, r, load_steps override the scene's (as --levels, --mu, --r, --steps);
    solver ("schur", "lu", "krylov"), krylov, pc, linear_tol choose the Newton-system solver
    (as --linear, --krylov, --pc, --linear-tol; none: chosen by size); numbering ("hilbert",
    "lattice") orders each level's unknowns (as --numbering; none: lattice where the default
    solver sweeps by lattices, levels 4 and finer, else hilbert); cold=True solves the
    finest level alone (--cold); keep_steps=True keeps every step's state (Result.step_state);
    progress=True prints the per-step progress lines on stdout; extrapolate=False starts every
    load step from the usual guess (--no-extrapolation).

    The GIL is released while solving; Ctrl-C raises KeyboardInterrupt within one Newton
    iteration. A step that does not converge raises NotConverged (raise_on_failure=False returns
    the Result with converged False instead).
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"solve() needs a mlcontact.Scene, got {type(scene).__name__}")
    options = {}
    for name, value, kind in (("levels", levels, int), ("load_steps", load_steps, int),
                              ("mu", mu, float), ("r", r, float), ("linear_tol", linear_tol, float),
                              ("solver", solver, str), ("krylov", krylov, str), ("pc", pc, str),
                              ("numbering", numbering, str)):
        if value is not None:  # numpy scalars too (a sweep over np.arange)
            abc = {int: _numbers.Integral, float: _numbers.Real, str: str}[kind]
            if not isinstance(value, abc) or isinstance(value, bool):
                raise BadType(f"{name}: {value!r} is not {'an' if kind is int else 'a'} {kind.__name__}")
            value = kind(value)
        options[name] = value
    result = _core.solve(scene, cold=cold, keep_steps=keep_steps, progress=progress,
                         extrapolate=bool(extrapolate), **options)
    if not result.converged and raise_on_failure:
        raise NotConverged(result.failure, result)
    return result


def tractions(result):
    """Pressure and tangential traction along each contact pair's boundary.

    Per pair (a dict keyed by pair name): the contact node indices ordered along the contactor
    boundary from its first node, arc length s, position x, pressure p = -lambda_n / l (positive in
    compression) and tangential traction q = lambda_t / l, with l the node's tributary length
    (half the length of each contactor boundary edge between two contact nodes of the pair that
    touches it), and the status codes. Computed from the arrays of the result."""
    x = _np.asarray(result.contact_x)
    pair = _np.asarray(result.contact_pair)
    vertex = _np.asarray(result.contact_vertex)
    node_of_vertex = {int(v): i for i, v in enumerate(vertex)}
    trib = _np.zeros(len(vertex))
    neighbours = {i: [] for i in range(len(vertex))}
    for v0, v1 in _np.asarray(result.boundary_edges):
        a, b = node_of_vertex.get(int(v0)), node_of_vertex.get(int(v1))
        if a is None or b is None or pair[a] != pair[b]:
            continue
        h = float(_np.hypot(*(x[a] - x[b])))
        trib[a] += 0.5 * h
        trib[b] += 0.5 * h
        neighbours[a].append(b)
        neighbours[b].append(a)
    out = {}
    for k, name in enumerate(result.contact_pair_names):
        nodes = [i for i in range(len(vertex)) if pair[i] == k]
        if not nodes:
            continue
        # Walk each chain of the pair from an end (a node with one neighbour), leftmost first.
        order, seen = [], set()
        ends = sorted((i for i in nodes if len(neighbours[i]) <= 1), key=lambda i: tuple(x[i]))
        for start in ends + sorted(nodes, key=lambda i: tuple(x[i])):
            if start in seen:
                continue
            i = start
            while i is not None:
                order.append(i)
                seen.add(i)
                i = next((j for j in neighbours[i] if j not in seen), None)
        order = _np.array(order, dtype=int)
        steps = _np.hypot(*_np.diff(x[order], axis=0).T) if len(order) > 1 else _np.zeros(0)
        l = trib[order]
        with _np.errstate(divide="ignore", invalid="ignore"):
            p = _np.where(l > 0, -_np.asarray(result.lambda_n)[order] / l, 0.0)
            q = _np.where(l > 0, _np.asarray(result.lambda_t)[order] / l, 0.0)
        out[name] = {"nodes": order, "s": _np.concatenate([[0.0], _np.cumsum(steps)]),
                     "x": x[order], "pressure": p, "traction": q,
                     "status": _np.asarray(result.status)[order]}
    return out


Result.tractions = tractions


def _read_csv(path):
    """A CSV file as a dict of numpy arrays (numbers) or lists (text), by column."""
    with open(path, newline="") as f:
        rows = list(_csv.DictReader(f))
    table = {}
    for key in (rows[0].keys() if rows else []):
        values = [row[key] for row in rows]
        try:
            table[key] = _np.array([float(v) for v in values])
        except ValueError:
            table[key] = values
    return table


def _run_study(function, out, files, *args):
    folder = out if out is not None else _tempfile.mkdtemp(prefix="mlcontact_study_")
    code, report = function(*args, str(folder))
    result = {"exit_code": code, "report": report, "folder": str(folder)}
    for name in files:
        path = _os.path.join(folder, name)
        if not _os.path.exists(path):
            continue
        key = name.replace(".", "_")
        if name.endswith(".json"):
            with open(path) as f:
                result[key] = _json.load(f)
        else:
            result[key] = _read_csv(path)
    if code != 0:
        raise NotConvergedStudy(report, result)
    return result


class NotConvergedStudy(RuntimeError):
    """A study whose runs did not converge; `tables` holds what it wrote."""

    def __init__(self, report, tables):
        super().__init__(report.strip().splitlines()[-1] if report.strip() else "study failed")
        self.tables = tables


def study_status_transfer(scene, levels=3, q_rule="paper", increment=False, out=None):
    """`mlcontact study status-transfer` (without the plot): returns a dict with the report text
    and the tables it writes, status_transfer_csv (columns as numpy arrays), status_transfer_json
    and statuses_csv. `out`: the folder for the files (default a new temporary folder)."""
    return _run_study(_core.study_status_transfer, out,
                      ["status_transfer.csv", "status_transfer.json", "statuses.csv"],
                      scene, levels, q_rule, increment)


def study_accuracy(scene, levels=3, compare_integration=True, out=None):
    """`mlcontact study accuracy` (without the plot) for hertz, mindlin, patch: returns a dict
    with the report text, accuracy_csv (columns as numpy arrays) and accuracy_json."""
    return _run_study(_core.study_accuracy, out, ["accuracy.csv", "accuracy.json"],
                      scene, levels, compare_integration)
