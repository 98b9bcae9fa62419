#!/usr/bin/env bash
# The square exported from level L as a Gmsh file against the refined square (docs/results/mg.md#results-mg
# and docs/guide/scenes.md#scenes-recovered-levels). The export is a uniform
# refinement, so by default the scene recovers its levels ([scene].recover_levels): the default
# solver (coarse-to-fine, mg) and `--linear schur` on it; then the same file read flat
# (`recover_levels = false`: one level, no hierarchy) with its default (schur there),
# `--linear krylov` (the default mg pair over the aggregation hierarchy) and `--pc mg` (CGS +
# V(1,1)); and `run square --levels L --cold` (geometric mg), alternated REPEAT times. Prints one
# line per run (configuration, run, wall milliseconds) and the medians.
# Run it on an idle machine: it measures wall time.
#
#   bash scripts/measure/bench_gmsh_export.sh [L [REPEAT]]     # default: level 4, 3 repeats
set -euo pipefail
cd "$(dirname "$0")/../.."
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
flat=$work/square_L${level}_flat.toml
sed -e "s|^\[scene\]$|[scene]\nrecover_levels = false|" "$scene" > "$flat"
grep -q "recover_levels = false" "$flat" || { echo "could not write the flat scene"; exit 1; }
declare -A args=(
  [default]="run $scene"
  [schur]="run $scene --linear schur"
  [flat_default]="run $flat"
  [flat_krylov]="run $flat --linear krylov"
  [flat_pc_mg]="run $flat --pc mg"
  [cold]="run square --levels $level --cold"
)
names=(default schur flat_default flat_krylov flat_pc_mg cold)
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
