"""Peers from the generated URDF: TRAC-IK and ikpy."""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

import om_redundant as om

from ..robots import (
    EE_LINK,
    ROOT_LINK,
    home_joints,
    urdf_text,
)
from .base import Method, Peer, Unavailable, _revolute_only, _rows

#: TRAC-IK settings: time budget per solve (s) and its convergence threshold (below 1e-6).
TRAC_IK_TIMEOUT = 0.005
TRAC_IK_EPSILON = 1e-7


def trac_ik_peer(arm: om.Arm, rng: np.random.Generator) -> Peer:
    """TRAC-IK (KDL + SQP, C++) via pytracik, from the generated URDF; one call from home."""
    try:
        import pytracik
    except ImportError as exc:
        raise Unavailable(f"not installed ({exc})") from exc
    _revolute_only(arm)
    solver = pytracik.TRAC_IK(
        ROOT_LINK, EE_LINK, urdf_text(arm), TRAC_IK_TIMEOUT, TRAC_IK_EPSILON, pytracik.SolveType.Speed
    )
    if pytracik.get_num_joints(solver) != arm.dof:
        raise Unavailable(
            f"parsed {pytracik.get_num_joints(solver)} joints from the URDF, expected {arm.dof}"
        )
    home = home_joints(arm)

    def prepare(T: np.ndarray, _: np.ndarray) -> tuple[float, ...]:
        x, y, z, w = Rotation.from_matrix(T[:3, :3]).as_quat()
        return (*T[:3, 3], x, y, z, w)

    def solutions(_: Any, result: Any) -> np.ndarray:
        return _rows(result[1:], arm.dof) if result[0] >= 0 else np.empty((0, arm.dof))

    return Peer(
        "TRAC-IK",
        arm,
        lambda q: np.asarray(pytracik.fk(solver, np.asarray(q, dtype=float))),
        f"Speed, timeout {TRAC_IK_TIMEOUT * 1e3:g} ms, epsilon {TRAC_IK_EPSILON:g}, seed = home; "
        "limits stored in float32 (1e-6 rad slack)",
        limit_tolerance=1e-6,
        any=Method(prepare, lambda target: pytracik.ik(solver, home, *target), solutions),
    )


def ikpy_peer(arm: om.Arm, rng: np.random.Generator) -> Peer:
    """ikpy (scipy least squares), from the generated URDF; one call from home."""
    try:
        import ikpy.chain
    except ImportError as exc:
        raise Unavailable(f"not installed ({exc})") from exc
    _revolute_only(arm)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"{arm.name}.urdf"
        path.write_text(urdf_text(arm))
        chain = ikpy.chain.Chain.from_urdf_file(
            str(path), base_elements=[ROOT_LINK], active_links_mask=[False, *[True] * arm.dof, False]
        )
    start = np.concatenate([[0.0], home_joints(arm), [0.0]])

    def fk(q: np.ndarray) -> np.ndarray:
        return chain.forward_kinematics(np.concatenate([[0.0], q, [0.0]]))

    return Peer(
        "ikpy",
        arm,
        fk,
        'inverse_kinematics_frame, orientation_mode="all", default optimizer (least_squares), start = home',
        any=Method(
            lambda T, _: T,
            lambda T: chain.inverse_kinematics_frame(T, initial_position=start, orientation_mode="all"),
            lambda _, q: _rows(np.asarray(q)[1:-1], arm.dof),
        ),
    )
