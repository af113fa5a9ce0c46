/* The roots of g on the runs of reach of the circle's scan: brackets of sign changes, cells
 * halved where g may hold more roots than their ends show, close pairs at the minima of |g|,
 * touches of zero, and cells split at psi's half-line (circle_pole.c); a near arm's windows of
 * G by its scan's callback (the method: om_redundant/ik/kernel_data.py). */
#include "circle.h"

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

/* Whether G may cross zero next to w, where g~ = gw does not: G at w is out of reach or of the
 * other sign, or within NEAR_DIFFERENCE times its difference from g~ of zero (the difference,
 * the correction's effect on g, changes little along a cell). */
static bool _near_crossing(om_problem *pb, double w, double gw, double *q)
{
    pb->nominal = false;
    double G = om_g(pb, w, q, false);
    pb->nominal = true;
    return !(G * gw > 0.0) || fabs(G) < NEAR_DIFFERENCE * fabs(G - gw) + OM_TOUCH;
}

/* _near_crossing where g~ = gw comes within circle_near of zero at w. */
static bool _near_miss(om_problem *pb, double w, double gw, double *q)
{
    return fabs(gw) < circle_near(pb) && _near_crossing(pb, w, gw, q);
}

/* Add the root of g on [a, b] (both ends reachable) to out[n:]; returns the new count.
 * A sign change is one root; a wrap of g from about +pi to -pi is none; a sign change of g
 * itself (not of a near arm's g~, whose roots lie off G's) about the scan's known root is that
 * root. */
static int _bracket(om_problem *pb, const circle_scan *scan, double a, double ga, double b, double gb, double *q,
                    double *out, int n, int cap)
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
    if (pb->nominal && it > 0) /* a steep swing of g~ (a singular wrist): G's may cross where g~'s wraps */
        return scan->window(pb, a, b, 0, q, out, n, cap);
    /* Bisected to the last bit and still a jump short of a wrap's 2 pi: g crosses zero
     * there, too steeply for floating point (the wrist within about 1e-9 of its
     * singularity, where q_J swings by pi). The candidate goes to the lifted Newton, which
     * is smooth there (see om_all_roots). */
    if (it == 60 && ga * gb < 0.0)
        return _put(out, n, cap, 0.5 * (a + b));
    if (fabs(ga - gb) > OM_PI)
        return n;
    double from_a = om_wrap(scan->known - a); /* (NaN: no root known) */
    if (ga * gb < 0.0 && !pb->nominal && from_a >= 0.0 && from_a <= b - a) /* its one root, known */
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
static int _cell_roots(om_problem *pb, const circle_scan *scan, double a, double ga, double b, double gb,
                       double curvature, int halvings, double *q, double *out, int n, int cap)
{
    double h = b - a;
    bool monotone = fabs(gb - ga) > 0.5 * curvature * h * h;
    bool clear = ga * gb > 0.0 && py_min(fabs(ga), fabs(gb)) > 0.125 * curvature * h * h;
    if (halvings == 0 || monotone || clear || fabs(ga - gb) > OM_PI)
        return _bracket(pb, scan, a, ga, b, gb, q, out, n, cap);
    double m = 0.5 * (a + b), gm = om_g(pb, m, q, false);
    if (isnan(gm)) /* a gap of reach inside */
        return _bracket(pb, scan, a, ga, b, gb, q, out, n, cap);
    if (pb->nominal && gm * ga > 0.0 && gm * gb > 0.0 && fabs(gm) < py_min(fabs(ga), fabs(gb)) &&
        _near_miss(pb, m, gm, q)) /* a dip of g~ toward zero */
        return scan->window(pb, a, b, 0, q, out, n, cap);
    /* A wrap in one half goes to _bracket as that half (the check above): the other half may
     * hold a root that the whole cell's ends hide (g turning by more than pi across the cell,
     * next to psi's half-line: a root and a wrap whose ends differ by less than pi). */
    curvature = py_max(curvature, CELL_SAFETY * fabs(ga - 2.0 * gm + gb) / (0.25 * h * h));
    n = _cell_roots(pb, scan, a, ga, m, gm, curvature, halvings - 1, q, out, n, cap);
    return _cell_roots(pb, scan, m, gm, b, gb, curvature, halvings - 1, q, out, n, cap);
}

/* The roots on the cell [a, b] of a run (both ends reachable) split at the points split[0 ..
 * k): a run of its own (om_run_roots, depth splits more at most), so that its parts get the
 * curvature estimates and the close-pair search of the run's samples. A split point out of
 * reach is left out. */
static int _split_roots(om_problem *pb, const circle_scan *scan, int depth, double a, double ga, const double *split,
                        int k, double b, double gb, double *q, double *out, int n, int cap)
{
    double sw[2 * (POLE_SPLITS + POLE_SPREAD) + 3], sg[2 * (POLE_SPLITS + POLE_SPREAD) + 3];
    double curvatures[2 * (POLE_SPLITS + POLE_SPREAD) + 3];
    int m = 1;
    sw[0] = a;
    sg[0] = ga;
    for (int i = 0; i < k; i++) {
        sw[m] = split[i];
        sg[m] = om_g(pb, split[i], q, false);
        m += !isnan(sg[m]);
    }
    sw[m] = b;
    sg[m] = gb;
    return om_run_roots(pb, scan, depth, sw, sg, m + 1, false, curvatures, q, out, n, cap);
}

/* CELL_SAFETY times |g''| estimated at each run point i from the wrapped slopes of its two
 * cells (0 at the ends of a run that is not cyclic, and where a cell is empty) into out[0 ..
 * L); each cell's slope is computed once, for both of its ends. */
static void _curvatures(const double *pw, const double *pg, int L, bool cyclic, double *out)
{
    double h0 = 0.0, s0 = 0.0; /* the cell before point i (from point i - 1) */
    if (cyclic && L > 0) {
        h0 = om_wrap(pw[0] - pw[L - 1]);
        s0 = om_wrap(pg[0] - pg[L - 1]) / h0;
    }
    for (int i = 0; i < L; i++) {
        int after = (i + 1) % L;
        double h1 = om_wrap(pw[after] - pw[i]), s1 = om_wrap(pg[after] - pg[i]) / h1;
        bool end = !cyclic && (i <= 0 || i >= L - 1);
        out[i] = end || L < 3 || !(h0 > 0.0) || !(h1 > 0.0) ? 0.0 : CELL_SAFETY * fabs(s1 - s0) / (0.5 * (h0 + h1));
        h0 = h1;
        s0 = s1;
    }
}

/* The estimate of _curvatures at point k of the run, k taken modulo L where the run is cyclic;
 * NaN for a k beyond its ends where it is not (and for an empty run). */
static double _curvature_near(const double *curvatures, int L, bool cyclic, int k)
{
    if (L < 1 || (!cyclic && (k < 0 || k >= L)))
        return NAN;
    return curvatures[py_mod(k, L)];
}

/* Add a close pair of roots on [a, b] to out[n:]: g has one sign at a, x0 and b, and its
 * extremum between them may cross zero. Returns the new count. */
static int _pair(om_problem *pb, const circle_scan *scan, double a, double ga, double x0, double b, double gb,
                 double *q, double *out, int n, int cap)
{
    double gw;
    double w = om_extremum(pb, a, b, x0, -om_sign(ga), false, q, &gw, NULL);
    if (pb->nominal && !(gw * ga <= 0.0) && _near_miss(pb, w, gw, q))
        return scan->window(pb, a, b, 0, q, out, n, cap);
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
 * singular boundary, where the closed form's last digits are lost. A cell where w_hat passes
 * close by psi's half-line is split first (om_pole_splits, at most depth times nested, and not
 * once the scan has taken POLE_BUDGET evaluations). A
 * cyclic run covers the whole circle. curvatures: scratch for L doubles. */
int om_run_roots(om_problem *pb, const circle_scan *scan, int depth, const double *pw, const double *pg, int L,
                 bool cyclic, double *curvatures, double *q, double *out, int n, int cap)
{
    const pole_guard *pole = &scan->pole;
    if (!cyclic) { /* g near zero at an edge of reach: a root at the singular boundary there */
        if (fabs(pg[0]) < OM_TOUCH)
            n = _put(out, n, cap, pw[0]);
        if (L > 1 && fabs(pg[L - 1]) < OM_TOUCH)
            n = _put(out, n, cap, pw[L - 1]);
    }
    /* The estimates at points i - 1 .. i + 2 of cell i, as the window slides (NaN beyond the
     * ends of a run that is not cyclic: none there). */
    _curvatures(pw, pg, L, cyclic, curvatures);
    double near[4];
    for (int m = 0; m < 4; m++)
        near[m] = _curvature_near(curvatures, L, cyclic, m - 1);
    for (int i = 0; i < L - 1 + (int)cyclic; i++) {
        int j = (i + 1) % L;
        double wj = pw[j] + (j == 0 ? 2.0 * OM_PI : 0.0);
        double curvature = 0.0; /* the largest estimate at the cell's ends and their neighbours */
        for (int m = 0; m < 4; m++)
            if (!isnan(near[m]))
                curvature = py_max(curvature, near[m]);
        memmove(near, near + 1, 3 * sizeof(double));
        near[3] = _curvature_near(curvatures, L, cyclic, i + 3);
        double split[2 * (POLE_SPLITS + POLE_SPREAD) + 1];
        int k = pole->active && depth > 0 && pb->counter < pole->until ? om_pole_splits(pole, pw[i], wj, split) : 0;
        if (k)
            n = _split_roots(pb, scan, depth - 1, pw[i], pg[i], split, k, wj, pg[j], q, out, n, cap);
        else
            n = _cell_roots(pb, scan, pw[i], pg[i], wj, pg[j], curvature, CELL_HALVINGS, q, out, n, cap);
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
            n = _pair(pb, scan, a, ga, pw[i], b, gb, q, out, n, cap);
    }
    return n;
}
