/* The bounded search on the torus (w1, w7) of an arm with shoulder offsets: the lifted
 * residual on a grid, damped Newton (torus_newton.c) from its local minima and sign changes,
 * with deflation and fold partners, and at psi's half-line (torus_half_line.c)
 * (the method: om_redundant/ik/system.py). */
#include "torus.h"

#define MAX_KNOWN 64           /* roots of the lifted torus system kept for deflation */
#define NEAR_ROOT 0.1          /* on the whole torus, every node with a lifted residual below this starts Newton */
#define PARTNER_CELLS 2.0      /* a root's fold partner is sought this many grid cells away at most */
#define PARTNER_SAMPLES 8      /* samples each way along the fold direction */

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

/* Newton's method from x, deflated by the known roots if deflate; a new root is appended
 * to known, with its model IK in q. Returns the number of known roots. */
static int _new_root(om_problem *pb, vec3 x, bool deflate, known_roots *known, int n_known, double *q)
{
    vec3 x_root;
    double r = om_newton(pb, x, q, known->x, deflate ? n_known : 0, &x_root);
    if (r > OM_ROOT_TOL)
        return n_known;
    for (int k = 0; k < n_known; k++)
        if (same_point(x_root, v_load(known->x, 3 * k)))
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

/* Bounded search on the torus (w1, w7) of an arm with shoulder offsets; returns the count.
 * The lifted residual is sampled on an n x n grid (the square of half-width radius around
 * the centre's (q1, q7) when radius < pi); Newton starts from local minima of its norm and
 * from cells where the shoulder and wrist residuals change sign, with deflation and fold
 * partners; and around the points of psi's singular half-line, where the lifted residual
 * turns about a point, in their charts (om_half_line_roots). The candidates go to verification
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
                count = torus_candidate(pb, q, roots, count, log);
                while (n_known < MAX_KNOWN) { /* deflated, from the same start */
                    int found = n_known;
                    n_known = _new_root(pb, x, true, &known, n_known, q);
                    if (n_known == found)
                        break;
                    count = torus_candidate(pb, q, roots, count, log);
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
                            count = torus_candidate(pb, q, roots, count, log);
                    }
                }
            }
        }
    }
    count = om_half_line_roots(pb, lo1, lo7, step, m, q, roots, count, log);
    free(S);
    free(known.x);
    return count;
}
