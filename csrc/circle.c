/* The bounded search on the circle: every root of g(w), the paper's guarantee
 * (the method: om_redundant/om/system.py). */
#include "om_system.h"

#define CELL_SAFETY 4.0  /* the curvature of g taken as this multiple of its sampled second differences */
#define CELL_HALVINGS 6  /* halvings of a scan cell that may hide roots: 16 points as fine as 1024 */
#define POLE_TURN (0.25 * OM_PI) /* rad: the most w_hat's azimuth about up turns in one cell below the shoulder */
#define POLE_SPLITS 3            /* split points on either side of a close pass: azimuth steps of pi / 8 */
#define POLE_SPREAD 60           /* then offsets doubling out to the cell's ends (g's own slope beside the turn) */
#define POLE_DEPTH 64            /* nested splits of a cell at psi's half-line: to the last bit */
#define POLE_BUDGET 65536        /* evaluations after which a scan splits no more cells (a pose far from
                                  * orthonormal splits every cell to POLE_DEPTH: exponential); the most
                                  * a whole solve takes on random poses is ~1,400 at 1,024 scan points */
#define POLE_NEWTON 8            /* Newton steps to the closest pass of h to zero in a cell */
#define POLE_ROUNDING 1e-15      /* relative rounding of W - S: of |e| + |u1| + |u2| (DBL_EPSILON 2.2e-16) */

/* An arm near a family scans its nominal arm's g~ and searches G in windows (near.c): G may
 * cross zero where it is within NEAR_DIFFERENCE times its difference from g~ of it. */
#define NEAR_DIFFERENCE 4.0
#define NEAR_WINDOW 5 /* points of a window of G at least (one per scan cell otherwise) */
#define WRIST_SAMPLES 4 /* samples of the wrist residual per scan cell of a near arm's singular window */
#define WRIST_CONTRACTION 10.0 /* per metre of the deviation: |sin q5| of such a window (_near_singular) */

#define MEMO_POINTS 128 /* a scan of at most this many points shares its samples' model parts (scan_memo) */
#define MEMO_EDGES 16   /* edges of reach a scan memo keeps */
#define MEMO_KEY (9 + 3 + 3)

/* An edge of reach a scan met (om_reach_edge(inside, outside) = w), the model's parts there and
 * the wrist's terms for the arm angle psi (terms_valid). */
typedef struct {
    double inside, outside, w;
    om_srs_elbow parts;
    om_srs_wrist_terms terms;
    bool terms_valid;
    double psi;
} memo_edge;

/* What the last scan of the circle of an S-R-S arm whose dp turns with q7 through a memo, in
 * one ELBOW branch, keeps for the next: the model's parts at its samples w_k that do not
 * depend on the arm angle (om_srs_elbow_at: those of the hand position p_d + R delta(w_k),
 * the orientation and the ELBOW sign), those that do not depend on the WRIST sign
 * (om_srs_wrist_terms_of) for the arm angle psi, and the edges of reach it met (the reach
 * margin depends on the pose alone) with the same parts there. A grid of problems of one pose
 * (solve_grid: arm angles, each in 8 branches) scans the same samples again and again; a scan
 * whose key is the last one's takes these instead of computing them again (the same
 * arithmetic on the same inputs: the same bits), and solves q7 alone. */
typedef struct {
    bool valid;
    double key[MEMO_KEY]; /* R, p_d, lo, h, the points (the model's parameters: one solver's) */
    om_srs_elbow parts[MEMO_POINTS];
    bool terms_valid;
    double psi;
    om_srs_wrist_terms terms[MEMO_POINTS];
    int n_edges;
    memo_edge edges[MEMO_EDGES];
} scan_memo;

/* The scan memos of the problems of one solver (its parameters and delta fixed: not in the
 * key), one per ELBOW branch; om_scan_cache owns it for a batch. */
struct om_scan_memo {
    scan_memo branches[2]; /* ELBOW -1, +1 */
};

/* Whether the scans of solver s keep a memo: those of an S-R-S arm whose dp turns with q7 (not
 * near a family: its model side moves with the correction at every sample, near.c). */
static bool _keeps_memo(const om_solver_data *s)
{
    return s->family == OM_SRS && s->mode == OM_CIRCLE && s->dp_joint == 6 && !s->nominal_table;
}

/* (86 kB: allocated only for an arm that keeps one, and not zeroed: a branch's parts are
 * written where its key is.) */
om_scan_memo *om_scan_memo_new(const om_solver_data *s)
{
    if (!_keeps_memo(s))
        return NULL;
    om_scan_memo *memo = malloc(sizeof(om_scan_memo));
    if (memo)
        memo->branches[0].valid = memo->branches[1].valid = false;
    return memo;
}

void om_scan_memo_free(om_scan_memo *memo) { free(memo); }

static void _memo_key(const om_problem *pb, double lo, double h, int n_pts, double *key)
{
    const mat3 *R = &pb->t.R;
    const vec3 rows[3] = {R->r0, R->r1, R->r2};
    double *k = key;
    for (int i = 0; i < 3; i++)
        *k++ = rows[i].x, *k++ = rows[i].y, *k++ = rows[i].z;
    *k++ = pb->p.x, *k++ = pb->p.y, *k++ = pb->p.z;
    *k++ = lo, *k++ = h;
    *k = (double)n_pts;
}

/* Whether two doubles have the same bits (cos and sin of -0.0 and 0.0 differ in a sign). */
static bool _same_bits(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

/* g at w and the reach margin as om_g_margin computes them (one residual evaluation; q as it
 * leaves q), from the model's parts e there: the wrist's terms from *terms where fresh (for
 * this arm angle), else computed into it. */
static double _g_of_parts(om_problem *pb, double w, const om_srs_elbow *e, om_srs_wrist_terms *terms, bool fresh,
                          double *q, double *margin)
{
    const double *P = pb->s->params;
    pb->counter++;
    *margin = e->margin;
    if (e->margin < -OM_REACH_SLACK)
        return NAN;
    if (!fresh)
        *terms = om_srs_wrist_terms_of(P, &pb->t, e);
    om_srs_q7_of(P, &pb->t, e, terms, pb->signs, pb->q_prev, q);
    return om_wrap(q[6] - w);
}

/* The smallest |branch quantity| of the model at q (margin its reach margin; q NULL: out of
 * reach, INFINITY) into *nearest, its WRIST quantity's into *wrist. On an S-R-S arm, whose scan
 * of its nominal arm solves q7 alone, the ELBOW quantity's alone, |sin(phi4 - phi*)| =
 * sqrt(margin) (the SHOULDER's and the WRIST's singular swings show in g~ itself, and the
 * scan searches G there: _bracket), and no WRIST quantity (its wrist residual is not searched:
 * _near_singular). */
static void _near_branches(const om_solver_data *s, const double *q, double margin, double *nearest, double *wrist)
{
    double values[3];
    *nearest = *wrist = INFINITY;
    if (!q)
        return;
    if (s->family == OM_SRS) {
        *nearest = sqrt(py_max(margin, 0.0));
        return;
    }
    om_branch_values(s->family, s->params, q, values);
    for (int i = 0; i < s->n_signs; i++)
        *nearest = py_min(*nearest, fabs(values[i]));
    *wrist = fabs(values[2]);
}

/* g and the reach margin at the scan's points ws[k] = lo + h k, k < n_pts, into gs and ms as
 * om_g_margin computes them, the parts that the problem's memo holds for them taken from it;
 * for an arm near a family (which keeps no memo), the model's smallest |branch quantity| there
 * into bs[k], its |WRIST quantity| into bs[n_pts + k] (INFINITY out of reach).
 * Returns that memo's branch, now this scan's (NULL where the problem or the arm keeps
 * none), valid until the memo's next scan. */
static scan_memo *_sample(om_problem *pb, double lo, double h, int n_pts, double *ws, double *gs, double *ms,
                          double *bs, double *q)
{
    const om_solver_data *s = pb->s;
    for (int k = 0; k < n_pts; k++)
        ws[k] = lo + h * (double)k;
    if (!pb->memo || n_pts > MEMO_POINTS) { /* (pb->memo: an arm that keeps one, om_scan_memo_new) */
        for (int k = 0; k < n_pts; k++) {
            gs[k] = om_g_margin(pb, ws[k], q, false, &ms[k]);
            if (s->nominal_table)
                _near_branches(s, isnan(gs[k]) ? NULL : q, ms[k], &bs[k], &bs[n_pts + k]);
        }
        return NULL;
    }
    double elbow = (double)pb->signs[1];
    scan_memo *memo = &pb->memo->branches[elbow > 0.0];
    double key[MEMO_KEY];
    _memo_key(pb, lo, h, n_pts, key);
    if (!memo->valid || memcmp(key, memo->key, sizeof key) != 0) {
        for (int k = 0; k < n_pts; k++)
            om_srs_elbow_at(s->params, &pb->t, om_on_circle(pb, ws[k]), elbow, &memo->parts[k]);
        memcpy(memo->key, key, sizeof key);
        memo->valid = true;
        memo->terms_valid = false;
        memo->n_edges = 0;
    }
    bool fresh = memo->terms_valid && _same_bits(memo->psi, pb->t.psi);
    for (int k = 0; k < n_pts; k++)
        gs[k] = _g_of_parts(pb, ws[k], &memo->parts[k], &memo->terms[k], fresh, q, &ms[k]);
    memo->psi = pb->t.psi;
    memo->terms_valid = true;
    return memo;
}

/* The edge of reach om_reach_edge(inside, outside) and g there (om_g) into *g, through this
 * scan's memo (NULL: none): an edge that the memo's scans met is the same, and g there is
 * evaluated from the parts kept. */
static double _edge(om_problem *pb, scan_memo *memo, double inside, double outside, double *q, double *g)
{
    memo_edge *edge = NULL;
    for (int i = 0; memo && i < memo->n_edges && !edge; i++)
        if (_same_bits(memo->edges[i].inside, inside) && _same_bits(memo->edges[i].outside, outside))
            edge = &memo->edges[i];
    if (!edge) {
        double w = om_reach_edge(pb, inside, outside, q);
        if (!memo || memo->n_edges == MEMO_EDGES) {
            *g = om_g(pb, w, q, false);
            return w;
        }
        edge = &memo->edges[memo->n_edges++];
        edge->inside = inside, edge->outside = outside, edge->w = w;
        om_srs_elbow_at(pb->s->params, &pb->t, om_on_circle(pb, w), (double)pb->signs[1], &edge->parts);
        edge->terms_valid = false;
    }
    double margin;
    *g = _g_of_parts(pb, edge->w, &edge->parts, &edge->terms, edge->terms_valid && _same_bits(edge->psi, pb->t.psi),
                     q, &margin);
    edge->psi = pb->t.psi;
    edge->terms_valid = true;
    return edge->w;
}

/* out[n] = v if there is room; returns the new count (the candidates' capacity is a bound, checked). */
static int _put(double *out, int n, int cap, double v)
{
    if (n >= cap)
        return n;
    out[n] = v;
    return n + 1;
}

/* An arm near a family's scan of its nominal arm's g~ (pb->nominal) finds the real arm's roots,
 * the zeros of G, near g~'s own (each refined on G, om_all_roots); where G may cross zero and
 * g~ does not (near.c), the cells [a, b] are scanned again, on G, in points points (at least
 * NEAR_WINDOW): their candidates into out[n:]. */
static int _near_window(om_problem *pb, double a, double b, int points, double *q, double *out, int n, int cap)
{
    pb->nominal = false;
    n += om_circle_candidates(pb, a, b, points > NEAR_WINDOW ? points : NEAR_WINDOW, false, q, out + n, cap - n);
    pb->nominal = true;
    return n;
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

/* How near to zero a near arm's g~, reach margin or branch quantity comes for G's to reach it. */
static double _near(const om_problem *pb) { return OM_NEAR_SENSITIVITY * pb->s->near_deviation; }

/* _near_crossing where g~ = gw comes within _near of zero at w. */
static bool _near_miss(om_problem *pb, double w, double gw, double *q)
{
    return fabs(gw) < _near(pb) && _near_crossing(pb, w, gw, q);
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
    if (pb->nominal && it > 0) /* a steep swing of g~ (a singular wrist): G's may cross where g~'s wraps */
        return _near_window(pb, a, b, 0, q, out, n, cap);
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
    if (isnan(gm)) /* a gap of reach inside */
        return _bracket(pb, a, ga, b, gb, q, out, n, cap);
    if (pb->nominal && gm * ga > 0.0 && gm * gb > 0.0 && fabs(gm) < py_min(fabs(ga), fabs(gb)) &&
        _near_miss(pb, m, gm, q)) /* a dip of g~ toward zero */
        return _near_window(pb, a, b, 0, q, out, n, cap);
    /* A wrap in one half goes to _bracket as that half (the check above): the other half may
     * hold a root that the whole cell's ends hide (g turning by more than pi across the cell,
     * next to psi's half-line: a root and a wrap whose ends differ by less than pi). */
    curvature = py_max(curvature, CELL_SAFETY * fabs(ga - 2.0 * gm + gb) / (0.25 * h * h));
    n = _cell_roots(pb, a, ga, m, gm, curvature, halvings - 1, q, out, n, cap);
    return _cell_roots(pb, m, gm, b, gb, curvature, halvings - 1, q, out, n, cap);
}

/* psi's singular half-line on the circle. The model's shoulder-wrist vector is x(w) = W(w) -
 * S = e + u1 cos w + u2 sin w (om_srs_wrist_circle), an ellipse: its part across up, h(w), and
 * its height z(w) = up . x(w). Where x passes close by -up (the wrist centre straight below the
 * shoulder), psi's reference n(w_hat) = R(up -> w_hat) r turns by about twice the azimuth of h,
 * a full turn within a fraction of a scan cell when h passes close by zero, and with it q_J
 * and g: a root there is not bracketed by the samples. Such a cell is split until the azimuth
 * turns by at most POLE_TURN in each part, by a bound: on a cell [a, b] of width L, h stays
 * within sigma L^2 t (1 - t) / 2 of its chord h(a) + t (h(b) - h(a)) (|h''| <= sigma, the
 * largest singular value of u1, u2 across up), so where the chord keeps farther than that
 * from zero, the azimuth of h turns across the cell as the chord's ends show. */
typedef struct {
    bool active; /* some cell may be one to split (a bound over the whole ellipse) */
    vec3 up, e, u1, u2;
    double sigma;   /* bounds |h'| and |h''| */
    double sigma_z; /* bounds |z''| */
    double slack;   /* rounding of x(w) (m) */
    int64_t until;  /* pb->counter from which no cell is split (POLE_BUDGET) */
} pole_guard;

/* The part of x across up. */
static vec3 _across(const pole_guard *pole, vec3 x)
{
    return v_sub(x, v_scale(v_dot(pole->up, x), pole->up));
}

/* The guard of the circle for scan cells of width L: active unless every cell keeps the
 * azimuth's turn below POLE_TURN (the whole ellipse above the shoulder, or h everywhere at
 * least M = |e across| - sigma from zero: its turn across a cell is at most sigma L / M, and
 * its chords keep 3 sigma L^2 / 8 clear of zero where M exceeds that). */
static pole_guard _pole_guard(om_problem *pb, double L)
{
    pole_guard pole = {false};
    pole.until = pb->counter + POLE_BUDGET;
    if (pb->s->family != OM_SRS)
        return pole;
    pole.up = v_load(pb->s->params, SRS_UP);
    om_srs_wrist_circle(pb, &pole.e, &pole.u1, &pole.u2);
    vec3 a1 = _across(&pole, pole.u1), a2 = _across(&pole, pole.u2);
    double p = 0.5 * (v_dot(a1, a1) + v_dot(a2, a2)), d = 0.5 * (v_dot(a1, a1) - v_dot(a2, a2));
    pole.sigma = sqrt(p + sqrt(d * d + v_dot(a1, a2) * v_dot(a1, a2)));
    double z1 = v_dot(pole.up, pole.u1), z2 = v_dot(pole.up, pole.u2);
    pole.sigma_z = sqrt(z1 * z1 + z2 * z2);
    pole.slack = POLE_ROUNDING * (v_norm(pole.e) + v_norm(pole.u1) + v_norm(pole.u2));
    double nearest = v_norm(_across(&pole, pole.e)) - pole.sigma;
    double needed = py_max(0.375 * pole.sigma * L * L, pole.sigma * L / POLE_TURN) + pole.slack;
    pole.active = v_dot(pole.up, pole.e) - pole.sigma_z < pole.slack && nearest <= needed;
    return pole;
}

/* x(w) on the ellipse. */
static vec3 _shoulder_wrist(const pole_guard *pole, double w)
{
    return v_add(pole->e, v_add(v_scale(cos(w), pole->u1), v_scale(sin(w), pole->u2)));
}

/* Whether |h0 + t d| > K t + slack for t in [0, 1/2]: the squares' difference is a quadratic
 * A t^2 + B t + C, positive at both ends and at its vertex if that lies inside. */
static bool _clear_of_zero(vec3 h0, vec3 d, double K, double slack)
{
    double A = v_dot(d, d) - K * K, B = 2.0 * (v_dot(h0, d) - K * slack), C = v_dot(h0, h0) - slack * slack;
    double f = A * 0.25 + B * 0.5 + C, t = A > 0.0 ? -B / (2.0 * A) : 0.0;
    return C > 0.0 && f > 0.0 && !(0.0 < t && t < 0.5 && C - B * B / (4.0 * A) <= 0.0);
}

/* Where the cell [a, b] is to be split at psi's half-line: 0 if it is calm (above the
 * shoulder all along, or the azimuth of h turns by at most POLE_TURN across it, by the bound
 * above: the deviation sigma L^2 t (1 - t) / 2 is at most K min(t, 1 - t), K = sigma L^2 / 2);
 * else the split points in (a, b), ascending, into split (2 POLE_SPLITS + 1): around h's
 * closest pass w* to zero (Newton on h . h' = 0 from the chord's), at distance rho with speed
 * v there, w* + (rho / v) tan(k pi / 8), k = -3 ... 3, between which a straight pass turns the
 * azimuth by pi / 8 (the midpoint if none of them lies inside, as at a pass through zero to
 * the last bit). A part that is still not calm is split again (_run_roots' depth). Returns
 * the count. */
static int _pole_splits(const pole_guard *pole, double a, double b, double *split)
{
    vec3 xa = _shoulder_wrist(pole, a), xb = _shoulder_wrist(pole, b);
    double width = b - a, sag_z = 0.125 * pole->sigma_z * width * width + pole->slack;
    if (v_dot(pole->up, xa) > sag_z && v_dot(pole->up, xb) > sag_z) /* above the shoulder all along */
        return 0;
    vec3 ha = _across(pole, xa), hb = _across(pole, xb), d = v_sub(hb, ha);
    double K = 0.5 * pole->sigma * width * width;
    if (atan2(v_norm(v_cross(ha, hb)), v_dot(ha, hb)) <= POLE_TURN && _clear_of_zero(ha, d, K, pole->slack) &&
        _clear_of_zero(hb, v_scale(-1.0, d), K, pole->slack))
        return 0;
    double dd = v_dot(d, d), centre = a + (dd > 0.0 ? py_min(py_max(-v_dot(ha, d) / dd, 0.0), 1.0) : 0.0) * width;
    vec3 h, speed; /* h and h' at the pass */
    for (int it = 0; it < POLE_NEWTON; it++) { /* Newton on (|h|^2)' / 2 = h . h' from the chord's pass */
        double c = cos(centre), s = sin(centre);
        h = _across(pole, _shoulder_wrist(pole, centre));
        speed = _across(pole, v_sub(v_scale(c, pole->u2), v_scale(s, pole->u1)));
        vec3 bend = v_sub(_across(pole, pole->e), h); /* h'' = -(h - e across) */
        double slope = v_dot(speed, speed) + v_dot(h, bend);
        double next = py_min(py_max(centre - v_dot(h, speed) / slope, a), b);
        if (!(slope > 0.0) || next == centre)
            break;
        centre = next;
    }
    double v = v_norm(speed), scale = v > 0.0 ? v_norm(h) / v : 0.0;
    double outer = scale * tan((double)POLE_SPLITS * OM_PI / (2.0 * (double)POLE_SPLITS + 2.0));
    int n = 0;
    for (int k = -POLE_SPLITS - POLE_SPREAD; k <= POLE_SPLITS + POLE_SPREAD; k++) {
        int far = abs(k) - POLE_SPLITS; /* beyond the pass: doublings of the outermost offset */
        double w = far > 0 ? centre + (double)(k > 0 ? 1 : -1) * ldexp(outer, far)
                           : centre + scale * tan((double)k * OM_PI / (2.0 * (double)POLE_SPLITS + 2.0));
        if (a < w && w < b && (n == 0 || w > split[n - 1]))
            split[n++] = w;
    }
    double middle = 0.5 * (a + b);
    if (n == 0 && a < middle && middle < b)
        split[n++] = middle;
    return n;
}

static int _run_roots(om_problem *pb, const pole_guard *pole, int depth, const double *pw, const double *pg, int L,
                      bool cyclic, double *curvatures, double *q, double *out, int n, int cap);

/* The roots on the cell [a, b] of a run (both ends reachable) split at the points split[0 ..
 * k): a run of its own (_run_roots, depth splits more at most), so that its parts get the
 * curvature estimates and the close-pair search of the run's samples. A split point out of
 * reach is left out. */
static int _split_roots(om_problem *pb, const pole_guard *pole, int depth, double a, double ga, const double *split,
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
    return _run_roots(pb, pole, depth, sw, sg, m + 1, false, curvatures, q, out, n, cap);
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
static int _pair(om_problem *pb, double a, double ga, double x0, double b, double gb, double *q, double *out, int n,
                 int cap)
{
    double gw;
    double w = om_extremum(pb, a, b, x0, -om_sign(ga), false, q, &gw, NULL);
    if (pb->nominal && !(gw * ga <= 0.0) && _near_miss(pb, w, gw, q))
        return _near_window(pb, a, b, 0, q, out, n, cap);
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
 * close by psi's half-line is split first (_pole_splits, at most depth times nested, and not
 * once the scan has taken POLE_BUDGET evaluations). A
 * cyclic run covers the whole circle. curvatures: scratch for L doubles. */
static int _run_roots(om_problem *pb, const pole_guard *pole, int depth, const double *pw, const double *pg, int L,
                      bool cyclic, double *curvatures, double *q, double *out, int n, int cap)
{
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
        int k = pole->active && depth > 0 && pb->counter < pole->until ? _pole_splits(pole, pw[i], wj, split) : 0;
        if (k)
            n = _split_roots(pb, pole, depth - 1, pw[i], pg[i], split, k, wj, pg[j], q, out, n, cap);
        else
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

/* A near arm's window of G (_near_window) where g~'s reach changes between samples i and
 * i + 1 of ws (count of them, gs and ms their g~ and margins), at the edge w (g~ = gw there),
 * unless G cannot cross zero next to it. At an edge of reach g turns as the square root of the
 * distance to it, g ~ g_e + k sqrt(w_e - w) (the elbow at the end of its reach), and G's edge
 * lies away from g~'s by about its margin at w over the margin's slope, d = |m_G(w)| / m~'
 * (m~(w) = 0): G may run on by about k sqrt(d) beyond g~'s edge (or end that much short of
 * it), which the difference G - g~ at w does not show. k and m~' come from the inside sample.
 * The window takes the samples whose margin is within _near of zero (where G's edge may lie),
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
    double near = _near(pb);
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
    n += om_circle_candidates(pb, a, b, WRIST_SAMPLES * (points - 1) + 1, false, q, out + n, cap - n);
    pb->nominal = nominal, pb->wrist = false;
    return n;
}

/* A near arm's windows about the samples ws (n of them, h apart) whose model comes near its
 * singular set (bs: the smallest |branch quantity| of each, then the |WRIST quantity|). Within
 * _near of it the model IK's sensitivity to its target grows as 1 / |b| (the wrist's and the
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
        n_out = _near_runs(pb, ws, bs, n, h, _near(pb), _near_window, q, out, n_out, cap);
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
int om_circle_candidates(om_problem *pb, double lo, double hi, int n_pts, bool full_circle, double *q,
                         double *cands, int cap)
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
    pole_guard pole = _pole_guard(pb, h);
    int start = -1;
    scan_memo *memo = _sample(pb, lo, h, n_pts, ws, gs, ms, bs, q);
    /* (the samples in order, for a near arm's windows about its singular set: ws may be rotated
     * below. Its candidates come after the runs': one whose secant runs to another root finds
     * that root found already, and takes the wrist's secant, om_all_roots) */
    const double *samples = ws;
    int n = 0;
    for (int k = 0; k < n_pts && start < 0; k++)
        if (isnan(gs[k]))
            start = k;
    if (full_circle && start < 0) { /* reachable everywhere: one cyclic run */
        n = _run_roots(pb, &pole, POLE_DEPTH, ws, gs, n_pts, true, curvatures, q, cands, n, cap);
        if (pb->s->nominal_table && !pb->wrist)
            n = _near_singular(pb, samples, bs, n_pts, h, q, cands, n, cap);
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
    om_reach_bound bound = OM_REACH_BOUND_NONE;
    bound.samples = memo ? memo->parts : NULL, bound.lo = lo, bound.h = h, bound.n = n_pts;
    int L = 0;
    for (int i = 0; i < count; i++) {
        double w = ws[i];
        if (!isnan(gs[i])) {
            if (L == 0 && i > 0) { /* entering reach */
                pw[0] = _edge(pb, memo, w, ws[i - 1], q, &pg[0]);
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
            pw[L] = _edge(pb, memo, pw[L - 1], w, q, &pg[L]);
            if (pb->nominal)
                n = _near_edge(pb, ws, gs, ms, i - 1, count, pw[L], pg[L], q, cands, n, cap);
            n = _run_roots(pb, &pole, POLE_DEPTH, pw, pg, L + 1, false, curvatures, q, cands, n, cap);
            L = 0;
        }
        if (i + 1 < count && isnan(gs[i + 1])) {
            /* Both ends of this cell are out of reach: look for an island of reach between
             * them where the model may reach (for a near arm's G, where g~'s margin peaks
             * within _near of zero: the cell is searched on G). */
            double near = _near(pb);
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
                    n = _run_roots(pb, &pole, POLE_DEPTH, pw, pg, 3, false, curvatures, q, cands, n, cap);
                }
            }
        }
    }
    if (L > 0) /* a run that reaches the end of the window */
        n = _run_roots(pb, &pole, POLE_DEPTH, pw, pg, L, false, curvatures, q, cands, n, cap);
    if (pb->s->nominal_table && !pb->wrist)
        n = _near_singular(pb, samples, bs, n_pts, h, q, cands, n, cap);
    free(buffer);
    free(order);
    return n;
}
