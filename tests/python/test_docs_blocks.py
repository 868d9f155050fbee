"""Every code block of README.md and docs/*.md runs or compiles as shown (a
newcomer's snippets failed on a missing pandas and showed a stale output).

Python blocks: each runs in a fresh namespace with `flexmbd` imported (some blocks continue
an earlier one's import), in the source folder (the blocks name examples/...); a comment
`# -> TEXT` after a statement that prints is the output the doc shows: TEXT must appear in
what the block printed. Blocks that need a Dask scheduler on another machine are marked in
the docs with the comment `# (not run by the tests)`.

Shell blocks: every line that runs flexmbd (`flexmbd`, `build/app/flexmbd`,
`build/python/flexmbd-study`) with concrete arguments runs in a fresh folder beside the
examples and must exit 0 (`summary`, `plot` and `view` of `out/` after a run of
examples/slider_crank_rigid.json into it). Lines with a placeholder (`[--option X]`, `SCENE.json`, `DIR`,
`FILE`, `NAME`, a `tcp://host` scheduler) show a synopsis, not a command, and the make,
ctest and cmake lines are what CI itself runs: those are not run here.

C++ blocks: each compiles (g++ -fsyntax-only, the engine's headers): its `#include` and
`using` lines at the top, the rest in a `main` after `using namespace flexmbd;` and after
the declarations of a line `// given: ...` in the block (what an excerpt takes from the
code around it, e.g. `// given: System sys; BodyIndex crank, slider;`).

Run by CTest as part of python_bindings (tests/CMakeLists.txt).
"""
import contextlib
import glob
import io
import os
import re
import shlex
import shutil
import subprocess

import pytest

SOURCE = os.path.abspath(os.environ.get("FLEXMBD_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..")))
TUTORIALS = sorted(glob.glob(os.path.join(SOURCE, "docs", "tutorials", "*.md")))


def pages():
    """README.md, docs/*.md and docs/tutorials/*.md."""
    return [os.path.join(SOURCE, "README.md")] + sorted(glob.glob(os.path.join(SOURCE, "docs", "*.md"))) + TUTORIALS


# A block that shows a file of the project is marked by the line before it,
# `<!-- file: examples/NAME -->`: it must be that file, as it is (the file itself is built,
# run and tested where it is), so it is compared, not run.
FILE_MARK = re.compile(r"<!-- file: (\S+) -->\n```\w+\n(.*?)^```", re.S | re.M)


def shows_a_file(text, start):
    return re.search(r"<!-- file: \S+ -->\n$", text[:start]) is not None


def python_blocks():
    for path in pages():
        text = open(path, encoding="utf-8").read()
        for k, m in enumerate(re.finditer(r"^```python\n(.*?)^```", text, re.S | re.M)):
            if shows_a_file(text, m.start()):
                continue
            line = text[:m.start()].count("\n") + 1
            yield pytest.param(m.group(1), id=f"{os.path.relpath(path, SOURCE)}:{line}")


BLOCKS = list(python_blocks())


def test_the_docs_have_python_blocks():
    assert len(BLOCKS) >= 4  # README's quick look and docs/python.md's three


@pytest.mark.parametrize("code", BLOCKS)
def test_python_block_runs_as_shown(code, monkeypatch):
    if "# (not run by the tests)" in code:
        pytest.skip("marked in the doc: needs what a test machine has not")
    monkeypatch.chdir(SOURCE)
    out = io.StringIO()
    namespace = {"__name__": "__docs__"}
    exec("import flexmbd", namespace)  # noqa: S102  (the docs' own code)
    with contextlib.redirect_stdout(out):
        exec(compile(code, "<doc block>", "exec"), namespace)  # noqa: S102
    printed = out.getvalue()
    for shown in re.findall(r"# -> (.+)$", code, re.M):
        assert shown.strip() in printed, f"the doc shows {shown.strip()!r}; the block printed:\n{printed}"


# ----- shell blocks ----------------------------------------------------------------------------

def blocks(languages):
    for path in pages():
        if path in TUTORIALS and languages & {"sh", "bash"}:
            continue  # a tutorial's commands run as one session (test_tutorial_runs_as_shown)
        text = open(path, encoding="utf-8").read()
        for m in re.finditer(r"^```(\w+)\n(.*?)^```", text, re.S | re.M):
            if m.group(1) in languages and not shows_a_file(text, m.start()):
                line = text[:m.start()].count("\n") + 1
                yield f"{os.path.relpath(path, SOURCE)}:{line}", m.group(2)


COMMAND = re.compile(r"^(flexmbd|build/app/flexmbd|build/python/flexmbd-study|build/examples/example_\w+)(\s|$)")
PLACEHOLDER = re.compile(r"\[|\bSCENE\b|\bDIR\b|\bFILE\b|\bNAME\b|tcp://host")

SHELL_COMMANDS = [pytest.param(line, id=f"{where}:{line.split()[1] if len(line.split()) > 1 else line}")
                  for where, code in blocks({"sh", "bash"})
                  for line in code.splitlines()
                  if COMMAND.match(line) and not PLACEHOLDER.search(line)]


def test_the_docs_have_shell_commands_that_run():
    assert len(SHELL_COMMANDS) >= 4  # the study, sid, modes --sweep and more


@pytest.mark.parametrize("line", SHELL_COMMANDS)
def test_shell_command_runs_as_shown(line, tmp_path):
    cli = os.environ.get("FLEXMBD_CLI")
    if not cli:
        pytest.skip("FLEXMBD_CLI not set (CTest sets it)")
    build = os.path.dirname(os.path.dirname(cli))  # <build>/app/flexmbd
    os.symlink(os.path.join(SOURCE, "examples"), tmp_path / "examples")
    os.symlink(build, tmp_path / "build")
    words = line.split()
    words[0] = cli if words[0] in ("flexmbd", "build/app/flexmbd") else words[0]
    if words[1] in ("summary", "plot", "view") and "out/" in words:
        # the folder of a run these commands look at: the docs' own first run
        subprocess.run([cli, "run", "examples/slider_crank_rigid.json", "--out", "out/", "--quiet"], cwd=tmp_path,
                       check=True, capture_output=True)
    r = subprocess.run(words, cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, f"{line}\nexit {r.returncode}\n{r.stderr[-2000:]}"


# ----- C++ blocks ------------------------------------------------------------------------------

CPP_BLOCKS = [pytest.param(code, id=where) for where, code in blocks({"cpp"})]


def test_the_docs_have_cpp_blocks():
    assert len(CPP_BLOCKS) >= 4


@pytest.mark.parametrize("code", CPP_BLOCKS)
def test_cpp_block_compiles(code, tmp_path):
    compiler = shutil.which("c++") or shutil.which("g++")
    if not compiler:
        pytest.skip("no C++ compiler")
    head, body, given = [], [], []
    for line in code.splitlines():
        stripped = line.strip()
        if stripped.startswith("#include") or stripped.startswith("using namespace"):
            head.append(line)
        elif stripped.startswith("// given:"):
            decls = stripped[len("// given:"):]
            given.append(decls[:decls.rfind(";") + 1])  # the declarations, not the words after them
        else:
            body.append(line)
    source = "\n".join(head + ["#include <cstdio>", "#include <cmath>", "#include \"scene/scene.hpp\"",
                               "#include \"simulation/simulation.hpp\"", "using namespace flexmbd;",
                               "int main() {"] + given + body + ["}"]) + "\n"
    path = tmp_path / "block.cpp"
    path.write_text(source)
    r = subprocess.run([compiler, "-std=c++17", "-fsyntax-only", "-I", SOURCE, "-isystem", "/usr/include/eigen3",
                        "-isystem", "/usr/include/suitesparse", str(path)], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, f"{source}\n{r.stderr[-3000:]}"


# ----- blocks that show a file, and the tutorials ------------------------------------------

FILE_BLOCKS = [pytest.param(m.group(1), m.group(2), id=f"{os.path.relpath(path, SOURCE)}:{m.group(1)}")
               for path in pages() for m in FILE_MARK.finditer(open(path, encoding="utf-8").read())]


def test_the_tutorials_show_files():
    assert len(TUTORIALS) >= 3 and len(FILE_BLOCKS) >= 3


@pytest.mark.parametrize("name,code", FILE_BLOCKS)
def test_a_block_that_shows_a_file_is_that_file(name, code):
    with open(os.path.join(SOURCE, name), encoding="utf-8") as f:
        assert code == f.read(), f"the block shown as {name} differs from the file: copy the file into the page"


# A synopsis in a tutorial: an optional part "[--...]" or a placeholder word (a scene path
# such as 'bodies[1].mass' is a concrete argument there).
SYNOPSIS = re.compile(r"\[-|\bSCENE\b|\bDIR\b|\bFILE\b|\bNAME\b|tcp://host")


@pytest.mark.parametrize("page", [pytest.param(p, id=os.path.basename(p)) for p in TUTORIALS])
def test_tutorial_runs_as_shown(page, tmp_path):
    # Every command line of the page's shell blocks, in order, in one folder: later steps
    # read what earlier ones wrote, as they do for a reader who follows the page.
    cli = os.environ.get("FLEXMBD_CLI")
    if not cli:
        pytest.skip("FLEXMBD_CLI not set (CTest sets it)")
    build = os.path.dirname(os.path.dirname(cli))
    os.symlink(os.path.join(SOURCE, "examples"), tmp_path / "examples")
    os.symlink(build, tmp_path / "build")
    text = open(page, encoding="utf-8").read()
    lines = [line for m in re.finditer(r"^```(?:sh|bash)\n(.*?)^```", text, re.S | re.M)
             for line in m.group(1).splitlines() if COMMAND.match(line) and not SYNOPSIS.search(line)]
    assert lines, f"{page} has no command to run"
    for line in lines:
        words = shlex.split(line)
        words[0] = cli if words[0] in ("flexmbd", "build/app/flexmbd") else words[0]
        r = subprocess.run(words, cwd=tmp_path, capture_output=True, text=True, timeout=600)
        assert r.returncode == 0, f"{os.path.basename(page)}: {line}\nexit {r.returncode}\n{r.stderr[-2000:]}"
