"""The examples, the snippets of the README and the documentation, and the paper's experiment run as
a user would run them."""

from __future__ import annotations

import json
import re

import pytest

from om_redundant.ik.experiment import run
from tests.conftest import ROOT, run_python


def test_paper_benchmark_small_run():
    result = run("spherical", n=300, seed=1)
    assert result.converged == 1.0 and result.configuration_errors == 0
    assert result.max_position_error < 1e-10 and result.max_orientation_error < 1e-12
    assert "| converged | 100.000 % | 100 % |" in result.table()


#: The pages whose ```python blocks run as tests: the README and the documentation site's.
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
#: A block the tests do not run carries this comment on the line above its fence, with the
#: reason: <!-- not run: needs a display -->.
NOT_RUN = re.compile(r"<!--\s*not run:\s*(.*?)\s*-->")


def python_blocks(page):
    """The page's ```python blocks: (first line, code, the reason it is not run or None)."""
    lines = page.read_text().splitlines()
    blocks, i = [], 0
    while i < len(lines):
        if lines[i].strip() == "```python":
            start = i
            end = lines.index("```", i + 1)
            above = NOT_RUN.fullmatch(lines[start - 1].strip()) if start else None
            blocks.append((start + 1, "\n".join(lines[start + 1 : end]) + "\n", above and above.group(1)))
            i = end
        i += 1
    return blocks


BLOCKS = [(page, *block) for page in PAGES for block in python_blocks(page)]


def test_the_readme_and_the_guide_have_snippets():
    pages = {page.name for page, *_ in BLOCKS}
    assert {"README.md", "getting-started.md", "mink.md", "arm-angle.md", "arms.md"} <= pages


@pytest.mark.parametrize(
    "page, line, code, not_run", BLOCKS, ids=[f"{p.relative_to(ROOT)}:{n}" for p, n, *_ in BLOCKS]
)
def test_page_snippet_runs(page, line, code, not_run):
    """Every ```python block of the README and of docs/ runs as written, each on its own."""
    if not_run:
        pytest.skip(not_run)
    exec(compile("\n" * line + code, str(page.relative_to(ROOT)), "exec"), {"__name__": "__snippet__"})


def test_readme_is_short():
    """The README is the front page (what, install, a first example, the mink loop, where to
    read on); the rest lives in docs/."""
    assert len((ROOT / "README.md").read_text().splitlines()) <= 300


def test_the_api_reference_names_every_public_name():
    import om_redundant

    text = (ROOT / "docs" / "api.md").read_text()
    documented = set(re.findall(r"^\.\. auto\w+:: om_redundant\.(\w+)$", text, flags=re.M))
    assert documented == set(om_redundant.__all__)


SCRIPTS = sorted(p for p in (ROOT / "examples").glob("*.py") if not p.name.startswith("_"))


@pytest.mark.parametrize(
    "script", [p for p in SCRIPTS if not p.name.startswith(("avoid_", "realtime_"))], ids=lambda p: p.name
)
def test_example_runs(script):
    done = run_python(str(script))
    assert done.returncode == 0, done.stderr


@pytest.mark.parametrize("scene", ["panda_pole", "iiwa14_shelf"])
def test_obstacle_example(scene, tmp_path, monkeypatch):
    """Headless, 2 s of simulated time: OM keeps the margin, lags its moving target by under
    1e-5 m and ends on the pose; plain mink's numbers are only reported."""
    monkeypatch.setenv("MUJOCO_GL", "egl")
    script = ROOT / "examples" / "avoid_obstacles.py"
    done = run_python(str(script), "--scene", scene, "--headless", "--seconds", "2", "--out", str(tmp_path))
    assert done.returncode == 0, done.stderr
    summary = json.loads(done.stdout.strip().splitlines()[-1])
    print(summary)
    assert summary["example"] == scene
    assert summary["om"]["min_clearance"] >= summary["margin"]
    assert summary["om"]["final_error"] < 1e-4 and summary["om"]["max_error"] < 1e-5
    assert {"min_clearance", "final_error"} <= summary["mink"].keys()
    assert (tmp_path / f"{scene}_strip.png").exists() and (tmp_path / f"{scene}_clearance.png").exists()


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
