"""The batched evaluations behind the global optimiser's sweep (issue 16): each agrees with
the one-at-a-time evaluation it replaces."""

from __future__ import annotations

import functools
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from benchmarks.control_rate import HOMES, MIN_CLEARANCE, obstacles
from om_redundant import _core
from om_redundant.redundancy import self_motion_tangent
from om_redundant.redundancy.choice.box_qp import step_1d
from om_redundant.redundancy.choice.start_bounds import StartBounds
from om_redundant.redundancy.objective.objective import Objective
from om_redundant.redundancy.objective.terms import Evaluation
from om_redundant.redundancy.paths.points import evaluate_points
from om_redundant.redundancy.paths.probe import Probe
from om_redundant.redundancy.self_motion import self_motion_tangents
from tests.conftest import random_groups, steps_numpy
from tests.reference import box_qp as box_qp_numpy
from tests.reference import objective as objective_numpy
from tests.reference import start_bounds as start_bounds_numpy
from tests.reference.objective import Group
from tests.reference.self_motion import self_motion_tangents as reference_tangents


@functools.cache
def optimizer_of(name: str, count: int) -> om.RedundancyOptimizer:
    """The arm's optimiser with count obstacles about its home hand (cached)."""
    solver = om.OMSolver(name)
    shapes = obstacles(solver.arm.fk(HOMES[name])[:3, 3], count)
    return om.RedundancyOptimizer(solver, shapes or None, min_clearance=MIN_CLEARANCE)


def along(group: Group, tangent: np.ndarray) -> Group:
    """The reference of Objective.groups' ``tangent``: the group with its jacobian by q
    chained through dq/dpsi = tangent (dof, r)."""
    return replace(group, jacobian=group.jacobian @ tangent)


def joints(optimizer, seed, n=40):
    arm = optimizer.solver.arm
    return np.random.default_rng(seed).uniform(arm.lower - 0.3, arm.upper + 0.3, (n, arm.dof))


def test_the_kernels_evaluations_are_read_by_their_names():
    """_core.evaluate writes each field of Evaluation into the array of that name
    (_core.Evaluations), whose rows Objective.evaluations reads in Evaluation's order."""
    assert _core.Evaluations._fields == Evaluation._fields


@settings(max_examples=6, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(list(HOMES)), count=st.sampled_from([0, 1, 3]))
def test_batched_evaluations_equal_the_single_ones(seed, name, count):
    """Objective.evaluations and Clearance.minima give exactly evaluate(q) and minimum(q)
    row by row (the global sweep's feasibility and values are unchanged by the batch)."""
    optimizer = optimizer_of(name, count)
    q = joints(optimizer, seed)
    objective = optimizer.objective
    assert objective.evaluations(q) == [objective.evaluate(row) for row in q]
    for row in q[:5]:  # the groups' minima, capped, weighted and summed (C's sin or numpy's)
        evaluation, groups = (
            objective.evaluate(row),
            {g.kind: g for g in objective_numpy.groups(objective, row)},
        )
        terms = [objective_numpy.term(g) for g in groups.values()]
        assert evaluation.value == pytest.approx(sum(terms), rel=0, abs=1e-15)
        assert evaluation.margin == groups["margin"].values.min()
        assert evaluation.slack == min(objective_numpy.slack(g) for g in groups.values())
        if "clearance" in groups:
            assert evaluation.clearance == groups["clearance"].values.min() * objective.clearance_cap
        if "singularity" in groups:
            assert evaluation.singularity == pytest.approx(
                groups["singularity"].values.min() * 0.5, abs=1e-16
            )
        if objective.clearance is not None:
            distances = objective.clearance.distances_and_gradients(row)[0]
            assert objective.evaluate(row, distances) == objective.evaluate(row)
    if objective.clearance is not None:
        assert objective.clearance.minima(q).tolist() == [objective.clearance.minimum(row) for row in q]


@settings(max_examples=6, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(list(HOMES)))
def test_batched_tangents_equal_the_single_ones(seed, name):
    """self_motion_tangents gives self_motion_tangent's dq/dpsi row by row (to rounding: the
    batched determinants may round differently), compiled as numpy computes it (to rounding:
    another elimination, the Jacobian in another frame), and it keeps the hand still
    (J t = 0) and moves psi at unit rate."""
    solver = optimizer_of(name, 0).solver
    q = joints(optimizer_of(name, 0), seed, 20)
    tangents = self_motion_tangents(solver, q)
    reference = reference_tangents(solver, q)  # numpy's
    np.testing.assert_allclose(tangents, reference, rtol=1e-9, atol=1e-12 * np.abs(reference).max())
    for row, t in zip(q, tangents, strict=True):
        np.testing.assert_allclose(t, self_motion_tangent(solver, row), rtol=1e-12, atol=1e-15)
        assert np.abs(solver.arm.jacobian(row) @ t).max() < 1e-9 * max(1.0, np.abs(t).max())
        assert om.arm_angle_and_gradient(solver, row)[1] @ t[:, 0] == pytest.approx(1.0, abs=1e-9)


@settings(max_examples=8, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(list(HOMES)), count=st.sampled_from([0, 1, 3]))
def test_batched_pieces_and_points_equal_the_single_ones(seed, name, count):
    """Objective.pieces of all rows at once gives exactly those of each row;
    Clearance.distances_and_gradients of all rows exactly those of each row, from which the
    groups are those computed afresh; and the points of Probe.points (the objective of all
    rows in one batch, evaluate_points) carry exactly what a point evaluates alone."""
    optimizer = optimizer_of(name, count)
    objective, solver = optimizer.objective, optimizer.solver
    q = joints(optimizer, seed, 10)
    tangents = self_motion_tangents(solver, q)
    pairs = None if objective.clearance is None else objective.clearance.distances_and_gradients(q)
    g, dg = objective.pieces(q, tangents, pairs)
    for k, row in enumerate(q):
        mine = None
        if pairs is not None:
            mine = objective.clearance.distances_and_gradients(row)
            np.testing.assert_array_equal(mine[0], pairs[0][k])
            np.testing.assert_array_equal(mine[1], pairs[1][k])
            groups = [along(g, tangents[k]) for g in objective_numpy.groups(objective, row, jacobian=True)]
            for batched, fresh in zip(
                objective_numpy.groups(objective, row, jacobian=True, pairs=mine), groups, strict=True
            ):
                np.testing.assert_array_equal(batched.values, fresh.values)
                np.testing.assert_array_equal(along(batched, tangents[k]).jacobian, fresh.jacobian)
        one = objective.pieces(row, tangents[k], mine)
        np.testing.assert_array_equal(one[0], g[k])
        np.testing.assert_array_equal(one[1], dg[k])
    probe = Probe(solver, objective, solver.arm.fk(q[0]), optimizer.branches[0])
    psi = np.linspace(-1.0, 1.0, len(q))
    points = probe.points(psi, q)
    evaluate_points(objective, points)  # (in one batch, as the sweep does)
    for point in points:
        alone = Probe(solver, objective, probe.T, probe.signs).point(point.psi, point.q)
        assert point.evaluation == alone.evaluation
        for batched, single in zip(point.pieces(), alone.pieces(), strict=True):
            np.testing.assert_array_equal(batched, single)
        # the pieces from the pairs' gradients the batch computed (objective.pairs: the near
        # pairs' only), along the tangent, are the groups computed afresh and chained here
        fresh = [along(g, point.tangent) for g in objective_numpy.groups(objective, point.q, jacobian=True)]
        values, rates = point.linearised
        want = np.concatenate([g.jacobian[:, 0] for g in fresh])
        np.testing.assert_array_equal(values, np.concatenate([g.values for g in fresh]))
        np.testing.assert_allclose(rates, want, rtol=1e-13, atol=1e-14 * max(1.0, np.abs(want).max()))


@settings(max_examples=12, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    name=st.sampled_from([*HOMES, "gen3"]),
    count=st.sampled_from([0, 1, 3]),
    singular=st.booleans(),
)
def test_the_linearised_pieces_are_the_groups_along_psi(seed, name, count, singular):
    """Objective.linearised (one compiled call) is Objective.groups with the tangent,
    concatenated in the groups' order: the values exactly, the rates to rounding (numpy chains
    the jacobians by a matrix product); its layout has the groups' sizes, weights, floors and
    caps. With and without the singularity term, from the pairs of objective.pairs (a near
    pair's gradients only, the far ones at the reach) and with no obstacle; Gen3's continuous
    joints have no margin pieces."""
    solver = om.OMSolver(name)
    shapes = obstacles(solver.arm.fk(HOMES.get(name, np.zeros(7)))[:3, 3], count)
    clearance = om.Clearance.for_arm(solver.arm, shapes) if shapes else None
    singularity = om.Singularity.of(solver.model_arm, solver.flip) if singular else None
    objective = Objective(solver.arm, clearance, singularity, min_clearance=MIN_CLEARANCE)
    arm, layout = solver.arm, objective.layout
    lower = np.where(np.isfinite(arm.lower), arm.lower - 0.3, -4.0)
    upper = np.where(np.isfinite(arm.upper), arm.upper + 0.3, 4.0)
    q = np.random.default_rng(seed).uniform(lower, upper, (20, 7))
    for row, tangent in zip(q, self_motion_tangents(solver, q), strict=True):
        pairs = objective.pairs(row)
        groups = objective_numpy.groups(objective, row, pairs=pairs, tangent=tangent)
        values, rates = objective.linearised(row, tangent, pairs)
        np.testing.assert_array_equal(values, np.concatenate([g.values for g in groups]))
        want = np.concatenate([g.jacobian[:, 0] for g in groups])
        np.testing.assert_allclose(rates, want, rtol=1e-13, atol=1e-14 * max(1.0, np.abs(want).max()))
        assert np.diff(layout.ends).tolist() == [len(g.values) for g in groups]
        assert layout.weights.tolist() == [g.weight for g in groups]
        assert layout.floors.tolist() == [g.floor for g in groups]
        assert layout.caps.tolist() == [g.cap for g in groups]


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(list(HOMES)), wrapped=st.booleans())
def test_a_probe_step_is_the_largest_joint_step(seed, name, wrapped):
    """Probe.step gives exactly the reference's numbers (steps_numpy: numpy's), the largest
    |b_i - a_i| with the differences of compared-modulo-2-pi joints taken to [-pi, pi) by
    np.remainder: also differences of whole multiples of pi, or none; and NaN where a joint
    is NaN, the first or one after it (numpy's maximum: a NaN is not passed over)."""
    solver = optimizer_of(name, 0).solver
    probe = Probe(
        solver, optimizer_of(name, 0).objective, np.eye(4), optimizer_of(name, 0).branches[0], wrapped
    )
    rng = np.random.default_rng(seed)
    a = rng.uniform(-10.0, 10.0, (40, solver.arm.dof))
    moved = np.where(
        rng.random(a.shape) < 0.3, rng.integers(-4, 5, a.shape) * np.pi, rng.normal(0.0, 3.0, a.shape)
    )
    b = a + moved * (rng.random(a.shape) < 0.9)
    b[-2:, [0, solver.arm.dof // 2]] = [[np.nan, 0.0], [0.0, np.nan]]  # (joint 0, a middle joint)
    cyclic = solver.arm.revolute & wrapped
    got = [probe.step(x, y) for x, y in zip(a, b, strict=True)]
    assert np.array_equal(got, steps_numpy(cyclic, a, b), equal_nan=True)
    assert np.isnan(got[-2:]).all()
    z = np.zeros(solver.arm.dof)
    turned = np.where(np.arange(solver.arm.dof) == 0, 1.5 * np.pi, 0.0)
    assert probe.step(z, turned) == pytest.approx(0.5 * np.pi if cyclic[0] else 1.5 * np.pi, abs=1e-15)


@pytest.mark.sanitize  # also run under ASan and UBSan (.ci/sanitize)
@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    pieces=st.integers(1, 8),
    curvature=st.floats(1e-3, 1e3),
    reach=st.floats(1e-4, 1.0),
    spread=st.floats(0.0, 3.0),
)
def test_the_one_variable_qp_step_is_the_models_maximiser(seed, pieces, curvature, reach, spread):
    """box_qp.step_1d, from a point within the floors as the climb's: a delta within the box
    and the floors whose model value no point of a dense grid of the feasible interval beats,
    the breakpoints' maximiser (tests/reference/box_qp.py; phi is strictly concave, so one)
    to rounding, its gain the model's rise to it, multipliers in [0, w_g] per group, those of
    the reference, 0 for pieces spread out of reach of their group's least; from points below
    the floors, None exactly where the reference finds no delta."""
    rng = np.random.default_rng(seed)
    groups = random_groups(rng, 1, lambda floor: rng.uniform(0.0, spread, pieces) + max(floor, 0.0) + 0.3)
    lower, upper = -reach * rng.uniform(), reach * rng.uniform()
    concatenated = box_qp_numpy.concatenated(groups)
    delta, gain, z = step_1d(concatenated, curvature, lower, upper)
    want_delta, _, want_z = box_qp_numpy.step_1d(concatenated, curvature, lower, upper)
    assert delta == pytest.approx(want_delta, abs=1e-12)
    np.testing.assert_allclose(z, want_z, atol=1e-9)
    model = box_qp_numpy.model
    assert gain == model(concatenated, delta) - 0.5 * delta * curvature * delta - model(concatenated, 0.0)
    assert lower <= delta <= upper
    at = [g.values + g.jacobian[:, 0] * delta for g in groups]
    assert all(v.min() >= g.floor - 1e-12 for g, v in zip(groups, at, strict=True))
    grid = np.linspace(lower, upper, 20001)
    pieces_at = [g.values[None, :] + g.jacobian[None, :, 0] * grid[:, None] for g in groups]
    floors_kept = np.all([p.min(axis=1) >= g.floor for g, p in zip(groups, pieces_at, strict=True)], axis=0)
    phi = sum(
        (g.weight * np.minimum(g.cap, p.min(axis=1)) for g, p in zip(groups, pieces_at, strict=True)),
        start=-0.5 * curvature * grid**2,
    )
    value = sum(
        (g.weight * min(g.cap, v.min()) for g, v in zip(groups, at, strict=True)), -0.5 * curvature * delta**2
    )
    assert value >= phi[floors_kept].max(initial=-np.inf) - 1e-12
    for g, z_g in zip(groups, np.split(z, concatenated.ends[1:-1]), strict=True):
        assert (z_g >= 0.0).all() and z_g.sum() <= g.weight + 1e-12
    below = box_qp_numpy.concatenated([replace(g, values=g.values - 0.5) for g in groups])
    found, want = (s(below, curvature, lower, upper) for s in (step_1d, box_qp_numpy.step_1d))
    assert (found is None) == (want is None)  # (the floors may leave no delta)
    broken = concatenated._replace(values=np.where(np.arange(len(z)) == 0, np.nan, concatenated.values))
    with pytest.raises(ValueError, match="a piece is not a number"):
        step_1d(broken, curvature, lower, upper)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), runs=st.integers(1, 3), scale=st.floats(0.0, 4.0))
def test_the_climbs_start_bounds_hold_for_functions_within_their_slopes(seed, runs, scale):
    """start_bounds.StartBounds.within, for term functions c + A sin(omega psi + phi) (slope
    bound A omega; f's the weighted sum of its groups' largest) sampled on runs of uneven
    spacing: every start's bound is at least f anywhere within its reach (a dense grid), at
    least f at the start and at most the bound from its own cones (``cone``, the bound before);
    compiled exactly as numpy computes it, also without terms; without slopes given, L is
    each run's largest slope between its neighbouring samples."""
    rng = np.random.default_rng(seed)
    groups = [(rng.uniform(0, 2), np.inf, rng.integers(1, 5)), (rng.uniform(0, 2), 1.0, rng.integers(1, 5))]
    waves = [rng.uniform([0.2, 0.0, 0.5, -3.0], [1.5, scale, 8.0, 3.0], (p, 4)) for _, _, p in groups]

    def functions(x):  # (N,) -> per group (N, p)
        return [c + a * np.sin(omega * x[:, None] + phi) for c, a, omega, phi in (w.T for w in waves)]

    def objective(x):
        return sum(
            w * np.minimum(cap, v.min(axis=1)) for (w, cap, _), v in zip(groups, functions(x), strict=True)
        )

    slopes = [a * omega for _, a, omega, _ in (w.T for w in waves)]
    slope = sum(w * s.max() for (w, _, _), s in zip(groups, slopes, strict=True))
    psi = np.concatenate([np.sort(rng.uniform(-3, 3, rng.integers(1, 12))) for _ in range(runs)])
    starts = np.flatnonzero(np.concatenate([[True], np.diff(psi) < 0]))  # each run's first sample
    owner = np.cumsum(np.isin(np.arange(len(psi)), starts)) - 1
    first = starts[owner]
    last = np.append(starts[1:], len(psi))[owner] - 1
    terms = [(w, cap, v) for (w, cap, _), v in zip(groups, functions(psi), strict=True)]
    f = objective(psi)
    bounds = StartBounds(psi, f, terms, first, last, slope, slopes)
    reach = rng.uniform(0.0, 1.0, len(psi))
    cones = bounds.cone(np.arange(len(psi)), reach)
    np.testing.assert_array_equal(cones, start_bounds_numpy.cone(bounds, np.arange(len(psi)), reach))
    bare = StartBounds(psi, f, [], first, last, slope, [])
    np.testing.assert_array_equal(bare.cone(first, reach), start_bounds_numpy.cone(bare, first, reach))
    columns = np.column_stack([f] + [v for _, _, v in terms])
    sampled = [  # (each sample's run's)
        [
            max(
                (abs(c[i + 1] - c[i]) / max(psi[i + 1] - psi[i], 1e-12) for i in range(first[k], last[k])),
                default=0.0,
            )
            for c in columns.T
        ]
        for k in range(len(psi))
    ]
    np.testing.assert_array_equal(StartBounds(psi, f, terms, first, last)._slopes, sampled)  # (L sampled)
    assert (
        np.array(sampled) <= np.concatenate([[slope], *slopes]) + 1e-9
    ).all()  # (the fixture's own bounds hold)
    for k, (x, r, f_k) in enumerate(zip(psi, reach, f, strict=True)):
        bound = bounds.within(k, r)
        assert bound == start_bounds_numpy.within(bounds, k, r)  # (numpy's, the reference)
        assert bare.within(k, r) == start_bounds_numpy.within(bare, k, r)
        assert bound >= objective(np.linspace(x - r, x + r, 2001)).max() - 1e-12
        assert f_k <= bound <= min(cones[k], f_k + slope * r) + 1e-12
    holed = terms[0][2].copy()
    holed[rng.integers(len(psi)), 0] = np.nan  # (a function that is not a number at one sample)
    nan_bounds = StartBounds(psi, f, [(*terms[0][:2], holed), *terms[1:]], first, last, slope, slopes)
    everyone = np.arange(len(psi))
    np.testing.assert_equal(
        nan_bounds.cone(everyone, reach), start_bounds_numpy.cone(nan_bounds, everyone, reach)
    )
    for k, r in enumerate(reach.tolist()):  # NaN where numpy's is (then no start is skipped for it)
        np.testing.assert_equal(nan_bounds.within(k, r), start_bounds_numpy.within(nan_bounds, k, r))
