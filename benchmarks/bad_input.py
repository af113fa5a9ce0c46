"""The bad inputs of issue 18 (items 5 to 9), for ``python -m benchmarks.adversarial``.

Each input is given to the library (or to the ``om-redundant`` command, in a subprocess as a
user runs it), and the table says what it did: raised an ``om.OMError`` naming the problem
(the command: exit status 2 and one line on stderr), was accepted by a documented rule (and
then gave the right answer), or anything else, which is a failure.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

import om_redundant as om

ROOT = Path(__file__).resolve().parent.parent
CLI_PREFIX = "om-redundant: error: "
SCALED_QUATERNION = "a quaternion is divided by its largest entry before its norm is taken"


@dataclass
class BadInput:
    """What one bad input did.

    Attributes:
        label: The input.
        raised: The exception's type, ``"accepted"``, or the command's ``"exit N"``.
        library: Named by the library: an ``om.OMError`` (the command: exit 2, one line).
        message: The first line of the error (or what was returned).
        seconds: Wall time of the call.
    """

    label: str
    raised: str
    library: bool
    message: str
    seconds: float


def _sliding_panda() -> tuple[om.ExactPoseTask, Any, np.ndarray]:
    """An ExactPoseTask on the Panda whose base slides along x (a moving root, item 5), the
    configuration at a reachable pose, and that pose."""
    import mink

    panda = om.OMSolver("panda")
    spec = mujoco.MjSpec.from_string(om.arm_mjcf(panda.arm))
    base = spec.body("base")
    base.add_joint(name="slide", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[1, 0, 0])
    base.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.1, 0, 0])
    model = spec.compile()
    q = np.array([0.2, 0.4, -0.3, -1.8, 0.5, 1.9, 0.6])
    configuration = mink.Configuration(model, np.concatenate([[0.0], q]))
    task = om.ExactPoseTask(panda, model, arm_configuration=panda.configuration_of(q))
    T = panda.arm.fk(q)
    task.set_target(T)
    task.compute_error(configuration)
    return task, configuration, T


def _far_target_on_a_moving_root() -> str:
    task, configuration, T = _sliding_panda()
    far = T.copy()
    far[0, 3] += 5.0
    try:
        task.set_target(far)
    finally:  # the old target holds, raised or not
        if np.abs(task.compute_error(configuration)).max() > 1e-9:
            raise AssertionError("the task no longer holds its previous target")
    return "set_target took it"


def _scaled_tool_quaternion(scale: float) -> str:
    """The Panda's arm file with its tool quaternion times scale: the same FK (item 6)."""
    panda = om.load_arm("panda")
    text = Path(panda.source).read_text()
    tool = "quat = [0.3826834, 0.0, 0.0, 0.9238795]"
    path = Path(tempfile.mkdtemp(prefix="om_adversarial_")) / "scaled.toml"
    path.write_text(text.replace(tool, f"quat = [{0.3826834 * scale!r}, 0.0, 0.0, {0.9238795 * scale!r}]"))
    q = np.linspace(-1.0, 1.0, 7)
    miss = float(np.abs(om.load_arm(str(path)).fk(q) - panda.fk(q)).max())
    if not miss <= 1e-15:
        raise AssertionError(f"the FK moved by {miss:.3g}")
    return f"the same FK as the unscaled quaternion's (to {miss:.1g})"


def library_inputs() -> list[tuple[str, Callable[[], Any]]]:
    """(label, call) for each bad input of the issue's items 5, 6, 7 and 9."""
    import mink

    ur5e, panda = om.OMSolver("ur5e"), om.OMSolver("panda")
    q6 = np.array([0.4, -1.1, 1.3, -1.2, -1.4, 0.3])
    T = ur5e.arm.fk(q6)
    c = ur5e.configuration_of(q6)
    q7 = np.array([0.2, 0.4, -0.3, -1.8, 0.5, 1.9, 0.6])
    T7 = panda.arm.fk(q7)
    c7 = panda.configuration_of(q7)
    gen3 = om.OMSolver("gen3")
    T7g, c7g = gen3.arm.fk(q7), gen3.configuration_of(q7)
    deep = Path(tempfile.mkdtemp(prefix="om_adversarial_")) / "deep.toml"
    deep.write_text("x = " + "[" * 100_000 + "]" * 100_000 + "\n")
    from om_redundant.tasks import ExactPoseTask

    return [
        ("solve_batch: empty batch (0, 4, 4)", lambda: ur5e.solve_batch(np.zeros((0, 4, 4)), c.signs)),
        ("solve_batch: 3 sign rows for 2 poses", lambda: ur5e.solve_batch(np.stack([T, T]), [c.signs] * 3)),
        ("solve: pose as str", lambda: ur5e.solve("T", c)),
        ("solve: pose as dict", lambda: ur5e.solve({"T": T.tolist()}, c)),
        ("solve_batch: list of mink.SE3", lambda: ur5e.solve_batch([mink.SE3.from_matrix(T)] * 2, c.signs)),
        ("Configuration(signs=1)", lambda: om.Configuration(signs=1)),
        ("Configuration(redundancy=0.5)", lambda: om.Configuration(c7.signs, redundancy=0.5)),
        ("Configuration(redundancy=None)", lambda: om.Configuration(c7.signs, redundancy=None)),
        ("Configuration(redundancy=(0.5+1j,))", lambda: om.Configuration(c7.signs, redundancy=(0.5 + 1j,))),
        ("Configuration(redundancy='0.5')", lambda: om.Configuration(c7.signs, redundancy="0.5")),
        ("Configuration(redundancy=('0.5',))", lambda: om.Configuration(c7.signs, redundancy=("0.5",))),
        ("panda solve_batch(redundancy='0.5')", lambda: panda.solve_batch(T7[None], c7.signs, "0.5")),
        ("Configuration.isclose(None)", lambda: c.isclose(None)),
        ("OMSolver(None)", lambda: om.OMSolver(None)),
        ("OMSolver(123)", lambda: om.OMSolver(123)),
        ("load_arm(None)", lambda: om.load_arm(None)),
        ("load_arm(deeply nested TOML)", lambda: om.load_arm(str(deep))),
        ("OMSolver(position_tolerance='1e-10')", lambda: om.OMSolver("ur5e", position_tolerance="1e-10")),
        ("OMSolver(orientation_tolerance='1e-9')", lambda: om.OMSolver("ur5e", orientation_tolerance="1e-9")),
        ("OMSolver(scan_points='x')", lambda: om.OMSolver("ur5e", scan_points="x")),
        ("OMSolver(scan_points=8.9)", lambda: om.OMSolver("ur5e", scan_points=8.9)),
        (
            "OMSolver('ur5e', scan_points=100000).solve",
            lambda: om.OMSolver("ur5e", scan_points=100_000).solve(T, c),
        ),
        (
            "OMSolver('gen3', scan_points=100000).solve_all",
            lambda: (
                f"{len(om.OMSolver('gen3', scan_points=100_000).solve_all(T7g, c7g))} roots "
                f"(default scan_points: {len(om.OMSolver('gen3').solve_all(T7g, c7g))})"
            ),
        ),
        ("RedundancyOptimizer(max_step='x')", lambda: om.RedundancyOptimizer(panda, max_step="x")),
        ("RedundancyOptimizer(margin_weight='1')", lambda: om.RedundancyOptimizer(panda, margin_weight="1")),
        ("Sphere(center='abc')", lambda: om.Sphere(center="abc", radius=0.1)),
        ("ExactPoseTask(model='model')", lambda: ExactPoseTask(ur5e, "model", arm_configuration=c)),
        ("solve: complex T", lambda: ur5e.solve(T.astype(complex), c)),
        ("solve: complex T, imaginary part 1e-3", lambda: ur5e.solve(T + 1e-3j, c)),
        ("Configuration((np.True_, 1, 1))", lambda: om.Configuration((np.True_, 1, 1))),
        (
            "solve_batch: signs [[np.True_, 1, 1]]",
            lambda: ur5e.solve_batch(T[None], np.array([[True, 1, 1]], dtype=object)),
        ),
        ("ur5e solve_batch: (M, 1) redundancy", lambda: ur5e.solve_batch(T[None], c.signs, np.zeros((1, 1)))),
        ("ExactPoseTask on a sliding base: set_target 5 m away", _far_target_on_a_moving_root),
        ("arm file: tool quat times 1e300", lambda: _scaled_tool_quaternion(1e300)),
        ("arm file: tool quat times 1e-300", lambda: _scaled_tool_quaternion(1e-300)),
    ]


def summary(value: Any) -> str:
    """A short description of what a call that should have raised returned."""
    if isinstance(value, str):
        return value
    if isinstance(value, om.Solution):
        return f"a Solution, status '{value.status}'"
    if isinstance(value, om.BatchSolution):
        return f"a BatchSolution, status {value.status}"
    if isinstance(value, list):
        return f"a list of {len(value)}"
    return type(value).__name__


#: Inputs of the list that the library accepts on purpose, with the documented rule.
ACCEPTED_BY_DESIGN = {
    "arm file: tool quat times 1e300": SCALED_QUATERNION,
    "CLI: solve --quat 1e300 1e300 1e300 1e300": SCALED_QUATERNION,
}


def run_bad_inputs() -> list[BadInput]:
    """Every input of :func:`library_inputs`, then of :func:`cli_inputs`, printing a line each."""
    found = []
    for label, fn in library_inputs():
        start = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                value = fn()
                raised, library, message = "accepted", False, f"returned {summary(value)}"
            except Exception as error:
                raised, library = type(error).__name__, isinstance(error, om.OMError)
                message = str(error).splitlines()[0][:140] if str(error) else ""
        found.append(BadInput(label, raised, library, message, time.perf_counter() - start))
        print(
            f"bad input: {label}: {raised}{' (om.OMError)' if library else ''} {found[-1].seconds:.2f} s",
            flush=True,
        )
    found += [run_cli(*case) for case in cli_inputs()]
    return found


def _quat_1e300_target(out: str) -> str:
    """The target's rotation of ``--quat 1e300 1e300 1e300 1e300``: 120 deg about (1, 1, 1)."""
    R = np.array(json.loads(out)["target"])[:3, :3]
    miss = float(np.abs(R - [[0, 0, 1], [1, 0, 0], [0, 1, 0]]).max())
    if not miss <= 1e-15:
        raise AssertionError(f"the target's rotation is off by {miss:.3g}, not 120 deg about (1, 1, 1)")
    return "the target is 120 deg about (1, 1, 1), as for (1, 1, 1, 1)"


def cli_inputs() -> list[tuple[str, list[str], Callable[[str], str] | None, bool]]:
    """(label, arguments, check of the output if accepted (None: must exit 2), stdout closed)
    for item 8 and item 6's quaternion on the command line."""
    folder = Path(tempfile.mkdtemp(prefix="om_adversarial_cli_"))
    np.save(folder / "structured.npy", np.zeros((4, 4), dtype=[("a", "f8"), ("b", "i4")]))
    np.save(folder / "zero_size.npy", np.zeros((0,)))
    (folder / "empty.npy").write_bytes(b"")
    xyz = ["--xyz", "0.3", "0.1", "0.4"]
    return [
        (
            "CLI: solve --pose-file structured.npy",
            ["solve", "--pose-file", str(folder / "structured.npy")],
            None,
            False,
        ),
        (
            "CLI: solve --pose-file empty.npy (0 bytes)",
            ["solve", "--pose-file", str(folder / "empty.npy")],
            None,
            False,
        ),
        (
            "CLI: solve --pose-file zero_size.npy",
            ["solve", "--pose-file", str(folder / "zero_size.npy")],
            None,
            False,
        ),
        ("CLI: solve >&- (stdout closed)", ["solve"], None, True),
        (
            "CLI: solve --quat 1e300 1e300 1e300 1e300",
            ["solve", *xyz, "--quat", *["1e300"] * 4, "--json"],
            _quat_1e300_target,
            False,
        ),
        (
            "CLI: solve --quat 1e-300 1e-300 1e-300 1e-300",
            ["solve", *xyz, "--quat", *["1e-300"] * 4],
            None,
            False,
        ),
        ("CLI: solve --quat nan 1 1 1", ["solve", *xyz, "--quat", "nan", "1", "1", "1"], None, False),
    ]


def run_cli(label: str, argv: list[str], check: Callable[[str], str] | None, closed: bool) -> BadInput:
    """``python -m om_redundant.cli ARGV`` in a subprocess (stdout closed if ``closed``)."""
    start = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-m", "om_redundant.cli", *argv],
        cwd=ROOT,
        env=os.environ
        | {"PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))},
        stdout=subprocess.DEVNULL if closed else subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=(lambda: os.close(1)) if closed else None,
        timeout=600,
    )
    lines = done.stderr.splitlines()
    one_line = len(lines) == 1 and lines[0].startswith(CLI_PREFIX)
    message = lines[0][:200] if lines else ""
    if check is not None and done.returncode == 0:
        try:
            return BadInput(label, "accepted", False, check(done.stdout), time.perf_counter() - start)
        except (AssertionError, KeyError, ValueError) as error:
            message = f"{type(error).__name__}: {error}"
    library = check is None and done.returncode == 2 and one_line
    if check is None and not one_line:
        message = f"{len(lines)} lines on stderr: {message}"
    found = BadInput(label, f"exit {done.returncode}", library, message, time.perf_counter() - start)
    print(
        f"bad input: {label}: exit {done.returncode}, {len(lines)} line(s) {found.seconds:.2f} s", flush=True
    )
    return found


def bad_input_table(bad: list[BadInput]) -> list[str]:
    """The page's section: one row per input, and how many were named."""
    if not bad:
        return []
    named = sum(b.library for b in bad)
    by_design = sum(b.raised == "accepted" and b.label in ACCEPTED_BY_DESIGN for b in bad)
    out = [
        "",
        "## Bad input (issue items 5 to 9)",
        "",
        f"{named} of {len(bad)} named by a library error (an `om.OMError`; the command `om-redundant`, "
        "run in a subprocess: exit status 2 and one line on stderr); "
        f"{by_design} accepted by a documented rule (the message says which, and the answer was checked); "
        "the rest, if any, are failures.",
        "",
        "| input | raised | named | s | message |",
        "|---|---|---|---|---|",
    ]
    for b in bad:
        message = b.message.replace("|", "\\|")
        verdict = "yes" if b.library else "**no**"
        if b.raised == "accepted" and b.label in ACCEPTED_BY_DESIGN:
            verdict, message = "by design", f"{ACCEPTED_BY_DESIGN[b.label]}; {message}"
        out.append(f"| {b.label} | {b.raised} | {verdict} | {b.seconds:.2f} | {message} |")
    return out
