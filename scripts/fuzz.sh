#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz) and runs each for a bounded time on its seed corpus.
#
#   bash scripts/fuzz.sh            # both targets, 60 s each (in parallel on two cores)
#   bash scripts/fuzz.sh 600 scene  # fuzz_scene for 10 minutes
#
# Uses build-asan/ when scripts/sanitize.sh configured it with clang (MLC_BUILD_FUZZ=ON there), so
# the instrumented libraries are compiled once; otherwise configures build-fuzz/ with clang,
# address+undefined sanitizers and only what the fuzz targets need.
#
# A finding is any crash, sanitizer report, uncaught exception other than mlc::InvalidInput,
# input slower than -timeout, or memory above -rss_limit_mb: the script prints libFuzzer's report,
# keeps the input as <build>/fuzz/<target>/crash-*|timeout-*|oom-* and exits 1. Reproduce with
# `<build>/bin/fuzz_<target> <that file>`; each finding becomes a unit test in tests/apps or
# tests/mesh. New corpus entries go to <build>/fuzz/<target>/corpus, never to the committed seeds.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
targets=${2:-scene gmsh}
if grep -qs "MLC_BUILD_FUZZ:BOOL=ON" build-asan/CMakeCache.txt; then
  dir=build-asan
else
  dir=build-fuzz
  mkdir -p "$dir"
  bash scripts/deps.sh > /dev/null
  cxx=$(command -v clang++-14 || command -v clang++ || true)
  [ -n "$cxx" ] || { echo "fuzz: clang++ not found (libFuzzer needs clang; install clang-14)"; exit 1; }
  gen=()
  [ ! -f "$dir/CMakeCache.txt" ] && command -v ninja > /dev/null && gen=(-G Ninja)
  cmake -S . -B "$dir" "${gen[@]}" -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=Debug \
    "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -g1 -D_GLIBCXX_ASSERTIONS" -DCGAL_DO_NOT_WARN_ABOUT_CMAKE_BUILD_TYPE=TRUE \
    -DMLC_SANITIZE=ON -DMLC_BUILD_FUZZ=ON -DMLC_WITH_HYPRE=OFF -DMLC_BUILD_BENCH=OFF -DMLC_BUILD_PYTHON=OFF \
    -DMLC_BUILD_TESTS=OFF > "$dir/configure.log" 2>&1 || { cat "$dir/configure.log"; exit 1; }
fi
jobs=${MLC_JOBS:-$(nproc 2>/dev/null || echo 2)}
[ "$jobs" -gt 2 ] && jobs=2
fuzzers=()
for t in $targets; do fuzzers+=("fuzz_$t"); done
cmake --build "$dir" -j"$jobs" --target "${fuzzers[@]}" > "$dir/fuzz-build.log" 2>&1 ||
  { tail -n 60 "$dir/fuzz-build.log"; exit 1; }

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:halt_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
# -timeout: seconds per input (a hang); -rss_limit_mb: memory (ASan's shadow included);
# -max_len: larger than every seed. The runs are bounded by time, not by count; with two cores the
# two targets run side by side.
running=0
for t in $targets; do
  work=$dir/fuzz/$t
  mkdir -p "$work/corpus"
  rm -f "$work/exit"
  touch "$work/start"
  seeds=(tests/fuzz/corpus/"$t")
  [ "$t" = scene ] && seeds+=(scenes)  # every built-in scene is a seed too
  ( set +e
    "$dir/bin/fuzz_$t" "$work/corpus" "${seeds[@]}" -dict="tests/fuzz/$t.dict" \
      -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=8192 \
      -artifact_prefix="$work/" -print_final_stats=1 > "$work/fuzz.log" 2>&1
    echo $? > "$work/exit" ) &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then wait; running=0; fi
done
wait

status=0
for t in $targets; do
  work=$dir/fuzz/$t
  log=$work/fuzz.log
  runs=$(grep -oE "stat::number_of_executed_units: *[0-9]+" "$log" | grep -oE "[0-9]+$" || echo "?")
  cov=$(grep -E "^#[0-9]+" "$log" | tail -n 1 | grep -oE "cov: [0-9]+ ft: [0-9]+ corp: [0-9]+/[0-9]+[a-zA-Z]*" || echo "cov: ?")
  if [ "$(cat "$work/exit" 2>/dev/null)" = 0 ] && grep -q "^Done [0-9]* runs" "$log"; then
    echo "fuzz_$t: ${runs} runs in ${seconds} s, ${cov}, no findings"
  else
    echo "fuzz_$t: FINDING after ${runs} runs (exit $(cat "$work/exit" 2>/dev/null)); libFuzzer's report ($log):"
    grep -vE "^#[0-9]+ " "$log" | tail -n 60
    find "$work" -maxdepth 1 -newer "$work/start" -regex ".*/\(crash\|timeout\|oom\|leak\)-.*"
    status=1
  fi
done
exit $status
