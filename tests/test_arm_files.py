"""Arm files: loading, the built-in arms, and errors that name file, field and problem."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import om_redundant as om
from om_redundant.kinematics import pose_from_xyz_quat
from tests.conftest import random_q

UR5E_ROWS = """
[[rows]]
joint = "j1"
type = "revolute"
d = 0.1
alpha_deg = 90
"""


def write(tmp_path, text):
    path = tmp_path / "arm.toml"
    path.write_text(text)
    return path


def test_builtin_arms_are_listed_and_load():
    names = om.arm_names()
    assert names[:2] == ["spherical", "ur5e"]
    for name in names:
        arm = om.load_arm(name)
        assert arm.name == name and len(arm.joint_names) == arm.dof


def test_load_by_path_equals_load_by_name(tmp_path):
    by_name = om.load_arm("ur5e")
    by_path = om.load_arm(by_name.source)
    q = np.linspace(-1, 1, 6)
    np.testing.assert_array_equal(by_name.fk(q), by_path.fk(q))


@pytest.mark.parametrize("name", om.arm_names())
def test_written_arm_files_read_back_bit_for_bit(tmp_path, name):
    """write_arm_file writes the standard convention (the Panda's modified table comes out as
    standard rows) and load_arm reads back the same arm."""
    arm = om.load_arm(name)
    path = tmp_path / f"{name}.toml"
    om.write_arm_file(arm, path, comment="written by a test\nsecond line")
    text = path.read_text()
    assert text.startswith("# written by a test\n# second line\n") and 'convention = "standard"' in text
    back = om.load_arm(path)
    assert back.chain.rows == arm.chain.rows and back.joint_names == arm.joint_names
    for a, b in [
        (back.chain.T_root_base, arm.chain.T_root_base),
        (back.chain.T_flange_tool, arm.chain.T_flange_tool),
        (back.lower, arm.lower),
        (back.upper, arm.upper),
    ]:
        np.testing.assert_array_equal(a, b)
    fields = ("name", "description", "mujoco_model", "frame_name", "frame_type")
    assert [getattr(back, f) for f in fields] == [getattr(arm, f) for f in fields]


def test_written_strings_are_escaped(tmp_path):
    arm = om.load_arm("spherical")
    odd = arm.with_chain(arm.chain, 'quote " backslash \\ newline \n tab \t é')
    om.write_arm_file(odd, tmp_path / "odd.toml")
    assert om.load_arm(tmp_path / "odd.toml").name == odd.name


def test_unknown_arm_names_the_arm_and_the_choices():
    with pytest.raises(om.UnknownArm, match=r"unknown arm 'ur10'.*ur5e"):
        om.load_arm("ur10")


@pytest.mark.parametrize(
    "text, field, problem",
    [
        ('name = "x"\nconvention = "standard"\n', "rows", "non-empty array"),
        ('name = "x"\nconvention = "dh"\n' + UR5E_ROWS, "convention", "'standard' or 'modified'"),
        ('convention = "standard"\n' + UR5E_ROWS, "name", "missing"),
        (
            'name = "x"\nconvention = "standard"\n' + UR5E_ROWS.replace("d = 0.1", 'd = "0.1"'),
            "rows[0].d",
            "finite number",
        ),
        (
            'name = "x"\nconvention = "standard"\n' + UR5E_ROWS.replace("d = 0.1", "dd = 0.1"),
            "rows[0].dd",
            "unknown field",
        ),
        (
            'name = "x"\nconvention = "standard"\n' + UR5E_ROWS.replace('"revolute"', '"helical"'),
            "rows[0].type",
            "revolute, prismatic or fixed",
        ),
        (
            'name = "x"\nconvention = "standard"\n' + UR5E_ROWS + "range = [1.0, -1.0]\n",
            "rows[0].range",
            "below upper",
        ),
        (
            'name = "x"\nconvention = "standard"\n' + UR5E_ROWS + "range = [1.0]\n",
            "rows[0].range",
            "2 finite numbers",
        ),
        (
            'name = "x"\nconvention = "standard"\n[base]\nquat = [0, 0, 0, 0]\n' + UR5E_ROWS,
            "base.quat",
            "zero norm",
        ),
        (
            'name = "x"\nconvention = "standard"\n' + UR5E_ROWS.replace('joint = "j1"\n', ""),
            "rows[0].joint",
            "missing",
        ),
        (
            'name = "x"\nconvention = "standard"\n[[rows]]\ntype = "fixed"\njoint = "j"\n',
            "rows[0].joint",
            "fixed row",
        ),
        ('name = "x"\nconvention = "standard"\n' + UR5E_ROWS + UR5E_ROWS, "rows", "repeat"),
        ("name = \n", "<file>", "not valid TOML"),
    ],
)
def test_malformed_file_names_file_field_and_problem(tmp_path, text, field, problem):
    path = write(tmp_path, text)
    with pytest.raises(om.ArmFileError) as info:
        om.load_arm(path)
    assert info.value.field == field
    assert problem in info.value.problem
    assert str(path) in str(info.value)


def test_missing_file_is_named(tmp_path):
    with pytest.raises(om.ArmFileError, match="no such file"):
        om.load_arm(tmp_path / "nope.toml")


def test_spherical_arm_reproduces_the_papers_delta_p():
    """Equation (12) of the paper, for the documented reading of Table III's fixed row."""
    solver = om.OMSolver("spherical")
    Q = random_q(solver.arm, 200, np.random.default_rng(2))
    C, S = np.cos(Q), np.sin(Q)
    d5 = 0.02
    expected = d5 * np.stack(
        [
            C[:, 0] * S[:, 1] * S[:, 3] - C[:, 0] * C[:, 1] * C[:, 3],
            S[:, 0] * S[:, 1] * S[:, 3] - S[:, 0] * C[:, 1] * C[:, 3],
            -C[:, 1] * S[:, 3] - S[:, 1] * C[:, 3],
        ],
        axis=1,
    )
    np.testing.assert_allclose(solver.model_arm.dp(Q), expected, atol=1e-15)
    assert solver.dp_max == pytest.approx(d5, abs=1e-15)


# ---------------------------------------------------------------------------------------
# Issue 18: hostile files raise ArmFileError naming the problem, never another exception.


@pytest.mark.parametrize(
    "text, field, problem",
    [
        (
            'name = "x"\nconvention = "standard"\nrows = ' + "[" * 5000 + "]" * 5000,
            "<file>",
            "nested too deeply",
        ),
        (
            'name = "x"\nconvention = "standard"\n' + UR5E_ROWS.replace("d = 0.1", "d = 1" + "0" * 400),
            "rows[0].d",
            "too large for a float",
        ),
        ('name = "x"\nconvention = "standard"\ndescription = 5\n' + UR5E_ROWS, "description", "string"),
        ('name = "x"\nconvention = "standard"\n[mujoco]\nmodel = 5\n' + UR5E_ROWS, "mujoco.model", "string"),
        (
            'name = "x"\nconvention = "standard"\n[tool]\nxyz = [0, 0, true]\n' + UR5E_ROWS,
            "tool.xyz",
            "3 finite",
        ),
    ],
    ids=["deeply nested", "huge integer", "description", "model", "boolean"],
)
def test_hostile_file_names_file_field_and_problem(tmp_path, text, field, problem):
    path = write(tmp_path, text)
    with pytest.raises(om.ArmFileError) as info:
        om.load_arm(path)
    assert info.value.field == field and problem in info.value.problem, info.value


def test_a_file_that_is_not_text_is_named(tmp_path):
    path = tmp_path / "binary.toml"
    path.write_bytes(b"\xff\xfe\x00name")
    with pytest.raises(om.ArmFileError, match=r"binary\.toml: field '<file>': cannot read"):
        om.load_arm(path)


def test_an_optional_description_may_be_empty(tmp_path):
    assert om.load_arm(write(tmp_path, 'name = "x"\nconvention = "standard"\ndescription = ""\n' + UR5E_ROWS))


# ---------------------------------------------------------------------------------------
# Issue 18, item 6: a quaternion is normalised after scaling by its largest entry, so one whose
# norm overflows (1e300 in every entry) keeps its direction instead of becoming the identity;
# a tiny one (1e-300: no direction left) or a NaN one is refused.


@pytest.mark.parametrize("scale", [1e300, 1e100, 1e-5])
def test_a_scaled_quaternion_is_the_same_rotation(tmp_path, scale):
    panda = om.load_arm("panda")
    text = Path(panda.source).read_text()
    tool = "quat = [0.3826834, 0.0, 0.0, 0.9238795]"
    assert tool in text
    scaled = write(
        tmp_path, text.replace(tool, f"quat = [{0.3826834 * scale!r}, 0.0, 0.0, {0.9238795 * scale!r}]")
    )
    q = np.linspace(-1.0, 1.0, 7)
    np.testing.assert_allclose(om.load_arm(scaled).fk(q), panda.fk(q), atol=1e-15)


@pytest.mark.parametrize(
    "quat, problem",
    [
        ("[1e-300, 1e-300, 1e-300, 1e-300]", "has zero norm"),
        ("[nan, 0, 0, 1]", "4 finite numbers"),
        ("[inf, 0, 0, 1]", "4 finite numbers"),
    ],
)
def test_a_quaternion_without_a_direction_is_refused(tmp_path, quat, problem):
    path = write(tmp_path, f'name = "x"\nconvention = "standard"\n[tool]\nquat = {quat}\n' + UR5E_ROWS)
    with pytest.raises(om.ArmFileError) as info:
        om.load_arm(path)
    assert info.value.field == "tool.quat" and problem in info.value.problem


def test_pose_from_quaternion_scales_before_normalising():
    T = pose_from_xyz_quat([0.1, 0.2, 0.3], [1e300, 1e300, 1e300, 1e300])
    np.testing.assert_allclose(
        T[:3, :3], [[0, 0, 1], [1, 0, 0], [0, 1, 0]], atol=1e-15
    )  # 120 deg about (1,1,1)
    for quat, message in [
        ([1e-300] * 4, "has zero norm"),
        ([np.nan, 1, 1, 1], "is not finite"),
        ([np.inf, 1, 1, 1], "is not finite"),
        ([1, 1, 1], "must be 4 numbers"),
        ([1j, 0, 0, 0], "complex"),
        ("1 0 0 0", "got str"),
    ]:
        with pytest.raises(om.InvalidInput, match=message):
            pose_from_xyz_quat([0.0, 0.0, 0.0], quat)
