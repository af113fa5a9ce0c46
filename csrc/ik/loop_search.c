/* psi's singular half-line searched along the real arm's self-motion loops. Next to the
 * half-line (the model's wrist centre straight below the shoulder) psi turns by 2 pi within a
 * few rho / v of the loop's closest pass, and the model's search (circle, torus, their charts)
 * may find no candidate there, or only candidates of another branch: a false "no". The loop
 * itself is smooth there. So, where the pose's wrist centre can come near the half-line, a
 * 7-DOF S-R-S arm's configuration without a root is searched again: solutions of the pose in
 * the same branch signs at other arm angles (the bounded search, away from the trouble) are
 * points of its self-motion loops; each loop is traced in q at fixed T (the null vector of
 * the real 6 x 7 Jacobian, predictor and a corrector on the pose rows, no psi
 * parametrisation), whole, through every branch it passes, and psi's crossings of the
 * requested value along it are bisected to the last bit and verified as every candidate
 * (in the requested signs). A candidate of the model's search that meets the pose but not
 * psi next to the line gets the same search around the loop's closest approach
 * (om_loop_pass, loop_pass.c). */
#include "loop_search.h"

#define LOOP_NEAR 1e-2       /* rad: the half-line's reach (om_polish_candidate's NEAR_BOUNDARY) */
#define LOOP_GATE 64         /* nodes per offset angle of the cheap test whether a pose may come near the line */
#define LOOP_STARTS 8        /* arm angles psi + 2 pi k / LOOP_STARTS whose roots start the traces */
#define LOOP_STEP_MIN 1e-5   /* a step refused at this size ends the trace in that direction */
#define LOOP_LENGTH 40.0     /* rad of |dq| per direction: a Panda loop is about 14 */
#define LOOP_BEND 0.9        /* the tangent turns by at most acos(LOOP_BEND) per step */

/* The largest |a cos w + b sin w| over w: the largest singular value of the 3 x 2 (a, b). */
static double _ellipse_radius(vec3 a, vec3 b)
{
    double p = 0.5 * (v_dot(a, a) + v_dot(b, b)), d = 0.5 * (v_dot(a, a) - v_dot(b, b)), c = v_dot(a, b);
    return sqrt(p + sqrt(d * d + c * c));
}

/* Whether some x of the ball of radius r around c is within LOOP_NEAR rad of -up: its
 * directions make the cone of half-angle asin(r / |c|) around c. */
static bool _ball_may_pass(vec3 up, vec3 c, double r)
{
    double length = v_norm(c);
    return !(length > r) || atan2(v_norm(v_cross(up, c)), -v_dot(up, c)) - asin(r / length) < LOOP_NEAR;
}

/* What _gate reads of the pose: up, the centre c of x and the ellipses' axes a1, a2 (D4, D5)
 * and b1, b2 (R D1, R D2), 3 each (OM_GATE_KEY). */
static void _gate_key(const om_problem *pb, double *key)
{
    const double(*D)[3] = pb->s->D;
    const mat3 *R = &pb->t.R;
    const vec3 v[6] = {v_load(pb->s->params, SRS_UP), om_shoulder_wrist_centre(pb), v_load(D[4], 0),
                       v_load(D[5], 0),  m_mv(*R, v_load(D[1], 0)),     m_mv(*R, v_load(D[2], 0))};
    for (int i = 0; i < 6; i++)
        key[3 * i] = v[i].x, key[3 * i + 1] = v[i].y, key[3 * i + 2] = v[i].z;
}

/* Whether the model's shoulder-wrist vector x may come within LOOP_NEAR rad of -up at a
 * solution of the pose (key: _gate_key's): x(w1, w7) = p_d + R w_F - S + a(w1) + R delta(w7)
 * = c + A(w1) + B(w7), A and B ellipses of largest radii r1 = |(D4, D5)| and r7 = |(D1, D2)|,
 * so x moves by at most (r1 + r7) pi / LOOP_GATE from the nearest node of a LOOP_GATE x
 * LOOP_GATE grid of the two angles (one node along an angle x does not depend on). */
static bool _gate(const double *key)
{
    vec3 up = v_load(key, 0), c = v_load(key, 3), a1 = v_load(key, 6), a2 = v_load(key, 9);
    vec3 b1 = v_load(key, 12), b2 = v_load(key, 15);
    double r1 = _ellipse_radius(a1, a2), r7 = _ellipse_radius(b1, b2);
    int n1 = r1 > 0.0 ? LOOP_GATE : 1, n7 = r7 > 0.0 ? LOOP_GATE : 1;
    double r = (r1 + r7) * OM_PI / LOOP_GATE;
    for (int i = 0; i < n1; i++) {
        double w1 = 2.0 * OM_PI * (double)i / (double)n1;
        vec3 ci = v_add(c, v_add(v_scale(cos(w1), a1), v_scale(sin(w1), a2)));
        for (int j = 0; j < n7; j++) {
            double w7 = 2.0 * OM_PI * (double)j / (double)n7;
            if (_ball_may_pass(up, v_add(ci, v_add(v_scale(cos(w7), b1), v_scale(sin(w7), b2))), r))
                return true;
        }
    }
    return false;
}

/* _gate of the problem's pose, its answer kept in cache (NULL: none) for the next problem of
 * the same pose (every configuration without a root of a pose asks it). */
static bool _may_pass(const om_problem *pb, om_scan_cache *cache)
{
    double key[OM_GATE_KEY];
    _gate_key(pb, key);
    if (!cache)
        return _gate(key);
    if (!cache->gate_valid || memcmp(key, cache->gate_key, sizeof key) != 0) {
        cache->gate = _gate(key);
        memcpy(cache->gate_key, key, sizeof key);
        cache->gate_valid = true;
    }
    return cache->gate;
}

/* The search around the closest approach near the trace point a where a is below the
 * horizon, within LOOP_NEAR of the half-line and a local minimum of the line angle between
 * its neighbours before and after (om_loop_pass_roots, out to them). Returns the root count. */
static int _near_pass(loop_search *ls, const loop_point *before, const loop_point *a, const loop_point *after,
                      double *roots, int count)
{
    if (!(a->below && a->angle < LOOP_NEAR && a->angle < before->angle && a->angle <= after->angle))
        return count;
    double reach = sqrt(7.0) * py_max(om_wrapped_distance_max(before->q, a->q, 7), om_wrapped_distance_max(after->q, a->q, 7)); /* |dq| bound */
    return om_loop_pass_roots(ls, a, reach, INFINITY, roots, count);
}

/* Trace the self-motion loop through the pose's solution q0 (predictor along the tangent,
 * the corrector back onto the pose; a step halves where the corrector fails, drifts or the
 * tangent turns), both ways until it closes or LOOP_LENGTH, and search each step for psi's
 * crossings, each trace point for a close approach to the half-line (q0 too: between the
 * first points of the two ways, or between the last and the first where the loop closes).
 * Returns the root count. */
static int _trace(loop_search *ls, const double *q0, double *roots, int count)
{
    om_problem *pb = ls->pb;
    loop_point start, first[2]; /* the first point each way */
    bool stepped[2] = {false, false};
    double t0[7];
    if (!om_loop_tangent(pb, q0, NULL, t0))
        return count;
    memcpy(start.q, q0, sizeof start.q);
    om_loop_measure(ls, &start);
    for (int way = 0; way < 2; way++) {
        loop_point before = start, a = start, b;
        double t[7], tb[7], h = LOOP_STEP, length = 0.0;
        for (int j = 0; j < 7; j++)
            t[j] = (way == 0 ? 1.0 : -1.0) * t0[j];
        while (length < LOOP_LENGTH && h >= LOOP_STEP_MIN) {
            double drift = 0.0, turn = 0.0;
            for (int j = 0; j < 7; j++)
                b.q[j] = a.q[j] + h * t[j];
            bool on = om_polish(&ls->pose, LOOP_CORRECT, b.q) <= LOOP_ON_POSE && om_loop_tangent(pb, b.q, t, tb);
            for (int j = 0; on && j < 7; j++) {
                drift = py_max(drift, fabs(b.q[j] - a.q[j] - h * t[j]));
                turn += tb[j] * t[j];
            }
            if (!on || drift > LOOP_DRIFT * h || turn < LOOP_BEND) {
                h *= 0.5;
                continue;
            }
            om_loop_measure(ls, &b);
            count = om_loop_segment_roots(ls, &a, &b, roots, count);
            if (stepped[way])
                count = _near_pass(ls, &before, &a, &b, roots, count);
            else
                first[way] = b;
            stepped[way] = true;
            before = a;
            length += h;
            if (ls->n_seen < LOOP_POINTS)
                memcpy(ls->seen + 7 * ls->n_seen++, b.q, sizeof b.q);
            a = b;
            memcpy(t, tb, sizeof t);
            h = py_min(2.0 * h, LOOP_STEP);
            if (length > 4.0 * LOOP_STEP && om_wrapped_distance_max(a.q, q0, 7) < h) { /* closed: the other way is the same loop */
                count = om_loop_segment_roots(ls, &a, &start, roots, count);
                count = _near_pass(ls, &before, &a, &start, roots, count);
                return _near_pass(ls, &a, &start, &first[way], roots, count);
            }
        }
    }
    return stepped[0] && stepped[1] ? _near_pass(ls, &first[0], &start, &first[1], roots, count) : count;
}

/* Whether q lies on a loop already traced: within two steps of a kept point. */
static bool _seen(const loop_search *ls, const double *q)
{
    for (int k = 0; k < ls->n_seen; k++)
        if (om_wrapped_distance_max(q, ls->seen + 7 * k, 7) < 2.0 * LOOP_STEP)
            return true;
    return false;
}

int om_loop_roots(om_problem *pb, double *roots, int count, om_scan_cache *cache)
{
    const om_solver_data *s = pb->s;
    if (s->family != OM_SRS || s->dof != 7 || !_may_pass(pb, cache))
        return count;
    loop_search ls = om_loop_search(pb, malloc((size_t)LOOP_POINTS * 7 * sizeof(double)));
    if (!ls.seen)
        return count;
    double starts[OM_MAX_ROOTS * OM_MAX_DOF];
    /* psi + pi first, then + pi / 2 and - pi / 2, ...: the farthest from the requested one */
    static const int order[LOOP_STARTS - 1] = {4, 2, 6, 1, 3, 5, 7};
    for (int i = 0; i < LOOP_STARTS - 1 && count == 0; i++) {
        double psi = om_wrap(pb->redundancy[0] + 2.0 * OM_PI * (double)order[i] / (double)LOOP_STARTS);
        om_problem other = om_problem_at(pb, pb->signs, &psi);
        int n = om_all_roots(&other, s->scan_points, starts);
        pb->counter += other.counter;
        for (int r = 0; r < n; r++)
            if (!_seen(&ls, starts + 7 * r))
                count = _trace(&ls, starts + 7 * r, roots, count);
    }
    free(ls.seen);
    return count;
}
