"""The Python loops of path following and linking (``_core.follow``, ``csrc/redundancy/follow.c``;
``_core.link_paths``, ``csrc/redundancy/link.c``; the library's are
:meth:`~om_redundant.redundancy.paths.probe.Probe.follow`, ``next`` and ``link``): the same
steps, tests and decisions written over the solver's public ``solve`` (its bounded search
where the kernel solves locally) and numpy."""

from __future__ import annotations

import itertools
import math

import numpy as np

from om_redundant import _core
from om_redundant.angles import TURN, wrap_angles
from om_redundant.exceptions import SingularSelfMotion
from om_redundant.ik.configuration import Configuration
from om_redundant.ik.solver import BRANCH_BAND
from om_redundant.redundancy.paths.linking import Path
from om_redundant.redundancy.paths.points import Point, PointTerms
from om_redundant.redundancy.paths.probe import END_TOLERANCE, JUMP, SAME, Probe


def continues(probe: Probe, point: Point, psi: float, q: np.ndarray) -> bool:
    """Whether q at psi continues point's path: its joints moved at most JUMP and as the
    path's tangent predicts to first order, within half of the move (plus SAME)."""
    moved = q - point.q
    moved = np.where(probe.cyclic, wrap_angles(moved), moved)
    error = moved - point.tangent @ np.atleast_1d(psi - point.psi)
    jump = np.abs(moved).max()
    return bool(jump <= JUMP and np.abs(error).max() <= 0.5 * jump + SAME)


def next_point(probe: Probe, point: Point, psi: float) -> Point | None:
    """The solution at psi nearest point, if it continues point's path; a solution without a
    tangent (a fold met exactly) fails, as any other that does not continue."""
    solution = probe.solver.solve(probe.T, Configuration(probe.signs, (psi,)), q_hint=point.q)
    if not solution.ok:
        return None
    try:
        found = probe.point(psi, solution.q, solution)
    except SingularSelfMotion:
        return None
    return found if continues(probe, point, psi, found.q) else None


def follow(probe: Probe, start: Point, psi: float) -> tuple[Point, bool]:
    """Start's path followed towards psi: the point reached and whether it is at psi."""
    point, step = start, psi - start.psi
    ends, behind = end_measures(probe, point), None  # behind: (psi, end measures) of the point before
    crawled = 0  # accepted steps in a row shorter than FOLLOW_CRAWL
    for attempts in itertools.count():
        if point.psi == psi:
            break
        if abs(step) < END_TOLERANCE:
            return point, False
        if attempts == _core.FOLLOW_MAX_ATTEMPTS or crawled == _core.FOLLOW_CRAWL_STEPS:
            raise SingularSelfMotion(f"the self-motion crawls at psi = {point.psi:+.6f}")
        x = psi if abs(psi - point.psi) <= abs(step) else point.psi + step
        aim = math.inf
        if behind is not None:
            ahead = predicted_end(behind[1], ends, abs(point.psi - behind[0]))
            aim = max(_core.FOLLOW_AIM * ahead, 1.5 * END_TOLERANCE)
        if aim < abs(x - point.psi):
            x = point.psi + math.copysign(aim, step)
        found = next_point(probe, point, x)
        if found is None:  # (halved from x, not from step: psi nearer than step is not tried again)
            step = 0.5 * (x - point.psi)
        else:
            crawled = crawled + 1 if abs(x - point.psi) < _core.FOLLOW_CRAWL else 0
            step = 2.0 * (x - point.psi)
            behind, point = (point.psi, ends), found
            ends = end_measures(probe, point)
    return point, True


def end_measures(probe: Probe, point: Point) -> list[float]:
    """What ends a path, as functions of its point that fall to zero there linearly in psi:
    1 / |dq/dpsi|^2 at a fold, and s_i b_i + BRANCH_BAND where branch quantity b_i leaves its
    sign s_i beyond the band."""
    branch, redundancy = np.empty(len(probe.signs)), np.empty(1)
    probe.solver.kernel.configuration_values(np.ascontiguousarray(point.q), branch, redundancy)
    tt = 0.0
    for v in point.tangent[:, 0].tolist():  # (summed in order, as csrc/redundancy/follow.c does)
        tt += v * v
    return [1.0 / tt] + [
        float(s) * b + BRANCH_BAND for s, b in zip(probe.signs, branch.tolist(), strict=True)
    ]


def predicted_end(before: list[float], now: list[float], moved: float) -> float:
    """The distance in psi ahead of a point (end measures ``now``) to the nearest end that the
    secant of a measure falling towards zero predicts, from the point ``moved`` behind
    (measures ``before``); inf where none falls."""
    ahead = [moved * f / (b - f) for b, f in zip(before, now, strict=True) if 0.0 < f < b]
    return min(ahead, default=math.inf)


def link(probe: Probe, psi: np.ndarray, roots: list[list[Point]]) -> list[Path]:
    """The paths through the solutions ``roots[k]`` at the increasing grid psi[k]: each
    ongoing path followed to the next grid psi (or taken to its only solution where that
    continues it) and linked to the solution it arrives at; solutions not arrived at start
    new paths; then the paths joined across +-pi and followed back to where they end. (The
    follows are the kernel's, :func:`_follow`: this is the oracle of the linking's decisions.)"""
    n = len(psi)
    paths: list[list[Point]] = []
    first: list[int] = []  # grid index of each path's first sample
    ongoing: list[int] = []  # paths that reached the previous grid psi
    for k in range(n):
        taken = [False] * len(roots[k])
        reaching = []
        for i in ongoing:
            last = paths[i][-1]
            if len(roots[k]) == 1 and continues(probe, last, roots[k][0].psi, roots[k][0].q):
                reached, arrived = roots[k][0], True
            else:
                reached, arrived = _follow(probe, last, psi[k])
            if not arrived:
                paths[i] += [reached] if reached is not last else []
                continue
            j = _same(probe, reached, roots[k])
            if j is None:  # a solution the bounded search did not list
                roots[k].append(reached)
                taken.append(False)
                j = len(roots[k]) - 1
            if not taken[j]:  # (else two paths met: this one stops here)
                taken[j] = True
                paths[i].append(roots[k][j])
                reaching.append(i)
        for j, root in enumerate(roots[k]):
            if not taken[j]:
                paths.append([root])
                first.append(k)
                reaching.append(len(paths) - 1)
        ongoing = reaching
    return _joined(probe, psi, paths, first, ongoing)


def _joined(
    probe: Probe, psi: np.ndarray, paths: list[list[Point]], first: list[int], last: list[int]
) -> list[Path]:
    following: dict[int, int] = {}  # path i continues across +-pi into path following[i]
    for i in last:
        reached, arrived = _follow(probe, paths[i][-1], psi[0] + TURN)
        starts = [j for j in range(len(paths)) if first[j] == 0 and j not in following.values()]
        j = _same(probe, reached, [paths[j][0] for j in starts]) if arrived else None
        if j is not None:
            following[i] = starts[j]
        elif not arrived and reached is not paths[i][-1]:
            paths[i].append(reached)
    heads = [i for i in range(len(paths)) if i not in following.values()]
    result, seen = [], set()
    for head in heads + list(following):  # chains from their heads, then the loops
        if head in seen:
            continue
        chain = [head]
        while chain[-1] in following and following[chain[-1]] not in chain:
            chain.append(following[chain[-1]])
        seen.update(chain)
        points = [p.at(p.psi + TURN * turn) if turn else p for turn, i in enumerate(chain) for p in paths[i]]
        if following.get(chain[-1]) == chain[0]:
            result.append(Path(points, turns=len(chain)))
        else:
            k = first[chain[0]]
            reached, _ = _follow(probe, points[0], psi[k - 1] if k > 0 else psi[-1] - TURN)
            result.append(Path(([reached] if reached is not points[0] else []) + points))
    return result


def _same(probe: Probe, point: Point, candidates: list[Point]) -> int | None:
    for j, candidate in enumerate(candidates):
        if candidate is point:  # (the candidates are more than SAME apart)
            return j
    steps = [probe.step(point.q, c.q) for c in candidates]
    return int(np.argmin(steps)) if steps and min(steps) <= SAME else None


def _follow(probe: Probe, start: Point, psi: float) -> tuple[Point, bool]:
    """``_core.follow`` from start towards psi as the linking takes it: a follow that stalls
    ends the path at the last point it accepted (where :meth:`Probe.follow` raises)."""
    work = probe._work
    work.q[:] = start.q
    work.t[:] = start.tangent[:, 0]
    reached, status, steps = _core.follow(work, float(start.psi), float(psi), END_TOLERANCE)
    if steps == 0:
        return start, status == _core.FOLLOW_ARRIVED
    q, tangent = work.q.copy(), work.t.copy()[:, None]
    return Point(reached, q, tangent, PointTerms(probe.objective, q, tangent)), status == _core.FOLLOW_ARRIVED
