r"""How :class:`~om_redundant.ExactPoseTask` takes the arm to a target that jumped.

**The hand's way** (:func:`lead_pose`, :func:`next_aim`). With hand pose :math:`H` and target
:math:`T`, position gap :math:`d = |p_T - p_H|` and rotation gap :math:`\theta` (the angle of
:math:`R_H^T R_T`), an aim is the pose a fraction

.. math::  s = \min\big(1,\ \ell_p / d,\ \ell_r / \theta\big)

of the way from H to T: the position on the straight line, the rotation turned about the
fixed axis of :math:`R_H^T R_T` (spherical interpolation); the target itself where
:math:`s = 1`. The optimiser tracks from one aim to the next.

**The joints' way** (:class:`JointWay`): the straight segment from :math:`q_s`, where the
arm was, to a choice :math:`q^*` made afresh, whose clearance the optimiser certified. The
error pulls to the point of the segment a lead :math:`\ell_k` (max-norm) past the arm's
projection on it, the projection's fraction :math:`s` never going back:

.. math::  a_k = q_s + \min\!\big(1,\ s + \ell_k / |q^* - q_s|_\infty\big)\,(q^* - q_s),
           \qquad e = \frac{\ell}{\ell_k}\,(q - a_k), \quad J = \frac{\ell}{\ell_k}\,I.

The lead, at first :math:`\ell`, follows what the arm does per tick, :math:`\ell_k =
\min(\ell, \max(\ell_{min}, 2\,|\Delta q_{k-1}|_\infty))`: mink's velocity limits clip each
joint's step, and an aim farther ahead than a step would be clipped into a diagonal off the
segment (the arm left a Panda's segment by 0.05 rad so, and came 6 mm nearer the table than
the way it was certified on). The scale :math:`\ell/\ell_k` keeps the task's weight that of the full lead
:math:`\ell`, so a ``FrameTask`` pulling straight to the target does not bend the way.

**A stall** (:class:`Patience`): an arm held short of where the error pulls it (a collision
or joint limit holds it) makes the optimiser choose afresh.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from ..exceptions import InvalidInput, UnreachableTarget
from ..redundancy.objective.segment_clearance import ALONG_TOLERANCE
from ..validation import as_vector

#: An arm held short of its aim (farther than :data:`NEAR` rad) whose joints move less than
#: :data:`STILL` rad per tick for this many ticks is stalled.
STALL_TICKS = 50
NEAR, STILL = 1e-3, 1e-4

#: Default leads of :class:`~om_redundant.ExactPoseTask`'s aims: of the hand on its straight
#: way (m, rad), and of the joints on a joint-space way (rad, max-norm).
DEFAULT_LEAD = (0.05, 0.25, 0.1)
#: rad (max-norm): how far ahead of the arm a joint-space way is re-checked against obstacles
#: that moved, about a quarter second of an arm at 2 rad/s. (Farther parts are re-checked as the
#: arm comes within it: tracking moves q* meanwhile, so they are not yet the arm's path.)
WAY_HORIZON = 0.5
#: rad: the smallest lead on a joint-space way (an arm standing still), so the task's weight
#: grows at most by the joint lead over this.
MIN_WAY_LEAD = 1e-3
#: The most joint vectors one tick samples to re-check a way's rest against moved obstacles
#: (:meth:`~om_redundant.Clearance.minimum_along`): a way whose clearance
#: nears its floor needs thousands to decide, ~10 us each, past a 2 ms tick.
WAY_CHECK_SAMPLES = 128


def pose_gap(A: np.ndarray, B: np.ndarray) -> tuple[float, float]:
    """Position (m) and rotation angle (rad) between two poses."""
    cos = (np.trace(A[:3, :3].T @ B[:3, :3]) - 1.0) / 2.0
    return float(np.linalg.norm(B[:3, 3] - A[:3, 3])), math.acos(min(1.0, max(-1.0, cos)))


def lead_pose(hand: np.ndarray, target: np.ndarray, lead: tuple[float, ...]) -> np.ndarray:
    """The aim (module docstring): ``target`` itself (the same object) when it lies within
    the lead of the hand, else the pose a fraction s of the way there."""
    distance, angle = pose_gap(hand, target)
    s = min(1.0, lead[0] / distance if distance > 0.0 else 1.0, lead[1] / angle if angle > 0.0 else 1.0)
    if s >= 1.0:
        return target
    aim = np.eye(4)
    aim[:3, :3] = hand[:3, :3] @ _turned(hand[:3, :3].T @ target[:3, :3], angle, s)
    aim[:3, 3] = hand[:3, 3] + s * (target[:3, 3] - hand[:3, 3])
    return aim


def _turned(R: np.ndarray, angle: float, s: float) -> np.ndarray:
    """The rotation by s times the angle of R about R's axis (Rodrigues' formula)."""
    if angle == 0.0:
        return np.eye(3)
    if angle < math.pi - 1e-6:
        axis = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]) / (2.0 * math.sin(angle))
    else:  # a half turn: the axis from R + I, whose columns are multiples of it
        column = R + np.eye(3)
        axis = column[:, int(np.argmax(np.linalg.norm(column, axis=0)))]
    axis = axis / np.linalg.norm(axis)
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    t = s * angle
    return np.eye(3) + math.sin(t) * K + (1.0 - math.cos(t)) * (K @ K)


def as_lead(lead: Any) -> tuple[float, float, float]:
    """The leads (m, rad, rad), each positive, or InvalidInput."""
    distance, angle, joints = as_vector(lead, 3, "lead").tolist()
    if not (distance > 0.0 and angle > 0.0 and joints > 0.0):
        raise InvalidInput(f"lead must be (metres, radians, radians), all positive, got {lead!r}")
    return distance, angle, joints


def next_aim(
    hand: np.ndarray, target: np.ndarray, aim: np.ndarray | None, lead: tuple[float, ...]
) -> np.ndarray:
    """The aim on the hand's way: the first a lead ahead of the hand; the next a lead further
    along from the last once the hand is as near the target as that aim is, give or take half
    the lead (the FrameTask pulls the hand past the aim, towards the target, so the hand need
    not meet the aim itself); meanwhile the last."""
    if aim is None:
        return lead_pose(hand, target, lead)
    (hand_distance, hand_angle), (aim_distance, aim_angle) = pose_gap(hand, target), pose_gap(aim, target)
    if hand_distance <= aim_distance + 0.5 * lead[0] and hand_angle <= aim_angle + 0.5 * lead[1]:
        return lead_pose(aim, target, lead)
    return aim


@dataclass
class JointWay:
    """A joint-space way from ``start`` to q* (module docstring).

    Attributes:
        start: Where the arm was when the choice was made.
        floor: The clearance the way's rest keeps (m): the optimiser's ``min_clearance``, or
            the clearance at ``start`` where that was less, less the certificate's
            tolerance (what the optimiser certified the way above); below it, by more than
            that tolerance again (a re-check's bound), the way is blocked.
            -inf where there is nothing to keep (no obstacles, or a way the optimiser could
            not find clear: it is not re-checked).
        s: The fraction of the way the arm has come (its projection's, never going back).
        lead: The aim's current lead past the arm (rad, max-norm): at first the full lead (a
            first step clipped off the way is one tick's), then from the arm's steps.
        checked: The clearance's version the way's rest was last checked against.
    """

    start: np.ndarray
    floor: float = -math.inf
    s: float = 0.0
    lead: float = DEFAULT_LEAD[2]
    checked: int = -1
    _last: np.ndarray | None = None

    def follow(self, q: np.ndarray, q_target: np.ndarray, max_lead: float) -> None:
        """Take in the arm at q (once per tick: a q seen last changes nothing): the lead from
        its last step, the fraction from its projection on the way."""
        if self._last is not None and np.array_equal(q, self._last):
            return
        if self._last is not None:
            step = float(np.abs(q - self._last).max())
            self.lead = min(max_lead, max(MIN_WAY_LEAD, 2.0 * step))
        self._last = q.copy()
        delta = q_target - self.start
        length = float(delta @ delta)
        if length > 0.0:
            self.s = max(self.s, min(1.0, float((q - self.start) @ delta) / length))

    def ahead(self, q_target: np.ndarray, horizon: float) -> tuple[np.ndarray, np.ndarray]:
        """The part of the way's rest within ``horizon`` (rad, max-norm) of the arm's
        projection on it: its first and last points."""
        here = self.start + self.s * (q_target - self.start)
        span = float(np.abs(q_target - here).max())
        return here, (q_target if span <= horizon else here + (horizon / span) * (q_target - here))

    def aim(self, q_target: np.ndarray) -> np.ndarray:
        """The point of the way the lead past the arm's fraction (q_target itself at the end)."""
        delta = q_target - self.start
        span = float(np.abs(delta).max())
        if span == 0.0 or self.s + self.lead / span >= 1.0:
            return q_target
        return self.start + (self.s + self.lead / span) * delta

    def blocked(self, clearance: Any, q_target: np.ndarray) -> bool:
        """Whether obstacles that moved since the way was last checked now block its rest
        ahead (from the arm's projection on it, which the optimiser certified, the arm's own
        deviation its margin's, to :data:`WAY_HORIZON` further): below the way's floor by more
        than the certificate's tolerance (the arm's own way, certified above the floor to that
        tolerance, never blocks itself: a way chosen afresh from each near miss would sink by
        the tolerance each time). ``clearance``: the optimiser's live
        :class:`~om_redundant.Clearance`."""
        if self.floor == -math.inf or clearance.version == self.checked:
            return False  # (no floor: no obstacles, or a way the optimiser could not find clear)
        self.checked = clearance.version
        q, q_ahead = self.ahead(q_target, WAY_HORIZON)
        floor = self.floor - ALONG_TOLERANCE
        # (undecided within the samples, NaN: kept; the obstacle that nears the way is sampled
        # below its floor in a later tick, or moves off)
        return clearance.minimum_along(q, q_ahead, floor, WAY_CHECK_SAMPLES) < floor

    def weight(self, max_lead: float) -> float:
        """The error's scale, the full lead over the current one."""
        return max_lead / self.lead


class Patience:
    """Counts the ticks an arm stands still short of its aim (module docstring); each stall
    doubles the patience, arriving resets it."""

    def __init__(self) -> None:
        self.stalled, self.patience = 0, STALL_TICKS
        self._last: np.ndarray | None = None

    def reset(self) -> None:
        self.stalled, self.patience = 0, STALL_TICKS

    def run_out(self, q: np.ndarray, gap: float) -> bool:
        """Whether the arm at q, ``gap`` (rad, max-norm) short of its aim, has stood still
        for as many ticks as the patience (one call per tick)."""
        still = self._last is not None and float(np.abs(q - self._last).max()) < STILL
        self._last = q
        if gap <= NEAR:
            self.reset()
        self.stalled = self.stalled + 1 if still and gap > NEAR else 0
        if self.stalled < self.patience:
            return False
        self.stalled, self.patience = 0, 2 * self.patience
        return True


class LeadsToJumpedTargets:
    """:class:`~om_redundant.ExactPoseTask`'s approach to a target that jumped: an aim that
    leads the hand along its straight way while tracking can follow it, else the optimiser's
    fresh choice reached along a joint-space way. (The task's own state: ``optimizer``,
    ``lead``, ``free``, ``choice``, ``root``, ``joints`` and the world last seen.)"""

    def _aim_for(self, T_world: np.ndarray, data: mujoco.MjData) -> np.ndarray:
        """The aim while leading (:func:`~om_redundant.tasks.approach.next_aim`)."""
        return next_aim(self.root.frame_pose(data), T_world, self._aim, self.lead)

    def _leads(self) -> bool:
        """Whether the task aims a lead ahead of the hand: after a jump of the target (with an
        optimiser and a lead), until the hand is near it or the lead's way is blocked."""
        return self._leading and self._data is not None

    def _jumped(self, T_world: np.ndarray) -> bool:
        """Whether a new target lies farther than the lead from the last one (or there is none),
        with an optimiser, a lead and the hand seen: then the aim leads the hand, and the
        target is chosen at once (:meth:`_jump`)."""
        if self.optimizer is None or self.lead is None or self._data is None:
            return False
        if self.transform_target_to_world is None:
            return True
        distance, angle = pose_gap(self._target_matrix(), T_world)
        return distance > self.lead[0] or (self.free is None and angle > self.lead[1])

    def _jump(self, T_world: np.ndarray, root_pose: np.ndarray) -> None:
        """A target that jumped. Where tracking can follow the hand's straight way there, a
        lead at a time (:meth:`_tracks_to`: then the target is reachable), the task leads the
        hand (:meth:`_aim_for`); else the optimiser's fresh choice there from the arm's joints
        is the target (UnreachableTarget if it has none), the arm going there in joint space."""
        self._patience.reset()
        if self.choice is not None and self.free is None and self._tracks_to(T_world, root_pose):
            self._leading, self._aim, self._way = True, None, None  # the first aim: a lead from the hand
            self._solve(T_world, root_pose, self._q_target, None)
            return
        q_current = self.joints.q(self._data.qpos)
        choice = self.optimizer.choose(
            self.root.in_root(T_world, root_pose), q_current=q_current, free=self.free
        )
        self._take(choice, root_pose, fresh=True)
        self._aim, self._leading = T_world, False

    def _tracks_to(self, T_world: np.ndarray, root_pose: np.ndarray) -> bool:
        """Whether the optimiser tracks from its last choice to the target along the hand's
        straight way there, a lead at a time (the aims :meth:`_aim_for` will take, the arm
        taken to follow each), without choosing afresh or losing a clear way."""
        previous, aim = self.choice, self.root.frame_pose(self._data)
        while aim is not T_world:
            aim = lead_pose(aim, T_world, self.lead)
            q = previous.solution.q
            previous = self.optimizer.choose(
                self.root.in_root(aim, root_pose), previous=previous, q_current=q, rechoose=False
            )
            if not (previous.ok and previous.way_clear):  # (not ok: tracking stopped)
                return False
        return True

    def _take(self, choice: Any, root_pose: np.ndarray, fresh: bool = False) -> None:
        """Take the optimiser's choice (UnreachableTarget if it is none within the limits); one
        made afresh from the arm's joints (``fresh``, or re-chosen where tracking stopped) is
        reached along a joint-space way (:meth:`_pull_to`)."""
        if not choice.ok:
            raise UnreachableTarget(
                f"ExactPoseTask: the optimizer found no configuration for the target: {choice.reason}"
            )
        q = np.asarray(choice.solution.q, dtype=np.float64)
        if not (choice.solution.ok and self.joints.within_limits(q)):
            raise UnreachableTarget(
                f"ExactPoseTask: the optimizer's solution {np.round(q, 4).tolist()} "
                f"({choice.solution.status}) does not reach the target within the joint limits"
            )
        self._q_target, self.choice, self._root_pose = q, choice, root_pose
        if self._clearance is not None:
            self._seen = self._clearance.version
        if (fresh or choice.rechosen) and self._data is not None and self.lead is not None:
            # q* jumped: a joint-space way there (no lead: q* at once)
            start = self.joints.q(self._data.qpos)
            floor = -np.inf  # (a way the optimiser could not find clear is not re-checked: it
            # would be "blocked" by what it already passes, and chosen again, tick after tick)
            if self._clearance is not None and choice.way_clear:
                floor = min(self.optimizer.min_clearance, self._clearance.minimum(start)) - ALONG_TOLERANCE
            self._way = JointWay(start, floor, lead=self.lead[2])
