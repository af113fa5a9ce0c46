"""ik-geo's decompositions: the fastest one that solves a chain, and the chain laid out for it."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .screws import ScrewChain
from .transforms import pose_errors

# ik-geo: the user picks the decomposition; a wrong one gives wrong answers.

#: ik-geo's decompositions, fastest first: (factory, joints whose axes must be parallel,
#: {joint: other joint} placing a joint's point at its intersection with the other's
#: axis, offsets of P that must then vanish).
IK_GEO_FAMILIES: tuple[tuple[str, tuple[int, ...], dict[int, int], tuple[int, ...]], ...] = (
    ("spherical_two_parallel", (1, 2), {3: 4, 4: 3, 5: 4}, (4, 5)),
    ("spherical_two_intersecting", (), {0: 1, 1: 0, 3: 4, 4: 3, 5: 4}, (1, 4, 5)),
    ("three_parallel_two_intersecting", (1, 2, 3), {3: 4, 4: 3, 5: 4}, (4,)),
    ("spherical", (), {3: 4, 4: 3, 5: 4}, (4, 5)),
    ("three_parallel", (1, 2, 3), {}, ()),
    ("two_parallel", (1, 2), {}, ()),
    ("gen_six_dof", (), {}, ()),
)

_GEOMETRY_TOLERANCE = 1e-9


@dataclass(frozen=True, eq=False)
class IkGeoLayout:
    """A 6-DOF chain laid out for one of ik-geo's decompositions.

    ik-geo solves ``R = rot(h0, q0) ... rot(h5, q5)`` (no end-effector rotation), and its
    Python binding takes (and its ``forward_kinematics`` returns) the TRANSPOSE of that
    rotation matrix (a row- versus column-major mix-up). Its decompositions assume exact
    structure (equal parallel axes, zero offsets between
    intersecting axes), so the chain may be reversed, axes flipped and points moved along
    their axes. Joint ``j`` of :attr:`chain` is the original joint ``order[j]`` with angle
    ``sign[j] * q[order[j]]``.

    Attributes:
        family: Name of the ik-geo factory.
        chain: The chain as given to ik-geo (:attr:`ScrewChain.home` rotation removed at solve time).
        reversed: Whether :attr:`chain` is the original chain reversed (targets inverted).
        order: Original joint of each of :attr:`chain`'s joints.
        sign: +1 or -1 per joint of :attr:`chain`.
    """

    family: str
    chain: ScrewChain
    reversed: bool
    order: np.ndarray
    sign: np.ndarray

    def robot(self) -> Any:
        """The ik-geo robot."""
        from ik_geo import Robot

        H, P = self.chain.hp()
        return getattr(Robot, self.family)(H, P)

    def target(self, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(R, t)`` to hand ik-geo for an end-effector pose T of the original chain."""
        T = np.linalg.inv(T) if self.reversed else T
        return self.chain.home[:3, :3] @ T[:3, :3].T, T[:3, 3]

    def fk(self, robot: Any, q: np.ndarray) -> np.ndarray:
        """The original chain's end-effector pose from ik-geo's own forward kinematics at q (6,)."""
        q_layout = np.empty(6)
        q_layout[:] = q[self.order] * self.sign
        R_t, t = robot.forward_kinematics(q_layout)
        T = np.eye(4)
        T[:3, :3] = np.asarray(R_t).T @ self.chain.home[:3, :3]
        T[:3, 3] = t
        return np.linalg.inv(T) if self.reversed else T

    def original(self, q: np.ndarray) -> np.ndarray:
        """Original joint vectors (k, 6) from ik-geo solutions (k, 6)."""
        q = np.asarray(q, dtype=float).reshape(-1, 6)
        out = np.empty_like(q)
        out[:, self.order] = q * self.sign
        return out


def ik_geo_layout(chain: ScrewChain, rng: np.random.Generator, samples: int = 16) -> IkGeoLayout:
    """The fastest ik-geo decomposition that solves the chain, forwards or reversed.

    A decomposition qualifies when the geometry fits (parallel axes, intersections) and
    its solutions reach every one of ``samples`` random FK poses to 1e-8.

    Raises:
        ValueError: No decomposition solves the chain (``gen_six_dof`` always should).
    """
    q_test = rng.uniform(-np.pi, np.pi, (samples, chain.dof))
    reasons = []
    for family, parallel, meet, zeros in IK_GEO_FAMILIES:
        for is_reversed in (False, True):
            base = chain.reversed() if is_reversed else chain
            order = np.arange(6)[::-1] if is_reversed else np.arange(6)
            layout = _fit_family(family, base, parallel, meet, zeros, is_reversed, order)
            if layout is None:
                continue
            missed = _round_trip_misses(layout, chain, q_test)
            if missed == 0:
                return layout
            reasons.append(f"{family}{' (reversed)' if is_reversed else ''}: {missed}/{samples} missed")
    raise ValueError("no ik-geo decomposition solves this chain: " + "; ".join(reasons))


def _fit_family(
    family: str,
    chain: ScrewChain,
    parallel: tuple[int, ...],
    meet: dict[int, int],
    zeros: tuple[int, ...],
    is_reversed: bool,
    order: np.ndarray,
) -> IkGeoLayout | None:
    axes, points = chain.axes.copy(), chain.points.copy()
    sign = np.ones(6)
    for j in parallel[1:]:
        if np.linalg.norm(np.cross(axes[parallel[0]], axes[j])) > _GEOMETRY_TOLERANCE:
            return None
        if axes[parallel[0]] @ axes[j] < 0.0:
            sign[j] = -1.0
        axes[j] = axes[parallel[0]]
    for j, other in meet.items():
        point = _intersection(axes[j], chain.points[j], axes[other], chain.points[other])
        if point is None:
            return None
        points[j] = point
    for k in zeros:  # offset k joins the points of joints k - 1 and k
        if np.linalg.norm(points[k] - points[k - 1]) > _GEOMETRY_TOLERANCE:
            return None
        points[k] = points[k - 1]
    return IkGeoLayout(family, ScrewChain(axes, points, chain.home), is_reversed, order, sign)


def _intersection(h_a: np.ndarray, o_a: np.ndarray, h_b: np.ndarray, o_b: np.ndarray) -> np.ndarray | None:
    """The point where two lines meet, or None if they are parallel or skew."""
    n = np.cross(h_a, h_b)
    if np.linalg.norm(n) < _GEOMETRY_TOLERANCE:
        return None
    d = o_b - o_a
    if abs(d @ n) / np.linalg.norm(n) > _GEOMETRY_TOLERANCE:
        return None
    t = np.cross(d, h_b) @ n / (n @ n)
    return o_a + t * h_a


def _round_trip_misses(layout: IkGeoLayout, chain: ScrewChain, q_test: np.ndarray) -> int:
    try:
        robot = layout.robot()
    except BaseException:  # a Rust panic surfaces as BaseException
        return len(q_test)
    missed = 0
    for q in q_test:
        T = chain.fk(q)
        try:
            found = [s for s, is_ls in robot.get_ik(*layout.target(T)) if not is_ls]
        except BaseException:
            found = []
        reached = [pose_errors(chain.fk(s), T) for s in layout.original(found)] if found else []
        missed += not any(p < 1e-8 and r < 1e-8 for p, r in reached)
    return missed
