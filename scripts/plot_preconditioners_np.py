#!/usr/bin/env python3
"""Draws preconditioners_np.png from preconditioners_np.csv (`mlcontact study preconditioners
--np-list ...`): the table the 1997 paper's parallel claim asks for.

(a) Krylov iterations per Newton step (mean; the bar reaches the max) against the process count N,
one line per preconditioner and level; (b) the same against the unknowns, one line per
preconditioner and N (the CSV says why a cell did not converge). The first mu and
r/E of the study (and its first Krylov method) are drawn; cells that did not converge are
crosses at the top of (a).
Usage: plot_preconditioners_np.py DIR
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

d = sys.argv[1]
rows = list(csv.DictReader(open(f"{d}/preconditioners_np.csv")))
if not rows:
    sys.exit("plot_preconditioners_np.py: no rows")
kr0, mu0, r0 = rows[0]["krylov"], rows[0]["mu"], rows[0]["r_over_E"]
rows = [r for r in rows if r["krylov"] == kr0 and r["mu"] == mu0 and r["r_over_E"] == r0]
failed = [r for r in rows if r["result"] != "converged"]
pcs = list(dict.fromkeys(r["pc"] for r in rows))
rows = [r for r in rows if r["result"] == "converged"]
levels = sorted({int(r["level"]) for r in rows})
nps = sorted({int(r["processes"]) for r in rows})
colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
styles = ["-", "--", ":", "-."]
markers = "os^vD<>pPX*h"
fig, ax = plt.subplots(1, 2, figsize=(13, 7))
by_pc_level = defaultdict(list)
by_pc_np = defaultdict(list)
for r in rows:
    by_pc_level[(r["pc"], int(r["level"]))].append(r)
    by_pc_np[(r["pc"], int(r["processes"]))].append(r)
for (pc, lv), rr in sorted(by_pc_level.items(), key=lambda kv: (pcs.index(kv[0][0]), kv[0][1])):
    rr.sort(key=lambda r: int(r["processes"]))
    n = [int(r["processes"]) for r in rr]
    mean = [float(r["krylov_per_newton_mean"]) for r in rr]
    mx = [float(r["krylov_per_newton_max"]) for r in rr]
    c = colours[pcs.index(pc) % len(colours)]
    ax[0].errorbar(n, mean, yerr=[[0] * len(mean), [b - a for a, b in zip(mean, mx)]],
                   fmt=markers[levels.index(lv) % 12] + styles[levels.index(lv) % 4], color=c,
                   capsize=3, label=f"{pc}, level {lv} ({rr[0]['unknowns']} unknowns)")
for (pc, n), rr in sorted(by_pc_np.items(), key=lambda kv: (pcs.index(kv[0][0]), kv[0][1])):
    rr.sort(key=lambda r: int(r["unknowns"]))
    c = colours[pcs.index(pc) % len(colours)]
    ax[1].plot([int(r["unknowns"]) for r in rr], [float(r["krylov_per_newton_mean"]) for r in rr],
               markers[nps.index(n) % 12] + styles[nps.index(n) % 4], color=c, label=f"{pc}, N = {n}")
# Cells that did not converge (the Krylov limit, or the time bound): a cross at the top, offset
# by level so that they do not hide each other.
top = max([float(r["krylov_per_newton_max"]) for r in rows] + [5000.0])
for r in failed:
    lv, k = int(r["level"]), pcs.index(r["pc"])
    x = int(r["processes"]) * (1 + 0.03 * (k - len(pcs) / 2) + 0.1 * (lv - max(levels or [lv])))
    ax[0].plot(x, top * 1.3, "x", ms=8, mew=2, color=colours[k % len(colours)])
    ax[0].annotate(f"L{lv}", (x, top * 1.3), textcoords="offset points", xytext=(0, 6),
                   ha="center", fontsize=6)
if failed:
    ax[0].axhline(top * 1.3, color="gray", lw=0.5)
ax[0].set_xscale("log", base=2)
ax[0].set_xticks(nps)
ax[0].set_xticklabels([str(n) for n in nps])
ax[0].set_xlabel("processes N (one block per process, Jacobi across the cuts)")
ax[1].set_xscale("log")
ax[1].set_xlabel("unknowns")
for a in ax:
    a.set_yscale("log")
    a.set_ylabel(f"{kr0.upper()} iterations per Newton step (mean; bar: max)")
    a.grid(alpha=0.3, which="both")
    a.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=3)
ax[0].set_title(f"by processes (mu = {mu0}, r = {r0} E)"
                + ("; x at the top: no convergence on level Ln" if failed else ""))
ax[1].set_title("by unknowns")
fig.tight_layout()
fig.savefig(f"{d}/preconditioners_np.png", dpi=110)
