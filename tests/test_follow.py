"""The compiled path following (``ckernels.follow``, csrc/follow.c) against the Python loop
it replaces (``Probe(..., compiled=False).follow``): the same point reached, the same answer
whether it arrived, on random poses and steps of both 7-DOF arms."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from om_redundant.redundancy.probe import END_TOLERANCE, Probe
from tests.test_redundancy_batch import optimizer_of


@settings(max_examples=12, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    name=st.sampled_from(["panda", "iiwa14"]),
    step=st.floats(-3.0, 3.0),
    wrapped=st.booleans(),
)
def test_compiled_follow_reaches_what_the_python_loop_reaches(seed, name, step, wrapped):
    optimizer = optimizer_of(name, 1)
    solver = optimizer.solver
    arm = solver.arm
    q = np.random.default_rng(seed).uniform(arm.lower, arm.upper)
    configuration = solver.configuration_of(q)
    (psi,) = configuration.redundancy
    T = arm.fk(q)
    probes = [
        Probe(solver, optimizer.objective, T, configuration.signs, wrapped, compiled=c) for c in (True, False)
    ]
    starts = [p.point(psi, q) for p in probes]
    (fast, fast_arrived), (slow, slow_arrived) = (
        p.follow(s, psi + step) for p, s in zip(probes, starts, strict=True)
    )
    assert fast_arrived == slow_arrived
    assert fast.psi == pytest.approx(slow.psi, abs=1e-12)
    np.testing.assert_allclose(fast.q, slow.q, atol=1e-9)
    np.testing.assert_allclose(fast.tangent, slow.tangent, rtol=1e-9, atol=1e-9)
    assert (fast is starts[0]) == (slow is starts[1])  # no step taken: the start itself
    assert fast.evaluation.value == pytest.approx(slow.evaluation.value, abs=1e-9)
    if fast is not starts[0]:  # the point reached is an exact solution on the branch
        assert np.abs(arm.fk(fast.q) - T).max() < 1e-9
        assert om.OMSolver(name).holds(fast.q, om.Configuration(configuration.signs, (fast.psi,)))


@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(["panda", "iiwa14"]), step=st.floats(-0.5, 0.5))
def test_compiled_next_is_the_python_next(seed, name, step):
    """Probe.next (one attempt of the loop, the climb's trial step) compiled and in Python:
    the same answer, the same point."""
    optimizer = optimizer_of(name, 3)
    solver = optimizer.solver
    q = np.random.default_rng(seed).uniform(solver.arm.lower, solver.arm.upper)
    configuration = solver.configuration_of(q)
    (psi,) = configuration.redundancy
    probes = [
        Probe(solver, optimizer.objective, solver.arm.fk(q), configuration.signs, compiled=c)
        for c in (True, False)
    ]
    fast, slow = (p.next(p.point(psi, q), psi + step) for p in probes)
    assert (fast is None) == (slow is None)
    if fast is not None:
        assert fast.psi == slow.psi
        np.testing.assert_allclose(fast.q, slow.q, atol=1e-9)
        np.testing.assert_allclose(fast.tangent, slow.tangent, rtol=1e-9, atol=1e-9)
        assert fast.evaluation.value == pytest.approx(slow.evaluation.value, abs=1e-9)


@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(["panda", "iiwa14"]), compiled=st.booleans())
def test_a_path_ends_where_follow_says(seed, name, compiled):
    """A path that ends on the way (a fold, or a branch quantity leaving its sign beyond the
    band) ends at the point reached, to END_TOLERANCE: no step of 2 END_TOLERANCE beyond it
    continues the path. The end is aimed at from the end measures of the last points, not
    halved towards: this checks that the aim does not stop short."""
    optimizer = optimizer_of(name, 0)
    solver = optimizer.solver
    q = np.random.default_rng(seed).uniform(solver.arm.lower, solver.arm.upper)
    configuration = solver.configuration_of(q)
    (psi,) = configuration.redundancy
    probe = Probe(solver, optimizer.objective, solver.arm.fk(q), configuration.signs, compiled=compiled)
    for side in (1.0, -1.0):
        end, arrived = probe.follow(probe.point(psi, q), psi + side * np.pi)
        if not arrived:
            assert probe.next(end, end.psi + side * 2.0 * END_TOLERANCE) is None
