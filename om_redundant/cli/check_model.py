"""``om-redundant check-model``: is a user's MuJoCo model this arm?"""

from __future__ import annotations

import argparse

from ..kinematics import load_arm
from ..mujoco_io.loading import load_mujoco_model
from ..mujoco_io.model_match import DEFAULT_TOLERANCE, compare_mujoco_model
from .common import Failed, add_arm_option, add_output_options, table_wanted, write_json


def add_parser(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser(
        "check-model",
        help="compare a MuJoCo model with an arm file, name the joint or frame that differs",
        description="Compare a MuJoCo model (MJCF) with an arm: joint names, types, order and limits, "
        "then each joint's axis and the end-effector frame against the arm's forward kinematics over "
        "random joint vectors. Exits 0 if they match within the tolerance, 1 with a one-line reason "
        "if not. Missing mesh and texture files are skipped (kinematics do not need them).",
    )
    parser.add_argument("model", metavar="MODEL.xml|MODEL.urdf", help="the MuJoCo model file")
    add_arm_option(parser, None, required=True)
    parser.add_argument(
        "--site",
        metavar="NAME",
        help="end-effector site (or body) in the model, as given or with the prefix; default the arm "
        "file's frame",
    )
    parser.add_argument(
        "--prefix", help="prefix of the model's joint (and frame) names; default the arm file's ([mujoco])"
    )
    parser.add_argument(
        "--root",
        metavar="BODY",
        help="body whose frame is the arm's root frame; default the arm file's ([mujoco]), else the world",
    )
    parser.add_argument(
        "--samples", type=int, default=100, help="random joint vectors compared (default 100)"
    )
    parser.add_argument("--seed", type=int, default=0, help="seed of the random joint vectors")
    parser.add_argument(
        "--tolerance",
        type=float,
        default=DEFAULT_TOLERANCE,
        help=f"largest accepted difference, m and rad (default {DEFAULT_TOLERANCE:g})",
    )
    add_output_options(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    arm = load_arm(args.arm)
    model = load_mujoco_model(args.model)
    result = compare_mujoco_model(
        arm,
        model,
        frame=args.site,
        prefix=args.prefix,
        root=args.root,
        samples=args.samples,
        seed=args.seed,
        tolerance=args.tolerance,
    )
    if args.json is not None:
        write_json(
            {
                "model": args.model,
                "arm": arm.name,
                "ok": result.ok,
                "differences": result.differences,
                "frame": result.frame,
                "samples": result.samples,
                "max_axis_error": result.max_axis_error,
                "max_anchor_error": result.max_anchor_error,
                "max_position_error": result.max_position_error,
                "max_orientation_error": result.max_orientation_error,
            },
            args.json,
        )
    if not result.ok:
        raise Failed(f"{args.model} differs from arm '{arm.name}': {result.differences[0]}")
    if table_wanted(args):
        print(
            f"{args.model} matches arm '{arm.name}': {arm.dof} joints (names, types, order, limits, axes) "
            f"and {result.frame} over {result.samples} random joint vectors; max error "
            f"{result.max_position_error:.1e} m, {result.max_orientation_error:.1e} rad"
        )
    return 0
