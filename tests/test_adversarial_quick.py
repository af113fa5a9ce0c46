"""The adversarial benchmark's cheap classes on a tiny sample: no wrong ok, no stray exception.

``python -m benchmarks.adversarial`` runs them at full size on every arm; here its own
functions run on two arms (a 6-DOF arm and the 7-DOF torus arm with unlimited joints) in a
few seconds. The singular class and the bad-input list are not asserted here.
"""

from __future__ import annotations

import pytest

import om_redundant as om
from benchmarks import adversarial as adv

ARMS = ["ur5e", "gen3"]
CLASSES = {
    "random": lambda run: adv.run_random(run, 200),
    "huge/tiny": lambda run: adv.run_huge_tiny(run, 20),
    "layouts": lambda run: adv.run_layouts(run, 4),
    "repeated": lambda run: adv.run_repeated(run, 30),
}


def _failures(run: adv.ArmRun) -> str:
    return "\n".join(adv.reproducer(f) for f in run.result.failures)


@pytest.mark.parametrize("cls", list(CLASSES))
@pytest.mark.parametrize("name", ARMS)
def test_no_wrong_ok_and_no_stray_exception(name, cls):
    run = adv.ArmRun(name, seed=7)
    tally = CLASSES[cls](run)
    assert tally.calls > 0 and tally.ok > 0
    # The page's 1e-10 rad is stricter than the solver's own orientation tolerance (1e-9 rad):
    # a miss between the two is noted there, and is no wrong answer by the solver's contract.
    within_tolerance = tally.notes["wrong ok within the solver's own tolerance"]
    assert tally.wrong_ok - within_tolerance == 0, _failures(run)
    assert tally.foreign == 0, _failures(run)
    if cls in ("layouts", "repeated"):  # these classes exist to compare answers
        assert tally.differs == 0, _failures(run)


@pytest.mark.parametrize("name", ["ur5e", "panda"])
def test_the_check_catches_a_wrong_answer(name):
    """The benchmark's own check (deferred and vectorised, or one at a time) flags a miss of
    1e-9 rad, a wrong within_limits, the other branch and (7-DOF) another psi."""

    class Fake:
        def __init__(self, q, within=True):
            self.q, self.ok, self.status, self.within_limits = q, True, "ok", within

    for deferred in (True, False):
        run = adv.ArmRun(name, seed=1)
        tally = run.tally("check")
        q = run.random_q(1)[0]
        T, c = run.arm.fk(q), run.solver.configuration_of(q)
        run.pending = [] if deferred else None
        flipped = adv.flipped(c, 2, run.solver.sign_names)
        cases = [(Fake(q), c), (Fake(q + 1e-9), c), (Fake(q, within=False), c), (Fake(q), flipped)]
        if c.redundancy:
            cases.append((Fake(q), om.Configuration(c.signs, (c.redundancy[0] + 2e-9,))))
        for sol, config in cases:
            run.judge(tally, "check", sol, T, config, True)
        run.flush()
        assert tally.ok == len(cases)
        assert tally.wrong_ok == len(cases) - 1, _failures(run)


@pytest.mark.parametrize("name", om.arm_names())
def test_boundary_poses_are_made_within_the_limits_at_the_value_asked(name):
    """The singular class's poses: a branch quantity at +-1e-3 ... 1e-14, q within the limits,
    on the first random q (the old 1-D Newton left the limits or diverged for 40-55 % of them,
    redrawing q, which kept out the crossings next to a limit)."""
    run = adv.ArmRun(name, seed=3)
    k = len(run.solver.sign_names)
    for i in range(36):
        value = (-1.0) ** i * 10.0 ** -(3 + i % 12)
        q = run.boundary_q(i % k, value)
        assert q is not None, (i % k, value)
        assert ((run.arm.lower <= q) & (q <= run.arm.upper)).all()
        assert abs(run.checker.branch(q)[i % k] - value) <= 0.05 * abs(value)


@pytest.mark.parametrize("name", ["panda", "xarm7", "sawyer"])
def test_arm_angle_line_poses_are_made_at_the_angle_asked(name):
    """The singular class's 7-DOF poses next to psi's singular half-line: the model's wrist
    centre at delta (1e-4 ... 1e-12) from straight below (or above) the shoulder, within limits."""
    run = adv.ArmRun(name, seed=5)
    made = 0
    for i in range(120):
        delta, side = 10.0 ** -(4 + i % 9), -1.0 if i % 3 else 1.0
        q = run.near_arm_angle_line(delta, side)
        if q is None:
            continue
        made += 1
        assert ((run.arm.lower <= q) & (q <= run.arm.upper)).all()
        assert 0.4 * delta <= run.arm_angle_line_angle(q, side) <= 1.6 * delta
    assert made >= 6
