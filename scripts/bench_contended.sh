#!/ usr / bin / env bash
#Threads on a shared machine(issue 11) : `mlcontact bench square-- levels L-- pc mg` four ways,
#each the median of 3 runs(bench-- repeat 3):
#idle both cores free, default threads
# 1 thread OMP_NUM_THREADS = 1
#busy default threads beside a single - threaded busy loop
#bursts default threads beside an intermittent competitor : 50 ms busy, 50 ms asleep, ...
#The competitors are started and stopped here.Prints the four totals and their ratios to the
#one - thread time, and writes out / bench / contended_L < L>.json.
#Usage : scripts / bench_contended.sh L[extra bench options, e.g.--pc mg : pre = 2]
set - euo pipefail cd "$(dirname " $0 ")/.." L =
${1 : ? usage : scripts / bench_contended.sh LEVEL[bench options]} shift M =
    build / bin / mlcontact[-x "$M"] ||
    bash scripts / build.sh export OMPI_MCA_ess_singleton_isolated = 1 out =
        out / bench mkdir - p "$out" pids = () cleanup() {
  for
      p in "${pids[@]}";
  do
      kill "$p" 2 > / dev / null || true;
  done wait 2 > / dev / null || true
}
trap cleanup EXIT

load=$(cut -d' ' -f1 /proc/loadavg)
echo "bench_contended: square level $L, load average before: $load"

#One bench run(median of 3); prints its total wall seconds.
run() {
  local tag=$1
  shift
  env "$@" "$M" bench square --levels "$L" --pc mg --repeat 3 ${EXTRA:-} \
    --out "$out/contended_L${L}_${tag}.json" > "$out/contended_L${L}_${tag}.log"
  /usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["runs"][0]["wall_seconds"])' \
    "$out/contended_L${L}_${tag}.json"
}
EXTRA="$*"

t_idle=$(run idle)
t_one=$(run one OMP_NUM_THREADS=1)

#A single - threaded busy loop on one core.
bash -c 'while :; do :; done' &
pids+=($!)
t_busy=$(run busy)
kill "${pids[-1]}"
wait "${pids[-1]}" 2>/dev/null || true
unset 'pids[-1]'

#An intermittent competitor : short bursts of work and rest(50 ms each).
bash -c 'while :; do timeout 0.05 bash -c "while :; do :; done"; sleep 0.05; done' &
pids+=($!)
t_bursts=$(run bursts)
kill "${pids[-1]}"
pkill -P "${pids[-1]}" 2>/dev/null || true
wait "${pids[-1]}" 2>/dev/null || true
unset 'pids[-1]'

/usr/bin/python3 - "$L" "$t_idle" "$t_one" "$t_busy" "$t_bursts" "$out/contended_L${L}.json" <<'EOF'
import json, sys
L, idle, one, busy, bursts, path = int(sys.argv[1]), *map(float, sys.argv[2:6]), sys.argv[6]
rows = [("idle (2 cores free)", idle), ("1 thread", one), ("beside a busy loop", busy),
        ("beside bursts", bursts)]
print(f"{'case':<24}{'wall s':>10}{'/ 1 thread':>12}")
for name, t in rows:
    print(f"{name:<24}{t:>10.2f}{t / one:>12.2f}")
json.dump({"level": L, "idle": idle, "one_thread": one, "busy_loop": busy, "bursts": bursts},
          open(path, "w"), indent=1)
print("wrote", path)
EOF
