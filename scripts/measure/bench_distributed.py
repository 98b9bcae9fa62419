#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""One process against N processes, back to back, on the same commit (docs/results/parallel.md#results-parallel):

    /usr/bin/python3 scripts/measure/bench_distributed.py --levels 6 --repeat 3 --np 2

runs `mlcontact bench square --levels L --repeat R` on one process (its default threads) and
then `mpirun -np N mlcontact bench square ...` (one thread per process), reads both JSON files
and prints and writes (out/bench/distributed_<scene>_L<L>_np<N>.json) the median wall times,
their ratio, the peak RSS of the one process against the largest of the N, and the Krylov
iterations per Newton step of every level side by side. Run it on an idle machine.
"""
import argparse
import json
import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent.parent


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", default="square")
    ap.add_argument("--levels", type=int, default=6)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--np", type=int, default=2)
    ap.add_argument("--mlcontact", default=str(ROOT / "build" / "bin" / "mlcontact"))
    ap.add_argument("--mpiexec", default="mpirun")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    out = pathlib.Path(a.out or f"out/bench/distributed_{a.scene}_L{a.levels}_np{a.np}.json")
    out.parent.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    one_json = out.with_name(out.stem + "_one.json")
    many_json = out.with_name(out.stem + "_many.json")
    common = ["bench", "square", a.scene, "--levels", str(a.levels), "--repeat", str(a.repeat)]
    subprocess.run([a.mlcontact, *common, "--out", str(one_json)], check=True,
                   env=dict(env, OMPI_MCA_ess_singleton_isolated="1"), stdout=sys.stderr)
    subprocess.run([a.mpiexec, "-np", str(a.np), "--oversubscribe", a.mlcontact, *common,
                    "--out", str(many_json)], check=True, env=env, stdout=sys.stderr)
    one = json.loads(one_json.read_text())
    many = json.loads(many_json.read_text())
    run = one["runs"][0]
    one_wall = run["wall_seconds"]
    one_rss = run.get("peak_rss_mib", 0) * 2**20
    its_one = {r["level"]: r["krylov_per_newton"] for r in run["levels"]}
    its_many = {r["level"]: r["its_per_newton"] for r in many["levels_table"]}
    result = {
        "scene": a.scene, "levels": a.levels, "repeat": a.repeat, "processes": a.np,
        "one_process_wall_seconds": one_wall, "processes_wall_seconds": many["wall_seconds"],
        "wall_ratio": many["wall_seconds"] / one_wall,
        "one_process_peak_rss_bytes": one_rss,
        "largest_process_peak_rss_bytes": many["peak_rss_bytes_max"],
        "rss_ratio": many["peak_rss_bytes_max"] / one_rss if one_rss else None,
        "its_per_newton": [{"level": l, "one": its_one.get(l), "many": its_many.get(l)}
                           for l in sorted(its_many)],
    }
    out.write_text(json.dumps(result, indent=2) + "\n")
    print(f"{a.scene} level {a.levels}, medians of {a.repeat}: one process "
          f"{one_wall:.2f} s, {a.np} processes {many['wall_seconds']:.2f} s "
          f"(ratio {result['wall_ratio']:.2f}); peak RSS {one_rss / 2**20:.0f} MiB against "
          f"{many['peak_rss_bytes_max'] / 2**20:.0f} MiB per process "
          f"(ratio {result['rss_ratio']:.2f})")
    for r in result["its_per_newton"]:
        print(f"  level {r['level']}: Krylov its per Newton step {r['one']} / {r['many']}")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
