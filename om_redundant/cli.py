"""The ``om-redundant`` command.

Without arguments it solves a built-in pose of the UR5e in all eight configurations.
``om-redundant solve`` solves a pose given on the command line; ``om-redundant bench
paper`` runs the OM paper's experiment.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from .arm import arm_names, rotation_from_quat
from .configuration import Configuration
from .exceptions import OMError
from .solver import OMSolver

DEFAULT_ARM = "ur5e"
DEFAULT_Q = (0.4, -1.1, 1.3, -1.2, -1.4, 0.3)  # the default target is fk(DEFAULT_Q)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="om-redundant",
        description="Exact inverse kinematics with configuration control (offset modification method).",
    )
    sub = parser.add_subparsers(dest="command")
    solve = sub.add_parser("solve", help="solve one pose in one or all configurations")
    solve.add_argument("--arm", default=DEFAULT_ARM, help=f"arm name ({', '.join(arm_names())}) or arm file")
    solve.add_argument("--xyz", type=float, nargs=3, metavar=("X", "Y", "Z"), help="target position (m)")
    solve.add_argument("--quat", type=float, nargs=4, metavar=("W", "X", "Y", "Z"), help="target orientation")
    solve.add_argument("--signs", type=int, nargs="+", help="branch signs, e.g. 1 -1 1 (default: all)")
    bench = sub.add_parser("bench", help="benchmarks")
    bench.add_argument("name", choices=["paper"], help="paper: the OM paper's experiment")
    bench.add_argument("--arm", default="spherical", choices=["spherical", "ur5e"])
    bench.add_argument("--n", type=int, default=100_000, help="number of targets")
    bench.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    try:
        if args.command == "bench":
            return _bench(args)
        if args.command == "solve":
            return _solve(args.arm, args.xyz, args.quat, args.signs)
        return _solve(DEFAULT_ARM, None, None, None)
    except (OMError, ValueError) as exc:
        print(f"om-redundant: error: {exc}", file=sys.stderr)
        return 2


def _solve(arm: str, xyz, quat, signs) -> int:
    solver = OMSolver(arm)
    if xyz is None and quat is None:
        T = solver.arm.fk(np.array(DEFAULT_Q[: solver.arm.dof]))
    else:
        if xyz is None or quat is None:
            raise ValueError("give both --xyz and --quat")
        norm = np.linalg.norm(quat)
        if not np.isfinite(norm) or norm < 1e-9:
            raise ValueError(f"quaternion {quat} has zero norm")
        T = np.eye(4)
        T[:3, :3] = rotation_from_quat(np.asarray(quat) / norm)
        T[:3, 3] = xyz
    configurations = solver.configurations() if signs is None else [Configuration(tuple(signs))]
    print(f"arm: {solver.arm.name} ({solver.arm.description})")
    print(f"model: {solver.om.family_name}, dp_max = {solver.dp_max:.4f} m")
    print(f"target: xyz = {np.round(T[:3, 3], 6).tolist()} m")
    names = " ".join(f"{n:>5}" for n in solver.sign_names)
    joints = " ".join(f"{j[:10]:>10}" for j in solver.arm.joint_names)
    print(f"\n{names}  {'status':<34} {joints}  {'pos err':>8}  limits")
    for c in configurations:
        sol = solver.solve(T, c)
        signs_text = " ".join(f"{s:>+5d}" for s in c.signs)
        q_text = " ".join(f"{v:>10.5f}" for v in sol.q)
        err = f"{sol.position_error:8.1e}" if sol.ok else f"{'-':>8}"
        inside = ("in" if sol.within_limits else "OUT") if sol.ok else "-"
        print(f"{signs_text}  {sol.status:<34} {q_text}  {err}  {inside}")
    return 0


def _bench(args) -> int:
    from .paper_experiment import run

    if args.n < 1:
        raise ValueError(f"--n must be positive, got {args.n}")
    result = run(args.arm, args.n, args.seed)
    print(result.table())
    return 0


if __name__ == "__main__":
    sys.exit(main())
