"""The benchmark's generated robots (URDF, MJCF, screw axes) reproduce the arm file's FK."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import om_redundant as om
from benchmarks.robots import ScrewChain, SixAxisView, check_fk, rot_z, urdf_text

ARMS = ["ur5e", "panda"]


def _origin(joint: ET.Element) -> np.ndarray:
    origin = joint.find("origin")
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("xyz", [float(v) for v in origin.get("rpy").split()]).as_matrix()
    T[:3, 3] = [float(v) for v in origin.get("xyz").split()]
    return T


def urdf_fk(text: str, q: np.ndarray) -> np.ndarray:
    """A minimal URDF FK for a serial chain of z-axis revolute joints listed in order."""
    T = np.eye(4)
    angles = iter(q)
    for joint in ET.fromstring(text).iter("joint"):
        T = T @ _origin(joint)
        if joint.get("type") in ("revolute", "continuous"):
            assert joint.find("axis").get("xyz") == "0 0 1"
            T = T @ rot_z(next(angles))
    return T


@pytest.mark.parametrize("name", ARMS)
def test_urdf_matches_arm_fk(name):
    arm = om.load_arm(name)
    text = urdf_text(arm)
    check = check_fk("urdf", arm, lambda q: urdf_fk(text, q), np.random.default_rng(0), samples=20)
    assert check.passed, check.line()
    limits = [j.find("limit") for j in ET.fromstring(text).iter("joint") if j.get("type") == "revolute"]
    assert [float(limit.get("lower")) for limit in limits] == list(arm.lower)


@pytest.mark.parametrize("name", ARMS)
def test_urdf_through_ikpy(name, tmp_path):
    chain_module = pytest.importorskip("ikpy.chain")
    arm = om.load_arm(name)
    path = tmp_path / f"{name}.urdf"
    path.write_text(urdf_text(arm))
    chain = chain_module.Chain.from_urdf_file(
        str(path), base_elements=["root"], active_links_mask=[False, *[True] * arm.dof, False]
    )
    check = check_fk(
        "ikpy",
        arm,
        lambda q: chain.forward_kinematics(np.concatenate([[0.0], q, [0.0]])),
        np.random.default_rng(1),
        samples=20,
    )
    assert check.passed, check.line()


@pytest.mark.parametrize("name", [*ARMS, "iiwa14"])
def test_screw_chain_forward_reversed_and_held(name):
    arm = om.load_arm(name)
    chain = ScrewChain.from_arm(arm)
    rng = np.random.default_rng(3)
    assert check_fk("screw", arm, chain.fk, rng, samples=20).passed
    backwards = chain.reversed()
    assert check_fk("reversed", arm, lambda q: np.linalg.inv(backwards.fk(q[::-1])), rng, samples=20).passed
    view = SixAxisView.of(arm)
    last = (lambda q: float(q[6])) if view.held else (lambda q: 0.0)
    assert check_fk("held", arm, lambda q: view.pose(view.chain.fk(q[:6]), last(q)), rng, samples=20).passed
    q = rng.uniform(-1.0, 1.0, arm.dof)
    np.testing.assert_allclose(view.chain.fk(q[:6]), view.target(arm.fk(q), last(q)), atol=1e-12)


@pytest.mark.parametrize("name", ARMS)
def test_analytic_peers_fk(name):
    pytest.importorskip("eaik")
    pytest.importorskip("ik_geo")
    from benchmarks.adapters import eaik_peer, ik_geo_peer

    arm = om.load_arm(name)
    for factory in (eaik_peer, ik_geo_peer):
        peer = factory(arm, np.random.default_rng(4))
        check = check_fk(peer.name, arm, peer.fk, np.random.default_rng(5), samples=20)
        assert check.passed, check.line()
