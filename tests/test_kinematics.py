"""DH conventions, forward kinematics and the geometric Jacobian."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import om_redundant as om
from om_redundant.kinematics import KinematicChain, standard_rows_from_modified

angles = st.floats(-np.pi, np.pi)
lengths = st.floats(-0.5, 0.5)


def rot_x(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def rot_z(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def trans(x, y, z):
    T = np.eye(4)
    T[:3, 3] = x, y, z
    return T


@st.composite
def modified_tables(draw):
    n = draw(st.integers(1, 7))
    rows = []
    for _ in range(n):
        kind = draw(st.sampled_from(list(om.JointKind)))
        rows.append(
            om.DHRow(a=draw(lengths), alpha=draw(angles), d=draw(lengths), theta=draw(angles), kind=kind)
        )
    return rows


@settings(max_examples=60, deadline=None)
@given(modified_tables(), st.data())
def test_modified_rows_convert_exactly(rows, data):
    """FK of converted rows equals the product Rx(alpha) Tx(a) Rz(theta + q) Tz(d + q)."""
    dof = sum(r.is_joint for r in rows)
    q = data.draw(arrays(np.float64, dof, elements=st.floats(-3, 3)))
    T = np.eye(4)
    j = 0
    for r in rows:
        qi = q[j] if r.is_joint else 0.0
        j += r.is_joint
        theta = r.theta + (qi if r.kind is om.JointKind.REVOLUTE else 0.0)
        d = r.d + (qi if r.kind is om.JointKind.PRISMATIC else 0.0)
        T = T @ rot_x(r.alpha) @ trans(r.a, 0, 0) @ rot_z(theta) @ trans(0, 0, d)
    chain = KinematicChain(tuple(standard_rows_from_modified(rows)))
    np.testing.assert_allclose(chain.fk(q), T, atol=1e-12)


@st.composite
def chains(draw):
    rows = draw(modified_tables())
    rows = [om.DHRow(r.a, r.alpha, r.d, r.theta, r.kind) for r in rows]
    base = rot_z(draw(angles)) @ rot_x(draw(angles)) @ trans(draw(lengths), draw(lengths), draw(lengths))
    tool = rot_x(draw(angles)) @ rot_z(draw(angles)) @ trans(draw(lengths), draw(lengths), draw(lengths))
    return KinematicChain(tuple(rows), base, tool)


@settings(max_examples=60, deadline=None)
@given(chains(), st.data())
def test_standard_fk_is_the_product_of_rows(chain, data):
    q = data.draw(arrays(np.float64, chain.dof, elements=st.floats(-3, 3)))
    T = chain.T_root_base.copy()
    j = 0
    for r in chain.rows:
        qi = q[j] if r.is_joint else 0.0
        j += r.is_joint
        theta = r.theta + (qi if r.kind is om.JointKind.REVOLUTE else 0.0)
        d = r.d + (qi if r.kind is om.JointKind.PRISMATIC else 0.0)
        T = T @ rot_z(theta) @ trans(0, 0, d) @ trans(r.a, 0, 0) @ rot_x(r.alpha)
    np.testing.assert_allclose(chain.fk(q), T @ chain.T_flange_tool, atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(chains(), st.data())
def test_joint_placements_compose_to_fk(chain, data):
    q = data.draw(arrays(np.float64, chain.dof, elements=st.floats(-3, 3)))
    placements, tail = chain.joint_placements()
    T = np.eye(4)
    for P, qi, row in zip(placements, q, (r for r in chain.rows if r.is_joint), strict=True):
        T = T @ P @ (rot_z(qi) if row.kind is om.JointKind.REVOLUTE else trans(0, 0, qi))
    np.testing.assert_allclose(T @ tail, chain.fk(q), atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(chains(), st.data())
def test_jacobian_matches_finite_differences(chain, data):
    q = data.draw(arrays(np.float64, chain.dof, elements=st.floats(-3, 3)))
    J = chain.jacobian(q)
    h = 1e-6
    for j in range(chain.dof):
        dq = np.zeros(chain.dof)
        dq[j] = h
        Tp, Tm = chain.fk(q + dq), chain.fk(q - dq)
        v = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
        dR = (Tp[:3, :3] - Tm[:3, :3]) / (2 * h) @ chain.fk(q)[:3, :3].T
        omega = np.array([dR[2, 1], dR[0, 2], dR[1, 0]])
        np.testing.assert_allclose(J[:3, j], v, atol=1e-7)
        np.testing.assert_allclose(J[3:, j], omega, atol=1e-7)


def test_batched_fk_equals_single_fk():
    arm = om.load_arm("ur5e")
    Q = np.random.default_rng(0).uniform(-3, 3, (50, 6))
    np.testing.assert_array_equal(arm.fk(Q), np.stack([arm.fk(q) for q in Q]))
