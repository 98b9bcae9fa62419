#!/usr/bin/env python3
"""Draws status_transfer.png from the CSV files of `mlcontact study status-transfer`.

Left: final contact statuses along the contact boundary (x) for every level (rows).
Right: Newton iterations per load step on every level, coarse-to-fine (warm) and cold.
Usage: plot_status_transfer.py DIR
"""
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

d = sys.argv[1]
colors = {"gap": "#bbbbbb", "stick": "#1f77b4", "slip_forward": "#d62728", "slip_backward": "#ff7f0e"}
st = defaultdict(list)
for r in csv.DictReader(open(f"{d}/statuses.csv")):
    st[int(r["level"])].append((float(r["x"]), r["status"]))
rows = list(csv.DictReader(open(f"{d}/status_transfer.csv")))
warm, cold = defaultdict(list), defaultdict(list)
for r in rows:
    warm[int(r["level"])].append(int(r["newton_warm"]))
    cold[int(r["level"])].append(int(r["newton_cold"]))

fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.5))
for lev, pts in sorted(st.items()):
    for name, c in colors.items():
        xs = [x for x, s in pts if s == name]
        a.scatter(xs, [lev] * len(xs), s=8 if lev > 3 else 16, color=c, marker="s",
                  label=name if lev == 0 else None)
a.set_xlabel("x along the contact boundary")
a.set_ylabel("level")
a.set_yticks(sorted(st))
a.set_title("final statuses (last load step)")
a.legend(loc="upper center", bbox_to_anchor=(0.5, -0.15), ncol=4, fontsize=8)
levels = sorted(warm)
w = [sum(warm[l]) / len(warm[l]) for l in levels]
c = [sum(cold[l]) / len(cold[l]) for l in levels]
b.plot(levels, c, "o-", label="cold (previous step)")
b.plot(levels, w, "s-", label="coarse-to-fine (P u, Q lambda)")
b.set_xlabel("level")
b.set_ylabel("Newton iterations per load step")
b.set_xticks(levels)
b.set_ylim(bottom=0)
b.grid(alpha=0.3)
b.legend()
b.set_title("Newton iterations")
fig.tight_layout()
png = f"{d}/status_transfer.png"
fig.savefig(png + ".tmp", dpi=110, format="png")  # renamed when complete
os.replace(png + ".tmp", png)
