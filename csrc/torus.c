/* Damped Newton on the lifted system, and the bounded search on the torus
 * (the method: om_redundant/om/system.py). */
#include "om_system.h"

#define TORUS_SIDE 0.75        /* the torus grid has TORUS_SIDE * scan points nodes per side (search.c) */
#define MAX_KNOWN 64           /* roots of the lifted torus system kept for deflation */
#define MIN_STEP (1.0 / 256.0) /* the shortest damped Newton step, as a fraction of the full one */
#define STALL 3                /* slow damped Newton steps in a row after which a run gives up */
#define NEAR_ROOT 0.1          /* on the whole torus, every node with a lifted residual below this starts Newton */
#define PARTNER_CELLS 2.0      /* a root's fold partner is sought this many grid cells away at most */
#define PARTNER_SAMPLES 8      /* samples each way along the fold direction */
#define LINE_SEEDS 16          /* directions phi around a point of psi's half-line from which Newton starts */
#define LINE_START 1e-6        /* m: the seeds' r (the lifted residual is about linear in r there) */
#define LINE_ROOT 1e-6         /* lifted residual under which a chart's end is a candidate (rounding: 1e-16 / rho) */
#define LINE_POINTS 8          /* points of the half-line kept per search */
#define LINE_NEWTON 30         /* Newton steps to a point of the half-line (h = 0) */

/* Coordinates of the lifted system around a point w* of the torus where the model's w_hat is
 * -up (psi's singular half-line): y = (r, phi, phi4) for (w1, w7) = w* + M r (cos phi, sin phi),
 * M the inverse of the Jacobian of h (w_hat's part across up, in a basis across it) at w*.
 * There h is about r (cos phi, sin phi): its azimuth, which psi's reference turns with, is phi,
 * and the lifted residual, which turns by 2 pi about w* within any distance, is smooth in y. */
typedef struct {
    double w1, w7, m[2][2];
} half_line_chart;

/* x = (w1, w7, phi4) of chart coordinates y (chart NULL: y is x). */
static vec3 _lifted_of(const half_line_chart *chart, vec3 y)
{
    if (!chart)
        return y;
    double u = y.x * cos(y.y), v = y.x * sin(y.y);
    return v3(chart->w1 + chart->m[0][0] * u + chart->m[0][1] * v, chart->w7 + chart->m[1][0] * u + chart->m[1][1] * v,
              y.z);
}

/* Damped Newton on the lifted system from x = (w1, w7, phi4) (chart not NULL: in its
 * coordinates, x and the steps there), forward-difference Jacobian, deflated by the first
 * n_known rows of known (n x 3). Returns the max norm of the (undeflated) residual at the end
 * (inf if not finite); the end point (lifted) in *x_end, q the model IK there (solved once, at
 * the end: the iterations need the residual alone). */
static double _newton(om_problem *pb, const half_line_chart *chart, vec3 x, double *q, const double *known,
                      int n_known, vec3 *x_end)
{
    vec3 F = om_deflated_residual(pb, _lifted_of(chart, x), NULL, known, n_known);
    double r = om_max_norm(F);
    double eps = 1e-7;
    int slow = 0;
    vec3 Fn = v3(NAN, NAN, NAN); /* set by the first damped step; NaN until then */
    for (int it = 0; it < 30; it++) {
        if (!(r < INFINITY) || r < 1e-15 || slow == STALL)
            break;
        /* Rows of the Jacobian, then the step -J^-1 F by cofactors. */
        vec3 F0 = om_deflated_residual(pb, _lifted_of(chart, v3(x.x + eps, x.y, x.z)), NULL, known, n_known);
        vec3 F1 = om_deflated_residual(pb, _lifted_of(chart, v3(x.x, x.y + eps, x.z)), NULL, known, n_known);
        vec3 F2 = om_deflated_residual(pb, _lifted_of(chart, v3(x.x, x.y, x.z + eps)), NULL, known, n_known);
        vec3 rows[3];
        for (int i = 0; i < 3; i++) {
            double Fi = v_get(F, i);
            rows[i] = v3((v_get(F0, i) - Fi) / eps, (v_get(F1, i) - Fi) / eps, (v_get(F2, i) - Fi) / eps);
        }
        vec3 c0 = v_cross(rows[1], rows[2]), c1 = v_cross(rows[2], rows[0]), c2 = v_cross(rows[0], rows[1]);
        double det = v_dot(rows[0], c0);
        if (!(fabs(det) > 0.0)) /* also NaN */
            break;
        vec3 step = v_scale(-1.0 / det, v_add(v_add(v_scale(F.x, c0), v_scale(F.y, c1)), v_scale(F.z, c2)));
        double size = py_max(py_max(fabs(step.x), fabs(step.y)), fabs(step.z));
        double t = size < 0.5 ? 1.0 : 0.5 / size;
        while (t > MIN_STEP) {
            Fn = om_deflated_residual(pb, _lifted_of(chart, v_add(x, v_scale(t, step))), NULL, known, n_known);
            if (om_max_norm(Fn) < r) /* false for NaN */
                break;
            t *= 0.5;
        }
        if (t <= MIN_STEP)
            break;
        x = v_add(x, v_scale(t, step));
        F = Fn;
        slow = om_max_norm(F) > 0.9 * r ? slow + 1 : 0;
        r = om_max_norm(F);
    }
    /* q must belong to the final iterate. */
    x = _lifted_of(chart, x);
    r = om_max_norm(om_lifted_residual(pb, x, q));
    if (x_end)
        *x_end = x;
    return r < INFINITY ? r : INFINITY;
}

double om_newton(om_problem *pb, vec3 x, double *q, const double *known, int n_known, vec3 *x_end)
{
    return _newton(pb, NULL, x, q, known, n_known, x_end);
}

/* Damped Newton on the lifted system in (q1, q7, phi4) from the joint vector start;
 * returns the final residual, q holding the model IK there. */
double om_lifted_solve(om_problem *pb, const double *start, double *q)
{
    vec3 x = v3(start[0], start[6], start[3] + pb->s->params[SRS_THETA + 3]);
    return om_newton(pb, x, q, NULL, 0, NULL);
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
    double *x; /* cap x 3 */
    int cap;
} known_roots;

/* Whether two points (w1, w7, phi4) are one: each coordinate within OM_SAME_ROOT, modulo 2 pi. */
static bool _same_point(vec3 a, vec3 b)
{
    return py_max(py_max(fabs(om_wrap(a.x - b.x)), fabs(om_wrap(a.y - b.y))), fabs(om_wrap(a.z - b.z))) < OM_SAME_ROOT;
}

/* Newton's method from x, deflated by the known roots if deflate; a new root is appended
 * to known, with its model IK in q. Returns the number of known roots. */
static int _new_root(om_problem *pb, vec3 x, bool deflate, known_roots *known, int n_known, double *q)
{
    vec3 x_root;
    double r = om_newton(pb, x, q, known->x, deflate ? n_known : 0, &x_root);
    if (r > OM_ROOT_TOL)
        return n_known;
    for (int k = 0; k < n_known; k++)
        if (_same_point(x_root, v_load(known->x, 3 * k)))
            return n_known;
    if (n_known >= known->cap) {
        int cap = 2 * known->cap;
        double *grown = realloc(known->x, (size_t)cap * 3 * sizeof(double));
        if (!grown)
            return n_known; /* out of memory: not kept */
        known->x = grown;
        known->cap = cap;
    }
    known->x[3 * n_known] = x_root.x;
    known->x[3 * n_known + 1] = x_root.y;
    known->x[3 * n_known + 2] = x_root.z;
    return n_known + 1;
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
 * lifted system): into starts (3); returns the count. */
static int _fold_partners(om_problem *pb, vec3 x, double reach, double *q, vec3 *starts)
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

/* x(w1, w7) = W - S = p_d + a(w1) + R delta(w7) + R w_F - S of the model on the torus, and
 * its derivatives in w1 and w7 (d1, d7). */
static vec3 _shoulder_wrist(om_problem *pb, double w1, double w7, vec3 *d1, vec3 *d7)
{
    const double(*D)[3] = pb->s->D;
    const mat3 *R = &pb->t.R;
    double c1 = cos(w1), s1 = sin(w1), c7 = cos(w7), s7 = sin(w7);
    vec3 a = v_add(v_load(D[3], 0), v_add(v_scale(c1, v_load(D[4], 0)), v_scale(s1, v_load(D[5], 0))));
    *d1 = v_sub(v_scale(c1, v_load(D[5], 0)), v_scale(s1, v_load(D[4], 0)));
    *d7 = m_mv(*R, v_sub(v_scale(c7, v_load(D[2], 0)), v_scale(s7, v_load(D[1], 0))));
    return v_add(v_add(pb->p, pb->t.wrist), v_add(a, m_mv(*R, om_delta(D, w7))));
}

vec3 om_shoulder_wrist_centre(const om_problem *pb)
{
    const double(*D)[3] = pb->s->D;
    return v_add(v_add(pb->p, pb->t.wrist), v_add(v_load(D[3], 0), m_mv(pb->t.R, v_load(D[0], 0))));
}

/* The part of x across up in the basis (b1, b2) across it. */
static void _across(vec3 x, vec3 b1, vec3 b2, double *h)
{
    h[0] = v_dot(b1, x);
    h[1] = v_dot(b2, x);
}

/* The points of the grid's square (lo1, lo7, step, m nodes a side) where the model's w_hat is
 * -up, psi's singular half-line, into charts (LINE_POINTS); returns the count. Newton on h = 0
 * from each cell where both parts of h may change sign (their range over the corners widened
 * by what the cell's curvature may hide); a point is kept if Newton converges there, below
 * the shoulder, with h's Jacobian regular. */
static int _half_line_points(om_problem *pb, double lo1, double lo7, double step, int m, half_line_chart *charts)
{
    vec3 up = v_load(pb->s->params, SRS_UP), d1, d7;
    vec3 b1 = v_unit(v_cross(up, fabs(up.x) < 0.9 ? v3(1.0, 0.0, 0.0) : v3(0.0, 1.0, 0.0))), b2 = v_cross(up, b1);
    const double(*D)[3] = pb->s->D;
    double r1 = v_norm(v_load(D[4], 0)) + v_norm(v_load(D[5], 0));
    double r7 = v_norm(v_load(D[1], 0)) + v_norm(v_load(D[2], 0));
    /* x = centre + (D4 cos w1 + D5 sin w1) + R (D1 cos w7 + D2 sin w7), the last two at most
     * r1 and r7 long: no point where the centre's part across up, or its height, exceeds that */
    vec3 centre = om_shoulder_wrist_centre(pb);
    double h0[2];
    _across(centre, b1, b2, h0);
    if (hypot(h0[0], h0[1]) > r1 + r7 || v_dot(up, centre) > r1 + r7)
        return 0;
    double bend = (r1 + r7) * step * step;
    double *H = malloc(2 * (size_t)m * (size_t)m * sizeof(double));
    vec3 *rows = malloc(2 * (size_t)m * sizeof(vec3)), *cols = rows + m;
    if (!H || !rows) {
        free(H);
        free(rows);
        return 0;
    }
    vec3 corner = _shoulder_wrist(pb, lo1, lo7, &d1, &d7);
    for (int i = 0; i < m; i++) { /* x = rows[i] + cols[j] at node (i, j) */
        rows[i] = _shoulder_wrist(pb, lo1 + (double)i * step, lo7, &d1, &d7);
        cols[i] = v_sub(_shoulder_wrist(pb, lo1, lo7 + (double)i * step, &d1, &d7), corner);
    }
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++)
            _across(v_add(rows[i], cols[j]), b1, b2, H + 2 * (i * m + j));
    free(rows);
    int count = 0;
    for (int i = 0; i + 1 < m && count < LINE_POINTS; i++) {
        for (int j = 0; j + 1 < m && count < LINE_POINTS; j++) {
            bool crosses = true;
            for (int c = 0; c < 2; c++) {
                double lo = INFINITY, hi = -INFINITY;
                for (int k = 0; k < 4; k++) {
                    double v = H[2 * ((i + k / 2) * m + j + k % 2) + c];
                    lo = py_min(lo, v);
                    hi = py_max(hi, v);
                }
                crosses = crosses && lo - bend <= 0.0 && 0.0 <= hi + bend;
            }
            if (!crosses)
                continue;
            double w1 = lo1 + ((double)i + 0.5) * step, w7 = lo7 + ((double)j + 0.5) * step, h[2], J[2][2], det = 0.0;
            vec3 x = v3(NAN, NAN, NAN);
            for (int it = 0; it < LINE_NEWTON; it++) {
                x = _shoulder_wrist(pb, w1, w7, &d1, &d7);
                _across(x, b1, b2, h);
                J[0][0] = v_dot(b1, d1), J[0][1] = v_dot(b1, d7), J[1][0] = v_dot(b2, d1), J[1][1] = v_dot(b2, d7);
                det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
                if (!(fabs(det) > 0.0))
                    break;
                double s1 = (J[1][1] * h[0] - J[0][1] * h[1]) / det, s7 = (J[0][0] * h[1] - J[1][0] * h[0]) / det;
                if (w1 - s1 == w1 && w7 - s7 == w7)
                    break;
                w1 -= s1;
                w7 -= s7;
            }
            bool inside = fabs(w1 - lo1 - ((double)i + 0.5) * step) <= step &&
                          fabs(w7 - lo7 - ((double)j + 0.5) * step) <= step;
            if (!(fabs(det) > 0.0) || !inside || !(v_dot(up, x) < 0.0) || hypot(h[0], h[1]) > 1e-12 * v_norm(x))
                continue;
            bool seen = false;
            for (int k = 0; k < count; k++)
                seen = seen || _same_point(v3(w1, w7, 0.0), v3(charts[k].w1, charts[k].w7, 0.0));
            if (seen)
                continue;
            half_line_chart chart = {w1, w7, {{J[1][1] / det, -J[0][1] / det}, {-J[1][0] / det, J[0][0] / det}}};
            charts[count++] = chart;
        }
    }
    free(H);
    return count;
}

/* om_add_candidate of a copy of q, logged (log not NULL): the search's q stays as Newton left
 * it, whatever the verification's refinement, which depends on the configuration's signs,
 * makes of the copy. So the candidates, in order, are those of every configuration that
 * differs in the SHOULDER and WRIST signs alone (om_srs_model_ik_lifted does not read them). */
static int _candidate(om_problem *pb, const double *q, double *roots, int count, om_candidate_log *log)
{
    double candidate[OM_MAX_DOF];
    memcpy(candidate, q, sizeof candidate);
    if (log) {
        int dof = pb->s->dof;
        if (log->count < log->cap)
            memcpy(log->q + (size_t)dof * (size_t)log->count, q, (size_t)dof * sizeof(double));
        log->count++;
    }
    return om_add_candidate(pb, candidate, roots, count);
}

/* Roots next to the points of psi's half-line in the grid's square (_half_line_points):
 * Newton in each point's chart from LINE_SEEDS directions at r = LINE_START; an end whose
 * lifted residual is below LINE_ROOT (its rounding there is about 1e-16 / rho) is a candidate,
 * refined on the real arm and verified (_candidate). Returns the root count. */
static int _half_line_roots(om_problem *pb, double lo1, double lo7, double step, int m, double *q, double *roots,
                            int count, om_candidate_log *log)
{
    half_line_chart charts[LINE_POINTS];
    int n = _half_line_points(pb, lo1, lo7, step, m, charts);
    vec3 ends[LINE_SEEDS];
    for (int c = 0; c < n; c++) {
        int n_ends = 0;
        for (int k = 0; k < LINE_SEEDS; k++) {
            vec3 y = v3(LINE_START, 2.0 * OM_PI * (double)k / (double)LINE_SEEDS, NAN), end;
            om_lifted_residual(pb, _lifted_of(&charts[c], y), q);
            y.z = q[3] + pb->s->params[SRS_THETA + 3]; /* the elbow's root there */
            if (_newton(pb, &charts[c], y, q, NULL, 0, &end) > LINE_ROOT)
                continue;
            bool seen = false;
            for (int e = 0; e < n_ends; e++)
                seen = seen || _same_point(end, ends[e]);
            if (seen)
                continue;
            ends[n_ends++] = end;
            count = _candidate(pb, q, roots, count, log);
        }
    }
    return count;
}

/* Bounded search on the torus (w1, w7) of an arm with shoulder offsets; returns the count.
 * The lifted residual is sampled on an n x n grid (the square of half-width radius around
 * the centre's (q1, q7) when radius < pi); Newton starts from local minima of its norm and
 * from cells where the shoulder and wrist residuals change sign, with deflation and fold
 * partners; and around the points of psi's singular half-line, where the lifted residual
 * turns about a point, in their charts (_half_line_roots). The candidates go to verification
 * in order, into log too (NULL: none). */
int om_torus_roots(om_problem *pb, int n, double *roots, const double *centre, double radius, om_candidate_log *log)
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
        lo1 = centre[0] - radius;
        lo7 = centre[6] - radius;
        span = 2.0 * radius;
    }
    double step = span / (double)n;
    int m = n + 1; /* on the whole torus the last row and column repeat the first */
    size_t mm = (size_t)m * (size_t)m;
    double *S = malloc(4 * mm * sizeof(double));
    known_roots known = {malloc((size_t)MAX_KNOWN * 3 * sizeof(double)), MAX_KNOWN};
    if (!S || !known.x) {
        free(S);
        free(known.x);
        return 0;
    }
    double *W = S + mm, *F = W + mm, *E = F + mm;
    const double *P = pb->s->params;
    for (int i = 0; i < m; i++) {
        for (int j = 0; j < m; j++) {
            vec3 r = om_lifted_residual(pb, v3(lo1 + (double)i * step, lo7 + (double)j * step, NAN), q);
            S[i * m + j] = r.x;
            W[i * m + j] = r.y;
            E[i * m + j] = q[3] + P[SRS_THETA + 3];
            F[i * m + j] = om_max_norm(r) < INFINITY ? om_max_norm(r) : INFINITY;
        }
    }
    int count = 0;
    int n_known = 0;
    vec3 partners[3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
    double phi_star = P[SRS_PHI_STAR];
    for (int i = 0; i < m; i++) {
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
                if (!start || n_known == MAX_KNOWN)
                    continue;
                int first = n_known;
                n_known = _new_root(pb, x, false, &known, n_known, q);
                if (n_known == first) {
                    /* Near the edge of reach the elbow angle changes fastest: try once more
                     * from the nearer edge's (the straight or the folded elbow). */
                    double edge = cos(x.z - phi_star) > 0.0 ? phi_star : phi_star + OM_PI;
                    n_known = _new_root(pb, v3(x.x, x.y, edge), false, &known, n_known, q);
                }
                if (n_known == first)
                    continue;
                count = _candidate(pb, q, roots, count, log);
                while (n_known < MAX_KNOWN) { /* deflated, from the same start */
                    int found = n_known;
                    n_known = _new_root(pb, x, true, &known, n_known, q);
                    if (n_known == found)
                        break;
                    count = _candidate(pb, q, roots, count, log);
                }
                int k = first;
                while (k < n_known && n_known < MAX_KNOWN) {
                    vec3 root = v_load(known.x, 3 * k);
                    k += 1;
                    int n_partners = _fold_partners(pb, root, PARTNER_CELLS * step, q, partners);
                    for (int a = 0; a < n_partners; a++) {
                        int found = n_known;
                        n_known = _new_root(pb, partners[a], true, &known, n_known, q);
                        if (n_known == found) { /* the line bends away from the partner: halfway */
                            vec3 halfway = v_scale(0.5, v_add(partners[a], root));
                            n_known = _new_root(pb, halfway, true, &known, n_known, q);
                        }
                        if (n_known > found)
                            count = _candidate(pb, q, roots, count, log);
                    }
                }
            }
        }
    }
    count = _half_line_roots(pb, lo1, lo7, step, m, q, roots, count, log);
    free(S);
    free(known.x);
    return count;
}
