"""Checks at the API edge: poses, joint vectors, branch signs.

Every public entry point funnels its numeric input through these functions so that a
malformed argument raises :class:`~om_redundant.exceptions.InvalidInput` naming the
problem instead of producing a silently wrong answer.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from . import ckernels
from .exceptions import InvalidInput

#: Largest accepted deviation max|R^T R - I| of a pose's rotation block.
ORTHONORMALITY_TOLERANCE = 1e-9


def as_pose(T: Any, name: str = "T") -> np.ndarray:
    """Return a validated (4, 4) homogeneous transform from an array or a ``mink.SE3``."""
    if hasattr(T, "as_matrix") and not isinstance(T, np.ndarray):
        T = T.as_matrix()
    T = np.ascontiguousarray(T, dtype=np.float64)
    if T.shape != (4, 4):
        raise InvalidInput(f"{name} must be a (4, 4) homogeneous transform, got shape {T.shape}")
    if ckernels.pose_is_valid(T, ORTHONORMALITY_TOLERANCE):  # fast path; the full check names the problem
        return T
    _check_poses(T[None], name)
    raise AssertionError("unreachable: pose_is_valid and _check_poses disagree")


def as_poses(T: Any, name: str = "T") -> np.ndarray:
    """Return a validated (M, 4, 4) stack of homogeneous transforms."""
    T = np.ascontiguousarray(T, dtype=np.float64)
    if T.ndim != 3 or T.shape[1:] != (4, 4):
        raise InvalidInput(f"{name} must have shape (M, 4, 4), got {T.shape}")
    _check_poses(T, name)
    return T


def _check_poses(T: np.ndarray, name: str) -> None:
    bad = ~np.isfinite(T).all(axis=(1, 2))
    if bad.any():
        raise InvalidInput(f"{name}{_where(bad, T)} contains NaN or inf")
    if np.abs(T[:, 3] - (0.0, 0.0, 0.0, 1.0)).max() > 0.0:
        raise InvalidInput(f"{name}: last row of a homogeneous transform must be [0, 0, 0, 1]")
    R = T[:, :3, :3]
    deviation = np.abs(np.einsum("mji,mjk->mik", R, R) - np.eye(3)).max(axis=(1, 2))
    bad = deviation > ORTHONORMALITY_TOLERANCE
    if bad.any():
        raise InvalidInput(
            f"{name}{_where(bad, T)}: rotation is not orthonormal "
            f"(max|R^T R - I| = {deviation.max():.2e} > {ORTHONORMALITY_TOLERANCE:.0e})"
        )
    bad = np.linalg.det(R) < 0.0
    if bad.any():
        raise InvalidInput(f"{name}{_where(bad, T)}: rotation has determinant -1 (a reflection)")


def _where(bad: np.ndarray, T: np.ndarray) -> str:
    return f"[{int(np.flatnonzero(bad)[0])}]" if len(T) > 1 else ""


def as_joint_vector(q: Any, dof: int, name: str = "q") -> np.ndarray:
    """Return a validated joint vector of shape (dof,) or stack of shape (M, dof)."""
    q = np.asarray(q, dtype=np.float64)
    if q.ndim not in (1, 2) or q.shape[-1] != dof:
        raise InvalidInput(f"{name} must have shape ({dof},) or (M, {dof}), got {q.shape}")
    if not np.isfinite(q).all():
        raise InvalidInput(f"{name} contains NaN or inf")
    return q


def as_signs(signs: Any, count: int, name: str = "signs") -> np.ndarray:
    """Return branch signs as an int64 array of shape (count,) or (M, count), each +-1."""
    raw = np.asarray(signs)
    if raw.ndim not in (1, 2) or raw.shape[-1] != count:
        raise InvalidInput(f"{name} must have {count} entries per configuration, got shape {raw.shape}")
    if raw.dtype.kind not in "iuf" or not np.isin(raw, (-1, 1)).all():
        raise InvalidInput(f"{name} must be -1 or +1, got {np.unique(raw)[:5].tolist()}")
    return raw.astype(np.int64)


def as_positive(value: Any, name: str) -> float:
    """A positive finite number, or InvalidInput naming ``name``."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InvalidInput(f"{name} must be a positive number, got {value!r}") from None
    if not (np.isfinite(number) and number > 0.0):
        raise InvalidInput(f"{name} must be a positive finite number, got {value!r}")
    return number
