#!/usr/bin/env python3
"""Draws contact.png from contact_steps.csv of `mlcontact run --plot`.

One column per contact pair: pressure (top) and tangential traction (bottom) along the pair's
contact boundary, against the arc length from its first node, at the final load step; with
--all-steps (run --every-step) the earlier steps are drawn too, lighter the earlier. The zones
of the final step are marked by a coloured band under each curve: gap (grey), stick (blue),
slip forward (red), slip backward (orange).
Usage: plot_contact.py DIR [--all-steps]
The PNG is written under a temporary name and renamed when complete.
"""
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

d = sys.argv[1]
all_steps = "--all-steps" in sys.argv[2:]
colors = {"gap": "#bbbbbb", "stick": "#1f77b4", "slip_forward": "#d62728",
          "slip_backward": "#ff7f0e"}
rows = list(csv.DictReader(open(os.path.join(d, "contact_steps.csv"))))
if not rows:
    sys.exit("plot_contact: contact_steps.csv has no rows")
pairs = list(dict.fromkeys(r["pair"] for r in rows))
steps = sorted({int(r["step"]) for r in rows})
last = steps[-1]
data = defaultdict(list)  # (pair, step) -> rows sorted by arc
for r in rows:
    data[(r["pair"], int(r["step"]))].append(r)
for k in data:
    data[k].sort(key=lambda r: float(r["arc"]))

fig, axes = plt.subplots(2, len(pairs), figsize=(6.5 * len(pairs), 7), squeeze=False,
                         sharex="col")
for j, pair in enumerate(pairs):
    ap, at = axes[0][j], axes[1][j]
    shown = steps if all_steps else [last]
    for step in shown:
        pts = data[(pair, step)]
        s_arc = [float(r["arc"]) for r in pts]
        final = step == last
        shade = 1.0 if final else 0.15 + 0.6 * (step - steps[0]) / max(1, last - steps[0])
        kw = dict(color="black" if final else plt.cm.Greys(shade), lw=1.6 if final else 0.8,
                  zorder=3 if final else 2)
        s = float(pts[0]["s"]) if pts else 0.0
        ap.plot(s_arc, [float(r["pressure"]) for r in pts],
                label=f"step {step} (s = {s:g})" if final or len(shown) <= 8 else None, **kw)
        at.plot(s_arc, [float(r["traction_t"]) for r in pts], **kw)
    # Zones of the final step: a band per node, half way to its neighbours.
    pts = data[(pair, last)]
    arc = [float(r["arc"]) for r in pts]
    for ax in (ap, at):
        lo, hi = ax.get_ylim()
        band = 0.04 * (hi - lo)
        for i, r in enumerate(pts):
            a0 = arc[i] if i == 0 else 0.5 * (arc[i - 1] + arc[i])
            a1 = arc[i] if i + 1 == len(pts) else 0.5 * (arc[i] + arc[i + 1])
            ax.fill_between([a0, a1], lo, lo + band, color=colors.get(r["status"], "white"),
                            lw=0, zorder=1)
        ax.set_ylim(lo, hi)
        ax.axhline(0.0, color="#888888", lw=0.5)
        ax.grid(alpha=0.3)
    ap.set_title(f"contact '{pair}'")
    ap.set_ylabel("pressure (force / length; > 0 compression)")
    at.set_ylabel("tangential traction on the contactor along t")
    at.set_xlabel("arc length from the first contact node")
    handles, labels = ap.get_legend_handles_labels()
    handles += [Patch(color=c, label=n) for n, c in colors.items()]
    ap.legend(handles=handles, fontsize=7, loc="best")
fig.suptitle("contact tractions" + (" over the load steps" if all_steps else " at the final step"))
fig.tight_layout()
tmp = os.path.join(d, f"contact.png.{os.getpid()}.tmp")  # this process's own temporary
try:
    fig.savefig(tmp, dpi=120, format="png")
    os.replace(tmp, os.path.join(d, "contact.png"))
except BaseException:
    if os.path.exists(tmp):
        os.remove(tmp)
    raise
print(f"wrote {os.path.join(d, 'contact.png')}")
