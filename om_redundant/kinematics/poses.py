"""Poses from and to a position and a unit quaternion (w, x, y, z), as arm files and MJCF
write them, and the poses and angles that survive that round trip bit for bit."""

from __future__ import annotations

import itertools
import math
from typing import Any

import mujoco
import numpy as np

from ..validation import as_quaternion, as_vector


def pose_from_xyz_quat(xyz: Any, quat: Any, quat_name: str = "quaternion") -> np.ndarray:
    """Pose (4, 4) from a position and a quaternion (w, x, y, z), which is normalised
    (:func:`~om_redundant.validation.as_quaternion`: scaled first, so huge entries normalise
    correctly).

    Raises:
        InvalidInput: xyz is not 3 finite numbers; the quaternion (named ``quat_name`` in the
            message) is not 4 finite numbers, or has zero norm (below 1e-9).
    """
    T = np.eye(4)
    T[:3, :3] = rotation_from_quat(as_quaternion(quat, quat_name))
    T[:3, 3] = as_vector(xyz, 3, "xyz")
    return T


def rotation_from_quat(wxyz: np.ndarray) -> np.ndarray:
    """Rotation matrix of a unit quaternion (w, x, y, z)."""
    w, x, y, z = wxyz
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def xyz_quat(T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position and unit quaternion (w, x, y, z; w >= 0) of a pose (4, 4), entries below
    1e-15 written as 0."""
    quat = np.empty(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(T[:3, :3], dtype=np.float64).ravel())
    quat = np.where(np.abs(quat) < 1e-15, 0.0, quat)
    if quat[0] < 0.0 or (quat[0] == 0.0 and quat[np.flatnonzero(quat)[0]] < 0.0):
        quat = -quat
    xyz = np.where(np.abs(T[:3, 3]) < 1e-15, 0.0, T[:3, 3])
    return xyz + 0.0, quat + 0.0  # + 0.0: no negative zeros


def file_xyz_quat(T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The ``xyz`` and ``quat`` :func:`~om_redundant.write_arm_file` writes for T: T's (:func:`xyz_quat`), or
    a quaternion a few 1e-16 from it that :func:`pose_from_xyz_quat` turns back into T
    exactly, where one exists (it does for every pose read from a file)."""
    xyz, quat = xyz_quat(T)
    for candidate in _nearby(quat):
        if np.array_equal(pose_from_xyz_quat(xyz, candidate), T):
            return xyz, candidate
    return xyz, quat


def exact_pose(T: np.ndarray) -> np.ndarray:
    """A pose within a few 1e-16 of T that :func:`~om_redundant.write_arm_file` writes and
    :func:`~om_redundant.load_arm` reads back bit for bit.

    The file holds a quaternion, which :func:`pose_from_xyz_quat` turns into a matrix with
    rounding: the poses of the quaternions around T's are tried until one gives its own
    quaternion back (else the first, for which :func:`file_xyz_quat` searches further).
    """
    xyz, quat = xyz_quat(T)
    for candidate in _nearby(quat):
        pose = pose_from_xyz_quat(xyz, candidate)
        if np.array_equal(pose_from_xyz_quat(*xyz_quat(pose)), pose):
            return pose
    return pose_from_xyz_quat(xyz, quat)


def _nearby(quat: np.ndarray):
    """quat, then quaternions that differ by -2 ... 2 steps of 2^-53 (then 2^-51) in each
    component, fewest steps first."""
    for step in (2.0**-53, 2.0**-51):
        for delta in _QUATERNION_STEPS:
            yield quat + step * delta


_QUATERNION_STEPS = np.array(
    sorted(itertools.product(range(-2, 3), repeat=4), key=lambda d: (sum(map(abs, d)), d)), dtype=np.float64
)


def exact_angle(angle: float) -> float:
    """The angle (rad) an arm file's degrees give for ``angle``: the same up to rounding, and
    one that :func:`~om_redundant.write_arm_file` writes and :func:`~om_redundant.load_arm` reads back bit
    for bit."""
    for _ in range(8):
        exact = math.radians(math.degrees(angle))
        if exact == angle:
            break
        angle = exact
    return angle
