"""The ``om-redundant`` command, run as a user runs it (a subprocess) where that is what is
tested (exit status, one-line errors, no traceback, pipes), else in-process through ``main``."""

from __future__ import annotations

import csv
import io
import json
import math
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pytest

import om_redundant as om
from om_redundant.cli import build_parser, main
from om_redundant.cli.common import UsageError
from om_redundant.cli.sweep import Progress, build_request, parse_obstacle, psi_grid, read_path
from om_redundant.ik.model import derive_model
from om_redundant.redundancy.sweep import SweepResult, compute_sweep, optimizer_for
from tests.conftest import MENAGERIE, ROOT, checkout_env, run_python

Q_PANDA = np.array([0.2, 0.4, -0.3, -1.8, 0.5, 1.9, 0.6])


def command(*args: str) -> subprocess.CompletedProcess:
    return run_python("-m", "om_redundant.cli", *args)


def pose_args(T: np.ndarray) -> list[str]:
    quat = np.empty(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(T[:3, :3]).ravel())
    return ["--xyz", *(repr(float(v)) for v in T[:3, 3]), "--quat", *(repr(float(v)) for v in quat)]


def in_process(capsys, *argv: str) -> tuple[int, str, str]:
    status = main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


# ---------------------------------------------------------------------------------------
# Conventions


def test_default_run_sweeps_the_panda_arm_angle():
    done = command()
    assert done.returncode == 0 and done.stderr == "", done.stderr
    assert "arm: panda" in done.stdout and "obstacles: 1" in done.stdout and "chosen: +1 -1 +1" in done.stdout


@pytest.mark.parametrize(
    "argv",
    [[], ["solve"], ["sweep"], ["arms"], ["check-model"], ["import-arm"], ["bench"]],
    ids=lambda a: a[0] if a else "top",
)
def test_help_everywhere(capsys, argv):
    status, out, _ = in_process(capsys, *argv, "--help")
    assert status == 0 and out.startswith(f"usage: om-redundant {' '.join(argv)}".rstrip())


@pytest.mark.parametrize(
    "argv, message",
    [
        (["solve", "--arm", "nope"], "unknown arm 'nope'"),
        (
            ["solve", "--xyz", "0", "0", "0", "--quat", "0", "0", "0", "0"],
            "--quat (0, 0, 0, 0) has zero norm",
        ),
        (["solve", "--pose-file", "no/such/pose.txt"], "cannot read pose file 'no/such/pose.txt'"),
        (["sweep", "--resolution", "-0.1"], "--resolution must be a positive number"),
        (["sweep", "--arm", "nope"], "unknown arm 'nope'"),
        (
            ["sweep", "--xyz", "0.5", "0", "0.4", "--quat", "0", "0", "0", "0"],
            "--quat (0, 0, 0, 0) has zero norm",
        ),
        (["sweep", "--path", "no/such/path.csv"], "cannot read path file 'no/such/path.csv'"),
    ],
    ids=[
        "unknown arm",
        "zero quaternion",
        "unreadable file",
        "negative resolution",
        "sweep unknown arm",
        "sweep zero quaternion",
        "sweep unreadable path",
    ],
)
def test_bad_input_exits_2_with_one_line_and_no_traceback(argv, message):
    done = command(*argv)
    assert done.returncode == 2
    assert done.stderr.startswith("om-redundant: error: ") and message in done.stderr
    assert done.stderr.count("\n") == 1 and done.stdout == ""


@pytest.mark.parametrize(
    "argv, message",
    [
        (["solve", "--signs", "1", "2", "1"], "-1 or +1"),
        (["solve", "--signs", "1", "1"], "--signs needs 3 values (ARM ELBOW WRIST)"),
        (["solve", "--xyz", "0", "0", "0"], "both --xyz and --quat"),
        (
            ["solve", "--xyz", "nan", "0", "0", "--quat", "1", "0", "0", "0"],
            "--xyz (nan, 0, 0) is not finite",
        ),
        (["solve", "--xyz", "1", "2"], "argument --xyz: expected 3 arguments"),
        (["solve", "--arm", "panda", "--psi", "inf"], "--psi must be a finite number"),
        (["solve", "--psi", "1"], "arm 'ur5e' has no arm angle"),
        (["solve", "--arm", "no/such/arm.toml"], "no/such/arm.toml"),
        (["bench", "paper", "--n", "0"], "--n must be positive"),
        (["frobnicate"], "invalid choice: 'frobnicate'"),
        (["arms", "nope"], "unknown arm 'nope'"),
        (["check-model", "model.xml"], "required: --arm"),
        (["check-model", "no/such/model.xml", "--arm", "panda"], "cannot read MuJoCo model"),
        (["check-model", "README.md", "--arm", "panda"], "must be an MJCF file ending in .xml"),
        (["check-model", "arms/panda.toml", "--arm", "nope"], "unknown arm 'nope'"),
        (["sweep", "--arm", "ur5e"], "arm 'ur5e' has no arm angle to sweep"),
        (["sweep", "--resolution", "0"], "--resolution must be a positive number"),
        (["sweep", "--resolution", "nan"], "--resolution must be a positive number"),
        (["sweep", "--resolution", "1e-9"], "the most is 100000"),
        (["sweep", "--signs", "1", "-1"], "--signs needs 3 values (SHOULDER ELBOW WRIST)"),
        (["sweep", "--obstacle", "cone:0,0,0,1"], "unknown shape 'cone'"),
        (["sweep", "--obstacle", "sphere:0,0,0"], "a sphere takes 4 numbers x,y,z,r, got 3"),
        (["sweep", "--obstacle", "box:0,0,0,1,-1,1"], "hy must be positive"),
        (["sweep", "--obstacle", "capsule:0,0,0,0,0,0,0.1"], "ends coincide"),
        (["sweep", "--obstacle", "sphere:0,0,x,1"], "z = 'x' is not a number"),
        (["sweep", "--scene", "no/such/scene.xml"], "cannot read MuJoCo model 'no/such/scene.xml'"),
        (["sweep", "--path", "no/such/path.csv"], "cannot read path file 'no/such/path.csv'"),
        (["sweep", "--path", "README.md", "--xyz", "0", "0", "0"], "either --path or a single pose"),
        (["sweep", "--plot", "sweep.jpg"], "use a file ending in .png or .svg"),
        (["sweep", "--csv", "no/such/dir/sweep.csv"], "directory 'no/such/dir' does not exist"),
        (["sweep", "--csv", "--json"], "cannot both go to standard output"),
        (["sweep", "--singularity-weight", "-1"], "--singularity-weight must be a finite number >= 0"),
        (["sweep", "--singularity-weight", "inf"], "--singularity-weight must be a finite number >= 0"),
    ],
)
def test_more_bad_input_one_line(capsys, argv, message):
    status, out, err = in_process(capsys, *argv)
    assert status == 2 and out == ""
    assert err.startswith("om-redundant: error: ") and message in err and err.count("\n") == 1


def test_bad_pose_files_name_the_problem(capsys, tmp_path):
    cases = {
        "short.txt": ("1 0 0 0\n0 1 0 0\n0 0 1 0\n", "must hold a 4x4 matrix, got shape (3, 4)"),
        "words.txt": ("a b c d\n", "cannot read pose file"),
        "skew.txt": ("1 0 0 0\n0 1 0.5 0\n0 0 1 0\n0 0 0 1\n", "rotation is not orthonormal"),
    }
    for name, (text, message) in cases.items():
        (tmp_path / name).write_text(text)
        status, _, err = in_process(capsys, "solve", "--pose-file", str(tmp_path / name))
        assert status == 2 and message in err and err.count("\n") == 1, err


def test_closed_pipe_exits_quietly():
    """``om-redundant arms | head -1`` when the reader is already gone: no traceback, status 141."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "om_redundant.cli", "arms"],
        cwd=ROOT,
        env=checkout_env(),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    proc.stdout.close()
    err = proc.stderr.read()
    assert proc.wait(timeout=120) == 141 and err == b""


# Issue 18, item 6: a quaternion whose norm overflows keeps its direction.


def test_a_quaternion_whose_norm_overflows_keeps_its_direction(capsys):
    argv = ["solve", "--xyz", "0.3", "0.1", "0.4", "--quat", "1e300", "1e300", "1e300", "1e300", "--json"]
    status, out, _ = in_process(capsys, *argv)
    T = np.array(json.loads(out)["target"])
    assert status == 0
    np.testing.assert_allclose(T[:3, :3], [[0, 0, 1], [1, 0, 0], [0, 1, 0]], atol=1e-15)  # not the identity


@pytest.mark.parametrize(
    "quat, message",
    [
        (["1e-300"] * 4, "--quat (1e-300, 1e-300, 1e-300, 1e-300) has zero norm"),
        (["nan", "1", "1", "1"], "--quat (nan, 1, 1, 1) is not finite"),
        (["inf", "1", "1", "1"], "--quat (inf, 1, 1, 1) is not finite"),
    ],
)
def test_a_quaternion_without_a_direction_exits_2(capsys, quat, message):
    status, out, err = in_process(capsys, "solve", "--xyz", "0.3", "0.1", "0.4", "--quat", *quat)
    assert status == 2 and out == "" and message in err and err.count("\n") == 1, err


# Issue 18, item 8: pose files of the wrong kind, and a closed standard output.


def test_pose_files_of_the_wrong_kind_exit_2_with_one_line(capsys, tmp_path):
    arrays = {
        "structured.npy": (np.zeros((4, 4), dtype=[("a", "f8"), ("b", "i4")]), "got a structured array"),
        "zero_size.npy": (np.zeros((0,)), "must hold a 4x4 matrix, got shape (0,)"),
        "complex.npy": (np.eye(4, dtype=complex), "got complex numbers"),
        "bool.npy": (np.eye(4, dtype=bool), "got booleans"),
        "objects.npy": (np.array([None, 1], dtype=object), "cannot read pose file"),  # a pickle
    }
    for name, (array, _) in arrays.items():
        np.save(tmp_path / name, array, allow_pickle=True)
    (tmp_path / "empty.npy").write_bytes(b"")
    (tmp_path / "cut.npy").write_bytes((tmp_path / "bool.npy").read_bytes()[:70])
    cases = {name: message for name, (_, message) in arrays.items()}
    cases |= {"empty.npy": "cannot read pose file", "cut.npy": "cannot read pose file"}
    for name, message in cases.items():
        status, out, err = in_process(capsys, "solve", "--pose-file", str(tmp_path / name))
        assert status == 2 and out == "" and err.startswith("om-redundant: error: "), (name, err)
        assert message in err and err.count("\n") == 1, (name, err)


def closed_stdout(*args: str) -> subprocess.CompletedProcess:
    """The command started with standard output closed, as ``om-redundant ARGS >&-``."""
    return subprocess.run(
        [sys.executable, "-m", "om_redundant.cli", *args],
        cwd=ROOT,
        env=checkout_env(),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: os.close(1),
        timeout=300,
    )


def test_closed_stdout_is_an_error_only_when_there_is_something_to_print(tmp_path):
    done = closed_stdout("solve")
    assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
    assert done.stderr.startswith("om-redundant: error: standard output is closed")
    assert closed_stdout("solve", "-q").returncode == 0
    done = closed_stdout("solve", "-q", "--json", str(tmp_path / "out.json"))
    assert done.returncode == 0 and done.stderr == ""
    assert json.loads((tmp_path / "out.json").read_text())["arm"] == "ur5e"


# ---------------------------------------------------------------------------------------
# solve


def test_solve_json_agrees_with_the_library():
    solver = om.OMSolver("panda")
    T = solver.arm.fk(Q_PANDA)
    c = solver.configuration_of(Q_PANDA)
    signs = [str(s) for s in c.signs]
    done = command(
        "solve",
        "--arm",
        "panda",
        *pose_args(T),
        "--psi",
        repr(float(c.redundancy[0])),
        "--signs",
        *signs,
        "--json",
    )
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    assert data["arm"] == "panda" and data["sign_names"] == ["SHOULDER", "ELBOW", "WRIST"]
    (row,) = data["solutions"]
    expected = solver.solve(np.array(data["target"]), om.Configuration(c.signs, c.redundancy))
    assert row["ok"] and row["status"] == "ok" and row["within_limits"]
    np.testing.assert_array_equal(row["q"], expected.q)
    np.testing.assert_allclose(row["q"], Q_PANDA, atol=1e-9)
    assert row["position_error"] == expected.position_error < 1e-10


def test_solve_every_configuration_and_every_root(capsys):
    solver = om.OMSolver("panda")
    T = solver.arm.fk(Q_PANDA)
    status, out, _ = in_process(capsys, "solve", "--arm", "panda", *pose_args(T), "--psi", "0.3", "--json")
    data = json.loads(out)
    rows, T = data["solutions"], np.array(data["target"])
    assert status == 0 and len(rows) == 8
    for row in rows:
        sol = solver.solve(T, om.Configuration(tuple(row["signs"]), (0.3,)))
        assert row["ok"] == sol.ok and row["status"] == sol.status
        assert (row["q"] is None) == (not sol.ok)
    status, out, _ = in_process(
        capsys, "solve", "--arm", "panda", *pose_args(T), "--psi", "0.3", "--all-roots", "--json"
    )
    data = json.loads(out)
    rows, T = data["solutions"], np.array(data["target"])
    expected = [(c.signs, s.q) for c in solver.configurations((0.3,)) for s in solver.solve_all(T, c)]
    found = [(tuple(r["signs"]), r["q"]) for r in rows if r["ok"]]
    assert status == 0 and len(found) == len(expected)
    for (signs, q), (want_signs, want_q) in zip(found, expected, strict=True):
        assert signs == want_signs
        np.testing.assert_array_equal(q, want_q)


def test_solve_table_quiet_and_json_file(capsys, tmp_path):
    argv = ["solve", "--arm", "spherical", "--xyz", "0.1", "0.2", "0.3", "--quat", "1", "0", "0", "0"]
    status, out, _ = in_process(capsys, *argv, "--signs", "1", "1", "1")
    assert status == 0 and "ARM ELBOW WRIST" in out and "dp_max = 0.0200 m" in out
    status, out, err = in_process(capsys, *argv, "--quiet")
    assert status == 0 and out == err == ""
    status, out, _ = in_process(capsys, *argv, "--json", str(tmp_path / "solve.json"))
    assert status == 0 and "ARM ELBOW WRIST" in out
    assert len(json.loads((tmp_path / "solve.json").read_text())["solutions"]) == 8
    pose = tmp_path / "pose.npy"
    np.save(pose, om.load_arm("ur5e").fk(np.array([0.4, -1.1, 1.3, -1.2, -1.4, 0.3])))
    status, out, _ = in_process(capsys, "solve", "--pose-file", str(pose), "--json")
    assert status == 0 and sum(r["ok"] for r in json.loads(out)["solutions"]) == 8


# ---------------------------------------------------------------------------------------
# arms, bench


def test_arms_lists_every_arm_with_its_model(arm_without_a_model):
    done = command("arms", "--json")
    assert done.returncode == 0, done.stderr
    rows = {row["name"]: row for row in json.loads(done.stdout)}
    assert list(rows) == om.arm_names()
    for name, row in rows.items():
        arm = om.load_arm(name)
        assert row["dof"] == arm.dof and row["joint_names"] == list(arm.joint_names)
        model = derive_model(arm)
        assert row["solvable"] and row["dp_max"] == model.dp_max and row["model_family"] == model.family_name
        assert row["sign_names"] == list(model.sign_names)
        assert row["redundancy_names"] == list(model.redundancy_names)
    assert rows["ur5e"]["upper"][0] == pytest.approx(6.28319)
    done = command("arms", str(arm_without_a_model), "--json")
    (row,) = json.loads(done.stdout)
    assert not row["solvable"] and row["dp_max"] is None
    assert row["reason"] == "fixed rows between joint 6 ('right_j5') and joint 7 ('right_j6') need a = 0"


def test_arms_table(capsys, arm_without_a_model):
    status, out, _ = in_process(capsys, "arms")
    lines = out.splitlines()
    assert status == 0 and len(lines) == 1 + len(om.arm_names())
    assert "0.0121 m" in out and "not yet solvable" not in out
    status, out, _ = in_process(capsys, "arms", str(arm_without_a_model))
    reason = "fixed rows between joint 6 ('right_j5') and joint 7 ('right_j6') need a = 0"
    assert status == 0 and f"not yet solvable: {reason}" in out


@pytest.mark.parametrize("subcommand", ["solve", "sweep"])
def test_an_arm_without_a_model_is_refused_in_one_line(capsys, arm_without_a_model, subcommand):
    status, _, err = in_process(capsys, subcommand, "--arm", str(arm_without_a_model))
    assert status == 2
    reason = "fixed rows between joint 6 ('right_j5') and joint 7 ('right_j6') need a = 0"
    assert err.strip().endswith(f"arm 'bent': {reason}")


def test_bench_paper_small_run(capsys):
    status, out, _ = in_process(capsys, "bench", "paper", "--n", "40", "--json")
    data = json.loads(out)
    assert status == 0 and data["n"] == 40 and data["converged"] == 1.0 and data["configuration_errors"] == 0


# ---------------------------------------------------------------------------------------
# check-model


def panda_mjcf(**changes) -> str:
    """The project's Panda MJCF with one change: a joint's range or name, a body's position,
    a joint's axis, or no end-effector site."""
    root = ET.fromstring(om.arm_mjcf(om.load_arm("panda")))
    joints = {j.get("name"): j for j in root.iter("joint")}
    bodies = {b.get("name"): b for b in root.iter("body")}
    if "range" in changes:
        joints["joint4"].set("range", changes["range"])
    if "rename" in changes:
        joints["joint3"].set("name", changes["rename"])
    if "move" in changes:
        pos = np.array(bodies["link4"].get("pos").split(), dtype=float) + changes["move"]
        bodies["link4"].set("pos", " ".join(repr(float(v)) for v in pos))
    if "axis" in changes:
        joints["joint2"].set("axis", changes["axis"])
    if "site" in changes:
        next(root.find("worldbody").iter("site")).set("name", changes["site"])
    if "mount" in changes:
        bodies["base"].set("pos", changes["mount"])
    return ET.tostring(root, encoding="unicode")


def test_check_model_accepts_the_projects_own_model(tmp_path):
    path = tmp_path / "panda.xml"
    path.write_text(panda_mjcf())
    done = command("check-model", str(path), "--arm", "panda")
    assert done.returncode == 0, done.stderr
    assert "matches arm 'panda'" in done.stdout and "site 'attachment_site'" in done.stdout


@pytest.mark.parametrize(
    "change, message",
    [
        (
            {"range": "-3 -0.0698"},
            "joint 'joint4' range differs: model [-3, -0.0698], arm [-3.0718, -0.0698]",
        ),
        (
            {"rename": "elbow"},
            "joint 'joint3' (arm joint 3) is not in the model; model joints: joint1, joint2, elbow",
        ),
        ({"move": [0.0, 0.0, 0.01]}, "joint 'joint4' lies up to 0.01 m off the arm's joint axis"),
        ({"axis": "0 0 -1"}, "joint 'joint2' axis differs from the arm's by up to 3.14 rad (reversed)"),
        ({"site": "flange"}, "site 'attachment_site' is not in the model"),
        ({"mount": "0.5 0 0"}, "joint 'joint1' lies up to 0.5 m off the arm's joint axis"),
    ],
    ids=["range", "renamed joint", "moved body", "reversed axis", "no site", "mounted elsewhere"],
)
def test_check_model_names_what_differs(capsys, tmp_path, change, message):
    path = tmp_path / "panda.xml"
    path.write_text(panda_mjcf(**change))
    status, out, err = in_process(capsys, "check-model", str(path), "--arm", "panda")
    assert status == 1 and out == "" and err.count("\n") == 1
    assert err.startswith(f"om-redundant: error: {path} differs from arm 'panda': {message}"), err


def test_check_model_moved_body_changes_the_frame_too(capsys, tmp_path):
    path = tmp_path / "panda.xml"
    path.write_text(panda_mjcf(move=[0.0, 0.0, 0.01]))
    status, out, _ = in_process(capsys, "check-model", str(path), "--arm", "panda", "--json")
    data = json.loads(out)
    assert status == 1 and not data["ok"] and len(data["differences"]) == 2
    assert data["differences"][1].startswith(
        "site 'attachment_site' differs from the arm's end-effector frame"
    )
    assert data["max_position_error"] > 0.005


def test_check_model_prefix_root_and_site_options(capsys, tmp_path):
    arm = om.load_arm("panda")
    path = tmp_path / "left.xml"
    path.write_text(om.arm_mjcf(arm, prefix="l_"))
    assert in_process(capsys, "check-model", str(path), "--arm", "panda", "--prefix", "l_")[0] == 0
    path.write_text(panda_mjcf(mount="1 2 0.5"))
    assert in_process(capsys, "check-model", str(path), "--arm", "panda", "--root", "base", "--json")[0] == 0
    path.write_text(panda_mjcf(site="flange"))
    assert in_process(capsys, "check-model", str(path), "--arm", "panda", "--site", "flange", "-q") == (
        0,
        "",
        "",
    )


@pytest.mark.parametrize(
    "option, message",
    [(["--samples", "0"], "samples must be at least 1"), (["--tolerance", "nan"], "tolerance")],
)
def test_check_model_bad_settings(capsys, tmp_path, option, message):
    path = tmp_path / "panda.xml"
    path.write_text(panda_mjcf())
    status, _, err = in_process(capsys, "check-model", str(path), "--arm", "panda", *option)
    assert status == 2 and message in err and err.count("\n") == 1


def test_check_model_against_the_menagerie_panda():
    path = MENAGERIE / "franka_emika_panda" / "panda_nohand.xml"
    if not path.is_file():
        pytest.skip(f"reference model {path} not available")
    done = command("check-model", str(path), "--arm", "panda", "--samples", "200", "--json")
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    assert data["ok"] and data["samples"] == 200 and data["max_position_error"] < 1e-12
    done = command("check-model", str(path), "--arm", "fr3")
    assert done.returncode == 1 and "joint 'fr3_joint1' (arm joint 1) is not in the model" in done.stderr


def test_check_model_skips_missing_textures_and_mesh_fitted_geoms(capsys, tmp_path):
    """A material's texture file and a capsule fitted to a mesh (both missing) do not stop the
    kinematics; an error that remains names its own cause, not the mesh."""
    text = om.arm_mjcf(om.load_arm("ur5e")).replace(
        "<worldbody>",
        '<asset><texture name="skin" type="2d" file="gone.png"/><material name="m" texture="skin"/>'
        '<mesh name="shell" file="gone.stl"/></asset><worldbody>',
    )
    shell = '<body name="shell"><geom type="capsule" mesh="shell" material="m"/></body>'
    text = text.replace('<body name="link2"', shell + '<body name="link2"', 1)
    path = tmp_path / "ur5e.xml"
    path.write_text(text)
    assert in_process(capsys, "check-model", str(path), "--arm", "ur5e", "-q") == (0, "", "")
    path.write_text(text.replace("</mujoco>", '<actuator><motor joint="no_such_joint"/></actuator></mujoco>'))
    status, _, err = in_process(capsys, "check-model", str(path), "--arm", "ur5e")
    assert status == 2 and err.count("\n") == 1
    assert re.search(
        r"no_such_joint.*\(with its inertial data replaced and its meshes and textures skipped, which failed "
        r"first: .*gone",
        err,
    )


# ---------------------------------------------------------------------------------------
# sweep: the input, checked into a request


def sweep_request(*argv: str):
    args = build_parser().parse_args(["sweep", *argv])
    return build_request(args)


def test_sweep_request_defaults():
    request = sweep_request()
    solver = om.OMSolver("panda")
    assert request.solver.arm.name == "panda" and not request.path and request.obstacles == ()
    np.testing.assert_array_equal(request.poses, solver.arm.fk(Q_PANDA)[None])
    assert request.branches == tuple(c.signs for c in solver.configurations())
    assert len(request.psi) == 360 and request.psi[0] == -math.pi and request.psi[-1] < math.pi
    assert request.scene is None and request.singularity_weight == 0.1


def test_sweep_request_with_everything(tmp_path):
    scene = tmp_path / "scene.xml"
    scene.write_text(
        '<mujoco><worldbody><geom name="table" type="box" size="0.5 0.5 0.02"/></worldbody></mujoco>'
    )
    path = tmp_path / "poses.csv"
    path.write_text("# a path\nt,qw,qx,qy,qz,x,y,z\n0,0,1,0,0,0.5,0,0.4\n\n1,0,1,0,0,0.5,0.1,0.4\n")
    request = sweep_request(
        "--arm", "iiwa14", "--path", str(path), "--signs", "1", "-1", "1", "--resolution", "0.1",
        "--obstacle", "sphere:0.4,0,0.3,0.05", "--obstacle", "capsule:0,0,0,0,0,1,0.1",
        "--obstacle", "box:0.5,0,0,0.1,0.2,0.3", "--scene", str(scene),
        "--csv", str(tmp_path / "s.csv"), "--json", str(tmp_path / "s.json"),
        "--plot", str(tmp_path / "map.svg"), "--singularity-weight", "0.5",
    )  # fmt: skip
    assert request.path and request.poses.shape == (2, 4, 4) and request.branches == ((1, -1, 1),)
    np.testing.assert_allclose(request.poses[1, :3, 3], [0.5, 0.1, 0.4])
    np.testing.assert_allclose(request.poses[1, :3, :3], np.diag([1.0, -1.0, -1.0]), atol=1e-15)
    assert len(request.psi) == 63 and np.allclose(np.diff(request.psi), 2 * math.pi / 63)
    assert [o.kind for o in request.obstacles] == ["sphere", "capsule", "box"]
    assert request.scene.ngeom == 1
    assert request.singularity_weight == 0.5 and optimizer_for(request).objective.singularity_weight == 0.5


def test_sweep_json_agrees_with_the_optimiser(tmp_path):
    """A subprocess run with an obstacle and a scene: the chosen configuration and q are
    RedundancyOptimizer.choose's, the intervals its intervals(T) (exact ends)."""
    scene = tmp_path / "scene.xml"
    scene.write_text(
        '<mujoco><worldbody><geom name="table" type="box" pos="0.6 0 -0.05" size="0.3 0.3 0.02"/>'
        "</worldbody></mujoco>"
    )
    out = tmp_path / "sweep.json"
    ball = "sphere:0.2,0.12,0.6,0.05"
    done = command(
        "sweep", "--obstacle", ball, "--scene", str(scene), "--resolution", "0.05", "--json", str(out)
    )
    assert done.returncode == 0, done.stderr
    data = json.loads(out.read_text())
    solver = om.OMSolver("panda")
    T = solver.arm.fk(Q_PANDA)
    shapes = [om.Sphere([0.2, 0.12, 0.6], 0.05, "cli_sphere0"), om.load_mujoco_model(scene)]
    optimizer = om.RedundancyOptimizer(solver, om.Clearance.for_arm(solver.arm, shapes))
    choice = optimizer.choose(T)
    (pose,) = data["poses"]
    chosen = pose["chosen"]
    assert tuple(chosen["signs"]) == choice.configuration.signs
    assert chosen["psi"] == pytest.approx(choice.configuration.redundancy[0], abs=1e-9)
    np.testing.assert_allclose(chosen["q"], choice.solution.q, atol=1e-9)
    assert chosen["margin"] == pytest.approx(choice.margin) and chosen["clearance"] == pytest.approx(
        choice.clearance
    )
    expected = {}
    for iv in optimizer.intervals(T):
        expected.setdefault(iv.signs, []).append([iv.lo, iv.hi])
    for branch in pose["branches"]:
        np.testing.assert_allclose(
            np.reshape(branch["intervals"], (-1, 2)),
            np.reshape(expected.get(tuple(branch["signs"]), []), (-1, 2)),
        )
    assert sum(bool(b["intervals"]) for b in pose["branches"]) == 2
    # the grid columns: margins are the library's, clearance the optimiser's own
    branch = next(b for b in pose["branches"] if tuple(b["signs"]) == choice.configuration.signs)
    k = int(np.flatnonzero(branch["ok"])[0])
    q = np.array(branch["q"][k])
    np.testing.assert_allclose(branch["margin"][k], om.joint_margins(solver.arm, q))
    assert branch["clearance"][k] == pytest.approx(optimizer.objective.clearance.minimum(q))


def test_sweep_plot_is_a_png_of_sensible_size(tmp_path):
    plot = tmp_path / "sweep.png"
    done = command(
        "sweep", "--obstacle", "sphere:0.2,0.12,0.6,0.05", "--resolution", "0.05", "--plot", str(plot), "-q"
    )
    assert done.returncode == 0 and done.stdout == "", done.stderr
    width, height = png_size(plot)
    assert plot.stat().st_size > 20_000 and 1000 <= width <= 2000 and 700 <= height <= 1500


def test_obstacles_parse_into_mujoco_geoms():
    specs = ["sphere:0.4,0,0.3,0.05", "capsule: 0,0,0, 0,0,1, 0.1", "BOX:0.5,0,0,0.1,0.2,0.3"]
    obstacles = [parse_obstacle(s) for s in specs]
    assert obstacles[1].values == (0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.1)
    shapes = [o.shape(f"o{k}") for k, o in enumerate(obstacles)]
    assert [type(s) for s in shapes] == [om.Sphere, om.Capsule, om.Box]
    model = om.Clearance.for_arm(om.load_arm("panda"), shapes).model
    sizes = [model.geom(f"o{k}").size for k in range(3)]
    np.testing.assert_allclose([s[0] for s in sizes], [0.05, 0.1, 0.1])
    np.testing.assert_allclose(sizes[2], [0.1, 0.2, 0.3])
    np.testing.assert_allclose(model.geom("o1").size[1], 0.5)
    np.testing.assert_allclose(model.geom("o2").pos, [0.5, 0, 0])


def test_path_files(tmp_path):
    path = tmp_path / "p.csv"
    path.write_text("0.5,0,0.4,1,0,0,0\n0.5,0,0.4,2,0,0,0\n")
    poses = read_path(str(path))
    assert poses.shape == (2, 4, 4) and np.allclose(poses[1, :3, :3], np.eye(3))
    bad = {
        "0.5,0,0.4,0,0,0,0\n": "line 1: quaternion (0, 0, 0, 0) has zero norm",
        "x,y,z,qw\n": "the header lacks column(s) qx, qy, qz",
        "x,y,z,qw,qx,qy,qz\n": "holds no poses",
        "0.5,0,0.4,1,0,0\n": "line 1: expected 7 values, got 6",
        "0.5,0,0.4,1,0,0,0\n0.5,a,0.4,1,0,0,0\n": "line 2: not a number",
        "0.5,0,inf,1,0,0,0\n": "line 1: position (0.5, 0, inf) is not finite",
    }
    for text, message in bad.items():
        path.write_text(text)
        with pytest.raises(UsageError, match=message.replace("(", r"\(").replace(")", r"\)")):
            read_path(str(path))


def test_psi_grid_covers_the_circle_once():
    assert len(psi_grid(2 * math.pi)) == 1 and len(psi_grid(100.0)) == 1
    grid = psi_grid(2 * math.pi / 720)
    assert len(grid) == 720 and grid[0] == -math.pi and math.pi - grid[-1] == pytest.approx(2 * math.pi / 720)


# ---------------------------------------------------------------------------------------
# sweep: what the command shows of a result, in-process with the real engine


def recording(monkeypatch) -> list[SweepResult]:
    """Record every result of compute_sweep during the test."""
    results = []
    real = compute_sweep

    def engine(request):
        results.append(real(request))
        return results[-1]

    monkeypatch.setattr("om_redundant.cli.sweep.compute_sweep", engine)
    return results


def png_size(path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")


def test_sweep_outputs_agree_with_the_result(capsys, tmp_path, monkeypatch):
    results = recording(monkeypatch)
    files = {"csv": tmp_path / "sweep.csv", "json": tmp_path / "sweep.json", "plot": tmp_path / "sweep.png"}
    argv = ["sweep", "--resolution", "0.05", *(a for k, f in files.items() for a in (f"--{k}", str(f)))]
    status, out, err = in_process(capsys, *argv)
    assert status == 0 and err == ""
    (result,) = results
    (pose,) = result.poses
    signs = " ".join(f"{v:+d}" for v in pose.chosen.configuration.signs)
    assert f"chosen: {signs}, psi = {pose.chosen.configuration.redundancy[0]:.4f} rad" in out
    for branch in pose.branches:
        assert all(f"[{lo:+.3f}, {hi:+.3f}]" in out for lo, hi in branch.intervals)
    assert sum(bool(b.intervals) for b in pose.branches) == 2
    width, height = png_size(files["plot"])
    assert 1000 <= width <= 2000 and 700 <= height <= 1500

    rows = list(csv.DictReader(files["csv"].open()))
    assert len(rows) == 8 * len(result.psi)
    for row in rows[:: len(result.psi) // 3]:
        k = int(np.argmin(np.abs(result.psi - float(row["psi"]))))
        branch = next(
            b for b in pose.branches if b.signs == tuple(int(row[n]) for n in ("SHOULDER", "ELBOW", "WRIST"))
        )
        assert float(row["psi"]) == result.psi[k] and bool(int(row["feasible"])) == branch.feasible[k]
        q = [float(row[f"q_joint{j}"]) for j in range(1, 8)]
        np.testing.assert_array_equal(q, branch.q[k])

    data = json.loads(files["json"].read_text())
    np.testing.assert_array_equal(data["psi"], result.psi)
    (got,) = data["poses"]
    assert got["chosen"]["psi"] == pose.chosen.configuration.redundancy[0]
    np.testing.assert_array_equal(got["chosen"]["q"], pose.chosen.q)
    for b, branch in zip(got["branches"], pose.branches, strict=True):
        assert tuple(b["signs"]) == branch.signs and [tuple(i) for i in b["intervals"]] == list(
            branch.intervals
        )
        q = np.array([[np.nan if v is None else v for v in r] for r in b["q"]])
        np.testing.assert_array_equal(q, branch.q)


def test_sweep_path_map_and_stdout_outputs(capsys, tmp_path, monkeypatch):
    solver = om.OMSolver("panda")
    path = tmp_path / "path.csv"
    rows = []
    for s in np.linspace(0.0, 0.6, 4):
        T = solver.arm.fk(Q_PANDA + s * np.array([1.0, 0.3, 0.0, 0.4, 0.0, -0.5, 0.0]))
        quat = np.empty(4)
        mujoco.mju_mat2Quat(quat, np.ascontiguousarray(T[:3, :3]).ravel())
        rows.append(",".join(repr(float(v)) for v in (*T[:3, 3], *quat)))
    path.write_text("\n".join(rows) + "\n")
    plot = tmp_path / "map.svg"
    argv = ["sweep", "--path", str(path), "--signs", "1", "-1", "1", "--resolution", "0.1"]
    status, out, _ = in_process(capsys, *argv, "--plot", str(plot))
    assert status == 0 and len(out.splitlines()) == 4 + 4 and plot.read_text().startswith("<?xml")
    png = tmp_path / "map.png"
    assert in_process(capsys, *argv, "--plot", str(png), "-q")[0] == 0 and png_size(png)[0] >= 800
    status, out, _ = in_process(capsys, *argv, "--json")
    data = json.loads(out)
    assert status == 0 and len(data["poses"]) == 4 and all(p["chosen"] for p in data["poses"])
    status, out, _ = in_process(capsys, *argv, "--csv", "--quiet")
    assert status == 0 and out.startswith(
        "pose,SHOULDER,ELBOW,WRIST,psi,ok,feasible,margin,clearance,q_joint1"
    )
    assert len(out.splitlines()) == 1 + 4 * 63


def test_progress_bar_on_a_terminal(monkeypatch):
    class Terminal(io.StringIO):
        def isatty(self):
            return True

    monkeypatch.setattr(sys, "stderr", Terminal())
    progress = Progress(4)
    for done in range(1, 5):
        progress(done)
    text = sys.stderr.getvalue()
    assert (
        text.count("\r") == 4
        and text.endswith("4/4 poses\n")
        and "[###############...............] 2/4" in text
    )
    assert not Progress(4, enabled=False).enabled and not Progress(1).enabled


def test_sweep_path_tracks_like_the_optimiser_and_says_why_not(capsys, tmp_path):
    """Every branch (some unsolved at some psi: no hints there), an obstacle: the tracked
    choices are choose(T, previous)'s, and a pose where tracking stopped is chosen afresh and
    says why."""
    solver = om.OMSolver("panda")
    rows = []
    for t in np.linspace(0.0, 0.5, 3):
        T = solver.arm.fk(Q_PANDA + t * np.array([1.0, 0.3, 0.0, 0.4, 0.0, -0.5, 0.0]))
        quat = np.empty(4)
        mujoco.mju_mat2Quat(quat, np.ascontiguousarray(T[:3, :3]).ravel())
        rows.append(",".join(repr(float(v)) for v in (*T[:3, 3], *quat)))
    path = tmp_path / "path.csv"
    path.write_text("\n".join(rows) + "\n")
    poses = read_path(str(path))
    ball = "sphere:0.2,0.12,0.6,0.05"
    status, out, err = in_process(
        capsys, "sweep", "--path", str(path), "--obstacle", ball, "--json", "--resolution", "0.1"
    )
    assert status == 0, err
    data = json.loads(out)
    optimizer = om.RedundancyOptimizer(solver, [om.Sphere([0.2, 0.12, 0.6], 0.05)])
    previous = None
    for got, T in zip(data["poses"], poses, strict=True):
        choice = optimizer.choose(T, previous)
        previous = choice
        assert choice.ok and got["note"] == choice.reason
        assert got["chosen"]["psi"] == pytest.approx(choice.configuration.redundancy[0], abs=1e-9)
        assert got["chosen"]["rechosen"] == choice.rechosen
        assert choice.rechosen == got["note"].startswith("tracking from branch")
    assert any(p["chosen"]["rechosen"] for p in data["poses"])
