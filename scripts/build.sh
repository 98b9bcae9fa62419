#!/usr/bin/env bash
# Installs missing Debian packages, configures a Release build in build/ and builds everything.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh
# Ninja where present (scripts/deps.sh installs it): unlike make, it compiles a target's files
# while the libraries it links are still being built. An existing build tree keeps its generator.
gen=()
[ ! -f build/CMakeCache.txt ] && command -v ninja > /dev/null && gen=(-G Ninja)
cmake -S . -B build "${gen[@]}" -DCMAKE_BUILD_TYPE=Release "$@" > build.log 2>&1 || { cat build.log; exit 1; }
jobs=$(nproc 2>/dev/null || echo 2)
cmake --build build -j"$jobs" >> build.log 2>&1 || { tail -n 60 build.log; exit 1; }
echo "build: ok (log in build.log); driver at build/bin/mlcontact, Python module in build/python (PYTHONPATH=build/python /usr/bin/python3)"
