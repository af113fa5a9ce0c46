"""mink, differential IK on the generated MJCF, as in its arm examples."""

from __future__ import annotations

from typing import Any

import numpy as np

import om_redundant as om

from ..robots import (
    home_joints,
)
from .base import Method, Peer, Unavailable, _revolute_only, _rows

#: mink settings, as in its arm examples: 200 steps of the QP from the home pose.
MINK_STEPS = 200
MINK_DT = 0.002
MINK_SOLVER = "daqp"
MINK_DAMPING = 1e-3


def mink_example_tasks(
    model: Any, frame: str, home: np.ndarray, posture: bool = True
) -> tuple[Any, list[Any]]:
    """mink's arm-example tasks: a FrameTask on the site ``frame`` (costs 1, lm_damping 1)
    and, with ``posture``, a PostureTask toward ``home`` (cost 1e-2).

    Returns:
        ``(frame_task, tasks)``.
    """
    import mink

    frame_task = mink.FrameTask(frame, "site", position_cost=1.0, orientation_cost=1.0, lm_damping=1.0)
    if not posture:
        return frame_task, [frame_task]
    posture_task = mink.PostureTask(model, cost=1e-2)
    posture_task.set_target(home)
    return frame_task, [frame_task, posture_task]


def _mink_peer(arm: om.Arm, posture: bool) -> Peer:
    try:
        import mink
    except ImportError as exc:
        raise Unavailable(f"not installed ({exc})") from exc
    _revolute_only(arm)
    model = om.arm_model(arm)
    frame = arm.frame_name or om.mujoco_io.DEFAULT_SITE
    configuration = mink.Configuration(model)
    home = home_joints(arm)
    frame_task, tasks = mink_example_tasks(model, frame, home, posture)
    limits = [mink.ConfigurationLimit(model)]

    def fk(q: np.ndarray) -> np.ndarray:
        configuration.update(np.asarray(q, dtype=float))
        return configuration.get_transform_frame_to_world(frame, "site").as_matrix()

    def call(target: Any) -> np.ndarray:
        configuration.update(home)
        frame_task.set_target(target)
        for _ in range(MINK_STEPS):
            velocity = mink.solve_ik(
                configuration, tasks, MINK_DT, MINK_SOLVER, damping=MINK_DAMPING, limits=limits
            )
            configuration.integrate_inplace(velocity, MINK_DT)
        return configuration.q.copy()

    what = "FrameTask + PostureTask (cost 1e-2)" if posture else "FrameTask only"
    return Peer(
        f"mink ({'frame+posture' if posture else 'frame only'})",
        arm,
        fk,
        f"{what}, lm_damping 1, damping {MINK_DAMPING:g}, ConfigurationLimit, {MINK_STEPS} steps of "
        f'solve_ik("{MINK_SOLVER}") from home',
        any=Method(lambda T, _: mink.SE3.from_matrix(T), call, lambda _, q: _rows(q, arm.dof)),
    )


def mink_peer(arm: om.Arm, rng: np.random.Generator) -> Peer:
    """mink as in its arm examples: a FrameTask plus a PostureTask toward home."""
    return _mink_peer(arm, posture=True)


def mink_frame_only_peer(arm: om.Arm, rng: np.random.Generator) -> Peer:
    """mink with the FrameTask alone (the posture task biases the end pose)."""
    return _mink_peer(arm, posture=False)
