r"""What climbs from the samples of the feasible runs can reach: the bounds by which the global
choice skips starts that cannot beat the best found (the module docstring of
:mod:`.optimizer`, Starts)."""

from __future__ import annotations

import numpy as np

from ... import _core

#: A start whose bound is within this of the best found is not climbed (it can at most tie).
CLIMB_ROUNDING = 1e-12


class StartBounds:
    r"""Bounds of what climbs from the samples of runs can reach (module docstring, Starts):
    f within a reach R of a start, a function u of slope bound L being below the cones
    :math:`u_i + L |x - \psi_i|` of the samples of its run.

    Args:
        psi, f: (M,) the runs' samples, a run's in increasing psi, and f there.
        terms: :meth:`~om_redundant.redundancy.objective.objective.Objective.term_functions` at them.
        first, last: (M,) each sample's run's first and last sample.
        slope, slopes: L of f and of each group's functions (p_g,) on every run; None:
            sampled, on each run the largest slope between its neighbouring samples (a climb
            stays within its run: module docstring).
    """

    def __init__(
        self,
        psi: np.ndarray,
        f: np.ndarray,
        terms: list[tuple[float, float, np.ndarray]],
        first: np.ndarray,
        last: np.ndarray,
        slope: float | None = None,
        slopes: list[np.ndarray] | None = None,
    ):
        # f and every group's functions as the columns of one array, their slope bounds L
        self.psi, self.first, self.last = psi, first, last
        self._values = np.ascontiguousarray(
            np.hstack([f[:, None]] + [v for _, _, v in terms])
        )  # (row by row)
        shape = self._values.shape
        if slope is None:  # (per run, by its first sample; each sample then takes its run's)
            inner = first[1:] == first[:-1]  # neighbours on one run
            step = np.maximum(np.diff(psi), 1e-12)[inner]
            rise = np.abs(np.diff(self._values, axis=0)[inner])
            largest = np.zeros(shape)
            np.maximum.at(largest, first[1:][inner], rise / step[:, None])
            self._slopes = np.ascontiguousarray(largest[first])
        else:
            self._slopes = np.ascontiguousarray(np.broadcast_to(np.concatenate([[slope], *slopes]), shape))
        # each group's first column
        self._groups = np.cumsum([1] + [v.shape[1] for _, _, v in terms[:-1]], dtype=np.int64)[: len(terms)]
        self._weights = np.array([w for w, _, _ in terms])
        self._caps = np.array([cap for _, cap, _ in terms])
        self._samples = _core.StartSamples(
            self.psi, self._values, self._slopes, self._groups, self._weights, self._caps
        )

    def cone(self, k: np.ndarray, reach: np.ndarray) -> np.ndarray:
        r"""(K,) the bounds from the starts' own cones: the smaller of :math:`f_k + L R` and
        :math:`\sum_g w_g \min(cap_g, \min_j (v_{jk} + L_j R))`, the groups summed in their
        order (``_core.start_cones``, ``csrc/redundancy/start_bounds.c``; its numpy oracle is
        ``tests/reference/start_bounds.py``)."""
        bounds, reach = np.empty(len(k)), np.ascontiguousarray(reach, dtype=float)
        _core.start_cones(self._samples, np.ascontiguousarray(k, dtype=np.int64), reach, bounds)
        return bounds

    def within(self, k: int, reach: float) -> float:
        r"""The bound of start k from every sample of its run within its reach R (never
        above :meth:`cone`'s for consistent slopes). Between neighbouring samples i, i + 1
        (h apart) the cones of the two meet at most at :math:`(u_i + u_{i+1} + L h)/2`; in
        a cell that R cuts, or beyond the run's end, the last sample's cone reaches
        :math:`u_i + L r` (r the reach left). Per cell or cut cell the smaller of f's bound
        and the terms' (:meth:`cone`'s sum), the largest over the cells; at least f_k
        (``_core.start_bound``, ``csrc/redundancy/start_bounds.c``; its numpy oracle is
        ``tests/reference/start_bounds.py``).

        Args:
            k: The start's sample.
            reach: R >= 0.
        """
        return _core.start_bound(self._samples, int(k), int(self.first[k]), int(self.last[k]), reach)
