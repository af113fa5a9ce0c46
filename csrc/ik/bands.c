/* The bands along the singular boundary, for a configuration whose bounded search found no
 * root: its touch points and the dips of its branch quantities between samples, a 6-DOF
 * wrist's consistency residual, the neighbouring configurations across a boundary it comes
 * near, and psi's half-line along the self-motion loops (loop_search.c). Every candidate is
 * refined and verified as the boundary's (boundary.c). */
#include "om_system.h"
#include "boundary.h"

#define GATE_POINTS 8      /* free-angle samples of the cheap test before a neighbour's search */
#define GATE_NEAR 0.2      /* |branch quantity| at a sample that lets a neighbour be searched */
#define DIP_STEPS 24       /* golden-section steps to a dip's bottom: 0.618^24 of two cells, 1e-5 rad */
#define SWING 1.5          /* rad: a change of g across one scan cell that is a swing of q_J (pi), not its slope */
#define WRIST_BISECTIONS 64 /* halvings of a cell of the wrist residual's sign change: to the last bit */

/* The problem with branch i flipped: the neighbouring configuration across that boundary.
 * psi's reference flips with the ELBOW branch, so there psi becomes psi + pi. */
static om_problem neighbour(const om_problem *pb, int i, int64_t *signs, double *redundancy)
{
    const om_solver_data *s = pb->s;
    memcpy(signs, pb->signs, (size_t)s->n_signs * sizeof(int64_t));
    signs[i] = -signs[i];
    for (int r = 0; r < s->n_redundancy; r++)
        redundancy[r] = pb->redundancy[r];
    if (s->family == OM_SRS && i == ELBOW_SIGN)
        redundancy[0] = om_wrap(redundancy[0] + OM_PI);
    return om_problem_at(pb, signs, redundancy);
}

/* |branch quantity i| of the model's solution at free angle w (INFINITY out of reach); q gets it. */
static double branch_at(om_problem *pb, int i, double w, double *q)
{
    double v[3];
    if (om_model_ik_at(pb, w, q, true) < -OM_REACH_SLACK)
        return INFINITY;
    om_branch_values(pb->s->family, pb->s->params, q, v);
    return isnan(v[i]) ? INFINITY : fabs(v[i]);
}

/* A dip of branch i between samples: where the model's branch quantity comes near zero, q_J
 * swings and g has its narrow features (a close pair of roots inside one cell of the scan,
 * a steep crossing). From a sample where |b_i| is a local minimum among the samples, golden
 * section on [w - h, w + h] finds the dip's bottom w*; there the model's solution is refined
 * on the real arm and the secant starts. Returns the root count. */
static int dip_roots(om_problem *pb, int i, double w, double h, double *roots, int count)
{
    const double ratio = 0.6180339887498949;
    double q[OM_MAX_DOF], a = w - h, b = w + h;
    double c = b - ratio * (b - a), d = a + ratio * (b - a);
    double fc = branch_at(pb, i, c, q), fd = branch_at(pb, i, d, q);
    for (int it = 0; it < DIP_STEPS; it++) {
        if (fc < fd) {
            b = d;
            d = c;
            fd = fc;
            c = b - ratio * (b - a);
            fc = branch_at(pb, i, c, q);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + ratio * (b - a);
            fd = branch_at(pb, i, d, q);
        }
    }
    double bottom = fc < fd ? c : d;
    if (!(branch_at(pb, i, bottom, q) < NEAR_BOUNDARY))
        return count;
    if (pb->s->mode == OM_CIRCLE)
        q[pb->s->dp_joint] = bottom;
    double start[OM_MAX_DOF], pos, ori;
    bool complete = true;
    memcpy(start, q, (size_t)pb->s->dof * sizeof(double));
    if (om_local_solve(pb, start, &complete, q, &pos, &ori)) /* as a hint at the bottom would */
        count = om_add_root(pb, q, roots, count);
    return count;
}

/* The root of the wrist's consistency residual r (om_wrist_residual) on [a, b], where ra and
 * rb differ in sign, by bisection to the last bit; its model IK into q. */
static void wrist_bisect(om_problem *pb, double a, double ra, double b, double *q)
{
    for (int it = 0; it < WRIST_BISECTIONS && a < 0.5 * (a + b) && 0.5 * (a + b) < b; it++) {
        double c = 0.5 * (a + b), rc = om_wrist_residual(pb, c, q);
        if (!(rc * ra > 0.0)) /* also NaN: the bracket's ends are reachable, keep the inner part */
            b = c;
        else {
            a = c;
            ra = rc;
        }
    }
    om_wrist_residual(pb, a, q);
}

/* The roots of r on the part of [a, b] (a run of reach, or an island in it) from inside a reachable
 * point with residual r_in toward the end e: e itself if reachable (r_e), else the edge of
 * reach. Returns the root count. */
static int wrist_bracket(om_problem *pb, double in, double r_in, double e, double r_e, double *roots, int count)
{
    double q[OM_MAX_DOF];
    if (isnan(r_e)) {
        e = om_reach_edge(pb, in, e, q);
        r_e = om_wrist_residual(pb, e, q);
    }
    if (isnan(r_e) || r_in * r_e > 0.0)
        return count;
    bool up = e > in;
    wrist_bisect(pb, up ? in : e, up ? r_in : r_e, up ? e : in, q);
    return om_add_candidate(pb, q, roots, count);
}

/* A 6-DOF circle arm's roots from the wrist's consistency residual r(w) with q_J = w given
 * (om_wrist_residual): smooth where the model's wrist is singular, where g's q_J is the
 * arbitrary split of the aligned wrist (g may then miss zero by far over a whole run of
 * reach, the wrist aligned all along it). r is sampled at the scan points; a sign change
 * between two samples, or between a sample and the edge of reach, is bisected; a cell with
 * both ends out of reach is searched from the maximum of the reach margin inside it where
 * the margin may reach zero. Its roots hold either WRIST sign (verified in the problem's).
 * Returns the root count. */
static int wrist_roots(om_problem *pb, double *roots, int count)
{
    int n = pb->s->scan_points;
    double q[OM_MAX_DOF], h = 2.0 * OM_PI / (double)n;
    double *rs = malloc(2 * (size_t)n * sizeof(double)), *ms = rs + n;
    if (!rs)
        return count;
    for (int k = 0; k < n; k++) {
        rs[k] = om_wrist_residual(pb, -OM_PI + h * (double)k, q);
        ms[k] = isnan(rs[k]) ? om_reach_margin(pb, -OM_PI + h * (double)k, q) : 0.0;
    }
    for (int k = 0; k < n; k++) {
        double a = -OM_PI + h * (double)k, b = a + h, ra = rs[k], rb = rs[(k + 1) % n];
        if (!isnan(ra))
            count = wrist_bracket(pb, a, ra, b, rb, roots, count);
        else if (!isnan(rb))
            count = wrist_bracket(pb, b, rb, a, ra, roots, count);
        else if (om_margin_may_reach(ms, k, n, true)) {
            double gc, c = om_extremum(pb, a, b, 0.5 * (a + b), 1.0, true, q, &gc, NULL);
            double rc = isnan(gc) ? NAN : om_wrist_residual(pb, c, q);
            if (!isnan(rc)) {
                count = wrist_bracket(pb, c, rc, a, NAN, roots, count);
                count = wrist_bracket(pb, c, rc, b, NAN, roots, count);
            }
        }
    }
    free(rs);
    return count;
}

/* Touch points: GATE_POINTS samples of the free angle w in the problem's own configuration.
 * Where the model's solution has a branch quantity within NEAR_BOUNDARY of zero, it is a
 * candidate from the crossing (q_J = w), refined and verified into roots (a singular wrist
 * aligned to the last bit keeps the previous wrist joint, so g there never crosses zero).
 * Also the cheap test before a neighbour's bounded search: near[i] if branch i comes within
 * GATE_NEAR of zero at a sample, or within its change to a neighbouring sample (it may dip to
 * zero between them); every branch where no sample is within reach. (A straight elbow is an
 * edge of reach, found by the touch candidates of the problem's own search.) On the torus
 * every branch is marked, no touch point is tried. Returns the root count. */
static int touch_points(om_problem *pb, bool *near, double *roots)
{
    const om_solver_data *s = pb->s;
    bool torus = s->mode == OM_TORUS;
    for (int i = 0; i < s->n_signs; i++)
        near[i] = torus;
    if (torus)
        return 0;
    double q[OM_MAX_DOF], values[GATE_POINTS][3];
    int points = s->mode == OM_FIXED ? 1 : GATE_POINTS, count = 0;
    for (int k = 0; k < points; k++) {
        double w = -OM_PI + 2.0 * OM_PI * (double)k / (double)points;
        double *v = values[k];
        if (om_model_ik_at(pb, w, q, true) < -OM_REACH_SLACK) {
            v[0] = v[1] = v[2] = NAN;
            continue;
        }
        om_branch_values(s->family, s->params, q, v);
        double nearest = INFINITY;
        for (int i = 0; i < s->n_signs; i++)
            nearest = py_min(nearest, fabs(v[i]));
        if (nearest < NEAR_BOUNDARY) {
            if (s->mode == OM_CIRCLE)
                q[s->dp_joint] = w;
            count = om_add_candidate(pb, q, roots, count);
        }
        if (s->mode == OM_CIRCLE) { /* the local solve from this sample, as a hint there would start it */
            om_secant(pb, w, q);
            count = om_add_candidate(pb, q, roots, count);
        }
    }
    for (int i = 0; i < s->n_signs && points > 1; i++) { /* the dips between samples */
        for (int k = 0; k < points; k++) {
            double v = fabs(values[k][i]), before = fabs(values[(k + points - 1) % points][i]);
            double after = fabs(values[(k + 1) % points][i]);
            if (v <= (isnan(before) ? INFINITY : before) && v <= (isnan(after) ? INFINITY : after)) /* not NaN */
                count = dip_roots(pb, i, -OM_PI + 2.0 * OM_PI * (double)k / (double)points, 2.0 * OM_PI / points,
                                  roots, count);
        }
    }
    bool seen = false; /* no sample within reach: nothing known, every neighbour is searched */
    for (int k = 0; k < points; k++)
        seen = seen || !isnan(values[k][0]);
    for (int i = 0; i < s->n_signs; i++)
        near[i] = !seen;
    for (int k = 0; k < points; k++) {
        const double *v = values[k], *next = values[(k + 1) % points];
        for (int i = 0; i < s->n_signs; i++) /* false for NaN (out of reach) */
            near[i] = near[i] || fabs(v[i]) < GATE_NEAR || fabs(v[i]) <= fabs(next[i] - v[i]);
    }
    return count;
}

/* Whether q_J swings between two neighbouring scan points of the circle: g changes by more
 * than SWING (modulo 2 pi, a wrap of g is no change) across one cell. The closed form's q_J
 * swings by pi where its joint's neighbour in the wrist passes its singularity (sin -> 0), in
 * a dip of the WRIST quantity that can be far narrower than the gate's samples; there the
 * neighbour across the WRIST boundary may hold a root in the band that no sample shows. */
static bool q_j_swings(om_problem *pb)
{
    int n = pb->s->scan_points;
    double q[OM_MAX_DOF], h = 2.0 * OM_PI / (double)n, first = om_g(pb, -OM_PI, q, false), before = first;
    for (int k = 1; k <= n; k++) {
        double gk = k < n ? om_g(pb, -OM_PI + h * (double)k, q, false) : first;
        if (fabs(om_wrap(gk - before)) > SWING) /* false for NaN (out of reach) */
            return true;
        before = gk;
    }
    return false;
}

int om_band_roots(om_problem *pb, double *roots, bool *neighbour_reached, om_scan_cache *cache)
{
    const om_solver_data *s = pb->s;
    int64_t signs[64];
    double redundancy[1], found[OM_MAX_ROOTS * OM_MAX_DOF];
    bool near[3];
    int count = touch_points(pb, near, roots);
    if (s->family != OM_SRS && s->mode == OM_CIRCLE && s->dp_joint == 5) /* q6 given: not for a4 != 0 */
        count = wrist_roots(pb, roots, count);
    if (s->mode == OM_CIRCLE && WRIST_SIGN < s->n_signs && !near[WRIST_SIGN])
        near[WRIST_SIGN] = q_j_swings(pb);
    *neighbour_reached = false;
    for (int i = 0; i < s->n_signs; i++) {
        if (!near[i])
            continue;
        om_problem other = neighbour(pb, i, signs, redundancy);
        int n = om_all_roots(&other, s->scan_points, found);
        pb->counter += other.counter;
        *neighbour_reached = *neighbour_reached || n > 0;
        for (int r = 0; r < n; r++) /* verified again in the problem's own configuration */
            count = om_add_root(pb, found + r * s->dof, roots, count);
    }
    if (count == 0) /* next to psi's half-line the model's search may miss what the real arm's loop meets */
        count = om_loop_roots(pb, roots, count, cache);
    return count;
}
