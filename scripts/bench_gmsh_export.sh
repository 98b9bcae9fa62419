#!/usr/bin/env bash
# The square exported from level L as a Gmsh file (one level, no hierarchy) against the refined
# square (README "`mg` on a mesh without levels"): the default (schur there), `--linear schur`,
# `--linear krylov` (the default mg pair over the aggregation hierarchy), `--pc mg` (CGS +
# V(1,1)) on the export, and `run square --levels L --cold` (geometric mg), alternated REPEAT
# times; prints one line per run (configuration, run, wall milliseconds) and the medians.
# Run it on an idle machine: it measures wall time.
#
#   bash scripts/bench_gmsh_export.sh [L [REPEAT]]     # default: level 4, 3 repeats
set -euo pipefail
cd "$(dirname "$0")/.."
level=${1:-4}
repeat=${2:-3}
exe=build/bin/mlcontact
export OMPI_MCA_ess_singleton_isolated=1
work=out/bench/gmsh_export_L$level
mkdir -p "$work"
"$exe" show square --msh-level "$level" > "$work/square_L$level.msh"
"$exe" show square | sed -e "s|^levels = .*|levels = 0|" \
  -e "s|^mesh = .*|mesh = { type = \"gmsh\", file = \"square_L$level.msh\" }|" > "$work/square_L$level.toml"
grep -q "square_L$level.msh" "$work/square_L$level.toml" || { echo "could not point the scene at the mesh"; exit 1; }
scene=$work/square_L$level.toml
declare -A args=(
  [default]="run $scene"
  [schur]="run $scene --linear schur"
  [krylov]="run $scene --linear krylov"
  [pc_mg]="run $scene --pc mg"
  [cold]="run square --levels $level --cold"
)
names=(default schur krylov pc_mg cold)
declare -A times
for ((r = 1; r <= repeat; r++)); do
  for k in "${names[@]}"; do
    start=$(date +%s%N)
    # shellcheck disable=SC2086
    "$exe" ${args[$k]} --quiet --out "$work/out_$k" > "$work/$k.log" 2>&1 ||
      { echo "$k failed:"; cat "$work/$k.log"; exit 1; }
    ms=$((($(date +%s%N) - start) / 1000000))
    echo "$k run $r: $ms ms"
    times[$k]="${times[$k]:-} $ms"
  done
done
for k in "${names[@]}"; do
  # shellcheck disable=SC2086
  echo "$k median $(printf '%s\n' ${times[$k]} | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}') ms"
done
