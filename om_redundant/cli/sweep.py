"""``om-redundant sweep``: the arm angle psi of a 7-DOF arm swept for a pose or a path.

The command reads and checks its input here (arm, pose or path of poses, branches, obstacles,
scene, resolution, output files) into a :class:`~om_redundant.redundancy.sweep.SweepRequest`,
and hands it to :func:`~om_redundant.redundancy.sweep.compute_sweep`, which returns a
:class:`~om_redundant.redundancy.sweep.SweepResult`: joint angles, normalised joint-limit
margins (:func:`~om_redundant.joint_margins`) and clearance along the psi grid, and from the
redundancy optimiser (:class:`~om_redundant.RedundancyOptimizer`) the feasible intervals
(exact ends) and its choice. :mod:`~om_redundant.cli.sweep_output` shows the result (table,
CSV, JSON, plots).
"""

from __future__ import annotations

import argparse
import csv
import math
import sys

import numpy as np

from ..ik.configuration import Configuration
from ..ik.solver import OMSolver
from ..mujoco_io.loading import load_mujoco_model
from ..redundancy.objective.terms import DEFAULT_SINGULARITY_WEIGHT
from ..redundancy.sweep import SHAPES, Obstacle, SweepRequest, compute_sweep
from .common import (
    UsageError,
    add_arm_option,
    add_output_options,
    add_pose_options,
    add_signs_option,
    check_output_path,
    parse_signs,
    pose_from_text,
    target_pose,
)
from .sweep_output import show

DEFAULT_ARM = "panda"
DEFAULT_RESOLUTION = 2.0 * math.pi / 360.0  # rad: 360 arm angles
MAX_SAMPLES = 100_000  # arm angles per branch and pose
PLOT_SUFFIXES = (".png", ".svg")
PATH_COLUMNS = ("x", "y", "z", "qw", "qx", "qy", "qz")
#: The run without a command: the Panda's built-in pose with a ball beside its elbow.
DEFAULT_RUN = ("sweep", "--obstacle", "sphere:0.2,0.12,0.6,0.05")

SIZES = {"r", "hx", "hy", "hz"}  # must be positive
SHAPE_USAGE = ", ".join(f"{kind}:{','.join(names)}" for kind, names in SHAPES.items())


def add_parser(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser(
        "sweep",
        help="sweep the arm angle psi of a 7-DOF arm for a pose or a path",
        description="Sweep the arm angle psi of a 7-DOF arm for a pose (or each pose of a path): which "
        "psi intervals and branches reach it within the joint limits and clear of obstacles, how close "
        "each joint comes to its limit, and which psi the optimiser picks. Prints a table; writes CSV, "
        "JSON and a plot on request.",
    )
    add_arm_option(parser, DEFAULT_ARM)
    add_pose_options(parser)
    parser.add_argument(
        "--path",
        metavar="POSES.csv",
        help="sweep a path: a CSV of poses, columns " + ",".join(PATH_COLUMNS) + " (header optional)",
    )
    add_signs_option(parser, "default: every combination")
    parser.add_argument(
        "--obstacle",
        action="append",
        default=[],
        metavar="SHAPE",
        help=f"an obstacle in the arm's root frame (m), repeatable: {SHAPE_USAGE} "
        "(box: centre and half-sizes, axis-aligned)",
    )
    parser.add_argument("--scene", metavar="FILE.xml", help="MuJoCo scene whose geoms are obstacles")
    parser.add_argument(
        "--singularity-weight",
        type=float,
        default=DEFAULT_SINGULARITY_WEIGHT,
        metavar="W",
        help="weight of the optimiser's distance from the wrist, elbow and shoulder singularities "
        f"(0: ignore them; default {DEFAULT_SINGULARITY_WEIGHT:g}, the joint-limit margin's is 1)",
    )
    parser.add_argument(
        "--resolution",
        type=float,
        default=DEFAULT_RESOLUTION,
        metavar="RAD",
        help=f"psi step in radians (default 2 pi / 360 = {DEFAULT_RESOLUTION:.4f})",
    )
    parser.add_argument(
        "--csv", nargs="?", const="-", metavar="FILE", help="write the sweep as CSV (- : stdout)"
    )
    parser.add_argument(
        "--plot",
        metavar="FILE",
        help="write a plot (.png or .svg): joint angles and clearance against psi for a pose, "
        "a map of pose index against psi for a path",
    )
    add_output_options(parser, "write the sweep as JSON to FILE, or to standard output instead of the table")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    request = build_request(args)
    show(request, compute_sweep(request), args)
    return 0


def build_request(args: argparse.Namespace) -> SweepRequest:
    """Check every input and output of the command, before any computation."""
    solver = OMSolver(args.arm)
    if solver.redundancy_names != ("psi",):
        raise UsageError(
            f"arm '{solver.arm.name}' has no arm angle to sweep ({solver.arm.dof} joints); "
            "use 'om-redundant solve'"
        )
    psi = psi_grid(args.resolution)
    if not (math.isfinite(args.singularity_weight) and args.singularity_weight >= 0.0):
        raise UsageError(f"--singularity-weight must be a finite number >= 0, got {args.singularity_weight}")
    branches = parse_signs(args.signs, solver)
    obstacles = tuple(parse_obstacle(text) for text in args.obstacle)
    if args.path is not None:
        if args.xyz is not None or args.quat is not None or args.pose_file is not None:
            raise UsageError("give either --path or a single pose (--xyz/--quat or --pose-file), not both")
        poses = read_path(args.path)
    else:
        poses = target_pose(args, solver.arm)[None]
    scene = None if args.scene is None else load_mujoco_model(args.scene)
    if args.csv == "-" and args.json == "-":
        raise UsageError("--csv and --json cannot both go to standard output")
    check_output_path(args.csv, "--csv")
    check_output_path(args.json, "--json")
    check_output_path(args.plot, "--plot", PLOT_SUFFIXES)
    all_signs = tuple(c.signs for c in Configuration.all_signs(len(solver.sign_names)))
    return SweepRequest(
        solver=solver,
        poses=poses,
        path=args.path is not None,
        branches=all_signs if branches is None else (branches,),
        psi=psi,
        obstacles=obstacles,
        scene=scene,
        singularity_weight=args.singularity_weight,
        progress=Progress(len(poses), enabled=args.path is not None and not getattr(args, "quiet", False)),
    )


def psi_grid(resolution: float) -> np.ndarray:
    """Arm angles -pi, -pi + step, ... below pi, the step at most ``resolution``."""
    if not math.isfinite(resolution) or resolution <= 0.0:
        raise UsageError(f"--resolution must be a positive number of radians, got {resolution}")
    n = max(math.ceil(2.0 * math.pi / resolution - 1e-9), 1)
    if n > MAX_SAMPLES:
        raise UsageError(f"--resolution {resolution:g} rad gives {n} arm angles; the most is {MAX_SAMPLES}")
    return -math.pi + 2.0 * math.pi * np.arange(n) / n


def parse_obstacle(text: str) -> Obstacle:
    """An obstacle from ``shape:n1,n2,...``; the message names the option, shape and number."""
    where = f"--obstacle '{text}'"
    kind, colon, numbers = text.partition(":")
    kind = kind.strip().lower()
    if kind not in SHAPES or not colon:
        raise UsageError(f"{where}: unknown shape '{kind}'; use {SHAPE_USAGE}")
    names = SHAPES[kind]
    parts = [p.strip() for p in numbers.split(",")] if numbers.strip() else []
    if len(parts) != len(names):
        raise UsageError(f"{where}: a {kind} takes {len(names)} numbers {','.join(names)}, got {len(parts)}")
    values = []
    for name, part in zip(names, parts, strict=True):
        try:
            value = float(part)
        except ValueError:
            raise UsageError(f"{where}: {name} = '{part}' is not a number") from None
        if not math.isfinite(value):
            raise UsageError(f"{where}: {name} = {part} is not finite")
        if name in SIZES and value <= 0.0:
            raise UsageError(f"{where}: {name} must be positive, got {value:g}")
        values.append(value)
    if kind == "capsule" and values[:3] == values[3:6]:
        raise UsageError(f"{where}: the capsule's ends coincide; use a sphere")
    return Obstacle(kind, tuple(values))


def read_path(path: str) -> np.ndarray:
    """(M, 4, 4) poses from a CSV file of x,y,z,qw,qx,qy,qz rows.

    A header row, if present, names the columns (in any order; other columns are ignored);
    without one the rows hold exactly those seven numbers. Blank lines and lines starting
    with ``#`` are skipped.
    """
    name = f"path file '{path}'"
    try:
        with open(path, newline="") as f:
            lines = [
                (n, row)
                for n, row in enumerate(csv.reader(f), start=1)
                if row and any(c.strip() for c in row) and not row[0].lstrip().startswith("#")
            ]
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise UsageError(f"cannot read {name}: {getattr(exc, 'strerror', None) or exc}") from None
    header = lines and not _is_number(lines[0][1][0])
    if header:
        names = [c.strip().lower() for c in lines[0][1]]
        missing = [c for c in PATH_COLUMNS if c not in names]
        if missing:
            raise UsageError(f"{name}: the header lacks column(s) {', '.join(missing)}")
        columns = [names.index(c) for c in PATH_COLUMNS]
        width = len(names)
        lines = lines[1:]
    else:
        columns, width = list(range(len(PATH_COLUMNS))), len(PATH_COLUMNS)
    if not lines:
        raise UsageError(f"{name} holds no poses")
    poses = np.empty((len(lines), 4, 4))
    for i, (n, row) in enumerate(lines):
        where = f"{name} line {n}"
        if len(row) != width:
            raise UsageError(f"{where}: expected {width} values, got {len(row)}")
        try:
            values = [float(row[c]) for c in columns]
        except ValueError:
            raise UsageError(f"{where}: not a number in {','.join(row)}") from None
        poses[i] = pose_from_text(values[:3], values[3:], f"{where}: position", f"{where}: quaternion")
    return poses


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


class Progress:
    """A one-line progress bar on standard error, for paths on a terminal."""

    def __init__(self, total: int, enabled: bool = True, width: int = 30):
        self.total, self.width = total, width
        self.enabled = enabled and total > 1 and sys.stderr.isatty()

    def __call__(self, done: int) -> None:
        if not self.enabled:
            return
        filled = self.width * done // self.total
        sys.stderr.write(f"\rsweep [{'#' * filled}{'.' * (self.width - filled)}] {done}/{self.total} poses")
        if done >= self.total:
            sys.stderr.write("\n")
        sys.stderr.flush()
