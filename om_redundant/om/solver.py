"""The OM solver: exact inverse kinematics of a real arm in a chosen configuration."""

from __future__ import annotations

import os
import weakref
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _core
from ..exceptions import InvalidInput, ModelError
from ..kinematics import Arm, load_arm
from ..validation import (
    as_count,
    as_instance,
    as_joint_vector,
    as_pose,
    as_poses,
    as_positive,
    as_redundancy,
    as_signs,
)
from . import system
from .configuration import Configuration
from .kernel_data import kernel_data
from .model import ModelArm
from .nominal import NominalArm, closed_form

DEFAULT_POSITION_TOLERANCE = 1e-10
DEFAULT_ORIENTATION_TOLERANCE = 1e-10
DEFAULT_SCAN_POINTS = 64
#: ``|branch quantity|`` within which a joint vector belongs to both neighbouring configurations
#: (the singular boundary's band; see :meth:`OMSolver.holds`).
BRANCH_BAND: float = _core.BRANCH_BAND
#: Seeded random joint vectors within the limits whose poses a new solver must solve.
SELF_CHECK_SAMPLES = 12

# Arms (by instance) that passed the self-check, with the (tolerances, scan points) it used.
_SELF_CHECKED: weakref.WeakKeyDictionary[Arm, set[tuple]] = weakref.WeakKeyDictionary()

#: Bounds of ``scan_points``. The bounded search of an arm whose dp turns with two joints
#: (the Gen3's torus) costs the square of it: one ``solve_all`` takes 0.7 s at 1024 points
#: (11 s at 4096), 6 ms at the default 64.
MIN_SCAN_POINTS, MAX_SCAN_POINTS = _core.MIN_SCAN_POINTS, _core.MAX_SCAN_POINTS
#: Most worker threads ``solve_batch`` accepts (it uses at most one per core).
MAX_THREADS = 1024


@dataclass(frozen=True, eq=False, slots=True)
class Solution:
    """The outcome of one solve.

    Attributes:
        q: Joint vector of the REAL arm (NaN when no solution). Revolute joints are
            shifted by multiples of 2 pi into the limits, nearest to the hint.
        ok: True only if the real arm reaches the pose within tolerance in the requested
            configuration (as :meth:`OMSolver.holds` reads it: within the branch band, both).
        status: ``"ok"``, ``"unreachable"`` (no configuration reaches the pose) or
            ``"no solution in this configuration"``.
        configuration: The configuration asked for.
        position_error: ``|p_real(q) - p_d|`` in metres.
        orientation_error: Angle of R_d^T R_real(q) in radians.
        iterations: Residual evaluations spent.
        within_limits: Whether q is within the joint limits.
    """

    q: np.ndarray
    ok: bool
    status: str
    configuration: Configuration
    position_error: float
    orientation_error: float
    iterations: int
    within_limits: bool


@dataclass(frozen=True, eq=False, slots=True)
class BatchSolution:
    """Outcomes of :meth:`OMSolver.solve_batch`, one row per target.

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
        return [system.STATUS_NAMES[c] for c in self.status_code]


@dataclass(frozen=True, eq=False, slots=True)
class BatchRoots:
    """Outcomes of :meth:`OMSolver.solve_all_batch`: every solution of each row's
    configuration, as :meth:`OMSolver.solve_all` finds them.

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


class OMSolver:
    """Exact IK of a real arm by the offset modification method.

    Args:
        arm: An :class:`Arm`, the name of a built-in arm or the path of an arm file.
        position_tolerance: Largest accepted position error (m), a positive number.
        orientation_tolerance: Largest accepted orientation error (rad), a positive number.
        scan_points: Grid points of the bounded search over the dp circle, a whole number
            from :data:`MIN_SCAN_POINTS` (8) to :data:`MAX_SCAN_POINTS` (1024).

    Raises:
        InvalidInput: An argument of the wrong type or out of range (named).
        UnknownArm, ArmFileError: The arm cannot be loaded.
        ModelError: The arm has no closed-form model (:func:`~.model.derive_model` names the
            condition), or it fails to solve its own pose ``arm.fk(q)`` in the configuration
            of q at one of ``SELF_CHECK_SAMPLES`` seeded random joint vectors within the limits
            (the message names q and the status). An accepted arm's "unreachable" means
            unreachable. The check takes about a millisecond and is done once per
            :class:`Arm` instance and tolerances.

    Example::

        solver = om.OMSolver("ur5e")
        sol = solver.solve(T_base_target, om.Configuration((1, -1, 1)))
        if sol.ok:
            print(sol.q)
    """

    def __init__(
        self,
        arm: Arm | str,
        *,
        position_tolerance: float = DEFAULT_POSITION_TOLERANCE,
        orientation_tolerance: float = DEFAULT_ORIENTATION_TOLERANCE,
        scan_points: int = DEFAULT_SCAN_POINTS,
    ):
        if not isinstance(arm, str | os.PathLike):
            as_instance(arm, Arm, "arm", "an om.Arm, an arm name or the path of an arm file")
        self.arm: Arm = arm if isinstance(arm, Arm) else load_arm(arm)
        self.tolerances = (
            as_positive(position_tolerance, "position_tolerance"),
            as_positive(orientation_tolerance, "orientation_tolerance"),
        )
        self.scan_points = as_count(scan_points, "scan_points", MIN_SCAN_POINTS, MAX_SCAN_POINTS)
        self.om: ModelArm
        #: The nominal arm the model is derived from, for an arm NEAR a family; else None.
        self.nominal: NominalArm | None
        self.om, self.nominal = closed_form(self.arm)
        self._flip = np.ones(self.arm.dof) if self.nominal is None else self.nominal.flip
        types = {"solution_type": Solution, "configuration_type": Configuration}
        self._kernel = _core.Solver(self.solver_data(), **types)
        self._check_solves_itself()

    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]:
        """Pickled as its arm and options (the compiled kernel is rebuilt): for spawned
        workers, Dask, Ray."""
        position, orientation = self.tolerances
        return (_rebuilt, (self.arm, position, orientation, self.scan_points))

    def solver_data(self) -> system.SolverData:
        """The fixed data of the compiled kernel (see :class:`~om_redundant.om.system.SolverData`):
        of the arm, or, for an arm near a family (:attr:`nominal`), of its nominal arm's model with
        the arm's exact chain (``csrc/near.c``)."""
        return kernel_data(self.om, self.tolerances, self.scan_points, self.nominal)

    @property
    def kernel(self) -> _core.Solver:
        """The compiled solver, for kernels that solve with it (``_core.track_step``)."""
        return self._kernel

    @property
    def model(self) -> Arm:
        """The offset-modified model arm (of the nominal arm for an arm near a family, in the
        model's joint coordinates ``flip * q``)."""
        return self.om.model

    @property
    def flip(self) -> np.ndarray:
        """The (dof,) signs (+-1) that give the model's joint coordinates ``flip * q`` (-1 where
        an arm near a family has a reversed axis, see :mod:`~om_redundant.om.nominal`)."""
        return self._flip

    @property
    def dp_max(self) -> float:
        """Radius of the ball that holds every solution p_m of system (9), in metres."""
        return self.om.dp_max

    @property
    def sign_names(self) -> tuple[str, ...]:
        """Names of the configuration's branch signs, e.g. ``("SHOULDER", "ELBOW", "WRIST")``."""
        return self.om.sign_names

    @property
    def redundancy_names(self) -> tuple[str, ...]:
        """Names of the configuration's redundancy values (``("psi",)`` for 7-DOF arms)."""
        return self.om.redundancy_names

    def configurations(self, redundancy: Any = ()) -> list[Configuration]:
        """Every branch-sign combination this arm's model distinguishes, with the given
        redundancy values (a 7-DOF arm's arm angle; default 0; as :class:`Configuration` takes them)."""
        redundancy = tuple(as_redundancy(redundancy).tolist()) or (0.0,) * len(self.redundancy_names)
        return [Configuration(c.signs, redundancy) for c in Configuration.all_signs(len(self.sign_names))]

    def configuration_of(self, q: np.ndarray) -> Configuration:
        """The configuration of joint vector q: the model's branch signs and arm angle at q.

        A branch quantity that is exactly zero (a singular joint) counts as +1.
        """
        q = as_joint_vector(q, self.arm.dof, stack=False)
        values = np.empty(len(self.sign_names))
        redundancy = np.empty(len(self.redundancy_names))
        self._kernel.configuration_values(q, values, redundancy)
        return Configuration(tuple(-1 if v < 0.0 else 1 for v in values.tolist()), tuple(redundancy.tolist()))

    def holds(self, q: np.ndarray, configuration: Configuration) -> bool:
        """Whether joint vector q is in the configuration, by the boundary contract.

        Each branch quantity ``b_i(q)`` (the values whose signs :meth:`configuration_of` reads)
        must have the requested sign ``s_i``, or lie in the band ``|b_i(q)|`` <= :data:`BRANCH_BAND`,
        where q belongs to both neighbouring configurations: ``s_i b_i(q) >= 0`` or
        ``|b_i(q)| <= 1e-7``. A 7-DOF arm's arm angle psi(q) must equal the requested one within
        1e-9 rad modulo 2 pi, or within its own rounding at q, ``|d psi / dq|_1 2^-51`` (psi's
        change when each joint moves by an ulp of pi: larger than 1e-9 only within about
        1e-7 rad of psi's singular half-line, the wrist centre straight below the shoulder,
        where ``|d psi / dq|`` grows as 1 / rho, and where the model's wrist centre is at its
        shoulder, where it grows as ``1 / |W - S|``: the folded elbow of a model with equal upper
        arm and forearm, the Sawyer's at q4 = +-pi, beyond its limits), psi read in the
        requested ELBOW branch (the
        elbow plane's normal flips with the branch, so at a straight elbow psi is the
        requested branch's).
        Every ``ok`` answer of :meth:`solve`, :meth:`solve_all` and :meth:`solve_batch`
        holds its configuration.

        Raises:
            InvalidInput: q is malformed, or the configuration does not fit this arm.
        """
        q = as_joint_vector(q, self.arm.dof, stack=False)
        self.check_configuration(configuration)
        return self._kernel.holds(q, configuration.signs, configuration.redundancy)

    def solve(self, T: Any, configuration: Configuration, q_hint: np.ndarray | None = None) -> Solution:
        """Joint vector reaching pose T in the given configuration.

        Args:
            T: Target pose of the end-effector frame in the root frame: 4x4 or ``mink.SE3``.
            configuration: Branch signs (and redundancy values for redundant arms).
            q_hint: Optional joint vector; among several solutions the nearest is returned,
                and 2 pi shifts are chosen nearest to it (a revolute joint's hint beyond
                1e4 rad counts modulo 2 pi, reduced exactly: at that magnitude a joint value's
                own rounding reaches the 1e-10 tolerances). Without a hint, a solution within
                the joint limits is preferred.

        Returns:
            A :class:`Solution`; ``ok`` is False (with a status saying why) when no solution
            exists in this configuration.
        """
        if q_hint is None:  # the common case, in one compiled call; None: the checks below decide
            solution = self._kernel.solve_pose(T, configuration)
            if solution is not None:
                return solution
        T = as_pose(T)
        self.check_configuration(configuration)
        q = np.empty(self.arm.dof)
        r = self._kernel.solve(T, configuration.signs, configuration.redundancy, self._hint(q_hint), q)
        return Solution(
            q,
            r.status == system.OK,
            system.STATUS_NAMES[r.status],
            configuration,
            r.position_error,
            r.orientation_error,
            r.evaluations,
            r.within_limits,
        )

    def solve_all(self, T: Any, configuration: Configuration) -> list[Solution]:
        """Every real solution with this configuration (the bounded search), possibly none."""
        T = as_pose(T)
        self.check_configuration(configuration)
        n = system.MAX_ROOTS
        roots = _core.Roots(np.empty((n, self.arm.dof)), np.empty(n), np.empty(n), np.empty(n, dtype=bool))
        found = self._kernel.solve_all(T, configuration.signs, configuration.redundancy, roots)
        return [
            Solution(
                roots.q[r],
                True,
                "ok",
                configuration,
                roots.position_error[r],
                roots.orientation_error[r],
                found.evaluations,
                bool(roots.within_limits[r]),
            )
            for r in range(found.count)
        ]

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
        kernel = self._kernel

        def solve_range(start: int, stop: int) -> None:
            kernel.solve_rows(batch, start, stop)

        system.run_rows(solve_range, m, threads)
        return BatchSolution(
            batch.q,
            batch.status == system.OK,
            batch.status,
            batch.position_error,
            batch.orientation_error,
            batch.evaluations,
            batch.within_limits,
        )

    def solve_all_batch(
        self, T: Any, signs: Any, redundancy: Any = None, threads: int | None = None
    ) -> BatchRoots:
        """:meth:`solve_all` for many targets at once, in parallel.

        Args:
            T, signs, redundancy, threads: As :meth:`solve_batch` takes them (no hints).

        Returns:
            A :class:`BatchRoots` with M rows, each row's solutions those of
            ``solve_all(T[i], Configuration(signs[i], redundancy[i]))``.

        Raises:
            InvalidInput: A malformed argument, or one whose rows do not match the M poses.
        """
        return self.solve_grid(T, signs, redundancy, None, threads)

    def solve_grid(
        self, T: Any, signs: Any, redundancy: Any, band: np.ndarray | None, threads: int | None = None
    ) -> BatchRoots:
        """:meth:`solve_all_batch`, where a row whose ``band`` is False returns its
        configuration's own roots (the bounded search's) and nothing else: where it has none,
        it is not searched further for the roots that :meth:`solve_all` adds then (those of
        the neighbouring configurations within :data:`BRANCH_BAND` of the boundary, the
        singular boundary's touch points, the local solve from the fixed-point start). For a
        caller that solves each such row's neighbouring configurations too, as the
        redundancy optimiser's sweep does.

        Args:
            T, signs, redundancy, threads: As :meth:`solve_all_batch` takes them.
            band: (M,) bool, or None: every row searches as :meth:`solve_all` does.

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
        n = system.MAX_ROOTS
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
        )
        kernel = self._kernel

        def solve_range(start: int, stop: int) -> None:
            kernel.solve_all_rows(batch, start, stop)

        system.run_rows(solve_range, m, threads)
        return BatchRoots(
            batch.q,
            batch.count,
            batch.position_error,
            batch.orientation_error,
            batch.evaluations,
            batch.within_limits,
        )

    def check_configuration(self, configuration: Configuration) -> None:
        """Check that a configuration fits this arm.

        The solves call this on their configuration; call it to reject a bad configuration
        before any solve (``ExactPoseTask`` does, when it is given one).

        Args:
            configuration: A :class:`Configuration` with as many branch signs as
                :attr:`sign_names` and as many redundancy values as :attr:`redundancy_names`.

        Raises:
            InvalidInput: Not a Configuration, or the wrong number of signs or redundancy
                values (the message names the arm and what it needs).
        """
        as_instance(configuration, Configuration, "configuration")
        k, names = len(self.sign_names), self.redundancy_names
        if len(configuration.signs) != k:
            raise InvalidInput(
                f"arm '{self.arm.name}' needs {k} configuration signs {self.sign_names}, "
                f"got {len(configuration.signs)}"
            )
        if len(configuration.redundancy) != len(names):
            raise InvalidInput(
                f"arm '{self.arm.name}' needs {len(names)} redundancy values {names}, "
                f"got {len(configuration.redundancy)}"
            )

    # -----------------------------------------------------------------------------------

    def _check_solves_itself(self) -> None:
        """Raise :class:`ModelError` unless the arm solves its own poses (see the class)."""
        key = (self.tolerances, self.scan_points)
        if key in _SELF_CHECKED.get(self.arm, ()):
            return
        arm = self.arm
        span = np.where(arm.revolute, np.pi, 1.0)
        lower = np.where(np.isfinite(arm.lower), arm.lower, -span)
        upper = np.where(np.isfinite(arm.upper), arm.upper, span)
        for q in np.random.default_rng(0).uniform(lower, upper, (SELF_CHECK_SAMPLES, arm.dof)):
            configuration = self.configuration_of(q)
            solution = self.solve(arm.fk(q), configuration)
            if not solution.ok:
                shown = ", ".join(f"{v:.4f}" for v in q)
                named = [f"{n} {s:+d}" for n, s in zip(self.sign_names, configuration.signs, strict=True)]
                named += [
                    f"{n} {v:.4f}"
                    for n, v in zip(self.redundancy_names, configuration.redundancy, strict=True)
                ]
                raise ModelError(
                    f"arm '{arm.name}' does not solve its own pose at q = [{shown}] "
                    f"(configuration {', '.join(named)}): {solution.status}; the offset-modified "
                    f"model ({self.om.family_name}) does not fit this arm"
                )
        _SELF_CHECKED.setdefault(arm, set()).add(key)

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

    def _hint(self, q_hint: np.ndarray | None) -> np.ndarray | None:
        """The hint as the kernel takes it (None: no hint)."""
        if q_hint is None:
            return None
        return as_joint_vector(q_hint, self.arm.dof, "q_hint", stack=False)


def _rebuilt(arm: Arm, position_tolerance: float, orientation_tolerance: float, scan_points: int) -> OMSolver:
    """An :class:`OMSolver` unpickled (:meth:`OMSolver.__reduce__`)."""
    return OMSolver(
        arm,
        position_tolerance=position_tolerance,
        orientation_tolerance=orientation_tolerance,
        scan_points=scan_points,
    )
