"""Many targets at once: the batch entry points of :class:`~om_redundant.ik.solver.OMSolver`
(:class:`BatchSolves`) and the records they return, one row per target."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _core
from ..exceptions import InvalidInput
from ..kinematics import Arm
from ..validation import as_count, as_joint_vector, as_poses, as_redundancy, as_signs
from .threads import BATCH_CHUNK, run_rows

#: Most worker threads ``solve_batch`` accepts (it uses at most one per core).
MAX_THREADS = 1024


@dataclass(frozen=True, eq=False, slots=True)
class BatchSolution:
    """Outcomes of :meth:`~om_redundant.OMSolver.solve_batch`, one row per target.

    Attributes:
        q: (M, dof) joint vectors (NaN rows where no solution).
        ok: (M,) bool.
        status_code: (M,) int; :attr:`status` gives the names.
        position_error: (M,) metres.
        orientation_error: (M,) radians.
        iterations: (M,) residual evaluations.
        within_limits: (M,) bool.
    """

    q: np.ndarray
    ok: np.ndarray
    status_code: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray
    iterations: np.ndarray
    within_limits: np.ndarray

    @property
    def status(self) -> list[str]:
        return [_core.STATUS_NAMES[c] for c in self.status_code]


@dataclass(frozen=True, eq=False, slots=True)
class BatchRoots:
    """Outcomes of :meth:`~om_redundant.OMSolver.solve_all_batch`: every solution of each row's
    configuration, as :meth:`~om_redundant.OMSolver.solve_all` finds them.

    Attributes:
        q: (M, MAX_ROOTS, dof): row i's solutions are ``q[i, :count[i]]``, in solve_all's
            order (NaN beyond).
        count: (M,) how many (0: none).
        position_error: (M, MAX_ROOTS) metres.
        orientation_error: (M, MAX_ROOTS) radians.
        iterations: (M,) residual evaluations.
        within_limits: (M, MAX_ROOTS) bool.
    """

    q: np.ndarray
    count: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray
    iterations: np.ndarray
    within_limits: np.ndarray


class BatchSolves:
    """The batch entry points of :class:`~om_redundant.ik.solver.OMSolver`: its solves of many
    targets at once, in parallel on the compiled kernel, row by row."""

    arm: Arm
    kernel: _core.Solver
    sign_names: tuple[str, ...]
    redundancy_names: tuple[str, ...]

    def solve_batch(
        self,
        T: Any,
        signs: Any,
        redundancy: Any = None,
        q_hint: Any = None,
        threads: int | None = None,
    ) -> BatchSolution:
        """Solve many targets at once, in parallel.

        Args:
            T: (M, 4, 4) target poses, or a sequence of M (4, 4) poses or ``mink.SE3``.
            signs: (M, k) branch signs, or (k,) for the same configuration everywhere.
            redundancy: Redundancy values (M, r) or (r,) (a 7-DOF arm's arm angle psi, r = 1;
                then also (M,) or one number); None for 6-DOF arms.
            q_hint: Optional (M, dof) hints.
            threads: Worker threads, 1 to :data:`MAX_THREADS` (at most one per core is
                used); None: one per core. 1 solves every row on the calling thread. The
                answers do not depend on it.

        Returns:
            A :class:`BatchSolution` with M rows.

        Raises:
            InvalidInput: A malformed argument, or one whose rows do not match the M poses.
        """
        T, signs, redundancy, threads = self._batch_rows(T, signs, redundancy, threads)
        m = len(T)
        hints = None
        if q_hint is not None:
            hints = as_joint_vector(q_hint, self.arm.dof, "q_hint").reshape(-1, self.arm.dof)
            if len(hints) != m:
                raise InvalidInput(f"q_hint must have {m} rows, got {len(hints)}")
        batch = _core.SolveBatch(
            T,
            signs,
            redundancy,
            hints,
            q=np.empty((m, self.arm.dof)),
            status=np.empty(m, dtype=np.int64),
            position_error=np.empty(m),
            orientation_error=np.empty(m),
            evaluations=np.empty(m, dtype=np.int64),
            within_limits=np.empty(m, dtype=bool),
        )
        kernel = self.kernel

        def solve_range(start: int, stop: int) -> None:
            kernel.solve_rows(batch, start, stop)

        run_rows(solve_range, m, threads)
        return BatchSolution(
            batch.q,
            batch.status == _core.OK,
            batch.status,
            batch.position_error,
            batch.orientation_error,
            batch.evaluations,
            batch.within_limits,
        )

    def solve_all_batch(
        self, T: Any, signs: Any, redundancy: Any = None, threads: int | None = None
    ) -> BatchRoots:
        """:meth:`~om_redundant.OMSolver.solve_all` for many targets at once, in parallel.

        Args:
            T, signs, redundancy, threads: As :meth:`solve_batch` takes them (no hints).

        Returns:
            A :class:`BatchRoots` with M rows, each row's solutions those of
            ``solve_all(T[i], Configuration(signs[i], redundancy[i]))``. On an arm whose
            search covers the whole torus (shoulder offsets that do not contract: the Sawyer),
            the rows of one pose start from its traced self-motion (``csrc/ik/torus_trace.c``):
            the same roots within the joint limits, in their own order; beyond them, where the
            folded elbow puts the wrist centre on the shoulder, either may hold roots the
            other lacks. A row's answer never depends on the other rows.

        Raises:
            InvalidInput: A malformed argument, or one whose rows do not match the M poses.
        """
        return self.solve_grid(T, signs, redundancy, None, threads)

    def solve_grid(
        self,
        T: Any,
        signs: Any,
        redundancy: Any,
        band: np.ndarray | None,
        threads: int | None = None,
        chunk: int = BATCH_CHUNK,
        traces: object | None = None,
    ) -> BatchRoots:
        """:meth:`solve_all_batch`, where a row whose ``band`` is False returns its
        configuration's own roots (the bounded search's) and nothing else: where it has none,
        it is not searched further for the roots that :meth:`~om_redundant.OMSolver.solve_all`
        adds then (those of the neighbouring configurations within
        :data:`~om_redundant.BRANCH_BAND` of the boundary, the singular boundary's touch points,
        the local solve from the fixed-point start). For a caller that solves each such row's
        neighbouring configurations too, as the redundancy optimiser's sweep does.

        Args:
            T, signs, redundancy, threads: As :meth:`solve_all_batch` takes them.
            band: (M,) bool, or None: every row searches as :meth:`~om_redundant.OMSolver.solve_all` does.
            chunk: Rows a thread takes at a time. A thread's rows of one pose share its memos
                (the torus' terms and traced self-motion, one per ELBOW sign), so a caller whose
                rows come grouped by pose and ELBOW sign passes a group's size.
            traces: Where the rows keep the self-motion they traced (``_core.torus_traces``
                of this solver's kernel; each ELBOW sign's first, kept until the traces go),
                for the follows of a sweep after them; None: not kept.

        Returns:
            A :class:`BatchRoots` with M rows.

        Raises:
            InvalidInput: A malformed argument, or one whose rows do not match the M poses.
        """
        T, signs, redundancy, threads = self._batch_rows(T, signs, redundancy, threads)
        m, dof = len(T), self.arm.dof
        band = np.ones(m, dtype=bool) if band is None else np.ascontiguousarray(band, dtype=bool)
        if band.shape != (m,):
            raise InvalidInput(f"band must have one entry per row ({m}), got shape {band.shape}")
        n = _core.MAX_ROOTS
        batch = _core.SolveAllBatch(
            T,
            signs,
            redundancy,
            band,
            q=np.full((m, n, dof), np.nan),
            count=np.zeros(m, dtype=np.int64),
            evaluations=np.zeros(m, dtype=np.int64),
            position_error=np.full((m, n), np.nan),
            orientation_error=np.full((m, n), np.nan),
            within_limits=np.zeros((m, n), dtype=bool),
            traces=traces,
        )
        kernel = self.kernel

        def solve_range(start: int, stop: int) -> None:
            kernel.solve_all_rows(batch, start, stop)

        run_rows(solve_range, m, threads, chunk)
        return BatchRoots(
            batch.q,
            batch.count,
            batch.position_error,
            batch.orientation_error,
            batch.evaluations,
            batch.within_limits,
        )

    def _batch_rows(
        self, T: Any, signs: Any, redundancy: Any, threads: int | None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, int | None]:
        """A batch's poses (M, 4, 4), signs (M, k) and redundancy rows (M, r), and threads, checked."""
        T = as_poses(T)
        m = len(T)
        k = len(self.sign_names)
        signs = np.ascontiguousarray(np.broadcast_to(as_signs(signs, k, stack=True, rows=m), (m, k)))
        redundancy = self._redundancy_rows(redundancy, m)
        threads = None if threads is None else as_count(threads, "threads", 1, MAX_THREADS)
        return T, signs, redundancy, threads

    def _redundancy_rows(self, redundancy: Any, m: int) -> np.ndarray:
        """(M, r) redundancy values for a batch, checked: shape and finiteness, named."""
        names = self.redundancy_names
        if redundancy is None and names:
            raise InvalidInput(f"arm '{self.arm.name}' needs redundancy values {names}")
        return as_redundancy(redundancy, "redundancy", names, rows=m)
