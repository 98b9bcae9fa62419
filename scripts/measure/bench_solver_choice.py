#!/usr/bin/python3
"""The default Newton-system solver against both candidates (a fast default at every
size; docs/results/solver-choice.md#results-solver-choice): for each scene and level, `mlcontact run SCENE --levels L --quiet` with no solver flag,
with `--linear schur` and with the Krylov + mg candidate (`--linear krylov`, the driver's own
pair: BiCGStab + mg:pre=0,post=2, damped with a two-body pair; --mg sets other flags; none on level 0, where the default is schur
whatever the size), REPEAT times each in turn. Wall time (perf_counter, ms resolution) and the peak
RSS of each process (wait4). Prints the medians, the solver the default chose and its ratios to
the faster and to the smaller candidate (the bar: both at most 1.15), and writes
out/bench/solver_choice.csv and .json. Run it on an idle machine: it measures wall time.

usage: scripts/measure/bench_solver_choice.py [--repeat N] [--mg "FLAGS"] [SCENE:L1,L2 ...]
  default cases (the table of docs/results/solver-choice.md#results-solver-choice): square:1,2,3,4 hertz:1,2,3 calumet:1,2 incline:1,2 patch:1,2
  patch_matching:2 dovetail:1,2,3,4 axis_release:1,2 mindlin:1,2
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EXE = os.path.join(ROOT, "build", "bin", "mlcontact")


def run_once(scene, level, flags):
    with tempfile.TemporaryDirectory() as d:
        cmd = [EXE, "run", scene, "--levels", str(level), "--quiet", "--out", d + "/out"] + flags
        env = dict(os.environ, OMPI_MCA_ess_singleton_isolated="1")
        with open(d + "/log", "w") as log:
            t0 = time.perf_counter()
            p = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=env)
            _, status, usage = os.wait4(p.pid, 0)
            seconds = time.perf_counter() - t0
        text = open(d + "/log").read()
        if status != 0:
            sys.exit(f"{' '.join(cmd)} failed:\n{text}")
        chosen = next(l for l in text.splitlines() if l.startswith("Newton-system solver:"))
        return seconds, usage.ru_maxrss / 1024.0, chosen.split(":", 1)[1].strip()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--mg", default="--linear krylov")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench", "solver_choice"))
    ap.add_argument("cases", nargs="*",
                    default=["square:1,2,3,4", "hertz:1,2,3", "calumet:1,2", "incline:1,2",
                             "patch:1,2", "patch_matching:2", "dovetail:1,2,3,4",
                             "axis_release:1,2", "mindlin:1,2"])
    a = ap.parse_args()
    if not os.access(EXE, os.X_OK):
        sys.exit(f"{EXE} not found: build first (bash scripts/build.sh)")
    candidates = {"default": [], "schur": ["--linear", "schur"], "mg": a.mg.split()}
    print(f"bench_solver_choice: load average before {os.getloadavg()[0]:.2f}; "
          f"mg candidate: {a.mg}; {a.repeat} runs each")
    rows = []
    for case in a.cases:
        scene, levels = case.split(":")
        for level in (int(x) for x in levels.split(",")):
            # On level 0 the default is schur whatever the size: the only candidate compared.
            names = [k for k in candidates if level > 0 or k != "mg"]
            runs = {k: [] for k in names}
            chosen = ""
            for _ in range(a.repeat):
                for name in names:
                    flags = candidates[name]
                    s, mib, c = run_once(scene, level, flags)
                    runs[name].append((s, mib))
                    if name == "default":
                        chosen = c
            med = {k: (statistics.median(s for s, _ in v), statistics.median(m for _, m in v))
                   for k, v in runs.items()}
            if "mg" not in med:
                med["mg"] = (float("nan"), float("nan"))
            best_t = min(t for t, _ in (med["schur"], med["mg"]) if t == t)
            best_m = min(m for _, m in (med["schur"], med["mg"]) if m == m)
            row = {"scene": scene, "level": level,
                   "default": "schur" if chosen.startswith("schur") else "mg",
                   "default_solver": chosen,
                   "time_ratio": med["default"][0] / best_t,
                   "memory_ratio": med["default"][1] / best_m,
                   "runs": {k: [{"seconds": s, "peak_MiB": m} for s, m in v]
                            for k, v in runs.items()}}
            for k in candidates:
                row[f"{k}_s"], row[f"{k}_MiB"] = (None, None) if med[k][0] != med[k][0] else med[k]
            row["within_1.15"] = row["time_ratio"] <= 1.15 and row["memory_ratio"] <= 1.15
            rows.append(row)
            print(f"{scene:9} L{level}  schur {med['schur'][0]:7.3f} s {med['schur'][1]:6.0f} MiB"
                  f"  mg {med['mg'][0]:7.3f} s {med['mg'][1]:6.0f} MiB"
                  f"  default {row['default']:5} {med['default'][0]:7.3f} s "
                  f"{med['default'][1]:6.0f} MiB  time/best {row['time_ratio']:.3f}"
                  f"  mem/best {row['memory_ratio']:.3f}"
                  + ("" if row["within_1.15"] else "  > 1.15"), flush=True)
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    keys = ["scene", "level", "schur_s", "mg_s", "default_s", "schur_MiB", "mg_MiB",
            "default_MiB", "default", "time_ratio", "memory_ratio", "within_1.15"]
    with open(a.out + ".csv.tmp", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    os.replace(a.out + ".csv.tmp", a.out + ".csv")
    with open(a.out + ".json.tmp", "w") as f:
        json.dump({"mg_candidate": a.mg, "repeat": a.repeat, "cases": rows}, f, indent=1)
    os.replace(a.out + ".json.tmp", a.out + ".json")
    ok = all(r["within_1.15"] for r in rows)
    print(("every default within 1.15x of the better candidate in time and memory" if ok
           else "some default above 1.15x") + f"; load average after {os.getloadavg()[0]:.2f}; "
          f"wrote {a.out}.csv, .json")


if __name__ == "__main__":
    main()
