r"""The clearance along a straight joint-space segment, certified by a Lipschitz bound
(:meth:`Clearance.minimum_along <om_redundant.Clearance.minimum_along>`)."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ... import _core
from .arm_geoms import ArmCores

#: m: :func:`segment_minimum` stops splitting a piece whose bound is this close to its ends'.
ALONG_TOLERANCE = 2e-4
#: Samples inside a segment that the first call has room for where their number is not bounded
#: (each call after doubles it; a budget gives the room at once).
_FIRST_ROOM = 256


def segment_minimum(
    cores: ArmCores,
    fill: Callable[[np.ndarray, np.ndarray, np.ndarray], None],
    q_from: np.ndarray,
    q_to: np.ndarray,
    lipschitz: float,
    floor: float,
    budget: float,
    reach: float,
) -> float:
    r"""The clearance along the segment from q_from to q_to as far as it matters against
    ``floor``: pieces of the segment whose bound :math:`(D_0 + D_1 - L h) / 2` is below
    ``floor`` are halved, a round at a time, until an end falls below it or a piece is within
    :data:`ALONG_TOLERANCE` of its ends (the returns of :meth:`Clearance.minimum_along
    <om_redundant.Clearance.minimum_along>`), in one ``_core.segment_minimum`` call
    (``csrc/redundancy/segment_clearance.c``; its oracle ``tests/reference/segment_clearance.py``),
    each round's distances in one ``_core.arm_clearance`` call.

    Args:
        cores: The clearance's arm and obstacles (:class:`~.arm_geoms.ArmCores`).
        fill: Fills the distances (M, pairs) of joint vectors (M, dof) that ``arm_clearance``
            left (nan) to MuJoCo, their nearest points (M, pairs, 6) with them:
            ``fill(q, dist, fromto)``.
        q_from, q_to: The segment's ends (dof,).
        lipschitz: L, the most any distance changes over the whole segment.
        floor: The clearance (m) it is checked against.
        budget: The most joint vectors sampled inside the segment (inf: no limit).
        reach: Distances are capped here (m).
    """
    dof, pairs = len(q_from), len(cores.pairs)
    check = _core.SegmentCheck(lipschitz, floor, budget, ALONG_TOLERANCE, reach)
    room = budget if math.isfinite(budget) else _FIRST_ROOM
    while True:  # (where the samples outgrow the room: the same rounds again, with twice the room)
        rows = 2 + int(room)
        segment = _core.Segment(
            q_from, q_to, np.empty((rows, dof)), np.empty((rows, pairs)), np.empty((rows, pairs, 6))
        )

        def filled(start: int, stop: int, segment: _core.Segment = segment) -> None:
            fill(segment.rows[start:stop], segment.dist[start:stop], segment.fromto[start:stop])

        found = _core.segment_minimum(cores, segment, check, filled)
        if found is not None:
            return found
        room *= 2
