/* The torus search at psi's singular half-line: the points of the grid's square where the
 * model's w_hat is -up (Newton on h = 0, the part of W - S across up), and Newton in each
 * point's chart from seeds around it, where the lifted residual turns about the point
 * (the method: om_redundant/ik/kernel_data.py). A PUMA-like 6-DOF wrist's torus is searched about
 * joint 1's axis instead, from the points where the wrist centre is on it and from the cells
 * at the shoulder's edge of reach, on the system with q1 and the elbow angle as unknowns. */
#include "torus.h"

#define LINE_SEEDS 16          /* directions phi around a point of psi's half-line from which Newton starts */
#define LINE_START 1e-6        /* m: the seeds' r (the lifted residual is about linear in r there) */
#define LINE_ROOT 1e-6         /* lifted residual under which a chart's end is a candidate (rounding: 1e-16 / rho) */
#define LINE_NEWTON 30         /* Newton steps to a point of the half-line (h = 0) */

/* x(w1, w7) = W - S = p_d + a(w1) + R delta(w7) + R w_F - S of the model on the torus, and
 * its derivatives in w1 and w7 (d1, d7; NULL: not wanted); of a 6-DOF arm (a PUMA-like
 * wrist), the wrist centre p_d + R delta(w5, w6) + R w_F, whose q1 turns by 2 pi about joint
 * 1's axis. */
static vec3 _shoulder_wrist(om_problem *pb, double w1, double w7, vec3 *d1, vec3 *d7)
{
    const double(*D)[3] = pb->s->D;
    const mat3 *R = &pb->t.R;
    if (pb->s->family != OM_SRS) {
        vec3 delta = om_six_dof_wrist_delta(pb->s->params, w1, w7, d1, d7);
        if (d1) {
            *d1 = m_mv(*R, *d1);
            *d7 = m_mv(*R, *d7);
        }
        return v_add(v_add(pb->p, pb->t.wrist), m_mv(*R, delta));
    }
    double c1 = cos(w1), s1 = sin(w1);
    vec3 a = v_add(v_load(D[3], 0), v_add(v_scale(c1, v_load(D[4], 0)), v_scale(s1, v_load(D[5], 0))));
    if (d1) {
        double c7 = cos(w7), s7 = sin(w7);
        *d1 = v_sub(v_scale(c1, v_load(D[5], 0)), v_scale(s1, v_load(D[4], 0)));
        *d7 = m_mv(*R, v_sub(v_scale(c7, v_load(D[2], 0)), v_scale(s7, v_load(D[1], 0))));
    }
    return v_add(v_add(pb->p, pb->t.wrist), v_add(a, m_mv(*R, om_delta(D, w7))));
}

/* What the search for the half-line's points needs of the arm: the axis (up) the singular line
 * runs along, x's value at the torus' centre (its constant part, c0), and a bound on how far the
 * rest takes it (the sum of its terms' lengths), which also bounds x's second derivatives. */
typedef struct {
    vec3 up, centre;
    double reach;
    bool below;     /* only the half-line below the shoulder (the arm angle's): S-R-S */
    bool separable; /* x = x1(w1) + x7(w7): S-R-S (a 6-DOF arm's delta(w5, w6) has mixed terms) */
} singular_line;

static singular_line _singular_line(const om_problem *pb)
{
    const om_solver_data *s = pb->s;
    singular_line line = {v3(0.0, 0.0, 1.0), v3(0.0, 0.0, 0.0), 0.0, s->family == OM_SRS, s->family == OM_SRS};
    if (s->family != OM_SRS) { /* joint 1's axis, z of DH frame 0 */
        line.centre = v_add(v_add(pb->p, pb->t.wrist), m_mv(pb->t.R, v_load(s->params, SD_WRIST_TORUS)));
        for (int k = 3; k < 27; k += 3)
            line.reach += v_norm(v_load(s->params, SD_WRIST_TORUS + k));
        return line;
    }
    const double(*D)[3] = s->D;
    line.up = v_load(s->params, SRS_UP);
    line.centre = om_shoulder_wrist_centre(pb);
    line.reach = v_norm(v_load(D[4], 0)) + v_norm(v_load(D[5], 0)) + v_norm(v_load(D[1], 0)) + v_norm(v_load(D[2], 0));
    return line;
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
int om_half_line_points(om_problem *pb, double lo1, double lo7, double step, int m, half_line_chart *charts)
{
    singular_line line = _singular_line(pb);
    vec3 up = line.up, d1, d7;
    vec3 b1 = v_unit(v_cross(up, fabs(up.x) < 0.9 ? v3(1.0, 0.0, 0.0) : v3(0.0, 1.0, 0.0))), b2 = v_cross(up, b1);
    /* x = centre + (D4 cos w1 + D5 sin w1) + R (D1 cos w7 + D2 sin w7), the last two at most
     * line.reach long: no point where the centre's part across up, or its height, exceeds that
     * (the 6-DOF's x the same with the terms of delta(w5, w6), whose mixed ones' second
     * derivatives the bend's four times covers) */
    double h0[2];
    _across(line.centre, b1, b2, h0);
    if (hypot(h0[0], h0[1]) > line.reach || (line.below && v_dot(up, line.centre) > line.reach))
        return 0;
    double bend = (line.below ? 1.0 : 4.0) * line.reach * step * step;
    double *H = malloc(2 * (size_t)m * (size_t)m * sizeof(double));
    vec3 *rows = malloc(2 * (size_t)m * sizeof(vec3)), *cols = rows + m;
    if (!H || !rows) {
        free(H);
        free(rows);
        return 0;
    }
    vec3 corner = _shoulder_wrist(pb, lo1, lo7, NULL, NULL);
    for (int i = 0; i < m; i++) { /* x = rows[i] + cols[j] at node (i, j), where separable */
        rows[i] = _shoulder_wrist(pb, lo1 + (double)i * step, lo7, NULL, NULL);
        cols[i] = v_sub(_shoulder_wrist(pb, lo1, lo7 + (double)i * step, NULL, NULL), corner);
    }
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++) {
            vec3 x = line.separable ? v_add(rows[i], cols[j])
                                    : _shoulder_wrist(pb, lo1 + (double)i * step, lo7 + (double)j * step, NULL, NULL);
            _across(x, b1, b2, H + 2 * (i * m + j));
        }
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
            if (!(fabs(det) > 0.0) || !inside || (line.below && !(v_dot(up, x) < 0.0)) ||
                hypot(h[0], h[1]) > 1e-12 * v_norm(x))
                continue;
            bool seen = false;
            for (int k = 0; k < count; k++)
                seen = seen || same_point(v3(w1, w7, 0.0), v3(charts[k].w1, charts[k].w7, 0.0));
            if (seen)
                continue;
            half_line_chart chart = {w1, w7, {{J[1][1] / det, -J[0][1] / det}, {-J[1][0] / det, J[0][0] / det}}};
            charts[count++] = chart;
        }
    }
    free(H);
    return count;
}

/* The largest of |F_i|, i < 4 (inf where one is not finite). */
static double _norm4(const double *F)
{
    double most = 0.0;
    for (int i = 0; i < 4; i++)
        most = isfinite(F[i]) ? py_max(most, fabs(F[i])) : INFINITY;
    return most;
}

/* Damped Newton on a 6-DOF arm's system about joint 1's axis (om_axis_residual: x = (w5, w6, q1,
 * gamma), no square root anywhere: smooth where the wrist centre is on the axis or at the
 * shoulder's edge of reach, and at the elbow's edge too) from x (its gamma NaN: the ELBOW
 * branch's root there), as om_lifted_newton's (forward-difference Jacobian, steps of at most
 * 0.5 rad, halved down to AXIS_MIN_STEP until the residual falls, AXIS_STALL slow steps at
 * most). x becomes the end, q the model IK there; returns the residual's max norm there. */
#define AXIS_NEWTON 30
#define AXIS_STALL 3
#define AXIS_MIN_STEP (1.0 / 256.0)
static double _axis_newton(om_problem *pb, double *x, double *q)
{
    double F[4], Fn[4], J[16], step[4], y[4], eps = 1e-7;
    om_axis_residual(pb, x, q, F);
    if (isnan(x[3]))
        x[3] = lifted_elbow(pb->s, q);
    double r = _norm4(F);
    int slow = 0;
    for (int it = 0; it < AXIS_NEWTON && r < INFINITY && r > 1e-15 && slow < AXIS_STALL; it++) {
        for (int k = 0; k < 4; k++) {
            memcpy(y, x, sizeof y);
            y[k] += eps;
            om_axis_residual(pb, y, q, Fn);
            for (int i = 0; i < 4; i++)
                J[4 * i + k] = (Fn[i] - F[i]) / eps;
        }
        for (int i = 0; i < 4; i++)
            step[i] = -F[i];
        if (!om_eliminate(J, step, 4, NULL))
            break;
        double size = py_max(py_max(fabs(step[0]), fabs(step[1])), py_max(fabs(step[2]), fabs(step[3])));
        double t = size < 0.5 ? 1.0 : 0.5 / size, rn = INFINITY;
        for (; t > AXIS_MIN_STEP; t *= 0.5) {
            for (int k = 0; k < 4; k++)
                y[k] = x[k] + t * step[k];
            om_axis_residual(pb, y, q, Fn);
            rn = _norm4(Fn);
            if (rn < r)
                break;
        }
        if (!(rn < r))
            break;
        memcpy(x, y, sizeof y);
        memcpy(F, Fn, sizeof F);
        slow = rn > 0.9 * r ? slow + 1 : 0;
        r = rn;
    }
    om_axis_residual(pb, x, q, F); /* (q of the end) */
    return _norm4(F);
}

/* Newton about joint 1's axis (_axis_newton) from (w5, w6, q1), gamma the ELBOW branch's; an end
 * not in ends (n_ends of them, LINE_SEEDS at most; compared in w5, w6, q1) is a candidate, as
 * torus_candidate's. Returns the root count. */
static int _about_axis(om_problem *pb, vec3 start, vec3 *ends, int *n_ends, double *q, double *roots, int count,
                       om_candidate_log *log)
{
    double x[4] = {start.x, start.y, start.z, NAN};
    if (_axis_newton(pb, x, q) > OM_ROOT_TOL)
        return count;
    vec3 end = v3(x[0], x[1], x[2]);
    for (int e = 0; e < *n_ends; e++)
        if (same_point(end, ends[e]))
            return count;
    if (*n_ends < LINE_SEEDS)
        ends[(*n_ends)++] = end;
    return torus_candidate(pb, q, roots, count, log);
}

/* A 6-DOF arm's roots next to the points where the wrist centre is on joint 1's axis, from each
 * point with LINE_SEEDS values of q1 (_about_axis). Returns the root count. */
static int _axis_roots(om_problem *pb, const half_line_chart *points, int n, double *q, double *roots, int count,
                       om_candidate_log *log)
{
    vec3 ends[LINE_SEEDS];
    for (int c = 0; c < n; c++) {
        int n_ends = 0;
        for (int k = 0; k < LINE_SEEDS; k++) {
            vec3 x = v3(points[c].w1, points[c].w7, -OM_PI + 2.0 * OM_PI * (double)k / (double)LINE_SEEDS);
            count = _about_axis(pb, x, ends, &n_ends, q, roots, count, log);
        }
    }
    return count;
}

int om_shoulder_edge_roots(om_problem *pb, double lo1, double lo7, double step, int m, double *q, double *roots,
                           int count, om_candidate_log *log)
{
    const double *P = pb->s->params;
    double h = P[SD_LATERAL];
    if (h == 0.0)
        return count;
    /* K = pw_x^2 + pw_y^2 - h^2 at the nodes: the reach's condition. pw = c + R delta terms, each
     * at most line.reach long with its derivatives: |K''| <= 2 (|pw'|^2 + |pw| |pw''|), along
     * any direction of a cell (mixed terms: 4x), within a cell's half-diagonal */
    singular_line line = _singular_line(pb);
    double size = hypot(line.centre.x, line.centre.y) + line.reach;
    double bend = 8.0 * (line.reach * line.reach + size * line.reach) * step * step;
    double *K = malloc((size_t)m * (size_t)m * sizeof(double));
    if (!K)
        return count;
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++) {
            vec3 pw = _shoulder_wrist(pb, lo1 + (double)i * step, lo7 + (double)j * step, NULL, NULL);
            K[i * m + j] = pw.x * pw.x + pw.y * pw.y - h * h;
        }
    for (int i = 0; i + 1 < m; i++) {
        for (int j = 0; j + 1 < m; j++) {
            double lo = INFINITY, hi = -INFINITY;
            for (int k = 0; k < 4; k++) {
                lo = py_min(lo, K[(i + k / 2) * m + j + k % 2]);
                hi = py_max(hi, K[(i + k / 2) * m + j + k % 2]);
            }
            if (!(lo - bend <= 0.0 && 0.0 <= hi + bend)) /* the edge neither crosses the cell nor may touch it */
                continue;
            /* at the edge rho = 0: phi1 = azimuth - atan2(-sigma1 h, 0), both ARM branches' */
            double w5 = lo1 + ((double)i + 0.5) * step, w6 = lo7 + ((double)j + 0.5) * step;
            vec3 pw = _shoulder_wrist(pb, w5, w6, NULL, NULL);
            double q1 = atan2(pw.y, pw.x) - atan2(-P[SD_SIGMA1] * h, 0.0) - P[SD_THETA1];
            vec3 ends[LINE_SEEDS];
            int n_ends = 0;
            count = _about_axis(pb, v3(w5, w6, q1), ends, &n_ends, q, roots, count, log);
        }
    }
    free(K);
    return count;
}

/* Roots next to the points of psi's half-line (charts, n of them: om_half_line_points):
 * Newton in each point's chart from LINE_SEEDS directions at r = LINE_START; an end whose
 * lifted residual is below LINE_ROOT (its rounding there is about 1e-16 / rho) is a candidate,
 * refined on the real arm and verified (torus_candidate). A 6-DOF arm's points, where the wrist
 * centre is on joint 1's axis, are searched about the axis instead (_axis_roots): there the
 * model's q1 turns by pi across the point, which no chart of the lifted system smooths. Returns
 * the root count. */
int om_half_line_roots(om_problem *pb, const half_line_chart *charts, int n, double *q, double *roots, int count,
                       om_candidate_log *log)
{
    if (pb->s->family != OM_SRS)
        return _axis_roots(pb, charts, n, q, roots, count, log);
    vec3 ends[LINE_SEEDS];
    for (int c = 0; c < n; c++) {
        int n_ends = 0;
        for (int k = 0; k < LINE_SEEDS; k++) {
            vec3 y = v3(LINE_START, 2.0 * OM_PI * (double)k / (double)LINE_SEEDS, NAN), end;
            om_lifted_residual(pb, lifted_of(&charts[c], y), q);
            y.z = lifted_elbow(pb->s, q); /* the elbow's root there */
            if (om_lifted_newton(pb, &charts[c], y, q, NULL, 0, NULL, &end) > LINE_ROOT)
                continue;
            bool seen = false;
            for (int e = 0; e < n_ends; e++)
                seen = seen || same_point(end, ends[e]);
            if (seen)
                continue;
            ends[n_ends++] = end;
            count = torus_candidate(pb, q, roots, count, log);
        }
    }
    return count;
}
