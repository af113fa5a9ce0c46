r"""The OM system (9) and its solvers, as numba kernels.

System (9) asks for the model's hand position :math:`p_m` with

.. math::  p_m = p_d + \Delta p\big(\mathrm{IK}_{model}(R_d, p_m, c)\big).

Every solution has the form :math:`p_m = p_d + R_d\,\delta(w)`, where :math:`\delta` is dp
seen from the flange and depends on one wrist joint, :math:`w = q_J` (see
:mod:`om_redundant.model`). So the three equations reduce exactly to one on the circle,

.. math::  g(w) = \mathrm{wrap}\big(\mathrm{IK}_{model}(R_d, p_d + R_d\,\delta(w), c)_J - w\big) = 0,

and a root gives the real arm's joints :math:`q = \mathrm{IK}_{model}(\ldots)` with
:math:`|p_{real}(q) - p_d| = |\delta(w) - \delta(q_J)| \le \Delta p_{max}\,|g(w)|`.

Arms with shoulder offsets (Gen3) add :math:`a(q_1)`, so solutions lie on a torus
:math:`(q_1, q_7)`. The search then scans :math:`w = q_1`, where the larger offset acts,
and solves :math:`q_7` inside each evaluation of g by a secant iteration on
:math:`\mathrm{IK}(R_d, p_d + a(w) + R_d\,\delta(w_7), c)_7 = w_7`, which is nearly
the identity because the wrist offset is small. Where that iteration has no root, the
point counts as out of reach.

* Local solve: Broyden's method, which in one unknown is the secant method, started with a
  finite-difference slope, from the joint of the paper's fixed-point start
  (:math:`p_m = p_d`) or of a hint.
* Bounded search, the paper's guarantee: g is sampled on a grid over the whole circle (the
  image of the ball :math:`|p_m - p_d| \le \Delta p_{max}` that can hold solutions); each sign
  change is refined; near the edges of the model's reach, at local minima of |g| and on
  small islands of reach, where roots come in close pairs, 1-D extremum searches find
  them. Every candidate is verified with the REAL arm's forward kinematics.

All kernels work in DH frame 0 with the flange pose. One target's problem travels as one
tuple, see :func:`make_problem`; its last entry counts the residual evaluations.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from .closed_form import REACH_SLACK, branch_values, model_ik, redundancy_values, wrap
from .closed_form.common import dot, mtm
from .kinematics import flange_kernel

OK = 0
UNREACHABLE = 1
NO_SOLUTION_IN_CONFIGURATION = 2
STATUS_NAMES = ("ok", "unreachable", "no solution in this configuration")

MAX_ROOTS = 16
_ROOT_TOL = 1e-13  # |g| accepted as a root before verification
_SAME_ROOT = 1e-9  # joint-space distance under which two roots are one
_START_POINTS = 8  # samples of the dp circle tried when p_d is outside the model's reach
_WINDOW_POINTS = 8  # samples of the window searched around a hint
_PAIR_SEARCH = 1.0  # |g| (rad) below which a local minimum is searched for a root pair
_REDUNDANCY_TOL = 1e-9  # a solution's redundancy values (rad) must equal the requested ones
_INNER_TOL = 1e-12  # |h| (rad) at which the inner q7 iteration has converged


@nb.njit(cache=True, inline="always")
def _delta(D, w):
    """dp seen from the flange, delta(w) = D0 + D1 cos w + D2 sin w (see ModelArm.delta)."""
    c, s = np.cos(w), np.sin(w)
    return (
        D[0, 0] + D[1, 0] * c + D[2, 0] * s,
        D[0, 1] + D[1, 1] * c + D[2, 1] * s,
        D[0, 2] + D[1, 2] * c + D[2, 2] * s,
    )


@nb.njit(cache=True)
def make_problem(family, P, mtab, rtab, J, D, R, p, signs, redundancy, q_prev):
    """Bundle one target's data: model family and parameters, model and real DH tables,
    the joint J that dp depends on and the coefficients D of delta, the flange pose (R, p),
    the configuration (branch signs and redundancy values), the joints kept at
    singularities (q_prev), and an evaluation counter."""
    return (family, P, mtab, rtab, J, D, R, p, signs, redundancy, q_prev, np.zeros(1, dtype=np.int64))


@nb.njit(cache=True)
def _with_signs(problem, signs):
    """The same problem in another configuration, sharing the evaluation counter."""
    family, P, mtab, rtab, J, D, R, p, _, redundancy, q_prev, counter = problem
    return (family, P, mtab, rtab, J, D, R, p, signs, redundancy, q_prev, counter)


@nb.njit(cache=True, inline="always")
def _g_margin(problem, w, q):
    """Residual g(w) (NaN if unreachable) and the model's reach margin; writes the IK into q.

    With shoulder offsets (D has six rows), w is q_1 and q_7 is solved inside
    (:func:`_wrist_ik`); otherwise w is q_J.
    """
    J, D, p = problem[4], problem[5], problem[7]
    if D.shape[0] == 6:
        c, s = np.cos(w), np.sin(w)
        pm = np.empty(3)
        for k in range(3):
            pm[k] = p[k] + D[3, k] + D[4, k] * c + D[5, k] * s
        margin = _wrist_ik(problem, pm, q)
    else:
        margin = _ik_plus_delta(problem, p, w, q)
    if margin < -REACH_SLACK:
        return np.nan, margin
    if J < 0:
        return 0.0, margin
    return wrap(q[J] - w), margin


@nb.njit(cache=True, inline="always")
def _ik_plus_delta(problem, base, w, q):
    """Model IK for p_m = base + R delta(w) (one residual evaluation); returns the reach margin."""
    family, P, mtab, _, _, D, R, _, signs, redundancy, q_prev, counter = problem
    counter[0] += 1
    d = _delta(D, w)
    pm = np.empty(3)
    for k in range(3):
        pm[k] = base[k] + R[k, 0] * d[0] + R[k, 1] * d[1] + R[k, 2] * d[2]
    return model_ik(family, P, mtab, R, pm, signs, redundancy, q_prev, q)


@nb.njit(cache=True)
def _ik_at_q7(problem, pm, w7, q):
    """Model IK for p_m + R delta(w7); returns (h, margin), h = wrap(q_7 - w7) (NaN out of reach)."""
    margin = _ik_plus_delta(problem, pm, w7, q)
    if margin < -REACH_SLACK:
        return np.nan, margin
    return wrap(q[6] - w7), margin


@nb.njit(cache=True)
def _wrist_ik(problem, pm, q):
    """Model IK with the wrist offsets' dp :math:`R\\,\\delta(q_7)` taken at the model's own q_7.

    Solves :math:`h(w_7) = \\mathrm{wrap}(\\mathrm{IK}(p_m + R\\,\\delta(w_7))_7 - w_7) = 0` by
    the secant method. The wrist offsets are small next to the shoulder's (the bounded search
    scans q_1), so :math:`dh/dw_7 \\approx -1` and the root is unique except within a
    hair of the model's reach edge. The start is the hint's q_7, or, if the model cannot
    reach from there, the best of a few samples of the circle. Returns the reach margin at
    the root, whose IK is in q; without a root, a negative number.
    """
    w0 = problem[10][6]
    h0, margin = _ik_at_q7(problem, pm, w0, q)
    if np.isnan(h0):
        best, best_margin = np.inf, margin
        for k in range(_START_POINTS):
            w = -np.pi + 2.0 * np.pi * k / _START_POINTS
            h, m = _ik_at_q7(problem, pm, w, q)
            best_margin = max(best_margin, m)
            if abs(h) < best:  # False for NaN
                best, w0, h0 = abs(h), w, h
        if np.isnan(h0):
            return best_margin
    w1 = w0 + h0  # a fixed-point step
    h1, margin = _ik_at_q7(problem, pm, w1, q)
    for _ in range(40):
        while np.isnan(h1) and abs(w1 - w0) > 1e-12:  # stepped out of reach: step back
            w1 = 0.5 * (w0 + w1)
            h1, margin = _ik_at_q7(problem, pm, w1, q)
        if np.isnan(h1) or abs(h1) < 1e-15 or h1 == h0:
            break
        step = -h1 * (w1 - w0) / (h1 - h0)
        if abs(step) > 0.5:
            step = 0.5 * np.sign(step)
        w0, h0 = w1, h1
        w1 = w1 + step
        h1, margin = _ik_at_q7(problem, pm, w1, q)
    if np.isnan(h1):  # q must belong to a reachable iterate
        h1, margin = _ik_at_q7(problem, pm, w0, q)
    # No root: the iterates ran into the reach edge. -|h| extends the margin past the edge,
    # where both vanish, so that the search sees the region as out of reach.
    return margin if abs(h1) < _INNER_TOL else -abs(h1)


@nb.njit(cache=True, inline="always")
def _g(problem, w, q):
    """Residual g(w) of the reduced system; writes the model IK into q. NaN if unreachable."""
    return _g_margin(problem, w, q)[0]


@nb.njit(cache=True)
def _broyden(problem, w0, q):
    """Secant (1-D Broyden) iteration from w0 with a finite-difference slope.

    Returns |g| at the end; q holds the model IK at the last iterate.
    """
    g0 = _g(problem, w0, q)
    if problem[4] < 0 or np.isnan(g0):
        return abs(g0)
    h = 1e-7
    g1 = _g(problem, w0 + h, q)
    slope = (g1 - g0) / h if not np.isnan(g1) else -1.0
    w, g = w0, g0
    for _ in range(40):
        if g == 0.0 or slope == 0.0 or np.isnan(slope):
            break
        step = -g / slope
        if abs(step) > 0.5:
            step = 0.5 * np.sign(step)
        g_new = _g(problem, w + step, q)
        if np.isnan(g_new):
            break
        slope = (g_new - g) / step
        w, g = w + step, g_new
        if abs(step) < 1e-15 * max(1.0, abs(w)) or abs(g) < 1e-16:
            break
    # q must belong to the final iterate.
    return abs(_g(problem, w, q))


@nb.njit(cache=True)
def _refine_bracket(problem, a, ga, b, gb, q):
    """Illinois regula falsi on a sign-changing bracket; returns the root estimate."""
    side = 0
    for _ in range(100):
        c = (a * gb - b * ga) / (gb - ga)
        gc = _g(problem, c, q)
        if np.isnan(gc) or gc == 0.0 or abs(b - a) < 1e-15:
            return c
        if np.sign(gc) == np.sign(gb):
            b, gb = c, gc
            if side == -1:
                ga *= 0.5
            side = -1
        else:
            a, ga = c, gc
            if side == 1:
                gb *= 0.5
            side = 1
    return 0.5 * (a + b)


@nb.njit(cache=True)
def _reach_edge(problem, inside, outside, q):
    """A reachable point next to the edge of the model's reach, between inside and outside.

    Illinois regula falsi on the reach margin, which is smooth across the edge, keeping
    margin(inside) >= -slack > margin(outside) until the two are adjacent.
    """
    fi = _g_margin(problem, inside, q)[1] + REACH_SLACK
    fo = _g_margin(problem, outside, q)[1] + REACH_SLACK
    side = 0
    for _ in range(80):
        if abs(outside - inside) <= 4e-16 * max(1.0, abs(inside)):
            break
        c = (inside * fo - outside * fi) / (fo - fi)
        if not min(inside, outside) < c < max(inside, outside):
            c = 0.5 * (inside + outside)
        fc = _g_margin(problem, c, q)[1] + REACH_SLACK
        if fc >= 0.0:
            inside, fi = c, fc
            if side == 1:
                fo *= 0.5
            side = 1
        else:
            outside, fo = c, fc
            if side == -1:
                fi *= 0.5
            side = -1
    return inside


@nb.njit(cache=True)
def verify(problem, q, tol_pos, tol_ori):
    """Position and orientation error of the REAL arm at q, and the configuration check.

    Returns (position error, orientation error, accepted).
    """
    family, P, _, rtab, _, _, R, p, signs, redundancy, _, _ = problem
    Rr, pr = np.empty((3, 3)), np.empty(3)
    flange_kernel(rtab, q, Rr, pr)
    d = pr - p
    pos = np.sqrt(dot(d, d))
    E = mtm(R, Rr)
    s = 0.5 * np.sqrt((E[2][1] - E[1][2]) ** 2 + (E[0][2] - E[2][0]) ** 2 + (E[1][0] - E[0][1]) ** 2)
    ori = np.arctan2(s, 0.5 * (E[0][0] + E[1][1] + E[2][2] - 1.0))
    values = np.empty(signs.shape[0])
    branch_values(family, P, q, values)
    same = True
    for i in range(signs.shape[0]):
        # A branch quantity at zero (a singular joint) belongs to both branches.
        if values[i] * signs[i] < -1e-12:
            same = False
    values = np.empty(redundancy.shape[0])
    redundancy_values(family, P, q, values)
    for i in range(redundancy.shape[0]):
        if abs(wrap(values[i] - redundancy[i])) > _REDUNDANCY_TOL:
            same = False
    return pos, ori, same and pos <= tol_pos and ori <= tol_ori


@nb.njit(cache=True, inline="always")
def _objective(problem, w, sign, of_margin, q):
    """sign * g(w) (unreachable: -inf), or the reach margin; and g and the margin."""
    g, m = _g_margin(problem, w, q)
    if of_margin:
        return m, g, m
    return (-np.inf if np.isnan(g) else sign * g), g, m


@nb.njit(cache=True)
def _extremum(problem, a, b, x0, sign, of_margin, q):
    """Brent's search, from x0, for the maximum of sign * g (or of the reach margin) on [a, b].

    Unreachable points count as -inf for g. It stops early at the first point that settles
    the caller's question: sign * g > 0 (g crosses zero) or, for the margin, a reachable
    point. Returns (argmax, g there, margin there).
    """
    golden = 0.3819660112501051
    x = w = v = x0
    fx, gx, mx = _objective(problem, x, sign, of_margin, q)
    fw = fv = fx
    d = e = 0.0
    for _ in range(60):
        if fx > 0.0 if not of_margin else not np.isnan(gx):
            break
        xm = 0.5 * (a + b)
        tol = 1e-10 * abs(x) + 1e-11
        if abs(x - xm) <= 2.0 * tol - 0.5 * (b - a):
            break
        parabolic = False
        if abs(e) > tol:  # a parabola through x, w, v (NaN with an unreachable point: skipped)
            r = (x - w) * (fx - fv)
            p_ = (x - v) * (fx - fw)
            den = 2.0 * (p_ - r)
            num = (x - v) * p_ - (x - w) * r
            if den > 0.0:
                num = -num
            den = abs(den)
            if abs(num) < abs(0.5 * den * e) and num > den * (a - x) and num < den * (b - x):
                e, d = d, num / den
                parabolic = True
                if (x + d) - a < 2.0 * tol or b - (x + d) < 2.0 * tol:
                    d = tol if xm >= x else -tol
        if not parabolic:
            e = (a - x) if x >= xm else (b - x)
            d = golden * e
        u = x + (d if abs(d) >= tol else (tol if d > 0.0 else -tol))
        fu, gu, mu = _objective(problem, u, sign, of_margin, q)
        if fu >= fx:
            if u >= x:
                a = x
            else:
                b = x
            v, fv, w, fw = w, fw, x, fx
            x, fx, gx, mx = u, fu, gu, mu
        else:
            if u < x:
                a = u
            else:
                b = u
            if fu >= fw or w == x:
                v, fv, w, fw = w, fw, u, fu
            elif fu >= fv or v in (x, w):
                v, fv = u, fu
    # q must belong to the returned point.
    gx, mx = _g_margin(problem, x, q)
    return x, gx, mx


@nb.njit(cache=True)
def _brackets(problem, a, ga, b, gb, q, out, n):
    """Add the root of g on [a, b] (both ends reachable) to out[n:]; returns the new count.

    A sign change is one root; a wrap of g from about +pi to -pi is none.
    """
    if ga == 0.0:
        out[n] = a
        return n + 1
    # A jump of more than pi is a wrap of g (from about +pi to -pi) or a steep crossing of
    # zero near a singular wrist: bisect until it is clearly one or the other.
    for _ in range(60):
        if abs(ga - gb) <= np.pi or abs(ga - gb) > 1.9 * np.pi:
            break
        c = 0.5 * (a + b)
        gc = _g(problem, c, q)
        if np.isnan(gc):
            return n
        if gc * ga > 0.0:
            a, ga = c, gc
        else:
            b, gb = c, gc
    if gb == 0.0:
        out[n] = b
        return n + 1
    if abs(ga - gb) > np.pi:
        return n
    if ga * gb < 0.0:
        out[n] = _refine_bracket(problem, a, ga, b, gb, q)
        return n + 1
    return n


@nb.njit(cache=True)
def _pair(problem, a, ga, x0, b, gb, q, out, n):
    """Add a close pair of roots on [a, b] to out[n:]: g has one sign at a, x0 and b, and
    its extremum between them may cross zero. Returns the new count."""
    w, g, _ = _extremum(problem, a, b, x0, -np.sign(ga), False, q)
    if np.isnan(g) or g * ga > 0.0:
        return n
    if g == 0.0:
        out[n] = w
        return n + 1
    out[n] = _refine_bracket(problem, a, ga, w, g, q)
    out[n + 1] = _refine_bracket(problem, w, g, b, gb, q)
    return n + 2


@nb.njit(cache=True)
def _run_roots(problem, pw, pg, L, cyclic, q, out, n):
    """Add the roots on a run of reachable points (w ascending) to out[n:]; returns the count.

    Consecutive points with a sign change bracket a root. At each local minimum of |g|, the
    adjacent cells without a sign change are searched for an extremum of g that crosses
    zero: a close pair of roots. A cyclic run covers the whole circle.
    """
    for i in range(L - 1 + cyclic):
        j = (i + 1) % L
        wj = pw[j] + (2.0 * np.pi if j == 0 else 0.0)
        n = _brackets(problem, pw[i], pg[i], wj, pg[j], q, out, n)
    for i in range(L):
        gi = pg[i]
        has_prev, has_next = i > 0 or cyclic, i < L - 1 or cyclic
        glo = pg[(i - 1) % L] if has_prev else np.inf
        ghi = pg[(i + 1) % L] if has_next else np.inf
        if abs(gi) > _PAIR_SEARCH or abs(glo) < abs(gi) or abs(ghi) < abs(gi):
            continue
        # One search over the cells on either side without a sign change.
        a, ga, b, gb = pw[i], gi, pw[i], gi
        if has_prev and glo * gi > 0.0:
            a, ga = pw[(i - 1) % L] - (2.0 * np.pi if i == 0 else 0.0), glo
        if has_next and ghi * gi > 0.0:
            b, gb = pw[(i + 1) % L] + (2.0 * np.pi if i == L - 1 else 0.0), ghi
        if b > a:
            n = _pair(problem, a, ga, pw[i], b, gb, q, out, n)
    return n


@nb.njit(cache=True)
def _scan(problem, lo, hi, n_pts, full_circle, q, cands):
    """Candidate roots of g on [lo, hi] (the whole circle if ``full_circle``); returns the count.

    g and the model's reach margin are sampled at ``n_pts`` points. Each run of reachable
    samples, extended to the edges of reach (found by bisection), is searched by
    :func:`_run_roots`. Between unreachable samples whose reach margin could peak above
    zero, the margin is maximised to find small islands of reach, searched the same way.
    """
    h = (hi - lo) / (n_pts if full_circle else n_pts - 1)
    ws = np.empty(n_pts + 1)
    gs = np.empty(n_pts + 1)
    ms = np.empty(n_pts + 1)
    start = -1
    for k in range(n_pts):
        ws[k] = lo + h * k
        gs[k], ms[k] = _g_margin(problem, ws[k], q)
        if start < 0 and np.isnan(gs[k]):
            start = k
    n = 0
    if full_circle and start < 0:  # reachable everywhere: one cyclic run
        return _run_roots(problem, ws, gs, n_pts, True, q, cands, n)
    if full_circle:  # rotate to start and end at the same unreachable sample
        count = n_pts + 1
        order = np.array([(start + i) % n_pts for i in range(count)])
        ws, gs, ms = ws[order] + h * (np.arange(count) - order + start), gs[order], ms[order]
        ws[0] = lo + h * start
    else:
        count = n_pts
    pw = np.empty(count + 2)
    pg = np.empty(count + 2)
    L = 0
    for i in range(count):
        w = ws[i]
        if not np.isnan(gs[i]):
            if L == 0 and i > 0:  # entering reach
                pw[0] = _reach_edge(problem, w, ws[i - 1], q)
                pg[0] = _g(problem, pw[0], q)
                L = 1
            pw[L], pg[L] = w, gs[i]
            L += 1
            continue
        if L > 0:  # leaving reach
            pw[L] = _reach_edge(problem, pw[L - 1], w, q)
            pg[L] = _g(problem, pw[L], q)
            n = _run_roots(problem, pw, pg, L + 1, False, q, cands, n)
            L = 0
        if i + 1 < count and np.isnan(gs[i + 1]):
            # Both ends of this cell are out of reach. The margin can peak between them by
            # about half its change across a cell (estimated from this cell and its
            # neighbours); if that could reach zero, look for an island of reach.
            change = abs(ms[i + 1] - ms[i])
            if i > 0:
                change = max(change, abs(ms[i] - ms[i - 1]))
            if i + 2 < count:
                change = max(change, abs(ms[i + 2] - ms[i + 1]))
            if max(ms[i], ms[i + 1]) + change > 0.0:
                c, gc, _ = _extremum(problem, w, ws[i + 1], 0.5 * (w + ws[i + 1]), 1.0, True, q)
                if not np.isnan(gc):  # an island of reach around c
                    pw[0] = _reach_edge(problem, c, w, q)
                    pw[1], pg[1] = c, gc
                    pw[2] = _reach_edge(problem, c, ws[i + 1], q)
                    pg[0] = _g(problem, pw[0], q)
                    pg[2] = _g(problem, pw[2], q)
                    n = _run_roots(problem, pw, pg, 3, False, q, cands, n)
    if L > 0:  # a run that reaches the end of the window
        n = _run_roots(problem, pw, pg, L, False, q, cands, n)
    return n


@nb.njit(cache=True)
def all_roots(problem, n_scan, tol_pos, tol_ori, roots, lo=-np.pi, hi=np.pi):
    """Bounded search: every verified solution in this configuration. Returns the count.

    With ``lo, hi`` narrower than the circle, only roots with q_J in [lo, hi] are sought.
    """
    dof = roots.shape[1]
    q = np.empty(dof)
    if problem[4] < 0:
        g = _g(problem, 0.0, q)
        if not np.isnan(g) and verify(problem, q, tol_pos, tol_ori)[2]:
            roots[0] = q
            return 1
        return 0
    cands = np.empty(8 * n_scan + 8)
    full_circle = hi - lo >= 2.0 * np.pi
    n = _scan(problem, lo, lo + 2.0 * np.pi if full_circle else hi, n_scan, full_circle, q, cands)
    count = 0
    for i in range(n):
        g = _g(problem, cands[i], q)
        if not np.isnan(g) and abs(g) > _ROOT_TOL:  # polish the bracket's estimate
            _broyden(problem, cands[i], q)
        if not verify(problem, q, tol_pos, tol_ori)[2]:
            continue
        duplicate = False
        for r in range(count):
            diff = 0.0
            for j in range(dof):
                diff = max(diff, abs(wrap(q[j] - roots[r, j])))
            if diff < _SAME_ROOT:
                duplicate = True
        if not duplicate and count < roots.shape[0]:
            roots[count] = q
            count += 1
    return count


@nb.njit(cache=True)
def representative(q, revolute, lower, upper, hint, has_hint):
    """Shift revolute joints by multiples of 2 pi into the limits, nearest to the hint.

    Without a hint the shift nearest to zero is taken. Returns whether q is within limits.
    """
    inside = True
    for j in range(q.shape[0]):
        if not revolute[j]:
            inside = inside and lower[j] <= q[j] <= upper[j]
            continue
        target = hint[j] if has_hint else 0.0
        best = wrap(q[j] - target) + target
        found = lower[j] <= best <= upper[j]
        if not found:
            base = wrap(q[j])
            best_dist = np.inf
            for k in range(-3, 4):
                cand = base + 2.0 * np.pi * k
                if lower[j] <= cand <= upper[j] and abs(cand - target) < best_dist:
                    best, best_dist, found = cand, abs(cand - target), True
        q[j] = best
        inside = inside and found
    return inside


@nb.njit(cache=True)
def _exists_other(problem, n_scan, tol_pos, tol_ori):
    """Whether any configuration other than the problem's has a solution."""
    signs = problem[8]
    k = signs.shape[0]
    other = np.empty(k, dtype=np.int64)
    roots = np.empty((MAX_ROOTS, problem[10].shape[0]))
    for code in range(2**k):
        same = True
        for i in range(k):
            other[i] = 1 if (code >> i) & 1 else -1
            same = same and other[i] == signs[i]
        if same:
            continue
        if all_roots(_with_signs(problem, other), n_scan, tol_pos, tol_ori, roots):
            return True
    return False


@nb.njit(cache=True)
def _nearest_in_window(problem, hint, tol_pos, tol_ori, q):
    """Replace root q by any root nearer the hint.

    A root nearer the hint than q in joint space has |q_J - hint_J| below that distance, so
    scanning that window of the circle is enough.
    """
    d2 = 0.0
    for j in range(q.shape[0]):
        d2 += wrap(q[j] - hint[j]) ** 2
    radius = np.sqrt(d2)
    if radius < 1e-12:
        return
    roots = np.empty((MAX_ROOTS, q.shape[0]))
    J = problem[4]
    n = all_roots(problem, _WINDOW_POINTS, tol_pos, tol_ori, roots, hint[J] - radius, hint[J] + radius)
    for r in range(n):
        e2 = 0.0
        for j in range(q.shape[0]):
            e2 += wrap(roots[r, j] - hint[j]) ** 2
        if e2 < d2:
            d2 = e2
            q[:] = roots[r]


@nb.njit(cache=True)
def flange_target(T, base_inv, tool_inv):
    """The flange pose in DH frame 0 for an end-effector pose T in the root frame."""
    F = base_inv @ T @ tool_inv
    return np.ascontiguousarray(F[:3, :3]), np.ascontiguousarray(F[:3, 3])


@nb.njit(cache=True)
def solve_one(arm, settings, T, signs, redundancy, hint, has_hint, q_out):
    """One OM solve: local Broyden, then the bounded search.

    Args:
        arm: (family, P, model table, real table, J, D, base^-1, tool^-1, revolute, lower,
            upper), fixed per solver.
        settings: (scan points, position tolerance, orientation tolerance).

    Returns (status, position error, orientation error, evaluations, within limits).
    """
    family, P, mtab, rtab, J, D, base_inv, tool_inv, revolute, lower, upper = arm
    n_scan, tol_pos, tol_ori = settings
    R, p = flange_target(T, base_inv, tool_inv)
    dof = q_out.shape[0]
    q_prev = hint if has_hint else np.zeros(dof)
    problem = make_problem(family, P, mtab, rtab, J, D, R, p, signs, redundancy, q_prev)
    counter = problem[11]
    q = np.empty(dof)
    if has_hint:
        w0 = hint[J] if J >= 0 else 0.0
    else:  # the paper's fixed-point start, p_m = p_d
        reach = model_ik(family, P, mtab, R, p, signs, redundancy, q_prev, q) >= -REACH_SLACK
        w0 = q[J] if (reach and J >= 0) else np.nan
        if not reach and J >= 0:
            # p_d is outside the model's reach: start from the point of the dp circle
            # that the model reaches with the smallest residual.
            best = np.inf
            for k in range(_START_POINTS):
                w = -np.pi + 2.0 * np.pi * k / _START_POINTS
                g = _g(problem, w, q)
                if abs(g) < best:  # False for NaN
                    best, w0 = abs(g), w
    if not np.isnan(w0):
        _broyden(problem, w0, q)
        if verify(problem, q, tol_pos, tol_ori)[2]:
            if has_hint and J >= 0:
                _nearest_in_window(problem, hint, tol_pos, tol_ori, q)
            q_out[:] = q
            inside = representative(q_out, revolute, lower, upper, hint, has_hint)
            if inside or has_hint or J < 0:
                pos, ori, _ = verify(problem, q_out, tol_pos, tol_ori)
                return OK, pos, ori, counter[0], inside
            # Without a hint, a root within the limits is preferred: search for one.
    roots = np.empty((MAX_ROOTS, dof))
    n = all_roots(problem, n_scan, tol_pos, tol_ori, roots)
    if n == 0:
        q_out[:] = np.nan
        if _exists_other(problem, n_scan, tol_pos, tol_ori):
            return NO_SOLUTION_IN_CONFIGURATION, np.nan, np.nan, counter[0], False
        return UNREACHABLE, np.nan, np.nan, counter[0], False
    # The root nearest the hint; without one, a root within the limits first, then the one
    # nearest the fixed-point start's joint J.
    best, best_dist = 0, np.inf
    for r in range(n):
        dist = 0.0
        if has_hint:
            for j in range(dof):
                dist += wrap(roots[r, j] - hint[j]) ** 2
        else:
            if J >= 0 and not np.isnan(w0):
                dist = abs(wrap(roots[r, J] - w0))
            shifted = roots[r].copy()
            if not representative(shifted, revolute, lower, upper, hint, False):
                dist += 4.0 * np.pi
        if dist < best_dist:
            best, best_dist = r, dist
    q_out[:] = roots[best]
    inside = representative(q_out, revolute, lower, upper, hint, has_hint)
    pos, ori, _ = verify(problem, q_out, tol_pos, tol_ori)
    return OK, pos, ori, counter[0], inside


@nb.njit(cache=True)
def solve_all_kernel(arm, settings, T, signs, redundancy, roots, pos, ori, within):
    """Every solution in one configuration: the bounded search, in one call from Python.

    Writes the roots (revolute joints shifted into the limits where possible) and their
    errors and limit checks. Returns (count, residual evaluations).
    """
    family, P, mtab, rtab, J, D, base_inv, tool_inv, revolute, lower, upper = arm
    n_scan, tol_pos, tol_ori = settings
    R, p = flange_target(T, base_inv, tool_inv)
    zeros = np.zeros(roots.shape[1])
    problem = make_problem(family, P, mtab, rtab, J, D, R, p, signs, redundancy, zeros)
    n = all_roots(problem, n_scan, tol_pos, tol_ori, roots)
    for r in range(n):
        within[r] = representative(roots[r], revolute, lower, upper, zeros, False)
        pos[r], ori[r], _ = verify(problem, roots[r], tol_pos, tol_ori)
    return n, problem[11][0]


@nb.njit(cache=True, parallel=True)
def solve_batch_kernel(
    arm, settings, Ts, signs, redundancy, hints, has_hint, q_out, status, pos, ori, evals, within
):
    for m in nb.prange(Ts.shape[0]):
        st, e_pos, e_ori, ev, inside = solve_one(
            arm, settings, Ts[m], signs[m], redundancy[m], hints[m], has_hint, q_out[m]
        )
        status[m], pos[m], ori[m], evals[m], within[m] = st, e_pos, e_ori, ev, inside
