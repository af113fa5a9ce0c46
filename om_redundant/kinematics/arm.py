"""Arms: a kinematic chain with joint names, limits and the MuJoCo frame it matches (arm
files, which describe them, are read and written by :mod:`.arm_file`)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from ..exceptions import InvalidInput
from ..validation import as_array, as_joint_vector, as_number
from .chain import JointKind, KinematicChain


@dataclass(frozen=True, eq=False)
class Arm:
    """A serial arm: kinematic chain, joint names and limits.

    Attributes:
        name: Short name, e.g. ``"ur5e"``.
        chain: The kinematic chain (standard DH rows, base and tool transforms).
        joint_names: Joint names, as in the MuJoCo model the arm matches.
        lower: Lower joint limits (dof,); ``-inf`` where unlimited.
        upper: Upper joint limits (dof,); ``+inf`` where unlimited.
        description: Human-readable description.
        mujoco_model: Path of the matching MuJoCo Menagerie model, relative to Menagerie's root.
        frame_name: Name of the end-effector frame in that model, without the prefix where it
            has it.
        frame_type: ``"body"`` or ``"site"``.
        prefix: Prefix of the model's names of the arm's joints (and of the frame's, where it has
            it), e.g. ``"l_"``; the defaults of ``check-model``, :class:`~om_redundant.ArmJoints`
            and the tasks.
        root: The model's body whose frame is the arm's root frame, the frame of :meth:`fk`
            and of the poses the solver takes; None for the world.
        source: File the arm was read from.
    """

    name: str
    chain: KinematicChain
    joint_names: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray
    description: str = ""
    mujoco_model: str | None = None
    frame_name: str | None = None
    frame_type: str | None = None
    prefix: str = ""
    root: str | None = None
    source: str | None = None
    revolute: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        kinds = [self.chain.rows[i].kind for i in self.chain.joint_rows]
        object.__setattr__(self, "revolute", np.array([k is JointKind.REVOLUTE for k in kinds]))
        for side in ("lower", "upper"):  # one real number per joint, -inf or +inf for none
            limit = as_array(getattr(self, side), f"arm '{self.name}' {side} limits", "numbers")
            if limit.shape != (self.dof,) or np.isnan(limit).any():
                raise InvalidInput(
                    f"arm '{self.name}' {side} limits must be {self.dof} numbers (+-inf for none), "
                    f"got {limit.tolist() if limit.ndim == 1 else limit.shape}"
                )
            object.__setattr__(self, side, limit)
        inverted = np.flatnonzero(~(self.lower <= self.upper))
        if len(inverted):
            j = int(inverted[0])
            raise InvalidInput(
                f"arm '{self.name}' joint '{self.joint_names[j]}' has its lower limit {self.lower[j]} "
                f"above its upper limit {self.upper[j]}"
            )

    @property
    def dof(self) -> int:
        return self.chain.dof

    def fk(self, q: np.ndarray) -> np.ndarray:
        """Pose (4, 4) of the end-effector frame in the root frame; (M, 4, 4) for (M, dof)."""
        return self.chain.fk(q)

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """Geometric Jacobian (6, dof), rows ``[v; omega]``, in the root frame."""
        return self.chain.jacobian(q)

    def within_limits(self, q: np.ndarray, tolerance: float = 0.0) -> bool | np.ndarray:
        """Whether q (dof,) or each row of q (M, dof) lies within the joint limits."""
        q = as_joint_vector(q, self.dof)
        tolerance = as_number(tolerance, "tolerance")
        inside = ((q >= self.lower - tolerance) & (q <= self.upper + tolerance)).all(axis=-1)
        return bool(inside) if q.ndim == 1 else inside

    def with_chain(self, chain: KinematicChain, name: str) -> Arm:
        """The same arm (names, limits, model) on another chain, e.g. an offset-modified model."""
        return dataclasses.replace(self, name=name, chain=chain)
