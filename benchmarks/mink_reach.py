"""mink with the exact-pose task against plain mink: reach random targets from home; writes
results/mink_reach.md.

For each model and QP solver, N joint vectors q uniform within the limits give the targets:
the world pose T of the end-effector frame at q, to be reached in the configuration
c = configuration_of(q) (branch signs and arm angle psi). Every run starts from the home pose
(the middle of each joint's range) and calls ``mink.solve_ik`` with a ``ConfigurationLimit``,
dt = 2 ms and damping 1e-3, as mink's arm examples do:

* **om**: the example's FrameTask plus :class:`om_redundant.ExactPoseTask` (c, default cost),
  until the hand is within 1e-10 of T (at most 50 steps);
* **plain mink**: the example's FrameTask plus PostureTask toward home (cost 1e-2), until the
  hand is within the success tolerance (at most 200 steps);
* **plain mink, frame only**: the FrameTask alone (no posture bias), likewise.

Success: the hand within 1e-6 m and 1e-6 rad of T, measured on the MuJoCo frame, and, "in c",
configuration_of(q) equal to c (psi within 1e-6 rad). Time: per target, from setting the
targets to the last step, pose checks included.

Run: ``python -m benchmarks.mink_reach [--n 500] [--seed 0]``.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from collections.abc import Callable
from dataclasses import dataclass
from importlib import metadata

import mink
import mujoco
import numpy as np

import om_redundant as om

from .adapters import MINK_DAMPING, MINK_DT, MINK_STEPS, mink_example_tasks
from .report import cpu_model, write_page
from .robots import home_joints, pose_errors, random_joints, reference_model

#: Success tolerance on the hand's position (m) and orientation (rad), and on psi (rad).
TOLERANCE = 1e-6
#: The exact-pose runs stop below this pose error, or after this many steps.
EXACT_STOP = 1e-10
EXACT_STEPS = 50
QP_SOLVERS = ("daqp", "osqp")
PACKAGES = ("om_redundant", "mink", "mujoco", "qpsolvers", "daqp", "osqp")
METHODS = ("om", "plain mink", "plain mink, frame only")


@dataclass(frozen=True)
class Setup:
    """One arm in one MuJoCo model."""

    key: str
    label: str
    arm: str
    model: Callable[[], mujoco.MjModel]


SETUPS = (
    Setup("panda", "panda (project MJCF)", "panda", lambda: om.arm_model(om.load_arm("panda"))),
    Setup("iiwa14", "iiwa14 (project MJCF)", "iiwa14", lambda: om.arm_model(om.load_arm("iiwa14"))),
    Setup(
        "panda-menagerie",
        "panda (Menagerie panda_nohand.xml)",
        "panda",
        lambda: reference_model("franka_emika_panda/panda_nohand.xml"),
    ),
)


@dataclass(frozen=True)
class Reach:
    """Outcomes of one run, one entry per target.

    Attributes:
        position_error: (N,) final distance of the hand to the target (m).
        orientation_error: (N,) final rotation angle to the target (rad).
        in_configuration: (N,) whether the final joints are in the requested configuration.
        steps: (N,) ``solve_ik`` steps taken.
        seconds: (N,) wall time per target.
    """

    position_error: np.ndarray
    orientation_error: np.ndarray
    in_configuration: np.ndarray
    steps: np.ndarray
    seconds: np.ndarray

    def reached(self, tolerance: float = TOLERANCE) -> np.ndarray:
        """(N,) the hand within ``tolerance`` in position and orientation."""
        return (self.position_error < tolerance) & (self.orientation_error < tolerance)

    def success(self) -> np.ndarray:
        """(N,) reached within :data:`TOLERANCE`, in the requested configuration."""
        return self.reached() & self.in_configuration


def reach(solver: om.OMSolver, model: mujoco.MjModel, Q: np.ndarray, qp: str, method: str = "om") -> Reach:
    """Run mink from home to the pose of each row of Q, by one of :data:`METHODS`."""
    arm = solver.arm
    joints = om.ArmJoints(arm, model)
    root = om.ArmRoot(joints)
    home = joints.qpos_with(model.qpos0, home_joints(arm))
    frame_task, tasks = mink_example_tasks(model, root.frame_name, home, posture=method == "plain mink")
    if method == "om":
        exact_task = om.ExactPoseTask(solver, model, arm_configuration=solver.configuration_of(Q[0]))
        tasks = [frame_task, exact_task]
    stop, max_steps = (EXACT_STOP, EXACT_STEPS) if method == "om" else (TOLERANCE, MINK_STEPS)
    configuration = mink.Configuration(model)
    limits = [mink.ConfigurationLimit(model)]
    out = np.empty((5, len(Q)))
    for i, q in enumerate(Q):
        c = solver.configuration_of(q)
        T = root.fixed_pose @ arm.fk(q)
        start = time.perf_counter()
        frame_task.set_target(mink.SE3.from_matrix(T))
        if method == "om":
            exact_task.set_target(T, c)
        configuration.update(home)
        step = 0
        while step < max_steps:
            step += 1
            velocity = mink.solve_ik(configuration, tasks, MINK_DT, qp, damping=MINK_DAMPING, limits=limits)
            configuration.integrate_inplace(velocity, MINK_DT)
            hand = configuration.get_transform_frame_to_world(root.frame_name, root.frame_type).as_matrix()
            position, angle = pose_errors(hand, T)
            if max(position, angle) < stop:
                break
        seconds = time.perf_counter() - start
        reached_c = solver.configuration_of(joints.q(configuration.data.qpos)).isclose(c, TOLERANCE)
        out[:, i] = position, angle, reached_c, step, seconds
    return Reach(out[0], out[1], out[2].astype(bool), out[3].astype(int), out[4])


def _row(setup: str, qp: str, method: str, run: Reach) -> str:
    n = len(run.steps)
    return (
        f"| {setup} | {qp} | {method} | {100 * run.success().mean():.1f} % "
        f"| {100 * run.reached().mean():.1f} % | {100 * run.reached(1e-4).mean():.1f} % "
        f"| {np.median(run.position_error):.0e} m "
        f"| {np.median(run.steps):.0f} / {run.steps.max()} | {1e3 * np.median(run.seconds):.2f} "
        f"/ {1e3 * run.seconds.mean():.2f} | {n} |"
    )


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--n", type=int, default=500)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    load = os.getloadavg()[0]
    start = time.perf_counter()
    rows = []
    for setup in SETUPS:
        solver = om.OMSolver(setup.arm)
        model = setup.model()
        Q = random_joints(solver.arm, args.n, np.random.default_rng(args.seed))
        for qp in QP_SOLVERS:
            for method in METHODS:
                run = reach(solver, model, Q, qp, method)
                rows.append(_row(setup.label, qp, method, run))
                print(rows[-1], flush=True)
    packages = ", ".join(f"{name} {metadata.version(name)}" for name in PACKAGES)
    text = "\n".join(
        [
            f"# mink reaching {args.n} random targets from home: exact-pose task vs plain mink",
            "",
            f"Machine: {cpu_model()}, {len(os.sched_getaffinity(0))} cores, Python "
            f"{platform.python_version()}; load average {load:.2f} at the start, "
            f"{os.getloadavg()[0]:.2f} at the end. Packages: {packages}.  ",
            f"Run: `python -m benchmarks.mink_reach --n {args.n} --seed {args.seed}`, "
            f"{time.perf_counter() - start:.0f} s.",
            "",
            __doc__.split("\n\n", 1)[1].rsplit("\n\nRun:", 1)[0].strip(),
            "",
            "| model | QP | method | success (in c, 1e-6) | pose within 1e-6 | pose within 1e-4 "
            "| median position error | steps median / max | ms per target median / mean | targets |",
            "|---|---|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    write_page("mink_reach.md", text + "\n")


if __name__ == "__main__":
    main()
