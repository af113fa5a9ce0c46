/* The bounded search on the circle: every root of g(w), the paper's guarantee
 * (the method: om_redundant/om/system.py). */
#include "om_system.h"

#define CELL_SAFETY 4.0  /* the curvature of g taken as this multiple of its sampled second differences */
#define CELL_HALVINGS 6  /* halvings of a scan cell that may hide roots: 16 points as fine as 1024 */

/* out[n] = v if there is room; returns the new count (the candidates' capacity is a bound, checked). */
static int _put(double *out, int n, int cap, double v)
{
    if (n >= cap)
        return n;
    out[n] = v;
    return n + 1;
}

/* Add the root of g on [a, b] (both ends reachable) to out[n:]; returns the new count.
 * A sign change is one root; a wrap of g from about +pi to -pi is none. */
static int _bracket(om_problem *pb, double a, double ga, double b, double gb, double *q, double *out, int n,
                    int cap)
{
    if (ga == 0.0)
        return _put(out, n, cap, a);
    /* A jump of more than pi is a wrap of g or a steep crossing of zero near a singular
     * wrist: bisect until it is clearly one or the other. */
    int it = 0;
    for (; it < 60; it++) {
        if (fabs(ga - gb) <= OM_PI || fabs(ga - gb) > 1.9 * OM_PI)
            break;
        double c = 0.5 * (a + b);
        double gc = om_g(pb, c, q, false);
        if (isnan(gc))
            return n;
        if (gc * ga > 0.0) {
            a = c;
            ga = gc;
        } else {
            b = c;
            gb = gc;
        }
    }
    if (gb == 0.0)
        return _put(out, n, cap, b);
    /* Bisected to the last bit and still a jump short of a wrap's 2 pi: g crosses zero
     * there, too steeply for floating point (the wrist within about 1e-9 of its
     * singularity, where q_J swings by pi). The candidate goes to the lifted Newton, which
     * is smooth there (see om_all_roots). */
    if (it == 60 && ga * gb < 0.0)
        return _put(out, n, cap, 0.5 * (a + b));
    if (fabs(ga - gb) > OM_PI)
        return n;
    if (ga * gb < 0.0)
        return _put(out, n, cap, om_refine_bracket(pb, a, ga, b, gb, q));
    return n;
}

/* The roots on one cell [a, b] of a run (both ends reachable). g can hold more roots there
 * than its end signs show only where it is not monotone, and none where it stays away from
 * zero: with |g''| <= curvature on the cell, g is monotone where the chord's slope exceeds
 * curvature * (b - a) / 2, and keeps its sign where min(|g(a)|, |g(b)|) exceeds curvature *
 * (b - a)^2 / 8 (g lies within that of its chord). Any other cell is halved, the curvature
 * raised to CELL_SAFETY times the second difference seen at the midpoint, down to
 * CELL_HALVINGS halvings (16 scan points: as fine as 1024); each leaf goes to _bracket. The
 * curvature is an estimate from samples (second differences times CELL_SAFETY), not a proof. */
static int _cell_roots(om_problem *pb, double a, double ga, double b, double gb, double curvature, int halvings,
                       double *q, double *out, int n, int cap)
{
    double h = b - a;
    bool monotone = fabs(gb - ga) > 0.5 * curvature * h * h;
    bool clear = ga * gb > 0.0 && py_min(fabs(ga), fabs(gb)) > 0.125 * curvature * h * h;
    if (halvings == 0 || monotone || clear || fabs(ga - gb) > OM_PI)
        return _bracket(pb, a, ga, b, gb, q, out, n, cap);
    double m = 0.5 * (a + b), gm = om_g(pb, m, q, false);
    if (isnan(gm) || fabs(gm - ga) > OM_PI || fabs(gb - gm) > OM_PI) /* a gap of reach or a wrap inside */
        return _bracket(pb, a, ga, b, gb, q, out, n, cap);
    curvature = py_max(curvature, CELL_SAFETY * fabs(ga - 2.0 * gm + gb) / (0.25 * h * h));
    n = _cell_roots(pb, a, ga, m, gm, curvature, halvings - 1, q, out, n, cap);
    return _cell_roots(pb, m, gm, b, gb, curvature, halvings - 1, q, out, n, cap);
}

/* CELL_SAFETY times |g''| estimated at run point i from the wrapped slopes of its two cells
 * (0 at the ends of a run that is not cyclic). */
static double _curvature_at(const double *pw, const double *pg, int L, bool cyclic, int i)
{
    if (!cyclic && (i <= 0 || i >= L - 1))
        return 0.0;
    int before = py_mod(i - 1, L), after = py_mod(i + 1, L);
    double h0 = om_wrap(pw[i] - pw[before]), h1 = om_wrap(pw[after] - pw[i]);
    if (L < 3 || !(h0 > 0.0) || !(h1 > 0.0))
        return 0.0;
    double s0 = om_wrap(pg[i] - pg[before]) / h0, s1 = om_wrap(pg[after] - pg[i]) / h1;
    return CELL_SAFETY * fabs(s1 - s0) / (0.5 * (h0 + h1));
}

/* Add a close pair of roots on [a, b] to out[n:]: g has one sign at a, x0 and b, and its
 * extremum between them may cross zero. Returns the new count. */
static int _pair(om_problem *pb, double a, double ga, double x0, double b, double gb, double *q, double *out, int n,
                 int cap)
{
    double gw;
    double w = om_extremum(pb, a, b, x0, -om_sign(ga), false, q, &gw, NULL);
    if (isnan(gw) || gw * ga > 0.0) /* no crossing; a touch of zero is a boundary candidate */
        return fabs(gw) < OM_TOUCH ? _put(out, n, cap, w) : n;
    if (gw == 0.0)
        return _put(out, n, cap, w);
    double r0 = om_refine_bracket(pb, a, ga, w, gw, q);
    double r1 = om_refine_bracket(pb, w, gw, b, gb, q);
    n = _put(out, n, cap, r0);
    return _put(out, n, cap, r1);
}

/* Add the roots on a run of reachable points (w ascending) to out[n:]; returns the count.
 * Sign changes bracket roots; local minima of |g| are searched for close pairs; a touch of
 * zero (|g| < OM_TOUCH without a crossing, also at an edge of reach) is a candidate for the
 * singular boundary, where the closed form's last digits are lost. A cyclic run covers the
 * whole circle. */
static int _run_roots(om_problem *pb, const double *pw, const double *pg, int L, bool cyclic, double *q,
                      double *out, int n, int cap)
{
    if (!cyclic) { /* g near zero at an edge of reach: a root at the singular boundary there */
        if (fabs(pg[0]) < OM_TOUCH)
            n = _put(out, n, cap, pw[0]);
        if (L > 1 && fabs(pg[L - 1]) < OM_TOUCH)
            n = _put(out, n, cap, pw[L - 1]);
    }
    for (int i = 0; i < L - 1 + (int)cyclic; i++) {
        int j = (i + 1) % L;
        double wj = pw[j] + (j == 0 ? 2.0 * OM_PI : 0.0);
        double curvature = 0.0; /* the largest estimate at the cell's ends and their neighbours */
        for (int k = i - 1; k <= i + 2; k++)
            if (cyclic || (k >= 0 && k < L))
                curvature = py_max(curvature, _curvature_at(pw, pg, L, cyclic, py_mod(k, L)));
        n = _cell_roots(pb, pw[i], pg[i], wj, pg[j], curvature, CELL_HALVINGS, q, out, n, cap);
    }
    for (int i = 0; i < L; i++) {
        double gi = pg[i];
        bool has_prev = i > 0 || cyclic, has_next = i < L - 1 || cyclic;
        double glo = has_prev ? pg[py_mod(i - 1, L)] : INFINITY;
        double ghi = has_next ? pg[py_mod(i + 1, L)] : INFINITY;
        if (fabs(gi) > OM_PAIR_SEARCH || fabs(glo) < fabs(gi) || fabs(ghi) < fabs(gi))
            continue;
        /* One search over the cells on either side without a sign change. */
        double a = pw[i], ga = gi, b = pw[i], gb = gi;
        if (has_prev && glo * gi > 0.0) {
            a = pw[py_mod(i - 1, L)] - (i == 0 ? 2.0 * OM_PI : 0.0);
            ga = glo;
        }
        if (has_next && ghi * gi > 0.0) {
            b = pw[py_mod(i + 1, L)] + (i == L - 1 ? 2.0 * OM_PI : 0.0);
            gb = ghi;
        }
        if (b > a)
            n = _pair(pb, a, ga, pw[i], b, gb, q, out, n, cap);
    }
    return n;
}

/* Whether the reach margin, sampled as ms[0 .. count) (cyclic: ms[0] follows ms[count - 1]),
 * may reach zero between samples i and i + 1, both out of reach: it can peak between them by
 * about its change across a cell (this one's or a neighbour's). */
bool om_margin_may_reach(const double *ms, int i, int count, bool cyclic)
{
    int next = cyclic ? (i + 1) % count : i + 1;
    double change = fabs(ms[next] - ms[i]);
    if (cyclic || i > 0)
        change = py_max(change, fabs(ms[i] - ms[cyclic ? (i + count - 1) % count : i - 1]));
    if (cyclic || i + 2 < count)
        change = py_max(change, fabs(ms[cyclic ? (i + 2) % count : i + 2] - ms[next]));
    return py_max(ms[i], ms[next]) + change > 0.0;
}

/* Whether the model may reach some point of the cell [ws[i], ws[i + 1]] (both ends out of
 * reach): on an S-R-S arm by a bound (om_srs_reach_possible); otherwise where the margin
 * may (om_margin_may_reach). */
static bool _island_possible(om_problem *pb, const double *ws, const double *ms, int i, int count)
{
    if (pb->s->family == OM_SRS)
        return om_srs_reach_possible(pb, ws[i], ws[i + 1]);
    return om_margin_may_reach(ms, i, count, false);
}

/* Candidate roots of g on [lo, hi] (the whole circle if full_circle) into cands (capacity
 * cap); returns the count. g and the reach margin are sampled at n_pts points; runs of
 * reach (extended to its edges) and islands of reach between samples are searched. */
int om_circle_candidates(om_problem *pb, double lo, double hi, int n_pts, bool full_circle, double *q,
                         double *cands, int cap)
{
    double h = (hi - lo) / (double)(full_circle ? n_pts : n_pts - 1);
    int count = full_circle ? n_pts + 1 : n_pts;
    /* ws, gs, ms (n_pts + 1 each), their rotations (count each), pw, pg (count + 2 each) */
    size_t size = (size_t)(3 * (n_pts + 1) + 3 * count + 2 * (count + 2));
    double *buffer = malloc(size * sizeof(double));
    int *order = malloc((size_t)count * sizeof(int));
    if (!buffer || !order) {
        free(buffer);
        free(order);
        return 0;
    }
    double *ws = buffer, *gs = ws + (n_pts + 1), *ms = gs + (n_pts + 1);
    double *rws = ms + (n_pts + 1), *rgs = rws + count, *rms = rgs + count;
    double *pw = rms + count, *pg = pw + (count + 2);
    int start = -1;
    for (int k = 0; k < n_pts; k++) {
        ws[k] = lo + h * (double)k;
        gs[k] = om_g_margin(pb, ws[k], q, false, &ms[k]);
        if (start < 0 && isnan(gs[k]))
            start = k;
    }
    int n = 0;
    if (full_circle && start < 0) { /* reachable everywhere: one cyclic run */
        n = _run_roots(pb, ws, gs, n_pts, true, q, cands, n, cap);
        free(buffer);
        free(order);
        return n;
    }
    if (full_circle) { /* rotate to start and end at the same unreachable sample */
        for (int i = 0; i < count; i++)
            order[i] = (start + i) % n_pts;
        for (int i = 0; i < count; i++) {
            rws[i] = ws[order[i]] + h * (double)(i - order[i] + start);
            rgs[i] = gs[order[i]];
            rms[i] = ms[order[i]];
        }
        ws = rws;
        gs = rgs;
        ms = rms;
        ws[0] = lo + h * (double)start;
    }
    int L = 0;
    for (int i = 0; i < count; i++) {
        double w = ws[i];
        if (!isnan(gs[i])) {
            if (L == 0 && i > 0) { /* entering reach */
                pw[0] = om_reach_edge(pb, w, ws[i - 1], q);
                pg[0] = om_g(pb, pw[0], q, false);
                L = 1;
            }
            pw[L] = w;
            pg[L] = gs[i];
            L += 1;
            continue;
        }
        if (L > 0) { /* leaving reach */
            pw[L] = om_reach_edge(pb, pw[L - 1], w, q);
            pg[L] = om_g(pb, pw[L], q, false);
            n = _run_roots(pb, pw, pg, L + 1, false, q, cands, n, cap);
            L = 0;
        }
        if (i + 1 < count && isnan(gs[i + 1])) {
            /* Both ends of this cell are out of reach: look for an island of reach between
             * them where the model may reach. */
            if (_island_possible(pb, ws, ms, i, count)) {
                double gc;
                double c = om_extremum(pb, w, ws[i + 1], 0.5 * (w + ws[i + 1]), 1.0, true, q, &gc, NULL);
                if (!isnan(gc)) { /* an island of reach around c */
                    pw[0] = om_reach_edge(pb, c, w, q);
                    pw[1] = c;
                    pg[1] = gc;
                    pw[2] = om_reach_edge(pb, c, ws[i + 1], q);
                    pg[0] = om_g(pb, pw[0], q, false);
                    pg[2] = om_g(pb, pw[2], q, false);
                    n = _run_roots(pb, pw, pg, 3, false, q, cands, n, cap);
                }
            }
        }
    }
    if (L > 0) /* a run that reaches the end of the window */
        n = _run_roots(pb, pw, pg, L, false, q, cands, n, cap);
    free(buffer);
    free(order);
    return n;
}
