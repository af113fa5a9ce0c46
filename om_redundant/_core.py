"""The boundary to the compiled core (``csrc/``, the extension ``om_redundant.ckernels``): the
one module that imports it. The rest of the package reaches the kernels, their constants and
the records that cross into them through here.
"""

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from . import ckernels
from .ckernels import (
    BRANCH_BAND,
    CIRCLE,
    CORE_BOX,
    CORE_MUJOCO,
    CORE_POINT,
    CORE_SEGMENT,
    DH_A,
    DH_COLUMNS,
    DH_COS_ALPHA,
    DH_D,
    DH_KIND,
    DH_SIN_ALPHA,
    DH_THETA,
    END_TOLERANCE,
    FIXED,
    FOLLOW_AIM,
    FOLLOW_ARRIVED,
    FOLLOW_CRAWL,
    FOLLOW_CRAWL_STEPS,
    FOLLOW_MAX_ATTEMPTS,
    FOLLOW_SINGULAR,
    FOLLOW_STALLED,
    JOINT_FIXED,
    JOINT_PRISMATIC,
    JOINT_REVOLUTE,
    LINK_DONE,
    LINK_FULL,
    LINK_SINGULAR,
    MAX_DOF,
    MAX_ROOTS,
    MAX_SCAN_POINTS,
    MIN_SCAN_POINTS,
    NO_SOLUTION_IN_CONFIGURATION,
    OK,
    ORTHONORMALITY_TOLERANCE,
    PATH_JUMP,
    PATH_SAME,
    REACH_SLACK,
    RRP_SPHERICAL_WRIST,
    RRR_SPHERICAL_WRIST,
    SD_A1,
    SD_A2,
    SD_AXIS4,
    SD_AXIS6,
    SD_BETA,
    SD_D1,
    SD_D3,
    SD_E_ROT,
    SD_ELL3,
    SD_LATERAL,
    SD_N_PARAMS,
    SD_SIGMA1,
    SD_SIGMA2,
    SD_SIGMA4,
    SD_SIGMA5,
    SD_THETA1,
    SD_THETA2,
    SD_THETA3,
    SD_THETA4,
    SD_THETA5,
    SD_THETA6,
    SD_WRIST_CENTRE,
    SD_WRIST_OFFSET,
    SD_WRIST_ROW,
    SRS,
    SRS_BEND,
    SRS_COS_BETA,
    SRS_COS_PHI_STAR,
    SRS_E_ROT,
    SRS_K,
    SRS_K0,
    SRS_N_PARAMS,
    SRS_PHI_STAR,
    SRS_R_PRE,
    SRS_REF,
    SRS_S3,
    SRS_SHOULDER,
    SRS_SIGMA1,
    SRS_SIGMA2,
    SRS_SIGMA5,
    SRS_SIN_BETA,
    SRS_SIN_PHI_STAR,
    SRS_THETA,
    SRS_U,
    SRS_UP,
    SRS_WRIST,
    SRS_X3,
    SRS_X4,
    STATUS_NAMES,
    TORUS,
    TRACK_INFEASIBLE,
    TRACK_LEFT,
    TRACK_NO_SOLUTION,
    TRACK_OK,
    TRACK_SINGULAR,
    UNREACHABLE,
    Followed,
    Found,
    Lifted,
    Linked,
    QPStep,
    Solved,
    Solver,
    TorusBound,
    TrackingStep,
    all_finite,
    arm_angle_gradient,
    arm_clearance,
    arm_geom_poses,
    box_overlap,
    branch_values,
    cell_looks,
    crossing,
    evaluate,
    fk,
    flange,
    flange_target,
    follow,
    jacobian,
    joint_step,
    link_paths,
    maximise_1d,
    model_ik,
    model_ik_at_reach,
    model_ik_lifted,
    pieces,
    polish,
    pose_is_valid,
    redundancy_values,
    self_motion_tangents,
    srs_model_q7,
    start_bound,
    start_cones,
    step_1d,
    surprise,
    track_step,
)

__all__ = [
    "BRANCH_BAND",
    "CIRCLE",
    "CORE_BOX",
    "CORE_MUJOCO",
    "CORE_POINT",
    "CORE_SEGMENT",
    "DH_A",
    "DH_COLUMNS",
    "DH_COS_ALPHA",
    "DH_D",
    "DH_KIND",
    "DH_SIN_ALPHA",
    "DH_THETA",
    "END_TOLERANCE",
    "FIXED",
    "FOLLOW_AIM",
    "FOLLOW_ARRIVED",
    "FOLLOW_CRAWL",
    "FOLLOW_CRAWL_STEPS",
    "FOLLOW_MAX_ATTEMPTS",
    "FOLLOW_SINGULAR",
    "FOLLOW_STALLED",
    "JOINT_FIXED",
    "JOINT_PRISMATIC",
    "JOINT_REVOLUTE",
    "LINK_DONE",
    "LINK_FULL",
    "LINK_SINGULAR",
    "MAX_DOF",
    "MAX_ROOTS",
    "MAX_SCAN_POINTS",
    "MIN_SCAN_POINTS",
    "NO_SOLUTION_IN_CONFIGURATION",
    "OK",
    "ORTHONORMALITY_TOLERANCE",
    "PATH_JUMP",
    "PATH_SAME",
    "REACH_SLACK",
    "RRP_SPHERICAL_WRIST",
    "RRR_SPHERICAL_WRIST",
    "SD_A1",
    "SD_A2",
    "SD_AXIS4",
    "SD_AXIS6",
    "SD_BETA",
    "SD_D1",
    "SD_D3",
    "SD_ELL3",
    "SD_E_ROT",
    "SD_LATERAL",
    "SD_N_PARAMS",
    "SD_SIGMA1",
    "SD_SIGMA2",
    "SD_SIGMA4",
    "SD_SIGMA5",
    "SD_THETA1",
    "SD_THETA2",
    "SD_THETA3",
    "SD_THETA4",
    "SD_THETA5",
    "SD_THETA6",
    "SD_WRIST_CENTRE",
    "SD_WRIST_OFFSET",
    "SD_WRIST_ROW",
    "SRS",
    "SRS_BEND",
    "SRS_COS_BETA",
    "SRS_COS_PHI_STAR",
    "SRS_E_ROT",
    "SRS_K",
    "SRS_K0",
    "SRS_N_PARAMS",
    "SRS_PHI_STAR",
    "SRS_REF",
    "SRS_R_PRE",
    "SRS_S3",
    "SRS_SHOULDER",
    "SRS_SIGMA1",
    "SRS_SIGMA2",
    "SRS_SIGMA5",
    "SRS_SIN_BETA",
    "SRS_SIN_PHI_STAR",
    "SRS_THETA",
    "SRS_U",
    "SRS_UP",
    "SRS_WRIST",
    "SRS_X3",
    "SRS_X4",
    "STATUS_NAMES",
    "TORUS",
    "TRACK_INFEASIBLE",
    "TRACK_LEFT",
    "TRACK_NO_SOLUTION",
    "TRACK_OK",
    "TRACK_SINGULAR",
    "UNREACHABLE",
    "ArmAngleRow",
    "ArmCores",
    "ArmLinks",
    "CellModels",
    "CellSamples",
    "Evaluations",
    "FamilyModel",
    "FlangeTarget",
    "FollowWork",
    "Followed",
    "Found",
    "GeomPose",
    "Lifted",
    "Linearisation",
    "LinkRoots",
    "LinkRows",
    "Linked",
    "ObjectiveTerms",
    "PairDistances",
    "PieceLimits",
    "PieceRows",
    "Pieces",
    "QPStep",
    "Roots",
    "SolveAllBatch",
    "SolveBatch",
    "Solved",
    "Solver",
    "SolverData",
    "StartSamples",
    "TorusBound",
    "TrackingStart",
    "TrackingStep",
    "TrackingWork",
    "all_finite",
    "arm_angle_gradient",
    "arm_clearance",
    "arm_geom_poses",
    "box_overlap",
    "branch_values",
    "cell_looks",
    "ckernels",
    "crossing",
    "evaluate",
    "fk",
    "flange",
    "flange_target",
    "follow",
    "jacobian",
    "joint_step",
    "link_paths",
    "maximise_1d",
    "model_ik",
    "model_ik_at_reach",
    "model_ik_lifted",
    "pieces",
    "polish",
    "pose_is_valid",
    "redundancy_values",
    "self_motion_tangents",
    "srs_model_q7",
    "start_bound",
    "start_cones",
    "step_1d",
    "surprise",
    "track_step",
]


class FollowWork(NamedTuple):
    """The arrays ``follow`` reads and writes, set up once per
    :class:`~om_redundant.redundancy.probe.Probe` (``link_paths`` reads the branch's: all but
    ``q`` and ``t``).

    Attributes:
        kernel: The compiled solver.
        T: (4, 4) the pose.
        signs: The branch signs (int64).
        cyclic: (7,) joints compared modulo 2 pi (uint8).
        centred: (7,) joints taken at the turn nearest mid-range (uint8).
        centre: (7,) the mid-ranges (0 where not centred).
        q, t: (7,) the start's joints and tangent on entry, the point reached's on return.
    """

    kernel: Solver
    T: np.ndarray
    signs: np.ndarray
    cyclic: np.ndarray
    centred: np.ndarray
    centre: np.ndarray
    q: np.ndarray
    t: np.ndarray


class TrackingWork(NamedTuple):
    """What ``track_step`` reads of the optimiser, set up once per
    :class:`~om_redundant.redundancy.tracking.Tracker`, and where it writes the new joints.

    Attributes:
        kernel: The compiled solver of the 7-DOF arm.
        lower, upper: (7,) joint limits (inf: not limited).
        singular_joints, singular_offsets: (k,) the singularities' joints (as floats) and
            constants (:class:`~om_redundant.Singularity`).
        q: (7,) the new joints (written).
        margin_weight, clearance_weight, singularity_weight: The objective's weights.
        clearance_floor: d_min / d_cap.
        clearance_cap: d_cap (m).
        singularity_cap: s_cap.
        joint_step: The step keeps the linearised joint motion within this (rad).
    """

    kernel: Solver
    lower: np.ndarray
    upper: np.ndarray
    singular_joints: np.ndarray
    singular_offsets: np.ndarray
    q: np.ndarray
    margin_weight: float
    clearance_weight: float
    singularity_weight: float
    clearance_floor: float
    clearance_cap: float
    singularity_cap: float
    joint_step: float


class TrackingStart(NamedTuple):
    """Where a tracking step starts (``track_step``).

    Attributes:
        T: (4, 4) the new pose.
        signs: The branch signs (int64).
        psi: The previous arm angle.
        q: (7,) the previous joints.
        curvature: The curvature b of the step's model.
    """

    T: np.ndarray
    signs: np.ndarray
    psi: float
    q: np.ndarray
    curvature: float


class Linearisation(NamedTuple):
    """The clearances at joints q, the tracking step's model of them about q (``track_step``
    reads q, distances and gradients).

    Attributes:
        q: (7,) the joints.
        distances: (P,) the pairs' distances there (m), capped at the objective's reach.
        gradients: (P, 7) their gradients (zero where capped).
        version: The clearance's :attr:`~om_redundant.Clearance.version` (the obstacles'
            poses) they were computed with.
    """

    q: np.ndarray
    distances: np.ndarray
    gradients: np.ndarray
    version: int = 0


class ArmLinks(NamedTuple):
    """An arm's links with geoms on them: what ``arm_geom_poses`` reads (of an
    :class:`ArmCores` too).

    Attributes:
        table: The arm's DH table (``KinematicChain.table``).
        start: (12,) world pose of DH frame 0, K: rotation (row-major) and position.
        link: (A,) each arm geom's link: the number of the arm's joints that move it (int64).
        offset: (A, 12) each arm geom's pose in its link's frame, as ``start``.
        slide: (dof,) which joints slide (else turn; uint8).
    """

    table: np.ndarray
    start: np.ndarray
    link: np.ndarray
    offset: np.ndarray
    slide: np.ndarray


class ArmCores(NamedTuple):
    """What ``arm_clearance`` reads: the arm's links (:class:`ArmLinks`' fields) with the arm
    geoms' offsets in them, and the geoms as cores, the arm's A geoms first, then the O
    obstacles (G = A + O).

    Attributes:
        table, start, link, offset, slide: As :class:`ArmLinks`'.
        obstacle_pos, obstacle_mat: (O, 3), (O, 9) the obstacles' world poses.
        kind: (G,) each geom's core (int64): ``CORE_POINT`` (sphere), ``CORE_SEGMENT``
            (capsule), ``CORE_BOX``; ``CORE_MUJOCO`` where MuJoCo computes its distances (other
            kinds, arm geoms other than spheres and capsules).
        radius: (G,) radius about the core (0 for a box).
        half: (G, 3) half length of a segment along its z axis (0, 0, l); a box's half sizes.
        pairs: (P, 2) each pair's geoms: (arm geom, obstacle) in this numbering (int64).
        bounds: (P,) sum of each pair's bounding-sphere radii (inf: a plane).
    """

    table: np.ndarray
    start: np.ndarray
    link: np.ndarray
    offset: np.ndarray
    slide: np.ndarray
    obstacle_pos: np.ndarray
    obstacle_mat: np.ndarray
    kind: np.ndarray
    radius: np.ndarray
    half: np.ndarray
    pairs: np.ndarray
    bounds: np.ndarray


class PairDistances(NamedTuple):
    """Where ``arm_clearance`` writes (or, given, reads) the pairs' distances of M joint vectors.

    Attributes:
        dist: (M, P) the distances.
        fromto: (M, P, 6) their nearest points, arm geom's then obstacle's.
        grad: (M, P, dof) their gradients, or None for none.
    """

    dist: np.ndarray
    fromto: np.ndarray
    grad: np.ndarray | None


class GeomPose(NamedTuple):
    """A geom placed in the world, as ``box_overlap`` reads it.

    Attributes:
        pos: (3,) its position.
        mat: (9,) its rotation, row-major.
        half: (3,) a capsule's (0, 0, l), a box's half sizes.
        radius: Its radius about its core (a box's: not read).
    """

    pos: np.ndarray
    mat: np.ndarray
    half: np.ndarray
    radius: float = 0.0


class ObjectiveTerms(NamedTuple):
    """The objective's terms, as ``evaluate`` reads them
    (:class:`~om_redundant.redundancy.objective.Objective`).

    Attributes:
        dof: The arm's joints.
        limited: (L,) the limited joints (int64), their limits lower, upper and half ranges
            half (L,).
        joints, offsets: (K,) the singularities' joints (int64) and constants.
        margin_weight, clearance_weight, singularity_weight: w_m, w_c, w_s.
        clearance_cap, min_clearance: d_cap, d_min (m).
        singularity_cap: s_cap.
    """

    dof: int
    limited: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    half: np.ndarray
    joints: np.ndarray
    offsets: np.ndarray
    margin_weight: float
    clearance_weight: float
    singularity_weight: float
    clearance_cap: float
    min_clearance: float
    singularity_cap: float


class Evaluations(NamedTuple):
    """Where ``evaluate`` writes the objective at M joint vectors: (M,) each, the fields of
    :class:`~om_redundant.redundancy.objective.Evaluation`.

    Attributes:
        value, margin, clearance, slack, singularity: f, M, D, the slack and S.
    """

    value: np.ndarray
    margin: np.ndarray
    clearance: np.ndarray
    slack: np.ndarray
    singularity: np.ndarray


class Pieces(NamedTuple):
    """Groups of pieces in one variable concatenated, as ``maximise_1d`` and ``step_1d`` read
    them: group g's pieces are ``ends[g]`` to ``ends[g + 1] - 1``, each group has at least one.

    Attributes:
        values: (n,) the pieces v_j.
        rates: (n,) their rates a_j.
        ends: (G + 1,) int64, from 0 to n.
        weights, floors, caps: (G,) per group.
    """

    values: np.ndarray
    rates: np.ndarray
    ends: np.ndarray
    weights: np.ndarray
    floors: np.ndarray
    caps: np.ndarray


class StartSamples(NamedTuple):
    """The samples of runs, as ``start_bound`` and ``start_cones`` read them.

    Attributes:
        psi: (M,) the runs' samples, a run's in increasing psi.
        values: (M, C) f and every group's functions there.
        slopes: (C,) their slope bounds L.
        groups: (G,) each group's first column (int64).
        weights, caps: (G,) per group.
    """

    psi: np.ndarray
    values: np.ndarray
    slopes: np.ndarray
    groups: np.ndarray
    weights: np.ndarray
    caps: np.ndarray


class SolverData(NamedTuple):
    r"""A solver's fixed data, as the compiled kernels take it (C-contiguous float64 arrays).

    Attributes:
        family: Closed-form family code of the model (:mod:`om_redundant.om.families`).
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
            system (9), whose correction ``csrc/near.c`` solves); real_table is then the arm's
            exact chain and lower, upper its limits, in the nominal joint coordinates
            ``flip * q``. Empty (0 rows) for an arm in its family.
        flip: (dof,) +-1: the kernels' joint coordinates are ``flip * q`` (all +1 but a near
            arm's reversed axes); joint vectors cross the kernels' entry points in the arm's own.
        near_deviation: A bound (m) on how far the nominal arm's flange frame is from the
            arm's (:attr:`~om_redundant.om.nominal.NominalArm.deviation`); 0 in its family.
        near_left: The correction on the left, in DH frame 0 (an arm whose nominal arm zeroes a
            shoulder offset, :attr:`~om_redundant.om.nominal.NominalArm.shoulder_offset`, larger
            than its wrist offset); False: on the right, in the flange frame (``csrc/near.c``).
        near_mixed: The correction's translation mixed from its last two steps (an arm whose
            nominal arm zeroes a shoulder or wrist offset; ``csrc/near.c``).
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


class LinkRoots(NamedTuple):
    """A branch's roots at the grid psi that ``link_paths`` links into paths.

    Attributes:
        psi: (n,) the grid, increasing within a turn.
        counts: (n,) the roots at each grid psi (int64), M in all.
        q, t: (M, 7) the roots' joints and tangents, grid psi by grid psi.
    """

    psi: np.ndarray
    counts: np.ndarray
    q: np.ndarray
    t: np.ndarray


class LinkRows(NamedTuple):
    """Where ``link_paths`` writes the paths it links: the R rows that following adds (rows
    M, M + 1, ... after the M roots) and each path's rows.

    Attributes:
        psi: (R,) the added rows' psi.
        q, t: (R, 7) their joints and tangents.
        members: (M + R, 2) int64: the paths' rows in order, path after path, each with the
            turns of psi it is taken at.
        paths: (M + R, 2) int64: per path, where its members end and its turns (a loop's, else 0).
    """

    psi: np.ndarray
    q: np.ndarray
    t: np.ndarray
    members: np.ndarray
    paths: np.ndarray


class PieceRows(NamedTuple):
    """The M joint vectors at which ``pieces`` computes the feasibility functions.

    Attributes:
        q: (M, dof) the joints.
        t: (M, dof) dq/dpsi there.
        distances: (M, P) the clearance pairs' distances.
        gradients: (M, P, dof) their gradients.
    """

    q: np.ndarray
    t: np.ndarray
    distances: np.ndarray
    gradients: np.ndarray


class PieceLimits(NamedTuple):
    """The L limited joints of an arm, as ``pieces`` reads them.

    Attributes:
        limited: (L,) their indices (int64).
        lower, upper: (L,) their limits.
        half: (L,) half their ranges.
    """

    limited: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    half: np.ndarray


class CellModels(NamedTuple):
    """The cubic Hermite models of a cell's n feasibility functions between its ends a and b
    (``surprise``, ``crossing``).

    Attributes:
        ga, da: (n,) the functions and their rates along psi at a.
        gb, db: (n,) the same at b.
        span: psi_b - psi_a.
        hermite: (4, N) the Hermite basis at the cell's N points.
    """

    ga: np.ndarray
    da: np.ndarray
    gb: np.ndarray
    db: np.ndarray
    span: float
    hermite: np.ndarray


class CellSamples(NamedTuple):
    """The M samples of P paths, path after path, whose cells ``cell_looks`` tests.

    Attributes:
        q: M joint vectors (float64, (dof,) each).
        psi: M floats.
        pieces: M pairs (g, dg) of float64 arrays (n,): the feasibility functions and rates.
        feasible: M bools.
        bounds: (P + 1,) int64: each path's first sample, then M.
        cyclic: (P, dof) bool: each path's joints compared modulo 2 pi.
    """

    q: Sequence[np.ndarray]
    psi: Sequence[float]
    pieces: Sequence[tuple[np.ndarray, np.ndarray]]
    feasible: Sequence[bool]
    bounds: np.ndarray
    cyclic: np.ndarray
