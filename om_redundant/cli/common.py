"""What the subcommands share: options, input checks that name the problem, JSON output."""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

from ..exceptions import InvalidInput, OMError
from ..ik.solver import OMSolver
from ..kinematics import Arm, arm_names, pose_from_xyz_quat
from ..validation import as_pose, as_signs, numbers_text

#: Joint vectors whose forward kinematics is the built-in target, by number of joints;
#: clipped into each arm's limits (the UR5e pose of the README; the Panda's for 7-DOF arms).
DEFAULT_Q = {
    6: (0.4, -1.1, 1.3, -1.2, -1.4, 0.3),
    7: (0.2, 0.4, -0.3, -1.8, 0.5, 1.9, 0.6),
}


class UsageError(OMError, ValueError):
    """Bad input on the command line: the command prints one line and exits with 2."""


class Failed(OMError):
    """The input was fine but the answer is no (a model that differs, a feature not built yet):
    the command prints one line and exits with 1."""


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (an exception the command prints)."""

    def error(self, message: str):
        raise UsageError(f"{message} (see '{self.prog} --help')")


def add_output_options(parser: argparse.ArgumentParser, json_help: str | None = None) -> None:
    """``--quiet`` and ``--json [FILE]`` (FILE ``-`` or absent: standard output)."""
    parser.add_argument(
        "-q",
        "--quiet",
        action="store_true",
        default=argparse.SUPPRESS,
        help="print no table or progress; errors, and JSON if asked for, still appear",
    )
    parser.add_argument(
        "--json",
        nargs="?",
        const="-",
        metavar="FILE",
        help=json_help or "write the result as JSON to FILE, or to standard output instead of the table",
    )


def add_arm_option(parser: argparse.ArgumentParser, default: str | None, required: bool = False) -> None:
    parser.add_argument(
        "--arm",
        default=default,
        required=required,
        help=f"arm name ({', '.join(arm_names())}) or path of an arm file (.toml)"
        + (f"; default {default}" if default else ""),
    )


def add_pose_options(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("target pose (default: a built-in pose of the arm)")
    group.add_argument("--xyz", type=float, nargs=3, metavar=("X", "Y", "Z"), help="position (m)")
    group.add_argument(
        "--quat",
        type=float,
        nargs=4,
        metavar=("W", "X", "Y", "Z"),
        help="orientation quaternion (normalised)",
    )
    group.add_argument(
        "--pose-file",
        metavar="FILE",
        help="4x4 homogeneous transform: a text file of 4 rows of 4 numbers, or a .npy file",
    )


def add_signs_option(parser: argparse.ArgumentParser, what: str) -> None:
    parser.add_argument(
        "--signs",
        type=int,
        nargs="+",
        metavar="S",
        help=f"branch signs, each -1 or +1, e.g. 1 -1 1 (ARM ELBOW WRIST or SHOULDER ELBOW WRIST); {what}",
    )


def default_q(arm: Arm) -> np.ndarray:
    """The joint vector of the built-in target pose, within the arm's limits."""
    q = np.array(DEFAULT_Q.get(arm.dof, (0.0,) * arm.dof), dtype=np.float64)
    return np.clip(q, arm.lower, arm.upper)


def target_pose(args: argparse.Namespace, arm: Arm) -> np.ndarray:
    """The pose given by --xyz/--quat or --pose-file, else the arm's built-in pose."""
    if args.pose_file is not None:
        if args.xyz is not None or args.quat is not None:
            raise UsageError("give either --pose-file or --xyz and --quat, not both")
        return read_pose_file(args.pose_file)
    if args.xyz is None and args.quat is None:
        return arm.fk(default_q(arm))
    if args.xyz is None or args.quat is None:
        raise UsageError("give both --xyz and --quat")
    return pose_from_text(args.xyz, args.quat, "--xyz", "--quat")


def pose_from_text(xyz, quat, xyz_name: str, quat_name: str) -> np.ndarray:
    """:func:`~om_redundant.kinematics.poses.pose_from_xyz_quat` of numbers read from the command line or a
    file, an error naming them and the problem (a quaternion that is not finite, has zero norm,
    ...: :func:`~om_redundant.validation.as_quaternion`)."""
    xyz = np.asarray(xyz, dtype=np.float64)
    if not np.isfinite(xyz).all():
        raise UsageError(f"{xyz_name} {numbers_text(xyz)} is not finite")
    try:
        return pose_from_xyz_quat(xyz, quat, quat_name)
    except InvalidInput as exc:
        raise UsageError(str(exc)) from None


def read_pose_file(path: str) -> np.ndarray:
    """A 4x4 pose from a text file (4 rows of 4 numbers) or a .npy file, validated."""
    name = f"pose file '{path}'"
    if not Path(path).is_file():
        raise UsageError(f"cannot read {name}: no such file")
    try:
        if path.endswith(".npy"):
            T = np.load(path, allow_pickle=False)
        else:
            T = np.loadtxt(path, ndmin=2)
    except (OSError, ValueError, EOFError) as exc:  # EOFError: an empty or cut-off .npy file
        raise UsageError(f"cannot read {name}: {' '.join(str(exc).split())}") from None
    if T.shape != (4, 4):
        raise UsageError(f"{name} must hold a 4x4 matrix, got shape {T.shape}")
    return as_pose(T, name)


def parse_signs(signs: list[int] | None, solver: OMSolver) -> tuple[int, ...] | None:
    """--signs checked against the arm: one value per branch, each -1 or +1."""
    if signs is None:
        return None
    names = solver.sign_names
    if len(signs) != len(names):
        raise UsageError(f"--signs needs {len(names)} values ({' '.join(names)}), got {len(signs)}")
    return tuple(as_signs(signs, len(names), "--signs").tolist())


def finite(value: float, option: str) -> float:
    if not math.isfinite(value):
        raise UsageError(f"{option} must be a finite number, got {value}")
    return value


def check_output_path(path: str | None, option: str, suffixes: tuple[str, ...] = ()) -> None:
    """Fail before any work if an output file cannot be written where asked."""
    if path is None or path == "-":
        return
    target = Path(path)
    if suffixes and target.suffix.lower() not in suffixes:
        raise UsageError(f"{option} '{path}': use a file ending in {' or '.join(suffixes)}")
    if target.is_dir():
        raise UsageError(f"{option} '{path}' is a directory")
    if not target.parent.is_dir():
        raise UsageError(f"{option} '{path}': directory '{target.parent}' does not exist")


def jsonable(value: Any) -> Any:
    """Numbers, arrays and containers as JSON values; NaN and infinities become null."""
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    return value


def write_json(data: Any, destination: str) -> None:
    """JSON to a file, or to standard output for ``-``."""
    text = json.dumps(jsonable(data), indent=2, allow_nan=False) + "\n"
    if destination == "-":
        sys.stdout.write(text)
    else:
        Path(destination).write_text(text)


def table_wanted(args: argparse.Namespace) -> bool:
    """Print the human-readable table: not --quiet, and standard output not taken by JSON."""
    return not getattr(args, "quiet", False) and getattr(args, "json", None) != "-"
