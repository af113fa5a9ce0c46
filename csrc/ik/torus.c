/* The bounded search on the torus (w1, w7) of an arm with shoulder offsets: the lifted
 * residual on a grid, damped Newton (torus_newton.c) from its local minima and sign changes,
 * with deflation and fold partners, and at psi's half-line (torus_half_line.c)
 * (the method: om_redundant/ik/kernel_data.py). */
#include "torus.h"

#define MAX_KNOWN 64           /* roots of the lifted torus system kept for deflation */
#define NEAR_ROOT 0.1          /* on the whole torus, every node with a lifted residual below this starts Newton */
/* A deflated run that ends with a residual below this, but not below OM_ROOT_TOL, is finished
 * undeflated from its end: next to a known root deflation's factor, 1 + 1 / |x - x_k|^2 (3e9 at a
 * near-double root's 1.8e-5), lifts the residual's rounding above the tolerance. */
#define DEFLATED_END 1e-8
#define PARTNER_CELLS 2.0      /* a root's fold partner is sought this many grid cells away at most */
#define PARTNER_SAMPLES 8      /* samples each way along the fold direction */
/* A window's fold partners are sought this many radii away at most: any other root of the window
 * lies within 2 radii of a root found in each of w1, w7 and phi4 (both within a radius of the
 * hint's joints), 2 sqrt(3) radii in all. */
#define WINDOW_PARTNERS 3.5
#define WINDOW_REACH 3.0 /* radii from the hint's (w1, w7) beyond which a window's Newton run gives up */

#define TRACE_STARTS 1024 /* starts of one search from the traced self-motion (a handful a root) */
#define TERMS_KEY 13 /* the flange pose (R, p) and the grid's side */

/* One ELBOW branch's terms at the whole torus' grid for the pose of its key. */
typedef struct {
    bool valid;
    double key[TERMS_KEY];
    om_srs_lifted_terms *terms; /* cap of them */
    size_t cap;
    om_trace *trace;            /* the self-motion traced at the pose of key (NULL: not yet) */
    bool untraced;              /* where om_trace_new failed: the grid's starts instead */
    half_line_chart charts[LINE_POINTS]; /* psi's half-line's points in the grid (n_charts; -1: not yet) */
    int n_charts;
} terms_grid;

/* An S-R-S arm's searches of the whole torus at one pose, in a grid of arm angles (solve_grid: each in 8
 * branches), sample the same nodes again and again, and there the lifted residual is linear in cos psi
 * and sin psi (om_srs_lifted_terms): a search whose pose is the last one's takes the terms and
 * evaluates them at its psi. */
struct om_torus_memo {
    terms_grid branches[2]; /* ELBOW -1, +1 */
};

om_torus_memo *om_torus_memo_new(const om_solver_data *s)
{
    if (s->family != OM_SRS || s->mode != OM_TORUS)
        return NULL;
    om_torus_memo *memo = malloc(sizeof(om_torus_memo));
    for (int b = 0; memo && b < 2; b++)
        memo->branches[b] = (terms_grid){.valid = false, .n_charts = -1};
    return memo;
}

void om_torus_memo_take(om_torus_memo *into, om_torus_memo *from)
{
    for (int b = 0; into && from && b < 2; b++) {
        terms_grid *kept = &into->branches[b], *taken = &from->branches[b];
        if (!taken->valid || !taken->trace || kept->valid)
            continue;
        *kept = *taken;
        *taken = (terms_grid){.valid = false, .n_charts = -1};
        free(kept->terms); /* (the windows read the trace and its pose's key alone) */
        kept->terms = NULL;
        kept->cap = 0;
    }
}

void om_torus_memo_free(om_torus_memo *memo)
{
    if (memo) {
        free(memo->branches[0].terms);
        free(memo->branches[1].terms);
        om_trace_free(memo->branches[0].trace);
        om_trace_free(memo->branches[1].trace);
    }
    free(memo);
}

/* A grid's key: pb's pose (R, p) and the grid's nodes a side, m. */
static void _grid_key(const om_problem *pb, int m, double *key)
{
    const mat3 *R = &pb->t.R;
    double k[TERMS_KEY] = {R->r0.x, R->r0.y, R->r0.z, R->r1.x, R->r1.y, R->r1.z, R->r2.x,
                           R->r2.y, R->r2.z, pb->p.x, pb->p.y, pb->p.z, (double)m};
    memcpy(key, k, sizeof k);
}

/* The self-motion at pb's pose and ELBOW sign that pb->traces keeps traced (NULL: none; the
 * trace does not depend on the grid it was seeded from: the key's pose alone is compared). */
static const om_trace *_kept_trace(const om_problem *pb)
{
    if (!pb->traces)
        return NULL;
    const terms_grid *grid = &pb->traces->branches[pb->signs[1] > 0];
    double key[TERMS_KEY];
    _grid_key(pb, 0, key);
    bool same = grid->valid && memcmp(key, grid->key, (TERMS_KEY - 1) * sizeof(double)) == 0;
    return same ? grid->trace : NULL;
}

/* The lifted residual's terms at the m x m nodes (lo + step i, lo + step j) for pb's pose and
 * ELBOW sign (NaN where W = S): the torus memo's where it holds this grid's, else computed, into
 * the memo where the problem has one, else into *scratch (allocated; the caller frees it). NULL:
 * out of memory. */
static const om_srs_lifted_terms *_grid_terms(om_problem *pb, double lo, double step, int m,
                                              om_srs_lifted_terms **scratch)
{
    double key[TERMS_KEY];
    _grid_key(pb, m, key);
    double elbow = (double)pb->signs[1];
    terms_grid *grid = pb->torus_memo ? &pb->torus_memo->branches[elbow > 0.0] : NULL;
    if (grid && grid->valid && memcmp(key, grid->key, sizeof key) == 0)
        return grid->terms;
    size_t mm = (size_t)m * (size_t)m;
    om_srs_lifted_terms *terms;
    if (grid) {
        om_trace_free(grid->trace);
        grid->trace = NULL;
        grid->untraced = false;
        grid->n_charts = -1;
        if (grid->cap < mm) {
            grid->valid = false;
            free(grid->terms);
            grid->terms = malloc(mm * sizeof(om_srs_lifted_terms));
            grid->cap = grid->terms ? mm : 0;
        }
        terms = grid->terms;
    } else {
        terms = *scratch = malloc(mm * sizeof(om_srs_lifted_terms));
    }
    if (!terms)
        return NULL;
    for (int i = 0; i < m; i++) {
        for (int j = 0; j < m; j++) {
            double w1 = lo + (double)i * step, w7 = lo + (double)j * step;
            om_srs_lifted_terms *k = &terms[i * m + j];
            if (!om_srs_lifted_terms_at(pb->s->params, &pb->t, om_torus_point(pb, w1, w7), elbow, w1, w7, NAN, k))
                *k = (om_srs_lifted_terms){{NAN, NAN, NAN}, {NAN, NAN, NAN}, NAN, NAN};
        }
    }
    if (grid) {
        memcpy(grid->key, key, sizeof key);
        grid->valid = true;
    }
    return terms;
}

/* The self-motion at the pose and ELBOW sign of the torus memo's grid (its terms, computed by
 * _grid_terms), traced on first use; NULL where that failed (om_trace_new). */
static const om_trace *_grid_trace(om_problem *pb, terms_grid *grid, double lo, double step, int m)
{
    if (!grid->trace && !grid->untraced) {
        grid->trace = om_trace_new(pb, grid->terms, lo, step, m);
        grid->untraced = !grid->trace;
    }
    return grid->trace;
}

/* Whether A (m x m) changes sign over the grid cell (i, j) (four reachable corners, no wrap). */
static bool _crosses(const double *A, int m, int i, int j)
{
    double lo = INFINITY, hi = -INFINITY;
    double corners[4] = {A[i * m + j], A[(i + 1) * m + j], A[i * m + j + 1], A[(i + 1) * m + j + 1]};
    for (int k = 0; k < 4; k++) {
        double a = corners[k];
        if (isnan(a))
            return false;
        lo = py_min(lo, a);
        hi = py_max(hi, a);
    }
    return lo <= 0.0 && 0.0 <= hi && hi - lo < OM_PI;
}

/* The known roots (n x 3), grown as needed: the fold-partner search can add roots after the
 * first MAX_KNOWN, and must never write past the end. */
typedef struct {
    double *x;    /* cap x 3 */
    double *near; /* cap: how near an undeflated Newton run gives up to each (newton_limits) */
    int cap;
} known_roots;

/* One search's state: its known roots, candidates so far (into roots, logged as torus_candidate
 * does), how far a root's fold partners are sought, and a window's centre (w1, w7) and the
 * reach beyond which its Newton runs give up (INFINITY on the whole torus). */
typedef struct {
    om_problem *pb;
    known_roots known;
    int n_known, count;
    double *roots, *q; /* q: the model IK of the last Newton run's end */
    om_candidate_log *log;
    double partner_reach, w1, w7, reach;
} torus_search;

/* The root x appended to the known ones; returns whether it was (out of memory: not). */
static bool _keep(torus_search *t, vec3 x)
{
    known_roots *known = &t->known;
    if (t->n_known >= known->cap) {
        int cap = 2 * known->cap;
        double *grown = realloc(known->x, (size_t)cap * 3 * sizeof(double));
        if (grown)
            known->x = grown;
        double *near = grown ? realloc(known->near, (size_t)cap * sizeof(double)) : NULL;
        if (!near)
            return false; /* out of memory: not kept */
        known->near = near;
        known->cap = cap;
    }
    known->near[t->n_known] = 0.0; /* until its fold partners are sought */
    known->x[3 * t->n_known] = x.x;
    known->x[3 * t->n_known + 1] = x.y;
    known->x[3 * t->n_known + 2] = x.z;
    t->n_known++;
    return true;
}

/* Newton's method from x, deflated by the known roots if deflate; a new root is appended to the
 * known ones and handed to verification. Returns whether one was; *converging (unless NULL):
 * whether the run gave up next to a known root instead, on its way there. */
static bool _new_root(torus_search *t, vec3 x, bool deflate, bool *converging)
{
    vec3 x_root;
    known_roots *known = &t->known;
    newton_limits limits = {t->w1, t->w7, t->reach, known->x, known->near, t->n_known};
    double r = om_lifted_newton(t->pb, NULL, x, t->q, known->x, deflate ? t->n_known : 0, &limits, &x_root);
    if (converging)
        *converging = !deflate && isinf(r) && near_known(&limits, x_root);
    if (deflate && r > OM_ROOT_TOL && r < DEFLATED_END) /* (not where the run gave up: inf) */
        r = om_lifted_newton(t->pb, NULL, x_root, t->q, known->x, 0, &limits, &x_root);
    if (r > OM_ROOT_TOL)
        return false;
    for (int k = 0; k < t->n_known; k++)
        if (same_point(x_root, v_load(known->x, 3 * k)))
            return false;
    if (!_keep(t, x_root))
        return false;
    t->count = torus_candidate(t->pb, t->q, t->roots, t->count, t->log);
    return true;
}

/* Unit vector nearest the null space of a nearly singular 3x3 matrix (given by rows):
 * the longest cross product of two rows. */
static vec3 _null_vector(const vec3 *rows)
{
    vec3 best = v_cross(rows[0], rows[1]);
    vec3 cs[2] = {v_cross(rows[1], rows[2]), v_cross(rows[2], rows[0])};
    for (int k = 0; k < 2; k++) {
        if (v_dot(cs[k], cs[k]) > v_dot(best, best))
            best = cs[k];
    }
    return v_unit(best);
}

/* Starts for the partners of the root x, if x is one of a close pair (a fold of the
 * lifted system): into starts (3); returns the count. *gap: the distance to the partner that the
 * quadratic model along the fold direction predicts (inf: none). */
static int _fold_partners(om_problem *pb, vec3 x, double reach, double *q, vec3 *starts, double *gap)
{
    double eps = 1e-7;
    vec3 F = om_lifted_residual(pb, x, q);
    vec3 F0 = om_lifted_residual(pb, v3(x.x + eps, x.y, x.z), q);
    vec3 F1 = om_lifted_residual(pb, v3(x.x, x.y + eps, x.z), q);
    vec3 F2 = om_lifted_residual(pb, v3(x.x, x.y, x.z + eps), q);
    vec3 cols[3] = {
        v_scale(1.0 / eps, v3(F0.x - F.x, F0.y - F.y, F0.z - F.z)),
        v_scale(1.0 / eps, v3(F1.x - F.x, F1.y - F.y, F1.z - F.z)),
        v_scale(1.0 / eps, v3(F2.x - F.x, F2.y - F.y, F2.z - F.z)),
    };
    vec3 rows[3] = {
        v3(cols[0].x, cols[1].x, cols[2].x),
        v3(cols[0].y, cols[1].y, cols[2].y),
        v3(cols[0].z, cols[1].z, cols[2].z),
    };
    vec3 v = _null_vector(rows), u = _null_vector(cols);
    double slope = v_dot(u, v_add(v_add(v_scale(v.x, cols[0]), v_scale(v.y, cols[1])), v_scale(v.z, cols[2])));
    int n = 0;
    double h = reach / PARTNER_SAMPLES;
    /* A partner closer than the samples (a near-double root): the second zero of the
     * quadratic u.F = slope t + c t^2, c from one more point. */
    double d = 1e-4;
    double c = (v_dot(u, om_lifted_residual(pb, v_add(x, v_scale(d, v)), q)) - v_dot(u, F) - slope * d) / (d * d);
    double t = -slope / c;
    *gap = isnan(t) ? INFINITY : fabs(t);
    if (fabs(t) < h) /* also not NaN */
        starts[n++] = v_add(x, v_scale(t, v));
    static const double directions[2] = {-1.0, 1.0};
    for (int s = 0; s < 2; s++) {
        double direction = directions[s];
        double t_prev = 0.0, f_prev = 0.0;
        for (int k = 1; k < PARTNER_SAMPLES + 1; k++) {
            t = direction * (double)k * h;
            double f = v_dot(u, om_lifted_residual(pb, v_add(x, v_scale(t, v)), q));
            if (isnan(f))
                break;
            if (f * slope * direction < 0.0) { /* u.F has come back through zero */
                if (k > 1)
                    t = t_prev + (t - t_prev) * f_prev / (f_prev - f);
                starts[n++] = v_add(x, v_scale(t, v));
                break;
            }
            t_prev = t;
            f_prev = f;
        }
    }
    return n;
}

/* The fold partners of the known roots from first on, and of theirs (MAX_KNOWN roots in all);
 * each root's runs then give up within KNOWN_REACH of it, or a tenth of its predicted partner's
 * distance where that is nearer (a near-double root's partner, which Newton may reach where
 * the partner's own start fails). */
static void _partners(torus_search *t, int first)
{
    vec3 partners[3];
    for (int k = first; k < t->n_known && t->n_known < MAX_KNOWN; k++) {
        vec3 root = v_load(t->known.x, 3 * k);
        double gap;
        int n = _fold_partners(t->pb, root, t->partner_reach, t->q, partners, &gap);
        t->known.near[k] = py_min(KNOWN_REACH, 0.1 * gap);
        for (int a = 0; a < n; a++)
            if (!_new_root(t, partners[a], true, NULL)) /* the line bends away from the partner: halfway */
                _new_root(t, v_scale(0.5, v_add(partners[a], root)), true, NULL);
    }
}

/* The roots Newton finds from the start x (from the nearer edge of reach's elbow where its run
 * stalls), on the whole torus then from x again deflated until none, and their fold partners. */
static void _roots_from(torus_search *t, vec3 x)
{
    int first = t->n_known;
    bool converging;
    if (!_new_root(t, x, false, &converging)) {
        /* Near the edge of reach the elbow angle changes fastest: a run that stalls tries once
         * more from the nearer edge's (the straight or the folded elbow). One that gave up next
         * to a known root was converging to it: x lies in that root's basin, not at the edge. */
        if (converging)
            return;
        double straight = straight_elbow(t->pb->s);
        double edge = cos(x.z - straight) > 0.0 ? straight : straight + OM_PI;
        if (!_new_root(t, v3(x.x, x.y, edge), false, NULL))
            return;
    }
    while (isinf(t->reach) && t->n_known < MAX_KNOWN && _new_root(t, x, true, NULL))
        ;
    _partners(t, first);
}

/* Bounded search on the torus (w1, w7) of an arm with shoulder offsets; returns the count.
 * The lifted residual is sampled on an n x n grid (the square of half-width radius around
 * the centre's (q1, q7) when radius < pi: a window; an S-R-S arm's whole torus from the terms of
 * its nodes, om_srs_lifted_terms, which the searches of one pose share at every arm angle through
 * pb->torus_memo); Newton starts from local minima of its
 * norm and from cells where the shoulder and wrist residuals change sign, with deflation and
 * fold partners; and around the points of psi's singular half-line, where the lifted residual
 * turns about a point, in their charts (om_half_line_roots). The candidates go to verification
 * in order, into log too (NULL: none).
 *
 * Undeflated Newton runs give up within KNOWN_REACH of a known root, where they would end
 * (newton_limits). A window seeks the roots nearer the centre than a root found already (found:
 * its joints; NULL none), which it starts from; its runs give up beyond WINDOW_REACH radii of
 * the centre, whose roots it does not seek; it does not deflate, and seeks each root's fold
 * partners across the window (WINDOW_PARTNERS): a root of the window near one known is such a
 * partner, and one farther from every known root has a local minimum of the norm of its own on
 * the grid, as on the whole torus. n = 0: a window without a grid (no wider than a cell of the
 * whole torus' grid: search.c, _window_side), the root found and its fold partners alone. A
 * window at a pose whose traced self-motion pb->traces keeps (a sweep's follows) starts from the
 * trace's crossings within its reach instead of its grid and the fold partners of the root
 * found, as the batch's searches of the whole torus started. */
int om_torus_roots(om_problem *pb, int n, double *roots, const double *centre, double radius, const double *found,
                   om_candidate_log *log)
{
    double q[OM_MAX_DOF];
    nan_fill(q, OM_MAX_DOF); /* read as E where W = S at the first node: NaN */
    bool whole = radius >= OM_PI;
    double lo1, lo7, span;
    if (whole) {
        lo1 = -OM_PI;
        lo7 = -OM_PI;
        span = 2.0 * OM_PI;
    } else {
        lo1 = centre[torus_joint(pb->s, 0)] - radius;
        lo7 = centre[torus_joint(pb->s, 1)] - radius;
        span = 2.0 * radius;
    }
    bool grid = n > 0; /* (a window without a grid: its square one cell, for psi's half-line) */
    double step = span / (double)(grid ? n : 1);
    int m = (grid ? n : 1) + 1; /* on the whole torus the last row and column repeat the first */
    size_t mm = (size_t)m * (size_t)m;
    double *S = malloc(4 * mm * sizeof(double));
    known_roots known = {malloc((size_t)MAX_KNOWN * 3 * sizeof(double)), malloc(MAX_KNOWN * sizeof(double)), MAX_KNOWN};
    torus_search t = {pb,   known, 0, 0, roots, q, log, PARTNER_CELLS * step, centre[torus_joint(pb->s, 0)],
                      centre[torus_joint(pb->s, 1)], INFINITY};
    if (!S || !t.known.x || !t.known.near) {
        free(S);
        free(t.known.x);
        free(t.known.near);
        return 0;
    }
    if (!whole) {
        t.reach = WINDOW_REACH * radius;
        t.partner_reach = py_max(t.partner_reach, WINDOW_PARTNERS * radius);
    }
    double *W = S + mm, *F = W + mm, *E = F + mm;
    /* An arm near a family: the whole torus' grid samples its nominal arm's system (g~ of near.c,
     * one model IK a node instead of a fixed point of the correction), and Newton refines every
     * start on G. |G - g~| <= |dg/dX| delta (near.c: 20 per metre away from the singular set,
     * half a radian at the TIAGo Pro's 26 mm) stays below OM_PAIR_SEARCH: a root of G lies at a
     * dip of |g~|, which the grid's starts take, as the circle's scan of g~ has it. A window's
     * grid samples G: its cells are finer than the nominal arm's roots lie from the real arm's
     * (about the offsets over the arm's reach), so a dip of |g~| there need not be one of |G|. */
    pb->nominal = whole && pb->s->nominal_table != NULL;
    /* On an S-R-S arm's whole torus the nodes' residuals come from their terms (the same for every
     * arm angle: the torus memo's), one evaluation each. */
    om_srs_lifted_terms *scratch = NULL;
    const om_srs_lifted_terms *terms = NULL;
    if (whole && grid && pb->s->family == OM_SRS && !(terms = _grid_terms(pb, lo1, step, m, &scratch))) {
        free(S);
        free(t.known.x);
        free(t.known.near);
        return 0;
    }
    /* A batch's searches of one pose (the torus memo's, holding its grid's terms) start from its
     * traced self-motion instead of the grid's starts: one start a root (an arm near a family: the
     * grid's, its Newton on G); and find psi's half-line's points once. */
    terms_grid *memo = terms && pb->torus_memo ? &pb->torus_memo->branches[pb->signs[1] > 0] : NULL;
    const om_trace *trace = memo && !pb->s->nominal_table ? _grid_trace(pb, memo, lo1, step, m) : NULL;
    /* A window at a pose whose self-motion a batch traced and kept (pb->traces: a follow's scan
     * for a root nearer its hint) starts from the trace's crossings within its reach instead of
     * its grid's starts and the found root's fold partners: the starts of the batch's searches of
     * the whole torus, a fold's pair of roots among them. */
    const om_trace *kept = whole ? NULL : _kept_trace(pb);
    grid = grid && !kept;
    for (int i = 0; i < m && grid && !trace; i++) {
        for (int j = 0; j < m; j++) {
            vec3 r;
            if (terms) {
                const om_srs_lifted_terms *k = &terms[i * m + j];
                pb->counter++;
                r = om_srs_lifted_at(k, pb->t.cos_psi, pb->t.sin_psi);
                double theta4 = pb->s->params[SRS_THETA + 3];
                E[i * m + j] = om_wrap(k->phi4 - theta4) + theta4; /* (lifted_elbow's bits) */
            } else {
                r = om_lifted_residual(pb, v3(lo1 + (double)i * step, lo7 + (double)j * step, NAN), q);
                E[i * m + j] = lifted_elbow(pb->s, q);
            }
            S[i * m + j] = r.x;
            W[i * m + j] = r.y;
            F[i * m + j] = om_max_norm(r) < INFINITY ? om_max_norm(r) : INFINITY;
        }
    }
    free(scratch);
    pb->nominal = false;
    if (found && !whole) { /* (a verified root: known as it is, the window's incumbent, not a candidate) */
        _keep(&t, lifted_point(pb->s, found));
        if (!kept)
            _partners(&t, 0);
    }
    if (trace || kept) {
        pb->counter += trace ? om_trace_evaluations(trace) : 0;
        vec3 starts[TRACE_STARTS];
        bool fold[TRACE_STARTS];
        int n_starts = om_trace_starts(trace ? trace : kept, pb->t.psi, starts, fold, TRACE_STARTS);
        for (int k = 0; k < n_starts && t.n_known < MAX_KNOWN; k++) {
            if (py_max(fabs(om_wrap(starts[k].x - t.w1)), fabs(om_wrap(starts[k].y - t.w7))) > t.reach)
                continue; /* (a window's runs give up there) */
            if (fold[k])
                _roots_from(&t, starts[k]);
            else
                _new_root(&t, starts[k], false, NULL);
        }
    }
    for (int i = 0; i < m && grid && !trace; i++) {
        for (int j = 0; j < m; j++) {
            for (int centre_of_cell = 0; centre_of_cell < 2; centre_of_cell++) {
                bool start;
                vec3 x;
                if (centre_of_cell) {
                    start = i < n && j < n && _crosses(S, m, i, j) && _crosses(W, m, i, j);
                    x = v3(lo1 + ((double)i + 0.5) * step, lo7 + ((double)j + 0.5) * step, E[i * m + j]);
                } else {
                    start = F[i * m + j] < OM_PAIR_SEARCH;
                    int ii_end = i + 2 < m ? i + 2 : m, jj_end = j + 2 < m ? j + 2 : m;
                    for (int ii = i - 1 > 0 ? i - 1 : 0; ii < ii_end; ii++)
                        for (int jj = j - 1 > 0 ? j - 1 : 0; jj < jj_end; jj++)
                            start = start && F[ii * m + jj] >= F[i * m + j];
                    start = start || (whole && F[i * m + j] < NEAR_ROOT);
                    x = v3(lo1 + (double)i * step, lo7 + (double)j * step, E[i * m + j]);
                }
                if (start && t.n_known < MAX_KNOWN)
                    _roots_from(&t, x);
            }
        }
    }
    half_line_chart own[LINE_POINTS];
    if (memo && memo->n_charts < 0)
        memo->n_charts = om_half_line_points(pb, lo1, lo7, step, m, memo->charts);
    int n_charts = memo ? memo->n_charts : om_half_line_points(pb, lo1, lo7, step, m, own);
    int count = om_half_line_roots(pb, memo ? memo->charts : own, n_charts, q, roots, t.count, log);
    if (pb->s->family != OM_SRS && grid)
        count = om_shoulder_edge_roots(pb, lo1, lo7, step, m, q, roots, count, log);
    free(S);
    free(t.known.x);
    free(t.known.near);
    return count;
}
