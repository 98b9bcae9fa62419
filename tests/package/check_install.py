#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The CMake package end to end (ctest package.find_package): installs the build tree into a
fresh prefix, checks the header layout (everything under include/mlcontact/, no generic core/ or
mesh/ on the consumer's include path), configures and builds examples/library against the
installed tree alone, runs it and the installed driver on the same scene and checks that the
printed resultants equal the driver's summary.json values to 1e-12. Builds
tests/package/toy_preconditioner against the installed tree too: a preconditioner registered from
user code, planned by levels::plan_solver and solved with.

usage: check_install.py CMAKE BUILD_DIR SOURCE_DIR WORK_DIR
"""
import json
import os
import re
import shutil
import subprocess
import sys

cmake, build, source, work = sys.argv[1:5]
shutil.rmtree(work, ignore_errors=True)
prefix = os.path.join(work, "prefix")


def run(cmd, **kw):
    p = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if p.returncode != 0:
        sys.exit(f"FAILED ({p.returncode}): {' '.join(cmd)}\n{p.stdout[-4000:]}\n{p.stderr[-4000:]}")
    return p.stdout


run([cmake, "--install", build, "--prefix", prefix])
inc = os.path.join(prefix, "include")
assert sorted(os.listdir(inc)) == ["mlcontact"], f"include/ holds {os.listdir(inc)}, expected mlcontact/ only"
for folder in ["core", "mesh", "fem", "contact", "transfer", "smoothers", "solvers", "levels", "scene", "run", "studies", "bench"]:
    assert os.path.isdir(os.path.join(inc, "mlcontact", folder)), folder
    assert os.path.exists(os.path.join(prefix, "lib", f"libmlc_{folder}.a")), folder
solve_hpp = open(os.path.join(inc, "mlcontact", "levels", "solve.hpp")).read()
assert '#include "mlcontact/core/timer.hpp"' in solve_hpp, "own includes not prefixed"
assert not re.search(r'#include "(core|mesh|fem|contact|transfer|smoothers|solvers|levels|scene|run|studies|bench)/', solve_hpp)
cfg = os.path.join(prefix, "lib", "cmake", "mlcontact")
for f in ["mlcontactConfig.cmake", "mlcontactConfigVersion.cmake", "mlcontactTargets.cmake"]:
    assert os.path.exists(os.path.join(cfg, f)), f
driver = os.path.join(prefix, "bin", "mlcontact")
assert os.access(driver, os.X_OK)

ex = os.path.join(work, "example")
run([cmake, "-S", os.path.join(source, "examples", "library"), "-B", ex, f"-DCMAKE_PREFIX_PATH={prefix}",
     "-DCMAKE_BUILD_TYPE=Release"])
cache = open(os.path.join(ex, "CMakeCache.txt")).read()
assert f"mlcontact_DIR:PATH={cfg}" in cache, "found another mlcontact than the installed one"
run([cmake, "--build", ex, "-j2"])
flags = open(os.path.join(ex, "CMakeFiles", "contact_resultant.dir", "flags.make")).read()
includes = re.findall(r"(?:-I|-isystem )(\S+)", flags)
assert os.path.join(prefix, "include") in includes, includes
for d in includes:  # the installed tree, the dependencies', never the source or build tree
    inside = [t for t in (source, build) if d == t or d.startswith(t + "/")]
    assert not inside or d.startswith(work + "/"), f"the example compiles against {d}"
    assert not re.search(r"/(core|mesh|fem|levels)/?$", d), f"generic include folder {d}"

# Every installed header compiles from the installed tree alone (one translation unit including
# them all, linked against mlcontact::mlcontact): no include left pointing at a generic folder.
hdr = os.path.join(work, "all_headers")
os.makedirs(hdr)
headers = sorted(os.path.relpath(os.path.join(d, f), inc) for d, _, fs in os.walk(os.path.join(inc, "mlcontact"))
                 for f in fs if f.endswith(".hpp"))
assert len(headers) > 40, headers
with open(os.path.join(hdr, "all_headers.cpp"), "w") as f:
    f.writelines(f"#include <{h}>\n" for h in headers)
    f.write("int main() { return 0; }\n")
with open(os.path.join(hdr, "CMakeLists.txt"), "w") as f:
    f.write("cmake_minimum_required(VERSION 3.20)\nproject(all_headers LANGUAGES CXX)\n"
            "set(CMAKE_CXX_STANDARD 20)\nfind_package(mlcontact 0.1 REQUIRED)\n"
            "add_executable(all_headers all_headers.cpp)\n"
            "target_link_libraries(all_headers PRIVATE mlcontact::mlcontact)\n")
run([cmake, "-S", hdr, "-B", os.path.join(hdr, "build"), f"-DCMAKE_PREFIX_PATH={prefix}"])
run([cmake, "--build", os.path.join(hdr, "build")])
print(f"package: all {len(headers)} installed headers compile together from {inc}")

scene, levels = "square", "1"
out = run([os.path.join(ex, "contact_resultant"), scene, levels])
print(out, end="")
printed = re.findall(r"contact '([^']+)': resultant (\S+) (\S+), (\d+) nodes in contact", out)
assert printed, out
cli_dir = os.path.join(work, "cli")
run([driver, "run", scene, "--levels", levels, "--quiet", "--out", cli_dir])
summary = json.load(open(os.path.join(cli_dir, "summary.json")))
assert len(summary["contacts"]) == len(printed)
for (name, fx, fy, closed), ref in zip(printed, summary["contacts"]):
    assert name == ref["name"], (name, ref)
    scale = max(abs(ref["resultant"][0]), abs(ref["resultant"][1]))
    for got, want in zip((float(fx), float(fy)), ref["resultant"]):
        assert abs(got - want) <= 1e-12 * scale, (name, got, want)
    assert int(closed) == ref["nodes_in_contact"]
    assert scale > 0
print(f"package: installed, example built against {prefix} and its resultants equal the driver's")

# A preconditioner registered from user code and run through the planner.
toy = os.path.join(work, "toy")
run([cmake, "-S", os.path.join(source, "tests", "package", "toy_preconditioner"), "-B", toy,
     f"-DCMAKE_PREFIX_PATH={prefix}", "-DCMAKE_BUILD_TYPE=Release"])
run([cmake, "--build", toy, "-j2"])
out = run([os.path.join(toy, "toy_preconditioner")])
assert out.startswith("toy: registered, planned and solved"), out
print(out, end="")
