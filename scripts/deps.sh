#!/usr/bin/env bash
# Installs the Debian packages mlcontact needs, only those that are missing.
# Runs apt-get as root, or through sudo when not root.
set -euo pipefail
packages=(
  build-essential cmake pkg-config
  ninja-build                   # the build tool of scripts/*.sh: starts a target's files before the libraries it links are done
  libeigen3-dev libhypre-dev libopenmpi-dev openmpi-bin
  libcgal-dev libtomlplusplus-dev libcli11-dev libgtest-dev libsuitesparse-dev
  libopenblas0-serial           # the BLAS behind CHOLMOD (schur): 1.9-2.5x faster set-up than libblas3
  zlib1g-dev                    # binary (zlib-compressed) VTU output
  libmetis-dev                  # mesh partitioning for the distributed solve (mesh/partition)
  python3 python3-matplotlib
  python3-vtk9                  # tests: VTK's own reader opens our VTU/PVD files
  pybind11-dev python3-dev python3-numpy python3-pytest   # the Python module (python/) and the Python tests
  clang-14 libclang-rt-14-dev   # sanitizer build and libFuzzer (scripts/sanitize.sh, fuzz.sh)
  python3-sphinx python3-myst-parser python3-sphinx-rtd-theme   # the docs site (scripts/docs.sh)
  doxygen python3-breathe       # the C++ API pages (docs/api/cpp.md#api-cpp)
  libjs-mathjax fonts-mathjax   # math rendered offline, from the built site
  chromium                      # tests: the built site opened in a headless browser
  xvfb xauth                    # offscreen VTK rendering under xvfb-run (docs/viewing.md#viewing-vtk)
  universal-ctags               # function lengths for scripts/check_code_size.sh
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "deps: all Debian packages present"
  exit 0
fi
echo "deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
