"""Shared helpers: the reference Menagerie models (kinematics only) beside the project, and
running the checkout's code in a fresh interpreter."""

from __future__ import annotations

import dataclasses
import functools
import math
import os
import subprocess
import sys
import threading
from pathlib import Path

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from om_redundant import _core
from om_redundant.ik.kernel_data import flange_target
from om_redundant.mujoco_io.loading import load_mujoco_model
from tests.reference.objective import Group

# The suite's property tests draw the same examples on every run, so that CI answers for the
# code and not for the draw; HYPOTHESIS_PROFILE=explore draws new ones (run it to hunt bugs:
# the known gaps it can find are listed in docs/status.md).
settings.register_profile("repeatable", derandomize=True)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))

ROOT = Path(__file__).resolve().parents[1]
#: A solve's accepted errors (m, rad): every root must reach its pose within them.
EXACT = 1e-10
#: Away from the singular boundaries and the edge of reach (smallest singular value of the
#: real arm's Jacobian, and |branch quantity|), where a miss is a failure of a test; the
#: miss rate nearer them is measured by benchmarks/near_family.py and benchmarks/menagerie.py.
WELL_CONDITIONED = 0.05
MENAGERIE = ROOT.parent / "shared" / "reference" / "menagerie"


def load_reference_model(relative_path: str) -> mujoco.MjModel:
    """Load a Menagerie MJCF, without its meshes (the files ship without them)."""
    path = MENAGERIE / relative_path
    if not path.is_file():
        pytest.skip(f"reference model {path} not available")
    return load_mujoco_model(path)


def checkout_env() -> dict[str, str]:
    """The environment in which a fresh interpreter imports this checkout's package."""
    path = os.pathsep.join([str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])])
    return {**os.environ, "PYTHONPATH": path}


def run_python(*args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    """``python ARGS`` in a fresh interpreter, as a user runs it (``-m om_redundant.cli ...`` or a
    script), importing this checkout's package; output captured as text."""
    return subprocess.run(
        [sys.executable, *args], cwd=ROOT, env=checkout_env(), capture_output=True, text=True, timeout=timeout
    )


def wrap(angle: np.ndarray) -> np.ndarray:
    """Wrap angles into [-pi, pi)."""
    return (np.asarray(angle) + np.pi) % (2 * np.pi) - np.pi


def random_q(arm, n: int, rng: np.random.Generator) -> np.ndarray:
    """Uniform joint vectors within limits; unlimited revolute joints in [-pi, pi]."""
    lower = np.where(np.isfinite(arm.lower), arm.lower, -np.pi)
    upper = np.where(np.isfinite(arm.upper), arm.upper, np.pi)
    return rng.uniform(lower, upper, (n, arm.dof))


@functools.cache
def solver_of(name: str) -> om.OMSolver:
    """The named arm's solver, one per test process."""
    return om.OMSolver(name)


def random_pose(solver: om.OMSolver, seed: int) -> np.ndarray:
    """A random reachable pose of the solver's arm: the hand at joints drawn within the limits."""
    return solver.arm.fk(np.random.default_rng(seed).uniform(solver.arm.lower, solver.arm.upper))


def in_threads(work, rows: int, threads: int = 4) -> None:
    """work(range(k, rows, threads)) on each of `threads` threads at once, all joined."""
    running = [threading.Thread(target=work, args=(range(k, rows, threads),)) for k in range(threads)]
    for thread in running:
        thread.start()
    for thread in running:
        thread.join()


# The optimiser's sweep at a random reachable pose (random_pose's seed) of an arm, with 1 or 3
# obstacles about the hand (benchmarks.control_rate.obstacles): the property tests' scenes.
random_scenes = given(
    seed=st.integers(0, 2**32 - 1),
    name=st.sampled_from(["panda", "iiwa14", "fr3"]),
    count=st.sampled_from([1, 3]),
)


def random_groups(rng: np.random.Generator, r: int, values) -> list[Group]:
    """The objective's three kinds of group (margin, clearance with floor 0.3, singularity), of
    random weights, pieces ``values(floor)`` and rates by r variables drawn from N(0, 1): the
    climb's QP problems."""
    groups = []
    for kind, weight, floor, cap in (
        ("margin", rng.uniform(0, 2), 0.0, np.inf),
        ("clearance", rng.uniform(0, 2), 0.3, 1.0),
        ("singularity", rng.uniform(0, 1), -np.inf, 1.0),
    ):
        v = values(floor)
        groups.append(Group(kind, weight, floor, cap, v, rng.normal(size=(len(v), r))))
    return groups


def steps_numpy(cyclic: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The reference of the largest joint step (``_core.joint_step``, ``Probe.step``) between
    the rows of a and b (M, dof): max_i |b_i - a_i|, the differences of the cyclic joints taken
    to one turn by the exact IEEE remainder (``math.remainder``, whose magnitude is the wrap's;
    not a number where the difference is not finite); numpy's maximum, so a NaN gives NaN."""
    d = b - a
    remainder = np.vectorize(
        lambda x: math.remainder(x, 2.0 * math.pi) if math.isfinite(x) else math.nan, otypes=[float]
    )
    d = np.where(cyclic, remainder(d), d)
    return np.abs(d).max(axis=1, initial=0.0)


@pytest.fixture
def arm_without_a_model(tmp_path) -> Path:
    """An arm file the OM method refuses: the Sawyer with a sideways offset (a = 0.01 m) in its
    fixed row between joints 6 and 7, which would make dp depend on q6 as well."""
    text = (ROOT / "arms" / "sawyer.toml").read_text()
    text = text.replace('name = "sawyer"', 'name = "bent"').replace("d = 0.11\n", "d = 0.11\na = 0.01\n")
    path = tmp_path / "bent.toml"
    path.write_text(text)
    return path


def with_offsets(arm: om.Arm, **changes: dict[str, float]) -> om.Arm:
    """The arm with fields of joint rows changed: ``joint3={"a": 0.07}`` sets a4 (0-based joints)."""
    rows = list(arm.chain.rows)
    for key, fields in changes.items():
        r = arm.chain.joint_rows[int(key.removeprefix("joint"))]
        rows[r] = dataclasses.replace(rows[r], **fields)
    return arm.with_chain(arm.chain.replace_rows(rows), f"{arm.name}-offset")


def distance(arm: om.Arm, a: np.ndarray, b: np.ndarray) -> float:
    """Largest joint difference, revolute joints modulo 2 pi."""
    return float(np.abs(np.where(arm.revolute, wrap(a - b), a - b)).max())


def nearest_distance(roots: list[np.ndarray], hint: np.ndarray) -> float:
    """The wrapped Euclidean distance from the hint to the nearest of the roots."""
    return min(float(np.linalg.norm(wrap(root - hint))) for root in roots)


def check_hinted_nearest(
    solver: om.OMSolver, q: np.ndarray, rng: np.random.Generator, sigma: float, within: float
) -> None:
    """The hinted solve at fk(q) in q's configuration returns a root at least as near the hint
    (wrapped Euclidean distance) as every root of solve_all: at a hint sigma from q (N(0, sigma)
    per joint), and 0.3 and 0.45 of the way from each root to each other root closer than within
    (the largest joint difference)."""
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    roots = [root.q for root in solver.solve_all(T, c)] + [q]
    hints = [q + rng.normal(0.0, sigma, solver.arm.dof)]
    hints += [
        a + t * wrap(b - a)
        for a in roots
        for b in roots
        for t in (0.3, 0.45)
        if 0 < distance(solver.arm, a, b) < within
    ]
    for hint in hints:
        hinted = solver.solve(T, c, q_hint=hint)
        assert hinted.ok
        assert np.linalg.norm(wrap(hinted.q - hint)) <= nearest_distance(roots, hint) + 1e-9, (q, hint)


#: Random starts of the independent search per target (polished_roots).
STARTS = 400


def polished_roots(solver: om.OMSolver, T: np.ndarray, psi: float, rng: np.random.Generator) -> list:
    """The roots of T (and, on a 7-DOF arm, of the arm angle psi) that damped Gauss-Newton on the
    arm's exact chain reaches from STARTS random joint vectors: a search that shares nothing with
    the OM system but the chain and psi's definition. In the arm's own joint coordinates."""
    nominal = solver.nominal
    exact = solver.arm.chain if nominal is None else nominal.exact
    flip = np.ones(solver.arm.dof) if nominal is None else nominal.flip
    R, p = flange_target(T, np.linalg.inv(exact.T_root_base), np.linalg.inv(exact.T_flange_tool))
    seven = solver.arm.dof == 7
    arm_angle = _core.ArmAngleRow(solver.model_arm.params, solver.model.chain.table, psi) if seven else None
    roots: list[np.ndarray] = []
    for start in rng.uniform(-np.pi, np.pi, (STARTS, solver.arm.dof)):
        q = np.ascontiguousarray(start)
        if _core.polish(exact.table, R, p, q, 100, arm_angle) > 1e-13:
            continue
        q = flip * q
        if not any(distance(solver.arm, q, r) < 1e-7 for r in roots):
            roots.append(q)
    return roots


def check_exact(solver: om.OMSolver, q: np.ndarray, strict: bool) -> None:
    """Every root of solve_all(fk(q), c) reaches the pose (1e-10 m, 1e-10 rad) in c; where
    ``strict``, q is among them and the hinted solve returns it."""
    arm = solver.arm
    T = arm.fk(q)
    c = solver.configuration_of(q)
    roots = solver.solve_all(T, c)
    for root in roots:
        reached = arm.fk(root.q)
        assert np.linalg.norm(reached[:3, 3] - T[:3, 3]) <= EXACT
        assert np.abs(reached[:3, :3] - T[:3, :3]).max() <= EXACT
        assert solver.holds(root.q, c)
        assert arm.within_limits(root.q) == root.within_limits
    if strict:
        assert any(distance(arm, r.q, q) < 1e-7 for r in roots), q
        hinted = solver.solve(T, c, q_hint=q)
        assert hinted.ok and distance(arm, hinted.q, q) < 1e-7


def well_conditioned(solver: om.OMSolver, q: np.ndarray) -> bool:
    """Away from the singular boundaries: the map to (pose, psi) on a 7-DOF arm (its Jacobian
    with the arm angle's gradient as a seventh row; a fold of the psi-constrained map is where
    two roots of (T, c) meet), the pose map on a 6-DOF arm, and every branch quantity (of the
    model, at ``solver.flip * q``)."""
    values = np.empty(len(solver.sign_names))
    _core.branch_values(solver.model_arm.family, solver.model_arm.params, solver.flip * q, values)
    jacobian = solver.arm.jacobian(q)
    if solver.arm.dof == 7:
        jacobian = np.vstack([jacobian, om.arm_angle_and_gradient(solver, q)[1]])
    sigma = np.linalg.svd(jacobian, compute_uv=False)[-1]
    return sigma > WELL_CONDITIONED and np.abs(values).min() > WELL_CONDITIONED
