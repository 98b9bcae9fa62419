#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The installed program stands alone (ctest package.installed_tree): installs the build tree
into a fresh prefix, renames the installed tree, and runs
`mlcontact study status-transfer square --levels 2` from it with the source and build trees
gone, checking that the study draws its PNG (the plot script comes from
<prefix>/share/mlcontact/plots) and that the binary holds neither tree's path.

What "the source and build trees gone" means here: they are not renamed on disk, since other
tests running at the same time use them; the driver runs in a private mount namespace
(`unshare --mount`, with `--map-root-user` when not root) in which an empty folder is mounted
over the source tree and over the build tree, so that no path into either reaches a file, as
after renaming them. The installed tree itself is renamed (moved) after the install, so that
nothing may depend on the prefix it was installed to either.

usage: installed_tree.py CMAKE BUILD_DIR SOURCE_DIR
"""
import atexit
import os
import shutil
import subprocess
import sys
import tempfile

cmake, build, source = sys.argv[1:4]
build, source = os.path.realpath(build), os.path.realpath(source)
# The installed tree and the study's output lie outside both trees (a temporary folder), since
# both trees are hidden while the study runs; removed at the end.
work = os.path.realpath(tempfile.mkdtemp(prefix="mlc_installed_tree_"))
atexit.register(shutil.rmtree, work, True)
for tree in (source, build):
    assert not (work + "/").startswith(tree + "/"), f"the temporary folder {work} lies in {tree}"


def run(cmd, **kw):
    p = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if p.returncode != 0:
        sys.exit(f"FAILED ({p.returncode}): {' '.join(cmd)}\n{p.stdout[-4000:]}\n{p.stderr[-4000:]}")
    return p.stdout


installed = os.path.join(work, "installed")
run([cmake, "--install", build, "--prefix", installed])
moved = os.path.join(work, "moved")
os.rename(installed, moved)
exe = os.path.join(moved, "bin", "mlcontact")
plots = os.path.join(moved, "share", "mlcontact", "plots")
assert os.path.isfile(os.path.join(plots, "plot_status_transfer.py")), os.listdir(moved)

# No path into the source or build tree in the binary: neither as a string (`strings`) nor
# anywhere in its bytes.
data = open(exe, "rb").read()
for tree in (source, build):
    assert tree.encode() not in data, f"{exe} holds the path {tree}"
if shutil.which("strings"):
    text = run(["strings", "-a", exe])
    for tree in (source, build):
        assert tree not in text, f"`strings {exe}` prints the path {tree}"

# The study from the installed tree, the source and build trees hidden.
empty = os.path.join(work, "empty")
os.makedirs(empty)
out = os.path.join(work, "study")
# The build tree first: it may lie inside the source tree, hidden with it.
hide = f"mount --bind '{empty}' '{build}' && mount --bind '{empty}' '{source}'"
check = f"test ! -e '{source}/CMakeLists.txt' && test ! -e '{build}/CMakeCache.txt'"
script = f"{hide} && {check} && cd '{work}' && exec '{exe}' study status-transfer square --levels 2 --out '{out}'"
env = {k: v for k, v in os.environ.items() if k not in ("MLC_PLOT_DIR", "PYTHONPATH")}
env["MPLCONFIGDIR"] = os.path.join(work, "mpl")
unshare = ["unshare", "--mount"] + ([] if os.geteuid() == 0 else ["--map-root-user"])
p = subprocess.run(unshare + ["sh", "-c", script], capture_output=True, text=True, env=env)
assert p.returncode == 0, f"exit {p.returncode}\n{p.stdout[-4000:]}\n{p.stderr[-4000:]}"
assert "plot:" not in p.stdout, p.stdout[-2000:]
png = os.path.join(out, "status_transfer.png")
assert os.path.isfile(png), f"no {png}; the study printed:\n{p.stdout[-2000:]}"
with open(png, "rb") as f:
    assert f.read(8) == b"\x89PNG\r\n\x1a\n", f"{png} is not a PNG"
assert os.path.getsize(png) > 10000, f"{png} is {os.path.getsize(png)} bytes"
print(f"installed tree moved to {moved}: the study drew {png} with the source and build trees hidden")
