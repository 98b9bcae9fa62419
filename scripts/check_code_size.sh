#!/usr/bin/env bash
# Code-size limits of the source tree; fails (exit 1) listing every breach:
#   - a function longer than FN_MAX lines (150), measured by universal-ctags (its `end:` field),
#     in the code folders: every top-level folder with a CMakeLists.txt but tests/, scripts/,
#     docs/, cmake/, examples/ and build trees (lambdas count as functions of their own);
#   - a C++ file of a code folder longer than FILE_MAX lines (700);
#   - apps/ (its C++ files together) longer than APPS_MAX lines (4000);
#   - a file under python/ that includes a header of apps/ (the Python module binds the
#     libraries beside the command line, not the command line itself).
# Usage: scripts/check_code_size.sh [source dir]   (default: the tree this script is in)
# Needs ctags-universal (Debian package universal-ctags, in scripts/deps.sh); exit 2 without it.
set -euo pipefail
src=${1:-"$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"}
cd "$src"
FN_MAX=${FN_MAX:-150}
FILE_MAX=${FILE_MAX:-700}
APPS_MAX=${APPS_MAX:-4000}
if ! command -v ctags-universal >/dev/null; then
  echo "check_code_size: ctags-universal not found (install universal-ctags: scripts/deps.sh)" >&2
  exit 2
fi

folders=()
for d in */; do
  d=${d%/}
  case $d in tests | scripts | docs | cmake | examples | build*) continue ;; esac
  [ -f "$d/CMakeLists.txt" ] && folders+=("$d")
done
cxx_files() { find "$@" -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' -o -name '*.cc' \) | sort; }

breaches=0
report() {
  echo "$1"
  breaches=$((breaches + 1))
}

# Functions over FN_MAX lines.
while IFS= read -r line; do
  [ -n "$line" ] && report "function over $FN_MAX lines: $line"
done < <(ctags-universal -R --languages=C++ --kinds-C++=f --fields=+ne -f - "${folders[@]}" 2>/dev/null |
  awk -F'\t' -v N="$FN_MAX" '{
    line = ""; end = ""
    for (i = 4; i <= NF; i++) {
      if ($i ~ /^line:/) line = substr($i, 6)
      if ($i ~ /^end:/) end = substr($i, 5)
    }
    if (end != "" && end - line + 1 > N) printf "%d %s:%s %s\n", end - line + 1, $2, line, $1
  }' | sort -rn | awk '{ n = $1; $1 = ""; printf "%s (%d lines)\n", substr($0, 2), n }')

# Files over FILE_MAX lines.
while IFS= read -r f; do
  n=$(wc -l <"$f")
  [ "$n" -gt "$FILE_MAX" ] && report "file over $FILE_MAX lines: $f ($n lines)"
done < <(cxx_files "${folders[@]}")

# apps/ in all.
if [ -d apps ]; then
  total=$(cxx_files apps | xargs cat | wc -l)
  [ "$total" -gt "$APPS_MAX" ] && report "apps/ over $APPS_MAX lines: $total lines in its C++ files"
fi

# python/ including apps/.
if [ -d python ]; then
  while IFS= read -r hit; do
    report "python/ includes apps/: $hit"
  done < <(grep -rnE '^[[:space:]]*#[[:space:]]*include[[:space:]]*[<"]apps/' python || true)
fi

echo "check_code_size: ${#folders[@]} code folders (${folders[*]}); $breaches breach(es)"
[ "$breaches" -eq 0 ]
