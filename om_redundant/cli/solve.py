"""``om-redundant solve``: one pose in one configuration or all, and the default run."""

from __future__ import annotations

import argparse

import mujoco
import numpy as np

from ..ik.configuration import Configuration
from ..ik.solver import OMSolver, Solution
from .common import (
    UsageError,
    add_arm_option,
    add_output_options,
    add_pose_options,
    add_signs_option,
    finite,
    parse_signs,
    table_wanted,
    target_pose,
    write_json,
)

DEFAULT_ARM = "ur5e"
NO_SOLUTION = "no solution in this configuration"


def add_parser(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser(
        "solve",
        help="solve one pose in one configuration or all, print q",
        description="Solve one pose exactly, in one configuration or in all branch-sign combinations, and "
        "print the joint vectors, statuses, errors and whether they are within the limits. "
        "Without arguments: the UR5e's built-in pose in all eight configurations.",
    )
    add_arm_option(parser, DEFAULT_ARM)
    add_pose_options(parser)
    add_signs_option(parser, "default: every combination")
    parser.add_argument(
        "--psi", type=float, metavar="RAD", help="arm angle of a 7-DOF arm, in radians (default 0)"
    )
    parser.add_argument(
        "--all-roots",
        action="store_true",
        help="every solution in each configuration (the bounded search), not only the preferred one",
    )
    add_output_options(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    solver = OMSolver(args.arm)
    T = target_pose(args, solver.arm)
    signs = parse_signs(args.signs, solver)
    redundancy: tuple[float, ...] = ()
    if solver.redundancy_names:
        redundancy = (finite(0.0 if args.psi is None else args.psi, "--psi"),)
    elif args.psi is not None:
        raise UsageError(f"arm '{solver.arm.name}' has no arm angle ({solver.arm.dof} joints); drop --psi")
    if signs is None:
        configurations = solver.configurations(redundancy)
    else:
        configurations = [Configuration(signs, redundancy)]
    rows = []
    for c in configurations:
        if args.all_roots:
            found = solver.solve_all(T, c)
            rows += [_row(s) for s in found] or [_no_solution(c)]
        else:
            rows.append(_row(solver.solve(T, c)))
    result = {
        "arm": solver.arm.name,
        "description": solver.arm.description,
        "model_family": solver.model_arm.family_name,
        "dp_max": solver.dp_max,
        "target": T,
        "sign_names": solver.sign_names,
        "redundancy_names": solver.redundancy_names,
        "joint_names": solver.arm.joint_names,
        "solutions": rows,
    }
    if table_wanted(args):
        print(_table(solver, T, redundancy, rows))
    if args.json is not None:
        write_json(result, args.json)
    return 0


def _row(sol: Solution) -> dict:
    return {
        "signs": sol.configuration.signs,
        "redundancy": sol.configuration.redundancy,
        "ok": sol.ok,
        "status": sol.status,
        "q": sol.q if sol.ok else None,
        "position_error": sol.position_error if sol.ok else None,
        "orientation_error": sol.orientation_error if sol.ok else None,
        "within_limits": sol.within_limits if sol.ok else None,
    }


def _no_solution(c: Configuration) -> dict:
    return {
        "signs": c.signs,
        "redundancy": c.redundancy,
        "ok": False,
        "status": NO_SOLUTION,
        "q": None,
        "position_error": None,
        "orientation_error": None,
        "within_limits": None,
    }


def _table(solver: OMSolver, T: np.ndarray, redundancy: tuple[float, ...], rows: list[dict]) -> str:
    quat = np.empty(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(T[:3, :3]).ravel())
    lines = [
        f"arm: {solver.arm.name} ({solver.arm.description})",
        f"model: {solver.model_arm.family_name}, dp_max = {solver.dp_max:.4f} m",
        f"target: xyz = {_vector(T[:3, 3])} m, quat = {_vector(quat)}",
    ]
    lines += [
        f"{name} = {value:.6f} rad" for name, value in zip(solver.redundancy_names, redundancy, strict=True)
    ]
    widths = [max(len(n), 2) for n in solver.sign_names]
    names = " ".join(f"{n:>{w}}" for n, w in zip(solver.sign_names, widths, strict=True))
    joints = " ".join(f"{j[:10]:>10}" for j in solver.arm.joint_names)
    lines.append(f"\n{names}  {'status':<34} {joints}  {'pos err':>8} {'ori err':>8}  limits")
    for row in rows:
        signs = " ".join(f"{s:>+{w}d}" for s, w in zip(row["signs"], widths, strict=True))
        if row["ok"]:
            q = " ".join(f"{v:>10.5f}" for v in row["q"])
            errors = f"{row['position_error']:8.1e} {row['orientation_error']:8.1e}"
            inside = "in" if row["within_limits"] else "OUT"
        else:
            q = " ".join(f"{'-':>10}" for _ in solver.arm.joint_names)
            errors, inside = f"{'-':>8} {'-':>8}", "-"
        lines.append(f"{signs}  {row['status']:<34} {q}  {errors}  {inside}")
    return "\n".join(lines)


def _vector(values: np.ndarray) -> str:
    return "[" + ", ".join(f"{v:.6f}" for v in values) + "]"
