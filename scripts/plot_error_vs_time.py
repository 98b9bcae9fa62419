#!/usr/bin/env python3
"""Draws error_vs_time.png from error_vs_time.csv (`mlcontact study error-vs-time`).

Log-log: wall seconds (x) against the primary error (y), one marker style and colour per
configuration (the multilevel ones, mg and mgr, drawn with thicker lines), the level written
next to each point, the Pareto front as a black step line.
Usage: plot_error_vs_time.py DIR
"""
import csv
import json
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

d = sys.argv[1]
rows = [r for r in csv.DictReader(open(f"{d}/error_vs_time.csv")) if r["converged"] == "1"]
by = defaultdict(list)
for r in rows:
    by[r["configuration"]].append(r)
markers = "os^vD<>pPX*h"
colors = plt.get_cmap("tab20").colors
fig, ax = plt.subplots(figsize=(10, 6.5))
for i, (name, rs) in enumerate(by.items()):
    xs = [float(r["seconds"]) for r in rs]
    ys = [float(r["primary_error"]) for r in rs]
    multilevel = "+mg" in name
    ax.plot(xs, ys, markers[i % len(markers)] + "-", alpha=0.9 if multilevel else 0.7, label=name,
            linewidth=2.0 if multilevel else 0.8, color=colors[(2 * i) % 20 + (i // 10) % 2])
    for r in rs:
        ax.annotate(r["level"], (float(r["seconds"]), float(r["primary_error"])), fontsize=7,
                    xytext=(3, 3), textcoords="offset points")
front = sorted((float(r["seconds"]), float(r["primary_error"])) for r in rows if r["pareto"] == "1")
if front:
    ax.step([p[0] for p in front], [p[1] for p in front], "k-", where="post", linewidth=2,
            label="Pareto front", alpha=0.6)
ax.set_xscale("log")
ax.set_yscale("log")
ax.set_xlabel("wall time of the solve [s]")
# The scene as the study names it (error_vs_time.json), not the folder's name (-o may be any).
try:
    scene = json.load(open(f"{d}/error_vs_time.json"))["scene"]
except (OSError, ValueError, KeyError):
    scene = d.rstrip("/").split("/")[-1].replace("_error_vs_time", "")
ylabel = "relative L2 pressure error vs closed form" if scene == "hertz" else \
    "relative energy-norm displacement error (vs finer reference)"
ax.set_ylabel(ylabel)
ax.set_title(f"{scene}: error against run time (numbers: level)")
ax.grid(alpha=0.3, which="both")
ax.legend(fontsize=8)
fig.tight_layout()
png = f"{d}/error_vs_time.png"
fig.savefig(png + ".tmp", dpi=110, format="png")  # renamed when complete
os.replace(png + ".tmp", png)
