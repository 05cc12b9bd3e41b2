"""Every Python block of the README and of docs/ runs as written (from a scratch directory that
sees the repository's tests/ and examples/), so the documentation cannot drift from the package."""

import os
import re

import pytest

from conftest import ROOT

DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
# Blocks that need a machine we do not have in CI: a Slurm cluster.
NEEDS_CLUSTER = ("SLURMCluster",)


def python_blocks():
    for path in DOCS:
        text = path.read_text(encoding="utf-8")
        for m in re.finditer(r"^```python\n(.*?)^```", text, re.S | re.M):
            line = text[: m.start()].count("\n") + 1
            yield pytest.param(m.group(1), id=f"{path.name}:{line}")


BLOCKS = list(python_blocks())


def test_the_docs_have_python_blocks():
    assert len(BLOCKS) >= 2


@pytest.mark.parametrize("code", BLOCKS)
def test_python_block_runs(code, tmp_path, monkeypatch):
    if any(k in code for k in NEEDS_CLUSTER):
        pytest.skip("needs a Slurm cluster (dask-jobqueue)")
    for d in ("tests", "examples"):
        os.symlink(ROOT / d, tmp_path / d)
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "<docs>", "exec"), {"__name__": "__docs__"})
