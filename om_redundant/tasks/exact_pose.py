"""The mink task that pulls the arm's joints to the exact OM solution of a hand pose.

:class:`ExactPoseTask` turns a hand pose into the exact joint vector :math:`q^*` of the
configuration you chose (branch signs and arm angle, or the redundancy optimiser's choice)
and pulls the arm's joints there. Targets are poses of the arm's end-effector frame in
MuJoCo's world frame, like a ``FrameTask``'s; the task finds the arm's root frame in the
model (:class:`~om_redundant.ArmRoot`).
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np
import numpy.typing as npt
from mink import SE3, Objective, TargetNotSet, TaskDefinitionError
from mink import Configuration as MinkConfiguration

from ..exceptions import InvalidInput, UnreachableTarget
from ..ik.configuration import Configuration
from ..ik.solver import OMSolver
from ..mujoco_io.arm_in_model import ArmRoot
from ..redundancy.free_rotation import FreeRotation
from ..validation import as_instance, as_pose
from .approach import DEFAULT_LEAD, JointWay, LeadsToJumpedTargets, Patience, as_lead
from .arm_task import ArmTask
from .chooser import Chooser, live_clearance

#: Default cost of :class:`ExactPoseTask`, per radian (metre for prismatic joints). With
#: mink's usual ``FrameTask`` costs of 1 it makes the exact target dominate far from it,
#: which removes the spurious stationary points of the sum (see :class:`ExactPoseTask`).
EXACT_POSE_COST = 10.0


class ExactPoseTask(ArmTask, LeadsToJumpedTargets):
    r"""Pull the arm's joints to the exact solution of a hand pose in a chosen configuration.

    On :meth:`set_target` the OM solver gives :math:`q^*` with :math:`\mathrm{fk}(q^*) =
    T_{root,world} T_{world,target} X^{-1}` exactly (X the target frame in the arm's
    end-effector frame: the identity for the arm's own frame, a constant for a hand or TCP
    fixed to its last link, :class:`~om_redundant.ArmRoot`), in the configuration c given
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

    The world may move: the arm's root (a mobile base, a mocap body) and, with an optimiser
    whose :class:`~om_redundant.Clearance` is of this task's model, the obstacles (mocap
    bodies, other arms: :meth:`Clearance.update <om_redundant.Clearance.update>` reads them
    from the configuration). Then :math:`q^*` is solved again whenever they have moved, at
    the next ``compute_*``; the Jacobian's columns of the base stay zero (the base follows
    the other tasks). :meth:`set_target` solves for the world as the task last saw it (in
    the ``mink.Configuration`` of its last ``compute_*``, :meth:`seed` or
    :meth:`set_target_from_configuration`); a target set before the task has seen any is
    solved at the next ``compute_*``.

    With an optimiser, each solve tracks the previous choice and gives it the arm's joints
    as last seen (``q_current``): where tracking cannot continue (a target that jumps, a
    feasible range that moves away, an obstacle moved onto the way), the optimiser chooses
    afresh from where the arm is, weighing the joint travel and wanting a clear way
    (:attr:`choice` says so: ``rechosen``, ``reason``). :meth:`reset_choice` forces a fresh
    choice at the next target. The arm goes to a fresh choice along the straight joint-space
    way the optimiser certified clear, the error pulling a step at a time along it (and
    scaled to keep the task's weight, :mod:`~om_redundant.tasks.approach`); obstacles that
    move onto the rest of the way make it choose afresh from where the arm is.

    Failure is never silent: if the pose is out of reach, has no solution in c, or only
    solutions that break a joint limit (with an optimiser: no feasible arm angle on any
    allowed branch, the limits and the clearance kept), :meth:`set_target` raises
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
        optimizer: Instead of c: a redundancy optimiser, asked ``optimizer.choose(T_root,
            previous=<its last choice>, q_current=<the arm's joints>)`` at each target.
        prefix: Prefix of the arm's joint names in the model, e.g. ``"l_"``; default the arm's
            (``arm.prefix``).
        frame_name, frame_type: The frame the targets are for: the arm's end-effector frame
            (the one ``arm.fk`` gives) or any frame fixed to its last link (a hand body, a
            TCP site); default the prefix plus the arm's Menagerie frame.
        cost: Cost per joint error (1/rad), one value or one per joint.
        gain: Task gain in [0, 1].
        lm_damping: Levenberg-Marquardt damping (see ``mink.Task``).
        lead: With an optimiser, how far the aims run ahead on the way to a target that
            jumped: the hand's (m, rad) and the joints' (rad, max-norm); None: no aims, the
            target (and a fresh choice's q*, no joint-space way) at once.
        free: With an optimiser, a rotation of the target it may choose:
            ``"tool_axis"`` (any turn about the frame's z axis: a tool to point, as
            ``mink.FrameTask(..., orientation_cost=[1, 1, 0])`` asks) or ``"orientation"``
            (a position to reach: ``orientation_cost=0``); the choice's ``turn`` says which
            (:class:`~om_redundant.FreeRotation`, about the frame's origin).

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
        optimizer: Chooser | None = None,
        prefix: str | None = None,
        frame_name: str | None = None,
        frame_type: str | None = None,
        cost: npt.ArrayLike = EXACT_POSE_COST,
        gain: float = 1.0,
        lm_damping: float = 0.0,
        lead: tuple[float, float, float] | None = DEFAULT_LEAD,
        free: str | None = None,
    ):
        as_instance(solver, OMSolver, "solver")
        if (arm_configuration is None) == (optimizer is None):
            raise TaskDefinitionError(
                "ExactPoseTask takes either arm_configuration (a fixed om.Configuration) or optimizer"
            )
        super().__init__(solver, model, solver.arm.dof, prefix, cost, gain, lm_damping)
        self.root = ArmRoot(self.joints, frame_name, frame_type)
        self.optimizer = optimizer
        self._clearance = live_clearance(optimizer, model, self.root)
        if free is not None and optimizer is None:
            raise TaskDefinitionError("ExactPoseTask: a free rotation is chosen by an optimizer")
        try:
            self.free = None if free is None else FreeRotation.of_frame(free, self.root.tool)
        except InvalidInput as exc:
            raise TaskDefinitionError(f"ExactPoseTask: {exc}") from None
        self.arm_configuration = arm_configuration
        if arm_configuration is not None:
            solver.check_configuration(arm_configuration)  # raises InvalidInput naming the problem
        self.transform_target_to_world: SE3 | None = None
        # the matrix of the target given to set_target: an SE3 made of it does not give it back
        # bit for bit, and a target that differs in its last bit is solved again
        self._given: tuple[SE3 | None, np.ndarray | None] = (None, None)
        self.choice: Any = None
        self._q_target: np.ndarray | None = None
        self._root_pose: np.ndarray | None = None
        self._data: mujoco.MjData | None = None  # of the configuration last seen: where the world is
        self._seen = -1  # the clearance's version the target was solved for
        self.lead = None if lead is None else as_lead(lead)
        self._aim: np.ndarray | None = None  # the world pose q* was solved for: the target or a lead
        self._way: JointWay | None = None  # the joint-space way to q* chosen afresh
        self._leading = False  # a target jumped to: the aim runs ahead of the hand until it is near
        self._blind = False  # the optimiser chose without the arm's joints (none seen yet)
        self._patience = Patience()
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
        # (a copy: the task keeps it, and a caller's array may change in place before the next)
        T = as_pose(transform_target_to_world, "transform_target_to_world").copy()
        if arm_configuration is None:
            arm_configuration = self.arm_configuration
        elif self.optimizer is not None:
            raise TaskDefinitionError("this ExactPoseTask takes its configurations from its optimizer")
        else:
            self.solver.check_configuration(arm_configuration)  # raises InvalidInput naming the problem
        if self.root.fixed_pose is not None or self._data is not None:
            if self._clearance is not None and self._data is not None:
                self._clearance.update(self._data)
            root = self.root.pose(self._data)
            if self._jumped(T):
                self._jump(T, root)  # or raises
            else:
                self._solve(T, root, self._q_target, arm_configuration)  # or raises
            self._unsolved_fallback = None
        else:  # the root moves and the task has not seen where: solved at the next compute_*
            if self._unsolved_fallback is None:
                self._unsolved_fallback = (self.transform_target_to_world, self.arm_configuration)
            self._root_pose = None
            self._leading = False
        # (an SE3 given is kept as it is: SE3.from_matrix costs as much as the tracking step)
        given = transform_target_to_world
        self.transform_target_to_world = given if isinstance(given, SE3) else SE3.from_matrix(T)
        self._given = (self.transform_target_to_world, T)
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
        self._given = (self.transform_target_to_world, T)

    def reset_choice(self) -> None:
        """Forget the optimiser's last choice: the next solve chooses afresh (from the arm's
        joints as last seen) instead of tracking it. The current target stays until then."""
        self.choice = None
        self._leading, self._way = False, None

    def _blocked(self, q_target: np.ndarray) -> bool:
        """Whether obstacles that moved since the joint-space way was last checked now block
        its rest ahead (:meth:`~om_redundant.tasks.approach.JointWay.blocked`)."""
        return self._way is not None and self._way.blocked(self._clearance, q_target)

    def seed(self, configuration: MinkConfiguration) -> None:
        """Put the arm's joints of ``configuration`` at :math:`q^*` of the target itself (not of
        a lead ahead of the hand; the other joints stay)."""
        _, q_target = self._joint_target(configuration, lead=False)
        configuration.update(self.joints.qpos_with(configuration.data.qpos, q_target))

    def compute_error(self, configuration: MinkConfiguration) -> np.ndarray:
        r"""The joint error :math:`e(q) = q_{arm} - \tilde q^*` (dof,)."""
        return self._pull(configuration)[0]

    def compute_jacobian(self, configuration: MinkConfiguration) -> np.ndarray:
        """The identity in the arm's dof columns (on a joint-space way, scaled as the error),
        (dof, nv)."""
        q, q_target = self._joint_target(configuration)
        return self._scaled_jacobian(self._pull_to(q, q_target)[1])

    def compute_qp_residual(self, configuration: MinkConfiguration) -> tuple[np.ndarray, np.ndarray, float]:
        """mink's weighted residual (``mink.Task.compute_qp_residual``), the world read once
        for the error and the Jacobian both."""
        error, weight = self._pull(configuration)
        return self._weighted_residual(error, self._scaled_jacobian(weight))

    def compute_qp_objective(self, configuration: MinkConfiguration) -> Objective:
        """mink's QP objective (``mink.Task.compute_qp_objective``), the world read once for
        the error and the Jacobian both."""
        error, weight = self._pull(configuration)
        return self._assemble_qp(error, self._scaled_jacobian(weight), configuration._eye_nv)

    def _pull(self, configuration: MinkConfiguration) -> tuple[np.ndarray, float]:
        """The error and its scale (:meth:`_pull_to`), choosing afresh where the arm is held
        short of q* or its way is blocked."""
        q, q_target = self._joint_target(configuration)
        aim, weight = self._pull_to(q, q_target)
        if self.optimizer is not None and (
            self._patience.run_out(q, float(np.abs(q - self.joints.nearest_turn(q_target, q)).max()))
            or self._blocked(q_target)
        ):
            self.reset_choice()  # held short of q*, or its way blocked: choose afresh
            q, q_target = self._joint_target(configuration, resolve=True)
            aim, weight = self._pull_to(q, q_target)
        return weight * (q - aim), weight

    def _pull_to(self, q: np.ndarray, q_target: np.ndarray) -> tuple[np.ndarray, float]:
        """What the error pulls the arm's joints to, and the error's scale: :math:`\tilde q^*`
        and 1, or on a joint-space way to a choice made afresh, the way's aim and weight
        (:class:`~om_redundant.tasks.approach.JointWay`) until the aim is q* itself."""
        way = self._way
        if way is not None:
            way.follow(q, q_target, self.lead[2])
            aim = way.aim(q_target)
            if aim is not q_target:
                return aim, way.weight(self.lead[2])
            self._way = None
        return self.joints.nearest_turn(q_target, q), 1.0

    def _scaled_jacobian(self, weight: float) -> np.ndarray:
        return self._jacobian if weight == 1.0 else weight * self._jacobian

    # -----------------------------------------------------------------------------------

    def _joint_target(
        self, configuration: MinkConfiguration, lead: bool = True, resolve: bool = False
    ) -> tuple[np.ndarray, np.ndarray]:
        """The arm's joints q and :math:`q^*` for the configuration's world, solved again if
        the root or the obstacles moved, or the aim (a lead ahead of the hand, or with
        ``lead=False`` the target itself) did."""
        q = self._arm_q(configuration)
        if self.transform_target_to_world is None:
            raise TargetNotSet(self.__class__.__name__)
        root = self.root.pose(configuration.data)
        moved = self._root_pose is None or (
            root is not self._root_pose and not np.array_equal(root, self._root_pose)
        )
        if self._clearance is not None:
            self._clearance.update(configuration.data)
            moved = moved or self._clearance.version != self._seen
        T = self._target_matrix()
        blind = lead and self._blind and self.lead is not None  # chosen before the arm was seen
        moved = moved or resolve
        if not (moved or blind):  # the aim moved on?
            aim = self._aim_for(T, configuration.data) if lead and self._leads() else T
            moved = self._aim is None or not np.array_equal(aim, self._aim)
        if moved or blind:
            try:
                if blind:  # chosen afresh from the arm's joints, and led there
                    self._jump(T, root)
                else:
                    self._solve(T, root, self._q_target, self.arm_configuration, lead)
            except UnreachableTarget as exc:
                if self._unsolved_fallback is None:
                    raise  # a solved target the world has moved away from: kept
                self.transform_target_to_world, self.arm_configuration = self._unsolved_fallback
                self._unsolved_fallback = None
                raise UnreachableTarget(f"{exc}; the target is dropped for the previous one") from None
            self._unsolved_fallback = None
        assert self._q_target is not None
        return q, self._q_target

    def _target_matrix(self) -> np.ndarray:
        """The target as a (4, 4) matrix: the one given to :meth:`set_target` while it is the
        target."""
        given, T = self._given
        target = self.transform_target_to_world
        return T if target is given else target.as_matrix()

    def _arm_q(self, configuration: MinkConfiguration) -> np.ndarray:
        """The arm's joints (checked as :meth:`arm_q`); remembers where the world is."""
        q = self.arm_q(configuration)
        self._data = configuration.data
        return q

    def _solve(
        self,
        T_world: np.ndarray,
        root_pose: np.ndarray,
        hint: np.ndarray | None,
        arm_configuration: Configuration | None,
        lead: bool = True,
    ) -> None:
        """Solve T_world (the target frame's pose), or the lead ahead of the hand on the way
        there, for the root at root_pose and, only if that succeeds, take it. Where the lead
        has no feasible choice (the straight way passes through an obstacle or out of reach),
        the target itself, from then on until the target jumps."""
        if lead and self._leads():
            aim = self._aim_for(T_world, self._data)
            if aim is not T_world:
                try:
                    self._solve_at(aim, root_pose, hint, arm_configuration)
                    if not (self.choice.rechosen and not self.choice.way_clear):
                        self._aim = aim
                        return
                except UnreachableTarget:
                    pass
                self.choice = None  # the way on is blocked: the target itself, chosen afresh
            self._leading = False  # (or arrived: the target tracked from the last aim)
        self._solve_at(T_world, root_pose, hint, arm_configuration)
        self._aim = T_world

    def _solve_at(
        self,
        T_world: np.ndarray,
        root_pose: np.ndarray,
        hint: np.ndarray | None,
        arm_configuration: Configuration | None,
    ) -> None:
        """Solve the world pose T_world for the root at root_pose and, only if that succeeds,
        take it."""
        T_root = self.root.in_root(T_world, root_pose)
        if arm_configuration is None:
            q_current = None if self._data is None else self.joints.q(self._data.qpos)
            self._blind, fresh = q_current is None, self.choice is None
            choice = self.optimizer.choose(T_root, previous=self.choice, q_current=q_current, free=self.free)
            self._take(choice, root_pose, fresh)
            return
        self._q_target, self.choice, self._root_pose = (
            self.solve_within_limits(T_root, arm_configuration, hint, "ExactPoseTask"),
            None,
            root_pose,
        )
        if self._clearance is not None:
            self._seen = self._clearance.version
