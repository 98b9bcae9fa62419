#!/usr/bin/env bash
# Builds the documentation site into build/docs/html (Sphinx, MyST Markdown pages, warnings as
# errors): the Python module first when it is missing or older than its sources (autodoc imports
# it from build/python), then Doxygen's XML of the headers (the C++ API page, through Breathe),
# then the site, and copies Debian's MathJax into it so that math renders offline.
# MLC_BUILD_DIR (default build) names the build tree. Exits non-zero on any warning.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
build=${MLC_BUILD_DIR:-$root/build}
py=/usr/bin/python3
for m in sphinx myst_parser breathe sphinx_rtd_theme; do
  "$py" -c "import $m" 2>/dev/null || { echo "docs: python module $m missing: bash scripts/deps.sh" >&2; exit 1; }
done
command -v doxygen >/dev/null || { echo "docs: doxygen missing: bash scripts/deps.sh" >&2; exit 1; }
[ -f /usr/share/javascript/mathjax/MathJax.js ] || { echo "docs: libjs-mathjax missing: bash scripts/deps.sh" >&2; exit 1; }

# The Python module (autodoc imports it).
if [ ! -f "$build/CMakeCache.txt" ]; then
  gen=()
  command -v ninja > /dev/null && gen=(-G Ninja)
  cmake -S "$root" -B "$build" "${gen[@]}" -DCMAKE_BUILD_TYPE=Release > "$build.docs-cmake.log" 2>&1 || {
    cat "$build.docs-cmake.log" >&2; exit 1; }
fi
cmake --build "$build" --target mlc_python -j"${MLC_DOCS_JOBS:-2}" > "$build/docs-module.log" 2>&1 || {
  tail -30 "$build/docs-module.log" >&2; exit 1; }

# Doxygen XML of the public headers.
out=$build/docs
mkdir -p "$out/doxygen"
(cat docs/Doxyfile; echo "OUTPUT_DIRECTORY=$out/doxygen") | doxygen - > "$out/doxygen.log" 2>&1 || {
  tail -30 "$out/doxygen.log" >&2; exit 1; }

# The site: -W turns every warning (a broken reference, a missing page, a bad directive) into
# an error; --keep-going reports them all before failing. -E: a fresh environment each time.
MLC_BUILD_DIR=$build MLC_DOXYGEN_XML=$out/doxygen/xml \
  "$py" -m sphinx -b html -W --keep-going -E -q -d "$out/doctrees" docs "$out/html"

# MathJax 2 from libjs-mathjax, without its unpacked sources and tests.
rm -rf "$out/html/_static/mathjax"
mkdir -p "$out/html/_static/mathjax"
for d in MathJax.js config extensions fonts jax; do
  cp -rL "/usr/share/javascript/mathjax/$d" "$out/html/_static/mathjax/"
done
echo "docs: $out/html/index.html"
