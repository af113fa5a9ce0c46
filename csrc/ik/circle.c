/* The bounded search on the circle: every root of g(w), the paper's guarantee: the scan's runs
 * of reach (their roots: circle_runs.c), the islands of reach between its samples, and a near
 * arm's windows of G (the method: om_redundant/ik/kernel_data.py). */
#include "circle.h"

#define POLE_DEPTH 64            /* nested splits of a cell at psi's half-line: to the last bit */
#define NEAR_WINDOW 5 /* points of a window of G at least (one per scan cell otherwise) */
#define WRIST_SAMPLES 4 /* samples of the wrist residual per scan cell of a near arm's singular window */
#define WRIST_CONTRACTION 10.0 /* per metre of the deviation: |sin q5| of such a window (_near_singular) */

/* An arm near a family's scan of its nominal arm's g~ (pb->nominal) finds the real arm's roots,
 * the zeros of G, near g~'s own (each refined on G, om_all_roots); where G may cross zero and
 * g~ does not (near.c), the cells [a, b] are scanned again, on G, in points points (at least
 * NEAR_WINDOW): their candidates into out[n:]. */
static int _near_window(om_problem *pb, double a, double b, int points, double *q, double *out, int n, int cap)
{
    pb->nominal = false;
    n += om_circle_candidates(pb, a, b, points > NEAR_WINDOW ? points : NEAR_WINDOW, false, NAN, q, out + n, cap - n);
    pb->nominal = true;
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

/* A near arm's window of G (_near_window) where g~'s reach changes between samples i and
 * i + 1 of ws (count of them, gs and ms their g~ and margins), at the edge w (g~ = gw there),
 * unless G cannot cross zero next to it. At an edge of reach g turns as the square root of the
 * distance to it, g ~ g_e + k sqrt(w_e - w) (the elbow at the end of its reach), and G's edge
 * lies away from g~'s by about its margin at w over the margin's slope, d = |m_G(w)| / m~'
 * (m~(w) = 0): G may run on by about k sqrt(d) beyond g~'s edge (or end that much short of
 * it), which the difference G - g~ at w does not show. k and m~' come from the inside sample.
 * The window takes the samples whose margin is within circle_near of zero (where G's edge may lie),
 * and one more each way. */
static int _near_edge(om_problem *pb, const double *ws, const double *gs, const double *ms, int i, int count,
                      double w, double gw, double *q, double *out, int n, int cap)
{
    int inside = isnan(gs[i]) ? i + 1 : i;
    double span = fabs(ws[inside] - w), m_edge = 0.0;
    pb->nominal = false;
    double G = om_g_margin(pb, w, q, false, &m_edge);
    pb->nominal = true;
    double k = span > 0.0 ? fabs(gs[inside] - gw) / sqrt(span) : 0.0;
    double slope = span > 0.0 ? fabs(ms[inside]) / span : 0.0; /* (the margin is about 0 at the edge) */
    double run_on = slope > 0.0 ? k * sqrt(fabs(m_edge) / slope) : INFINITY;
    /* where G is out of reach at w, its edge is inside, and G there within run_on of g~ */
    double G_edge = isnan(G) ? gw : G, apart = isnan(G) ? 0.0 : fabs(G - gw);
    if (G_edge * gw > 0.0 && fabs(G_edge) >= NEAR_DIFFERENCE * (apart + run_on) + OM_TOUCH)
        return n;
    double near = circle_near(pb);
    int lo = i, hi = i + 1;
    while (lo > 0 && fabs(ms[lo]) < near)
        lo--;
    while (hi < count - 1 && fabs(ms[hi]) < near)
        hi++;
    return _near_window(pb, ws[lo], ws[hi], hi - lo + 1, q, out, n, cap);
}

/* A near arm's windows about the runs of samples ws (n of them, h apart) whose values bs come
 * below near, each a cell wider each way, searched by search (a scan of g~'s: on G, _near_window;
 * on the wrist residual, _wrist_window). Candidates into out[n_out:]; returns the count. */
static int _near_runs(om_problem *pb, const double *ws, const double *bs, int n, double h, double near,
                      int (*search)(om_problem *, double, double, int, double *, double *, int, int), double *q,
                      double *out, int n_out, int cap)
{
    for (int k = 0; k < n; k++) {
        if (!(bs[k] < near))
            continue;
        int last = k;
        while (last + 1 < n && bs[last + 1] < near)
            last++;
        n_out = search(pb, ws[k] - h, ws[last] + h, last - k + 3, q, out, n_out, cap);
        k = last;
    }
    return n_out;
}

/* The cells [a, b] of a 6-DOF near arm searched on its wrist residual (om_wrist_residual: q6 = w
 * given, smooth at the singular wrist; its zeros, close pairs at the edge of reach included, by
 * the same search, in WRIST_SAMPLES points per cell of the points - 1): candidates into out[n:]. */
static int _wrist_window(om_problem *pb, double a, double b, int points, double *q, double *out, int n, int cap)
{
    bool nominal = pb->nominal;
    pb->nominal = false, pb->wrist = true;
    n += om_circle_candidates(pb, a, b, WRIST_SAMPLES * (points - 1) + 1, false, NAN, q, out + n, cap - n);
    pb->nominal = nominal, pb->wrist = false;
    return n;
}

/* A near arm's windows about the samples ws (n of them, h apart) whose model comes near its
 * singular set (bs: the smallest |branch quantity| of each, then the |WRIST quantity|). Within
 * circle_near of it the model IK's sensitivity to its target grows as 1 / |b| (the wrist's and the
 * shoulder's Euler angles, the elbow's square root), and the correction's effect on g with it:
 * G's singular swing may lie cells away from g~'s, so where the scan was of g~ the window is
 * searched on G. Within WRIST_CONTRACTION times the deviation of a 6-DOF arm's aligned wrist
 * (the model splits it by q_prev, the real arm does not, and the correction at the split moves
 * by about the deviation over |sin q5|), the correction's fixed point need not contract: G's q6
 * need not be the real root's where there is one, and the window is searched on the wrist
 * residual. Candidates into out[n_out:]; returns the count. */
static int _near_singular(om_problem *pb, const double *ws, const double *bs, int n, double h, double *q,
                          double *out, int n_out, int cap)
{
    if (pb->nominal)
        n_out = _near_runs(pb, ws, bs, n, h, circle_near(pb), _near_window, q, out, n_out, cap);
    if (pb->s->family != OM_SRS && pb->s->dp_joint == 5)
        n_out = _near_runs(pb, ws, bs + n, n, h, WRIST_CONTRACTION * pb->s->near_deviation, _wrist_window, q, out,
                           n_out, cap);
    return n_out;
}

/* Whether the model may reach some point of the cell [ws[i], ws[i + 1]] (both ends out of
 * reach): on an S-R-S arm by a bound (om_srs_reach_possible); otherwise where the margin
 * may (om_margin_may_reach). */
static bool _island_possible(om_problem *pb, om_reach_bound *bound, const double *ws, const double *ms, int i,
                             int count)
{
    if (pb->s->family == OM_SRS)
        return om_srs_reach_possible(pb, bound, ws[i], ws[i + 1]);
    return om_margin_may_reach(ms, i, count, false);
}

/* Candidate roots of g on [lo, hi] (the whole circle if full_circle) into cands (capacity
 * cap); returns the count. g and the reach margin are sampled at n_pts points; runs of
 * reach (extended to its edges) and islands of reach between samples are searched. */
int om_circle_candidates(om_problem *pb, double lo, double hi, int n_pts, bool full_circle, double known,
                         double *q, double *cands, int cap)
{
    double h = (hi - lo) / (double)(full_circle ? n_pts : n_pts - 1);
    int count = full_circle ? n_pts + 1 : n_pts;
    /* ws, gs, ms (n_pts + 1 each), their rotations (count each), pw, pg and a run's curvature
     * estimates (count + 2 each) */
    size_t size = (size_t)(5 * (n_pts + 1) + 3 * count + 3 * (count + 2));
    double *buffer = malloc(size * sizeof(double));
    int *order = malloc((size_t)count * sizeof(int));
    if (!buffer || !order) {
        free(buffer);
        free(order);
        return 0;
    }
    double *ws = buffer, *gs = ws + (n_pts + 1), *ms = gs + (n_pts + 1);
    double *rws = ms + (n_pts + 1), *rgs = rws + count, *rms = rgs + count;
    double *pw = rms + count, *pg = pw + (count + 2), *curvatures = pg + (count + 2), *bs = curvatures + (count + 2);
    circle_scan scan = {om_pole_guard(pb, h), _near_window, known};
    int start = -1;
    scan_memo *memo = om_circle_sample(pb, lo, h, n_pts, ws, gs, ms, bs, q);
    /* (the samples in order, for a near arm's windows about its singular set: ws may be rotated
     * below. Its candidates come after the runs': one whose secant runs to another root finds
     * that root found already, and takes the wrist's secant, om_all_roots) */
    const double *samples = ws;
    int n = 0;
    for (int k = 0; k < n_pts && start < 0; k++)
        if (isnan(gs[k]))
            start = k;
    if (full_circle && start < 0) { /* reachable everywhere: one cyclic run */
        n = om_run_roots(pb, &scan, POLE_DEPTH, ws, gs, n_pts, true, curvatures, q, cands, n, cap);
        goto near_singular;
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
    om_reach_bound bound = OM_REACH_BOUND_NONE;
    bound.samples = memo ? om_scan_memo_parts(memo) : NULL, bound.lo = lo, bound.h = h, bound.n = n_pts;
    int L = 0;
    for (int i = 0; i < count; i++) {
        double w = ws[i];
        if (!isnan(gs[i])) {
            if (L == 0 && i > 0) { /* entering reach */
                pw[0] = om_circle_edge(pb, memo, w, ws[i - 1], q, &pg[0]);
                if (pb->nominal)
                    n = _near_edge(pb, ws, gs, ms, i - 1, count, pw[0], pg[0], q, cands, n, cap);
                L = 1;
            }
            pw[L] = w;
            pg[L] = gs[i];
            L += 1;
            continue;
        }
        if (L > 0) { /* leaving reach */
            pw[L] = om_circle_edge(pb, memo, pw[L - 1], w, q, &pg[L]);
            if (pb->nominal)
                n = _near_edge(pb, ws, gs, ms, i - 1, count, pw[L], pg[L], q, cands, n, cap);
            n = om_run_roots(pb, &scan, POLE_DEPTH, pw, pg, L + 1, false, curvatures, q, cands, n, cap);
            L = 0;
        }
        if (i + 1 < count && isnan(gs[i + 1])) {
            /* Both ends of this cell are out of reach: look for an island of reach between
             * them where the model may reach (for a near arm's G, where g~'s margin peaks
             * within circle_near of zero: the cell is searched on G). */
            double near = circle_near(pb);
            if (_island_possible(pb, &bound, ws, ms, i, count) ||
                (pb->nominal && py_max(ms[i], ms[i + 1]) > -near)) {
                double gc, mc;
                double c = om_extremum(pb, w, ws[i + 1], 0.5 * (w + ws[i + 1]), 1.0, true, q, &gc, &mc);
                if (pb->nominal && mc > -near && mc > py_max(ms[i], ms[i + 1])) { /* inside: not an edge's */
                    n = _near_window(pb, w, ws[i + 1], 0, q, cands, n, cap);
                } else if (!isnan(gc)) { /* an island of reach around c */
                    pw[0] = om_reach_edge(pb, c, w, q);
                    pw[1] = c;
                    pg[1] = gc;
                    pw[2] = om_reach_edge(pb, c, ws[i + 1], q);
                    pg[0] = om_g(pb, pw[0], q, false);
                    pg[2] = om_g(pb, pw[2], q, false);
                    n = om_run_roots(pb, &scan, POLE_DEPTH, pw, pg, 3, false, curvatures, q, cands, n, cap);
                }
            }
        }
    }
    if (L > 0) /* a run that reaches the end of the window */
        n = om_run_roots(pb, &scan, POLE_DEPTH, pw, pg, L, false, curvatures, q, cands, n, cap);
near_singular:
    if (pb->s->nominal_table && !pb->wrist)
        n = _near_singular(pb, samples, bs, n_pts, h, q, cands, n, cap);
    free(buffer);
    free(order);
    return n;
}
