"""The compiled cell test of the global choose's solution paths (``_core.pieces``,
``_core.surprise``, ``_core.joint_step``, ``_core.cell_spans`` and ``_core.cell_looks``,
csrc/redundancy/cells.c) against the numpy it replaces (tests/reference/cells.py): the
feasibility functions of the margin and clearance groups and their rates, where the cubic
Hermite models of a cell predict a feasibility its ends do not explain, the largest joint
step, the chord's parameter, and the first tests of every cell of a path; and a cell that
ends at a fold, which the models along the chord take as the smooth curve it is."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from benchmarks.control_rate import HOMES
from om_redundant import _core
from om_redundant.redundancy.paths.linking import _BOUND_SLACK, _HERMITE, FINE_STEP
from om_redundant.redundancy.self_motion import self_motion_tangents
from tests.conftest import steps_numpy
from tests.reference import objective as objective_numpy
from tests.reference.cells import chord_spans_numpy, crossing_numpy, looks_numpy, quiet_numpy, surprise_numpy
from tests.test_redundancy_batch import optimizer_of


@settings(max_examples=8, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(list(HOMES)), count=st.sampled_from([0, 1, 3]))
def test_pieces_are_the_groups_constraints(seed, name, count):
    """Objective.pieces: the margin and clearance groups' Group.constraints along the
    tangent, to rounding (the rates' sums may be ordered otherwise), near the obstacles (the
    pairs capped at 2 d_cap) and far."""
    optimizer = optimizer_of(name, count)
    objective, arm = optimizer.objective, optimizer.solver.arm
    q = np.random.default_rng(seed).uniform(arm.lower - 0.3, arm.upper + 0.3, (10, arm.dof))
    tangents = self_motion_tangents(optimizer.solver, q)
    for row, t in zip(q, tangents, strict=True):
        pairs = None if objective.clearance is None else objective.clearance.distances_and_gradients(row)
        g, dg = objective.pieces(row, t, pairs)
        found = objective_numpy.groups(objective, row, tangent=t)
        groups = [group for group in found if group.floor > -np.inf]  # (those with a floor)
        want_g, want_dg = (
            np.concatenate(x) for x in zip(*(group.constraints() for group in groups), strict=True)
        )
        np.testing.assert_allclose(g, want_g, rtol=0, atol=1e-15 * (1 + np.abs(want_g).max()))
        np.testing.assert_allclose(dg, want_dg, rtol=0, atol=1e-13 * (1 + np.abs(want_dg).max()))


# (the spans at the cell's ends: equal in psi; along the chord, at a fold, one far below the other)
RATIOS = st.sampled_from([1.0, 1e-6, 0.3, 3.0])


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), pieces=st.integers(1, 12), span=st.floats(1e-6, 1.0), ratio=RATIOS)
def test_surprise_is_numpys(seed, pieces, span, ratio):
    """_core.surprise gives the numpy models' answer (pieces whose bound keeps them
    positive skipped), for ends feasible or not as their values say, with dips and islands
    between them (slopes large against the values), the ends' spans alike or not."""
    rng = np.random.default_rng(seed)
    ga, gb = rng.normal(0.3, 0.5, (2, pieces))
    da, db = rng.normal(0.0, 3.0 / span, (2, pieces))
    fa, fb = bool((ga >= 0).all()), bool((gb >= 0).all())
    got = _core.surprise(_core.CellModels(ga, da, gb, db, span, span * ratio, _HERMITE), fa, fb, _BOUND_SLACK)
    assert got == surprise_numpy(ga, da, gb, db, span, span * ratio, fa, fb)


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), pieces=st.integers(1, 12), span=st.floats(-1.0, 1.0), ratio=RATIOS)
def test_crossing_is_numpys(seed, pieces, span, ratio):
    """_core.crossing gives the numpy models' first zero, to rounding (pieces whose bound
    keeps them positive skipped), from a feasible end towards either side (span < 0: the
    cell lies below the feasible end), with dips and islands between."""
    rng = np.random.default_rng(seed)
    ga, gb = np.abs(rng.normal(0.3, 0.5, pieces)), rng.normal(0.3, 0.5, pieces)
    da, db = rng.normal(0.0, 3.0 / max(abs(span), 1e-6), (2, pieces))
    got, want = (
        _core.crossing(_core.CellModels(ga, da, gb, db, span, span * ratio, _HERMITE)),
        crossing_numpy(ga, da, gb, db, span, span * ratio),
    )
    assert (got is None) == (want is None)
    if want is not None:
        assert 0.0 <= got <= 1.0 and abs(got - want) <= 1e-12


def cell_looks(paths):
    """_core.cell_looks of paths [(q, t, psi, g, dg, feasible, cyclic)], given as lists of
    samples; each path's looks."""
    lengths = [len(psi) for _, _, psi, *_ in paths]
    q, t, psi, pieces, feasible = [], [], [], [], []
    for q_p, t_p, psi_p, g_p, dg_p, feasible_p, _ in paths:
        q += list(q_p)
        t += list(t_p)
        psi += psi_p.tolist()
        pieces += list(zip(g_p, dg_p, strict=True))
        feasible += feasible_p.tolist()
    bounds = np.cumsum([0, *lengths])
    cyclic = np.array([c for *_, c in paths], dtype=bool).reshape(-1, 7)
    first = np.full(len(psi), -7.0)
    samples = _core.CellSamples(q, t, psi, pieces, feasible, bounds, cyclic)
    _core.cell_looks(samples, FINE_STEP, _BOUND_SLACK, _HERMITE, first)
    return np.split(first, bounds[1:-1]) if paths else []


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), pieces=st.integers(1, 12), span=st.floats(1e-6, 1.0), ratio=RATIOS)
def test_a_quiet_cell_has_no_surprise(seed, pieces, span, ratio):
    """cell_looks' bounds: where they call a cell quiet, _core.surprise finds no change
    that its ends do not explain (so skipping its look changes no sample); cells drawn near
    the bounds' edge (values small against the slopes), ends feasible or not as they say;
    and the bounds are numpy's (quiet_numpy). (Joint 1 moves 0.1 rad, within FINE_STEP, at
    the speeds that make the chord's spans span and span * ratio.)"""
    rng = np.random.default_rng(seed)
    ga, gb = rng.normal(0.05, 0.3, (2, pieces))
    da, db = rng.normal(0.0, 0.5 / span, (2, pieces))
    fa, fb = bool((ga >= 0).all()), bool((gb >= 0).all())
    q, t, cyclic = np.zeros((2, 7)), np.zeros((2, 7)), np.ones(7, dtype=bool)
    q[1, 0], t[:, 0] = 0.1, [0.1 / span, 0.1 / (span * ratio)]
    feasible = np.array([fa, fb])
    (first,) = cell_looks(
        [(q, t, np.array([0.0, span]), np.array([ga, gb]), np.array([da, db]), feasible, cyclic)]
    )
    span_a, span_b = _core.cell_spans(cyclic, q[0], t[0], q[1], t[1])
    quiet = quiet_numpy(
        np.array([span_a]),
        np.array([span_b]),
        ga[None],
        da[None],
        gb[None],
        db[None],
        np.array([fa]),
        np.array([fb]),
    )
    surprise = _core.surprise(
        _core.CellModels(ga, da, gb, db, span_a, span_b, _HERMITE), fa, fb, _BOUND_SLACK
    )
    assert np.isnan(first[0]) == (quiet[0] or surprise is None)
    if quiet[0]:
        assert surprise is None


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), dof=st.integers(1, 7), scale=st.sampled_from([0.1, 1.0, 10.0, 1e3]))
def test_joint_step_is_the_numpy_step(seed, dof, scale):
    """_core.joint_step is the numpy reference (steps_numpy) to the bit: joints drawn far
    apart (turns of the cyclic ones) and at exact multiples of pi apart, where the remainder's
    sign rule decides."""
    rng = np.random.default_rng(seed)
    cyclic = rng.random(dof) < 0.7
    a = rng.normal(0.0, scale, (8, dof))
    b = a + rng.normal(0.0, scale, (8, dof))
    b[-2:] = a[-2:] + math.pi * rng.integers(-4, 5, (2, dof))  # (rounded: near the turn's edge)
    want = steps_numpy(cyclic, a, b)
    got = [_core.joint_step(cyclic, x, y) for x, y in zip(a, b, strict=True)]
    assert np.array_equal(got, want)


@settings(max_examples=200, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1), paths=st.lists(st.integers(1, 12), max_size=4), pieces=st.integers(0, 9)
)
def test_cell_looks_are_numpys(seed, paths, pieces):
    """_core.cell_looks gives each cell's first look as the reference (calm: NaN; a step
    above FINE_STEP: 1/2; else the numpy surprise), path by path with each path's cyclic
    joints: samples close and far apart in the joints, values small against the slopes
    (dips and islands), ends feasible or not as they say, no pieces at all, no paths."""
    rng = np.random.default_rng(seed)
    drawn = []
    for samples in paths:
        q = np.cumsum(rng.normal(0.0, rng.choice([0.02, 0.3]), (samples, 7)), axis=0)
        t = rng.normal(0.0, 1.0, (samples, 7)) * rng.choice([0.0, 1.0, 1e4], (samples, 1))  # (a fold's: 1e4)
        psi = np.cumsum(rng.uniform(1e-6, 0.2, samples))
        g = rng.normal(0.1, 0.3, (samples, pieces))
        dg = rng.normal(0.0, 2.0, (samples, pieces))
        drawn.append((q, t, psi, g, dg, (g >= 0.0).all(axis=1), rng.random(7) < 0.8))
    for got, path in zip(cell_looks(drawn), drawn, strict=True):
        assert np.array_equal(got, looks_numpy(*path), equal_nan=True)


def test_cell_looks_refuses_what_it_cannot_read():
    """Samples of another size or kind than the first's, and bounds that do not cover the
    samples, are refused with the error named (not read past)."""
    q, pieces, feasible = [np.zeros(7)] * 2, [(np.zeros(3), np.zeros(3))] * 2, [True, True]
    bounds, cyclic, first = np.array([0, 2]), np.ones((1, 7), dtype=bool), np.empty(2)
    rest = (FINE_STEP, _BOUND_SLACK, _HERMITE, first)
    _core.cell_looks(_core.CellSamples(q, q, [0.0, 0.1], pieces, feasible, bounds, cyclic), *rest)
    assert first[0] == 0.5 or np.isnan(first[0])
    wider = [pieces[0], (np.zeros(4), np.zeros(4))]
    with pytest.raises(ValueError, match="g must have 3 entries"):
        _core.cell_looks(_core.CellSamples(q, q, [0.0, 0.1], wider, feasible, bounds, cyclic), *rest)
    with pytest.raises(TypeError, match="q must be float64"):
        _core.cell_looks(
            _core.CellSamples(
                [q[0], np.zeros(7, np.float32)], q, [0.0, 0.1], pieces, feasible, bounds, cyclic
            ),
            *rest,
        )
    with pytest.raises(ValueError, match="tangent must have 7 entries"):
        _core.cell_looks(
            _core.CellSamples(q, [q[0], np.zeros(6)], [0.0, 0.1], pieces, feasible, bounds, cyclic), *rest
        )
    with pytest.raises(ValueError, match="disagree"):
        _core.cell_looks(
            _core.CellSamples(q, q, [0.0, 0.1], pieces, feasible, np.array([0, 3]), cyclic), *rest
        )
    with pytest.raises(ValueError, match="disagree"):
        _core.cell_looks(_core.CellSamples(q, q, [0.0], pieces, feasible, bounds, cyclic), *rest)


@settings(max_examples=200, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), dof=st.integers(1, 7), scale=st.sampled_from([1e-6, 0.1, 1.0, 10.0]))
def test_cell_spans_are_numpys(seed, dof, scale):
    """_core.cell_spans is the reference (chord_spans_numpy) to the bit: joints far apart
    (turns of the cyclic ones), tangents small and large, and a tangent of zero (span 0)."""
    rng = np.random.default_rng(seed)
    cyclic = rng.random(dof) < 0.7
    qa, qb = rng.normal(0.0, scale, (2, dof))
    qb += 2.0 * math.pi * rng.integers(-2, 3, dof)
    ta, tb = rng.normal(0.0, 1.0, (2, dof)) * rng.choice([0.0, 1e-3, 1.0, 1e6], (2, 1))
    got = _core.cell_spans(cyclic, qa, ta, qb, tb)
    assert got == chord_spans_numpy(cyclic, qa, ta, qb, tb)
    with pytest.raises(ValueError, match="disagree"):
        _core.cell_spans(cyclic, qa, ta, qb, tb[:-1] if dof > 1 else np.zeros(2))


@pytest.mark.parametrize("distance", [1e-6, 1e-9, 1e-12])
def test_a_cell_at_a_fold_has_no_surprise_along_its_chord(distance):
    """A cell whose end b lies ``distance`` from a fold, where the path turns back in psi:
    q(psi) = q_f + c sqrt(psi_f - psi), |dq/dpsi| there about 1 / sqrt(distance). A joint's
    margin between the ends is monotone and stays positive, so the ends explain the cell;
    the models along the chord say so, those in psi (the end's rate as a cubic's slope) see a
    dip that is not there (the joint's rate, towards the fold, a cubic's slope at b)."""
    psi_f, width = 0.4, 0.05
    c = np.array([-0.3, -0.2, 0.0, 0.1, 0.0, 0.0, 0.05])

    def at(psi):
        root = math.sqrt(psi_f - psi)
        return 0.5 + c * root, -c / (2.0 * root)  # q, dq/dpsi

    (qa, ta), (qb, tb) = at(psi_f - width), at(psi_f - distance)
    lower, half = 0.35, 1.0  # joint 1's margin (q_1 - lower) / half, its rate along psi
    ga, gb, da, db = (qa[0] - lower) / half, (qb[0] - lower) / half, ta[0] / half, tb[0] / half
    margins = (
        0.5 + c[0] * np.sqrt(psi_f - np.linspace(psi_f - width, psi_f - distance, 1001)) - lower
    ) / half
    assert margins.min() > 0.0 and ga > 0.0 and gb > 0.0  # (the cell is feasible throughout)
    cyclic = np.zeros(7, dtype=bool)
    span_a, span_b = _core.cell_spans(cyclic, qa, ta, qb, tb)
    models = _core.CellModels(
        np.array([ga]), np.array([da]), np.array([gb]), np.array([db]), span_a, span_b, _HERMITE
    )
    assert _core.surprise(models, True, True, _BOUND_SLACK) is None
    span = width - distance
    in_psi = _core.CellModels(
        np.array([ga]), np.array([da]), np.array([gb]), np.array([db]), span, span, _HERMITE
    )
    assert _core.surprise(in_psi, True, True, _BOUND_SLACK) is not None
    (first,) = cell_looks(
        [
            (
                np.array([qa, qb]),
                np.array([ta, tb]),
                np.array([psi_f - width, psi_f - distance]),
                np.array([[ga], [gb]]),
                np.array([[da], [db]]),
                np.array([True, True]),
                cyclic,
            )
        ]
    )
    assert np.isnan(first[0])
