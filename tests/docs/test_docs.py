# SPDX-License-Identifier: MIT
"""The documentation is checked like code: its citations, cross-references, key lists, code
tables and examples must match the program. One ctest entry per test (label docs).

Environment (set by tests/CMakeLists.txt): MLC_SOURCE_DIR (the repository), MLC_BUILD_DIR (the
build tree), MLC_CLI (the driver), PYTHONPATH (build/python, for mlcontact)."""
import glob
import inspect
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

import pytest

SRC = os.path.abspath(os.environ.get("MLC_SOURCE_DIR",
                                     os.path.join(os.path.dirname(__file__), "..", "..")))
BUILD = os.path.abspath(os.environ.get("MLC_BUILD_DIR", os.path.join(SRC, "build")))
CLI = os.environ.get("MLC_CLI", os.path.join(BUILD, "bin", "mlcontact"))
DOCS = os.path.join(SRC, "docs")


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def doc_pages(include_results=True):
    pages = sorted(glob.glob(os.path.join(DOCS, "**", "*.md"), recursive=True))
    if not include_results:
        pages = [p for p in pages if not p.startswith(os.path.join(DOCS, "results") + os.sep)]
    return pages


def labels_of(path):
    """The MyST targets `(label)=` a page defines."""
    return set(re.findall(r"^\(([A-Za-z0-9_.:-]+)\)=\s*$", read(path), re.M))


def all_labels():
    out = {}
    for p in doc_pages():
        for label in labels_of(p):
            out[label] = p
    return out


# ---------------------------------------------------------------------------------------------
# Citations of the docs in the sources: `docs/<page>.md#<label>`.

CITATION = re.compile(r"docs/([A-Za-z0-9_./-]+\.md)(?:#([A-Za-z0-9_-]+))?")
CITING_FOLDERS = ["apps", "python", "scene", "levels", "solvers", "scenes", "bench", "scripts",
                  "core", "mesh", "fem", "contact", "transfer", "smoothers", "comm", "examples"]


def source_files():
    for folder in CITING_FOLDERS:
        for path in glob.glob(os.path.join(SRC, folder, "**", "*"), recursive=True):
            if os.path.isfile(path) and path.endswith((".cpp", ".hpp", ".py", ".toml", ".sh")):
                yield path


def check_citations(text, where):
    """Every `docs/PAGE.md#LABEL` in text names an existing page and a label it defines."""
    bad = []
    for m in CITATION.finditer(text):
        page, label = m.group(1), m.group(2)
        path = os.path.join(DOCS, page)
        if not os.path.isfile(path):
            bad.append(f"{where}: {m.group(0)}: no page docs/{page}")
        elif label is None:
            bad.append(f"{where}: {m.group(0)}: no anchor (write docs/{page}#<label>)")
        elif label not in labels_of(path):
            bad.append(f"{where}: {m.group(0)}: docs/{page} has no label ({label})=")
    return bad


def test_citations_name_existing_pages_and_anchors():
    bad, count = [], 0
    for path in source_files():
        text = read(path)
        count += len(CITATION.findall(text))
        bad += check_citations(text, os.path.relpath(path, SRC))
    assert count >= 10, f"only {count} citations found: is the pattern still docs/PAGE.md#LABEL?"
    assert not bad, "\n".join(bad)


def test_no_user_visible_string_cites_the_readme():
    bad = []
    literal = re.compile(r'"(?:[^"\\\n]|\\.)*README(?:[^"\\\n]|\\.)*"')
    for path in glob.glob(os.path.join(SRC, "apps", "*.cpp")) + [
            os.path.join(SRC, "python", "module.cpp")]:
        for m in literal.finditer(read(path)):
            bad.append(f"{os.path.relpath(path, SRC)}: {m.group(0)}")
    for path in glob.glob(os.path.join(SRC, "python", "mlcontact", "*.py")):
        if "README" in read(path):
            bad.append(f"{os.path.relpath(path, SRC)} mentions README")
    for path in glob.glob(os.path.join(SRC, "scenes", "*.toml")):
        if "README" in read(path) or "benchmarks.md" in read(path).replace(
                "scenes-benchmarks.md", ""):
            bad.append(f"{os.path.relpath(path, SRC)} cites a file outside the docs")
    assert not bad, "\n".join(bad)


def test_cross_references_name_existing_labels_and_pages():
    """{ref}`label` and {doc}`page` in every page resolve (Sphinx -W checks it too, but this
    runs without building the site; theory.md and solver-guide.md included)."""
    labels = all_labels()
    bad = []
    for page in doc_pages():
        text = read(page)
        for m in re.finditer(r"\{ref\}`(?:[^`<]*<)?([^`>]+)>?`", text):
            if m.group(1) not in labels:
                bad.append(f"{os.path.relpath(page, SRC)}: {{ref}} {m.group(1)}")
        for m in re.finditer(r"\{doc\}`(?:[^`<]*<)?([^`>]+)>?`", text):
            target = m.group(1)
            base = DOCS if target.startswith("/") else os.path.dirname(page)
            if not os.path.isfile(os.path.normpath(os.path.join(base, target.lstrip("/") + ".md"))):
                bad.append(f"{os.path.relpath(page, SRC)}: {{doc}} {target}")
    assert not bad, "\n".join(bad)


# ---------------------------------------------------------------------------------------------
# Dates, times of day, "this evening" and tracker numbers.

DATED = [
    (re.compile(r"\b(19|20)\d\d-[01]\d-[0-3]\d\b"), "an ISO date"),
    (re.compile(r"\b([01]?\d|2[0-3]):[0-5]\d(:[0-5]\d)?\s*(UTC|GMT|am|pm|h)\b"), "a time of day"),
    (re.compile(r"\b([01]\d|2[0-3]):[0-5]\d-([01]\d|2[0-3]):[0-5]\d\b"), "a time range"),
    (re.compile(r"\bthis (evening|morning|afternoon|night)\b|\btonight\b", re.I),
     "a time of day in words"),
    (re.compile(r"\bissues? #?\d+\b", re.I), "a tracker number"),
]


def dated_lines(text, where):
    bad = []
    for n, line in enumerate(text.splitlines(), 1):
        for pattern, what in DATED:
            m = pattern.search(line)
            if m:
                bad.append(f"{where}:{n}: {what}: {m.group(0)!r}")
    return bad


def undated_files():
    files = [os.path.join(SRC, "README.md")] + doc_pages(include_results=False)
    files += [os.path.join(DOCS, "conf.py")] + sorted(glob.glob(os.path.join(SRC, "scenes", "*.toml")))
    return files


def test_no_dates_times_or_issue_numbers_outside_results_and_changelog():
    bad = []
    for path in undated_files():
        bad += dated_lines(read(path), os.path.relpath(path, SRC))
    assert not bad, "\n".join(bad)


def test_the_date_check_finds_what_it_must():
    found = dated_lines("new default, 2026-11-27\nat 14:16 UTC\nthis evening\nissue 15\n", "x")
    assert len(found) == 4, found
    assert not dated_lines("file:12: unknown key\nratio 1:4\nlevels 0..5\n", "x")


# ---------------------------------------------------------------------------------------------
# README and links.

def test_readme_is_short_and_narrow():
    lines = read(os.path.join(SRC, "README.md")).splitlines()
    assert len(lines) <= 300, f"README.md has {len(lines)} lines (at most 300)"
    wide = [f"line {n}: {len(l)} characters" for n, l in enumerate(lines, 1) if len(l) > 100]
    assert not wide, "\n".join(wide)


LINK = re.compile(r"\]\(\s*([^)\s]+)\s*\)")
URL = re.compile(r"\b(?:https?|ftp|file)://[^\s)>`\"']+")


def test_links_stay_in_the_repository_or_go_to_public_web_pages():
    files = [os.path.join(SRC, "README.md")] + doc_pages() + sorted(
        glob.glob(os.path.join(SRC, "scenes", "*.toml")))
    bad = []
    for path in files:
        text = read(path)
        where = os.path.relpath(path, SRC)
        for needle in ("shared/spec", "../shared", "/work/", "formulation.md", "design.md"):
            if needle in text:
                bad.append(f"{where}: names {needle!r}, outside the repository")
        for url in URL.findall(text):
            if not url.startswith("https://") or re.match(r"https://(localhost|127\.|10\.|192\.168\.)", url):
                bad.append(f"{where}: {url}: not a public web page")
        for target in LINK.findall(text):
            if re.match(r"[a-z]+:", target) or target.startswith("#"):
                continue
            file_part = target.split("#")[0]
            resolved = os.path.normpath(os.path.join(os.path.dirname(path), file_part))
            if not resolved.startswith(SRC + os.sep) or not os.path.exists(resolved):
                bad.append(f"{where}: link {target} does not resolve inside the repository")
    assert not bad, "\n".join(bad)


# ---------------------------------------------------------------------------------------------
# Scene keys: the parser's lists against docs/guide/scenes.md.

def parser_key_lists():
    folder = os.path.join(SRC, "scene")
    src = "".join(read(os.path.join(folder, f)) for f in sorted(os.listdir(folder))
                  if f.endswith(".cpp"))
    lists = []
    for m in re.finditer(r"check_keys\(\s*[^,]+,\s*\{([^}]*)\}", src):
        lists.append(re.findall(r'"([^"]+)"', m.group(1)))
    # The top-level tables: the rows of the section table (kSections) in scene/scene.cpp.
    sections = re.search(r"kSections\{\{(.*?)\}\};", src, re.S)
    assert sections, "no kSections table in scene/*.cpp"
    lists.append(re.findall(r'\{"([a-z_]+)",', sections.group(1)))
    return lists


def documented_key_tables():
    """The key reference of docs/guide/scenes.md: per `###` section, the keys of its table."""
    text = read(os.path.join(DOCS, "guide", "scenes.md"))
    ref = text[text.index("(scene-keys)="):]
    tables = {}
    for section in re.split(r"^### ", ref, flags=re.M)[1:]:
        title = section.splitlines()[0]
        keys = re.findall(r"^\| `([A-Za-z_]+)` \|", section, re.M)
        tables[title] = set(keys)
    return tables


def test_every_parser_key_is_documented_and_every_documented_key_exists():
    lists = parser_key_lists()
    assert len(lists) >= 15, f"found {len(lists)} check_keys lists in scene/*.cpp"
    tables = documented_key_tables()
    missing = []
    for keys in lists:
        if not any(set(keys) <= documented for documented in tables.values()):
            best = max(tables.items(), key=lambda kv: len(set(keys) & kv[1]))
            missing.append(f"keys {keys}: no table of docs/guide/scenes.md lists them all "
                           f"(closest '{best[0]}' lacks {sorted(set(keys) - best[1])})")
    known = set().union(*map(set, lists))
    extra = sorted(set().union(*tables.values()) - known)
    assert not missing, "\n".join(missing)
    assert not extra, f"documented keys the parser does not know: {extra}"


def test_the_key_lists_the_python_module_sees_are_documented():
    """The Scene parameters settable from Python are scene keys or documented in python.md."""
    import mlcontact
    text = read(os.path.join(DOCS, "guide", "python.md")) + read(
        os.path.join(DOCS, "guide", "scenes.md"))
    settable = [k for k in dir(mlcontact.Scene) if isinstance(getattr(mlcontact.Scene, k), property)
                and getattr(mlcontact.Scene, k).fset is not None]
    assert settable
    missing = [k for k in settable if k not in text]
    assert not missing, f"Scene parameters not in the guide: {missing}"


# ---------------------------------------------------------------------------------------------
# Status and exit codes.

def codes_page():
    return read(os.path.join(DOCS, "guide", "codes.md"))


def table_after(text, label):
    part = text[text.index(f"({label})="):]
    rows = []
    for line in part.splitlines()[2:]:
        if line.startswith("(") and line.endswith(")="):
            break
        if line.startswith("|") and not line.startswith("|---"):
            rows.append([c.strip() for c in line.strip("|").split("|")])
    return rows[1:]  # the header row off


def test_status_table_is_status_names():
    import mlcontact
    rows = table_after(codes_page(), "status-codes")
    named = {int(r[0]): r[1].strip("`") for r in rows if r[1]}
    assert named == dict(enumerate(mlcontact.STATUS_NAMES))
    assert int(rows[0][0]) == -1  # VTU: not a contact node
    assert (mlcontact.GAP, mlcontact.STICK, mlcontact.SLIP_FORWARD, mlcontact.SLIP_BACKWARD) == (
        0, 1, 2, 3)
    rows3 = table_after(codes_page(), "status-codes-3d")
    assert {int(r[0]): r[1].strip("`") for r in rows3 if r[1]} == dict(
        enumerate(mlcontact.STATUS_NAMES_3D))
    for page in ("guide/outputs.md", "guide/python.md"):
        assert "{ref}`status-codes`" in read(os.path.join(DOCS, page)), page
    assert "{ref}`exit-codes`" in read(os.path.join(DOCS, "guide", "cli.md"))
    # One table each: no other page restates them.
    for page in doc_pages():
        if page.endswith(os.path.join("guide", "codes.md")):
            continue
        assert not re.search(r"^\| *130 *\|", read(page), re.M), f"{page} has an exit-code table"


def exit_code_table():
    return {int(r[0]): r[1] for r in table_after(codes_page(), "exit-codes")}


def test_exit_code_table_lists_the_driver_codes():
    assert sorted(exit_code_table()) == [0, 1, 2, 3, 4, 130, 143]


def run_cli(args, cwd, timeout=300, **kw):
    env = dict(os.environ, OMPI_MCA_ess_singleton_isolated="1")
    return subprocess.run([CLI] + args, cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=timeout, **kw)


BAD_SCENE = """[scene]
name = "bad"
[[body]]
E = -1.0
nu = 0.3
mesh = { type = "rectangle", corner = [0, 0], size = [1, 1], divisions = [2, 2] }
"""


def test_exit_codes_of_the_driver_are_the_documented_ones(tmp_path):
    table = exit_code_table()
    ok = run_cli(["run", "patch_matching", "--quiet", "--out", str(tmp_path / "ok")], tmp_path)
    assert ok.returncode == 0 and "success" in table[0], ok.stderr
    (tmp_path / "bad.toml").write_text(BAD_SCENE)
    bad = run_cli(["run", "bad.toml", "--quiet", "--out", str(tmp_path / "bad")], tmp_path)
    assert bad.returncode == 1 and "bad input" in table[1]
    assert bad.stderr.startswith("mlcontact: error: ") and "E" in bad.stderr
    # No convergence: one Newton iteration allowed, no r continuation, no fallback.
    scene = read(os.path.join(SRC, "scenes", "square.toml")) + "\n[newton]\nmax_iter = 1\n"
    if "[newton]" in read(os.path.join(SRC, "scenes", "square.toml")):
        pytest.fail("square.toml has a [newton] table: adapt this test")
    (tmp_path / "short.toml").write_text(scene)
    nc = run_cli(["run", "short.toml", "--quiet", "--no-continuation", "--linear", "schur",
                  "--out", str(tmp_path / "nc")], tmp_path)
    assert nc.returncode == 2 and "did not converge" in table[2], (nc.returncode, nc.stderr)
    # A command-line parse error is bad input too, with the same prefix.
    typo = run_cli(["run", "square", "--levls", "1"], tmp_path)
    assert typo.returncode == 1 and typo.stderr.startswith("mlcontact: error: "), typo.stderr
    # A NaN or Inf residual is a numerical breakdown.
    nf = run_cli(["run", os.path.join(SRC, "tests", "data", "nonfinite_residual.toml"), "--quiet",
                  "--out", str(tmp_path / "nf")], tmp_path)
    assert nf.returncode == 3 and "breakdown" in table[3], (nf.returncode, nf.stderr)
    # A plot that fails after the results were written: a matplotlib that cannot be imported.
    broken = tmp_path / "site" / "matplotlib"
    broken.mkdir(parents=True)
    (broken / "__init__.py").write_text('raise RuntimeError("this matplotlib is broken")\n')
    env = dict(os.environ, OMPI_MCA_ess_singleton_isolated="1", PYTHONPATH=str(tmp_path / "site"))
    pl = subprocess.run([CLI, "run", "patch_matching", "--quiet", "--plot",
                         "--out", str(tmp_path / "plot")], cwd=tmp_path, env=env,
                        capture_output=True, text=True, timeout=300)
    assert pl.returncode == 4 and "plot" in table[4], (pl.returncode, pl.stderr)
    assert (tmp_path / "plot" / "contact.csv").exists()
    assert not (tmp_path / "plot" / "contact.png").exists()


@pytest.mark.parametrize("sig,code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_a_stopped_run_exits_with_the_documented_code(tmp_path, sig, code):
    table = exit_code_table()
    assert ("SIGTERM" if sig == signal.SIGTERM else "SIGINT") in table[code]
    env = dict(os.environ, OMPI_MCA_ess_singleton_isolated="1")
    p = subprocess.Popen([CLI, "run", "hertz", "--levels", "3", "--steps", "400",
                          "--out", str(tmp_path / "stop")], cwd=tmp_path, env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        # Wait for the first completed load step (a progress line), then stop the run.
        while True:
            line = p.stdout.readline()
            assert line, "the run ended before printing a load step"
            if re.search(r"\bstep\b", line) and re.search(r"\bs\b|seconds|\d+\.\d+", line):
                break
        p.send_signal(sig)
        out, err = p.communicate(timeout=120)
    finally:
        if p.poll() is None:
            p.kill()
    assert p.returncode == code, (p.returncode, err)
    assert "stopped by" in out + err


# ---------------------------------------------------------------------------------------------
# CLI help.

def subcommands(help_text):
    parts = re.split(r"^subcommands:\s*$", help_text, flags=re.M | re.I)
    part = parts[1] if len(parts) > 1 else ""
    return re.findall(r"^\s{2}([a-z][a-z-]*)\s", part, re.M)


def test_cli_help_has_no_dates_no_readme_and_valid_citations(tmp_path):
    texts = {}
    todo = [[]]
    while todo:
        path = todo.pop()
        r = run_cli(path + ["--help"], tmp_path, timeout=60)
        assert r.returncode == 0, (path, r.stderr)
        texts[" ".join(["mlcontact"] + path)] = r.stdout
        todo += [path + [s] for s in subcommands(r.stdout)]
    assert len(texts) >= 12, sorted(texts)
    bad = []
    for where, text in texts.items():
        bad += dated_lines(text, where)
        bad += check_citations(text, where)
        if "README" in text:
            bad.append(f"{where}: cites the README")
    assert not bad, "\n".join(bad)
    assert sum(len(CITATION.findall(t)) for t in texts.values()) >= 3


def test_builtin_scenes_as_the_driver_shows_them(tmp_path):
    """`mlcontact show NAME` prints the compiled-in scene: no date, no file outside the
    repository, citations that resolve."""
    names = run_cli(["scenes"], tmp_path, timeout=60).stdout.split()
    shown = [n for n in names if os.path.isfile(os.path.join(SRC, "scenes", n + ".toml"))]
    assert len(shown) >= 10, names
    bad = []
    for name in shown:
        text = run_cli(["show", name], tmp_path, timeout=60).stdout
        assert text.startswith("#"), name
        bad += dated_lines(text, f"show {name}") + check_citations(text, f"show {name}")
        for needle in ("shared/spec", "benchmarks.md#", "formulation.md"):
            if needle in text.replace("scenes-benchmarks.md#", ""):
                bad.append(f"show {name}: names {needle}")
    assert not bad, "\n".join(bad)


# ---------------------------------------------------------------------------------------------
# Docstrings of the Python API.

SIGNATURE = re.compile(r"^\s*(\d+\.\s*)?([A-Za-z_][\w.]*)?\(.*\) -> \S.*$")


def own_text(doc):
    """A docstring without pybind11's generated signature lines."""
    if not doc:
        return ""
    lines = [l for l in doc.splitlines() if not SIGNATURE.match(l)
             and l.strip() != "Overloaded function."]
    return "\n".join(lines).strip()


def public_api():
    import mlcontact
    for name in mlcontact.__all__:
        obj = getattr(mlcontact, name)
        if name == "__version__" or isinstance(obj, tuple):
            continue
        yield f"mlcontact.{name}", obj
        if inspect.isclass(obj):
            for attr, value in vars(obj).items():
                if attr.startswith("_") or attr in vars(BaseException):
                    continue
                yield f"mlcontact.{name}.{attr}", value


def test_every_public_function_class_method_and_property_has_a_docstring():
    missing = []
    count = 0
    for qualname, obj in public_api():
        count += 1
        doc = obj.__doc__ if not isinstance(obj, property) else (obj.__doc__ or (
            obj.fget.__doc__ if obj.fget else None))
        if isinstance(obj, (str, int, float, tuple)):
            continue
        if len(own_text(doc)) < 10:
            missing.append(qualname)
    assert count > 40
    assert not missing, "no docstring: " + ", ".join(missing)


def test_the_docstring_check_sees_a_missing_docstring():
    assert own_text("copy(self: mlcontact._core.Scene) -> mlcontact._core.Scene\n") == ""
    assert own_text("(k,) normal multipliers (forces)") == "(k,) normal multipliers (forces)"
    assert own_text("copy(self: a.B) -> a.B\n\nA copy of the scene.\n") == "A copy of the scene."
    assert own_text("(self: mlcontact._core.Result) -> bool\n") == ""  # a property's getter


# ---------------------------------------------------------------------------------------------
# Header comments: every public class of the installed headers says what it is for.

def test_every_public_class_in_the_headers_has_a_comment(tmp_path):
    doxygen = shutil.which("doxygen")
    assert doxygen, "doxygen missing: bash scripts/deps.sh"
    config = read(os.path.join(DOCS, "Doxyfile")) + f"\nOUTPUT_DIRECTORY={tmp_path}\n"
    subprocess.run([doxygen, "-"], input=config, cwd=SRC, text=True, check=True,
                   capture_output=True, timeout=300)
    missing, count = [], 0
    for f in glob.glob(str(tmp_path / "xml" / "class*.xml")) + glob.glob(
            str(tmp_path / "xml" / "struct*.xml")):
        c = ET.parse(f).getroot().find("compounddef")
        name = c.findtext("compoundname")
        if c.get("prot") != "public" or not name.startswith("mlc::") or "detail" in name.split("::"):
            continue
        count += 1
        text = "".join(c.find("briefdescription").itertext()).strip() + "".join(
            c.find("detaileddescription").itertext()).strip()
        if not text:
            loc = c.find("location")
            missing.append(f"{os.path.relpath(loc.get('file'), SRC)}:{loc.get('line')}: {name}")
    assert count > 100, count
    assert not missing, "classes without a comment:\n" + "\n".join(sorted(missing))


# ---------------------------------------------------------------------------------------------
# Runnable examples of the guide.

RUNNABLE = re.compile(r"^```\{code-block\} (sh|python)\n:class: runnable\n\n(.*?)^```\s*$",
                      re.M | re.S)


def runnable_blocks():
    blocks = []
    for page in doc_pages(include_results=False):
        for m in RUNNABLE.finditer(read(page)):
            blocks.append((os.path.relpath(page, DOCS), m.group(1), m.group(2)))
    return blocks


def test_there_are_runnable_blocks_in_the_guide():
    pages = {p for p, _, _ in runnable_blocks()}
    assert len(runnable_blocks()) >= 8 and {"guide/cli.md", "guide/scenes.md",
                                            "guide/python.md"} <= pages, pages


@pytest.mark.parametrize("page,kind,code", runnable_blocks(),
                         ids=[f"{p}:{i}" for i, (p, _, _) in enumerate(runnable_blocks())])
def test_runnable_block(tmp_path, page, kind, code):
    """Each block runs in a fresh folder holding links to the build tree and the sources."""
    for name in ("build", "scenes", "examples", "scripts", "python"):
        os.symlink(BUILD if name == "build" else os.path.join(SRC, name), tmp_path / name)
    env = dict(os.environ, OMPI_MCA_ess_singleton_isolated="1",
               PYTHONPATH=os.path.join(BUILD, "python"))
    if kind == "sh":
        cmd = ["bash", "-euo", "pipefail", "-c", code]
    else:
        cmd = ["/usr/bin/python3", "-c", code]
    r = subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, f"{page}:\n{code}\nstdout:\n{r.stdout[-3000:]}\nstderr:\n{r.stderr[-3000:]}"


# ---------------------------------------------------------------------------------------------
# The site: built by scripts/docs.sh, opened in a real browser.

HTML = os.path.join(BUILD, "docs", "html")


def test_site_builds_with_warnings_as_errors():
    env = dict(os.environ, MLC_BUILD_DIR=BUILD)
    r = subprocess.run(["bash", os.path.join(SRC, "scripts", "docs.sh")], env=env,
                       capture_output=True, text=True, timeout=1800)
    assert r.returncode == 0, r.stdout[-5000:] + r.stderr[-5000:]
    for page in ("index.html", "search.html", "searchindex.js", "api/python.html",
                 "api/cpp.html", "guide/codes.html", "_static/mathjax/MathJax.js"):
        assert os.path.isfile(os.path.join(HTML, page)), page
    # Math renders offline: the pages load MathJax from the site, never from a CDN.
    theory = read(os.path.join(HTML, "theory.html"))
    assert "_static/mathjax/MathJax.js" in theory and "cdn." not in theory


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def chromium_dom(url, profile):
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    assert browser, "chromium missing: bash scripts/deps.sh"
    r = subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu",
                        "--disable-background-networking", "--disable-component-update",
                        "--disable-sync", "--no-first-run", f"--user-data-dir={profile}",
                        "--dump-dom", "--virtual-time-budget=10000", url],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    return r.stdout


def test_site_in_a_browser(tmp_path):
    assert os.path.isfile(os.path.join(HTML, "index.html")), "build the site first (docs.site)"
    port = free_port()
    server = subprocess.Popen([sys.executable, "-m", "http.server", str(port), "--bind",
                               "127.0.0.1", "--directory", HTML],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.time() + 20
        while True:
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                assert time.time() < deadline, "the http server did not start"
                time.sleep(0.2)
        base = f"http://127.0.0.1:{port}"
        index = chromium_dom(f"{base}/index.html", tmp_path / "p1")
        assert "wy-nav-side" in index or "sphinxsidebar" in index  # the navigation
        for page in ("guide/cli.html", "theory.html", "api/python.html", "results/index.html"):
            assert f'href="{page}"' in index, page
        search = chromium_dom(f"{base}/search.html?q=coarse", tmp_path / "p2")
        assert 'class="search"' in search, "no search results listed"
        results = search[search.index('class="search"'):]
        results = results[:results.index("</ul>")]
        assert 'href="theory.html' in results, results[:3000]
        api = chromium_dom(f"{base}/api/python.html", tmp_path / "p3")
        assert 'id="mlcontact.solve"' in api
        # Math is typeset by the site's own MathJax: no formula is left as TeX source.
        cli = chromium_dom(f"{base}/guide/cli.html", tmp_path / "p4")
        assert cli.count("mjx-chtml") >= 4
        assert not re.search(r'class="math notranslate nohighlight">\\[(\[]', cli)
    finally:
        server.terminate()
        try:
            server.wait(timeout=10)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait(timeout=10)
