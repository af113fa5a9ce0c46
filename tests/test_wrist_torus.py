"""6-DOF arms with a PUMA-like wrist, a4 != 0 with joint 4 across joint 2 (Reach Bravo 7): dp turns
with q5 and q6 (om.six_dof_model.wrist_torus), the solutions lie on the torus (q5, q6), lifted by
the elbow angle (csrc/ik/six_dof.c, om_six_dof_model_ik_lifted), and are found exactly."""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

import om_redundant as om
from benchmarks.near_family import bent
from om_redundant import _core
from om_redundant.ik import derive_model
from om_redundant.kinematics.chain import KinematicChain
from tests.conftest import (
    EXACT,
    check_exact,
    check_hinted_nearest,
    distance,
    polished_roots,
    random_q,
    well_conditioned,
    with_offsets,
    wrap,
)

pytestmark = pytest.mark.sanitize  # also run under ASan and UBSan (.ci/sanitize)

RIGHT = np.pi / 2


@functools.cache
def puma_wrist_arm(kind: str, a4: float, d5: float, a5: float, lateral: float = 0.0) -> om.Arm:
    """A PUMA-like arm with the wrist offsets a4, d5, a5: "bravo", Reach Bravo 7's table (its URDF's
    rows rounded to 0.1 mm; a4 = a5 = -0.0408 there), or "puma", a PUMA 560 (d4 = 0.36 m) with the
    lateral offset d3 = lateral (0.15 m on the PUMA: the shoulder's edge of reach is then a
    cylinder of that radius about joint 1's axis)."""
    if kind == "bravo":
        rows = (
            om.DHRow(a=-0.046, alpha=RIGHT, d=-0.1454, theta=0.0),
            om.DHRow(a=-0.2906, alpha=0.0, d=0.0, theta=-1.5529),
            om.DHRow(a=0.0408, alpha=-RIGHT, d=0.0, theta=1.5529),
            om.DHRow(a=a4, alpha=RIGHT, d=-0.16, theta=0.0),
            om.DHRow(a=a5, alpha=-RIGHT, d=d5, theta=0.0),
            om.DHRow(a=0.0, alpha=0.0, d=0.2616, theta=0.0),
        )
    else:
        rows = (
            om.DHRow(a=0.0, alpha=RIGHT, d=0.6718, theta=0.0),
            om.DHRow(a=0.4318, alpha=0.0, d=0.0, theta=0.0),
            om.DHRow(a=0.0203, alpha=-RIGHT, d=lateral, theta=0.0),
            om.DHRow(a=a4, alpha=RIGHT, d=0.36, theta=0.0),
            om.DHRow(a=a5, alpha=-RIGHT, d=d5, theta=0.0),
            om.DHRow(a=0.0, alpha=0.0, d=0.05625, theta=0.0),
        )
    return om.Arm(
        name=f"{kind}-wrist-{a4:g}-{d5:g}-{a5:g}",
        chain=KinematicChain(rows, np.eye(4), np.eye(4)),
        joint_names=tuple(f"joint{j}" for j in range(1, 7)),
        lower=np.full(6, -np.pi),
        upper=np.full(6, np.pi),
    )


BRAVO = ("bravo", -0.0408, 0.0, -0.0408)
PUMA = ("puma", 0.03, 0.01, 0.02, 0.15)
offsets = st.tuples(
    st.sampled_from(["bravo", "puma"]),
    st.floats(0.01, 0.08) | st.floats(-0.08, -0.01),
    st.sampled_from([0.0, 0.02, -0.03]),
    st.sampled_from([0.0, 0.04, -0.04]),
    st.sampled_from([0.0, 0.15]),
)


@functools.cache
def solver_of(kind: str, a4: float, d5: float, a5: float, lateral: float = 0.0) -> om.OMSolver:
    return om.OMSolver(puma_wrist_arm(kind, a4, d5, a5, lateral))


@settings(max_examples=20, deadline=None)
@given(offsets=offsets, q_seed=st.integers(0, 2**32 - 1))
def test_dp_of_a_puma_like_wrist_is_its_torus_fit_and_bounded_by_dp_max(offsets, q_seed):
    """dp = R_flange delta(q5, q6) with delta = sum_ij C_ij t_i(q5) t_j(q6) (model.wrist_torus),
    and |dp| <= dp_max = hypot(a4, d5) + |a5| (-(a4 x4 + d5 z4 + a5 x5), x4 normal to z4), at
    random joint vectors."""
    kind, a4, d5, a5, lateral = offsets
    model = derive_model(puma_wrist_arm(kind, a4, d5, a5, lateral))
    assert model.wrist_torus is not None and model.dp_joint == -1 and "on the torus" in model.family_name
    assert model.dp_max == pytest.approx(np.hypot(a4, d5) + abs(a5), rel=1e-15)
    for q in random_q(model.real, 16, np.random.default_rng(q_seed)):
        t5, t6 = (np.array([1.0, np.cos(w), np.sin(w)]) for w in q[4:6])
        delta = np.einsum("i,j,ijk->k", t5, t6, model.wrist_torus)
        dp = model.dp(q)
        np.testing.assert_allclose(dp, model.model.fk(q)[:3, :3] @ delta, rtol=0, atol=1e-15)
        assert np.linalg.norm(dp) <= model.dp_max + 1e-15


@settings(max_examples=20, deadline=None)
@given(offsets=offsets, q_seed=st.integers(0, 2**32 - 1))
def test_arms_with_a_puma_like_wrist_are_solved_exactly(offsets, q_seed):
    """Accepted by OMSolver (its self-check passes) on the torus; every root exact and in c, and
    away from the singular boundaries q among solve_all's roots and the hinted solve's answer."""
    solver = solver_of(*offsets)
    assert solver.nominal is None and solver.solver_data().mode == _core.TORUS
    for q in random_q(solver.arm, 6, np.random.default_rng(q_seed)):
        check_exact(solver, q, well_conditioned(solver, q))


@pytest.mark.parametrize("arm", [BRAVO, PUMA])
def test_q_is_among_solve_all_at_every_random_target(arm):
    """Not only away from the boundaries: at 300 random joint vectors of the Bravo's table and of a
    PUMA 560 with wrist offsets, the edges of reach and the singular wrist included, q is among
    solve_all's roots in its configuration."""
    solver = solver_of(*arm)
    for q in random_q(solver.arm, 300, np.random.default_rng(11)):
        T = solver.arm.fk(q)
        roots = solver.solve_all(T, solver.configuration_of(q))
        assert any(distance(solver.arm, r.q, q) < 1e-7 for r in roots), q


def arm_value(solver: om.OMSolver, q: np.ndarray) -> float:
    """The ARM branch quantity a1 + u at q: zero where the wrist centre is on joint 1's axis."""
    values = np.empty(3)
    _core.branch_values(solver.model_arm.family, solver.model_arm.params, q, values)
    return float(values[0])


@settings(max_examples=40, deadline=None)
@given(arm=st.sampled_from([BRAVO, PUMA]), q_seed=st.integers(0, 2**32 - 1))
@example(arm=PUMA, q_seed=801794989)  # the edge touching the torus' reach from outside, between nodes
def test_q_is_found_at_the_shoulders_edge(arm, q_seed):
    """q2 set so that ARM = 0 (to rounding): the wrist centre on joint 1's axis (the Bravo), where q1
    turns by 2 pi about a point of the torus, or h from it (a PUMA with h = 0.15 m), the shoulder's
    edge of reach, where the lifted system's q1 has a square root: q is among solve_all's roots
    in both ARM configurations it holds (the search about the axis, csrc/ik/torus_half_line.c;
    without it the grid misses such roots; the example: the torus' wrist centres all beyond the
    reach at the grid's nodes, the root where the reach touches between them)."""
    solver = solver_of(*arm)
    q = random_q(solver.arm, 1, np.random.default_rng(q_seed))[0]
    grid = np.linspace(-np.pi, np.pi, 65)
    values = [arm_value(solver, np.r_[q[:1], w, q[2:]]) for w in grid]
    crossing = next((k for k in range(64) if values[k] * values[k + 1] < 0.0), None)
    assume(crossing is not None)
    arm_at = lambda w: arm_value(solver, np.r_[q[:1], w, q[2:]])  # noqa: E731
    q[1] = brentq(arm_at, grid[crossing], grid[crossing + 1], xtol=1e-15)
    assert abs(arm_value(solver, q)) < 1e-12
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    for signs in (c.signs, (-c.signs[0], *c.signs[1:])):
        roots = solver.solve_all(T, om.Configuration(signs, ()))
        assert any(distance(solver.arm, r.q, q) < 1e-7 for r in roots), (q, signs)


@settings(max_examples=30, deadline=None)
@given(arm=st.sampled_from([BRAVO, PUMA]), folded=st.booleans(), q_seed=st.integers(0, 2**32 - 1))
@example(arm=PUMA, folded=True, q_seed=1024)  # the shoulder's edge 4 mm away (ARM 0.0037) as well
def test_q_is_found_at_the_elbows_edge(arm, folded, q_seed):
    """q3 set so that the elbow is straight or folded (gamma = phi3 + beta = 0 or pi: ELBOW = 0),
    the edge of reach, where the closed form's gamma has a square root and the lifted system
    takes gamma as an unknown: q is among solve_all's roots in both ELBOW configurations, also
    where the shoulder's edge is near too (the system about joint 1's axis lifts both)."""
    solver = solver_of(*arm)
    params = solver.model_arm.params
    q = random_q(solver.arm, 1, np.random.default_rng(q_seed))[0]
    q[2] = wrap((np.pi if folded else 0.0) - params[_core.SD_BETA] - params[_core.SD_THETA3])
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    for signs in (c.signs, (c.signs[0], -c.signs[1], c.signs[2])):
        roots = solver.solve_all(T, om.Configuration(signs, ()))
        assert any(distance(solver.arm, r.q, q) < 1e-7 for r in roots), (q, signs)


@pytest.mark.parametrize("offsets", [BRAVO, ("puma", 0.05, 0.02, -0.04), PUMA])
def test_every_root_of_an_independent_search_is_found(offsets):
    """At random targets every root that Gauss-Newton on the arm's chain reaches from 400 random
    starts is among solve_all's roots in its configuration: "no root in c" is true."""
    solver = solver_of(*offsets)
    rng = np.random.default_rng(3)
    found = 0
    for q in random_q(solver.arm, 4, rng):
        T = solver.arm.fk(q)
        for root in polished_roots(solver, T, 0.0, rng):
            assert np.abs(solver.arm.fk(root) - T).max() < EXACT
            c = solver.configuration_of(root)
            assert any(distance(solver.arm, s.q, root) < 1e-7 for s in solver.solve_all(T, c)), (q, root)
            found += 1
    assert found >= 8


def test_the_hinted_solve_returns_the_root_nearest_its_hint():
    """Hints near q and between roots up to 0.8 rad apart: the answer is at least as near the hint
    as every root of solve_all (the torus window about the hint, csrc/ik/search.c)."""
    solver = solver_of(*BRAVO)
    rng = np.random.default_rng(5)
    for q in random_q(solver.arm, 40, rng):
        for sigma in (0.01, 0.3):
            check_hinted_nearest(solver, q, rng, sigma, 0.8)


@pytest.mark.parametrize("deviation", [1e-9, 1e-5])
def test_a_puma_like_wrist_near_a_family_is_solved_exactly(deviation):
    """The Bravo's twists bent by +-deviation (its URDF's are 4e-10 rad off): solved through the
    nominal arm, on its torus, exactly."""
    arm = bent(puma_wrist_arm(*BRAVO), deviation, np.random.default_rng(1))
    solver = om.OMSolver(arm)
    assert solver.nominal is not None and "on the torus" in solver.model_arm.family_name
    for q in random_q(solver.arm, 30, np.random.default_rng(5)):
        check_exact(solver, q, well_conditioned(solver, q))


def test_a_ur5e_turned_into_a_puma_like_wrist_is_solved_on_the_torus():
    """The UR5e with joint 4 across joints 2 and 3 (alpha_3 = 90 deg: its d4 no longer lateral)
    and a4 = 0.07: accepted on the torus and exact (refused before the torus existed)."""
    puma = with_offsets(om.load_arm("ur5e"), joint2={"alpha": RIGHT})
    solver = om.OMSolver(with_offsets(puma, joint3={"a": 0.07}))
    assert "on the torus" in solver.model_arm.family_name
    for q in random_q(solver.arm, 20, np.random.default_rng(4)):
        check_exact(solver, q, well_conditioned(solver, q))


def test_a_puma_like_wrist_on_an_rrp_arm_is_refused_by_name():
    """The paper's Spherical arm (RRP) with joint 4 turned across joint 2 and a4 = 0.03: the torus'
    lifted system is the RRR family's, so refused, naming the joints and the family; without a4
    the arm is accepted."""
    arm = om.load_arm("spherical")
    rows = list(arm.chain.rows)
    rows[3] = dataclasses.replace(rows[3], alpha=0.0)  # the fixed row after joint 3
    turned = arm.with_chain(arm.chain.replace_rows(rows), "spherical-turned")
    om.OMSolver(turned)
    with pytest.raises(om.ModelError, match=r"joint 4 \('q4'\) across joint 2.*not RRP \+ spherical wrist"):
        om.OMSolver(with_offsets(turned, joint3={"a": 0.03}))


@pytest.mark.parametrize("arm", [BRAVO, PUMA])
def test_the_batches_and_the_control_tick_answer_as_the_single_calls(arm):
    """solve_all_batch, each pose in all eight configurations in a row (ARM changing alone from
    one to the next), finds as many roots per (pose, c) as solve_all (its search cache, shared by
    the configurations of a pose, is keyed by the ARM sign, which the 6-DOF lifted system reads);
    solve_batch hinted with q and the control tick from joints 0.002 rad back return q."""
    solver = solver_of(*arm)
    rng = np.random.default_rng(9)
    qs = random_q(solver.arm, 40, rng)
    every = np.array([(a, e, w) for e in (1, -1) for w in (1, -1) for a in (1, -1)])
    T_all = np.repeat(solver.arm.fk(qs[:10]), len(every), axis=0)
    signs_all = np.tile(every, (10, 1))
    counts = solver.solve_all_batch(T_all, signs_all, None).count
    expected = [
        len(solver.solve_all(T, om.Configuration(tuple(c), ())))
        for T, c in zip(T_all, signs_all, strict=True)
    ]
    assert list(counts) == expected and sum(expected) >= 10
    T = solver.arm.fk(qs)
    configurations = [solver.configuration_of(q) for q in qs]
    signs = np.array([c.signs for c in configurations])
    batch = solver.solve_batch(T, signs, None, q_hint=qs)
    assert batch.ok.all() and max(distance(solver.arm, a, b) for a, b in zip(batch.q, qs, strict=True)) < 1e-9
    for q, c in zip(qs, configurations, strict=True):
        tick = solver.solve_from(solver.arm.fk(q), c, q + rng.normal(0.0, 0.002, 6))
        assert tick.ok and distance(solver.arm, tick.q, q) < 1e-7
