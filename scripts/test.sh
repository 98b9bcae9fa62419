#!/usr/bin/env bash
# Second of the two commands (docs/guide/install.md#install-two-commands): build (installing what is missing) and run the whole test suite.
# `ctest --test-dir build -LE slow` runs the fast subset only.
# Then, hostile input (docs/testing.md#testing-hostile): the fast unit tests again under address+undefined sanitizers
# (scripts/sanitize.sh, build-asan/) and both fuzz targets for 60 s each (scripts/fuzz.sh).
# These are skipped when ctest arguments are given or MLC_HOSTILE=0; MLC_FUZZ_SECONDS sets the
# fuzzing time.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
export OMPI_MCA_ess_singleton_isolated=1
ctest --test-dir build --output-on-failure -j2 "$@"
if [ $# -eq 0 ] && [ "${MLC_HOSTILE:-1}" != 0 ]; then
  bash scripts/sanitize.sh
  bash scripts/fuzz.sh "${MLC_FUZZ_SECONDS:-60}"
fi
