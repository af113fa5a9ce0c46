"""The examples, the README's snippets and the paper's experiment run as a user would run them."""

from __future__ import annotations

import json
import re

import pytest

from om_redundant.om.experiment import run
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


SCRIPTS = sorted(p for p in (ROOT / "examples").glob("*.py") if not p.name.startswith("_"))


@pytest.mark.parametrize(
    "script", [p for p in SCRIPTS if not p.name.startswith("avoid_")], ids=lambda p: p.name
)
def test_example_runs(script):
    done = run_python(str(script))
    assert done.returncode == 0, done.stderr


@pytest.mark.parametrize("script", [p for p in SCRIPTS if p.name.startswith("avoid_")], ids=lambda p: p.name)
def test_obstacle_example(script, tmp_path, monkeypatch):
    """Headless, 2 s of simulated time: OM keeps the margin, lags its moving target by under
    1e-5 m and ends on the pose; plain mink's numbers are only reported."""
    monkeypatch.setenv("MUJOCO_GL", "egl")
    done = run_python(str(script), "--headless", "--seconds", "2", "--out", str(tmp_path))
    assert done.returncode == 0, done.stderr
    summary = json.loads(done.stdout.strip().splitlines()[-1])
    print(summary)
    assert "failure" not in summary["om"], summary["om"]
    assert summary["om"]["min_clearance"] >= summary["margin"]
    assert summary["om"]["final_error"] < 1e-4 and summary["om"]["max_error"] < 1e-5
    assert {"min_clearance", "final_error"} <= summary["mink"].keys()
    assert any(tmp_path.glob("*_strip.png")) and any(tmp_path.glob("*_clearance.png"))
