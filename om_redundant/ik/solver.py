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
    as_positive,
    as_redundancy,
)
from .batch import BatchSolves
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


class OMSolver(BatchSolves):
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
        self.model_arm: ModelArm
        #: The nominal arm the model is derived from, for an arm NEAR a family; else None.
        self.nominal: NominalArm | None
        self.model_arm, self.nominal = closed_form(self.arm)
        self._flip = np.ones(self.arm.dof) if self.nominal is None else self.nominal.flip
        types = {"solution_type": Solution, "configuration_type": Configuration}
        self._kernel = _core.Solver(self.solver_data(), **types)
        self._check_solves_itself()

    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]:
        """Pickled as its arm and options (the compiled kernel is rebuilt): for spawned
        workers, Dask, Ray."""
        position, orientation = self.tolerances
        return (_rebuilt, (self.arm, position, orientation, self.scan_points))

    def solver_data(self) -> _core.SolverData:
        """The fixed data of the compiled kernel (see :class:`~om_redundant._core.SolverData`):
        of the arm, or, for an arm near a family (:attr:`nominal`), of its nominal arm's model with
        the arm's exact chain (``csrc/ik/near.c``)."""
        return kernel_data(self.model_arm, self.tolerances, self.scan_points, self.nominal)

    @property
    def kernel(self) -> _core.Solver:
        """The compiled solver, for kernels that solve with it (``_core.track_step``)."""
        return self._kernel

    @property
    def model(self) -> Arm:
        """The offset-modified model arm (of the nominal arm for an arm near a family, in the
        model's joint coordinates ``flip * q``)."""
        return self.model_arm.model

    @property
    def flip(self) -> np.ndarray:
        """The (dof,) signs (+-1) that give the model's joint coordinates ``flip * q`` (-1 where
        an arm near a family has a reversed axis, see :mod:`~om_redundant.ik.nominal`)."""
        return self._flip

    @property
    def dp_max(self) -> float:
        """Radius of the ball that holds every solution p_m of system (9), in metres."""
        return self.model_arm.dp_max

    @property
    def sign_names(self) -> tuple[str, ...]:
        """Names of the configuration's branch signs, e.g. ``("SHOULDER", "ELBOW", "WRIST")``."""
        return self.model_arm.sign_names

    @property
    def redundancy_names(self) -> tuple[str, ...]:
        """Names of the configuration's redundancy values (``("psi",)`` for 7-DOF arms)."""
        return self.model_arm.redundancy_names

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
        return self._solved(T, configuration, q_hint, False)

    def solve_from(self, T: Any, configuration: Configuration, q_previous: np.ndarray) -> Solution:
        """The joint vector the arm moves to from ``q_previous`` (its joints at the previous
        pose) as its hand moves to T, in the given configuration: the root whose joints moved
        as their first-order motion along the hand's predicts (each within a quarter of its
        step), where one does beyond doubt; else the root nearest ``q_previous``
        (:meth:`solve`'s with it as the hint). What a control loop asks each tick: the same
        answer as the hinted solve but where two roots lie close (a fold, a singular wrist),
        without the hinted solve's scan for a nearer root (on an arm with offsets that turn
        with two joints, most of its time: ``csrc/redundancy/solve_from.c``).

        Args:
            T: Target pose of the end-effector frame in the root frame: 4x4 or ``mink.SE3``.
            configuration: Branch signs (and redundancy values for redundant arms).
            q_previous: (dof,) the arm's joints at the previous pose.

        Returns:
            A :class:`Solution`, as :meth:`solve`'s.
        """
        return self._solved(T, configuration, q_previous, True)

    def _solved(self, T: Any, configuration: Configuration, hint: Any, from_previous: bool) -> Solution:
        """One compiled solve (``_core.Solver.solve``) as a :class:`Solution`, its pose,
        configuration and hint (None: none; ``from_previous``: the previous joints) checked."""
        T = as_pose(T)
        self.check_configuration(configuration)
        if hint is not None:
            name = "q_previous" if from_previous else "q_hint"
            hint = as_joint_vector(hint, self.arm.dof, name, stack=False)
        q = np.empty(self.arm.dof)
        r = self._kernel.solve(T, configuration.signs, configuration.redundancy, hint, q, from_previous)
        return Solution(
            q,
            r.status == _core.OK,
            _core.STATUS_NAMES[r.status],
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
        n = _core.MAX_ROOTS
        q, position, orientation = np.empty((n, self.arm.dof)), np.empty(n), np.empty(n)
        within = np.empty(n, dtype=bool)
        roots = _core.Roots(q, position, orientation, within)
        found = self._kernel.solve_all(T, configuration.signs, configuration.redundancy, roots)
        evals = found.evaluations
        return [
            Solution(q[r], True, "ok", configuration, position[r], orientation[r], evals, bool(within[r]))
            for r in range(found.count)
        ]

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
                    f"model ({self.model_arm.family_name}) does not fit this arm"
                )
        _SELF_CHECKED.setdefault(arm, set()).add(key)


def _rebuilt(arm: Arm, position_tolerance: float, orientation_tolerance: float, scan_points: int) -> OMSolver:
    """An :class:`OMSolver` unpickled (:meth:`OMSolver.__reduce__`)."""
    return OMSolver(
        arm,
        position_tolerance=position_tolerance,
        orientation_tolerance=orientation_tolerance,
        scan_points=scan_points,
    )
