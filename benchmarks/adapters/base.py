"""What every peer is: a :class:`Peer` with its :class:`Method`\\ s, and the joint-limit helpers."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

import om_redundant as om


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


def _revolute_only(arm: om.Arm) -> None:
    if not arm.revolute.all():
        raise Unavailable(
            f"arm '{arm.name}' has a prismatic joint (this suite writes URDF/MJCF for revolute arms)"
        )
