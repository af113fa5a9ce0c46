/* The self-motion of an S-R-S arm with shoulder offsets traced on the lifted torus, once per pose
 * and ELBOW sign: the starts of a batch's whole-torus searches (om_torus_roots), one for each root
 * of each arm angle, instead of the grid's starts at each (the method: om_redundant/ik/kernel_data.py).
 *
 * Every root of every arm angle lies on the curve C = {y = (w1, w7, phi4, psi): F(y) = 0}, F the
 * lifted residual (shoulder, wrist, elbow) with psi a coordinate: three equations in four unknowns,
 * smooth but where W = S. Each closed component of C is traced once by predictor-corrector
 * continuation; a search at psi then starts Newton from each point where the trace crosses psi.
 * The components are found from the seeds the grid's starts would take at some psi (torus.c):
 * where Phi, the condition that the shoulder's and the wrist's residuals vanish at one psi, changes
 * sign along an edge of the grid; at the nodes where both come within NEAR_CURVE of zero at some
 * psi, or nearer than at the nodes around; at the dips of Phi (two contours within a cell); and
 * where the edges cross the elbow's edge of reach (a path hugging the straight or folded elbow).
 * A seed is moved onto C by Newton's minimal-norm steps and traced unless it lies on a component
 * traced already; one that lands on a traced component from a node between two is tried again
 * mirrored across it. Where a trace cannot finish (MAX_STEPS, memory), the searches take the
 * grid's starts instead. */
#include "torus.h"

#define STEP_FIRST 0.02   /* the continuation's first step (rad, in y) */
#define STEP_MAX 0.2      /* its longest: a cell and a half of the grid, two rows of psi */
#define STEP_MIN 1e-9     /* its shortest: a trace that needs a shorter one ends there (W = S) */
#define TURN_COS 0.95     /* the tangents of a step's ends turn by 18 deg at most */
#define MAX_STEPS 20000   /* steps each way from a component's seed */
#define VERTEX_TOL 1e-9   /* a vertex's residual: the searches' Newton runs finish their starts */
#define SEED_TOL 1e-7     /* a seed's residual where it is compared with the traced components */
#define COVER_TOL 1e-4    /* a seed within this of a traced segment (and its sag) lies on it */
#define COVER_SAG 0.05    /* a chord's sag, as a fraction of its length, at TURN_COS */
/* A node whose residual comes this near zero at some psi is a seed (the grid's NEAR_ROOT, 0.1,
 * found no more components on 600 Sawyer poses, and a pose's two traces took 12 ms, not 7). */
#define NEAR_CURVE 0.02
#define EDGE_INTO 0.05    /* an edge-of-reach seed's elbow this far into its sheet (rad) */
#define SEED_REACH 0.6    /* how far a seed's Newton run may move it onto the curve (rad, in y) */
#define FOLD_NEAR 0.01    /* a search this near a fold's psi seeks the fold's pair of roots from it */
#define PSI_SAMPLES 64    /* arm angles at which a node's nearness to the curve is sampled */

typedef struct {
    double y[4]; /* (w1, w7, phi4, psi), unwrapped along its component; psi NaN: between components */
    bool fold;   /* psi turns here */
} trace_vertex;

struct om_trace {
    trace_vertex *v;
    int *next; /* each vertex's next in its grid cell's list (-1: none) */
    int n, cap;
    int side;          /* grid cells a side */
    double lo, step;   /* the grid's */
    int *head;         /* each grid cell's first vertex (-1: none) */
    uint16_t *crossed; /* 2 x side x side: how often the trace crosses each edge of the grid */
    int64_t evaluations;
};

static bool _push(om_trace *tr, const double *y, bool fold)
{
    if (tr->n >= tr->cap) {
        int cap = tr->cap ? 2 * tr->cap : 1024;
        trace_vertex *v = realloc(tr->v, (size_t)cap * sizeof(trace_vertex));
        if (v)
            tr->v = v;
        int *next = v ? realloc(tr->next, (size_t)cap * sizeof(int)) : NULL;
        if (!next)
            return false;
        tr->next = next;
        tr->cap = cap;
    }
    memcpy(tr->v[tr->n].y, y, sizeof tr->v[tr->n].y);
    tr->v[tr->n++].fold = fold;
    return true;
}

/* F(y) into F, and (J not NULL) its Jacobian (3 x 4, by rows): in (w1, w7, phi4) by forward
 * differences, in psi from the terms. false where not finite. */
static bool _residual(om_problem *pb, double elbow, const double *y, double *F, double *J)
{
    om_srs_lifted_terms k;
    pb->counter++;
    if (!om_srs_lifted_terms_at(pb->s->params, &pb->t, om_torus_point(pb, y[0], y[1]), elbow, y[0], y[1], y[2], &k))
        return false;
    double c = cos(y[3]), s = sin(y[3]);
    vec3 r = om_srs_lifted_at(&k, c, s);
    F[0] = r.x, F[1] = r.y, F[2] = r.z;
    if (!(isfinite(F[0]) && isfinite(F[1]) && isfinite(F[2])))
        return false;
    if (!J)
        return true;
    J[3] = -k.shoulder[1] * s + k.shoulder[2] * c;
    J[7] = -k.wrist[1] * s + k.wrist[2] * c;
    J[11] = 0.0;
    double eps = 1e-7;
    for (int i = 0; i < 3; i++) {
        double z[4] = {y[0], y[1], y[2], y[3]}, Fz[3];
        z[i] += eps;
        if (!_residual(pb, elbow, z, Fz, NULL))
            return false;
        for (int r = 0; r < 3; r++)
            J[4 * r + i] = (Fz[r] - F[r]) / eps;
    }
    return true;
}

/* The unit tangent of C where F's Jacobian is J (3 x 4): its null vector (om_null_vector). */
static bool _tangent(const double *J, double *t)
{
    om_null_vector(J, 3, t);
    double norm = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2] + t[3] * t[3]);
    if (!(norm > 0.0))
        return false;
    for (int i = 0; i < 4; i++)
        t[i] /= norm;
    return true;
}

/* Newton's minimal-norm step d = -J^T (J J^T)^-1 F. */
static bool _min_norm_step(const double *J, const double *F, double *d)
{
    double A[9], l[3] = {F[0], F[1], F[2]};
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            A[3 * a + b] = J[4 * a] * J[4 * b] + J[4 * a + 1] * J[4 * b + 1] + J[4 * a + 2] * J[4 * b + 2] +
                           J[4 * a + 3] * J[4 * b + 3];
    if (!om_eliminate(A, l, 3, NULL))
        return false;
    for (int i = 0; i < 4; i++)
        d[i] = -(J[i] * l[0] + J[4 + i] * l[1] + J[8 + i] * l[2]);
    return isfinite(d[0] + d[1] + d[2] + d[3]);
}

/* y moved onto C (to tol) by Newton's minimal-norm steps, the Jacobian kept while the residual
 * falls fourfold a step; false where that does not converge within reach of the start. */
static bool _project(om_problem *pb, double elbow, double *y, double reach, double tol)
{
    double z[4] = {y[0], y[1], y[2], y[3]}, F[3], J[12], d[4], last = INFINITY;
    for (int it = 0; it < 16; it++) {
        bool fresh = it == 0;
        if (!_residual(pb, elbow, z, F, fresh ? J : NULL))
            return false;
        double r = om_max_norm(v_load(F, 0));
        if (r < tol) {
            memcpy(y, z, sizeof z);
            return true;
        }
        if (!fresh && !(r < 0.25 * last) && !_residual(pb, elbow, z, F, J))
            return false;
        last = r;
        if (!_min_norm_step(J, F, d))
            return false;
        double size = py_max(py_max(fabs(d[0]), fabs(d[1])), py_max(fabs(d[2]), fabs(d[3])));
        double f = size > 0.5 ? 0.5 / size : 1.0;
        for (int i = 0; i < 4; i++)
            z[i] += f * d[i];
        if (om_wrapped_distance_max(z, y, 4) > reach)
            return false;
    }
    return false;
}

static int _cell_of(const om_trace *tr, double w)
{
    return ((int)floor((w - tr->lo) / tr->step) % tr->side + tr->side) % tr->side;
}

/* The grid's edges that the segment a -> b crosses, counted (at most one line of the grid each
 * way: the segment is shorter than a cell). */
static void _mark_crossings(om_trace *tr, const double *a, const double *b)
{
    int side = tr->side;
    for (int c = 0; c < 2; c++) { /* c 0: a line w1 = lo + i step, 1: a line w7 = lo + i step */
        double ia = floor((a[c] - tr->lo) / tr->step), ib = floor((b[c] - tr->lo) / tr->step);
        if (ia == ib)
            continue;
        double line = tr->lo + py_max(ia, ib) * tr->step;
        double along = a[1 - c] + (line - a[c]) / (b[c] - a[c]) * (b[1 - c] - a[1 - c]);
        int i = ((int)py_max(ia, ib) % side + side) % side, j = _cell_of(tr, along);
        uint16_t *crossed = &tr->crossed[((size_t)c * side + (size_t)i) * side + j];
        if (*crossed < UINT16_MAX)
            (*crossed)++;
    }
}

/* The fold between the vertices x and z, where psi's rate along the curve goes from ta to tb (of
 * opposite signs): where it vanishes, by regula falsi along the chord, each point moved onto C. */
static bool _fold_between(om_problem *pb, double elbow, const double *x, double ta, const double *z, double tb,
                          double *fold)
{
    double lo = 0.0, hi = 1.0, g_lo = ta, g_hi = tb, best = INFINITY, chord[4];
    for (int i = 0; i < 4; i++)
        chord[i] = z[i] - x[i];
    for (int it = 0; it < 12 && hi - lo > 1e-12; it++) {
        double u = lo + (hi - lo) * g_lo / (g_lo - g_hi), p[4], F[3], J[12], t[4];
        if (!(u > lo && u < hi))
            u = 0.5 * (lo + hi);
        for (int i = 0; i < 4; i++)
            p[i] = x[i] + u * chord[i];
        if (!_project(pb, elbow, p, 0.5 * om_wrapped_distance_max(x, z, 4) + 1e-9, VERTEX_TOL) || !_residual(pb, elbow, p, F, J) ||
            !_tangent(J, t))
            break;
        double along = t[0] * chord[0] + t[1] * chord[1] + t[2] * chord[2] + t[3] * chord[3];
        double g = along < 0.0 ? -t[3] : t[3];
        if (fabs(g) < best) {
            best = fabs(g);
            memcpy(fold, p, sizeof p);
        }
        if (fabs(g) < 1e-10)
            break;
        if ((g < 0.0) == (g_lo < 0.0)) { /* (Illinois: the stale end's value halved) */
            lo = u;
            g_lo = g;
            g_hi *= 0.5;
        } else {
            hi = u;
            g_hi = g;
            g_lo *= 0.5;
        }
    }
    return best < INFINITY;
}

/* The step from x (tangent t) to z (tangent tz, turned to agree with t) appended: the fold
 * between them first, where psi turns. */
static bool _append_step(om_trace *tr, om_problem *pb, double elbow, const double *x, const double *t,
                         const double *z, double *tz)
{
    if (tz[0] * t[0] + tz[1] * t[1] + tz[2] * t[2] + tz[3] * t[3] < 0.0)
        for (int i = 0; i < 4; i++)
            tz[i] = -tz[i];
    _mark_crossings(tr, x, z);
    double fold[4];
    if (t[3] * tz[3] < 0.0 && _fold_between(pb, elbow, x, t[3], z, tz[3], fold) && !_push(tr, fold, true))
        return false;
    return _push(tr, z, false);
}

/* How a trace from a point ended. */
typedef enum {
    TRACE_ENDED,  /* where the continuation needs a step below STEP_MIN (at W = S) */
    TRACE_CLOSED, /* back at its start: a loop */
    TRACE_FAILED, /* MAX_STEPS, or out of memory: the trace cannot vouch for its component */
} trace_end;

/* Traces C from y0 (on it) along sign times its tangent, appending the vertices after y0 (a loop's
 * last y0 again). Each step: a predictor along the tangent, Newton's minimal-norm steps to
 * VERTEX_TOL, halved where they do not converge, where the tangent turns more than TURN_COS
 * allows or the corrector moves more than half the step. */
static trace_end _trace_from(om_trace *tr, om_problem *pb, double elbow, const double *y0, double sign)
{
    double F[3], J[12], t0[4], t[4], x[4], z[4], d[4], tz[4];
    if (!_residual(pb, elbow, y0, F, J) || !_tangent(J, t0))
        return TRACE_ENDED;
    for (int i = 0; i < 4; i++) {
        t0[i] *= sign;
        t[i] = t0[i];
        x[i] = y0[i];
    }
    double h = STEP_FIRST, length = 0.0;
    for (int step = 0; step < MAX_STEPS && h >= STEP_MIN; step++) {
        for (int i = 0; i < 4; i++)
            z[i] = x[i] + h * t[i];
        bool converged = false;
        int it;
        double last = INFINITY;
        for (it = 0; it < 8; it++) {
            if (!_residual(pb, elbow, z, F, J))
                break;
            double r = om_max_norm(v_load(F, 0));
            if ((converged = r < VERTEX_TOL) || !(r < 0.5 * last) || !_min_norm_step(J, F, d))
                break;
            last = r;
            for (int i = 0; i < 4; i++)
                z[i] += d[i];
        }
        double turn = 0.0, off = 0.0;
        if (converged && _tangent(J, tz)) {
            for (int i = 0; i < 4; i++) {
                turn += tz[i] * t[i];
                off = py_max(off, fabs(z[i] - x[i] - h * t[i]));
            }
        }
        if (!converged || fabs(turn) < TURN_COS || off > 0.5 * h) {
            h *= 0.5;
            continue;
        }
        if (!_append_step(tr, pb, elbow, x, t, z, tz))
            return TRACE_FAILED;
        length += h;
        memcpy(x, z, sizeof x);
        memcpy(t, tz, sizeof t);
        if (length > 3.0 * STEP_MAX && om_wrapped_distance_max(x, y0, 4) < 1.5 * h &&
            t[0] * t0[0] + t[1] * t0[1] + t[2] * t0[2] + t[3] * t0[3] > 0.5) { /* back at y0 */
            double close[4], t_close[4];
            for (int i = 0; i < 4; i++)
                close[i] = x[i] + om_wrap(y0[i] - x[i]);
            memcpy(t_close, t0, sizeof t_close);
            return _append_step(tr, pb, elbow, x, t, close, t_close) ? TRACE_CLOSED : TRACE_FAILED;
        }
        if (it <= 3)
            h = py_min(1.5 * h, STEP_MAX);
    }
    return h < STEP_MIN ? TRACE_ENDED : TRACE_FAILED;
}

/* The vertices from first on filed by their grid cell (w1, w7). */
static void _file(om_trace *tr, int first)
{
    for (int i = first; i < tr->n; i++) {
        if (isnan(tr->v[i].y[3]))
            continue;
        int cell = _cell_of(tr, tr->v[i].y[0]) * tr->side + _cell_of(tr, tr->v[i].y[1]);
        tr->next[i] = tr->head[cell];
        tr->head[cell] = i;
    }
}

/* v[lo, hi) reversed in place. */
static void _reverse(trace_vertex *v, int lo, int hi)
{
    for (hi--; lo < hi; lo++, hi--) {
        trace_vertex swap = v[lo];
        v[lo] = v[hi];
        v[hi] = swap;
    }
}

/* The component of C through y0, appended (a loop from y0 back to it; a path from its one end to
 * its other), then a break; false where a trace failed. */
static bool _trace_component(om_trace *tr, om_problem *pb, double elbow, const double *y0)
{
    int first = tr->n;
    if (!_push(tr, y0, false))
        return false;
    trace_end end = _trace_from(tr, pb, elbow, y0, 1.0);
    if (end == TRACE_FAILED)
        return false;
    if (end == TRACE_ENDED) { /* the other way too, in front, reversed: reverse(A B) then A again */
        int middle = tr->n;
        if (_trace_from(tr, pb, elbow, y0, -1.0) == TRACE_FAILED)
            return false;
        _reverse(tr->v, first, tr->n);
        _reverse(tr->v, tr->n - (middle - first), tr->n);
    }
    _file(tr, first);
    double between[4] = {NAN, NAN, NAN, NAN};
    return _push(tr, between, false);
}

/* Whether y, within a segment's length of a, lies within tol (and the chord's sag) of a -> b. */
static bool _on_segment(const double *a, const double *b, const double *y, double tol)
{
    double ab[4], ay[4], L2 = 0.0, u = 0.0, d2 = 0.0;
    for (int k = 0; k < 4; k++) {
        ab[k] = b[k] - a[k];
        ay[k] = om_wrap(y[k] - a[k]);
        L2 += ab[k] * ab[k];
        u += ay[k] * ab[k];
    }
    u = L2 > 0.0 ? py_min(py_max(u / L2, 0.0), 1.0) : 0.0;
    for (int k = 0; k < 4; k++)
        d2 += (ay[k] - u * ab[k]) * (ay[k] - u * ab[k]);
    return sqrt(d2) < tol + COVER_SAG * sqrt(L2);
}

/* Whether y (on C) lies on a component traced already: next to a segment of it in the cells
 * around y's (a segment is at most STEP_MAX, two cells, long). */
static bool _covered(const om_trace *tr, const double *y)
{
    int side = tr->side, ci = _cell_of(tr, y[0]), cj = _cell_of(tr, y[1]);
    for (int di = -2; di <= 2; di++)
        for (int dj = -2; dj <= 2; dj++)
            for (int i = tr->head[((ci + di + side) % side) * side + (cj + dj + side) % side]; i >= 0;
                 i = tr->next[i]) {
                const double *v = tr->v[i].y;
                if ((i > 0 && !isnan(tr->v[i - 1].y[3]) && _on_segment(tr->v[i - 1].y, v, y, COVER_TOL)) ||
                    (i + 1 < tr->n && !isnan(tr->v[i + 1].y[3]) && _on_segment(v, tr->v[i + 1].y, y, COVER_TOL)))
                    return true;
            }
    return false;
}

/* A seed y: onto C and traced unless it lies on a component traced already; a seed between two
 * contours (mirrored) is tried again across the one it reached. */
static bool _seed(om_trace *tr, om_problem *pb, double elbow, double *y, double reach, bool mirrored)
{
    double y0[4] = {y[0], y[1], y[2], y[3]};
    if (!_project(pb, elbow, y, reach, SEED_TOL))
        return true;
    if (_covered(tr, y)) {
        if (!mirrored)
            return true;
        for (int i = 0; i < 4; i++)
            y[i] = 2.0 * y0[i] - y[i];
        if (!_project(pb, elbow, y, reach, SEED_TOL) || _covered(tr, y))
            return true;
    }
    return !_project(pb, elbow, y, reach, VERTEX_TOL) || _trace_component(tr, pb, elbow, y);
}

/* Phi at a node's terms, normalised into [-1, 1] (the shoulder's and wrist's residuals
 * s0 + s1 cos psi + s2 sin psi and w0 + w1 cos psi + w2 sin psi vanish at one psi iff
 * N1^2 + N2^2 = D^2), and (psi not NULL) that psi (D's sign decides between psi and psi + pi). */
static double _phi(const om_srs_lifted_terms *k, double *psi)
{
    const double *s = k->shoulder, *w = k->wrist;
    double D = s[1] * w[2] - s[2] * w[1], N1 = s[2] * w[0] - s[0] * w[2], N2 = s[0] * w[1] - s[1] * w[0];
    if (psi)
        *psi = D < 0.0 ? atan2(-N2, -N1) : atan2(N2, N1);
    return (N1 * N1 + N2 * N2 - D * D) / (N1 * N1 + N2 * N2 + D * D);
}

/* A seed at (w1, w7, phi4), at Phi's psi there. */
static bool _seed_at(om_trace *tr, om_problem *pb, double elbow, vec3 x, double reach, bool mirrored)
{
    om_srs_lifted_terms k;
    if (!om_srs_lifted_terms_at(pb->s->params, &pb->t, om_torus_point(pb, x.x, x.y), elbow, x.x, x.y, x.z, &k))
        return true;
    double y[4] = {x.x, x.y, x.z, 0.0};
    _phi(&k, &y[3]);
    return _seed(tr, pb, elbow, y, reach, mirrored);
}

/* The least over PSI_SAMPLES arm angles (cos, sin in cs) of the larger of a node's shoulder and
 * wrist residuals, and its psi. */
static double _least(const om_srs_lifted_terms *k, const double (*cs)[2], double *psi)
{
    double best = INFINITY;
    for (int a = 0; a < PSI_SAMPLES; a++) {
        double r = py_max(fabs(k->shoulder[0] + k->shoulder[1] * cs[a][0] + k->shoulder[2] * cs[a][1]),
                          fabs(k->wrist[0] + k->wrist[1] * cs[a][0] + k->wrist[2] * cs[a][1]));
        if (r < best) {
            best = r;
            *psi = -OM_PI + 2.0 * OM_PI * (double)a / PSI_SAMPLES;
        }
    }
    return best;
}

/* The elbow's reach argument x at (w1, w7) (om_srs_reach; NaN where W = S): the model's elbow
 * reaches W - S where |x| <= 1. */
static double _reach_x(om_problem *pb, double w1, double w7)
{
    double x = NAN;
    om_srs_reach(pb->s->params, &pb->t, om_torus_point(pb, w1, w7), &x);
    return x;
}

/* The components from the seeds (the file's docstring), in order. */
static bool _trace_seeds(om_trace *tr, om_problem *pb, const om_srs_lifted_terms *terms, double elbow)
{
    int side = tr->side, m = side + 1;
    double lo = tr->lo, step = tr->step, cs[PSI_SAMPLES][2];
    for (int a = 0; a < PSI_SAMPLES; a++) {
        cs[a][0] = cos(-OM_PI + 2.0 * OM_PI * (double)a / PSI_SAMPLES);
        cs[a][1] = sin(-OM_PI + 2.0 * OM_PI * (double)a / PSI_SAMPLES);
    }
    double *Phi = malloc((size_t)m * (size_t)m * sizeof(double));
    if (!Phi)
        return false;
    for (int i = 0; i < m * m; i++)
        Phi[i] = _phi(&terms[i], NULL);
    bool ok = true;
    /* Phi's sign changes along an edge not crossed yet (beyond the reach at both ends, where the
     * elbow's root is clamped, they mean nothing) */
    for (int c = 0; c < 2 && ok; c++)
        for (int i = 0; i < side && ok; i++)
            for (int j = 0; j < side && ok; j++) {
                int a = i * m + j, b = c ? (i + 1) * m + j : i * m + j + 1; /* c 0: along w7 */
                bool crossed = tr->crossed[((size_t)c * side + (c ? j : i)) * side + (c ? i : j)] > 0;
                bool beyond = fabs(terms[a].elbow) > 1e-9 && fabs(terms[b].elbow) > 1e-9;
                if (!(isfinite(Phi[a]) && isfinite(Phi[b])) || (Phi[a] < 0.0) == (Phi[b] < 0.0) || crossed || beyond)
                    continue;
                double u = Phi[a] / (Phi[a] - Phi[b]);
                vec3 x = v3(lo + step * (c ? i + u : i), lo + step * (c ? j : j + u),
                            terms[a].phi4 + u * om_wrap(terms[b].phi4 - terms[a].phi4));
                ok = _seed_at(tr, pb, elbow, x, SEED_REACH, false);
            }
    /* nodes within reach near C at some psi (the grid's NEAR_ROOT starts) or nearer it than
     * their neighbours (its dips), and Phi's dips */
    double *least = malloc((size_t)m * (size_t)m * 2 * sizeof(double)), *least_psi = least + (size_t)m * (size_t)m;
    if (!least) {
        free(Phi);
        return false;
    }
    for (int i = 0; i < m * m; i++)
        least[i] = fabs(terms[i].elbow) > 1e-9 ? INFINITY : _least(&terms[i], cs, &least_psi[i]);
    for (int i = 0; i < side && ok; i++)
        for (int j = 0; j < side && ok; j++) {
            const om_srs_lifted_terms *k = &terms[i * m + j];
            double f = least[i * m + j];
            if (!(f < INFINITY))
                continue;
            bool start = true; /* a local minimum */
            for (int d = 0; d < 9 && start; d++)
                start = least[((i + d / 3 - 1 + side) % side) * m + (j + d % 3 - 1 + side) % side] >= f;
            double y[4] = {lo + i * step, lo + j * step, k->phi4, least_psi[i * m + j]};
            if (start || f < NEAR_CURVE)
                ok = _seed(tr, pb, elbow, y, SEED_REACH, true);
            double phi = Phi[i * m + j];
            double around[4] = {Phi[((i + side - 1) % side) * m + j], Phi[((i + 1) % side) * m + j],
                                Phi[i * m + (j + side - 1) % side], Phi[i * m + (j + 1) % side]};
            bool dip = false;
            for (int d = 0; d < 2; d++)
                dip = dip || (phi * around[2 * d] > 0.0 && phi * around[2 * d + 1] > 0.0 &&
                              fabs(phi) < 0.25 * py_min(fabs(around[2 * d]), fabs(around[2 * d + 1])));
            if (ok && dip)
                ok = _seed_at(tr, pb, elbow, v3(y[0], y[1], k->phi4), SEED_REACH, true);
        }
    free(least);
    free(Phi);
    /* the elbow's edge of reach: where the edges cross |x| = 1, the elbow a little into the
     * ELBOW sign's sheet (at the edge the elbow's residual is flat in phi4) */
    double straight = straight_elbow(pb->s);
    for (int c = 0; c < 2 && ok; c++)
        for (int i = 0; i < side && ok; i++)
            for (int j = 0; j < side && ok; j++) {
                double a1 = lo + i * step, a7 = lo + j * step, b1 = c ? a1 + step : a1, b7 = c ? a7 : a7 + step;
                double xa = _reach_x(pb, a1, a7), xb = _reach_x(pb, b1, b7), fa = fabs(xa) - 1.0, fb = fabs(xb) - 1.0;
                if (!(isfinite(fa) && isfinite(fb)) || (fa <= 0.0) == (fb <= 0.0))
                    continue;
                double u = fa / (fa - fb);
                bool straight_edge = xa + xb > 0.0;
                double phi4 = straight_edge ? straight + elbow * EDGE_INTO : straight + OM_PI - elbow * EDGE_INTO;
                ok = _seed_at(tr, pb, elbow, v3(a1 + u * (b1 - a1), a7 + u * (b7 - a7), phi4), SEED_REACH, false);
            }
    return ok;
}

om_trace *om_trace_new(om_problem *pb, const om_srs_lifted_terms *terms, double lo, double step, int m)
{
    om_trace *tr = calloc(1, sizeof(om_trace));
    if (!tr)
        return NULL;
    int side = m - 1;
    tr->side = side;
    tr->lo = lo;
    tr->step = step;
    tr->crossed = calloc((size_t)2 * (size_t)side * (size_t)side, sizeof(uint16_t));
    tr->head = malloc((size_t)side * (size_t)side * sizeof(int));
    for (int i = 0; tr->head && i < side * side; i++)
        tr->head[i] = -1;
    int64_t before = pb->counter;
    bool traced = tr->crossed && tr->head && _trace_seeds(tr, pb, terms, (double)pb->signs[1]);
    tr->evaluations = pb->counter - before;
    pb->counter = before;
    if (!traced) {
        om_trace_free(tr);
        return NULL;
    }
    return tr;
}

void om_trace_free(om_trace *tr)
{
    if (tr) {
        free(tr->v);
        free(tr->next);
        free(tr->head);
        free(tr->crossed);
    }
    free(tr);
}

int64_t om_trace_evaluations(const om_trace *tr)
{
    return tr->evaluations;
}

int om_trace_starts(const om_trace *tr, double psi, vec3 *starts, bool *fold, int cap)
{
    int n = 0;
    for (int i = 0; i + 1 < tr->n && n < cap; i++) {
        const double *a = tr->v[i].y, *b = tr->v[i + 1].y;
        if (isnan(a[3]) || isnan(b[3]))
            continue;
        double p = psi + 2.0 * OM_PI * ceil((py_min(a[3], b[3]) - psi) / (2.0 * OM_PI));
        if (p < py_max(a[3], b[3])) {
            /* (psi is quadratic in the arc next to a fold) */
            double u = (p - a[3]) / (b[3] - a[3]);
            if (tr->v[i].fold != tr->v[i + 1].fold)
                u = tr->v[i].fold ? sqrt(u) : 1.0 - sqrt(1.0 - u);
            starts[n] = v3(a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1]), a[2] + u * (b[2] - a[2]));
            fold[n++] = false;
        }
        if (tr->v[i + 1].fold && fabs(om_wrap(b[3] - psi)) < FOLD_NEAR && n < cap) {
            starts[n] = v3(b[0], b[1], b[2]);
            fold[n++] = true;
        }
    }
    return n;
}
