r"""The OM system (9) and its solvers, as numba kernels.

System (9) asks for the model's hand position :math:`p_m` with

.. math::  p_m = p_d + \Delta p\big(\mathrm{IK}_{model}(R_d, p_m, c)\big).

Every solution has the form :math:`p_m = p_d + R_d\,\delta(w)`, where :math:`\delta` is dp
seen from the flange and depends on one wrist joint, :math:`w = q_J` (see
:mod:`om_redundant.om.model`). So the three equations reduce exactly to one on the circle,

.. math::  g(w) = \mathrm{wrap}\big(\mathrm{IK}_{model}(R_d, p_d + R_d\,\delta(w), c)_J - w\big) = 0,

and a root gives the real arm's joints :math:`q = \mathrm{IK}_{model}(\ldots)` with
:math:`|p_{real}(q) - p_d| = |\delta(w) - \delta(q_J)| \le \Delta p_{max}\,|g(w)|`.

Arms with shoulder offsets (Gen3, Sawyer) add :math:`a(q_1)`, so solutions lie on a torus
:math:`(w_1, w_7) = (q_1, q_7)`: :math:`p_m = p_d + a(w_1) + R_d\,\delta(w_7)`. There the
system is lifted to three unknowns :math:`(w_1, w_7, \varphi_4)` and three residuals that
are smooth everywhere (:func:`~om_redundant.om.families.srs.model_ik_lifted`): the model IK
with q1, q7 and the elbow angle given is consistent with the shoulder, the wrist and the
elbow equation. In (w1, w7) alone the residual has a square-root branch point at the edge of
reach (the straight or folded elbow) and steep Euler angles at the shoulder and wrist
singularities, which is where roots crowd; lifted, Newton's method converges there.

* Local solve: Broyden's method, which in one unknown is the secant method, started with a
  finite-difference slope, from the joint of the paper's fixed-point start
  (:math:`p_m = p_d`) or of a hint; on the torus, damped Newton on the lifted system. On a
  7-DOF circle arm, where the secant fails (g's square root at the edge of reach sends it
  out of reach) or p_d is beyond the model's reach (the start then holds the elbow at the
  edge), the same lifted Newton, with zero shoulder offsets, takes over.
* Bounded search, the paper's guarantee: g is sampled on a grid over the whole circle (the
  image of the ball :math:`|p_m - p_d| \le \Delta p_{max}` that can hold solutions); each sign
  change is refined; near the edges of the model's reach, at local minima of |g| and on
  small islands of reach, where roots come in close pairs, 1-D extremum searches find
  them. On the torus, a grid of the lifted residual seeds Newton's method, with deflation
  and a search along each root's fold direction for close pairs (:func:`_torus_roots`);
  this is a thorough search rather than a proof. Every candidate is verified with the REAL
  arm's forward kinematics.

All kernels work in DH frame 0 with the flange pose. One target's problem travels as one
tuple, see :func:`make_problem`; its last entry counts the residual evaluations.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from ..kinematics.kernels import flange_kernel
from .families import REACH_SLACK, branch_values, model_ik, redundancy_values, srs, wrap
from .families.common import add, cross, dot, mtm, scale, unit

OK = 0
UNREACHABLE = 1
NO_SOLUTION_IN_CONFIGURATION = 2
STATUS_NAMES = ("ok", "unreachable", "no solution in this configuration")

MAX_ROOTS = 16
_ROOT_TOL = 1e-13  # |g| accepted as a root before verification
_SAME_ROOT = 1e-9  # joint-space distance under which two roots are one
_START_POINTS = 8  # starts on the dp circle when p_d is out of reach or a first root out of limits
_WINDOW_POINTS = 8  # samples of the window searched around a hint
_LAST_STEP = 1e-5  # a secant step (rad) below which the next iterate is evaluated with every joint
_PAIR_SEARCH = 1.0  # |g| (rad) below which a local minimum is searched for a root pair
_REDUNDANCY_TOL = 1e-9  # a solution's redundancy values (rad) must equal the requested ones
_TORUS_SIDE = 0.75  # the torus grid has _TORUS_SIDE * scan points nodes per side
_MAX_KNOWN = 64  # roots of the lifted torus system kept for deflation
_MIN_STEP = 1.0 / 256.0  # the shortest damped Newton step on the torus, as a fraction of the full one
_STALL = 3  # slow damped Newton steps in a row after which a run on the torus gives up
_NEAR_ROOT = 0.1  # on the whole torus, every node with a lifted residual below this starts Newton
_PARTNER_CELLS = 2.0  # a root's fold partner is sought this many grid cells away at most
_PARTNER_SAMPLES = 8  # samples each way along the fold direction


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
def _g_margin(problem, w, q, all_joints=False):
    """Residual g(w) (NaN if unreachable) and the model's reach margin; writes the IK into q.

    The searches need only q_J; where q itself is wanted, ``all_joints`` makes the model
    write every joint (a 7-DOF model skips its shoulder otherwise).
    """
    J, p = problem[4], problem[7]
    margin = _ik_plus_delta(problem, p, w, q, all_joints or J < 0)
    if margin < -REACH_SLACK:
        return np.nan, margin
    if J < 0:
        return 0.0, margin
    return wrap(q[J] - w), margin


@nb.njit(cache=True, inline="always")
def _ik_plus_delta(problem, base, w, q, all_joints):
    """Model IK for p_m = base + R delta(w) (one residual evaluation); returns the reach margin."""
    family, P, mtab, _, _, D, R, _, signs, redundancy, q_prev, counter = problem
    counter[0] += 1
    d = _delta(D, w)
    pm = (  # a tuple: no heap allocation in the innermost loop
        base[0] + R[0, 0] * d[0] + R[0, 1] * d[1] + R[0, 2] * d[2],
        base[1] + R[1, 0] * d[0] + R[1, 1] * d[1] + R[1, 2] * d[2],
        base[2] + R[2, 0] * d[0] + R[2, 1] * d[1] + R[2, 2] * d[2],
    )
    return model_ik(family, P, mtab, R, pm, signs, redundancy, q_prev, q, all_joints)


@nb.njit(cache=True, inline="always")
def _torus_target(problem, w1, w7):
    """p_m = p_d + a(w1) + R delta(w7); counts one residual evaluation."""
    D, R, p, counter = problem[5], problem[6], problem[7], problem[11]
    counter[0] += 1
    c1, s1 = np.cos(w1), np.sin(w1)
    d = _delta(D, w7)
    pm = np.empty(3)
    for k in range(3):
        pm[k] = (
            p[k] + D[3, k] + D[4, k] * c1 + D[5, k] * s1 + R[k, 0] * d[0] + R[k, 1] * d[1] + R[k, 2] * d[2]
        )
    return pm


@nb.njit(cache=True, inline="always")
def _lifted_residual(problem, x, q):
    """The lifted residual (shoulder, wrist, elbow) at x = (w1, w7, phi4) for
    p_m = p_d + a(w1) + R delta(w7) (see srs.model_ik_lifted); writes the model IK into q."""
    _, P, _, _, _, _, R, _, signs, redundancy, _, _ = problem
    pm = _torus_target(problem, x[0], x[1])
    return srs.model_ik_lifted(P, R, pm, signs, redundancy[0], x[0], x[1], x[2], q)


@nb.njit(cache=True, inline="always")
def _deflated_residual(problem, x, q, known, n_known):
    """The lifted residual times prod_k (1 + 1 / |x - x_k|^2) over the roots x_k already
    known (deflation: Newton's method is then repelled from them, to find another)."""
    F = _lifted_residual(problem, x, q)
    factor = 1.0
    for k in range(n_known):
        d2 = 0.0
        for i in range(3):
            d2 += wrap(x[i] - known[k, i]) ** 2
        factor *= 1.0 + 1.0 / max(d2, 1e-300)
    return scale(factor, F)


@nb.njit(cache=True)
def _newton_torus(problem, x, q, known, n_known):
    """Damped Newton's method on the lifted system from x = (w1, w7, phi4), with a
    forward-difference Jacobian, deflated by the first n_known rows of known.

    Each step is halved until the residual's max norm decreases, so that it stops, rather
    than jumps, where the Jacobian is singular; it also stops after ``_STALL`` steps in a row
    that shrink the norm by less than a tenth (a local minimum of the norm that is no root).
    Returns the max norm of the (undeflated) residual at the end, inf if not finite, and the
    end point; q holds the model IK there.
    """
    F = _deflated_residual(problem, x, q, known, n_known)
    r = _norm(F)
    eps = 1e-7
    slow = 0
    for _ in range(30):
        if not r < np.inf or r < 1e-15 or slow == _STALL:
            break
        # Rows of the Jacobian, then the step -J^-1 F by cofactors.
        F0 = _deflated_residual(problem, (x[0] + eps, x[1], x[2]), q, known, n_known)
        F1 = _deflated_residual(problem, (x[0], x[1] + eps, x[2]), q, known, n_known)
        F2 = _deflated_residual(problem, (x[0], x[1], x[2] + eps), q, known, n_known)
        rows = [((F0[i] - F[i]) / eps, (F1[i] - F[i]) / eps, (F2[i] - F[i]) / eps) for i in range(3)]
        c0, c1, c2 = cross(rows[1], rows[2]), cross(rows[2], rows[0]), cross(rows[0], rows[1])
        det = dot(rows[0], c0)
        if not abs(det) > 0.0:  # also NaN
            break
        step = scale(-1.0 / det, add(add(scale(F[0], c0), scale(F[1], c1)), scale(F[2], c2)))
        size = max(abs(step[0]), abs(step[1]), abs(step[2]))
        t = 1.0 if size < 0.5 else 0.5 / size
        while t > _MIN_STEP:
            Fn = _deflated_residual(problem, add(x, scale(t, step)), q, known, n_known)
            if _norm(Fn) < r:  # False for NaN
                break
            t *= 0.5
        if t <= _MIN_STEP:
            break
        x = add(x, scale(t, step))
        F = Fn
        slow = slow + 1 if _norm(F) > 0.9 * r else 0
        r = _norm(F)
    # q must belong to the final iterate.
    r = _norm(_lifted_residual(problem, x, q))
    return (r if r < np.inf else np.inf), x


@nb.njit(cache=True, inline="always")
def _norm(F):
    return max(abs(F[0]), abs(F[1]), abs(F[2]))


@nb.njit(cache=True, inline="always")
def _g(problem, w, q, all_joints=False):
    """Residual g(w) of the reduced system; writes the model IK into q (see :func:`_g_margin`).
    NaN if unreachable."""
    return _g_margin(problem, w, q, all_joints)[0]


@nb.njit(cache=True)
def _broyden(problem, w0, q):
    """Secant (1-D Broyden) iteration from w0 with a finite-difference slope.

    Returns |g| at the end; q holds the model IK (every joint) at the last iterate. The
    iterates need only q_J; once a step is below ``_LAST_STEP``, the next iterate is
    usually the last (the secant converges superlinearly), so it is evaluated with every
    joint, which spares a final evaluation.
    """
    g0 = _g(problem, w0, q)
    if problem[4] < 0 or np.isnan(g0):
        return abs(g0)
    h = 1e-7
    g1 = _g(problem, w0 + h, q)
    slope = (g1 - g0) / h if not np.isnan(g1) else -1.0
    w, g = w0, g0
    complete = False  # whether q holds every joint at w
    for _ in range(40):
        if g == 0.0 or slope == 0.0 or np.isnan(slope):
            break
        step = -g / slope
        if abs(step) > 0.5:
            step = 0.5 * np.sign(step)
        last = abs(step) < _LAST_STEP
        g_new = _g(problem, w + step, q, last)
        if np.isnan(g_new):
            complete = False
            break
        slope = (g_new - g) / step
        w, g, complete = w + step, g_new, last
        if abs(step) < 1e-15 * max(1.0, abs(w)) or abs(g) < 1e-16:
            break
    if not complete:
        g = _g(problem, w, q, True)
    return abs(g)


@nb.njit(cache=True)
def _refine_bracket(problem, a, ga, b, gb, q):
    """Illinois regula falsi on a sign-changing bracket; returns the root estimate.

    Both ends are reachable, but a gap of reach can hide between them (the model's elbow
    straightens and bends back within a sample spacing). If the iterate falls into one, the
    bracket shrinks to the side of the gap whose edge keeps the sign change.
    """
    side = 0
    for _ in range(100):
        c = (a * gb - b * ga) / (gb - ga)
        gc = _g(problem, c, q)
        if np.isnan(gc):
            e = _reach_edge(problem, a, c, q)
            ge = _g(problem, e, q)
            if ge * ga <= 0.0:
                b, gb = e, ge
            else:
                e = _reach_edge(problem, b, c, q)
                ge = _g(problem, e, q)
                if ge * gb > 0.0:  # no sign change on either side: none to refine
                    return c
                a, ga = e, ge
            side = 0
            continue
        if gc == 0.0 or abs(b - a) < 1e-15:
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
    values = np.empty(max(signs.shape[0], redundancy.shape[0]))
    branch_values(family, P, q, values)
    same = True
    for i in range(signs.shape[0]):
        # A branch quantity at zero (a singular joint) belongs to both branches.
        if values[i] * signs[i] < -1e-12:
            same = False
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
def _add_root(problem, q, tol_pos, tol_ori, roots, count):
    """Append q to roots if the real arm verifies it and it is new; returns the count."""
    if not verify(problem, q, tol_pos, tol_ori)[2]:
        return count
    for r in range(count):
        diff = 0.0
        for j in range(q.shape[0]):
            diff = max(diff, abs(wrap(q[j] - roots[r, j])))
        if diff < _SAME_ROOT:
            return count
    if count < roots.shape[0]:
        roots[count] = q
        count += 1
    return count


@nb.njit(cache=True)
def _crosses(A, i, j):
    """Whether A changes sign over the grid cell (i, j) (four reachable corners, no wrap)."""
    lo, hi = np.inf, -np.inf
    for a in (A[i, j], A[i + 1, j], A[i, j + 1], A[i + 1, j + 1]):
        if np.isnan(a):
            return False
        lo, hi = min(lo, a), max(hi, a)
    return lo <= 0.0 <= hi and hi - lo < np.pi


@nb.njit(cache=True)
def _torus_roots(problem, n, tol_pos, tol_ori, roots, centre, radius):
    """Bounded search on the torus (w1, w7) of an arm with shoulder offsets; returns the count.

    The lifted residual, with phi4 from the elbow equation (so its third entry is zero in
    reach and the reach deficit beyond), is sampled on an n x n grid (over the square of
    half-width ``radius`` around the centre's (q_1, q_7) when radius < pi). Its max norm is
    continuous. Newton's method starts from every node where the norm is a local minimum
    below ``_PAIR_SEARCH`` or (on the whole torus) below ``_NEAR_ROOT``, and from every cell
    where both the shoulder and the wrist residual change sign. Each new root is followed by
    more runs from the same start, deflated by the roots found so far, until they find no new
    one, and by runs from its fold partners (:func:`_fold_partners`): close pairs of roots
    are not missed.
    """
    q = np.empty(roots.shape[1])
    whole = radius >= np.pi
    if whole:
        lo1, lo7, span = -np.pi, -np.pi, 2.0 * np.pi
    else:
        lo1, lo7, span = centre[0] - radius, centre[6] - radius, 2.0 * radius
    step = span / n
    m = n + 1  # on the whole torus the last row and column repeat the first
    S, W, F, E = np.empty((m, m)), np.empty((m, m)), np.empty((m, m)), np.empty((m, m))
    for i in range(m):
        for j in range(m):
            r = _lifted_residual(problem, (lo1 + i * step, lo7 + j * step, np.nan), q)
            S[i, j], W[i, j], E[i, j] = r[0], r[1], q[3] + problem[1][srs.THETA + 3]
            F[i, j] = _norm(r) if _norm(r) < np.inf else np.inf
    count = 0
    known = np.empty((_MAX_KNOWN, 3))
    n_known = 0
    partners = [(0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)]
    phi_star = problem[1][srs.PHI_STAR]
    for i in range(m):
        for j in range(m):
            for centre_of_cell in (False, True):
                if centre_of_cell:
                    start = i < n and j < n and _crosses(S, i, j) and _crosses(W, i, j)
                    x = (lo1 + (i + 0.5) * step, lo7 + (j + 0.5) * step, E[i, j])
                else:
                    start = F[i, j] < _PAIR_SEARCH
                    for ii in range(max(i - 1, 0), min(i + 2, m)):
                        for jj in range(max(j - 1, 0), min(j + 2, m)):
                            start = start and F[ii, jj] >= F[i, j]
                    start = start or (whole and F[i, j] < _NEAR_ROOT)
                    x = (lo1 + i * step, lo7 + j * step, E[i, j])
                if not start or n_known == _MAX_KNOWN:
                    continue
                first = n_known
                n_known = _new_root(problem, x, False, known, n_known, q)
                if n_known == first:
                    # Near the edge of reach the elbow angle changes fastest: try once more
                    # from the nearer edge's (the straight or the folded elbow).
                    edge = phi_star if np.cos(x[2] - phi_star) > 0.0 else phi_star + np.pi
                    n_known = _new_root(problem, (x[0], x[1], edge), False, known, n_known, q)
                if n_known == first:
                    continue
                count = _add_root(problem, q, tol_pos, tol_ori, roots, count)
                while n_known < _MAX_KNOWN:  # deflated, from the same start
                    found = n_known
                    n_known = _new_root(problem, x, True, known, n_known, q)
                    if n_known == found:
                        break
                    count = _add_root(problem, q, tol_pos, tol_ori, roots, count)
                k = first
                while k < n_known < _MAX_KNOWN:
                    root = (known[k, 0], known[k, 1], known[k, 2])
                    k += 1
                    for a in range(_fold_partners(problem, root, _PARTNER_CELLS * step, q, partners)):
                        found = n_known
                        n_known = _new_root(problem, partners[a], True, known, n_known, q)
                        if n_known == found:  # the line bends away from the partner: halfway
                            halfway = scale(0.5, add(partners[a], root))
                            n_known = _new_root(problem, halfway, True, known, n_known, q)
                        if n_known > found:
                            count = _add_root(problem, q, tol_pos, tol_ori, roots, count)
    return count


@nb.njit(cache=True)
def _new_root(problem, x, deflate, known, n_known, q):
    """Newton's method from x, deflated by the known roots if ``deflate``; a new root is
    appended to known, with its model IK in q. Returns the number of known roots."""
    r, x_root = _newton_torus(problem, x, q, known, n_known if deflate else 0)
    if r > _ROOT_TOL:
        return n_known
    for k in range(n_known):
        if (
            max(
                abs(wrap(x_root[0] - known[k, 0])),
                abs(wrap(x_root[1] - known[k, 1])),
                abs(wrap(x_root[2] - known[k, 2])),
            )
            < _SAME_ROOT
        ):
            return n_known
    known[n_known] = x_root
    return n_known + 1


@nb.njit(cache=True)
def _fold_partners(problem, x, reach, q, starts):
    r"""Starts for the partners of the root x, if x is one of a close pair; returns the count.

    Two roots close together straddle a fold, where the Jacobian J is singular. With u, v
    J's near-null left and right vectors, the residual along the line x + t v is nearly
    :math:`u \cdot F`, which vanishes at t = 0 with slope :math:`u \cdot J v` and, at a
    partner, again. A partner nearer than the samples (a near-double root) is the second
    zero of the quadratic fit :math:`u \cdot F \approx (u \cdot J v)\, t + c\, t^2`; further
    out, :math:`u \cdot F` is sampled at ``_PARTNER_SAMPLES`` points each way up to
    ``reach``, and the first sign change each way is a start.
    """
    eps = 1e-7
    F = _lifted_residual(problem, x, q)
    F0 = _lifted_residual(problem, (x[0] + eps, x[1], x[2]), q)
    F1 = _lifted_residual(problem, (x[0], x[1] + eps, x[2]), q)
    F2 = _lifted_residual(problem, (x[0], x[1], x[2] + eps), q)
    cols = (
        scale(1.0 / eps, (F0[0] - F[0], F0[1] - F[1], F0[2] - F[2])),
        scale(1.0 / eps, (F1[0] - F[0], F1[1] - F[1], F1[2] - F[2])),
        scale(1.0 / eps, (F2[0] - F[0], F2[1] - F[1], F2[2] - F[2])),
    )
    rows = (
        (cols[0][0], cols[1][0], cols[2][0]),
        (cols[0][1], cols[1][1], cols[2][1]),
        (cols[0][2], cols[1][2], cols[2][2]),
    )
    v, u = _null_vector(rows), _null_vector(cols)
    slope = dot(u, add(add(scale(v[0], cols[0]), scale(v[1], cols[1])), scale(v[2], cols[2])))
    n = 0
    h = reach / _PARTNER_SAMPLES
    # A partner closer than the samples (a near-double root): the second zero of the
    # quadratic u.F = slope t + c t^2, c from one more point.
    d = 1e-4
    c = (dot(u, _lifted_residual(problem, add(x, scale(d, v)), q)) - dot(u, F) - slope * d) / (d * d)
    t = -slope / c
    if abs(t) < h:  # also not NaN
        starts[n] = add(x, scale(t, v))
        n += 1
    for direction in (-1.0, 1.0):
        t_prev, f_prev = 0.0, 0.0
        for k in range(1, _PARTNER_SAMPLES + 1):
            t = direction * k * h
            f = dot(u, _lifted_residual(problem, add(x, scale(t, v)), q))
            if np.isnan(f):
                break
            if f * slope * direction < 0.0:  # u.F has come back through zero
                if k > 1:
                    t = t_prev + (t - t_prev) * f_prev / (f_prev - f)
                starts[n] = add(x, scale(t, v))
                n += 1
                break
            t_prev, f_prev = t, f
    return n


@nb.njit(cache=True, inline="always")
def _null_vector(rows):
    """Unit vector nearest the null space of a nearly singular 3x3 matrix (given by rows):
    the longest cross product of two rows."""
    best = cross(rows[0], rows[1])
    for c in (cross(rows[1], rows[2]), cross(rows[2], rows[0])):
        if dot(c, c) > dot(best, best):
            best = c
    return unit(best)


@nb.njit(cache=True)
def all_roots(problem, n_scan, tol_pos, tol_ori, roots, centre, radius):
    """Bounded search: every verified solution in this configuration. Returns the count.

    With ``radius < pi``, only roots whose scanned joints (q_J, or q_1 and q_7 on the torus)
    lie within ``radius`` of the centre's are sought.
    """
    dof = roots.shape[1]
    q = np.empty(dof)
    J = problem[4]
    if J < 0:
        g = _g(problem, 0.0, q, True)
        return 0 if np.isnan(g) else _add_root(problem, q, tol_pos, tol_ori, roots, 0)
    if problem[5].shape[0] == 6:
        return _torus_roots(
            problem, max(int(_TORUS_SIDE * n_scan), 4), tol_pos, tol_ori, roots, centre, radius
        )
    cands = np.empty(8 * n_scan + 8)
    full_circle = radius >= np.pi
    lo, hi = (-np.pi, np.pi) if full_circle else (centre[J] - radius, centre[J] + radius)
    n = _scan(problem, lo, hi, n_scan, full_circle, q, cands)
    count = 0
    for i in range(n):
        g = _g(problem, cands[i], q, True)
        if not np.isnan(g) and abs(g) > _ROOT_TOL:  # polish the bracket's estimate
            _broyden(problem, cands[i], q)
        count = _add_root(problem, q, tol_pos, tol_ori, roots, count)
    return count


@nb.njit(cache=True)
def _local_solve(problem, start, tol_pos, tol_ori, q):
    """Local solve from the joint vector start, verified with the real arm: the secant on g
    from its q_J; on the torus, and on a 7-DOF circle arm where the secant fails,
    :func:`_lifted_solve`. Returns :func:`verify`'s (position error, orientation error,
    accepted); q holds the model IK at the end."""
    family, J, D = problem[0], problem[4], problem[5]
    if D.shape[0] == 6:
        _lifted_solve(problem, start, q)
        return verify(problem, q, tol_pos, tol_ori)
    _broyden(problem, start[J] if J >= 0 else 0.0, q)
    result = verify(problem, q, tol_pos, tol_ori)
    if not result[2] and family == srs.SRS and J >= 0:
        _lifted_solve(problem, start, q)
        result = verify(problem, q, tol_pos, tol_ori)
    return result


@nb.njit(cache=True)
def _lifted_solve(problem, start, q):
    """Damped Newton on the lifted system in (q1, q7, phi4) from the joint vector start.

    A 7-DOF arm whose dp turns with q7 alone is lifted with zero shoulder offsets: g has a
    square root at the edge of the model's reach, which sends the secant out of reach near
    it, while the lifted system is smooth there. Returns the final residual; q holds the
    model IK there.
    """
    if problem[5].shape[0] == 3:
        family, P, mtab, rtab, J, D, R, p, signs, redundancy, q_prev, counter = problem
        D_torus = np.zeros((6, 3))
        D_torus[:3] = D
        problem = (family, P, mtab, rtab, J, D_torus, R, p, signs, redundancy, q_prev, counter)
    x = (start[0], start[6], start[3] + problem[1][srs.THETA + 3])
    return _newton_torus(problem, x, q, np.empty((0, 3)), 0)[0]


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
        if all_roots(_with_signs(problem, other), n_scan, tol_pos, tol_ori, roots, signs, np.inf):
            return True
    return False


@nb.njit(cache=True, inline="always")
def _shifted(a, b):
    """Whether joint vectors a and b differ (by the 2 pi shifts of :func:`representative`)."""
    for j in range(a.shape[0]):  # noqa: SIM110 (numba compiles no generator into any())
        if a[j] != b[j]:
            return True
    return False


@nb.njit(cache=True)
def _nearest_in_window(problem, hint, tol_pos, tol_ori, q):
    """Replace root q by any root nearer the hint; returns whether one was.

    A root nearer the hint than q in joint space has |q_J - hint_J| below that distance, so
    scanning that window of the circle (or square of the torus) is enough.
    """
    d2 = 0.0
    for j in range(q.shape[0]):
        d2 += wrap(q[j] - hint[j]) ** 2
    radius = np.sqrt(d2)
    if radius < 1e-12:
        return False
    roots = np.empty((MAX_ROOTS, q.shape[0]))
    n = all_roots(problem, _WINDOW_POINTS, tol_pos, tol_ori, roots, hint, radius)
    replaced = False
    for r in range(n):
        e2 = 0.0
        for j in range(q.shape[0]):
            e2 += wrap(roots[r, j] - hint[j]) ** 2
        if e2 < d2:
            d2, replaced = e2, True
            q[:] = roots[r]
    return replaced


@nb.njit(cache=True)
def flange_target(T, base_inv, tool_inv):
    """The flange pose in DH frame 0 for an end-effector pose T in the root frame.

    Written out: for 4x4 matrices a loop beats the BLAS call that ``@`` makes.
    """
    F = np.empty((3, 4))  # rows 0-2 of base_inv @ T (row 3 is [0, 0, 0, 1])
    for i in range(3):
        for j in range(4):
            F[i, j] = (
                base_inv[i, 0] * T[0, j] + base_inv[i, 1] * T[1, j] + base_inv[i, 2] * T[2, j]
            ) + base_inv[i, 3] * T[3, j]
    R, p = np.empty((3, 3)), np.empty(3)
    for i in range(3):
        for j in range(3):
            R[i, j] = F[i, 0] * tool_inv[0, j] + F[i, 1] * tool_inv[1, j] + F[i, 2] * tool_inv[2, j]
        p[i] = F[i, 0] * tool_inv[0, 3] + F[i, 1] * tool_inv[1, 3] + F[i, 2] * tool_inv[2, 3] + F[i, 3]
    return R, p


@nb.njit(cache=True)
def solve_one(arm, settings, T, signs, redundancy, hint, has_hint, q_out):
    """One OM solve: the local solve (secant, or lifted Newton), then the bounded search.

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
    start = hint.copy()
    found = has_hint
    if not has_hint:  # the paper's fixed-point start, p_m = p_d
        found = model_ik(family, P, mtab, R, p, signs, redundancy, q_prev, start) >= -REACH_SLACK
        if not found and family == srs.SRS and J >= 0:
            # p_d is outside the model's reach: the elbow held at the edge of reach instead,
            # a start for the lifted Newton (see _local_solve).
            found = srs.model_ik_at_reach(P, R, p, signs, redundancy[0], q_prev, start)
        elif not found and J >= 0 and D.shape[0] == 3:
            # p_d is outside the model's reach: start from the point of the dp circle
            # that the model reaches with the smallest residual.
            best = np.inf
            for k in range(_START_POINTS):
                g = _g(problem, -np.pi + 2.0 * np.pi * k / _START_POINTS, q, True)
                if abs(g) < best:  # False for NaN
                    best, found = abs(g), True
                    start[:] = q
    if found:
        pos, ori, verified = _local_solve(problem, start, tol_pos, tol_ori, q)
        if verified:
            if has_hint and J >= 0 and _nearest_in_window(problem, hint, tol_pos, tol_ori, q):
                pos, ori, _ = verify(problem, q, tol_pos, tol_ori)
            q_out[:] = q
            inside = representative(q_out, revolute, lower, upper, hint, has_hint)
            if inside or has_hint or J < 0:
                if _shifted(q_out, q):  # the errors of the vector returned, to its rounding
                    pos, ori, _ = verify(problem, q_out, tol_pos, tol_ori)
                return OK, pos, ori, counter[0], inside
            # Without a hint, a root within the limits is preferred: search for one.
    if not has_hint and J >= 0 and D.shape[0] == 3:
        # Other starts on the circle first: cheaper than the bounded search, and a root
        # within the limits is usually among their roots.
        for k in range(_START_POINTS):
            _broyden(problem, -np.pi + 2.0 * np.pi * (k + 0.5) / _START_POINTS, q)
            pos, ori, verified = verify(problem, q, tol_pos, tol_ori)
            if verified:
                q_out[:] = q
                if representative(q_out, revolute, lower, upper, hint, False):
                    if _shifted(q_out, q):
                        pos, ori, _ = verify(problem, q_out, tol_pos, tol_ori)
                    return OK, pos, ori, counter[0], True
    roots = np.empty((MAX_ROOTS, dof))
    n = all_roots(problem, n_scan, tol_pos, tol_ori, roots, hint, np.inf)
    if n == 0:
        q_out[:] = np.nan
        if _exists_other(problem, n_scan, tol_pos, tol_ori):
            return NO_SOLUTION_IN_CONFIGURATION, np.nan, np.nan, counter[0], False
        return UNREACHABLE, np.nan, np.nan, counter[0], False
    # The root nearest the hint; without one, a root within the limits first, then the one
    # nearest the fixed-point start.
    best, best_dist = 0, np.inf
    for r in range(n):
        dist = 0.0
        if found:
            for j in range(dof):
                dist += wrap(roots[r, j] - start[j]) ** 2
        if not has_hint:
            shifted = roots[r].copy()
            if not representative(shifted, revolute, lower, upper, hint, False):
                dist += dof * (2.0 * np.pi) ** 2  # after every root within the limits
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
    n = all_roots(problem, n_scan, tol_pos, tol_ori, roots, zeros, np.inf)
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
