"""Menagerie's humanoids and mobile manipulators: their arms imported from the MJCF as it comes.

Run: ``nice python -m benchmarks.menagerie_humanoids --dir DIR [--n 10000] [--seed 0] [--arms
NAME ...]``; writes ``results/menagerie_humanoids.md``. DIR holds model files of
google-deepmind/mujoco_menagerie in its layout (``DIR/unitree_g1/g1_with_hands.xml``, ...), as
they are in the repository (no edits; the meshes and textures they name may be absent: the loader
skips them) and kept outside the project; DIR/SOURCES.txt, if there, names the commit of each
file and is quoted on the page. For each arm of ``ARMS`` whose file DIR holds (the others are
skipped with a note, and without any the benchmark writes nothing), the row of
:func:`benchmarks.menagerie.measure` with its median times: the arm imported with its frame,
prefix and root (the body its chain starts from: a torso, a mobile base, a floating base),
``check-model``'s comparison over 1,000 random q, and where ``OMSolver`` accepts the arm, N random
in-limit q solved against MuJoCo's own frame pose in the root body's frame; an arm OMSolver
refuses is listed with its ModelError, one that does not import with its error. ``NOT_SERIAL``
names the Menagerie models of this kind not measured, and why.
"""

from __future__ import annotations

import argparse
import os
import sys

from .menagerie import Entry, files_arguments, import_row, present, table
from .report import write_page

#: The arms: model file, end-effector body or site, the prefix of the arm's joint names and the
#: root body (the torso or base the arm is mounted on; the world where there is none).
ARMS = {
    "Unitree G1 29-DoF, left": Entry(
        "unitree_g1/g1_with_hands.xml", "wrist_yaw_link", "body", "left_", "torso_link"
    ),
    "Unitree G1 29-DoF, right": Entry(
        "unitree_g1/g1_with_hands.xml", "wrist_yaw_link", "body", "right_", "torso_link"
    ),
    "Unitree H1, left": Entry("unitree_h1/h1.xml", "elbow_link", "body", "left_", "torso_link"),
    "Apptronik Apollo, left": Entry(
        "apptronik_apollo/apptronik_apollo.xml", "wrist_pitch_link", "body", "l_", "torso_link"
    ),
    "Apptronik Apollo, right": Entry(
        "apptronik_apollo/apptronik_apollo.xml", "wrist_pitch_link", "body", "r_", "torso_link"
    ),
    "Fourier N1, left": Entry("fourier_n1/n1.xml", "end_effector_link", "body", "left_", "torso_link"),
    "Booster T1, left": Entry("booster_t1/t1.xml", "left_hand_link", "body", "Left_", "Trunk"),
    "PAL Talos, left": Entry("pal_talos/talos.xml", "7_link", "body", "arm_left_", "torso_2_link"),
    "PAL Talos, right": Entry("pal_talos/talos.xml", "7_link", "body", "arm_right_", "torso_2_link"),
    "PAL TIAGo": Entry("pal_tiago/tiago.xml", "7_link", "body", "arm_", "torso_lift_link"),
    "PAL TIAGo Dual, left": Entry(
        "pal_tiago_dual/tiago_dual.xml", "7_link", "body", "arm_left_", "torso_lift_link"
    ),
    "PAL TIAGo Dual, right": Entry(
        "pal_tiago_dual/tiago_dual.xml", "7_link", "body", "arm_right_", "torso_lift_link"
    ),
    "Rainbow RB-Y1, left": Entry(
        "rainbow_robotics_rby1/rby1a_1.2_no_gripper.xml",
        "link_left_arm_6",
        "body",
        "left_arm_",
        "link_torso_5",
    ),
    "Rainbow RB-Y1, right": Entry(
        "rainbow_robotics_rby1/rby1a_1.2_no_gripper.xml",
        "link_right_arm_6",
        "body",
        "right_arm_",
        "link_torso_5",
    ),
    "Stanford TidyBot (Kinova Gen3)": Entry(
        "stanford_tidybot/tidybot.xml", "pinch_site", "site", "", "base_link"
    ),
    "ALOHA 2 (ViperX 300 6DOF), left": Entry("aloha/aloha.xml", "gripper", "site", "left/"),
    "ALOHA 2 (ViperX 300 6DOF), right": Entry("aloha/aloha.xml", "gripper", "site", "right/"),
    "Google Robot, torso and arm": Entry("google_robot/robot.xml", "gripper", "site", "", "base_link"),
    "Google Robot, arm": Entry("google_robot/robot.xml", "gripper", "site", "", "link_torso"),
    "Boston Dynamics Spot Arm": Entry(
        "boston_dynamics_spot/spot_arm.xml", "arm_link_wr1", "body", "arm_", "body"
    ),
    "Franka FR3 Duo, left": Entry(
        "franka_fr3_duo/fr3_duo.xml", "left_attachment_site", "site", "left_fr3v2_"
    ),
    "Franka FR3 Duo, right": Entry(
        "franka_fr3_duo/fr3_duo.xml", "right_attachment_site", "site", "right_fr3v2_"
    ),
}

#: Menagerie humanoids and mobile manipulators not in ARMS, and why.
NOT_SERIAL = {
    "Unitree G1 (g1.xml)": "5-joint arms (shoulder pitch, roll, yaw, elbow pitch, roll); its 29-DoF "
    "model g1_with_hands.xml, with 7-joint arms, is measured",
    "Unitree H1-2": "not in Menagerie (unitree_h1 is the H1, whose arms have 4 joints: measured, refused)",
    "Hello Robot Stretch 2, 3": "not a serial revolute arm: a lift and a telescoping arm (prismatic) "
    "carry the wrist",
    "Fourier GR1": "not in Menagerie (fourier_n1 is: 5-joint arms, measured, refused)",
}


def main() -> None:
    args = files_arguments(__doc__, ARMS, "Menagerie's model files", 10_000)
    rows, loads = [], [os.getloadavg()[0]]
    for name in present(ARMS, args.dir, args.arms):
        entry = ARMS[name]
        where = {
            "frame": f"{entry.frame_type} `{entry.frame}`",
            "prefix, root": f"{f'`{entry.prefix}`' if entry.prefix else 'none'}, {entry.root or 'world'}",
        }
        rows.append(
            {"file": entry.path, **where, **import_row(name, entry, args.n, args.seed, args.dir, times=True)}
        )
        loads.append(os.getloadavg()[0])
        print(rows[-1], flush=True)
    if not rows:
        print(f"no model file of ARMS under {args.dir}: nothing measured")
        return
    write_page("menagerie_humanoids.md", page(rows, args, loads))


def page(rows: list[dict], args: argparse.Namespace, loads: list[float]) -> str:
    """The results page: how it was run, the table (the arm's name first), the models not measured."""
    command = " ".join(["python -m benchmarks.menagerie_humanoids", *sys.argv[1:]])
    sources = args.dir / "SOURCES.txt"
    lines = [
        f"# Menagerie humanoids and mobile manipulators ({args.n:,} random q per accepted arm, "
        f"seed {args.seed})",
        "",
        f"`{command}` on {os.cpu_count()} cores, niceness {os.nice(0)}; the 1-minute load average "
        f"was {min(loads):.1f} to {max(loads):.1f} between the arms (times are wall times under that load).",
        "",
        *table([{"arm": row.pop("arm"), **row} for row in rows], ("model",)),
        "",
        "Not measured:",
        "",
        *(f"* {model}: {why}." for model, why in NOT_SERIAL.items()),
    ]
    if sources.is_file():
        lines += ["", "The model files (`SOURCES.txt`):", "", "```", sources.read_text().rstrip(), "```"]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
