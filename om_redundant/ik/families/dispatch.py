"""Dispatch on the family code: one entry point per question the solver asks a family.

The closed forms are C (``csrc/ik/six_dof.c``, ``csrc/ik/srs.c``, ``csrc/ik/families.c``); these
functions call them from Python on arrays, as the tests and the model's derivation do. The
solver itself calls them inside its compiled kernels.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ... import _core


def model_ik(
    family: int,
    P: np.ndarray,
    table: np.ndarray,
    R: np.ndarray,
    p: np.ndarray,
    signs: np.ndarray,
    redundancy: np.ndarray,
    q_prev: np.ndarray,
    q: np.ndarray,
    all_joints: bool = True,
) -> float:
    """Solve the model arm for the flange pose (R, p) in DH frame 0; write q.

    Args:
        family: Family code.
        P: The family's parameter vector.
        table: The model's DH table.
        R, p: Flange pose in DH frame 0.
        signs: Branch signs.
        redundancy: Redundancy values (the arm angle of a 7-DOF arm; empty for 6-DOF).
        q_prev: Joints kept at singularities.
        q: Output joint vector (C-contiguous float64).
        all_joints: False lets a family skip the joints that the OM residual does not need
            (a 7-DOF model's shoulder); the rest of q is then stale.

    Returns:
        The reach margin: negative (beyond ``REACH_SLACK``) when the pose is out of the
        model's reach, in which case q is not written; it measures how far.
    """
    model = _core.FamilyModel(int(family), f64(P), f64(table))
    return _core.model_ik(model, flange_target(R, p, signs, redundancy), f64(q_prev), q, all_joints)


def branch_values(family: int, P: np.ndarray, q: np.ndarray, out: np.ndarray) -> None:
    """Write the quantities whose signs are the configuration's branch signs at q."""
    _core.branch_values(int(family), f64(P), f64(q), out)


def redundancy_values(family: int, P: np.ndarray, q: np.ndarray, out: np.ndarray) -> None:
    """Write the redundancy values of the configuration at q (the arm angle for 7-DOF)."""
    _core.redundancy_values(int(family), f64(P), f64(q), out)


def flange_target(R: np.ndarray, p: np.ndarray, signs: np.ndarray, redundancy: Any) -> _core.FlangeTarget:
    """The kernels' record of a flange pose (R, p) in DH frame 0 in a configuration (signs,
    redundancy: an array, or the arm angle psi of a 7-DOF arm as a number)."""
    return _core.FlangeTarget(f64(R), f64(p), i64(signs), f64(redundancy).reshape(-1))


def f64(values: np.ndarray) -> np.ndarray:
    """C-contiguous float64, as the kernels read their inputs."""
    return np.ascontiguousarray(values, dtype=np.float64)


def i64(values: np.ndarray) -> np.ndarray:
    """C-contiguous int64 (branch signs)."""
    return np.ascontiguousarray(values, dtype=np.int64)
