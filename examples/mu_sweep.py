#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Sweep over the friction coefficient: pressure and tangential traction along the contact
boundary for each mu, as a plot (mu_sweep.png) and as numbers.

    python3 examples/mu_sweep.py                      # square, level 3, mu 0 .. 0.5
    python3 examples/mu_sweep.py --levels 2 --mu 0 0.3 --out /tmp/sweep

Each run is `mlcontact run SCENE --levels L --mu MU` through the library (same solver choice,
same numbers). The printed totals are sums over the contact nodes of the multipliers (force
per unit thickness): N = -sum lambda_n, T = sum lambda_t; mu_sweep.json holds them and every
node's x, lambda_t, lambda_n, status, so they can be compared with the driver's contact.csv.
"""
import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _path  # noqa: E402

_path.setup()
import numpy as np  # noqa: E402

import mlcontact  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", default="square", help="built-in scene name or .toml file (default square)")
    ap.add_argument("--levels", type=int, default=3, help="finest level (default 3)")
    ap.add_argument("--mu", type=float, nargs="+", default=[0.0, 0.1, 0.2, 0.3, 0.5])
    ap.add_argument("--out", default="out/mu_sweep", help="folder for mu_sweep.png and mu_sweep.json")
    ap.add_argument("--no-plot", action="store_true")
    args = ap.parse_args()

    if args.scene.endswith(".toml") or os.path.exists(args.scene):
        scene = mlcontact.Scene.from_file(args.scene)
    else:
        scene = mlcontact.Scene.builtin(args.scene)
    os.makedirs(args.out, exist_ok=True)
    runs = []
    print(f"scene {scene.name}, level {args.levels}, mlcontact {mlcontact.__version__}")
    print(f"{'mu':>6} {'newton':>7} {'N = -sum ln':>24} {'T = sum lt':>24} {'max |ln|':>24}"
          f" {'stick':>6} {'slip':>5} {'gap':>5}")
    for mu in args.mu:
        r = mlcontact.solve(scene, levels=args.levels, mu=mu)
        ln, lt, st = np.asarray(r.lambda_n), np.asarray(r.lambda_t), np.asarray(r.status)
        N, T, lmax = -float(np.sum(ln)), float(np.sum(lt)), float(np.max(np.abs(ln)))
        newton = sum(s["newton_iterations"] for s in r.steps)
        counts = [int(np.sum(st == k)) for k in range(4)]
        print(f"{mu:6.3f} {newton:7d} {N:24.17g} {T:24.17g} {lmax:24.17g}"
              f" {counts[1]:6d} {counts[2] + counts[3]:5d} {counts[0]:5d}")
        runs.append({"mu": mu, "newton_iterations": newton, "N": N, "T": T, "max_abs_lambda_n": lmax,
                     "resultants": [d["force"] for d in r.resultants],
                     "x": np.asarray(r.contact_x).tolist(), "lambda_t": lt.tolist(), "lambda_n": ln.tolist(),
                     "status": [mlcontact.STATUS_NAMES[k] for k in st],
                     "tractions": {name: {k: np.asarray(v).tolist() for k, v in d.items()}
                                   for name, d in r.tractions().items()}})
    with open(os.path.join(args.out, "mu_sweep.json"), "w") as f:
        json.dump({"scene": scene.name, "levels": args.levels, "runs": runs}, f)
    print(f"wrote {os.path.join(args.out, 'mu_sweep.json')}")
    if args.no_plot:
        return
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    pairs = list(runs[0]["tractions"].keys())
    fig, axes = plt.subplots(2, len(pairs), figsize=(7 * len(pairs), 7), squeeze=False, sharex="col")
    for j, name in enumerate(pairs):
        for run in runs:
            t = run["tractions"][name]
            axes[0][j].plot(t["s"], t["pressure"], label=f"mu = {run['mu']:g}")
            line, = axes[1][j].plot(t["s"], t["traction"], label=f"mu = {run['mu']:g}")
            # Stick nodes marked (the rest in contact slip; gap nodes carry no traction).
            stick = [i for i, s in enumerate(t["status"]) if s == mlcontact.STICK]
            axes[1][j].plot([t["s"][i] for i in stick], [t["traction"][i] for i in stick], "o",
                            color=line.get_color(), ms=3)
        axes[0][j].set_title(f"{scene.name}, contact '{name}', level {args.levels}")
        axes[0][j].set_ylabel("pressure p = -lambda_n / l")
        axes[1][j].set_ylabel("tangential traction q = lambda_t / l")
        axes[1][j].set_xlabel("arc length from the first contact node (dots: stick nodes)")
        for ax in axes[:, j]:
            ax.grid(True, alpha=0.3)
            ax.legend()
    fig.tight_layout()
    png = os.path.join(args.out, "mu_sweep.png")
    fig.savefig(png, dpi=120)
    print(f"wrote {png}")


if __name__ == "__main__":
    main()
