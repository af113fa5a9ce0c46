"""``om-redundant arms``: the arms, their model families and dp_max."""

from __future__ import annotations

import argparse

from ..exceptions import ModelError
from ..ik.solver import OMSolver
from ..kinematics import arm_names, load_arm
from .common import add_output_options, table_wanted, write_json


def add_parser(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser(
        "arms",
        help="list the arms, their model families and dp_max",
        description="List the built-in arms: joints, the closed-form model family the OM method uses, "
        "dp_max (the radius that bounds the search), the configuration's branch signs and redundancy "
        "values, or why an arm cannot be solved yet.",
    )
    parser.add_argument(
        "names", nargs="*", metavar="ARM", help="arm names or arm files (default: all built-in)"
    )
    add_output_options(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    rows = [_describe(name) for name in (args.names or arm_names())]
    if table_wanted(args):
        print(_table(rows))
    if args.json is not None:
        write_json(rows, args.json)
    return 0


def _describe(name: str) -> dict:
    arm = load_arm(name)
    row = {
        "name": arm.name,
        "description": arm.description,
        "dof": arm.dof,
        "joint_names": arm.joint_names,
        "lower": arm.lower,
        "upper": arm.upper,
        "mujoco_model": arm.mujoco_model,
        "frame": arm.frame_name,
        "solvable": True,
        "reason": None,
    }
    try:
        model = OMSolver(arm).model_arm  # the solver's acceptance: a closed-form model that solves the arm
    except ModelError as exc:
        reason = str(exc).removeprefix(f"arm '{arm.name}': ")
        return (
            row
            | dict.fromkeys(("model_family", "dp_max", "sign_names", "redundancy_names"))
            | {
                "solvable": False,
                "reason": reason,
            }
        )
    return row | {
        "model_family": model.family_name,
        "dp_max": model.dp_max,
        "sign_names": model.sign_names,
        "redundancy_names": model.redundancy_names,
    }


def _table(rows: list[dict]) -> str:
    lines = [f"{'arm':<10} {'dof':>3}  {'dp_max':>8}  {'configuration':<28} model family"]
    for row in rows:
        if row["solvable"]:
            c = " ".join(row["sign_names"] + row["redundancy_names"])
            lines.append(
                f"{row['name']:<10} {row['dof']:>3}  {row['dp_max']:>6.4f} m  {c:<28} {row['model_family']}"
            )
        else:
            lines.append(
                f"{row['name']:<10} {row['dof']:>3}  {'-':>8}  {'-':<28} not yet solvable: {row['reason']}"
            )
    return "\n".join(lines)
