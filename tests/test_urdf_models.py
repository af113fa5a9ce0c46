"""URDFs as they come (the 19 public arms of the issue): inertial data MuJoCo refuses, links on
fixed joints (tool frames), two arms named by a prefix on a torso that moves, frames with and
without the prefix. Each test builds a small URDF that reproduces the problem."""

from __future__ import annotations

import json
import re
import sys
import xml.etree.ElementTree as ET

import mink
import mujoco
import numpy as np
import pytest

import om_redundant as om
from benchmarks import urdf_arms
from benchmarks.menagerie import Entry
from om_redundant.cli import main
from om_redundant.kinematics import KinematicChain
from tests.conftest import random_q
from tests.test_arm_import import UR_JOINTS

#: Inertias MuJoCo refuses: PR2's, Romeo's and Talos's break A + B >= C; TIAGo's, iCub's and the
#: quadrupeds' have a negative eigenvalue.
BAD_INERTIA = (
    {"ixx": "1", "iyy": "1", "izz": "5", "ixy": "0", "ixz": "0", "iyz": "0"},
    {"ixx": "1", "iyy": "1", "izz": "1", "ixy": "2", "ixz": "0", "iyz": "0"},
)
GOOD_INERTIA = {"ixx": "0.01", "iyy": "0.01", "izz": "0.01", "ixy": "0", "ixz": "0", "iyz": "0"}


def link(robot: ET.Element, name: str, inertia: dict[str, str] | None = GOOD_INERTIA) -> None:
    element = ET.SubElement(robot, "link", name=name)
    if inertia is not None:
        inertial = ET.SubElement(element, "inertial")
        ET.SubElement(inertial, "mass", value="1")
        ET.SubElement(inertial, "inertia", **inertia)


def joint(
    robot: ET.Element, name: str, kind: str, parent: str, child: str, xyz="0 0 0", rpy="0 0 0", axis=None
):
    element = ET.SubElement(robot, "joint", name=name, type=kind)
    ET.SubElement(element, "parent", link=parent)
    ET.SubElement(element, "child", link=child)
    ET.SubElement(element, "origin", xyz=xyz, rpy=rpy)
    if axis is not None:
        ET.SubElement(element, "axis", xyz=axis)
    if kind in ("revolute", "prismatic"):
        ET.SubElement(element, "limit", lower="-3", upper="3", effort="10", velocity="1")


def two_arm_urdf(tmp_path, bad_inertia: bool = False):
    """A torso on a lift (prismatic torso_lift_joint) carrying two UR-like arms prefixed l_ and r_,
    each with its tool0 on a fixed joint and a tool frame named without the prefix
    (gripper_left_tcp, gripper_right_tcp, as Talos's gripper_left_base_link); with
    ``bad_inertia`` the torso and a link of each arm have inertias MuJoCo refuses."""
    robot = ET.Element("robot", name="two_arms")
    link(robot, "base_link")
    link(robot, "torso", BAD_INERTIA[0] if bad_inertia else GOOD_INERTIA)
    joint(robot, "torso_lift_joint", "prismatic", "base_link", "torso", "0 0 0.6", axis="0 0 1")
    for side, prefix, y in (("left", "l_", 0.25), ("right", "r_", -0.25)):
        link(robot, f"{prefix}base_link", None)  # no inertial at all, as URDF mounts often have
        joint(robot, f"{prefix}mount", "fixed", "torso", f"{prefix}base_link", f"0.1 {y} 0.3", "0 0 0.3")
        parent = f"{prefix}base_link"
        for name, child, xyz, rpy, sign, _ in UR_JOINTS:
            link(
                robot,
                prefix + child,
                BAD_INERTIA[1] if bad_inertia and child == "forearm_link" else GOOD_INERTIA,
            )
            kind = "revolute" if sign else "fixed"
            joint(
                robot, prefix + name, kind, parent, prefix + child, xyz, rpy, f"0 0 {sign}" if sign else None
            )
            parent = prefix + child
        link(robot, f"gripper_{side}_tcp", None)
        joint(
            robot, f"gripper_{side}_joint", "fixed", parent, f"gripper_{side}_tcp", "0 0 0.12", "0.1 0.2 0.3"
        )
    path = tmp_path / "two_arms.urdf"
    path.write_text(ET.tostring(robot, encoding="unicode"))
    return path


def import_left(path, out, *extra: str) -> int:
    return main(["import-arm", str(path), "--frame", "tool0", "--frame-type", "body", "-o", str(out), *extra])


# ---------------------------------------------------------------------------------------
# Inertial data never stops an import


def test_inertia_mujoco_refuses_never_stops_an_import(tmp_path, capsys):
    """The URDF's inertias (A + B < C, a negative eigenvalue) make MuJoCo refuse it as it is;
    the loader replaces them (kinematics need none) and the arm imports, checks and solves."""
    path = two_arm_urdf(tmp_path, bad_inertia=True)
    with pytest.raises(ValueError, match="inertia"):
        mujoco.MjModel.from_xml_path(str(path))
    model = om.load_mujoco_model(path)
    assert model.body("l_tool0").id > 0
    out = tmp_path / "left.toml"
    assert import_left(path, out, "--prefix", "l_", "--root", "torso") == 0
    assert "OMSolver: accepts it" in capsys.readouterr().out
    assert main(["check-model", str(path), "--arm", str(out), "--tolerance", "1e-12", "-q"]) == 0


def test_inertia_in_an_mjcf_likewise_and_a_model_that_compiles_keeps_its_own(tmp_path):
    arm_text = om.arm_mjcf(om.load_arm("ur5e"))
    root = ET.fromstring(arm_text)
    ET.SubElement(root.find("worldbody/body"), "inertial", pos="0 0 0", mass="1", diaginertia="1 1 5")
    bad = tmp_path / "bad.xml"
    bad.write_text(ET.tostring(root, encoding="unicode"))
    with pytest.raises(ValueError, match="inertia"):
        mujoco.MjModel.from_xml_path(str(bad))
    assert om.compare_mujoco_model(om.load_arm("ur5e"), om.load_mujoco_model(bad)).ok
    good = tmp_path / "good.xml"
    good.write_text(arm_text)
    np.testing.assert_array_equal(
        om.load_mujoco_model(good).body_mass, mujoco.MjModel.from_xml_path(str(good)).body_mass
    )


# ---------------------------------------------------------------------------------------
# Links on fixed joints stay frames


def test_a_link_on_a_fixed_joint_is_a_frame_of_the_loaded_model(tmp_path):
    """MuJoCo's URDF loader fuses tool0 into wrist_3_link by default; om.load_mujoco_model keeps
    it, for --frame and for ExactPoseTask, and the FrameNotFound of a fused model says why."""
    path = two_arm_urdf(tmp_path)
    fused = mujoco.MjModel.from_xml_path(str(path))
    assert mujoco.mj_name2id(fused, mujoco.mjtObj.mjOBJ_BODY, "l_tool0") == -1
    assert om.load_mujoco_model(path).body("l_tool0").id > 0
    out = tmp_path / "left.toml"
    assert import_left(path, out, "--prefix", "l_", "--root", "torso", "-q") == 0
    solver = om.OMSolver(om.load_arm(out))
    with pytest.raises(om.FrameNotFound, match=r"fusestatic off, as om\.load_mujoco_model does"):
        om.ExactPoseTask(solver, fused, arm_configuration=solver.configurations()[0])


# ---------------------------------------------------------------------------------------
# Prefix and root as data of the arm file


def test_prefix_and_root_are_kept_in_the_arm_file_and_used_as_defaults(tmp_path):
    path = two_arm_urdf(tmp_path)
    out = tmp_path / "left.toml"
    assert import_left(path, out, "--prefix", "l_", "--root", "torso", "-q") == 0
    assert (
        import_left(path, out, "--prefix", "l_", "--root", "torso", "--json", str(tmp_path / "out.json")) == 0
    )
    assert json.loads((tmp_path / "out.json").read_text())["root"] == "torso"
    text = out.read_text()
    assert 'prefix = "l_"' in text and 'root = "torso"' in text and 'frame = "tool0"' in text
    arm = om.load_arm(out)
    assert (arm.prefix, arm.root, arm.frame_name) == ("l_", "torso", "tool0")
    assert arm.joint_names[0] == "shoulder_pan_joint"
    again = tmp_path / "again.toml"
    om.write_arm_file(arm, again)
    assert om.load_arm(again).prefix == "l_" and om.load_arm(again).root == "torso"
    # check-model, ArmJoints and the frame take them when given none.
    assert main(["check-model", str(path), "--arm", str(out), "--tolerance", "1e-12", "-q"]) == 0
    model = om.load_mujoco_model(path)
    assert om.compare_mujoco_model(arm, model, tolerance=1e-12).ok
    assert om.ArmJoints(arm, model).names[0] == "l_shoulder_pan_joint"
    assert om.ArmRoot(om.ArmJoints(arm, model)).frame_name == "l_tool0"
    # Given ones win: the right arm is the same arm under "r_" (its own mount: the root found again).
    assert om.ArmRoot(om.ArmJoints(arm, model, "r_")).frame_name == "r_tool0"
    # The project's model of the arm has its names, its root body included: it drops in.
    ours = om.arm_model(arm)
    assert ours.body("torso").id == 1 and om.compare_mujoco_model(arm, ours, tolerance=1e-12).ok
    assert om.ArmJoints(arm, ours).names[0] == "l_shoulder_pan_joint"


def test_the_frame_is_found_with_or_without_the_prefix(tmp_path):
    """Talos's tool frame gripper_left_base_link does not carry its arm joints' prefix arm_left_:
    the frame is tried as given, then with the prefix, and kept as the model has it."""
    path = two_arm_urdf(tmp_path)
    model = om.load_mujoco_model(path)
    for given, kept in (("tool0", "tool0"), ("l_tool0", "tool0"), ("gripper_left_tcp", "gripper_left_tcp")):
        arm = om.arm_from_mujoco(model, given, "body", "l_", "torso")
        assert arm.frame_name == kept
        assert om.compare_mujoco_model(arm, model, tolerance=1e-12).ok
        assert om.ArmRoot(om.ArmJoints(arm, model)).frame_name in (kept, "l_" + kept)
    with pytest.raises(om.FrameNotFound, match=r"'hand' \(nor 'l_hand'\)"):
        om.arm_from_mujoco(model, "hand", "body", "l_", "torso")


def test_exact_pose_task_on_the_users_own_urdf(tmp_path):
    """The imported arm's task on the URDF loaded by om.load_mujoco_model, with no prefix, frame
    or root given: mink brings the arm to the exact joints of the pose in the configuration
    asked for, the tool frame onto the pose, and leaves the torso's lift (no task moves it)."""
    path = two_arm_urdf(tmp_path, bad_inertia=True)
    out = tmp_path / "left.toml"
    assert import_left(path, out, "--prefix", "l_", "--root", "torso", "-q") == 0
    solver = om.OMSolver(om.load_arm(out))
    model = om.load_mujoco_model(path)
    configuration = mink.Configuration(model)
    q_goal = random_q(solver.arm, 1, np.random.default_rng(4))[0]
    c = solver.configuration_of(q_goal)
    exact = om.ExactPoseTask(solver, model, arm_configuration=c)
    assert (exact.joints.names[0], exact.root.frame_name) == ("l_shoulder_pan_joint", "l_tool0")
    T = exact.root.pose(configuration.data) @ solver.arm.fk(q_goal)
    exact.set_target(T)
    for _ in range(10):
        velocity = mink.solve_ik(
            configuration, [exact], 0.002, "daqp", limits=[mink.ConfigurationLimit(model)]
        )
        configuration.integrate_inplace(velocity, 0.002)
    reached = configuration.get_transform_frame_to_world("l_tool0", "body").as_matrix()
    assert np.abs(reached - T).max() < 1e-9
    assert solver.configuration_of(exact.joints.q(configuration.q)).isclose(c, 1e-6)
    assert configuration.q[model.joint("torso_lift_joint").qposadr[0]] == 0.0


# ---------------------------------------------------------------------------------------
# Messages that name --root


def test_check_model_names_the_root_where_the_chain_starts(tmp_path, capsys):
    """An arm file whose chain starts at the torso, checked from the world (the file of an
    older import, or --root world): the difference names the body to give."""
    path = two_arm_urdf(tmp_path)
    out = tmp_path / "left.toml"
    assert import_left(path, out, "--prefix", "l_", "--root", "torso", "-q") == 0
    assert main(["check-model", str(path), "--arm", str(out), "--root", "world"]) == 1
    err = capsys.readouterr().err
    assert re.search(
        r"joint 'l_shoulder_\w+' lies up to [0-9.e-]+ m off the arm's joint axis; the arm matches the "
        r"model from root body 'torso' \(--root torso, root='torso'\)",
        err,
    ), err


def test_the_importer_names_the_root_of_an_arm_on_a_torso(tmp_path, capsys):
    """With the prefix but no root, the torso's lift is on the chain: the message names the body
    to give as the root."""
    path = two_arm_urdf(tmp_path)
    assert import_left(path, tmp_path / "left.toml", "--prefix", "l_") == 2
    err = capsys.readouterr().err
    assert (
        "joint 'torso_lift_joint' between the root and the frame does not start with the prefix 'l_'; if it "
        "is not the arm's, give the body it moves, 'torso', as the root (--root torso, root='torso')"
    ) in err


def test_a_chain_with_joints_above_the_arm_is_refused_naming_the_root():
    """TIAGo without --root: its torso's lift and seven arm joints; the refusal names the joint
    whose body is the root to give."""
    panda = om.load_arm("panda")
    lift = om.DHRow(d=0.3, kind=om.JointKind.PRISMATIC)
    chain = KinematicChain((lift, *panda.chain.rows), panda.chain.T_root_base, panda.chain.T_flange_tool)
    arm = om.Arm(
        "tiago",
        chain,
        ("torso_lift_joint", *panda.joint_names),
        np.r_[0, panda.lower],
        np.r_[0.35, panda.upper],
    )
    cause = (
        r"has 8 joints; models exist for 6- and 7-DOF arms; if the arm starts after joint 1 "
        r"\('torso_lift_joint'\) \(joints of a torso or a mobile base before it\), import it from the body "
        r"that joint moves as the root \(import-arm --root BODY\)"
    )
    with pytest.raises(om.ModelError, match=cause):
        om.OMSolver(arm)


# ---------------------------------------------------------------------------------------
# The benchmark of public URDFs


def test_the_urdf_benchmark_skips_the_files_its_folder_lacks(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(sys, "argv", ["urdf_arms", "--dir", str(tmp_path)])
    urdf_arms.main()
    out = capsys.readouterr().out
    assert "UR3: " in out and "absent, skipped" in out and out.rstrip().endswith("nothing measured")


def test_the_urdf_benchmark_row_of_an_arm_on_a_torso(tmp_path, monkeypatch):
    """A row: imported with its frame, prefix and root, checked, and solved exactly against
    MuJoCo's pose in the root body's frame; a file that does not load says why."""
    two_arm_urdf(tmp_path, bad_inertia=True)
    (tmp_path / "broken.urdf").write_text("<robot name='broken'><joint name='j'/></robot>")
    monkeypatch.setitem(
        urdf_arms.URDF_ARMS, "two arms", Entry("two_arms.urdf", "tool0", "body", "l_", "torso")
    )
    monkeypatch.setitem(urdf_arms.URDF_ARMS, "broken", Entry("broken.urdf", "tool0", "body"))
    row = urdf_arms.row("two arms", 5, 0, tmp_path)
    assert row["import"] == "yes" and row["solver"].startswith("accepted (RRR")
    assert row["q among solve_all"] == "100.000 %" and row["roots not exact or not in c"] == "0"
    assert urdf_arms.row("broken", 5, 0, tmp_path)["import"].startswith("failed: cannot load MuJoCo model")
