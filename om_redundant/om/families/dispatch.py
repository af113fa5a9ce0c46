"""Dispatch on the family code: one entry point per question the solver asks a family."""

from __future__ import annotations

import numba as nb

from . import six_dof, srs


@nb.njit(cache=True, inline="always")
def model_ik(family, P, table, R, p, signs, redundancy, q_prev, q, all_joints=True):
    """Solve the model arm for the flange pose (R, p) in DH frame 0; write q.

    Args:
        family: Family code.
        P: The family's parameter vector.
        table: The model's DH table.
        R, p: Flange pose in DH frame 0.
        signs: Branch signs.
        redundancy: Redundancy values (the arm angle of a 7-DOF arm; empty for 6-DOF).
        q_prev: Joints kept at singularities.
        q: Output joint vector.
        all_joints: False lets a family skip the joints that the OM residual does not need
            (a 7-DOF model's shoulder); the rest of q is then stale.

    Returns:
        The reach margin: negative (beyond ``REACH_SLACK``) when the pose is out of the
        model's reach, in which case q is not written; it measures how far.
    """
    if family == srs.SRS:
        return srs.model_ik(P, R, p, signs, redundancy[0], q_prev, q, all_joints)
    return six_dof.model_ik(family, P, table, R, p, signs, q_prev, q)


@nb.njit(cache=True)
def branch_values(family, P, q, out):
    """Write the quantities whose signs are the configuration's branch signs at q."""
    if family == srs.SRS:
        srs.branch_values(P, q, out)
    else:
        six_dof.branch_values(family, P, q, out)


@nb.njit(cache=True)
def redundancy_values(family, P, q, out):
    """Write the redundancy values of the configuration at q (the arm angle for 7-DOF)."""
    if family == srs.SRS:
        out[0] = srs.arm_angle(P, q)
