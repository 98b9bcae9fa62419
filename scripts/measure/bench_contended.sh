#!/usr/bin/env bash
# Threads on a shared machine (docs/results/mg.md#results-mg): `mlcontact bench square --levels L --pc mg` four ways,
# each the median of 3 runs (bench --repeat 3):
#   idle      both cores free, default threads
#   1 thread  OMP_NUM_THREADS=1
#   busy      default threads beside a single-threaded busy loop
#   bursts    default threads beside an intermittent competitor: 50 ms busy, 50 ms asleep, ...
# The competitors are started and stopped here. Prints the four totals and their ratios to the
# one-thread time, and writes out/bench/contended_L<L>.json.
# Usage: scripts/measure/bench_contended.sh L [extra bench options, e.g. --tol 1e-6]
set -euo pipefail
cd "$(dirname "$0")/../.."
L=${1:?usage: scripts/measure/bench_contended.sh LEVEL [bench options]}
shift
EXTRA=("$@")
M=build/bin/mlcontact
[ -x "$M" ] || bash scripts/build.sh
export OMPI_MCA_ess_singleton_isolated=1
out=out/bench
mkdir -p "$out"
competitor=""
stop_competitor() {
  if [ -n "$competitor" ]; then
    pkill -P "$competitor" 2>/dev/null || true
    kill "$competitor" 2>/dev/null || true
    wait "$competitor" 2>/dev/null || true
    competitor=""
  fi
}
trap stop_competitor EXIT

echo "bench_contended: square level $L, load average before: $(cut -d' ' -f1-3 /proc/loadavg)"

# One bench run (median of 3); prints its total wall seconds.
run() {
  local tag=$1
  shift
  env "$@" "$M" bench square --levels "$L" --pc mg --repeat 3 "${EXTRA[@]}" \
    --out "$out/contended_L${L}_${tag}.json" > "$out/contended_L${L}_${tag}.log"
  /usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["runs"][0]["wall_seconds"])' \
    "$out/contended_L${L}_${tag}.json"
}

t_idle=$(run idle)
t_one=$(run one OMP_NUM_THREADS=1)

# A single-threaded busy loop.
bash -c 'while :; do :; done' &
competitor=$!
t_busy=$(run busy)
stop_competitor

# An intermittent competitor: bursts of 50 ms of work, then 50 ms of rest.
bash -c 'while :; do timeout 0.05 bash -c "while :; do :; done"; sleep 0.05; done' &
competitor=$!
t_bursts=$(run bursts)
stop_competitor

/usr/bin/python3 - "$L" "$t_idle" "$t_one" "$t_busy" "$t_bursts" "$out/contended_L${L}.json" <<'PY'
import json, sys
L = int(sys.argv[1])
idle, one, busy, bursts = map(float, sys.argv[2:6])
path = sys.argv[6]
rows = [("idle (2 cores free)", idle), ("1 thread", one), ("beside a busy loop", busy),
        ("beside bursts", bursts)]
print(f"{'case':<24}{'wall s':>10}{'/ 1 thread':>12}")
for name, t in rows:
    print(f"{name:<24}{t:>10.2f}{t / one:>12.2f}")
json.dump({"level": L, "idle": idle, "one_thread": one, "busy_loop": busy, "bursts": bursts},
          open(path, "w"), indent=1)
print("wrote", path)
PY
