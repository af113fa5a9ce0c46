"""Closed-form inverse kinematics of the model arms' families.

A family solves the MODEL arm exactly for a flange pose in DH frame 0, a set of branch
signs and (for redundant arms) redundancy values, and evaluates the branch quantities and
redundancy values that define the configuration of a joint vector. The closed forms are C
(``csrc/``); these modules hold their math and call them from Python (:mod:`.dispatch`).
:mod:`om_redundant.ik.model` recognises the family of a model arm, and
:mod:`~om_redundant.ik.six_dof_model` and :mod:`~om_redundant.ik.srs_model` pack its parameters.
The family codes and the parameter layouts are written once, in ``csrc/ik/om_kernels.h``, and
read from :mod:`om_redundant._core` (the codes re-exported here).
"""

from ..._core import RRP_SPHERICAL_WRIST, RRR_SPHERICAL_WRIST, SRS
from .common import REACH_SLACK
from .dispatch import branch_values, model_ik, redundancy_values

__all__ = [
    "REACH_SLACK",
    "RRP_SPHERICAL_WRIST",
    "RRR_SPHERICAL_WRIST",
    "SRS",
    "branch_values",
    "model_ik",
    "redundancy_values",
]
