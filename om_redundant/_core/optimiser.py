"""The records the redundancy optimiser's kernels read and write by field name: the tracking
step, the clearance of the arm's geoms, the objective, the climb's QP and its start bounds."""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

if TYPE_CHECKING:
    from . import Solver


class TrackingWork(NamedTuple):
    """What ``track_step`` reads of the optimiser, set up once per
    :class:`~om_redundant.redundancy.choice.tracking.Tracker`, and where it writes the new joints.

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


class Segment(NamedTuple):
    """A straight joint-space segment and its samples, as ``segment_minimum`` reads and
    writes them.

    Attributes:
        q_from, q_to: (dof,) its ends.
        rows: (R, dof) the samples' joints, the ends first, then each round's midpoints.
        dist: (R, P) their pairs' distances.
        fromto: (R, P, 6) the pairs' nearest points.
    """

    q_from: np.ndarray
    q_to: np.ndarray
    rows: np.ndarray
    dist: np.ndarray
    fromto: np.ndarray


class SegmentCheck(NamedTuple):
    """How ``segment_minimum`` checks a segment.

    Attributes:
        lipschitz: L, the most any distance changes over the whole segment (m).
        floor: The clearance it is checked against (m).
        budget: The most joint vectors sampled inside it (inf: no limit).
        tolerance: A piece whose bound is this close to its ends' is not split (m).
        reach: Distances are capped here (m).
    """

    lipschitz: float
    floor: float
    budget: float
    tolerance: float
    reach: float


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
    """The objective's terms, as ``evaluate`` and ``linearise`` read them
    (:class:`~om_redundant.redundancy.objective.objective.Objective`).

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
    :class:`~om_redundant.redundancy.objective.terms.Evaluation`.

    Attributes:
        value, margin, clearance, slack, singularity: f, M, D, the slack and S.
    """

    value: np.ndarray
    margin: np.ndarray
    clearance: np.ndarray
    slack: np.ndarray
    singularity: np.ndarray


class Pieces(NamedTuple):
    """Groups of pieces in one variable concatenated, as ``step_1d`` reads them: group g's
    pieces are ``ends[g]`` to ``ends[g + 1] - 1``, each group has at least one.

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
        slopes: (M, C) their slope bounds L on each sample's run.
        groups: (G,) each group's first column (int64).
        weights, caps: (G,) per group.
    """

    psi: np.ndarray
    values: np.ndarray
    slopes: np.ndarray
    groups: np.ndarray
    weights: np.ndarray
    caps: np.ndarray
