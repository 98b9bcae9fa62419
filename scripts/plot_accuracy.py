#!/usr/bin/env python3
"""Draws accuracy.png from accuracy.csv of `mlcontact study accuracy`.

One curve per closed-form quantity: |error| against the level (h halves per level), on a log
scale, with reference slopes h and h^2 from the first level.
Usage: plot_accuracy.py DIR
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
err = defaultdict(dict)
scene_levels = set()
for r in csv.DictReader(open(f"{d}/accuracy.csv")):
    scene_levels.add(int(r["level"]))
    if r["error"] == "":
        continue
    e = abs(float(r["error"]))
    if e > 0:
        err[r["quantity"]][int(r["level"])] = e

fig, ax = plt.subplots(figsize=(9, 5))
markers = "osd^v<>ph*"
for i, (q, pts) in enumerate(sorted(err.items())):
    lv = sorted(pts)
    ax.semilogy(lv, [pts[l] for l in lv], marker=markers[i % len(markers)], label=q)
if err:
    lv = sorted(scene_levels)
    e0 = max(max(p.values()) for p in err.values())
    ax.semilogy(lv, [e0 * 0.5 ** (l - lv[0]) for l in lv], "k--", lw=0.8, label="O(h)")
    ax.semilogy(lv, [e0 * 0.25 ** (l - lv[0]) for l in lv], "k:", lw=0.8, label="O(h^2)")
ax.set_xlabel("level (h halves per level)")
ax.set_ylabel("|error| (relative)")
ax.set_xticks(sorted(scene_levels))
ax.grid(alpha=0.3, which="both")
ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.02, 0.5))
try:
    scene = json.load(open(f"{d}/accuracy.json"))["scene"]
except (OSError, ValueError, KeyError):
    scene = "?"
ax.set_title(f"{scene}: closed-form errors per level")
fig.tight_layout()
png = f"{d}/accuracy.png"
fig.savefig(png + ".tmp", dpi=120, format="png")  # renamed when complete
os.replace(png + ".tmp", png)
