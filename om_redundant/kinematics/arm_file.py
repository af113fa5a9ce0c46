"""Arm files (``arms/*.toml``) describe real arms in readable form; :func:`load_arm` reads one
by name or path and :func:`arm_names` lists the built-in ones. The file format::

    name = "ur5e"
    description = "Universal Robots UR5e"
    convention = "standard"        # or "modified" (Craig)

    [mujoco]                       # optional: the model this arm matches
    model = "universal_robots_ur5e/ur5e.xml"   # path under MuJoCo Menagerie
    frame = "wrist_3_link"
    frame_type = "body"            # "body" or "site"
    prefix = "l_"                  # optional: of the model's names of the joints (and frame)
    root = "torso"                 # optional: the body whose frame is the root frame; default the world

    [base]                         # pose of DH frame 0 in the arm's root frame
    xyz = [0, 0, 0]
    quat = [1, 0, 0, 0]            # w, x, y, z as in MJCF

    [tool]                         # pose of the end-effector frame in the last DH frame
    xyz = [0, 0, 0]
    quat = [1, 0, 0, 0]

    [[rows]]                       # one per DH row, in order
    joint = "shoulder_pan_joint"   # absent for a fixed row
    type = "revolute"              # revolute | prismatic | fixed
    a = 0.0                        # metres
    d = 0.163
    alpha_deg = 90.0               # degrees
    theta_deg = 0.0
    range = [-6.28319, 6.28319]    # radians (metres if prismatic); absent = unlimited

Units: metres for lengths and limits of prismatic joints, radians for revolute limits,
degrees for the DH angles (their key says so).

:func:`write_arm_file` writes an arm in this format (standard convention, numbers in full
precision), and :func:`load_arm` reads back the same arm bit for bit: rows, limits, names,
base and tool. That holds for every arm read from a file, and for arms whose angles and
transforms :func:`exact_angle` and :func:`exact_pose` made (an imported arm's;
:mod:`.poses`).
"""

from __future__ import annotations

import json
import math
import os
import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from ..exceptions import ArmFileError, InvalidInput, UnknownArm
from ..validation import as_instance, as_number
from .arm import Arm
from .chain import DHRow, JointKind, KinematicChain, standard_rows_from_modified
from .poses import file_xyz_quat, pose_from_xyz_quat


def arm_names() -> list[str]:
    """Names of the arms shipped with the package, in the order of the design card."""
    order = ["spherical", "ur5e", "panda", "fr3", "iiwa14", "gen3", "xarm7", "sawyer"]
    names = [p.name.removesuffix(".toml") for p in _arm_dir().iterdir() if p.name.endswith(".toml")]
    return sorted(names, key=lambda n: (order.index(n) if n in order else len(order), n))


def load_arm(name_or_path: str | Path) -> Arm:
    """Load an arm by built-in name (see :func:`arm_names`) or from a TOML arm file.

    Raises:
        UnknownArm: The name is neither a built-in arm nor an existing file.
        ArmFileError: The file is unreadable or malformed; the message names file, field and
            problem.
        InvalidInput: ``name_or_path`` is neither a string nor a path.
    """
    as_instance(name_or_path, str | os.PathLike, "arm", "an arm name or the path of an arm file")
    text_name = str(name_or_path)
    builtin = _arm_dir() / f"{text_name}.toml"
    if isinstance(name_or_path, str) and "/" not in text_name and not text_name.endswith(".toml"):
        if not builtin.is_file():
            raise UnknownArm(text_name, arm_names())
        return _parse(builtin.read_text(), str(builtin))
    path = Path(name_or_path)
    if not path.is_file():
        raise ArmFileError(str(path), "<file>", "no such file")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ArmFileError(str(path), "<file>", f"cannot read: {exc}") from None
    return _parse(text, str(path))


def _arm_dir() -> Any:
    return resources.files("om_redundant.arms")


# ---------------------------------------------------------------------------------------
# Parsing, strict: unknown keys are errors, so that a typo never silently means zero.

_REQUIRED = object()  # a field without a default
_TOP_KEYS = {"name", "description", "convention", "mujoco", "base", "tool", "rows"}
_ROW_KEYS = {"joint", "type", "a", "d", "alpha_deg", "theta_deg", "range"}


def _parse(text: str, path: str) -> Arm:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ArmFileError(path, "<file>", f"not valid TOML: {exc}") from None
    except RecursionError:  # arrays or tables nested thousands deep
        raise ArmFileError(path, "<file>", "not valid as an arm file: nested too deeply") from None
    f = _Fields(path)
    f.no_unknown(data, _TOP_KEYS, "")
    name = f.string(data, "name")
    convention = f.string(data, "convention")
    if convention not in ("standard", "modified"):
        raise ArmFileError(path, "convention", f"must be 'standard' or 'modified', got '{convention}'")
    raw_rows = data.get("rows")
    if not isinstance(raw_rows, list) or not raw_rows:
        raise ArmFileError(path, "rows", "must be a non-empty array of tables ([[rows]])")

    rows, joint_names, lower, upper = [], [], [], []
    for i, raw in enumerate(raw_rows):
        where = f"rows[{i}]"
        if not isinstance(raw, dict):
            raise ArmFileError(path, where, "must be a table")
        f.no_unknown(raw, _ROW_KEYS, where + ".")
        kind_text = f.string(raw, "type", where + ".")
        try:
            kind = JointKind(kind_text)
        except ValueError:
            raise ArmFileError(
                path, f"{where}.type", f"must be revolute, prismatic or fixed, got '{kind_text}'"
            ) from None
        row = DHRow(
            a=f.number(raw, "a", where + ".", 0.0),
            alpha=math.radians(f.number(raw, "alpha_deg", where + ".", 0.0)),
            d=f.number(raw, "d", where + ".", 0.0),
            theta=math.radians(f.number(raw, "theta_deg", where + ".", 0.0)),
            kind=kind,
        )
        rows.append(row)
        if kind is JointKind.FIXED:
            for key in ("joint", "range"):
                if key in raw:
                    raise ArmFileError(path, f"{where}.{key}", "a fixed row has no joint")
            continue
        joint_names.append(f.string(raw, "joint", where + "."))
        lo, hi = f.limits(raw, where)
        lower.append(lo)
        upper.append(hi)
    if len(set(joint_names)) != len(joint_names):
        raise ArmFileError(path, "rows", f"joint names repeat: {joint_names}")

    if convention == "modified":
        rows = standard_rows_from_modified(rows)
    mujoco = data.get("mujoco", {})
    if not isinstance(mujoco, dict):
        raise ArmFileError(path, "mujoco", "must be a table")
    f.no_unknown(mujoco, {"model", "frame", "frame_type", "prefix", "root"}, "mujoco.")
    frame_type = mujoco.get("frame_type")
    if frame_type not in (None, "body", "site"):
        raise ArmFileError(path, "mujoco.frame_type", f"must be 'body' or 'site', got '{frame_type}'")
    chain = KinematicChain(tuple(rows), f.transform(data, "base"), f.transform(data, "tool"))
    return Arm(
        name=name,
        chain=chain,
        joint_names=tuple(joint_names),
        lower=np.array(lower),
        upper=np.array(upper),
        description=f.string(data, "description", "", ""),
        mujoco_model=f.string(mujoco, "model", "mujoco.", None),
        frame_name=f.string(mujoco, "frame", "mujoco.", None),
        frame_type=frame_type,
        prefix=f.string(mujoco, "prefix", "mujoco.", ""),
        root=f.string(mujoco, "root", "mujoco.", None) or None,  # "" is the world too
        source=path,
    )


@dataclass
class _Fields:
    path: str

    def no_unknown(self, table: dict, allowed: set[str], prefix: str) -> None:
        for key in table:
            if key not in allowed:
                raise ArmFileError(self.path, prefix + key, f"unknown field; allowed: {sorted(allowed)}")

    def string(self, table: dict, key: str, prefix: str = "", default: Any = _REQUIRED) -> Any:
        if key not in table:
            if default is not _REQUIRED:
                return default
            raise ArmFileError(self.path, prefix + key, "missing")
        value = table[key]
        if not isinstance(value, str) or (not value and default is _REQUIRED):  # optional ones may be ""
            raise ArmFileError(self.path, prefix + key, f"must be a non-empty string, got {value!r}")
        return value

    def number(self, table: dict, key: str, prefix: str = "", default: float | None = None) -> float:
        if key not in table:
            if default is None:
                raise ArmFileError(self.path, prefix + key, "missing")
            return default
        try:
            return as_number(table[key], prefix + key)
        except InvalidInput as exc:
            raise ArmFileError(self.path, prefix + key, str(exc).removeprefix(prefix + key + " ")) from None

    def vector(self, table: dict, key: str, prefix: str, size: int, default: list[float]) -> np.ndarray:
        value = table.get(key, default)
        problem = f"must be {size} finite numbers, got {value!r}"
        if not isinstance(value, list) or len(value) != size:
            raise ArmFileError(self.path, prefix + key, problem)
        try:
            return np.array([as_number(v, prefix + key) for v in value])
        except InvalidInput:
            raise ArmFileError(self.path, prefix + key, problem) from None

    def limits(self, raw: dict, where: str) -> tuple[float, float]:
        if "range" not in raw:
            return -np.inf, np.inf
        lo, hi = self.vector(raw, "range", where + ".", 2, [])
        if not lo < hi:
            raise ArmFileError(self.path, f"{where}.range", f"lower limit {lo} must be below upper {hi}")
        return lo, hi

    def transform(self, data: dict, key: str) -> np.ndarray:
        table = data.get(key, {})
        if not isinstance(table, dict):
            raise ArmFileError(self.path, key, "must be a table with xyz and quat")
        self.no_unknown(table, {"xyz", "quat"}, key + ".")
        xyz = self.vector(table, "xyz", key + ".", 3, [0.0, 0.0, 0.0])
        quat = self.vector(table, "quat", key + ".", 4, [1.0, 0.0, 0.0, 0.0])
        try:
            return pose_from_xyz_quat(xyz, quat)
        except InvalidInput as exc:
            raise ArmFileError(self.path, key + ".quat", str(exc)) from None


# ---------------------------------------------------------------------------------------
# Writing: the same format, standard convention, numbers as shortest round-trip text.


def write_arm_file(arm: Arm, path: str | Path, comment: str = "") -> None:
    """Write the arm as an arm file that :func:`load_arm` reads back (see the module docstring).

    Args:
        arm: The arm.
        path: The file to write (overwritten).
        comment: Lines written first, each as a TOML comment.
    """
    Path(path).write_text(arm_file_text(arm, comment))


def arm_file_text(arm: Arm, comment: str = "") -> str:
    """The text :func:`write_arm_file` writes."""
    lines = [f"# {line}".rstrip() for line in comment.splitlines()]
    lines += [f"name = {_string(arm.name)}"]
    if arm.description:
        lines.append(f"description = {_string(arm.description)}")
    lines.append('convention = "standard"')
    fields = {
        "model": arm.mujoco_model,
        "frame": arm.frame_name,
        "frame_type": arm.frame_type,
        "prefix": arm.prefix,
        "root": arm.root,
    }
    if any(fields.values()):
        lines += ["", "[mujoco]"]
        lines += [f"{key} = {_string(value)}" for key, value in fields.items() if value]
    for key, T in (("base", arm.chain.T_root_base), ("tool", arm.chain.T_flange_tool)):
        xyz, quat = file_xyz_quat(T)
        lines += ["", f"[{key}]", f"xyz = {_numbers(xyz)}", f"quat = {_numbers(quat)}"]
    joint = 0
    for row in arm.chain.rows:
        lines += ["", "[[rows]]"]
        if row.is_joint:
            lines.append(f"joint = {_string(arm.joint_names[joint])}")
        lines.append(f"type = {_string(row.kind.value)}")
        for key, value in (("a", row.a), ("d", row.d)):
            if value != 0.0:
                lines.append(f"{key} = {value!r}")
        for key, value in (("alpha_deg", row.alpha), ("theta_deg", row.theta)):
            if value != 0.0:
                lines.append(f"{key} = {math.degrees(value)!r}")
        if row.is_joint:
            if np.isfinite(arm.lower[joint]) and np.isfinite(arm.upper[joint]):
                lines.append(f"range = {_numbers([arm.lower[joint], arm.upper[joint]])}")
            joint += 1
    return "\n".join(lines) + "\n"


def _string(text: str) -> str:
    """A TOML basic string (JSON's escapes are TOML's)."""
    return json.dumps(text, ensure_ascii=False)


def _numbers(values: Any) -> str:
    return "[" + ", ".join(repr(float(v)) for v in values) + "]"
