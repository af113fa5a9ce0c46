"""The torus search's certificate (csrc/ik/contraction.c): its rate bounds hold for the map itself,
and where it decides, it finds every root that the grid search finds, on random poses and
next to the singular shoulder, the singular wrist, the straight and the folded elbow."""

from __future__ import annotations

import numpy as np
import pytest

from om_redundant import _core
from om_redundant._core import MAX_ROOTS
from om_redundant.ik.kernel_data import flange_target
from tests.conftest import EXACT, random_q, solver_of, wrap

TORUS_ARMS = ["gen3", "sawyer"]
#: The share of the random problems below that the certificate decides, at least: the Gen3's offsets
#: (12 mm) leave its map a contraction on most of the torus; the Sawyer's (0.35 m) do not.
DECIDED = {"gen3": 0.5, "sawyer": 0.0}


def _map(solver, T, signs, psi, w):
    """G(w) = (q1, q7) of the model IK at the torus points w (n, 2); NaN out of reach."""
    data = solver.solver_data()
    R, p = flange_target(T, data.T_base_root, data.T_tool_flange)
    D = data.dp_coefficients
    out = np.full((len(w), 2), np.nan)
    q = np.empty(7)
    for k, (w1, w7) in enumerate(w):
        delta = D[0] + D[1] * np.cos(w7) + D[2] * np.sin(w7)
        pm = p + D[3] + D[4] * np.cos(w1) + D[5] * np.sin(w1) + R @ delta
        model = _core.FamilyModel(data.family, data.params, data.model_table)
        target = _core.FlangeTarget(R, pm, np.array(signs), np.array([psi]))
        margin = _core.model_ik(model, target, np.zeros(7), q, True)
        if margin >= -1e-12:
            out[k] = q[0], q[6]
    return out


def _rates(solver) -> tuple[float, float]:
    """r_a and r_d: |dx| <= r_a |dw1| + r_d |dw7| on the torus."""
    D = solver.solver_data().dp_coefficients
    return float(np.linalg.norm(D[4:6])), float(np.linalg.norm(D[1:3]))


@pytest.mark.parametrize("name", TORUS_ARMS)
def test_rate_bounds_hold_for_the_map(name):
    """|G_i(u) - G_i(v)| <= g_i (r_a |du1 - dv1| + r_d |du7 - dv7|) for pairs of points of the
    cells the bound is asked for (the whole torus, and squares about random points), and the
    model reaches every point where a bound is finite."""
    solver = solver_of(name)
    r_a, r_d = _rates(solver)
    rng = np.random.default_rng(7)
    checked = 0
    for q in random_q(solver.arm, 30, rng):
        T, c = solver.arm.fk(q), solver.configuration_of(q)
        for h in (4.0, np.pi / 4, np.pi / 32, np.pi / 256):
            centre = rng.uniform(-np.pi, np.pi, 2)
            bound = solver.kernel.torus_bound(T, c.signs, c.redundancy, centre[0], centre[1], h)
            g1, g7 = bound.g1, bound.g7
            if not (np.isfinite(g1) or np.isfinite(g7)):
                continue
            half = np.pi if h >= np.pi else 2 * h  # the square C' the bound holds on
            u = centre + rng.uniform(-half, half, (40, 2))
            v = u + rng.uniform(-1, 1, (40, 2)) * np.minimum(half, 1e-3 * rng.uniform(0, 1000, (40, 1)))
            v = np.clip(v, centre - half, centre + half)
            Gu, Gv = (_map(solver, T, c.signs, c.redundancy[0], w) for w in (u, v))
            step = r_a * np.abs(u[:, 0] - v[:, 0]) + r_d * np.abs(u[:, 1] - v[:, 1])
            for i, g in enumerate((g1, g7)):
                if np.isfinite(g):
                    assert np.isfinite(Gu[:, i]).all() and np.isfinite(Gv[:, i]).all()
                    assert (np.abs(wrap(Gu[:, i] - Gv[:, i])) <= g * step * (1 + 1e-9) + 1e-12).all()
                    checked += 1
    assert checked > 20


def _adversarial_q(solver, rng: np.random.Generator) -> list[np.ndarray]:
    """Joint vectors next to the model's singular shoulder (sin(q2 + theta2) = 0) and wrist
    (sin(q6 + theta6) = 0), and its straight and folded elbow (the edge of reach), at distances
    1e-7 to 1e-1 rad."""
    theta = solver.solver_data().params[_core.SRS_THETA : _core.SRS_THETA + 7]
    phi_star = solver.solver_data().params[_core.SRS_PHI_STAR]
    out = []
    for q in random_q(solver.arm, 12, rng):
        for eps in (1e-7, 1e-4, 1e-2, 1e-1):
            for joint, zero in ((1, 0.0), (5, 0.0), (3, phi_star), (3, phi_star + np.pi)):
                moved = q.copy()
                moved[joint] = wrap(zero - theta[joint] + eps * rng.choice([-1, 1]))
                out.append(moved)
    return out


def _roots(solver, T, c, certify: bool) -> tuple[np.ndarray, int]:
    roots = np.empty((MAX_ROOTS, 7))
    found = solver.kernel.bounded_search(T, c.signs, c.redundancy, roots, certify)
    return roots[: found.count], found.evaluations


@pytest.mark.parametrize("name", TORUS_ARMS)
def test_certificate_finds_every_root_of_the_grid_search(name):
    """Every root the grid search finds, the certified search finds too (it would not, were a
    cell it proves empty to hold one, or a cell it proves to hold one to hold two), and each of
    its roots reaches the pose in the configuration; on random poses in their own and in random
    configurations, and on adversarial ones (_adversarial_q)."""
    solver = solver_of(name)
    rng = np.random.default_rng(3)
    random = list(random_q(solver.arm, 60, rng))
    decided = 0
    for k, q in enumerate(random + _adversarial_q(solver, rng)):
        T = solver.arm.fk(q)
        own = solver.configuration_of(q)
        other = type(own)(tuple(rng.choice([-1, 1], 3).tolist()), (rng.uniform(-np.pi, np.pi),))
        for c in (own, other):
            grid, _ = _roots(solver, T, c, False)
            certified, evaluations = _roots(solver, T, c, True)
            decided += k < len(random) and evaluations < 1000
            for root in grid:
                assert min((np.abs(wrap(root - r)).max() for r in certified), default=np.inf) < 1e-6, (q, c)
            for root in certified:
                assert solver.holds(root, c)
                assert np.linalg.norm(solver.arm.fk(root)[:3, 3] - T[:3, 3]) < EXACT
    assert decided >= DECIDED[name] * 2 * len(random)


@pytest.mark.parametrize("name", TORUS_ARMS)
def test_hinted_solve_is_at_least_as_near_as_every_grid_root(name):
    """The hinted solve's window search (certified where it decides) returns a root at least
    as near the hint as every root of the grid search over the whole torus."""
    solver = solver_of(name)
    rng = np.random.default_rng(5)
    for q in random_q(solver.arm, 40, rng):
        T, c = solver.arm.fk(q), solver.configuration_of(q)
        hint = q + rng.uniform(-0.05, 0.05, 7)
        solution = solver.solve(T, c, q_hint=hint)
        assert solution.ok
        grid, _ = _roots(solver, T, c, False)
        nearest = min(np.linalg.norm(wrap(root - hint)) for root in grid)
        assert np.linalg.norm(wrap(solution.q - hint)) <= nearest + 1e-9


@pytest.mark.parametrize("name", TORUS_ARMS)
def test_rows_that_share_the_grid_search_are_rows_alone(name):
    """A batch's rows in the sweep's order (the four SHOULDER and WRIST signs of an ELBOW sign
    next to each other, which share the torus search's candidates, om_scan_cache) are the rows
    of batches of one row each: the same roots in the same order, bit for bit, and evaluations.
    (A batch's whole-torus searches start from the traced self-motion, torus_trace.c, and
    solve_all's from the grid: test_torus_trace.py compares those.)"""
    solver = solver_of(name)
    T = solver.arm.fk(random_q(solver.arm, 2, np.random.default_rng(8)))
    branches = sorted((c.signs for c in solver.configurations()), key=lambda s: (s[1:], s[0]))
    rows = [(t, s, x) for t in T for x in np.linspace(-np.pi, np.pi, 6, endpoint=False) for s in branches]
    Ts, signs, redundancy = (np.array(column) for column in zip(*rows, strict=True))
    batch = solver.solve_all_batch(Ts, signs, redundancy, threads=1)
    assert (batch.count > 0).any()
    for i in range(len(Ts)):
        alone = solver.solve_all_batch(Ts[i : i + 1], signs[i : i + 1], redundancy[i : i + 1])
        for field in ("q", "count", "position_error", "orientation_error", "iterations", "within_limits"):
            np.testing.assert_array_equal(getattr(batch, field)[i], getattr(alone, field)[0])
