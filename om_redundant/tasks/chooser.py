"""What :class:`~om_redundant.ExactPoseTask` needs of a redundancy optimiser."""

from __future__ import annotations

import warnings
from typing import Any, Protocol

import mujoco
import numpy as np


class Chooser(Protocol):
    """What :class:`ExactPoseTask` needs of a redundancy optimiser (duck-typed, as
    :class:`~om_redundant.RedundancyOptimizer`).

    ``choose(T, previous, q_current=q, free=f, rechoose=r)`` takes a pose in the arm's root
    frame, the previous choice (or None), the arm's joints now (or None), a free rotation (or
    None) and whether to choose afresh where tracking from ``previous`` stops (else a choice
    that is not ok), and returns an object with ``ok``
    (bool), ``solution`` (an om :class:`~om_redundant.Solution`), ``configuration`` (its
    :class:`~om_redundant.Configuration`), ``reason`` (str, why when not ok), ``rechosen``
    (bool: chosen afresh where tracking could not continue) and ``way_clear`` (bool: the
    joint-space way from ``q_current`` is clear), as a
    :class:`~om_redundant.RedundancyChoice` has them. ``clearance`` is its
    :class:`~om_redundant.Clearance` or None, ``min_clearance`` what its choices keep (m).
    """

    clearance: Any
    min_clearance: float

    def choose(
        self,
        T: np.ndarray,
        previous: Any = None,
        *,
        q_current: Any = None,
        free: Any = None,
        rechoose: bool = True,
    ) -> Any: ...


def live_clearance(optimizer: Chooser | None, model: mujoco.MjModel, root: Any) -> Any:
    """The optimiser's clearance where a task on ``model`` (its arm's root ``root``, an
    :class:`~om_redundant.ArmRoot`) reads its obstacles from the model (the clearance is of
    this model), else None (warning where the root moves)."""
    clearance = getattr(optimizer, "clearance", None)
    if clearance is None or clearance.model is model:
        return clearance
    if root.fixed_pose is None:
        warnings.warn(
            "ExactPoseTask: the optimizer's obstacles are not in this task's model, so they stay in "
            "the arm's root frame and move with its root; for obstacles that stay in the world, build "
            "the optimizer's Clearance on this model",
            stacklevel=3,
        )
    return None
