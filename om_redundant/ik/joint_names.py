"""How the model's messages name an arm's joints and DH rows: by their number on the arm and
their name in its model."""

from __future__ import annotations

from collections.abc import Iterable

from ..kinematics.arm import Arm


def joint_name(arm: Arm, j: int) -> str:
    """Joint j (0-based) as messages name it: its number on the arm and the model's name."""
    return f"joint {j + 1} ('{arm.prefix}{arm.joint_names[j]}')"


def joints_named(arm: Arm, joints: Iterable[int]) -> str:
    """Joints (0-based) as messages name them, comma-separated."""
    return ", ".join(joint_name(arm, j) for j in joints)


def row_name(arm: Arm, i: int) -> str:
    """DH row i as messages name it: the row of a joint, or a fixed row after one."""
    jr = arm.chain.joint_rows
    if i in jr:
        return f"the row of {joint_name(arm, jr.index(i))}"
    before = [k for k, r in enumerate(jr) if r < i]
    return f"a fixed row after {joint_name(arm, before[-1])}" if before else "a fixed row before joint 1"
