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
    "script", [p for p in SCRIPTS if not p.name.startswith(("avoid_", "realtime_"))], ids=lambda p: p.name
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


def test_realtime_example(tmp_path, monkeypatch):
    """Headless, 0.1 s of simulated time (50 ticks at 500 Hz): the hand stays on its moving
    target and the arm clear of both obstacles; the rate and tick times are reported (not
    asserted: speed is measured in benchmarks), the mp4 holds frames and the plot is a PNG."""
    import imageio

    monkeypatch.setenv("MUJOCO_GL", "egl")
    script = ROOT / "examples" / "realtime_panda.py"
    done = run_python(str(script), "--headless", "--seconds", "0.1", "--out", str(tmp_path))
    assert done.returncode == 0, done.stderr
    summary = json.loads(done.stdout.strip().splitlines()[-1])
    print(summary)
    assert summary["ticks"] == 50 and summary["unreachable"] == 0
    assert summary["min_clearance"] >= summary["margin"] and summary["max_error"] < 1e-5
    ticks = summary["tick_ms"]
    assert 0.0 < ticks["median"] <= ticks["p99"] <= ticks["worst"] and summary["rate_hz"] > 0.0
    with imageio.get_reader(tmp_path / "realtime_panda.mp4") as video:
        assert sum(1 for _ in video) == 3  # ticks 0, 17 and 34: a frame per round(500 / 30) ticks
    assert (tmp_path / "realtime_panda.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
