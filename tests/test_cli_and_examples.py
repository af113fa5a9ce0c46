"""The command line and the examples run as a user would run them."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from om_redundant.cli import main
from om_redundant.paper_experiment import run

ROOT = Path(__file__).resolve().parents[1]


def test_default_run_solves_all_eight_configurations(capsys):
    assert main([]) == 0
    out = capsys.readouterr().out
    assert out.count(" ok ") == 8 and "ur5e" in out


def test_solve_command_with_a_pose_and_signs(capsys):
    assert (
        main(
            [
                "solve",
                "--arm",
                "spherical",
                "--xyz",
                "0.1",
                "0.2",
                "0.3",
                "--quat",
                "1",
                "0",
                "0",
                "0",
                "--signs",
                "1",
                "1",
                "1",
            ]
        )
        == 0
    )
    assert "ARM ELBOW WRIST" in capsys.readouterr().out


@pytest.mark.parametrize(
    "argv, message",
    [
        (["solve", "--arm", "nope"], "unknown arm 'nope'"),
        (["solve", "--xyz", "0", "0", "0", "--quat", "0", "0", "0", "0"], "zero norm"),
        (["solve", "--signs", "1", "2", "1"], "-1 or +1"),
        (["solve", "--xyz", "0", "0", "0"], "both --xyz and --quat"),
        (["bench", "paper", "--n", "0"], "--n must be positive"),
    ],
)
def test_bad_input_gives_a_one_line_error(capsys, argv, message):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


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
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
