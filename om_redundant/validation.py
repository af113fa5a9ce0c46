"""Checks at the API edge: one function per kind of value.

Every public entry point funnels its input through these functions so that a malformed
argument raises :class:`~om_redundant.exceptions.InvalidInput` naming the argument and the
problem, instead of producing a silently wrong answer or another library's exception.

The rules, the same everywhere:

* Numbers are numbers: ``int`` and ``float`` and their numpy kinds. Text (``"0.5"``),
  booleans (``True``, ``np.True_``), complex numbers, ``None`` and other objects are refused,
  never converted (:func:`as_number`, :func:`as_array`).
* A count is a whole number within its stated range; ``8.9`` is refused, not truncated
  (:func:`as_count`).
* Arrays have the shape asked for; structured, object, text, boolean and complex arrays
  are refused (:func:`as_array` and the functions built on it: :func:`as_pose`,
  :func:`as_poses`, :func:`as_joint_vector`, :func:`as_signs`, :func:`as_redundancy`,
  :func:`as_vector`, :func:`as_quaternion`).
* Objects of a library type are checked by :func:`as_instance`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import mink
import mujoco
import numpy as np

from . import _core
from .exceptions import InvalidInput

#: Largest accepted deviation max|R^T R - I| of a pose's rotation block (1e-9; defined in
#: csrc/binding/binding.h, where ``OMSolver.solve``'s one-call path checks poses too).
ORTHONORMALITY_TOLERANCE: float = _core.ORTHONORMALITY_TOLERANCE
#: A quaternion whose norm is below this is refused as zero (it has no direction to keep).
MIN_QUATERNION_NORM = 1e-9

_REAL_KINDS = "iuf"  # numpy dtype kinds of real numbers: signed, unsigned, floating
_KIND_NAMES = {
    "bool among numbers": "a boolean among the numbers",
    "b": "booleans",
    "c": "complex numbers",
    "U": "text",
    "S": "bytes",
    "O": "objects that are not numbers",
    "V": "a structured array",
    "M": "dates",
    "m": "time spans",
}
_NOT_ARRAYS = (str, bytes, bytearray, Mapping, set, frozenset)
# Exact types of the fast paths (bool is not among them: True is refused by the general path).
_SEQUENCES = (tuple, list)
_INTEGERS = (int, np.int64, np.int32)
_REALS = (float, int, np.float64, np.int64)
_SCALARS = (int, float, complex, np.number, np.bool_)  # one number where a sequence is wanted


# ---------------------------------------------------------------------------------------
# Scalars


def as_number(value: Any, name: str) -> float:
    """One finite real number (int or float, Python or numpy) as a float.

    Raises:
        InvalidInput: Text, a boolean, a complex number, None, another object, NaN or inf.
    """
    if type(value) is float and math.isfinite(value):  # the common case, fast
        return value
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | float | np.integer | np.floating):
        raise InvalidInput(f"{name} must be a finite number, got {_describe(value)}")
    try:
        number = float(value)
    except OverflowError:  # an int beyond the float range
        raise InvalidInput(f"{name} must be a finite number, got an integer too large for a float") from None
    if not math.isfinite(number):
        raise InvalidInput(f"{name} must be a finite number, got {value!r}")
    return number


def as_positive(value: Any, name: str) -> float:
    """A positive finite number (:func:`as_number`), or InvalidInput naming ``name``."""
    number = as_number(value, name)
    if not number > 0.0:
        raise InvalidInput(f"{name} must be a positive finite number, got {value!r}")
    return number


def as_count(value: Any, name: str, minimum: int, maximum: int) -> int:
    """A whole number in [minimum, maximum]: an int, or a float with a whole value (64.0).

    Raises:
        InvalidInput: Not a number, a fraction (8.9 is refused, not truncated), or out of range.
    """
    number = as_number(value, name)
    if not number.is_integer():
        raise InvalidInput(f"{name} must be a whole number, got {value!r}")
    count = int(value)
    if not minimum <= count <= maximum:
        raise InvalidInput(f"{name} must be at least {minimum} and at most {maximum}, got {count}")
    return count


def as_instance(value: Any, kind: Any, name: str, what: str | None = None) -> Any:
    """``value`` if it is a ``kind`` (a class or a union of classes), else InvalidInput naming
    ``name``, what it must be (``what``, default "a/an <class name>") and what it is."""
    if not isinstance(value, kind):
        if what is None:
            what = ("an " if kind.__name__[0] in "AEIOU" else "a ") + kind.__name__
        raise InvalidInput(f"{name} must be {what}, got {_describe(value)}")
    return value


# ---------------------------------------------------------------------------------------
# Arrays


def as_array(value: Any, name: str, expected: str) -> np.ndarray:
    """A float64 array of real numbers, of any shape (the callers check it).

    Args:
        value: An array or nested sequence of ints and floats.
        name: The argument's name, for the message.
        expected: What the argument should be, e.g. ``"a (4, 4) homogeneous transform"``.

    Raises:
        InvalidInput: Text, a mapping, None, a ragged sequence, or an array of booleans,
            complex numbers, objects, text or records.
    """
    if isinstance(value, np.ndarray):
        array = value
    elif value is None or isinstance(value, _NOT_ARRAYS):
        raise InvalidInput(f"{name} must be {expected}, got {_describe(value)}")
    else:
        try:
            array = np.asarray(value)
        except (TypeError, ValueError, OverflowError, RecursionError):  # ragged, or refuses to convert
            raise InvalidInput(f"{name} must be {expected}, got {_describe(value)}") from None
    kind = array.dtype.kind
    if kind in _REAL_KINDS and array is not value and _holds_bool(value):  # numpy made True a number
        kind = "bool among numbers"
    if kind not in _REAL_KINDS:
        what = _KIND_NAMES.get(kind, f"dtype {array.dtype}")  # formatted only here: str(dtype) is slow
        kind_wanted = "" if "numbers" in expected else " (real numbers)"
        raise InvalidInput(f"{name} must be {expected}{kind_wanted}, got {what}")
    return array.astype(np.float64, copy=False)


def as_pose(T: Any, name: str = "T") -> np.ndarray:
    """Return a validated (4, 4) homogeneous transform from an array or a ``mink.SE3``."""
    if type(T) is not np.ndarray or T.dtype != np.float64:  # the fast path takes float64 arrays as given
        if _is_se3(T):
            T = _se3_matrix(T)
        T = as_array(T, name, "a (4, 4) homogeneous transform")
    if T.shape != (4, 4):
        raise InvalidInput(f"{name} must be a (4, 4) homogeneous transform, got shape {T.shape}")
    T = np.ascontiguousarray(T)
    if _core.pose_is_valid(T, ORTHONORMALITY_TOLERANCE):  # fast path; the full check names the problem
        return T
    _check_poses(T[None], name)
    raise AssertionError("unreachable: pose_is_valid and _check_poses disagree")


def as_poses(T: Any, name: str = "T") -> np.ndarray:
    """Return a validated (M, 4, 4) stack of homogeneous transforms, M >= 1.

    Takes an (M, 4, 4) array or a sequence of M (4, 4) arrays. An empty batch and
    ``mink.SE3`` (one, or a sequence of them) are refused with the fix in the message:
    ``solve`` takes one SE3, and the stack of matrices is one ``np.stack`` away. Always a
    copy: what is checked is what the kernels solve, whatever another thread writes into the
    caller's array meanwhile.
    """
    expected = "(M, 4, 4) poses"
    if _is_se3(T) or (isinstance(T, list | tuple) and any(_is_se3(x) for x in T)):
        what = f"one {type(T).__name__}" if _is_se3(T) else "a sequence holding mink.SE3"
        raise InvalidInput(
            f"{name} must be {expected}, got {what}: solve takes one SE3; for a batch give "
            f"np.stack([p.as_matrix() for p in poses])"
        )
    T = as_array(T, name, expected)
    if T.size == 0:
        raise InvalidInput(f"{name} holds no poses (shape {T.shape}): a batch needs at least one")
    if T.ndim != 3 or T.shape[1:] != (4, 4):
        raise InvalidInput(f"{name} must have shape (M, 4, 4), got {T.shape}")
    T = np.array(T, order="C")
    _check_poses(T, name)
    return T


def _is_se3(value: Any) -> bool:
    return hasattr(value, "as_matrix") and not isinstance(value, np.ndarray)


def _se3_matrix(T: Any) -> np.ndarray:
    """``T.as_matrix()``; for a ``mink.SE3`` (quaternion w, x, y, z and translation in
    ``wxyz_xyz``) the same matrix by the same ``mju_quat2Mat``, without mink's intermediate
    SO3 and arrays (a third of the time: :meth:`ExactPoseTask.set_target` takes SE3 every tick)."""
    wxyz_xyz = getattr(T, "wxyz_xyz", None)
    if type(T) is not mink.SE3 or type(wxyz_xyz) is not np.ndarray or wxyz_xyz.shape != (7,):
        return T.as_matrix()
    rotation = np.empty(9)
    mujoco.mju_quat2Mat(rotation, wxyz_xyz[:4])
    matrix = np.zeros((4, 4))
    matrix[:3, :3] = rotation.reshape(3, 3)
    matrix[:3, 3] = wxyz_xyz[4:]
    matrix[3, 3] = 1.0
    return matrix


def _check_poses(T: np.ndarray, name: str) -> None:
    if _core.pose_is_valid(T, ORTHONORMALITY_TOLERANCE):  # fast path
        return
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


def as_joint_vector(q: Any, dof: int, name: str = "q", *, stack: bool = True) -> np.ndarray:
    """Return a validated joint vector of shape (dof,), or with ``stack`` also a stack (M, dof),
    as a C-contiguous float64 array."""
    # the common case, fast: a C-contiguous float64 (dof,) array is checked as given
    if not (type(q) is np.ndarray and q.dtype == np.float64 and q.shape == (dof,) and q.flags.c_contiguous):
        shapes = f"({dof},) or (M, {dof})" if stack else f"({dof},)"
        q = as_array(q, name, f"a joint vector of shape {shapes}")
        if q.ndim not in ((1, 2) if stack else (1,)) or q.shape[-1] != dof:
            raise InvalidInput(f"{name} must have shape {shapes}, got {q.shape}")
        q = np.ascontiguousarray(q)
    if not _core.all_finite(q):
        raise InvalidInput(f"{name} contains NaN or inf")
    return q


def as_signs(
    signs: Any, count: int | None, name: str = "signs", *, stack: bool = False, rows: int | None = None
) -> np.ndarray:
    """Branch signs as an int64 array, each -1 or +1 (``True`` and ``np.True_`` are refused).

    Args:
        signs: One configuration's signs (count,), or with ``stack`` one row per configuration.
        count: Signs per configuration, or None for any number.
        name: The argument's name, for the message.
        stack: Also accept a stack (M, count).
        rows: With ``stack``, the number of rows a stack must have (one per target; one row
            also goes for every target).
    """
    if _plain(signs, _INTEGERS) and all(x in (1, -1) for x in signs) and len(signs) == (count or len(signs)):
        return np.array(signs, dtype=np.int64).reshape(-1)  # the common case, fast: a tuple of ints
    per = "" if count is None else f" ({count} per configuration)"
    raw = as_array(signs, name, f"numbers -1 or +1{per}")
    width = raw.shape[-1] if count is None and raw.ndim else count
    if raw.ndim not in ((1, 2) if stack else (1,)) or raw.shape[-1] != width:
        got = _describe(signs) if raw.ndim == 0 else f"shape {raw.shape}"
        if count is None:
            raise InvalidInput(f"{name} must be a sequence of -1 and +1, got {got}")
        raise InvalidInput(f"{name} must have {count} entries per configuration, got {got}")
    if rows is not None and raw.ndim == 2 and len(raw) not in (1, rows):
        raise InvalidInput(f"{name} must be one row or one row per pose ({rows}), got {len(raw)} rows")
    bad = (raw != 1.0) & (raw != -1.0)
    if bad.any():
        raise InvalidInput(f"{name} must be -1 or +1, got {numbers_text(np.unique(raw[bad])[:5])}")
    return raw.astype(np.int64)


def _plain(values: Any, types: tuple[type, ...]) -> bool:
    """A tuple or list of values of exactly these types (no bool: it is not among them)."""
    return type(values) in _SEQUENCES and all(type(x) in types for x in values)


def _holds_bool(values: Any) -> bool:
    """Whether a nested sequence holds a boolean (numpy turns True among numbers into 1)."""
    try:
        items = np.asarray(values, dtype=object).ravel()
    except (TypeError, ValueError):
        return False
    return any(isinstance(v, bool | np.bool_) for v in items)


def as_redundancy(
    values: Any, name: str = "redundancy", names: tuple[str, ...] | None = None, rows: int | None = None
) -> np.ndarray:
    """Redundancy values (a 7-DOF arm's arm angle psi), finite real numbers, always given as
    a sequence or array: a bare number or None is refused (one way to write them).

    For one configuration (``rows`` None): a sequence; returns shape (r,). For a batch
    (``rows`` = M, ``names`` the arm's r redundancy names): None for an arm without any;
    (r,) for every row, (M,) when r = 1, or (M, r); returns (M, r).
    """
    if values is None and rows is not None and not names:
        return np.zeros((rows, 0))
    if rows is None and _plain(values, _REALS) and all(_finite(x) for x in values):
        return np.array(values, dtype=np.float64)  # the common case, fast: a tuple of finite floats
    if rows is None:
        expected = "a sequence of real numbers"
        rule = f"be {expected} (() for none)"
    else:
        r = len(names or ())
        expected = f"an array of shape ({rows}, {r})"
        rule = f"have shape ({rows}, {r}) " + (
            f"for {names}" if names else "(the arm has no redundancy values: give None)"
        )
    if values is None or isinstance(values, _SCALARS):
        example = "; e.g. (0.5,) for psi = 0.5" if rows is None or names else ""
        raise InvalidInput(f"{name} must {rule}, got {_describe(values)}{example}")
    array = as_array(values, name, expected)
    if rows is None:
        if array.ndim != 1:
            raise InvalidInput(f"{name} must be a sequence of numbers, got shape {array.shape}")
        if not np.isfinite(array).all():
            raise InvalidInput(f"{name} values must be finite, got {tuple(array.tolist())}")
        return array
    assert names is not None, "a batch needs the arm's redundancy names"
    if array.ndim == 1 and len(array) == r:
        array = array.reshape(1, -1)
    elif array.ndim == 1 and r == 1 and len(array) == rows:
        array = array[:, None]
    if array.ndim != 2 or array.shape[1] != r or len(array) not in (1, rows):
        raise InvalidInput(f"{name} must {rule}, got {np.shape(values)}")
    array = np.ascontiguousarray(np.broadcast_to(array, (rows, r)))
    bad = ~np.isfinite(array)
    if bad.any():
        row, col = np.argwhere(bad)[0]
        raise InvalidInput(f"{name} value {names[col]} is {array[row, col]} in row {row}")
    return array


def _finite(x: int | float) -> bool:
    """Whether a real number is finite as a float (an int beyond the float range is not)."""
    try:
        return math.isfinite(x)
    except OverflowError:
        return False


def as_vector(value: Any, size: int, name: str) -> np.ndarray:
    """``size`` finite real numbers (a point, half sizes) as a float64 array (size,)."""
    expected = f"{size} finite numbers"
    vector = as_array(value, name, expected)
    if vector.shape != (size,) or not np.isfinite(vector).all():
        raise InvalidInput(f"{name} must be {expected}, got {_describe(value)}")
    return vector


def as_quaternion(quat: Any, name: str = "quaternion") -> np.ndarray:
    """A unit quaternion (w, x, y, z) from four finite real numbers, normalised.

    The norm is taken after scaling by the largest entry, so that 1e300 in every entry
    normalises correctly (the plain norm overflows to inf).

    Raises:
        InvalidInput: Not 4 finite numbers, or a norm below :data:`MIN_QUATERNION_NORM` (1e-300
            in every entry included: no direction to keep).
    """
    quat = as_array(quat, name, "a quaternion (w, x, y, z)")
    if quat.shape != (4,):
        raise InvalidInput(f"{name} must be 4 numbers (w, x, y, z), got shape {quat.shape}")
    if not np.isfinite(quat).all():
        raise InvalidInput(f"{name} {numbers_text(quat)} is not finite")
    scale = float(np.abs(quat).max())
    unit = quat / scale if scale > 0.0 else quat
    length = float(np.linalg.norm(unit))
    if not scale * length >= MIN_QUATERNION_NORM:
        raise InvalidInput(f"{name} {numbers_text(quat)} has zero norm (below {MIN_QUATERNION_NORM:g})")
    return unit / length


def _describe(value: Any) -> str:
    """The value, short, with its type when the repr does not show it."""
    if value is None or isinstance(value, bool | np.bool_):
        return repr(value)
    text = repr(value)
    if len(text) > 60:
        text = text[:57] + "..."
    kind = type(value).__name__
    return f"{kind} {text}" if isinstance(value, str | bytes | int | float | complex) else f"a {kind}: {text}"


def numbers_text(values: np.ndarray) -> str:
    """Numbers for a message: ``(1, 0, nan)``."""
    return "(" + ", ".join(f"{v:g}" for v in values) + ")"
