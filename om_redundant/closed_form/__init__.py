"""Closed-form inverse kinematics of the model arms' families (numba kernels).

A family kernel solves the MODEL arm exactly for a flange pose in DH frame 0 and a set
of branch signs, and evaluates the branch quantities whose signs define the
configuration of a joint vector. :mod:`om_redundant.model` recognises the family of a
model arm and packs its parameters; the solver calls :func:`model_ik` and
:func:`branch_values`, which dispatch on the family code.
"""

from .six_dof import REACH_SLACK, RRP_SPHERICAL_WRIST, RRR_SPHERICAL_WRIST, branch_values, model_ik

__all__ = ["REACH_SLACK", "RRP_SPHERICAL_WRIST", "RRR_SPHERICAL_WRIST", "branch_values", "model_ik"]
