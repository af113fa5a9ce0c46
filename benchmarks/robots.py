"""The peers' robots, generated from one om_redundant arm file, and checks of their FK.

Every peer gets its robot from the same joint placements,
``T_root_ee(q) = P[0] Rz(q0) P[1] Rz(q1) ... P[n-1] Rz(q_{n-1}) P_tail``
(:meth:`om_redundant.KinematicChain.joint_placements`):

* :func:`urdf_text` for TRAC-IK and ikpy (mink uses the library's :func:`om_redundant.arm_model`);
* :class:`ScrewChain`, the joints as lines in the zero configuration (axes ``H``, points
  ``P``), for EAIK and ik-geo; :class:`SixAxisView` holds a 7-DOF arm's last joint at a
  given value so that those 6-DOF solvers apply; :func:`ik_geo_layout` picks ik-geo's
  decomposition and moves the points to the axis intersections it needs.

:func:`check_fk` compares a peer's forward kinematics with ``arm.fk`` on random joint
vectors; the suite refuses a peer whose FK disagrees.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
from scipy.spatial.transform import Rotation

import om_redundant as om

#: Names of the generated URDF links that the peers chain between.
ROOT_LINK = "root"
EE_LINK = "ee"
#: The reference MuJoCo Menagerie models (kinematics only), beside the project.
MENAGERIE = Path(__file__).resolve().parents[2] / "shared" / "reference" / "menagerie"


# ---------------------------------------------------------------------------------------
# Transforms


def rot_z(angle: float) -> np.ndarray:
    """Homogeneous rotation about z (4x4)."""
    c, s = np.cos(angle), np.sin(angle)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    return T


def pose_errors(T_a: np.ndarray, T_b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position distance (m) and rotation angle (rad) between poses (..., 4, 4)."""
    position = np.linalg.norm(T_a[..., :3, 3] - T_b[..., :3, 3], axis=-1)
    R = np.swapaxes(T_a[..., :3, :3], -1, -2) @ T_b[..., :3, :3]
    # The angle from the skew part: accurate for small angles, unlike arccos of the trace.
    skew = np.stack(
        [R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]], -1
    )
    trace = R[..., 0, 0] + R[..., 1, 1] + R[..., 2, 2]
    angle = np.arctan2(np.linalg.norm(skew, axis=-1) / 2.0, (trace - 1.0) / 2.0)
    return position, angle


def random_joints(arm: om.Arm, n: int, rng: np.random.Generator) -> np.ndarray:
    """Uniform joint vectors within limits (unlimited joints in [-pi, pi]), shape (n, dof)."""
    lower = np.where(np.isfinite(arm.lower), arm.lower, -np.pi)
    upper = np.where(np.isfinite(arm.upper), arm.upper, np.pi)
    return rng.uniform(lower, upper, (n, arm.dof))


def joint_distance(arm: om.Arm, a: np.ndarray, b: np.ndarray) -> float:
    """max |a - b| over the joints, revolute joints modulo 2 pi."""
    d = a - b
    return float(np.abs(np.where(arm.revolute, np.remainder(d + np.pi, 2 * np.pi) - np.pi, d)).max())


def reference_spec(relative_path: str) -> mujoco.MjSpec:
    """A Menagerie MJCF under :data:`MENAGERIE` with its meshes stripped (the files ship
    without them), to edit before compiling."""
    return om.without_meshes(mujoco.MjSpec.from_file(str(MENAGERIE / relative_path)))


def reference_model(relative_path: str) -> mujoco.MjModel:
    """A Menagerie model under :data:`MENAGERIE`, compiled without its missing meshes."""
    return om.load_mujoco_model(MENAGERIE / relative_path)


def home_joints(arm: om.Arm) -> np.ndarray:
    """The start of the iterative peers: the middle of each joint's range (0 if unlimited)."""
    middle = (arm.lower + arm.upper) / 2.0
    return np.where(np.isfinite(middle), middle, 0.0)


# ---------------------------------------------------------------------------------------
# URDF and MJCF


def _numbers(values: Any) -> str:
    return " ".join(repr(float(v)) for v in np.ravel(values))


def urdf_text(arm: om.Arm) -> str:
    """A URDF of the arm: one link per joint frame, revolute joints about z, a fixed ``ee`` link.

    Joint origins are the placements ``P[i]`` (xyz and roll-pitch-yaw, full precision),
    limits are the arm's (``continuous`` where unlimited). Links carry a small inertia so
    that parsers which want one are satisfied, except the root (KDL refuses an inertial
    root link). Only revolute arms are supported.
    """
    if not arm.revolute.all():
        raise ValueError(f"arm '{arm.name}' has a prismatic joint; the URDF writer takes revolute arms")
    P, tail = arm.chain.joint_placements()
    links = [ROOT_LINK, *(f"link{i + 1}" for i in range(arm.dof)), EE_LINK]
    inertial = (
        '<inertial><mass value="0.1"/>'
        '<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>'
    )
    lines = ['<?xml version="1.0"?>', f'<robot name="{arm.name}">']
    lines.append(f'  <link name="{ROOT_LINK}"/>')
    lines += [f'  <link name="{name}">{inertial}</link>' for name in links[1:]]
    for i, (placement, joint) in enumerate(zip(P, arm.joint_names, strict=True)):
        lo, hi = float(arm.lower[i]), float(arm.upper[i])
        kind = "revolute" if np.isfinite(lo) and np.isfinite(hi) else "continuous"
        limit = (
            f'<limit lower="{lo!r}" upper="{hi!r}" effort="100" velocity="10"/>' if kind == "revolute" else ""
        )
        lines.append(
            f'  <joint name="{joint}" type="{kind}"><parent link="{links[i]}"/><child link="{links[i + 1]}"/>'
            f'{_urdf_origin(placement)}<axis xyz="0 0 1"/>{limit}</joint>'
        )
    lines.append(
        f'  <joint name="{EE_LINK}_joint" type="fixed"><parent link="{links[-2]}"/>'
        f'<child link="{EE_LINK}"/>{_urdf_origin(tail)}</joint>'
    )
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def _urdf_origin(T: np.ndarray) -> str:
    # URDF's rpy is R = Rz(yaw) Ry(pitch) Rx(roll): scipy's extrinsic "xyz".
    rpy = Rotation.from_matrix(T[:3, :3]).as_euler("xyz")
    return f'<origin xyz="{_numbers(T[:3, 3])}" rpy="{_numbers(rpy)}"/>'


# ---------------------------------------------------------------------------------------
# Screw axes: H and P for EAIK and ik-geo


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' rotation about a unit axis (3x3)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


@dataclass(frozen=True, eq=False)
class ScrewChain:
    r"""Revolute joints as lines in the zero configuration (product of exponentials).

    :math:`T(q) = g_0(q_0) \cdots g_{n-1}(q_{n-1})\, M`, where :math:`g_i` rotates by
    :math:`q_i` about the line through ``points[i]`` along ``axes[i]``. Any point of each
    line will do; :meth:`hp` turns them into EAIK's and ik-geo's ``(H, P)``.

    Attributes:
        axes: (n, 3) unit joint axes.
        points: (n, 3) a point of each joint axis.
        home: (4, 4) end-effector pose at q = 0.
    """

    axes: np.ndarray
    points: np.ndarray
    home: np.ndarray

    @classmethod
    def from_placements(cls, P: np.ndarray, tail: np.ndarray) -> ScrewChain:
        """The chain ``P[0] Rz(q0) ... P[n-1] Rz(q_{n-1}) tail`` (joints about local z)."""
        frames = []
        current = np.eye(4)
        for placement in P:
            current = current @ placement
            frames.append(current)
        frames = np.array(frames)
        return cls(frames[:, :3, 2].copy(), frames[:, :3, 3].copy(), current @ tail)

    @classmethod
    def from_arm(cls, arm: om.Arm) -> ScrewChain:
        """The chain of a revolute arm."""
        if not arm.revolute.all():
            raise ValueError(f"arm '{arm.name}' has a prismatic joint; H and P describe revolute chains")
        return cls.from_placements(*arm.chain.joint_placements())

    @property
    def dof(self) -> int:
        return len(self.axes)

    def fk(self, q: np.ndarray) -> np.ndarray:
        """End-effector pose (4x4) at joint vector q."""
        T = np.eye(4)
        for h, o, angle in zip(self.axes, self.points, q, strict=True):
            g = np.eye(4)
            g[:3, :3] = _rotation(h, angle)
            g[:3, 3] = o - g[:3, :3] @ o
            T = T @ g
        return T @ self.home

    def hp(self) -> tuple[np.ndarray, np.ndarray]:
        """``(H, P)``: (n, 3) axes and (n + 1, 3) offsets base -> point 0 -> ... -> end effector."""
        ends = np.vstack([np.zeros(3), self.points, self.home[:3, 3]])
        return self.axes.copy(), np.diff(ends, axis=0)

    def reversed(self) -> ScrewChain:
        r"""The chain of :math:`T(q)^{-1}` with the joints in reverse order and the same angles.

        :math:`T^{-1} = M^{-1} g_{n-1}^{-1} \cdots g_0^{-1}`; conjugating each factor by
        :math:`M` moves it in front, and negating the axis keeps the sign of the angle.
        """
        M_inv = np.linalg.inv(self.home)
        axes = -(M_inv[:3, :3] @ self.axes[::-1].T).T
        points = (M_inv[:3, :3] @ self.points[::-1].T).T + M_inv[:3, 3]
        return ScrewChain(axes, points, M_inv)


@dataclass(frozen=True, eq=False)
class SixAxisView:
    """An arm as six revolute joints: a 7-DOF arm with its last joint held at a given value.

    With the last joint held at ``q_last``,
    ``T = T6(q[:6]) Rz(q_last) P_tail``, so the 6-DOF chain ending at the last joint's
    frame must reach ``target(T, q_last) = T P_tail^-1 Rz(-q_last)``.

    Attributes:
        chain: The six free joints, ending at the last joint's frame (7-DOF) or at the
            end effector (6-DOF).
        held: Whether a last joint is held.
        tail_inv: Inverse of the last placement ``P_tail`` (identity for 6-DOF arms).
    """

    chain: ScrewChain
    held: bool
    tail_inv: np.ndarray

    @classmethod
    def of(cls, arm: om.Arm) -> SixAxisView:
        """The view of a 6-DOF or 7-DOF revolute arm."""
        if not arm.revolute.all() or arm.dof not in (6, 7):
            raise ValueError(f"arm '{arm.name}': EAIK and ik-geo take 6 or 7 revolute joints")
        P, tail = arm.chain.joint_placements()
        if arm.dof == 6:
            return cls(ScrewChain.from_placements(P, tail), False, np.eye(4))
        return cls(ScrewChain.from_placements(P[:6], P[6]), True, np.linalg.inv(tail))

    def target(self, T: np.ndarray, q_last: float = 0.0) -> np.ndarray:
        """The pose the six free joints must reach for end-effector pose T."""
        return T @ self.tail_inv @ rot_z(-q_last) if self.held else T

    def pose(self, T6: np.ndarray, q_last: float = 0.0) -> np.ndarray:
        """The end-effector pose when the six free joints reach T6: the inverse of :meth:`target`."""
        return T6 @ rot_z(q_last) @ np.linalg.inv(self.tail_inv) if self.held else T6

    def full(self, q6: np.ndarray, q_last: float = 0.0) -> np.ndarray:
        """The arm's joint vectors (k, dof) from six-joint solutions (k, 6)."""
        q6 = np.asarray(q6, dtype=float).reshape(-1, 6)
        return np.hstack([q6, np.full((len(q6), 1), q_last)]) if self.held else q6


def eaik_robot(chain: ScrewChain) -> Any:
    """An EAIK robot of the chain, from ``(H, P)`` and the end-effector orientation at q = 0."""
    from eaik.pybindings import EAIK

    H, P = chain.hp()
    return EAIK.Robot(H.T, P.T, chain.home[:3, :3], [], True)


# ---------------------------------------------------------------------------------------
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


# ---------------------------------------------------------------------------------------
# FK checks


@dataclass(frozen=True)
class FKCheck:
    """A peer's forward kinematics against ``arm.fk`` on random joint vectors.

    Attributes:
        peer: Peer name.
        arm: Arm name.
        samples: Number of joint vectors compared.
        position_error: Largest position difference (m).
        orientation_error: Largest rotation angle between the frames (rad).
        tolerance: The bound both must meet.
    """

    peer: str
    arm: str
    samples: int
    position_error: float
    orientation_error: float
    tolerance: float

    @property
    def passed(self) -> bool:
        return bool(self.position_error <= self.tolerance and self.orientation_error <= self.tolerance)

    def line(self) -> str:
        verdict = "ok" if self.passed else "REFUSED"
        return (
            f"FK {self.peer} on {self.arm}: max |dp| {self.position_error:.1e} m, max angle "
            f"{self.orientation_error:.1e} rad over {self.samples} q (tol {self.tolerance:.0e}): {verdict}"
        )


def check_fk(
    peer: str,
    arm: om.Arm,
    fk: Callable[[np.ndarray], np.ndarray],
    rng: np.random.Generator,
    samples: int = 64,
    tolerance: float = 1e-9,
) -> FKCheck:
    """Compare ``fk(q)`` (a 4x4 pose of the arm's end effector in its root) with ``arm.fk(q)``."""
    Q = random_joints(arm, samples, rng)
    peer_T = np.array([fk(q) for q in Q])
    position, angle = pose_errors(peer_T, arm.fk(Q))
    return FKCheck(peer, arm.name, samples, float(position.max()), float(angle.max()), tolerance)
