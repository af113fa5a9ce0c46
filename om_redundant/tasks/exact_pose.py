"""The mink task that pulls the arm's joints to the exact OM solution of a hand pose.

:class:`ExactPoseTask` turns a hand pose into the exact joint vector :math:`q^*` of the
configuration you chose (branch signs and arm angle, or the redundancy optimiser's choice)
and pulls the arm's joints there. Targets are poses of the arm's end-effector frame in
MuJoCo's world frame, like a ``FrameTask``'s; the task finds the arm's root frame in the
model (:class:`~om_redundant.ArmRoot`).
"""

from __future__ import annotations

from typing import Any, Protocol

import mujoco
import numpy as np
import numpy.typing as npt
from mink import SE3, TargetNotSet, TaskDefinitionError
from mink import Configuration as MinkConfiguration

from ..exceptions import UnreachableTarget
from ..mujoco_io.arm_in_model import ArmRoot
from ..om.configuration import Configuration
from ..om.solver import OMSolver
from ..validation import as_instance, as_pose
from .arm_task import ArmTask

#: Default cost of :class:`ExactPoseTask`, per radian (metre for prismatic joints). With
#: mink's usual ``FrameTask`` costs of 1 it makes the exact target dominate far from it,
#: which removes the spurious stationary points of the sum (see :class:`ExactPoseTask`).
EXACT_POSE_COST = 10.0


class RedundancyOptimizer(Protocol):
    """What :class:`ExactPoseTask` needs of a redundancy optimiser (duck-typed).

    ``choose(T, previous)`` takes a pose in the arm's root frame and the previous choice (or
    None) and returns an object with ``ok`` (bool), ``solution`` (an om
    :class:`~om_redundant.Solution`), ``configuration`` (its
    :class:`~om_redundant.Configuration`) and ``reason`` (str, why when not ok).
    """

    def choose(self, T: np.ndarray, previous: Any = None) -> Any: ...


class ExactPoseTask(ArmTask):
    r"""Pull the arm's joints to the exact solution of a hand pose in a chosen configuration.

    On :meth:`set_target` the OM solver gives :math:`q^*` with :math:`\mathrm{fk}(q^*) =
    T_{root,world} T_{world,target}` exactly, in the configuration c given
    (``arm_configuration``) or chosen by ``optimizer``, within the joint limits (the tighter
    of the arm's and the model's). The task's error and Jacobian are

    .. math::  e(q) = q_{arm} - \tilde q^*, \qquad J = [\,0 \;\cdots\; I_{dof} \;\cdots\; 0\,]
               \in \mathbb{R}^{dof \times n_v},

    the identity in the arm's dof columns, where :math:`\tilde q^*` is :math:`q^*` with each
    revolute joint shifted by the multiple of 2 pi that brings it nearest :math:`q_{arm}`, if
    that keeps it within the limits (so an unlimited joint takes the short way round, and a
    limited one never leaves its range).

    Since :math:`q^*` reaches the same pose as a ``FrameTask`` with the same target, the two
    tasks agree and mink converges to the pose exactly, in configuration c, with no posture
    bias. The QP step is a Gauss-Newton step on :math:`\tfrac12\sum_i |W_i e_i|^2`; apart
    from :math:`q^*`, a stationary point needs :math:`W^2 (q - q^*) = -J_f^T W_f^2 e_f`, which
    the default cost (:data:`EXACT_POSE_COST`, 10 times a unit ``FrameTask`` cost) confines
    so close to :math:`q^*` that none remains. With equal costs about a third of random
    targets on the Panda end at such a point, from the middle of the joint ranges.

    The arm's root may move (a mobile base, a mocap body): then :math:`q^*` is solved again
    whenever the root has moved, at the next :meth:`compute_error`; the Jacobian's columns
    of the base stay zero (the base follows the other tasks). :meth:`set_target` solves for
    the root where the task last saw it (in the ``mink.Configuration`` of its last
    ``compute_*``, :meth:`seed` or :meth:`set_target_from_configuration`); a target set
    before the task has seen any is solved at the next ``compute_*``.

    Failure is never silent: if the pose is out of reach, has no solution in c, or only
    solutions that break a joint limit, :meth:`set_target` raises
    :class:`~om_redundant.UnreachableTarget` naming the reason, and the task keeps its
    previous target (catch it to hold the arm where it was going). A target is never taken
    unsolved: when the first solve of a target set before the task saw its root fails, the
    ``compute_*`` raises and the task goes back to its previous target (or to none). Later,
    ``compute_*`` raises while the root stands where the target is out of the arm's reach.

    Args:
        solver: The OM solver of the arm.
        model: The MuJoCo model that holds the arm (possibly among other joints).
        arm_configuration: The configuration c to solve in (branch signs and, for a 7-DOF
            arm, the arm angle psi).
        optimizer: Instead of c: a redundancy optimiser, asked
            ``optimizer.choose(T_root, previous=<its last choice>)`` at each target.
        prefix: Prefix of the arm's joint names in the model, e.g. ``"l_"``; default the arm's
            (``arm.prefix``).
        frame_name, frame_type: The arm's end-effector frame in the model (the one
            ``arm.fk`` gives); default the prefix plus the arm's Menagerie frame.
        cost: Cost per joint error (1/rad), one value or one per joint.
        gain: Task gain in [0, 1].
        lm_damping: Levenberg-Marquardt damping (see ``mink.Task``).

    Raises:
        TaskDefinitionError: Neither or both of ``arm_configuration`` and ``optimizer``; a bad cost.
        JointNotFound, FrameNotFound, ModelMismatch: The model does not hold the arm as named.
    """

    def __init__(
        self,
        solver: OMSolver,
        model: mujoco.MjModel,
        *,
        arm_configuration: Configuration | None = None,
        optimizer: RedundancyOptimizer | None = None,
        prefix: str | None = None,
        frame_name: str | None = None,
        frame_type: str | None = None,
        cost: npt.ArrayLike = EXACT_POSE_COST,
        gain: float = 1.0,
        lm_damping: float = 0.0,
    ):
        as_instance(solver, OMSolver, "solver")
        if (arm_configuration is None) == (optimizer is None):
            raise TaskDefinitionError(
                "ExactPoseTask takes either arm_configuration (a fixed om.Configuration) or optimizer"
            )
        super().__init__(solver, model, solver.arm.dof, prefix, cost, gain, lm_damping)
        self.root = ArmRoot(self.joints, frame_name, frame_type)
        fixed = self.root.fixed_pose
        self._root_at_origin = fixed is not None and np.array_equal(fixed, np.eye(4))
        self._world_to_fixed_root = None if fixed is None else _inverse(fixed)
        self.optimizer = optimizer
        self.arm_configuration = arm_configuration
        if arm_configuration is not None:
            solver.check_configuration(arm_configuration)  # raises InvalidInput naming the problem
        self.transform_target_to_world: SE3 | None = None
        self.choice: Any = None
        self._q_target: np.ndarray | None = None
        self._root_pose: np.ndarray | None = None
        self._data: mujoco.MjData | None = None  # of the configuration last seen: where the root is
        self._unsolved_fallback: tuple[SE3 | None, Configuration | None] | None = None
        self._jacobian = self.scatter(np.eye(self.k))
        self._jacobian.setflags(write=False)

    @property
    def joint_target(self) -> np.ndarray | None:
        """The exact joint vector :math:`q^*` the task pulls to (None before the first solve)."""
        return None if self._q_target is None else self._q_target.copy()

    def set_target(
        self,
        transform_target_to_world: SE3 | np.ndarray,
        arm_configuration: Configuration | None = None,
    ) -> None:
        """Set the hand's target pose in the world frame and solve it exactly.

        The solve starts from the previous :math:`q^*` (the root nearest it), so a moving
        target keeps its branch and arm angle continuous. With a moving root it is solved for
        the root where the task last saw it (see the class docstring).

        Args:
            transform_target_to_world: ``mink.SE3`` or (4, 4) pose of the end-effector frame.
            arm_configuration: A new configuration c to solve in from now on (default: keep
                the task's); not with an optimiser.

        Raises:
            UnreachableTarget: No exact solution to pull to; the task keeps its old target
                and configuration.
            InvalidInput: A malformed pose or configuration.
            TaskDefinitionError: A configuration given to a task that uses an optimiser.
        """
        T = as_pose(transform_target_to_world, "transform_target_to_world")
        if arm_configuration is None:
            arm_configuration = self.arm_configuration
        elif self.optimizer is not None:
            raise TaskDefinitionError("this ExactPoseTask takes its configurations from its optimizer")
        else:
            self.solver.check_configuration(arm_configuration)  # raises InvalidInput naming the problem
        if self.root.fixed_pose is not None or self._data is not None:
            self._solve(T, self.root.pose(self._data), self._q_target, arm_configuration)  # or raises
            self._unsolved_fallback = None
        else:  # the root moves and the task has not seen where: solved at the next compute_*
            if self._unsolved_fallback is None:
                self._unsolved_fallback = (self.transform_target_to_world, self.arm_configuration)
            self._root_pose = None
        # (an SE3 given is kept as it is: SE3.from_matrix costs as much as the tracking step)
        given = transform_target_to_world
        self.transform_target_to_world = given if isinstance(given, SE3) else SE3.from_matrix(T)
        self.arm_configuration = arm_configuration

    def set_target_from_configuration(self, configuration: MinkConfiguration) -> None:
        """Hold the arm where it is: the target becomes the hand's current pose and, without
        an optimiser, c becomes the arm's current configuration (branch signs and psi)."""
        q = self._arm_q(configuration)
        T = configuration.get_transform_frame_to_world(self.root.frame_name, self.root.frame_type).as_matrix()
        c = self.solver.configuration_of(q) if self.optimizer is None else None
        self._solve(T, self.root.pose(configuration.data), q, c)
        self._unsolved_fallback = None
        self.arm_configuration = c
        self.transform_target_to_world = SE3.from_matrix(T)

    def seed(self, configuration: MinkConfiguration) -> None:
        """Put the arm's joints of ``configuration`` at :math:`q^*` (the other joints stay)."""
        _, q_target = self._joint_target(configuration)
        configuration.update(self.joints.qpos_with(configuration.data.qpos, q_target))

    def compute_error(self, configuration: MinkConfiguration) -> np.ndarray:
        r"""The joint error :math:`e(q) = q_{arm} - \tilde q^*` (dof,)."""
        q, q_target = self._joint_target(configuration)
        return q - self.joints.nearest_turn(q_target, q)

    def compute_jacobian(self, configuration: MinkConfiguration) -> np.ndarray:
        """The identity in the arm's dof columns, (dof, nv)."""
        self._joint_target(configuration)
        return self._jacobian

    # -----------------------------------------------------------------------------------

    def _joint_target(self, configuration: MinkConfiguration) -> tuple[np.ndarray, np.ndarray]:
        """The arm's joints q and :math:`q^*` for the configuration's root pose, solved again
        if the root moved."""
        q = self._arm_q(configuration)
        if self.transform_target_to_world is None:
            raise TargetNotSet(self.__class__.__name__)
        if self.root.fixed_pose is None:
            root = self.root.pose(configuration.data)
            if self._root_pose is None or not np.array_equal(root, self._root_pose):
                T = self.transform_target_to_world.as_matrix()
                try:
                    self._solve(T, root, self._q_target, self.arm_configuration)
                except UnreachableTarget as exc:
                    if self._unsolved_fallback is None:
                        raise  # a solved target the root has moved away from: kept
                    self.transform_target_to_world, self.arm_configuration = self._unsolved_fallback
                    self._unsolved_fallback = None
                    raise UnreachableTarget(f"{exc}; the target is dropped for the previous one") from None
                self._unsolved_fallback = None
        assert self._q_target is not None
        return q, self._q_target

    def _arm_q(self, configuration: MinkConfiguration) -> np.ndarray:
        """The arm's joints (checked as :meth:`arm_q`); remembers where the root is."""
        q = self.arm_q(configuration)
        self._data = configuration.data
        return q

    def _solve(
        self,
        T_world: np.ndarray,
        root_pose: np.ndarray,
        hint: np.ndarray | None,
        arm_configuration: Configuration | None,
    ) -> None:
        """Solve T_world for the root at root_pose and, only if that succeeds, take it."""
        if root_pose is self.root.fixed_pose:
            T_root = T_world if self._root_at_origin else self._world_to_fixed_root @ T_world
        else:
            R, p = root_pose[:3, :3], root_pose[:3, 3]
            T_root = np.eye(4)
            T_root[:3, :3] = R.T @ T_world[:3, :3]
            T_root[:3, 3] = R.T @ (T_world[:3, 3] - p)
        if arm_configuration is None:
            choice = self.optimizer.choose(T_root, previous=self.choice)
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
        else:
            choice, q = None, self._solve_in(T_root, arm_configuration, hint)
        self._q_target, self.choice, self._root_pose = q, choice, root_pose

    def _solve_in(self, T_root: np.ndarray, c: Configuration, hint: np.ndarray | None) -> np.ndarray:
        """The exact solution in configuration c within the limits, nearest the hint."""
        solution = self.solver.solve(T_root, c, q_hint=hint)
        if not solution.ok:
            raise UnreachableTarget(f"ExactPoseTask: {solution.status} for the target (configuration {c})")
        if self.joints.within_limits(solution.q):
            return solution.q
        inside = [s.q for s in self.solver.solve_all(T_root, c) if self.joints.within_limits(s.q)]
        if not inside:
            raise UnreachableTarget(
                f"ExactPoseTask: every solution for the target in configuration {c} breaks a joint limit"
            )
        return min(inside, key=lambda q: float(np.linalg.norm(q - solution.q)))


def _inverse(pose: np.ndarray) -> np.ndarray:
    """The inverse of a homogeneous transform, [[R^T, -R^T p], [0, 1]]."""
    inverse = np.eye(4)
    inverse[:3, :3] = pose[:3, :3].T
    inverse[:3, 3] = -pose[:3, :3].T @ pose[:3, 3]
    return inverse
