#!/usr/bin/env python3
"""Draws the scaling plot of `mlcontact bench square` and `mlcontact bench elastic`.

(a) seconds per Newton step per unknown against unknowns, one line per Newton-system solver
(levels >= 1 of every `bench square` JSON; a solver that appears in several files keeps, per
level, the entry of the file with the finest level), with the BoomerAMG-PCG and mg-CG solves of
the elastic block alone (setup + solve seconds per unknown, from `bench elastic` JSON files) as
dashed reference lines; (b) Krylov iterations per Newton step (elastic: CG iterations).
Usage: plot_bench.py OUT.png FILE.json [FILE.json ...]
Run with Debian's /usr/bin/python3 (matplotlib).
"""
import json
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

if len(sys.argv) < 3:
    sys.exit(__doc__)
out = sys.argv[1]
square = defaultdict(dict)  # solver -> unknowns -> (finest level of its file, row)
elastic = defaultdict(dict)  # solver -> unknowns -> row
for path in sys.argv[2:]:
    data = json.load(open(path))
    if "runs" in data:
        for run in data["runs"]:
            for row in run["levels"]:
                if row["level"] == 0 or not run["converged"] and row["level"] == data["levels"]:
                    continue
                old = square[run["solver"]].get(row["unknowns"])
                if old is None or old[0] < data["levels"]:
                    square[run["solver"]][row["unknowns"]] = (data["levels"], row)
    elif "solvers" in data:
        for s in data["solvers"]:
            if s["converged"]:
                elastic[s["solver"]][data["unknowns"]] = s
    else:
        sys.exit(f"{path}: neither a bench square nor a bench elastic JSON file")

fig, ax = plt.subplots(1, 2, figsize=(12, 4.8))
markers = "os^vD<>pPX*h"
colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
for i, (name, pts) in enumerate(sorted(square.items())):
    u = sorted(pts)
    rows = [pts[k][1] for k in u]
    style = dict(marker=markers[i % len(markers)], color=colors[i % len(colors)], label=name)
    ax[0].plot(u, [1e6 * r["seconds_per_newton_per_unknown"] for r in rows], "-", **style)
    if any(r["krylov_per_newton"] > 0 for r in rows):
        ax[1].plot(u, [r["krylov_per_newton"] for r in rows], "-", **style)
for i, (name, pts) in enumerate(sorted(n for n in elastic.items() if n[0] != "mg-gmres")):
    u = sorted(pts)
    j = i + len(square)
    style = dict(marker=markers[j % len(markers)], color=colors[j % len(colors)],
                 label=f"{name} (elastic block only)")
    ax[0].plot(u, [1e6 * pts[k]["total_seconds"] / k for k in u], "--", **style)
    ax[1].plot(u, [pts[k]["iterations"] for k in u], "--", **style)
ax[0].set_ylabel("microseconds per Newton step per unknown\n(elastic: setup + solve per unknown)")
ax[1].set_ylabel("Krylov iterations per Newton step")
for a in ax:
    a.set_xscale("log")
    a.set_xlabel("unknowns")
    a.grid(True, which="both", alpha=0.3)
    a.legend(fontsize=8)
ax[0].set_yscale("log")
ax[1].set_yscale("log")
ax[0].set_title("(a) time per Newton step per unknown")
ax[1].set_title("(b) iterations per Newton step")
fig.suptitle("square, mu = 1, 5 load steps, coarse-to-fine, CGS rel. tol 1e-8 (2 cores)")
fig.tight_layout()
png = out
fig.savefig(png + ".tmp", dpi=110, format="png")  # renamed when complete
os.replace(png + ".tmp", png)
print(f"wrote {out}")
