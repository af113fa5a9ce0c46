"""Arm files from MuJoCo models (``arm_from_mujoco``, ``import-arm``), and solvers that refuse
what they cannot solve.

Every reference Menagerie model beside the project (``../shared/reference/menagerie``) is
imported, written, read back bit for bit, accepted by ``check-model`` at 1e-12, and then
either solved exactly against MuJoCo's own forward kinematics or refused by ``OMSolver``
with a ModelError that names why.
"""

from __future__ import annotations

import json
import math
import re
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pytest

import om_redundant as om
from benchmarks.menagerie import EXTRA, available, frame_pose
from om_redundant.cli import main
from om_redundant.ik import derive_model
from om_redundant.mujoco_io.arm_import import IMPORT_TOLERANCE
from tests.conftest import MENAGERIE, random_q, wrap

#: model file, frame, frame type, and None where OMSolver accepts the arm, else the reason.
REFERENCE = {
    "panda_nohand": ("franka_emika_panda/panda_nohand.xml", "attachment_site", "site", None),
    "fr3": ("franka_fr3/fr3.xml", "attachment_site", "site", None),
    "iiwa14": ("kuka_iiwa_14/iiwa14.xml", "attachment_site", "site", None),
    "gen3": ("kinova_gen3/gen3.xml", "pinch_site", "site", None),
    "xarm7_nohand": ("ufactory_xarm7/xarm7_nohand.xml", "attachment_site", "site", None),
    "sawyer": ("rethink_robotics_sawyer/sawyer.xml", "attachment_site", "site", None),
    "ur5e": ("universal_robots_ur5e/ur5e.xml", "wrist_3_link", "body", None),
    "ur10e": ("universal_robots_ur10e/ur10e.xml", "attachment_site", "site", None),
    "flexiv_rizon4": ("flexiv_rizon4/flexiv_rizon4.xml", "link7", "body", None),
    "wx250s": ("trossen_wx250s/wx250s.xml", "wx250s/gripper_link", "body", None),
    # Twists 90 deg +- 4.2e-6 rad (rounded quaternions): solved through the nominal arm.
    "piper": ("agilex_piper/piper.xml", "link6", "body", None),
    # Joint 3's axis opposite to joint 2's, 7.3e-6 rad from antiparallel: joint 3 flipped.
    "lite6": ("ufactory_lite6/lite6.xml", "attachment_site", "site", None),
}
SOLVED = [name for name, entry in REFERENCE.items() if entry[3] is None]


def reference_path(name: str):
    path = MENAGERIE / REFERENCE[name][0]
    if not path.is_file():
        pytest.skip(f"reference model {path} not available")
    return path


_IMPORTED: dict[str, om.Arm] = {}


def imported(name: str) -> om.Arm:
    """The arm of a reference model (imported once per test process)."""
    if name not in _IMPORTED:
        _, frame, frame_type, _ = REFERENCE[name]
        _IMPORTED[name] = om.arm_from_mujoco(reference_path(name), frame, frame_type)
    return _IMPORTED[name]


def same_arm(a: om.Arm, b: om.Arm) -> bool:
    """Bit for bit the same rows, transforms, limits and names."""
    return (
        a.chain.rows == b.chain.rows
        and np.array_equal(a.chain.T_root_base, b.chain.T_root_base)
        and np.array_equal(a.chain.T_flange_tool, b.chain.T_flange_tool)
        and np.array_equal(a.lower, b.lower)
        and np.array_equal(a.upper, b.upper)
        and (a.name, a.joint_names, a.description) == (b.name, b.joint_names, b.description)
        and (a.mujoco_model, a.frame_name, a.frame_type) == (b.mujoco_model, b.frame_name, b.frame_type)
    )


# ---------------------------------------------------------------------------------------
# The reference models: import, write, read back, check-model


def test_reference_table_covers_every_reference_model():
    if not MENAGERIE.is_dir():
        pytest.skip("reference models not available")
    files = {p.relative_to(MENAGERIE).as_posix() for p in MENAGERIE.glob("*/*.xml")}
    assert {entry[0] for entry in REFERENCE.values()} == files - {"franka_emika_panda/panda.xml"}


@pytest.mark.parametrize("name", REFERENCE)
def test_import_arm_then_check_model(capsys, tmp_path, name):
    """import-arm writes a file that load_arm reads back bit for bit as arm_from_mujoco's arm,
    and check-model accepts it at 1e-12 over 200 random joint vectors."""
    path, frame, frame_type, reason = REFERENCE[name]
    model_file = reference_path(name)
    out = tmp_path / f"{name}.toml"
    assert (
        main(["import-arm", str(model_file), "--frame", frame, "--frame-type", frame_type, "-o", str(out)])
        == 0
    )
    printed = capsys.readouterr().out
    assert printed.startswith(f"wrote {out}: arm '{name}', ")
    assert ("OMSolver: accepts it" in printed) == (reason is None), printed
    arm = om.load_arm(out)
    assert same_arm(arm, imported(name))
    assert (arm.mujoco_model, arm.frame_name, arm.frame_type) == (path, frame, frame_type)
    argv = ["check-model", str(model_file), "--arm", str(out), "--tolerance", "1e-12", "--samples", "200"]
    assert main([*argv, "-q"]) == 0, capsys.readouterr().err
    capsys.readouterr()


@pytest.mark.parametrize("name", REFERENCE)
def test_imported_fk_is_mujocos(name):
    """arm.fk equals MuJoCo's pose of the frame, and the joints' names and limits are the model's."""
    arm = imported(name)
    model = om.load_mujoco_model(reference_path(name))
    data = mujoco.MjData(model)
    for j, joint in enumerate(arm.joint_names):
        limited = bool(model.joint(joint).limited[0])
        lo, hi = model.joint(joint).range if limited else (-np.inf, np.inf)
        assert (arm.lower[j], arm.upper[j]) == (lo, hi)
    for q in random_q(arm, 50, np.random.default_rng(3)):
        np.testing.assert_allclose(arm.fk(q), frame_pose(model, data, arm, q), rtol=0, atol=IMPORT_TOLERANCE)


@pytest.mark.parametrize("name", [n for n in om.arm_names() if om.load_arm(n).mujoco_model])
def test_imports_of_the_shipped_arms_agree_with_their_files(name):
    """The shipped arm files were written by hand from the same models: the imports have their
    joints, limits, forward kinematics (both match the model) and closed-form family."""
    shipped = om.load_arm(name)
    arm = imported(next(k for k, v in REFERENCE.items() if v[0] == shipped.mujoco_model))
    assert arm.joint_names == shipped.joint_names
    assert np.array_equal(arm.lower, shipped.lower) and np.array_equal(arm.upper, shipped.upper)
    q = random_q(arm, 100, np.random.default_rng(2))
    np.testing.assert_allclose(arm.fk(q), shipped.fk(q), rtol=0, atol=1e-9)
    assert derive_model(arm).family_name == derive_model(shipped).family_name


# ---------------------------------------------------------------------------------------
# Solving the imported arms


@pytest.mark.parametrize("name", SOLVED)
def test_accepted_imports_solve_exactly(name):
    """At random q within limits: q is among solve_all(fk(q), c) with c its configuration, every
    root reaches MuJoCo's own frame pose to 1e-10 in configuration c, and the hinted solve
    returns q."""
    arm = imported(name)
    solver = om.OMSolver(arm)
    model = om.load_mujoco_model(reference_path(name))
    data = mujoco.MjData(model)
    for q in random_q(arm, 20, np.random.default_rng(11)):
        T = frame_pose(model, data, arm, q)
        c = solver.configuration_of(q)
        roots = solver.solve_all(T, c)
        distance = [np.abs(np.where(arm.revolute, wrap(r.q - q), r.q - q)).max() for r in roots]
        assert roots and min(distance) < 1e-7, (name, q)
        for root in roots:
            reached = frame_pose(model, data, arm, root.q)
            assert np.abs(reached[:3, 3] - T[:3, 3]).max() < 1e-10
            assert np.abs(reached[:3, :3] - T[:3, :3]).max() < 1e-10
            assert solver.configuration_of(root.q).isclose(c, 1e-7)
        hinted = solver.solve(T, c, q_hint=q)
        assert hinted.ok and np.abs(hinted.q - q).max() < 1e-7


# ---------------------------------------------------------------------------------------
# Models made for the test: axes in every relative position, URDF, prefix and root


def numbers(values) -> str:
    return " ".join(repr(float(v)) for v in values)


def random_chain_mjcf(seed: int, kinds: str) -> str:
    """A serial chain whose joint axes stand to the previous one as ``kinds`` says, joint by
    joint: r(andom), p(arallel), o(pposite), c(oincident), i(ntersecting), n(early parallel,
    1e-7 rad), s(lide, random). Each joint has a reference position (``ref``)."""
    rng = np.random.default_rng(seed)
    root = ET.Element("mujoco", model=f"chain{seed}")
    parent = ET.SubElement(root, "worldbody")
    axis, previous_anchor = rng.normal(size=3), np.zeros(3)  # the previous joint's, in the parent's frame
    for k, kind in enumerate(kinds, start=1):
        quat = rng.normal(size=4)
        pos = rng.uniform(-0.3, 0.3, 3)
        body = ET.SubElement(parent, "body", name=f"b{k}", pos=numbers(pos), quat=numbers(quat))
        ET.SubElement(body, "geom", size="0.01")
        R = np.empty(9)
        mujoco.mju_quat2Mat(R, quat / np.linalg.norm(quat))
        R = R.reshape(3, 3)
        # The previous axis, in this body's frame (ignoring the earlier joints, at q = 0).
        previous = R.T @ axis
        new = {
            "p": previous,
            "o": -previous,
            "c": previous,
            "n": previous + 1e-7 * np.cross(previous, rng.normal(size=3)),
        }.get(kind, rng.normal(size=3))
        anchor = R.T @ (previous_anchor - pos) if kind in "ci" else rng.uniform(-0.1, 0.1, 3)
        ET.SubElement(
            body,
            "joint",
            name=f"j{k}",
            type="slide" if kind == "s" else "hinge",
            pos=numbers(anchor),
            axis=numbers(new),
            range=f"{-1 - k * 0.1!r} {1 + k * 0.1!r}",
            ref=repr(0.05 * k),  # qpos0 != 0: the arm's q is qpos all the same
        )
        axis, previous_anchor, parent = new, anchor, body
    ET.SubElement(parent, "site", name="tip", pos="0.05 0.02 0.1", quat="0.3 0.1 -0.2 0.9")
    return ET.tostring(root, encoding="unicode")


def test_a_root_found_twice_at_a_fold_is_returned_once():
    """Menagerie's Piper (near the family) at a random q (benchmarks.menagerie's draw, row 386
    of 600) where two of the near kernel's seeds polish to the same root 1.9e-8 rad apart (the
    residual is flat near the fold): solve_all returned both copies; now the more accurate one
    (near.ONE_ROOT, as the compiled solver's OM_ONE_ROOT)."""
    arm = imported("piper")
    solver = om.OMSolver(arm)
    q = np.array(
        [
            -0.22937982107726818,
            2.0660538554928696,
            -2.6959803050728404,
            -1.6783798057344002,
            0.05393236479461438,
            -1.8900275012471828,
        ]
    )
    T = arm.fk(q)
    roots = solver.solve_all(T, solver.configuration_of(q))
    assert any(np.abs(wrap(r.q - q)).max() < 1e-7 for r in roots)
    for i, a in enumerate(roots):
        for b in roots[i + 1 :]:
            assert np.abs(wrap(a.q - b.q)).max() >= 1e-6


@pytest.mark.parametrize(
    "seed, kinds",
    [(0, "rrrrrr"), (1, "rpprrr"), (2, "rooprr"), (3, "rcirrr"), (4, "rnrnrr"), (5, "srsrs"), (6, "rpnoci")],
)
def test_any_axis_lines_import_exactly(tmp_path, seed, kinds):
    path = tmp_path / "chain.xml"
    path.write_text(random_chain_mjcf(seed, kinds))
    arm = om.arm_from_mujoco(path, "tip")
    model = om.load_mujoco_model(path)
    result = om.compare_mujoco_model(arm, model, samples=200, tolerance=IMPORT_TOLERANCE)
    assert result.ok, result.differences
    out = tmp_path / "chain.toml"
    om.write_arm_file(arm, out)
    assert same_arm(om.load_arm(out), arm)
    assert all(abs(v) < 10.0 for r in arm.chain.rows for v in (r.a, r.d)), arm.chain.rows


#: A UR-like URDF's joints: name, child link, origin xyz and rpy, axis z sign, limit (None: continuous).
UR_JOINTS = [
    ("shoulder_pan_joint", "shoulder_link", "0 0 0.1625", "0 0 0", -1, 6.283),
    ("shoulder_lift_joint", "upper_arm_link", "0 0 0", "1.570796326794897 0 0", 1, 6.283),
    ("elbow_joint", "forearm_link", "-0.425 0 0", "0 0 0", 1, 3.14),
    ("wrist_1_joint", "wrist_1_link", "-0.3922 0 0.1333", "0 0 0", 1, 6.283),
    ("wrist_2_joint", "wrist_2_link", "0 -0.0997 0", "1.570796326794897 0 0", -1, 6.283),
    (
        "wrist_3_joint",
        "wrist_3_link",
        "0 0.0996 0",
        "1.570796326794897 3.141592653589793 3.141592653589793",
        1,
        None,
    ),
    ("flange_fixed", "tool0", "0 0 0.05", "0 0 1.5707963", 0, None),
]


def ur_like_urdf(tmp_path, elbow: int = 1):
    """The URDF (meshes missing, tool0 on a fixed joint); elbow -1 turns the elbow about -z."""
    robot = ET.Element("robot", name="ur_like")
    base = ET.SubElement(robot, "link", name="base_link")
    for kind, suffix in (("visual", "dae"), ("collision", "stl")):
        geometry = ET.SubElement(ET.SubElement(base, kind), "geometry")
        ET.SubElement(geometry, "mesh", filename=f"package://ur_like/meshes/base.{suffix}")
    parent = "base_link"
    for name, child, xyz, rpy, sign, limit in UR_JOINTS:
        link = ET.SubElement(robot, "link", name=child)
        if sign:
            inertial = ET.SubElement(link, "inertial")
            ET.SubElement(inertial, "mass", value="1")
            ET.SubElement(inertial, "inertia", ixx="0.01", iyy="0.01", izz="0.01", ixy="0", ixz="0", iyz="0")
        kind = "fixed" if not sign else "continuous" if limit is None else "revolute"
        joint = ET.SubElement(robot, "joint", name=name, type=kind)
        ET.SubElement(joint, "parent", link=parent)
        ET.SubElement(joint, "child", link=child)
        ET.SubElement(joint, "origin", xyz=xyz, rpy=rpy)
        if sign:
            ET.SubElement(joint, "axis", xyz=f"0 0 {sign * (elbow if name == 'elbow_joint' else 1)}")
        if kind == "revolute":
            ET.SubElement(joint, "limit", lower=str(-limit), upper=str(limit), effort="100", velocity="3")
        parent = child
    path = tmp_path / "ur_like.urdf"
    path.write_text(ET.tostring(robot, encoding="unicode"))
    return path


def test_urdf_imports_through_mujocos_loader(tmp_path):
    """A UR-like URDF with missing meshes, joints 1 and 5 turning about -z and a tool frame on a
    fixed joint: imported, checked, and solved exactly."""
    path = ur_like_urdf(tmp_path)
    out = tmp_path / "ur_like.toml"
    argv = ["import-arm", str(path), "--frame", "tool0", "--frame-type", "body", "-o", str(out), "-q"]
    assert main(argv) == 0
    assert main(["check-model", str(path), "--arm", str(out), "--tolerance", "1e-12", "-q"]) == 0
    arm = om.load_arm(out)
    assert arm.joint_names[-1] == "wrist_3_joint" and np.isinf(arm.upper[-1])
    assert arm.mujoco_model == f"{tmp_path.name}/ur_like.urdf" and arm.name == "ur_like"
    solver = om.OMSolver(arm)
    for q in random_q(arm, 20, np.random.default_rng(5)):
        T = arm.fk(q)
        solution = solver.solve(T, solver.configuration_of(q))
        assert solution.ok and np.abs(arm.fk(solution.q) - T).max() < 1e-10


def test_an_axis_opposite_to_the_previous_one_is_a_twist_of_180_deg(tmp_path):
    """The elbow turning about -z, against the shoulder: the rows hold it exactly (alpha_2 =
    180 deg); the nominal arm flips joint 3 (q -> -q) and the solver is exact."""
    path = ur_like_urdf(tmp_path, elbow=-1)
    arm = om.arm_from_mujoco(path, "tool0", "body")
    assert abs(arm.chain.rows[1].alpha) == math.pi
    assert om.compare_mujoco_model(arm, om.load_mujoco_model(path), tolerance=IMPORT_TOLERANCE).ok
    solver = om.OMSolver(arm)
    assert solver.nominal is not None and list(solver.nominal.flip) == [1, 1, -1, 1, 1, 1]
    for q in random_q(arm, 20, np.random.default_rng(6)):
        T = arm.fk(q)
        solution = solver.solve(T, solver.configuration_of(q))
        assert solution.ok and np.abs(arm.fk(solution.q) - T).max() < 1e-10


def test_prefix_and_root(tmp_path):
    """The project's Panda MJCF with prefixed names, on a body that a free joint moves: the
    root body gives the arm; the names lose the prefix; the world as root is refused."""
    panda = om.load_arm("panda")
    root = ET.fromstring(om.arm_mjcf(panda, prefix="l_"))
    world = root.find("worldbody")
    cart = ET.SubElement(world, "body", name="cart", pos="1 2 0.3", quat="0.9 0 0 0.3")
    ET.SubElement(cart, "freejoint")
    ET.SubElement(cart, "geom", size="0.1")
    arm_base = world.find("body")
    world.remove(arm_base)
    arm_base.set("pos", "0.1 0 0.2")
    cart.append(arm_base)
    path = tmp_path / "mobile.xml"
    path.write_text(ET.tostring(root, encoding="unicode"))
    arm = om.arm_from_mujoco(path, "attachment_site", prefix="l_", root="l_base")
    assert arm.joint_names == panda.joint_names and arm.frame_name == "attachment_site"
    q = random_q(panda, 20, np.random.default_rng(0))
    np.testing.assert_allclose(arm.fk(q), panda.fk(q), rtol=0, atol=1e-12)
    # Given with its prefix, the frame is found too.
    assert same_arm(om.arm_from_mujoco(path, "l_attachment_site", prefix="l_", root="l_base"), arm)
    with pytest.raises(
        om.InvalidInput,
        match=r"is a free joint; an arm has hinge and slide joints: give the body it moves, 'cart', as the "
        r"root \(--root cart, root='cart'\)",
    ):
        om.arm_from_mujoco(path, "attachment_site", prefix="l_")


@pytest.mark.parametrize(
    "kwargs, error, message",
    [
        ({"frame_name": "nowhere"}, om.FrameNotFound, "nowhere"),
        (
            {"frame_name": "link7", "frame_type": "site"},
            om.InvalidInput,
            "a body of that name: give frame_type='body'",
        ),
        (
            {"frame_name": "attachment_site", "frame_type": "geom"},
            om.InvalidInput,
            "must be 'site' or 'body'",
        ),
        (
            {"frame_name": "attachment_site", "root": "nobody"},
            om.InvalidInput,
            "root body 'nobody' is not in",
        ),
        (
            {"frame_name": "link1", "frame_type": "body", "root": "link3"},
            om.InvalidInput,
            "not below root body",
        ),
        ({"frame_name": "attachment_site", "root": "link7"}, om.InvalidInput, "no joint moves site"),
        ({"frame_name": "nowhere", "prefix": "r_"}, om.FrameNotFound, r"'nowhere' \(nor 'r_nowhere'\)"),
        (
            {"frame_name": "attachment_site", "prefix": "r_"},
            om.InvalidInput,
            "joint 'joint7' between the root and the frame does not start with the prefix 'r_'$",
        ),
    ],
)
def test_import_errors_name_the_problem(kwargs, error, message):
    model = om.arm_model(om.load_arm("panda"))
    with pytest.raises(error, match=message):
        om.arm_from_mujoco(model, **kwargs)


# ---------------------------------------------------------------------------------------
# arm_mjcf and arm files of what the import finds


def test_arm_mjcf_of_an_arm_whose_frame_body_is_named_like_a_link():
    """Flexiv Rizon 4's frame is its body 'link7', the name the writer gives its seventh link."""
    arm = imported("flexiv_rizon4")
    model = om.arm_model(arm)
    assert model.body("link7").id == model.nbody - 1 and model.body("link7_body").id == model.nbody - 2
    result = om.compare_mujoco_model(arm, model, tolerance=IMPORT_TOLERANCE)
    assert result.ok, result.differences


def test_twists_written_near_90_deg_keep_the_nominal_structure():
    """The imported Sawyer's joints 6 and 7 are 6.4e-7 rad off perpendicular (Menagerie's
    quaternion): row 6 keeps its -90 deg twist and a fixed row adds the rest, as the shipped
    file does, so the 7-DOF model accepts it."""
    rows = imported("sawyer").chain.rows
    assert [r.kind.value for r in rows].count("fixed") == 1
    fixed = next(r for r in rows if r.kind.value == "fixed")
    assert fixed.a == fixed.d == fixed.theta == 0.0
    assert math.isclose(abs(fixed.alpha), 6.4e-7, rel_tol=0.01)
    assert abs(abs(rows[5].alpha) - math.pi / 2) == 0.0


def test_import_arm_json_and_errors(capsys, tmp_path):
    path = tmp_path / "panda.xml"
    path.write_text(om.arm_mjcf(om.load_arm("panda")))
    out = tmp_path / "mine.toml"
    status = main(
        ["import-arm", str(path), "--frame", "attachment_site", "--name", "mine", "-o", str(out), "--json"]
    )
    data = json.loads(capsys.readouterr().out)
    assert status == 0 and data["arm"] == "mine" and data["solver_accepts"] and data["reason"] is None
    assert data["model_family"].startswith("S-R-S") and data["max_position_error"] < 1e-15
    assert om.load_arm(out).name == "mine"
    for argv, message in [
        (["-o", str(tmp_path / "mine.txt")], "--output '.*mine.txt': use a file ending in .toml"),
        (["-o", str(out), "--frame", "link7"], "a body of that name: give frame_type='body'"),
        (["-o", str(out), "--root", "nowhere"], "root body 'nowhere' is not in the model"),
    ]:
        argv = ["import-arm", str(path), "--frame", "attachment_site", *argv]
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert re.search(message, err) and err.count("\n") == 1, err


def test_menagerie_benchmark_skips_absent_extra_arms(tmp_path):
    """``--extra DIR`` measures the EXTRA arms whose files DIR holds and skips the others."""
    assert set(available()) == set(REFERENCE)
    assert set(available(tmp_path)) == set(REFERENCE)
    name, entry = next(iter(EXTRA.items()))
    (tmp_path / entry.path).parent.mkdir(parents=True)
    (tmp_path / entry.path).write_text("<mujoco/>")
    arms = available(tmp_path)
    assert set(arms) == set(REFERENCE) | {name}
    assert arms[name] == (entry, tmp_path)
