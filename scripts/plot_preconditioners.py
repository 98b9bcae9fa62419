#!/usr/bin/env python3
"""Draws preconditioners.png from preconditioners.csv (`mlcontact study preconditioners`).

Panels in the manner of Alart, Barboteu & Lebon (1997), Figs. 7-10 and Tables 2-5:
(a) Krylov iterations per Newton step against unknowns; (b) seconds per Newton step against
unknowns, with the paper's square-test values (their machine, hollow markers); (c) iterations
against the friction coefficient and (d) against the penalty factor, at the finest level.
Usage: plot_preconditioners.py DIR
"""
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

d = sys.argv[1]
rows = [r for r in csv.DictReader(open(f"{d}/preconditioners.csv")) if r["level"]]
paper = list(csv.DictReader(open(f"{d}/paper_1997_square.csv")))
key = lambda r: f'{r["krylov"]}+{r["pc"]}'  # noqa: E731
mus = sorted({float(r["mu"]) for r in rows})
rs = sorted({float(r["r_over_E"]) for r in rows})
mu0 = 1.0 if 1.0 in mus else mus[0]
r0 = 0.1 if 0.1 in rs else rs[0]
fig, ax = plt.subplots(2, 2, figsize=(12, 9))
markers = "os^vD<>pPX*h"
series = defaultdict(list)
for r in rows:
    if float(r["mu"]) == mu0 and float(r["r_over_E"]) == r0 and r["result"] == "converged":
        series[key(r)].append(r)
for i, (k, rr) in enumerate(sorted(series.items())):
    rr.sort(key=lambda r: int(r["unknowns"]))
    u = [int(r["unknowns"]) for r in rr]
    ax[0][0].plot(u, [float(r["krylov_per_newton_mean"]) for r in rr], markers[i % 12] + "-", label=k)
    ax[0][1].plot(u, [float(r["seconds_per_newton"]) for r in rr], markers[i % 12] + "-", label=k)
for name, style in (("ebe", "s"), ("ilu", "o"), ("diag", "^")):
    pts = [p for p in paper if p["pc"] == name and float(p["seconds_per_newton"]) > 0]
    ax[0][1].plot([float(p["unknowns"]) for p in pts], [float(p["seconds_per_newton"]) for p in pts],
                  style + "--", mfc="none", color="gray", label=f"1997 paper {name.upper()} (their CPU)")
for a, t in ((ax[0][0], "Krylov iterations per Newton step"), (ax[0][1], "seconds per Newton step")):
    a.set_xscale("log")
    a.set_yscale("log")
    a.set_xlabel("unknowns")
    a.set_ylabel(t)
    a.grid(alpha=0.3, which="both")
    a.legend(fontsize=7)
ax[0][0].set_title(f"mu = {mu0}, r = {r0} E")
ax[0][1].set_title("time per Newton step (paper: square test, mu = 0.1)")
finest = max(int(r["level"]) for r in rows)
for panel, var, fixed, fixval, label in ((ax[1][0], "mu", "r_over_E", r0, "friction coefficient mu"),
                                         (ax[1][1], "r_over_E", "mu", mu0, "penalty factor r / E")):
    ser = defaultdict(list)
    for r in rows:
        if int(r["level"]) == finest and float(r[fixed]) == fixval and r["result"] == "converged":
            ser[key(r)].append((float(r[var]), float(r["krylov_per_newton_mean"])))
    for i, (k, pts) in enumerate(sorted(ser.items())):
        pts.sort()
        panel.plot([p[0] for p in pts], [p[1] for p in pts], markers[i % 12] + "-", label=k)
    panel.set_xlabel(label)
    panel.set_ylabel("Krylov iterations per Newton step")
    panel.set_title(f"level {finest}")
    if var == "r_over_E":
        panel.set_xscale("log")
    panel.grid(alpha=0.3)
    panel.legend(fontsize=7)
fig.tight_layout()
png = f"{d}/preconditioners.png"
fig.savefig(png + ".tmp", dpi=100, format="png")  # renamed when complete
os.replace(png + ".tmp", png)
