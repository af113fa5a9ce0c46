"""The circle search's scan memo (csrc/ik/circle_samples.c) and the torus search's (csrc/ik/torus.c): a
batch's scan cache keeps the model's parts at the scan's samples and edges of reach, and the lifted
residual's terms at the torus' grid, for its next search of the same pose, so a row's answer must
not depend on which rows the batch solved before it, to the last bit."""

from __future__ import annotations

import numpy as np
import pytest

import om_redundant as om
from om_redundant import _core
from tests.conftest import random_q


def _grid(solver: om.OMSolver, T: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rows of a sweep of pose T (paths.sweep_circle's layout): n arm angles, each in every
    branch, the branches that differ in the SHOULDER sign alone next to each other."""
    branches = sorted((c.signs for c in solver.configurations()), key=lambda s: (s[1:], s[0]))
    psi = -np.pi + 2.0 * np.pi * np.arange(n) / n
    return (
        np.repeat(T[None], n * len(branches), axis=0),
        np.tile(branches, (n, 1)),
        np.repeat(psi, len(branches)),
    )


def _rows(batch: om.BatchRoots, order: np.ndarray) -> list[np.ndarray]:
    return [
        batch.q[order],
        batch.count[order],
        batch.position_error[order],
        batch.orientation_error[order],
        batch.iterations[order],
        batch.within_limits[order],
    ]


# (poses with 0, 1 and 2 roots)
@pytest.mark.parametrize(("name", "seed"), [("panda", 4), ("xarm7", 1), ("sawyer", 4)])
def test_grid_rows_do_not_depend_on_the_rows_before(name, seed):
    """A sweep's grid in its own order (every scan after the first of a pose takes the memo's
    parts), in a random order (arm angles and branches mixed: other parts kept, others
    replaced), with rows of poses of another position and of another orientation before
    each row (every scan computes its parts afresh), and row by row (each row a batch of its
    own: a memo of its own) give the same roots, errors and evaluation counts."""
    solver = om.OMSolver(name)
    rng = np.random.default_rng(seed)
    T, T_other = solver.arm.fk(random_q(solver.arm, 2, rng))
    Ts, signs, psi = _grid(solver, T, 16)
    band = rng.uniform(size=len(Ts)) < 0.5
    swept = solver.solve_grid(Ts, signs, psi, band, threads=1)
    assert (swept.count == 0).any() and (swept.count > 1).any()
    everything = np.arange(len(Ts))
    order = rng.permutation(len(Ts))
    mixed = solver.solve_grid(Ts[order], signs[order], psi[order], band[order], threads=1)
    for a, b in zip(_rows(swept, order), _rows(mixed, everything), strict=True):
        np.testing.assert_array_equal(a, b)
    # Row 3 i is row i of the sweep, rows 3 i + 1 and 3 i + 2 the same branch and arm angle at
    # poses that differ from T in the position alone and in the orientation alone.
    moved, turned = T.copy(), T.copy()
    moved[:3, 3] = T_other[:3, 3]
    turned[:3, :3] = T_other[:3, :3]
    thrice = np.repeat(everything, 3)
    poses = np.tile(np.stack([T, moved, turned]), (len(Ts), 1, 1))
    interleaved = solver.solve_grid(poses, signs[thrice], psi[thrice], band[thrice], threads=1)
    for a, b in zip(_rows(swept, everything), _rows(interleaved, 3 * everything), strict=True):
        np.testing.assert_array_equal(a, b)
    for i in rng.choice(len(Ts), 12, replace=False):
        alone = solver.solve_grid(Ts[i : i + 1], signs[i : i + 1], psi[i : i + 1], band[i : i + 1], threads=1)
        for a, b in zip(_rows(swept, np.array([i])), _rows(alone, np.array([0])), strict=True):
            np.testing.assert_array_equal(a, b)


def _solve_all_rows(solver: om.OMSolver, Ts: np.ndarray, signs: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """The kernel's (count, evaluations) of each row, the rows one batch (one scan memo), without
    the library's checks of the poses (which refuse a pose that is not a number)."""
    m, n = len(Ts), _core.MAX_ROOTS
    batch = _core.SolveAllBatch(
        Ts,
        signs,
        psi[:, None],
        band=np.ones(m, dtype=bool),
        q=np.full((m, n, solver.arm.dof), np.nan),
        count=np.zeros(m, dtype=np.int64),
        evaluations=np.zeros(m, dtype=np.int64),
        position_error=np.full((m, n), np.nan),
        orientation_error=np.full((m, n), np.nan),
        within_limits=np.zeros((m, n), dtype=bool),
    )
    solver.kernel.solve_all_rows(batch, 0, m)
    return np.stack([batch.count, batch.evaluations], axis=1)


@pytest.mark.parametrize("name", ["panda", "sawyer"])
def test_a_pose_that_is_not_a_number_does_not_read_the_rows_before(name):
    """The kernel's rows of a pose with a NaN position (reached only past the library's checks)
    are out of the model's reach at every sample whatever the batch solved before: no root, and
    the same evaluations as alone (a memo's parts of the pose before must not stand in for the
    parts that a NaN hand has none of)."""
    solver = om.OMSolver(name)
    T = solver.arm.fk(random_q(solver.arm, 1, np.random.default_rng(4))[0])
    Ts, signs, psi = _grid(solver, T, 4)
    broken = T.copy()
    broken[0, 3] = np.nan
    after = np.concatenate([Ts, np.repeat(broken[None], len(Ts), axis=0)])
    counts = _solve_all_rows(solver, after, np.concatenate([signs, signs]), np.concatenate([psi, psi]))
    alone = _solve_all_rows(solver, after[len(Ts) :], signs, psi)
    assert (counts[len(Ts) :, 0] == 0).all()
    np.testing.assert_array_equal(counts[len(Ts) :], alone)
