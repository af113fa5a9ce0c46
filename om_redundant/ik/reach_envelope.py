r"""How far a pose lies beyond a 7-DOF (S-R-S) arm's reach, at every arm angle and branch at once.

The S-R-S model reaches a flange pose :math:`(R, p)` (DH frame 0) exactly where its elbow
reaches the wrist centre: with :math:`w = R\,W + p_m - S` (W the wrist centre in the flange
frame, S the shoulder centre), :math:`x = (|w|^2 - K_0)/K \in [-1, 1]`, whatever the arm angle
and the branch signs. The model's target :math:`p_m` moves with the offsets the OM method
zeroes, :math:`p_m = p + a(q_1) + R\,\delta(q_7)` (the torus; on a circle arm one of them is
constant, on a fixed one both), so the real arm reaches the pose only where some
:math:`(q_1, q_7)` puts :math:`|w|` within :math:`[r_{min}, r_{max}] = [\sqrt{K_0 - |K|},
\sqrt{K_0 + |K|}]`; an arm near a family reaches it through its correction, which moves the
wrist centre by at most the nominal arm's deviation (``near_deviation``, m within reach, to
first order: taken with 10 % to spare).

On an N x N grid of the torus, :math:`|w|` differs from its value at the nearest node by at
most :math:`(\|D_4\| + \|D_5\| + \|D_1\| + \|D_2\|)\,h/2` (the offsets' slopes, h the grid
step), so the least distance of the nodes' :math:`|w|` from the range, less that and the
deviation, is a proven margin: where it is positive no configuration and no arm angle
reaches the pose (:meth:`ReachEnvelope.beyond`), and the optimiser answers so without sweeping
the circle of arm angles (a "no" that costs a torus arm's sweep 0.1-3 s otherwise).
"""

from __future__ import annotations

import numpy as np

from .. import _core
from .kernel_data import flange_target
from .solver import OMSolver

GRID = 128  # nodes per side of the torus grid
COARSE = 16  # every COARSE-th node a side is looked at first (beyond)
_ROUNDING = 1e-9  # m: the margin's own rounding, with room
_SECOND_ORDER = 1.1  # the deviation is a first-order bound: 10 % to spare


class ReachEnvelope:
    """The reach of a 7-DOF S-R-S solver's arm, for :meth:`beyond` (module docstring).

    Args:
        solver: The arm's solver.
    """

    def __init__(self, solver: OMSolver):
        data = solver.solver_data()
        self._data = data
        self.applies = data.family == _core.SRS
        if not self.applies:
            return
        P = data.params
        self._wrist = P[_core.SRS_WRIST : _core.SRS_WRIST + 3].copy()
        self._shoulder = P[_core.SRS_SHOULDER : _core.SRS_SHOULDER + 3].copy()
        k0, k = float(P[_core.SRS_K0]), abs(float(P[_core.SRS_K]))
        self._r_min, self._r_max = np.sqrt(max(k0 - k, 0.0)), np.sqrt(k0 + k)
        D = np.asarray(data.dp_coefficients, dtype=float).reshape(6, 3)
        w = np.linspace(-np.pi, np.pi, GRID, endpoint=False)
        c, s = np.cos(w)[:, None], np.sin(w)[:, None]
        # a(q1) at the nodes (GRID, 3), frame 0, and delta(q7), flange frame (one node where constant)
        self._a = D[3] + D[4] * c + D[5] * s if D[4:].any() else D[3][None]
        self._delta = D[0] + D[1] * c + D[2] * s if D[1:3].any() else D[0][None]
        slopes = sum(float(np.linalg.norm(D[i])) for i in (1, 2, 4, 5))
        deviation = _SECOND_ORDER * float(data.near_deviation)
        #: m: what the grid's spacing and a near arm's correction can make up of a node's distance
        self.slack = slopes * (2.0 * np.pi / GRID) / 2.0 + deviation + _ROUNDING

    def beyond(self, T: np.ndarray) -> float | None:
        """How far (m) the pose T (root frame, 4 x 4) lies out of the arm's reach where that is
        proven: the wrist centre's least distance from the elbow's range over the torus's nodes,
        where it exceeds :attr:`slack` (module docstring); None where the arm may reach T (or
        the arm is not S-R-S)."""
        if not self.applies:
            return None
        R, p = flange_target(T, self._data.T_base_root, self._data.T_tool_flange)
        # One node within the slack settles it (the usual answer): on the torus (both offsets
        # turning, GRID x GRID nodes), every COARSE-th node a side first.
        torus = len(self._a) > 1 and len(self._delta) > 1
        if torus and not self.gap(R, p, COARSE) > self.slack:
            return None
        gap = self.gap(R, p)
        return gap if gap > self.slack else None

    def gap(self, R: np.ndarray, p: np.ndarray, every: int = 1) -> float:
        """The wrist centre's least distance (m) from the elbow's range over the torus's nodes
        (every ``every``-th node a side) for the flange pose (R, p) in DH frame 0."""
        a, delta = self._a[::every], self._delta[::every]
        w = (R @ self._wrist + p - self._shoulder) + a[:, None, :] + (delta @ R.T)[None, :, :]
        norms = np.sqrt(np.einsum("ijk,ijk->ij", w, w))
        return float(np.maximum(norms - self._r_max, self._r_min - norms).min())
