"""``om-redundant import-arm``: an arm file from a MuJoCo model (MJCF or URDF)."""

from __future__ import annotations

import argparse

from ..exceptions import ModelError
from ..ik.solver import OMSolver
from ..kinematics import write_arm_file
from ..mujoco_io.arm_import import IMPORT_TOLERANCE, arm_from_mujoco
from ..mujoco_io.loading import load_mujoco_model
from ..mujoco_io.model_match import compare_mujoco_model
from .common import add_output_options, check_output_path, table_wanted, write_json


def add_parser(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser(
        "import-arm",
        help="write the arm file of a MuJoCo model (MJCF or URDF): DH rows, limits, names",
        description="Derive an arm file from a MuJoCo model: the hinge and slide joints from the root "
        "body (default the world) to the end-effector frame become standard DH rows (joint axes and "
        "anchors at q = 0), with their names and limits, base and tool transforms and the model and "
        "frame the arm matches. Missing mesh and texture files are skipped; a URDF is read by MuJoCo's "
        "URDF loader. The arm is checked against the model (to 1e-12 m and rad, as check-model does), "
        "and the OM solver is tried on it: the output says whether it accepts the arm or why not. "
        "Exits 0 when the file is written.",
    )
    parser.add_argument("model", metavar="MODEL.xml|MODEL.urdf", help="the MuJoCo model file")
    parser.add_argument("--frame", required=True, metavar="NAME", help="end-effector site or body")
    parser.add_argument(
        "--frame-type", choices=("site", "body"), default="site", help="what --frame names (default site)"
    )
    parser.add_argument(
        "--prefix",
        default="",
        help="prefix of the model's joint names (and of the frame's, if it has it), left out of the arm's "
        "names and kept in the file ([mujoco] prefix)",
    )
    parser.add_argument(
        "--root",
        metavar="BODY",
        help="body whose frame is the arm's root frame, where its chain starts (below a torso or a mobile "
        "base); default the world; kept in the file ([mujoco] root)",
    )
    parser.add_argument("--name", help="the arm's name; default the model file's stem")
    parser.add_argument("-o", "--output", required=True, metavar="ARM.toml", help="the arm file to write")
    add_output_options(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    check_output_path(args.output, "--output", (".toml",))
    arm = arm_from_mujoco(args.model, args.frame, args.frame_type, args.prefix, args.root, name=args.name)
    match = compare_mujoco_model(arm, load_mujoco_model(args.model), tolerance=IMPORT_TOLERANCE)
    try:
        family, reason = OMSolver(arm).model_arm.family_name, None
    except ModelError as exc:
        family, reason = None, str(exc).removeprefix(f"arm '{arm.name}': ")
    write_arm_file(arm, args.output, f"Written by om-redundant import-arm from {args.model}.")
    if args.json is not None:
        write_json(
            {
                "arm": arm.name,
                "file": args.output,
                "dof": arm.dof,
                "joint_names": arm.joint_names,
                "prefix": arm.prefix,
                "root": arm.root,
                "frame": match.frame,
                "max_position_error": match.max_position_error,
                "max_orientation_error": match.max_orientation_error,
                "solver_accepts": reason is None,
                "model_family": family,
                "reason": reason,
            },
            args.json,
        )
    if table_wanted(args):
        print(
            f"wrote {args.output}: arm '{arm.name}', {arm.dof} joints ({', '.join(arm.joint_names)}) to "
            f"{match.frame}; matches the model over {match.samples} random joint vectors to "
            f"{match.max_position_error:.1e} m, {match.max_orientation_error:.1e} rad"
        )
        print(f"OMSolver: {'accepts it (' + family + ')' if reason is None else 'refuses it: ' + reason}")
    return 0
