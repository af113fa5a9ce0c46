r"""mink tasks fed by exact OM solutions.

:class:`ExactPoseTask` turns a hand pose into the exact joint vector :math:`q^*` of the
configuration you chose (branch signs and arm angle, or the redundancy optimiser's choice)
and pulls the arm's joints there; :class:`ArmAngleTask` only steers a 7-DOF arm's elbow,
leaving the hand to mink's ``FrameTask``. Both are ``mink.Task``\ s: add them to the task
list of ``mink.solve_ik``, whose limits (joint, velocity, collision) keep every step safe.

Typical use (see docs/mink.md, "Using it with mink")::

    solver = om.OMSolver("panda")
    frame_task = mink.FrameTask("attachment_site", "site", position_cost=1.0, orientation_cost=1.0)
    exact_task = om.ExactPoseTask(solver, model, arm_configuration=om.Configuration((1, -1, 1), (0.3,)))
    frame_task.set_target(T_world_target)
    exact_task.set_target(T_world_target)
    velocity = mink.solve_ik(configuration, [frame_task, exact_task], dt, "daqp", limits=limits)

Targets are poses of the arm's end-effector frame in MuJoCo's world frame, like a
``FrameTask``'s; the tasks find the arm's root frame in the model (:class:`~om_redundant.ArmRoot`).
"""

from .arm_angle_task import ArmAngleTask
from .arm_task import ArmTask
from .exact_pose import EXACT_POSE_COST, ExactPoseTask

__all__ = ["EXACT_POSE_COST", "ArmAngleTask", "ArmTask", "ExactPoseTask"]
