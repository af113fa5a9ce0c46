r"""Targets that leave a rotation free: a tool axis to point (any turn about it) or a position
to reach (any orientation).

The end-effector pose T may turn by rotations R about a pivot c of the end-effector frame,
about the free axes :math:`a_i` (in that frame):

.. math::  T(R) = T \, \begin{bmatrix} R & c - R c \\ 0 & 1 \end{bmatrix}, \qquad
           R = \exp\big([\textstyle\sum_i \theta_i a_i]_\times\big)\ \text{composed},

so the pivot stays where T puts it (a tool's tip on its target point) while the frame turns.
The optimiser picks the turn along with psi: a fresh choice tries :data:`TURNS` turns about
the first axis (the tool axis; for any orientation, the hand's current tool axis after
turning T to the hand's current orientation), and tracking tries a step of ``max_step`` rad
each way about every axis, keeping the best feasible.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..exceptions import InvalidInput
from ..validation import as_vector

#: Turns about the first free axis tried by a fresh choice.
TURNS = 8


@dataclass(frozen=True, eq=False)
class FreeRotation:
    """The rotations of the target left free (module docstring).

    Attributes:
        axes: (n, 3) unit axes in the end-effector frame, n = 1 (a tool axis) or 3 (any
            orientation: a position-only target).
        pivot: (3,) the point of the end-effector frame that the turns keep in place.
    """

    axes: Any
    pivot: Any = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        axes = np.atleast_2d(np.asarray(self.axes, dtype=float))
        if axes.shape not in ((1, 3), (3, 3)) or not np.isfinite(axes).all():
            raise InvalidInput(
                f"FreeRotation axes must be one axis or three, shape (1, 3) or (3, 3), got {axes.shape}"
            )
        norms = np.linalg.norm(axes, axis=1)
        if not (norms > 1e-9).all():
            raise InvalidInput("FreeRotation axes must not be zero")
        object.__setattr__(self, "axes", axes / norms[:, None])
        object.__setattr__(self, "pivot", as_vector(self.pivot, 3, "FreeRotation pivot"))

    @classmethod
    def tool_axis(cls, axis: Any = (0.0, 0.0, 1.0), pivot: Any = (0.0, 0.0, 0.0)) -> FreeRotation:
        """Any turn about one axis of the end-effector frame (default its z, the tool axis)."""
        return cls([axis], pivot)

    @classmethod
    def orientation(cls, pivot: Any = (0.0, 0.0, 0.0)) -> FreeRotation:
        """Any orientation: the target is the pivot's position only (the tool axis z first)."""
        return cls([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], pivot)

    @classmethod
    def of_frame(cls, kind: str, tool: np.ndarray) -> FreeRotation:
        """``"tool_axis"`` or ``"orientation"`` for a frame E at pose ``tool`` (X) in the
        end-effector frame: turns about E's z axis, or any, about E's origin.

        Raises:
            InvalidInput: Another kind.
        """
        R, pivot = tool[:3, :3], tool[:3, 3]
        if kind == "tool_axis":
            return cls.tool_axis(R[:, 2], pivot)
        if kind == "orientation":
            return cls(R[:, [2, 0, 1]].T, pivot)
        raise InvalidInput(f"a free rotation is 'tool_axis' or 'orientation', got {kind!r}")

    def turned(self, T: np.ndarray, R: np.ndarray) -> np.ndarray:
        """T(R): the pose T turned by R about the pivot (module docstring)."""
        turn = np.eye(4)
        turn[:3, :3], turn[:3, 3] = R, self.pivot - R @ self.pivot
        return T @ turn

    def trials(self, R: np.ndarray, step: float) -> list[np.ndarray]:
        """R turned by +-step about each free axis (in the turned frame)."""
        return [R @ rotation(axis, sign * step) for axis in self.axes for sign in (-1.0, 1.0)]

    def starts(self, T: np.ndarray, hand: np.ndarray | None) -> list[np.ndarray]:
        """The turns a fresh choice tries: :data:`TURNS` about the first axis, from no turn
        (for any orientation: from the turn that gives T the hand's orientation, ``hand``
        the hand's pose or None)."""
        R0 = np.eye(3)
        if len(self.axes) == 3 and hand is not None:
            R0 = T[:3, :3].T @ hand[:3, :3]
        return [R0 @ rotation(self.axes[0], 2.0 * math.pi * k / TURNS) for k in range(TURNS)]


def rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """The rotation by angle about the unit axis (Rodrigues' formula)."""
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * (K @ K)
