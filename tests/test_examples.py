"""The examples, the README's snippets and the paper's experiment run as a user would run them."""

from __future__ import annotations

import re

import pytest

from om_redundant.paper_experiment import run
from tests.conftest import ROOT, run_python


def test_paper_benchmark_small_run():
    result = run("spherical", n=300, seed=1)
    assert result.converged == 1.0 and result.configuration_errors == 0
    assert result.max_position_error < 1e-10 and result.max_orientation_error < 1e-12
    assert "| converged | 100.000 % | 100 % |" in result.table()


def test_readme_snippets_run():
    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert blocks
    for block in blocks:
        exec(compile(block, "README.md", "exec"), {})


@pytest.mark.parametrize("script", sorted((ROOT / "examples").glob("*.py")), ids=lambda p: p.name)
def test_example_runs(script):
    done = run_python(str(script))
    assert done.returncode == 0, done.stderr
