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
    END_TOLERANCE,
    FIXED,
    FOLLOW_AIM,
    FOLLOW_ARRIVED,
    FOLLOW_CRAWL,
    FOLLOW_CRAWL_STEPS,
    FOLLOW_MAX_ATTEMPTS,
    FOLLOW_SINGULAR,
    FOLLOW_STALLED,
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
    UNREACHABLE,
    Followed,
    Linked,
    Solver,
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
    step_1d,
    surprise,
    track_step,
)

__all__ = [
    "BRANCH_BAND",
    "CIRCLE",
    "END_TOLERANCE",
    "FIXED",
    "FOLLOW_AIM",
    "FOLLOW_ARRIVED",
    "FOLLOW_CRAWL",
    "FOLLOW_CRAWL_STEPS",
    "FOLLOW_MAX_ATTEMPTS",
    "FOLLOW_SINGULAR",
    "FOLLOW_STALLED",
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
    "UNREACHABLE",
    "CellModels",
    "CellSamples",
    "FollowWork",
    "Followed",
    "LinkRoots",
    "LinkRows",
    "Linked",
    "PieceLimits",
    "PieceRows",
    "Solver",
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
