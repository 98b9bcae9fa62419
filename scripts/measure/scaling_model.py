#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""A model of the distributed mg's time per V-cycle and per load step on 64 and 1024 processes
(docs/parallel.md#cluster-model):

    /usr/bin/python3 scripts/measure/scaling_model.py measure   # the benches below (idle machine: timings)
    /usr/bin/python3 scripts/measure/scaling_model.py model     # the model from their JSON files

`measure` runs `mlcontact bench comm` on the square's elastic block (out/model/):
  counts_np{2,4,8}.json  level 6 under mpirun -np 2, 4, 8 --oversubscribe with the PMPI library
                         preloaded: messages, bytes, reductions per V-cycle, per level, per mat-vec
                         and per CGS iteration (oversubscribed runs count, they do not time);
  time_np1.json, time_np2.json   level 6 on 1 and 2 processes: seconds per operation (the
                         per-process compute cost); np 2 is the run the model is checked against;
  lu_p{1..4}.json        one process, partition level p = 1..4: seconds of one solve with level
                         p's LU (the gathered coarse solve), to fit its growth with the size;
  square_np{1,2}.json    `bench square --levels 6` on 1 process (1 thread) and 2 processes: Newton
                         steps per load step, Krylov iterations per Newton step, wall time per
                         load step.
`model` combines them with stated network assumptions (--latency, --bandwidth) and writes
out/model/scaling_model.json and docs/results/scaling_model.png, and prints the tables of
docs/results/parallel.md#results-parallel.

The model, per V-cycle on P processes from level L with partition level p (the run's rule):
  compute    sum over l = p+1..L of c * n_l / P * imbalance   (c: seconds per unknown and level
             of a V-cycle, measured on 2 processes; imbalance: largest owned / mean, at np 8)
  halo       sum over l of 4 exchanges * (m * alpha + b_l / beta), m messages per exchange (the
             neighbours: the measured np 8 value, at least 6 for P >= 64 in 2D), b_l bytes per
             process = k * 8 * sqrt(n_l / P), k fitted on the np 2, 4, 8 counts
  coarse     2 gathers * alpha * ceil(log2 P) + 8 n_p (P-1)/P / beta   (level p's residual on
             every process) + t_LU(n_p) = a * n_p^g fitted on the lu_p runs
and per CGS iteration 2 V-cycles, 2 mat-vecs and r reductions of 2 alpha log2 P each. A load step
costs, on every level p+1..L, (Newton steps per load step) x (iterations per step) x (one CGS
iteration from that level), plus the redundant one-process solve of levels 0..p (seconds per
unknown of level p per load step, from square_np1).
"""
import argparse
import json
import math
import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent.parent
OUT = ROOT / "out" / "model"


def sh(cmd, env=None):
    print("+", " ".join(cmd), flush=True)
    r = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"failed ({r.returncode}): {' '.join(cmd)}\n{r.stdout}\n{r.stderr}")
    return r.stdout


def measure(a):
    OUT.mkdir(parents=True, exist_ok=True)
    exe = a.mlcontact
    lib = str(pathlib.Path(exe).resolve().parent.parent / "lib" / "libmlc_pmpi_counters.so")
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    env1 = dict(env, OMPI_MCA_ess_singleton_isolated="1")
    mpi = [a.mpiexec, "--oversubscribe"]
    L = str(a.levels)
    for n in () if a.timing_only else (2, 4, 8):
        sh(mpi + ["-np", str(n), "-x", f"LD_PRELOAD={lib}", exe, "bench", "comm", "--levels", L,
                  "--ops", "2", "--out", str(OUT / f"counts_np{n}.json")], env)
    sh([exe, "bench", "comm", "--levels", L, "--out", str(OUT / "time_np1.json")], env1)
    sh(mpi + ["-np", "2", "-x", f"LD_PRELOAD={lib}", exe, "bench", "comm", "--levels", L,
              "--out", str(OUT / "time_np2.json")], env)
    for p in (1, 2, 3, 4):
        sh([exe, "bench", "comm", "--levels", str(p + 1), "--partition-level", str(p), "--ops",
            "20", "--out", str(OUT / f"lu_p{p}.json")], env1)
    env_t1 = dict(env1, OMP_NUM_THREADS="1")
    sh([exe, "bench", "square", "--levels", L, "--pc", "mg",
        "--out", str(OUT / "square_np1.json")], env_t1)
    sh(mpi + ["-np", "2", exe, "bench", "square", "--levels", L,
              "--out", str(OUT / "square_np2.json")], env)


def load(name):
    return json.loads((OUT / name).read_text())


def ops(js):
    return {(o["name"], o["level"]): o for o in js["operations"]}


def fit_power(xs, ys):
    """y = a x^g by least squares in logs."""
    lx = [math.log(x) for x in xs]
    ly = [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    g = sum((u - mx) * (v - my) for u, v in zip(lx, ly)) / sum((u - mx) ** 2 for u in lx)
    return math.exp(my - g * mx), g


def square_steps(js, load_steps):
    """Newton steps per load step and Krylov iterations per Newton step of the finest level, and
    the wall time per load step, from a bench square JSON (one process: its first solver; N
    processes: its levels table)."""
    if "runs" in js:
        run = js["runs"][0]
        lv = run["levels"][-1]
        return (lv["newton_steps"] / load_steps, lv["krylov_per_newton"],
                run["wall_seconds"] / load_steps)
    lv = js["levels_table"][-1]
    return lv["newton"] / load_steps, lv["its_per_newton"], js["wall_seconds"] / load_steps


def model(a):
    counts = {n: load(f"counts_np{n}.json") for n in (2, 4, 8)}
    t1, t2 = load("time_np1.json"), load("time_np2.json")
    L0 = t2["level"]
    T0 = t2["level0_triangles"]
    n_of = {x["level"]: x["unknowns"] for x in t2["levels"]}
    nL0 = n_of[L0]

    def n_level(l):  # elastic-block unknowns of square level l (x4 per level above L0)
        return n_of[l] if l in n_of else nL0 * 4.0 ** (l - L0)

    def p_rule(P, L):  # levels::partition_level
        p, t = 0, T0
        while p < L - 1 and t < 2000 * P:
            p, t = p + 1, t * 4
        return p

    # Compute: seconds per unknown and level of a V-cycle (np 2: the per-process cost with the
    # cuts), and of a mat-vec; np 1 beside it.
    def per_unknown(js, owned):
        o = ops(js)
        p, L = js["partition_level"], js["level"]
        share = o[("vcycle", L)]["seconds"] - o[("vcycle", p + 1)]["seconds"]
        return share / sum(owned(l) for l in range(p + 2, L + 1)), \
            o[("matvec", L)]["seconds"] / owned(L)
    own2 = {x["level"]: x["owned_max"] for x in t2["levels"]}
    c1, mv1 = per_unknown(t1, lambda l: n_of[l])
    c2, mv2 = per_unknown(t2, lambda l: own2[l])
    c, cmv = c2, mv2
    own8 = {x["level"]: x["owned_max"] for x in counts[8]["levels"]}
    imbalance = own8[L0] / (nL0 / 8)

    # Halo: messages per exchange and the bytes constant k, per np (finest level's share).
    halo = {}
    for n, js in counts.items():
        o = ops(js)
        p = js["partition_level"]
        lev = o[("vcycle", L0)]["max"]
        below = o[("vcycle", L0 - 1)]["max"] if L0 - 1 > p else {"p2p_messages": 0, "p2p_bytes": 0}
        msgs = (lev["p2p_messages"] - below["p2p_messages"]) / 4
        byts = (lev["p2p_bytes"] - below["p2p_bytes"]) / 4
        halo[n] = {"messages_per_exchange": msgs, "bytes_per_exchange": byts,
                   "k": byts / (8 * math.sqrt(nL0 / n)),
                   "cgs_reductions_per_iteration": o[("cgs", L0)]["max"]["reductions"],
                   "matvec_messages": o[("matvec", L0)]["max"]["p2p_messages"],
                   "matvec_bytes": o[("matvec", L0)]["max"]["p2p_bytes"],
                   "vcycle_gathers": o[("vcycle", L0)]["max"]["gathers"],
                   "vcycle_gather_bytes": o[("vcycle", L0)]["max"]["gather_bytes"],
                   "vcycle_messages": o[("vcycle", L0)]["max"]["p2p_messages"],
                   "vcycle_bytes": o[("vcycle", L0)]["max"]["p2p_bytes"],
                   "partition_level": p}
    k = max(h["k"] for h in halo.values())
    m8 = halo[8]["messages_per_exchange"]
    red = max(h["cgs_reductions_per_iteration"] for h in halo.values())

    # Coarse LU: seconds of one solve against level p's unknowns.
    lus = [load(f"lu_p{p}.json") for p in (1, 2, 3, 4)]
    xs = [js["coarse_unknowns"] for js in lus]
    ys = [ops(js)[("coarse_lu", js["partition_level"])]["seconds"] for js in lus]
    a_lu, g_lu = fit_power(xs, ys)

    # Newton steps and Krylov iterations per load step; the one-process time per load step.
    sq1, sq2 = load("square_np1.json"), load("square_np2.json")
    newton_per_step, its, wall1_step = square_steps(sq1, a.load_steps)
    _, _, wall2_step = square_steps(sq2, a.load_steps)
    serial_per_unknown = wall1_step / sum(n_level(l) for l in range(0, L0 + 1))
    # Per Newton step outside the Krylov solve (assembly, statuses, smoother and coarse setup),
    # seconds per unknown, from the one-process run's finest level.
    lv1 = sq1["runs"][0]["levels"][-1]
    newton_overhead = (lv1["level_seconds"] - lv1["solve_seconds"]) / lv1["newton_steps"] / \
        lv1["unknowns"]

    def predict(P, L, alpha, beta, neighbours=None, c=c2, p_set=None):
        p = p_rule(P, L) if p_set is None else p_set
        m = neighbours if neighbours is not None else (max(m8, 6) if P >= 64 else
                                                       halo.get(P, halo[8])["messages_per_exchange"])
        logp = math.ceil(math.log2(P)) if P > 1 else 0

        def vcycle(top):
            comp = sum(c * n_level(l) / P * imbalance for l in range(p + 1, top + 1))
            hal = sum(4 * (m * alpha + k * 8 * math.sqrt(n_level(l) / P) / beta)
                      for l in range(p + 1, top + 1))
            npc = n_level(p)
            gather = 2 * alpha * logp + 8 * npc * (P - 1) / P / beta
            lu = a_lu * npc ** g_lu
            return comp, hal, gather, lu

        def iteration(top):
            comp, hal, gather, lu = vcycle(top)
            mv = cmv * n_level(top) / P * imbalance + m * alpha + \
                k * 8 * math.sqrt(n_level(top) / P) / beta
            redu = red * 2 * alpha * logp
            return 2 * (comp + hal + gather + lu) + 2 * mv + redu

        comp, hal, gather, lu = vcycle(L)
        distributed = sum(newton_per_step * (its * iteration(l) +
                                             newton_overhead * n_level(l) / P * imbalance)
                          for l in range(p + 1, L + 1))
        serial = serial_per_unknown * sum(n_level(l) for l in range(0, p + 1))
        return {"processes": P, "level": L, "partition_level": p, "partition_rule": p_set is None,
                "unknowns": n_level(L), "coarse_unknowns": n_level(p),
                "vcycle": {"compute": comp, "halo": hal, "coarse_gather": gather,
                           "coarse_lu": lu, "total": comp + hal + gather + lu},
                "cgs_iteration": iteration(L),
                "load_step": {"distributed_levels": distributed, "serial_levels_0_to_p": serial,
                              "total": distributed + serial}}

    # The check: np 2 on this machine (shared memory; alpha, beta of a shared-memory MPI).
    # The compute cost from the one-process run (c1), so that the check is a prediction.
    check = predict(2, L0, a.shm_latency, a.shm_bandwidth,
                    neighbours=halo[2]["messages_per_exchange"], c=c1)
    o2 = ops(t2)
    # The distributed levels' seconds per load step (the bench's levels table, setup and output
    # left out, as the model leaves them out).
    dist2 = sum(x["seconds"] for x in sq2["levels_table"] if x["distributed"]) / a.load_steps
    serial2 = sum(x["seconds"] for x in sq2["levels_table"] if not x["distributed"]) / a.load_steps
    measured = {"vcycle": o2[("vcycle", L0)]["seconds"], "cgs_iteration": o2[("cgs", L0)]["seconds"],
                "load_step_distributed_levels": dist2, "load_step_serial_levels": serial2,
                "wall_per_load_step": wall2_step}
    rows = [predict(P, L, a.latency, a.bandwidth) for P in (64, 1024) for L in (8, 9, 10)]
    # The remedy the rows name for 1024 processes: a coarser partition level (--partition-level).
    rows += [predict(1024, L, a.latency, a.bandwidth, p_set=a.capped_p) for L in (8, 9, 10)]
    result = {
        "inputs": {"compute_seconds_per_unknown_level_vcycle": {"np1": c1, "np2": c2},
                   "matvec_seconds_per_unknown": {"np1": mv1, "np2": mv2},
                   "imbalance_np8": imbalance, "halo": halo, "k": k,
                   "reductions_per_cgs_iteration": red,
                   "coarse_lu_fit": {"a": a_lu, "g": g_lu, "unknowns": xs, "seconds": ys},
                   "newton_steps_per_load_step": newton_per_step,
                   "krylov_iterations_per_newton_step": its,
                   "one_process_seconds_per_load_step_level": wall1_step,
                   "serial_seconds_per_unknown_load_step": serial_per_unknown,
                   "newton_overhead_seconds_per_unknown": newton_overhead,
                   "latency": a.latency, "bandwidth": a.bandwidth,
                   "shm_latency": a.shm_latency, "shm_bandwidth": a.shm_bandwidth},
        "check_np2": {"predicted": check, "measured": measured},
        "rows": rows}
    (OUT / "scaling_model.json").write_text(json.dumps(result, indent=2))

    def us(x):
        return f"{x * 1e3:.3g} ms" if x < 1 else f"{x:.3g} s"
    print(f"inputs: c = {c2:.3g} s per unknown per level of a V-cycle (np 2; np 1: {c1:.3g}), "
          f"mat-vec {mv2:.3g} s per unknown, imbalance {imbalance:.3f}, k = {k:.2f}, "
          f"{m8:.2f} messages per exchange at np 8, {red:.2f} reductions per CGS iteration, "
          f"t_LU = {a_lu:.3g} n^{g_lu:.2f}, {newton_per_step:.2f} Newton steps per load step, "
          f"{its:.2f} CGS iterations per Newton step, {newton_overhead:.3g} s per unknown per Newton "
          f"step outside the Krylov solve")
    print("\n| np | messages/exchange | bytes/exchange (level %d) | k | V-cycle msgs | V-cycle bytes |"
          " gathers/V-cycle (bytes) | reductions/CGS it |" % L0)
    print("|---|---|---|---|---|---|---|---|")
    for n, h in halo.items():
        print(f"| {n} | {h['messages_per_exchange']:.2f} | {h['bytes_per_exchange']:.0f} | "
              f"{h['k']:.2f} | {h['vcycle_messages']:.0f} | {h['vcycle_bytes']:.0f} | "
              f"{h['vcycle_gathers']:.0f} ({h['vcycle_gather_bytes']:.0f}) | "
              f"{h['cgs_reductions_per_iteration']:.2f} |")
    print(f"\ncheck, np 2 level {L0}: V-cycle predicted {us(check['vcycle']['total'])} measured "
          f"{us(measured['vcycle'])}; CGS iteration predicted {us(check['cgs_iteration'])} measured "
          f"{us(measured['cgs_iteration'])}; load step, distributed levels: predicted "
          f"{us(check['load_step']['distributed_levels'])} measured "
          f"{us(measured['load_step_distributed_levels'])}, levels 0..p predicted "
          f"{us(check['load_step']['serial_levels_0_to_p'])} measured "
          f"{us(measured['load_step_serial_levels'])} (wall per load step with setup and output "
          f"{us(measured['wall_per_load_step'])})")
    print("\n| P | level | unknowns | p (coarse unknowns) | V-cycle compute | halo | coarse gather |"
          " coarse LU | V-cycle | load step (distributed + levels 0..p) | bottleneck |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        v = r["vcycle"]
        parts = {"compute": v["compute"], "halo": v["halo"], "coarse gather": v["coarse_gather"],
                 "coarse LU": v["coarse_lu"]}
        ls = r["load_step"]
        worst = max(parts, key=parts.get)
        if ls["serial_levels_0_to_p"] > ls["distributed_levels"]:
            worst = "levels 0..p on every process"
        pl = f"{r['partition_level']}" + ("" if r["partition_rule"] else " (set)")
        print(f"| {r['processes']} | {r['level']} | {r['unknowns']:.3g} | {pl} "
              f"({r['coarse_unknowns']:.3g}) | {us(v['compute'])} | {us(v['halo'])} | "
              f"{us(v['coarse_gather'])} | {us(v['coarse_lu'])} | {us(v['total'])} | "
              f"{us(ls['total'])} ({us(ls['distributed_levels'])} + {us(ls['serial_levels_0_to_p'])})"
              f" | {worst} |")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(10, 4.5))
        labels = [f"P={r['processes']}\nL={r['level']}" + ("" if r["partition_rule"] else
                                                           f"\np={r['partition_level']}")
                  for r in rows]
        bottom = [0.0] * len(rows)
        for key, name in (("compute", "compute"), ("halo", "halo"),
                          ("coarse_gather", "coarse gather"), ("coarse_lu", "coarse LU")):
            vals = [r["vcycle"][key] for r in rows]
            ax.bar(labels, vals, bottom=bottom, label=name)
            bottom = [b + v for b, v in zip(bottom, vals)]
        ax.set_ylabel("seconds per V-cycle (model)")
        ax.set_title(f"distributed mg on the square: model (alpha {a.latency:g} s, "
                     f"beta {a.bandwidth:g} B/s)")
        ax.legend()
        fig.tight_layout()
        fig.savefig(ROOT / "docs" / "results" / "scaling_model.png", dpi=110)
        print("\nwrote docs/results/scaling_model.png")
    except ImportError:
        print("matplotlib missing: no plot")
    print(f"wrote {OUT / 'scaling_model.json'}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("what", choices=["measure", "model"])
    ap.add_argument("--levels", type=int, default=6, help="level of the measured runs (6)")
    ap.add_argument("--timing-only", action="store_true",
                    help="measure: leave out the counting runs (kept from an earlier measure)")
    ap.add_argument("--capped-p", type=int, default=4,
                    help="model: the partition level set for the extra 1024-process rows (4)")
    ap.add_argument("--load-steps", type=int, default=5, help="the scene's load steps (square: 5)")
    ap.add_argument("--mlcontact", default=str(ROOT / "build" / "bin" / "mlcontact"))
    ap.add_argument("--mpiexec", default="mpirun")
    ap.add_argument("--latency", type=float, default=2e-6,
                    help="network latency per message, s (2e-6: InfiniBand HDR through MPI)")
    ap.add_argument("--bandwidth", type=float, default=10e9,
                    help="network bandwidth per process, B/s (1e10: HDR, one process per link)")
    ap.add_argument("--shm-latency", type=float, default=1e-6,
                    help="shared-memory MPI latency of this machine, s (for the np 2 check)")
    ap.add_argument("--shm-bandwidth", type=float, default=5e9,
                    help="shared-memory MPI bandwidth of this machine, B/s")
    a = ap.parse_args()
    measure(a) if a.what == "measure" else model(a)


if __name__ == "__main__":
    main()
