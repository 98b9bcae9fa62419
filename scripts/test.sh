#!/usr/bin/env bash
# Second README command: build (installing what is missing) and run the whole test suite.
# `ctest --test-dir build -LE slow` runs the fast subset only.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
export OMPI_MCA_ess_singleton_isolated=1
ctest --test-dir build --output-on-failure -j2 "$@"
