"""The base of the mink tasks on an arm's joints inside a larger MuJoCo model."""

from __future__ import annotations

import mujoco
import numpy as np
import numpy.typing as npt
from mink import Configuration as MinkConfiguration
from mink import Task, TaskDefinitionError

from ..exceptions import InvalidInput, UnreachableTarget
from ..ik.configuration import Configuration
from ..ik.solver import OMSolver
from ..mujoco_io.arm_in_model import ArmJoints
from ..validation import as_array, as_instance, as_number


class ArmTask(Task):
    """A task on the arm's joints inside a larger model: cost, model check, Jacobian columns.

    The base of :class:`~om_redundant.ExactPoseTask` and :class:`~om_redundant.ArmAngleTask`.

    Args:
        solver: The OM solver of the arm.
        model: The MuJoCo model that holds the arm (possibly among other joints).
        k: Number of coordinates of the task's error.
        prefix: Prefix of the arm's joint names in the model (None: the arm's).
        cost: Cost, one value for every coordinate of the error or one per coordinate.
        gain: Task gain in [0, 1].
        lm_damping: Levenberg-Marquardt damping (see ``mink.Task``).

    Raises:
        InvalidInput: solver is not an :class:`~om_redundant.OMSolver` or model not a
            ``mujoco.MjModel``.
        TaskDefinitionError: A bad cost.
    """

    def __init__(
        self,
        solver: OMSolver,
        model: mujoco.MjModel,
        k: int,
        prefix: str | None,
        cost: npt.ArrayLike,
        gain: float,
        lm_damping: float,
    ):
        as_instance(solver, OMSolver, "solver")
        try:
            gain, lm_damping = as_number(gain, "gain"), as_number(lm_damping, "lm_damping")
        except InvalidInput as exc:
            raise TaskDefinitionError(f"{self.__class__.__name__} {exc}") from None
        super().__init__(cost=np.zeros(k), gain=gain, lm_damping=lm_damping)
        self.k = k
        self.solver = solver
        self.joints = ArmJoints(solver.arm, model, prefix)
        self.set_cost(cost)

    def set_cost(self, cost: npt.ArrayLike) -> None:
        """Set the cost: one value for every coordinate of the error, or one per coordinate."""
        try:
            cost = np.atleast_1d(as_array(cost, "cost", "numbers"))
        except InvalidInput as exc:
            raise TaskDefinitionError(f"{self.__class__.__name__} {exc}") from None
        if cost.ndim != 1 or cost.shape[0] not in (1, self.k):
            raise TaskDefinitionError(
                f"{self.__class__.__name__} cost must be a vector of shape (1,) or ({self.k},), "
                f"got {cost.shape}"
            )
        if not np.all(cost >= 0.0):
            raise TaskDefinitionError(f"{self.__class__.__name__} cost should be >= 0")
        self.cost[:] = cost

    def arm_q(self, configuration: MinkConfiguration) -> np.ndarray:
        """The arm's joints in the configuration, after checking it is of this task's model."""
        self.joints.check_model(configuration.model, self.__class__.__name__)
        return self.joints.q(configuration.data.qpos)

    def scatter(self, rows: np.ndarray) -> np.ndarray:
        """(k, dof) derivatives w.r.t. the arm's joints as a (k, nv) Jacobian."""
        jacobian = np.zeros((self.k, self.joints.model.nv))
        jacobian[:, self.joints.dof_ids] = rows
        return jacobian

    def solve_within_limits(
        self, T_root: np.ndarray, c: Configuration, hint: np.ndarray | None, who: str
    ) -> np.ndarray:
        """The exact solution of pose T_root in configuration c within the joint limits (the
        tighter of the arm's and the model's): the one the arm moves to from the hint (the
        joints at the previous target, :meth:`~om_redundant.OMSolver.solve_from`).

        Raises:
            UnreachableTarget: None; the message says why (``who`` names the task).
        """
        solution = self.solver.solve(T_root, c) if hint is None else self.solver.solve_from(T_root, c, hint)
        if not solution.ok:
            raise UnreachableTarget(f"{who}: {solution.status} for the target (configuration {c})")
        if self.joints.within_limits(solution.q):
            return solution.q
        inside = [s.q for s in self.solver.solve_all(T_root, c) if self.joints.within_limits(s.q)]
        if not inside:
            raise UnreachableTarget(
                f"{who}: every solution for the target in configuration {c} breaks a joint limit"
            )
        return min(inside, key=lambda q: float(np.linalg.norm(q - solution.q)))
