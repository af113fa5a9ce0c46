"""The records the solver's kernels read and write by field name: the solver's fixed data,
a configuration's roots, batches of solves, and the closed forms' arguments."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class SolverData(NamedTuple):
    r"""A solver's fixed data, as the compiled kernels take it (C-contiguous float64 arrays).

    Attributes:
        family: Closed-form family code of the model (:mod:`om_redundant.ik.families`).
        mode: ``FIXED``, ``CIRCLE`` or ``TORUS``.
        params: The family's parameter vector.
        model_table: The model's DH table (rows of a, d, theta, cos alpha, sin alpha, kind).
        real_table: The real arm's DH table.
        dp_joint: The joint J that delta depends on on the circle (0 otherwise).
        dp_coefficients: (6, 3): rows 0-2 the coefficients D of
            :math:`\delta(w) = D_0 + D_1 \cos w + D_2 \sin w`, rows 3-5 those of the shoulder
            offsets' :math:`a(q_1)` (zero off the torus).
        T_base_root: Inverse of the pose of DH frame 0 in the root frame.
        T_tool_flange: Inverse of the pose of the end-effector frame in the flange frame.
        revolute: (dof,) bool.
        lower, upper: (dof,) joint limits.
        scan_points: Grid points of the bounded search.
        position_tolerance, orientation_tolerance: Accepted errors (m, rad).
        nominal_table: For an arm near a family, its nominal arm's DH table (the model side of
            system (9), whose correction ``csrc/ik/near.c`` solves); real_table is then the arm's
            exact chain and lower, upper its limits, in the nominal joint coordinates
            ``flip * q``. Empty (0 rows) for an arm in its family.
        flip: (dof,) +-1: the kernels' joint coordinates are ``flip * q`` (all +1 but a near
            arm's reversed axes); joint vectors cross the kernels' entry points in the arm's own.
        near_deviation: A bound (m) on how far the nominal arm's flange frame is from the
            arm's (:attr:`~om_redundant.ik.nominal.NominalArm.deviation`); 0 in its family.
        near_left: The correction on the left, in DH frame 0 (an arm whose nominal arm zeroes a
            shoulder offset, :attr:`~om_redundant.ik.nominal.NominalArm.shoulder_offset`, larger
            than its wrist offset); False: on the right, in the flange frame (``csrc/ik/near.c``).
        near_mixed: The correction's translation mixed from its last two steps (an arm whose
            nominal arm zeroes a shoulder or wrist offset; ``csrc/ik/near.c``).
    """

    family: int
    mode: int
    params: np.ndarray
    model_table: np.ndarray
    real_table: np.ndarray
    dp_joint: int
    dp_coefficients: np.ndarray
    T_base_root: np.ndarray
    T_tool_flange: np.ndarray
    revolute: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    scan_points: int
    position_tolerance: float
    orientation_tolerance: float
    nominal_table: np.ndarray
    flip: np.ndarray
    near_deviation: float
    near_left: bool
    near_mixed: bool


class Roots(NamedTuple):
    """The arrays ``Solver.solve_all`` writes a configuration's roots into (its first
    ``Found.count`` entries; the rest are left as they were).

    Attributes:
        q: (MAX_ROOTS, dof) the roots, in the arm's own joints.
        position_error: (MAX_ROOTS,) each root's position error (m).
        orientation_error: (MAX_ROOTS,) each root's orientation error (rad).
        within_limits: (MAX_ROOTS,) bool: whether each root is within the joint limits.
    """

    q: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray
    within_limits: np.ndarray


class SolveBatch(NamedTuple):
    """The arrays of a batch of solves, one row per pose: what ``Solver.solve_rows`` reads and
    writes (each call rows ``start:stop`` of them).

    Attributes:
        T: (M, 4, 4) the poses.
        signs: (M, k) int64 the configurations' branch signs.
        redundancy: (M, r) their redundancy values.
        hints: (M, dof) the hints, or None: no hint.
        q: (M, dof) out: the solutions.
        status: (M,) int64 out: ``OK``, ``UNREACHABLE`` or ``NO_SOLUTION_IN_CONFIGURATION``.
        position_error: (M,) out: metres.
        orientation_error: (M,) out: radians.
        evaluations: (M,) int64 out: the residual evaluations spent.
        within_limits: (M,) bool out.
    """

    T: np.ndarray
    signs: np.ndarray
    redundancy: np.ndarray
    hints: np.ndarray | None
    q: np.ndarray
    status: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray
    evaluations: np.ndarray
    within_limits: np.ndarray


class SolveAllBatch(NamedTuple):
    """The arrays of a batch of bounded searches, one row per pose: what
    ``Solver.solve_all_rows`` reads and writes (each call rows ``start:stop`` of them; a row's
    entries beyond its count are left as they were).

    Attributes:
        T: (M, 4, 4) the poses.
        signs: (M, k) int64 the configurations' branch signs.
        redundancy: (M, r) their redundancy values.
        band: (M,) bool: whether a row without a root of its own searches the branch band.
        q: (M, MAX_ROOTS, dof) out: each row's roots.
        count: (M,) int64 out: how many.
        evaluations: (M,) int64 out: the residual evaluations spent.
        position_error: (M, MAX_ROOTS) out: metres.
        orientation_error: (M, MAX_ROOTS) out: radians.
        within_limits: (M, MAX_ROOTS) bool out.
        traces: Where the rows keep the self-motion they traced (an S-R-S arm with shoulder
            offsets: each ELBOW sign's first, kept until the traces go; ``torus_traces(kernel)``),
            for the follows after the batch (``FollowWork.traces``); None: not kept.
    """

    T: np.ndarray
    signs: np.ndarray
    redundancy: np.ndarray
    band: np.ndarray
    q: np.ndarray
    count: np.ndarray
    evaluations: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray
    within_limits: np.ndarray
    traces: object | None = None


class FamilyModel(NamedTuple):
    """A closed-form model arm, as ``model_ik`` takes it.

    Attributes:
        family: The family code (``RRR_SPHERICAL_WRIST``, ``RRP_SPHERICAL_WRIST``, ``SRS``).
        params: The family's parameter vector (float64).
        table: The model's DH table (rows of a, d, theta, cos alpha, sin alpha, kind).
    """

    family: int
    params: np.ndarray
    table: np.ndarray


class FlangeTarget(NamedTuple):
    """What a model IK solves for: a flange pose in DH frame 0 in one configuration.

    Attributes:
        R: (3, 3) or (9,) the flange rotation (float64, row-major).
        p: (3,) the flange position.
        signs: (3,) int64 the branch signs.
        redundancy: The redundancy values (float64): (1,) the arm angle psi of a 7-DOF arm,
            (0,) for a 6-DOF one.
    """

    R: np.ndarray
    p: np.ndarray
    signs: np.ndarray
    redundancy: np.ndarray


class ArmAngleRow(NamedTuple):
    """The arm-angle row that ``polish`` adds for a 7-DOF arm: the S-R-S model whose arm
    angle it holds, and the value.

    Attributes:
        params: The S-R-S model's parameter vector.
        model_table: The model's DH table.
        psi: The arm angle to hold (rad).
    """

    params: np.ndarray
    model_table: np.ndarray
    psi: float
