#!/usr/bin/env bash
# First of the two commands (docs/guide/install.md#install-two-commands): install what is missing, build, and solve the built-in default scene.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
export OMPI_MCA_ess_singleton_isolated=1
./build/bin/mlcontact run
