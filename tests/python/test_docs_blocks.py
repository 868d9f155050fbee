"""Every Python code block of README.md and docs/*.md runs as shown (issue 28: a newcomer's
snippets failed on a missing pandas and showed a stale output). Each block runs in a fresh
namespace with `flexmbd` imported (some blocks continue an earlier one's import), in the
source folder (the blocks name examples/...); a comment `# -> TEXT` after a statement that
prints is the output the doc shows: TEXT must appear in what the block printed.

Not run: shell and C++ blocks (the commands they show are run by the CLI tests, the C++
examples are built and run as examples/*.cpp); blocks that need a Dask scheduler on
another machine are marked in the docs with the comment `# (not run by the tests)`.

Run by CTest as part of python_bindings (tests/CMakeLists.txt).
"""
import contextlib
import glob
import io
import os
import re

import pytest

SOURCE = os.path.abspath(os.environ.get("FLEXMBD_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..")))


def python_blocks():
    files = [os.path.join(SOURCE, "README.md")] + sorted(glob.glob(os.path.join(SOURCE, "docs", "*.md")))
    for path in files:
        text = open(path, encoding="utf-8").read()
        for k, m in enumerate(re.finditer(r"^```python\n(.*?)^```", text, re.S | re.M)):
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
