"""The analytic peers: EAIK and ik-geo, 6-DOF solvers with joint 7 held."""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

import om_redundant as om

from ..robots import (
    SixAxisView,
    eaik_robot,
    ik_geo_layout,
)
from .base import BatchMethod, Method, Peer, Unavailable, _rows, first_within_limits

#: Values of the held joint 7 tried by the analytic peers for "any in-limit solution".
Q7_GRID_SIZE = 32


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
