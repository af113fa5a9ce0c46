"""The benchmark of Menagerie's humanoids and mobile manipulators (benchmarks/menagerie_humanoids.py)
on a small model of that kind made here: a floating base, a waist joint and two arms named by a
prefix, its mesh files missing, as the Menagerie files come without their assets."""

from __future__ import annotations

import argparse
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco

import om_redundant as om
from benchmarks import menagerie_humanoids as humanoids
from benchmarks.menagerie import Entry, import_row, present


def humanoid_mjcf(folder: Path) -> Path:
    """A pelvis on a free joint, a torso on a waist hinge and a UR5e arm on each side ("left_",
    "right_"), with a visual mesh whose file is not there."""
    robot = mujoco.MjSpec()
    pelvis = robot.worldbody.add_body(name="pelvis", pos=[0, 0, 0.8])
    pelvis.add_freejoint(name="floating_base")
    pelvis.add_geom(size=[0.1, 0, 0])
    torso = pelvis.add_body(name="torso_link", pos=[0, 0, 0.2])
    torso.add_joint(name="waist_yaw", axis=[0, 0, 1], range=[-1, 1])
    torso.add_geom(size=[0.1, 0, 0])
    for prefix, y in (("left_", 0.2), ("right_", -0.2)):
        ur5e = mujoco.MjSpec.from_string(om.arm_mjcf(om.load_arm("ur5e")))
        torso.add_frame(pos=[0, y, 0.3]).attach_body(ur5e.body("base"), prefix, "")
    robot.compile()
    root = ET.fromstring(robot.to_xml())
    asset = root.find("asset")
    if asset is None:
        asset = ET.SubElement(root, "asset")
    ET.SubElement(asset, "mesh", name="shell", file="assets/shell.stl")
    pelvis_body = root.find("worldbody/body")
    ET.SubElement(pelvis_body, "geom", type="mesh", mesh="shell", contype="0", conaffinity="0")
    path = folder / "robot" / "humanoid.xml"
    path.parent.mkdir()
    path.write_text(ET.tostring(root, encoding="unicode"))
    return path


def test_a_row_of_an_arm_on_a_floating_torso_with_its_times(tmp_path):
    """Imported from its root body below the free joint and the waist, solved exactly against
    MuJoCo's pose, with the median times of solve and solve_all; from the world or the pelvis
    it does not import, and the row names the root to give."""
    humanoid_mjcf(tmp_path)
    entry = Entry("robot/humanoid.xml", "wrist_3_link", "body", "left_", "torso_link")
    row = import_row("left", entry, 5, 0, tmp_path, times=True)
    assert row["import"] == "yes" and row["solver"].startswith("accepted (RRR")
    assert row["q among solve_all"] == "100.000 %" and row["roots not exact or not in c"] == "0"
    for column in ("solve (hinted), median", "a tick (solve_from), median", "solve_all, median"):
        assert row[column].endswith(("µs", "ms"))
    assert row["the tick returns q"] == "100.000 %"
    floating = import_row("world", entry._replace(root=None), 5, 0, tmp_path)["import"]
    assert floating.startswith("failed: joint 'floating_base' between the root and the body is a free joint")
    assert "give the body it moves, 'pelvis', as the root" in floating
    waist = import_row("pelvis", entry._replace(root="pelvis"), 5, 0, tmp_path)["import"]
    assert waist.startswith("failed: joint 'waist_yaw' between the root and the frame does not start with")
    assert "give the body it moves, 'torso_link', as the root" in waist


def test_the_page_and_the_arms_a_folder_lacks(tmp_path, capsys):
    humanoid_mjcf(tmp_path)
    arms = {
        "here": Entry("robot/humanoid.xml", "wrist_3_link", "body", "right_", "torso_link"),
        "gone": Entry("robot/gone.xml", "wrist_3_link", "body"),
    }
    assert present(arms, tmp_path) == ["here"]
    assert "gone: " in capsys.readouterr().out
    (tmp_path / "SOURCES.txt").write_text("robot/humanoid.xml  made by the test\n")
    row = {"file": "robot/humanoid.xml", **import_row("here", arms["here"], 3, 0, tmp_path, times=True)}
    args = argparse.Namespace(dir=tmp_path, n=3, seed=0)
    text = humanoids.page([row], args, [1.0, 2.5])
    assert text.startswith(
        "# Menagerie humanoids and mobile manipulators (3 random q per accepted arm, seed 0)"
    )
    assert "load average was 1.0 to 2.5" in text and "robot/humanoid.xml  made by the test" in text
    assert "| arm | file | import |" in text and "| here | robot/humanoid.xml | yes |" in text
    assert "Hello Robot Stretch" in text


def test_the_benchmark_skips_the_files_its_folder_lacks(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(sys, "argv", ["menagerie_humanoids", "--dir", str(tmp_path), "--n", "3"])
    humanoids.main()
    out = capsys.readouterr().out
    assert "absent, skipped" in out and out.rstrip().endswith("nothing measured")


def test_every_arm_names_its_file_frame_and_root():
    """The entries as the benchmark reads them: a Menagerie folder and file, and a root body for
    every arm on a floating base or a mobile one (the free joint is not the arm's)."""
    for name, entry in humanoids.ARMS.items():
        assert entry.path.count("/") == 1 and entry.path.endswith(".xml"), name
        assert entry.frame_type in ("site", "body"), name
    assert all(
        entry.root for name, entry in humanoids.ARMS.items() if not name.startswith(("ALOHA", "Franka"))
    )
