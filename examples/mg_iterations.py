#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Krylov iterations of the multilevel preconditioner `mg` against the level: per level, the
Krylov (CGS) iterations per Newton step, averaged over the run and at their maximum. Iterations
that stay flat as the level grows are what a multilevel preconditioner promises.

    python3 examples/mg_iterations.py                 # square, levels 1..4
    python3 examples/mg_iterations.py --levels 1 2 3 --out /tmp/mg
"""
import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _path  # noqa: E402

_path.setup()
import mlcontact  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", default="square")
    ap.add_argument("--levels", type=int, nargs="+", default=[1, 2, 3, 4])
    ap.add_argument("--out", default="out/mg_iterations")
    ap.add_argument("--no-plot", action="store_true")
    args = ap.parse_args()
    scene = mlcontact.Scene.builtin(args.scene)
    os.makedirs(args.out, exist_ok=True)
    rows = []
    print(f"{'level':>5} {'unknowns':>10} {'newton':>7} {'krylov':>7} {'per newton':>11} {'max':>5} {'seconds':>8}")
    for level in args.levels:
        r = mlcontact.solve(scene, levels=level, pc="mg")
        per = [k for s in r.steps for k in s["linear_iterations_per_newton"]]
        newton = sum(s["newton_iterations"] for s in r.steps)
        krylov = sum(s["linear_iterations"] for s in r.steps)
        seconds = sum(s["seconds"] for s in r.steps)
        row = {"level": level, "unknowns": r.unknowns, "newton_iterations": newton,
               "krylov_iterations": krylov, "krylov_per_newton": krylov / max(newton, 1),
               "krylov_max": int(max(per)) if per else 0, "seconds": seconds}
        rows.append(row)
        print(f"{level:5d} {r.unknowns:10d} {newton:7d} {krylov:7d} {row['krylov_per_newton']:11.2f}"
              f" {row['krylov_max']:5d} {seconds:8.2f}")
    with open(os.path.join(args.out, "mg_iterations.json"), "w") as f:
        json.dump({"scene": scene.name, "pc": "mg", "rows": rows}, f, indent=1)
    if args.no_plot:
        return
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot([r["level"] for r in rows], [r["krylov_per_newton"] for r in rows], "o-", label="mean per Newton step")
    ax.plot([r["level"] for r in rows], [r["krylov_max"] for r in rows], "s--", label="max per Newton step")
    ax.set_xlabel("level")
    ax.set_ylabel("CGS iterations with mg")
    ax.set_title(f"{scene.name}: Krylov iterations of mg against level")
    ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    png = os.path.join(args.out, "mg_iterations.png")
    fig.savefig(png, dpi=120)
    print(f"wrote {png}")


if __name__ == "__main__":
    main()
