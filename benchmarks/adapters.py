"""Each IK library behind one small interface, so that the protocols treat them alike.

A :class:`Peer` is one library set up for one arm. It offers up to three
:class:`Method`\\ s, one per protocol of :mod:`benchmarks.protocols`:

* ``exact``: the solution for a given redundancy (7-DOF: q7 held at the true value for the
  peers, the true arm angle psi for om_redundant; 6-DOF: the plain solve);
* ``any``: some solution within the limits;
* ``every``: all solutions for a given redundancy value.

A method is split in three so that only the library call is timed: ``prepare`` converts
the target into the library's frames and types, ``call`` is the timed call and
``solutions`` turns its result into joint vectors of the arm.

Peer factories raise :class:`Unavailable` with the reason when a library is missing or
does not handle the arm; the suite prints it and goes on.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

import om_redundant as om

from .om_any import COARSE_PSI, FINE_PSI, AnyInLimits
from .robots import (
    EE_LINK,
    ROOT_LINK,
    SixAxisView,
    eaik_robot,
    home_joints,
    ik_geo_layout,
    rot_z,
    urdf_text,
)

#: Values of the held joint 7 tried by the analytic peers for "any in-limit solution".
Q7_GRID_SIZE = 32
#: TRAC-IK settings: time budget per solve (s) and its convergence threshold (below 1e-6).
TRAC_IK_TIMEOUT = 0.005
TRAC_IK_EPSILON = 1e-7
#: mink settings, as in its arm examples: 200 steps of the QP from the home pose.
MINK_STEPS = 200
MINK_DT = 0.002
MINK_SOLVER = "daqp"
MINK_DAMPING = 1e-3


class Unavailable(Exception):
    """A peer that cannot run on this arm or machine; the message says why."""


@dataclass(frozen=True)
class Method:
    """One way of solving a target, split so that only the library call is timed.

    Attributes:
        prepare: ``(T, q_true) -> argument``: the target in the library's terms (untimed).
            Only the ``exact`` and ``every`` protocols may use ``q_true`` (its redundancy).
        call: ``argument -> result``: the library call (timed).
        solutions: ``(argument, result) -> (k, dof)`` joint vectors of the arm (untimed).
    """

    prepare: Callable[[np.ndarray, np.ndarray], Any]
    call: Callable[[Any], Any]
    solutions: Callable[[Any, Any], np.ndarray]


@dataclass(frozen=True)
class BatchMethod:
    """A batch solve over all targets at once, split like :class:`Method`.

    Attributes:
        name: What is called, for the table.
        prepare: ``(T (N, 4, 4), q_true (N, dof)) -> argument`` (untimed).
        call: ``argument -> result`` (timed), on the library's own threads.
        one_thread: The same call on one thread (its CPU time is measured).
        solutions: ``(argument, result) -> [(k, dof) per target]`` (untimed).
    """

    name: str
    prepare: Callable[[np.ndarray, np.ndarray], Any]
    call: Callable[[Any], Any]
    one_thread: Callable[[Any], Any]
    solutions: Callable[[Any, Any], list[np.ndarray]]


@dataclass
class Peer:
    """An IK library set up for one arm.

    Attributes:
        name: Name in the tables.
        arm: The arm.
        fk: The library's own forward kinematics, mapped to the arm's root and end-effector
            frames; checked against ``arm.fk`` before any number is trusted.
        settings: The settings used, for the report.
        limit_tolerance: Slack (rad) on the joint limits, for libraries storing them in float32.
        exact: The ``exact`` protocol's method, if the library has one.
        any: The ``any`` protocol's method, if the library has one.
        every: The ``every`` protocol's method, if the library has one.
        batch: A batch call over all targets with the given redundancy, if the library has one.
    """

    name: str
    arm: om.Arm
    fk: Callable[[np.ndarray], np.ndarray] | None
    settings: str
    limit_tolerance: float = 0.0
    exact: Method | None = None
    any: Method | None = None
    every: Method | None = None
    batch: BatchMethod | None = None


def shift_into_limits(Q: np.ndarray, arm: om.Arm, tolerance: float = 0.0) -> np.ndarray:
    """Shift revolute joints by multiples of 2 pi into the limits where that is possible."""
    Q = np.array(Q, dtype=float, copy=True)
    lower, upper = arm.lower - tolerance, arm.upper + tolerance
    turns = np.ceil((lower - Q) / (2 * np.pi))
    shifted = Q + 2 * np.pi * turns
    inside = np.isfinite(lower) & (shifted <= upper) & arm.revolute
    return np.where(inside, shifted, Q)


def within_limits(Q: np.ndarray, arm: om.Arm, tolerance: float = 0.0) -> np.ndarray:
    """Which rows of Q (k, dof) lie within the limits widened by ``tolerance``."""
    lower, upper = arm.lower - tolerance, arm.upper + tolerance
    return ((lower <= Q) & (upper >= Q)).all(axis=1)


def first_within_limits(Q: np.ndarray, arm: om.Arm, tolerance: float = 0.0) -> np.ndarray | None:
    """The first row of Q (k, dof) within the limits after 2 pi shifts, or None."""
    if len(Q) == 0:
        return None
    Q = shift_into_limits(Q, arm, tolerance)
    index = np.flatnonzero(within_limits(Q, arm, tolerance))
    return Q[index[0]] if len(index) else None


def _rows(q: Any, dof: int) -> np.ndarray:
    """Joint vectors as (k, dof), NaN rows dropped; None or empty gives (0, dof)."""
    if q is None:
        return np.empty((0, dof))
    Q = np.asarray(q, dtype=float).reshape(-1, dof)
    return Q[~np.isnan(Q).any(axis=1)]


# ---------------------------------------------------------------------------------------
# om_redundant


def om_redundant_peer(arm: om.Arm, rng: np.random.Generator) -> Peer:
    """om_redundant's OMSolver."""
    try:
        solver = om.OMSolver(arm)
    except om.ModelError as exc:
        raise Unavailable(f"{arm.dof}-DOF solver not available (ModelError: {exc})") from exc

    def solved(_: Any, solution: om.Solution | None) -> np.ndarray:
        return solution.q[None, :] if solution is not None and solution.ok else np.empty((0, arm.dof))

    def every_prepare(T: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, list[om.Configuration]]:
        return T, solver.configurations(solver.configuration_of(q).redundancy)

    def every_call(argument: tuple[np.ndarray, list[om.Configuration]]) -> list[om.Solution]:
        T, configurations = argument
        return [s for c in configurations for s in solver.solve_all(T, c)]

    def batch_prepare(T: np.ndarray, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        configurations = [solver.configuration_of(q) for q in Q]
        redundancy = np.array([c.redundancy for c in configurations])
        return T, np.array([c.signs for c in configurations]), redundancy if redundancy.size else None

    def batch_solutions(_: Any, result: om.BatchSolution) -> list[np.ndarray]:
        return [
            q[None, :] if ok else np.empty((0, arm.dof)) for q, ok in zip(result.q, result.ok, strict=True)
        ]

    return Peer(
        "om_redundant",
        arm,
        None,
        "OMSolver defaults; any: first ok solution within limits over the configurations"
        + (
            f" x {COARSE_PSI} arm angles psi, most frequent cells of random in-limit joint vectors"
            f" first, then {FINE_PSI} arm angles"
            if solver.redundancy_names
            else ""
        ),
        exact=Method(
            lambda T, q: (T, solver.configuration_of(q)),
            lambda argument: solver.solve(*argument),
            solved,
        ),
        any=Method(lambda T, q: T, AnyInLimits(solver), solved),
        every=Method(
            every_prepare,
            every_call,
            lambda _, found: _rows([s.q for s in found], arm.dof),
        ),
        batch=BatchMethod(
            "om_redundant solve_batch (C, threads)",
            batch_prepare,
            lambda argument: solver.solve_batch(*argument),
            lambda argument: solver.solve_batch(*argument, threads=1),
            batch_solutions,
        ),
    )


# ---------------------------------------------------------------------------------------
# The analytic peers: EAIK and ik-geo, 6-DOF solvers with joint 7 held


@dataclass(frozen=True)
class _Analytic:
    """A 6-DOF analytic solver: ``call(prepare(T6))`` and ``rows(result)`` (k, 6) in the arm's order."""

    prepare: Callable[[np.ndarray], Any]
    call: Callable[[Any], Any]
    rows: Callable[[Any], np.ndarray]


def _analytic_peer(name: str, arm: om.Arm, view: SixAxisView, solver: _Analytic, settings: str) -> Peer:
    """exact / any / every methods of a 6-DOF analytic solver, joint 7 held for 7-DOF arms."""

    def held(q: np.ndarray) -> float:
        return float(q[6]) if view.held else 0.0

    def given(T: np.ndarray, q: np.ndarray) -> tuple[Any, float]:
        return solver.prepare(view.target(T, held(q))), held(q)

    def rows(argument: tuple[Any, float], result: Any) -> np.ndarray:
        return view.full(solver.rows(result), argument[1])

    given_method = Method(given, lambda argument: solver.call(argument[0]), rows)

    if view.held:
        limited = np.isfinite(arm.upper[6] - arm.lower[6])
        grid = np.linspace(*((arm.lower[6], arm.upper[6]) if limited else (-np.pi, np.pi)), Q7_GRID_SIZE)

        def grid_prepare(T: np.ndarray, _: np.ndarray) -> list[tuple[Any, float]]:
            return [(solver.prepare(view.target(T, v)), v) for v in grid]

        def grid_call(targets: list[tuple[Any, float]]) -> np.ndarray | None:
            for target, v in targets:
                q = first_within_limits(view.full(solver.rows(solver.call(target)), v), arm)
                if q is not None:
                    return q
            return None

        any_method = Method(grid_prepare, grid_call, lambda _, q: _rows(q, arm.dof))
        settings += f"; any: q7 on a grid of {Q7_GRID_SIZE} over its limits, first solution within limits"
    else:
        any_method = Method(
            lambda T, _: solver.prepare(T),
            lambda target: first_within_limits(solver.rows(solver.call(target)), arm),
            lambda _, q: _rows(q, arm.dof),
        )
    return Peer(name, arm, None, settings, exact=given_method, any=any_method, every=given_method)


def _six_axis_view(arm: om.Arm) -> SixAxisView:
    try:
        return SixAxisView.of(arm)
    except ValueError as exc:
        raise Unavailable(str(exc)) from exc


def eaik_peer(arm: om.Arm, rng: np.random.Generator) -> Peer:
    """EAIK (subproblem decomposition, C++), from H and P; q7 held by transforming the target."""
    try:
        import eaik  # noqa: F401
    except ImportError as exc:
        raise Unavailable(f"not installed ({exc})") from exc
    view = _six_axis_view(arm)
    robot = eaik_robot(view.chain)
    if not robot.has_known_decomposition():
        raise Unavailable(f"no known decomposition ({robot.get_kinematic_family()})")

    def rows(solution: Any) -> np.ndarray:
        Q = np.asarray(solution.Q, dtype=float).reshape(-1, 6)
        return Q[~np.asarray(solution.is_LS, dtype=bool)] if len(Q) else Q

    peer = _analytic_peer(
        "EAIK",
        arm,
        view,
        _Analytic(lambda T6: T6, robot.calculate_IK, rows),
        f"family {robot.get_kinematic_family()}, double precision; least-squares solutions dropped",
    )
    peer.fk = lambda q: view.pose(robot.fwdkin(q[:6]), float(q[6]) if view.held else 0.0)
    threads = os.cpu_count() or 1

    def batch_prepare(T: np.ndarray, Q: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
        held = Q[:, 6] if view.held else np.zeros(len(Q))
        return [view.target(pose, v) for pose, v in zip(T, held, strict=True)], held

    def batch_solutions(argument: tuple[list[np.ndarray], np.ndarray], result: list) -> list[np.ndarray]:
        return [view.full(rows(s), v) for s, v in zip(result, argument[1], strict=True)]

    peer.batch = BatchMethod(
        f"EAIK calculate_IK_batched ({threads} threads)",
        batch_prepare,
        lambda argument: robot.calculate_IK_batched(argument[0], threads),
        lambda argument: robot.calculate_IK_batched(argument[0], 1),
        batch_solutions,
    )
    return peer


def ik_geo_peer(arm: om.Arm, rng: np.random.Generator) -> Peer:
    """ik-geo (IK-Geo in Rust); decomposition chosen by geometry and a round-trip test."""
    os.environ["RUST_BACKTRACE"] = "0"  # a panicking decomposition would print a long trace
    try:
        import ik_geo  # noqa: F401
    except ImportError as exc:
        raise Unavailable(f"not installed ({exc})") from exc
    view = _six_axis_view(arm)
    try:
        layout = ik_geo_layout(view.chain, rng)
    except ValueError as exc:
        raise Unavailable(str(exc)) from exc
    robot = layout.robot()

    def rows(found: list[tuple[list[float], bool]]) -> np.ndarray:
        return layout.original([q for q, is_ls in found if not is_ls])

    peer = _analytic_peer(
        "ik-geo",
        arm,
        view,
        _Analytic(layout.target, lambda target: robot.get_ik(*target), rows),
        f"decomposition {layout.family}{' on the reversed chain' if layout.reversed else ''}; "
        "least-squares solutions dropped",
    )
    peer.fk = lambda q: view.pose(layout.fk(robot, q[:6]), float(q[6]) if view.held else 0.0)
    return peer


# ---------------------------------------------------------------------------------------
# Peers from a URDF: TRAC-IK and ikpy


def _revolute_only(arm: om.Arm) -> None:
    if not arm.revolute.all():
        raise Unavailable(
            f"arm '{arm.name}' has a prismatic joint (this suite writes URDF/MJCF for revolute arms)"
        )


def trac_ik_peer(arm: om.Arm, rng: np.random.Generator) -> Peer:
    """TRAC-IK (KDL + SQP, C++) via pytracik, from the generated URDF; one call from home."""
    try:
        import pytracik
    except ImportError as exc:
        raise Unavailable(f"not installed ({exc})") from exc
    _revolute_only(arm)
    solver = pytracik.TRAC_IK(
        ROOT_LINK, EE_LINK, urdf_text(arm), TRAC_IK_TIMEOUT, TRAC_IK_EPSILON, pytracik.SolveType.Speed
    )
    if pytracik.get_num_joints(solver) != arm.dof:
        raise Unavailable(
            f"parsed {pytracik.get_num_joints(solver)} joints from the URDF, expected {arm.dof}"
        )
    home = home_joints(arm)

    def prepare(T: np.ndarray, _: np.ndarray) -> tuple[float, ...]:
        x, y, z, w = Rotation.from_matrix(T[:3, :3]).as_quat()
        return (*T[:3, 3], x, y, z, w)

    def solutions(_: Any, result: Any) -> np.ndarray:
        return _rows(result[1:], arm.dof) if result[0] >= 0 else np.empty((0, arm.dof))

    return Peer(
        "TRAC-IK",
        arm,
        lambda q: np.asarray(pytracik.fk(solver, np.asarray(q, dtype=float))),
        f"Speed, timeout {TRAC_IK_TIMEOUT * 1e3:g} ms, epsilon {TRAC_IK_EPSILON:g}, seed = home; "
        "limits stored in float32 (1e-6 rad slack)",
        limit_tolerance=1e-6,
        any=Method(prepare, lambda target: pytracik.ik(solver, home, *target), solutions),
    )


def ikpy_peer(arm: om.Arm, rng: np.random.Generator) -> Peer:
    """ikpy (scipy least squares), from the generated URDF; one call from home."""
    try:
        import ikpy.chain
    except ImportError as exc:
        raise Unavailable(f"not installed ({exc})") from exc
    _revolute_only(arm)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"{arm.name}.urdf"
        path.write_text(urdf_text(arm))
        chain = ikpy.chain.Chain.from_urdf_file(
            str(path), base_elements=[ROOT_LINK], active_links_mask=[False, *[True] * arm.dof, False]
        )
    start = np.concatenate([[0.0], home_joints(arm), [0.0]])

    def fk(q: np.ndarray) -> np.ndarray:
        return chain.forward_kinematics(np.concatenate([[0.0], q, [0.0]]))

    return Peer(
        "ikpy",
        arm,
        fk,
        'inverse_kinematics_frame, orientation_mode="all", default optimizer (least_squares), start = home',
        any=Method(
            lambda T, _: T,
            lambda T: chain.inverse_kinematics_frame(T, initial_position=start, orientation_mode="all"),
            lambda _, q: _rows(np.asarray(q)[1:-1], arm.dof),
        ),
    )


# ---------------------------------------------------------------------------------------
# mink, differential IK on the generated MJCF


def mink_example_tasks(
    model: Any, frame: str, home: np.ndarray, posture: bool = True
) -> tuple[Any, list[Any]]:
    """mink's arm-example tasks: a FrameTask on the site ``frame`` (costs 1, lm_damping 1)
    and, with ``posture``, a PostureTask toward ``home`` (cost 1e-2).

    Returns:
        ``(frame_task, tasks)``.
    """
    import mink

    frame_task = mink.FrameTask(frame, "site", position_cost=1.0, orientation_cost=1.0, lm_damping=1.0)
    if not posture:
        return frame_task, [frame_task]
    posture_task = mink.PostureTask(model, cost=1e-2)
    posture_task.set_target(home)
    return frame_task, [frame_task, posture_task]


def _mink_peer(arm: om.Arm, posture: bool) -> Peer:
    try:
        import mink
    except ImportError as exc:
        raise Unavailable(f"not installed ({exc})") from exc
    _revolute_only(arm)
    model = om.arm_model(arm)
    frame = arm.frame_name or om.mujoco_io.DEFAULT_SITE
    configuration = mink.Configuration(model)
    home = home_joints(arm)
    frame_task, tasks = mink_example_tasks(model, frame, home, posture)
    limits = [mink.ConfigurationLimit(model)]

    def fk(q: np.ndarray) -> np.ndarray:
        configuration.update(np.asarray(q, dtype=float))
        return configuration.get_transform_frame_to_world(frame, "site").as_matrix()

    def call(target: Any) -> np.ndarray:
        configuration.update(home)
        frame_task.set_target(target)
        for _ in range(MINK_STEPS):
            velocity = mink.solve_ik(
                configuration, tasks, MINK_DT, MINK_SOLVER, damping=MINK_DAMPING, limits=limits
            )
            configuration.integrate_inplace(velocity, MINK_DT)
        return configuration.q.copy()

    what = "FrameTask + PostureTask (cost 1e-2)" if posture else "FrameTask only"
    return Peer(
        f"mink ({'frame+posture' if posture else 'frame only'})",
        arm,
        fk,
        f"{what}, lm_damping 1, damping {MINK_DAMPING:g}, ConfigurationLimit, {MINK_STEPS} steps of "
        f'solve_ik("{MINK_SOLVER}") from home',
        any=Method(lambda T, _: mink.SE3.from_matrix(T), call, lambda _, q: _rows(q, arm.dof)),
    )


def mink_peer(arm: om.Arm, rng: np.random.Generator) -> Peer:
    """mink as in its arm examples: a FrameTask plus a PostureTask toward home."""
    return _mink_peer(arm, posture=True)


def mink_frame_only_peer(arm: om.Arm, rng: np.random.Generator) -> Peer:
    """mink with the FrameTask alone (the posture task biases the end pose)."""
    return _mink_peer(arm, posture=False)


# ---------------------------------------------------------------------------------------
# frankik, the closed form of the Franka arms


def frankik_peer(arm: om.Arm, rng: np.random.Generator) -> Peer:
    """frankik (He and Liu's analytic Franka IK, q7 given), Franka arms only.

    frankik's ``fk`` returns the hand's TCP (flange, Rz(-45 deg), 0.1034 m along z) but its
    ``ik`` takes the flange pose: the adapter maps both to the arm file's frame, with the
    constant offset measured once at q = 0 and then checked on random q.
    """
    try:
        import frankik
    except ImportError as exc:
        raise Unavailable(f"not installed ({exc})") from exc
    if arm.name not in ("panda", "fr3"):
        raise Unavailable("Franka arms only")
    is_fr3 = arm.name == "fr3"
    kinematics = frankik.FrankaKinematics(frankik.RobotType.FR3 if is_fr3 else frankik.RobotType.PANDA)
    hand = rot_z(-np.pi / 4) @ _translation_z(0.1034)
    zero = np.zeros(7)
    # ik frame in the arm file's end-effector frame.
    offset = np.linalg.inv(arm.fk(zero)) @ frankik.fk(zero) @ np.linalg.inv(hand)
    home = home_joints(arm)

    def exact_rows(_: Any, result: np.ndarray) -> np.ndarray:
        return _rows(result, 7)

    exact = Method(
        lambda T, q: (T @ offset, home, float(q[6])),
        lambda argument: frankik.ik_full(*argument, is_fr3=is_fr3),
        exact_rows,
    )
    return Peer(
        "frankik",
        arm,
        lambda q: frankik.fk(np.asarray(q, dtype=float)) @ np.linalg.inv(hand) @ np.linalg.inv(offset),
        "ik_full with q7 given (returns in-limit solutions only); any: FrankaKinematics.inverse "
        "(q7 sampled by the library), q0 = home",
        exact=exact,
        any=Method(
            lambda T, _: T @ offset,
            lambda target: kinematics.inverse(target, q0=home),
            lambda _, q: _rows(q, 7),
        ),
        every=exact,
    )


def _translation_z(z: float) -> np.ndarray:
    T = np.eye(4)
    T[2, 3] = z
    return T


#: Peer factories by name, in table order.
PEERS: dict[str, Callable[[om.Arm, np.random.Generator], Peer]] = {
    "om_redundant": om_redundant_peer,
    "EAIK": eaik_peer,
    "ik-geo": ik_geo_peer,
    "frankik": frankik_peer,
    "TRAC-IK": trac_ik_peer,
    "ikpy": ikpy_peer,
    "mink (frame+posture)": mink_peer,
    "mink (frame only)": mink_frame_only_peer,
}

__all__ = [
    "PEERS",
    "BatchMethod",
    "Method",
    "Peer",
    "Unavailable",
    "first_within_limits",
    "shift_into_limits",
]
