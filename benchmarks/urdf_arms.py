"""Public URDF arms as they come: imported, checked, and solved or refused with the reason.

Run: ``python -m benchmarks.urdf_arms --dir DIR [--n 1000] [--seed 0] [--arms NAME ...]``;
writes ``results/urdf_arms.md``. DIR holds the URDF text of the public repositories in
``SOURCES``, each in its own layout under a folder of the repository's name (meshes are not
needed: the loader skips them, and replaces inertial data MuJoCo refuses). For each arm of
``URDF_ARMS`` whose file DIR holds (the others are skipped with a note, and without any the
benchmark writes nothing), the row of :func:`benchmarks.menagerie.measure`: the import with the
arm's frame, prefix and root, ``check-model``'s comparison over 1,000 random q, and where
``OMSolver`` accepts the arm, N random in-limit q solved against MuJoCo's own frame pose in
the root body's frame; an arm OMSolver refuses is listed with its ModelError, one that does
not import with its error.
"""

from __future__ import annotations

import sys
from pathlib import Path

from .menagerie import Entry, files_arguments, import_row, present, table
from .report import write_page

#: The repositories the URDFs come from, as folders of DIR, and the commit they were read at.
SOURCES = {
    "example-robot-data": "Gepetto/example-robot-data @ 39aa943",
    "unitree_ros": "unitreerobotics/unitree_ros @ d6f13aa",
    "xarm_ros2": "newtonjeri/xarm_ros2 @ f3b6bcd",
}

_ERD = "example-robot-data/robots"
#: The arms: file under DIR, the end-effector body (a link on a fixed joint where the URDF has
#: one), and the prefix and root body of arms on a torso, a mobile base or a quadruped.
URDF_ARMS = {
    "UR3": Entry(f"{_ERD}/ur_description/urdf/ur3_robot.urdf", "tool0", "body"),
    "UR5": Entry(f"{_ERD}/ur_description/urdf/ur5_robot.urdf", "tool0", "body"),
    "UR10": Entry(f"{_ERD}/ur_description/urdf/ur10_robot.urdf", "tool0", "body"),
    "Panda": Entry(f"{_ERD}/panda_description/urdf/panda.urdf", "link8", "body", "panda_"),
    "xArm7": Entry("xarm_ros2/xarm_description/urdf/xarm7.urdf", "link_eef", "body"),
    "Kinova Jaco2 (j2s6s200)": Entry(
        f"{_ERD}/kinova_description/robots/kinova.urdf", "end_effector", "body", "j2s6s200_"
    ),
    "Unitree Z1": Entry(f"{_ERD}/z1_description/urdf/z1.urdf", "gripperStator", "body"),
    "Reach Bravo 7": Entry(f"{_ERD}/bravo7_description/urdf/bravo7_no_ee.urdf", "end_effector_ball", "body"),
    "Baxter (left)": Entry(
        f"{_ERD}/baxter_description/urdf/baxter.urdf", "hand_link", "body", "left_", "torso"
    ),
    "PR2 (left)": Entry(
        f"{_ERD}/pr2_description/urdf/pr2.urdf", "gripper_tool_frame", "body", "l_", "torso_lift_link"
    ),
    "TIAGo": Entry(
        f"{_ERD}/tiago_description/robots/tiago.urdf", "tool_link", "body", "arm_", "torso_lift_link"
    ),
    "TIAGo Pro (left)": Entry(
        f"{_ERD}/tiago_pro_description/robots/tiago_pro.urdf",
        "tool_link",
        "body",
        "arm_left_",
        "torso_lift_link",
    ),
    "Talos (left)": Entry(
        f"{_ERD}/talos_data/robots/talos_reduced.urdf",
        "gripper_left_base_link",
        "body",
        "arm_left_",
        "torso_2_link",
    ),
    "iCub (left)": Entry(f"{_ERD}/icub_description/robots/icub.urdf", "hand_dh_frame", "body", "l_", "chest"),
    "Romeo (left)": Entry(f"{_ERD}/romeo_description/urdf/romeo.urdf", "l_gripper", "body", "L", "torso"),
    "Unitree G1 (left)": Entry(
        "unitree_ros/robots/g1_description/g1_29dof.urdf", "rubber_hand", "body", "left_", "torso_link"
    ),
    "ANYmal B + Kinova": Entry(
        f"{_ERD}/anymal_b_simple_description/robots/anymal-kinova.urdf",
        "end_effector",
        "body",
        "j2s6s200_",
        "base",
    ),
    "Unitree B1 + Z1": Entry(f"{_ERD}/b1_description/urdf/b1-z1.urdf", "gripperStator", "body", "", "trunk"),
}


def row(name: str, n: int, seed: int, folder: Path) -> dict:
    """The arm's row of :func:`benchmarks.menagerie.measure`, or where it does not import, why."""
    return import_row(name, URDF_ARMS[name], n, seed, folder)


def main() -> None:
    args = files_arguments(__doc__, URDF_ARMS, "the repositories' URDFs", 1000)
    rows = []
    for name in present(URDF_ARMS, args.dir, args.arms):
        rows.append(row(name, args.n, args.seed, args.dir))
        print(rows[-1], flush=True)
    if not rows:
        print(f"no URDF of URDF_ARMS under {args.dir}: nothing measured")
        return
    title = f"# Public URDF arms imported and solved ({args.n:,} random q per accepted arm, seed {args.seed})"
    command = " ".join(["python -m benchmarks.urdf_arms", *sys.argv[1:]])
    sources = ", ".join(f"`{folder}/` {source}" for folder, source in SOURCES.items())
    lines = [title, "", f"`{command}`; URDFs: {sources}.", "", *table(rows, ("model",))]
    write_page("urdf_arms.md", "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
