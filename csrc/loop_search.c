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
 * (om_loop_pass). */
#include "om_system.h"

#define LOOP_NEAR 1e-2       /* rad: the half-line's reach (om_polish_candidate's NEAR_BOUNDARY) */
#define LOOP_GATE 64         /* nodes per offset angle of the cheap test whether a pose may come near the line */
#define LOOP_STARTS 8        /* arm angles psi + 2 pi k / LOOP_STARTS whose roots start the traces */
#define LOOP_STEP 0.05       /* largest trace step (|dq|, rad) */
#define LOOP_STEP_MIN 1e-5   /* a step refused at this size ends the trace in that direction */
#define LOOP_LENGTH 40.0     /* rad of |dq| per direction: a Panda loop is about 14 */
#define LOOP_POINTS 4096     /* trace points kept (a start on a traced loop is skipped) */
#define LOOP_CORRECT 8       /* Jacobians of the corrector per step and per projected midpoint */
#define LOOP_ON_POSE 1e-12   /* pose residual (m, rad) of a point on the loop */
#define LOOP_DRIFT 0.25      /* the corrector moves at most this fraction of the step */
#define LOOP_BEND 0.9        /* the tangent turns by at most acos(LOOP_BEND) per step */
#define LOOP_TURN (OM_PI / 4.0) /* psi's turn across a calm segment (its bound, as its ends show) */
#define LOOP_CHORD 1e-7      /* |dq| below which a segment's midpoint is the chord's (off the loop by 1.3e-15 |q''|) */
#define LOOP_PASSES 3       /* Newton passes to a closest approach, each from the last one's on the loop */
#define LOOP_NEWTON 6       /* Newton steps of a pass along the tangent line */
#define LOOP_DIFFERENCE 1e-6 /* step (|dq|) of the central differences of `across` along the tangent */
#define LOOP_PASS_SCALES 64.0 /* a candidate's pass (om_loop_pass) is searched out to this many turning scales */
#define LOOP_OFFSET_MIN 1e-16 /* the smallest offset from a closest approach: below it q does not move */
#define LOOP_SPLITS 100000   /* midpoints per problem: a bound on the work (a loop by the line takes a few hundred) */

typedef struct {
    double q[7];
    double miss;    /* psi's wrapped miss of the requested one, read in the requested ELBOW branch */
    double grad[7]; /* d psi / dq */
    vec3 across;    /* up x (W - S) of the model: zero on the half-line, smooth through it */
    double angle;   /* of W - S from the half-line (om_srs_half_line_angle) */
    bool below;     /* W - S below the horizon of S (the half-line's side) */
} loop_point;

typedef struct {
    om_problem *pb;
    om_polish_task pose; /* the corrector: the pose rows alone */
    double *seen;        /* the points traced (LOOP_POINTS x 7) */
    int n_seen, splits;
} loop_search;

/* The search of the problem pb (seen: room for LOOP_POINTS trace points, or NULL: no trace). */
static loop_search _search(om_problem *pb, double *seen)
{
    const om_solver_data *s = pb->s;
    loop_search ls = {pb, {s->real_table, s->n_real_rows, 7, NULL, NULL, 0, pb->goal.R, pb->goal_p, 0.0, 0.0, true},
                       seen, 0, 0};
    return ls;
}

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

/* psi's miss and gradient at p->q. */
static void _measure(const loop_search *ls, loop_point *p)
{
    const om_problem *pb = ls->pb;
    om_arm_angle_gradient(pb->s->params, pb->s->model_table, pb->s->n_model_rows, p->q, p->grad);
    double psi = om_srs_half_line_psi(pb->s->params, p->q, (double)pb->signs[1], &p->across, &p->angle);
    p->below = p->angle < 0.5 * OM_PI;
    p->miss = om_wrap(psi - pb->redundancy[0]);
}

/* The unit null vector of the real Jacobian at q, turned toward `along` (NULL: as it comes);
 * false where J has lost rank (a branch point of the loop). */
static bool _tangent(const om_problem *pb, const double *q, const double *along, double *t)
{
    double n2 = 0.0, dot = 0.0;
    om_self_motion_null(pb->s, q, t);
    for (int j = 0; j < 7; j++) {
        n2 += t[j] * t[j];
        dot += along ? t[j] * along[j] : 0.0;
    }
    double k = (dot < 0.0 ? -1.0 : 1.0) / sqrt(n2);
    if (!(n2 > 0.0) || !isfinite(k))
        return false;
    for (int j = 0; j < 7; j++)
        t[j] *= k;
    return true;
}

/* The midpoint of the segment (a, b) of the loop into m: the chord's, on the loop again by
 * the corrector where the segment is longer than LOOP_CHORD. False where it cannot be split
 * (the midpoint is an end to the last bit, the corrector fails or moves it more than
 * LOOP_DRIFT of the segment, the budget is spent). The drift bound keeps m between the ends,
 * each half at most 3/4 of the segment: on a long segment the corrector may take the chord's
 * midpoint to another part of the loop, or back to an end, which splits nothing (the same
 * segment again, up to the budget, as deep in the recursion of _segment_roots). */
static bool _midpoint(loop_search *ls, const loop_point *a, const loop_point *b, loop_point *m)
{
    bool a_end = true, b_end = true;
    double length = 0.0;
    for (int j = 0; j < 7; j++) {
        m->q[j] = 0.5 * (a->q[j] + b->q[j]);
        a_end = a_end && m->q[j] == a->q[j];
        b_end = b_end && m->q[j] == b->q[j];
        length = py_max(length, fabs(b->q[j] - a->q[j]));
    }
    if (a_end || b_end || ls->splits >= LOOP_SPLITS)
        return false;
    ls->splits++;
    if (length > LOOP_CHORD) {
        double chord[7], drift = 0.0;
        memcpy(chord, m->q, sizeof chord);
        if (!(om_polish(&ls->pose, LOOP_CORRECT, m->q) <= LOOP_ON_POSE))
            return false;
        for (int j = 0; j < 7; j++)
            drift = py_max(drift, fabs(m->q[j] - chord[j]));
        if (drift > LOOP_DRIFT * length)
            return false;
    }
    _measure(ls, m);
    return true;
}

/* The crossing of the requested psi in (a, b), whose misses differ in sign (not a wrap):
 * bisected to the last bit, the end nearer psi verified first. Returns the root count. */
static int _bisect(loop_search *ls, loop_point a, loop_point b, double *roots, int count)
{
    loop_point m;
    while (_midpoint(ls, &a, &b, &m)) {
        if (m.miss * a.miss > 0.0)
            a = m;
        else
            b = m;
    }
    loop_point *near = fabs(a.miss) <= fabs(b.miss) ? &a : &b, *far = near == &a ? &b : &a;
    int before = count;
    count = om_add_root(ls->pb, near->q, roots, count);
    return count > before ? count : om_add_root(ls->pb, far->q, roots, count);
}

/* psi's crossings of the requested value on the loop's segment (a, b): a calm segment is
 * bisected where its misses change sign; any other is split in two (next to the half-line,
 * down to the scale rho on which psi turns). Calm: psi turns by at most LOOP_TURN across it,
 * as its ends show and as its slopes along it at both ends extrapolate, and below the
 * horizon the azimuth of `across` turns by at most half that. A pass at rho by the half-line
 * turns psi by 2 pi within a few rho / v, invisible to psi at ends far from it (a full turn,
 * slopes of rho / (v s^2)), but the azimuth of `across` turns by nearly pi between them. */
static int _segment_roots(loop_search *ls, const loop_point *a, const loop_point *b, double *roots, int count)
{
    double change_a = 0.0, change_b = 0.0; /* grad psi . (b - a) at either end */
    for (int j = 0; j < 7; j++) {
        change_a += a->grad[j] * (b->q[j] - a->q[j]);
        change_b += b->grad[j] * (b->q[j] - a->q[j]);
    }
    double azimuth = atan2(v_norm(v_cross(a->across, b->across)), v_dot(a->across, b->across));
    bool calm = fabs(om_wrap(b->miss - a->miss)) <= LOOP_TURN && fabs(change_a) <= LOOP_TURN &&
                fabs(change_b) <= LOOP_TURN && (!(a->below || b->below) || azimuth <= 0.5 * LOOP_TURN);
    loop_point m;
    if (!calm && _midpoint(ls, a, b, &m)) {
        count = _segment_roots(ls, a, &m, roots, count);
        return _segment_roots(ls, &m, b, roots, count);
    }
    if (a->miss * b->miss <= 0.0 && fabs(a->miss - b->miss) < OM_PI) /* false for NaN */
        count = _bisect(ls, *a, *b, roots, count);
    return count;
}

/* up x (W - S) at q + s t (x: scratch). */
static vec3 _across_at(const om_problem *pb, const double *q, const double *t, double s, double *x)
{
    for (int j = 0; j < 7; j++)
        x[j] = q[j] + s * t[j];
    return om_srs_half_line_across(pb->s->params, x);
}

/* `across` at q + s t and its first two derivatives in s (central differences: it is smooth
 * through the half-line, unlike psi). */
static vec3 _across_derivatives(const om_problem *pb, const double *q, const double *t, double s, vec3 *d1, vec3 *d2)
{
    double x[7], d = LOOP_DIFFERENCE;
    vec3 h = _across_at(pb, q, t, s, x), hp = _across_at(pb, q, t, s + d, x), hm = _across_at(pb, q, t, s - d, x);
    *d1 = v_scale(0.5 / d, v_sub(hp, hm));
    *d2 = v_scale(1.0 / (d * d), v_add(v_sub(hp, v_scale(2.0, h)), hm));
    return h;
}

/* The point of the loop at q + s t, on the pose again by the corrector where s exceeds
 * LOOP_CHORD (the tangent line leaves the loop by O(s^2)); false where the corrector fails. */
static bool _loop_point_at(loop_search *ls, const double *q, const double *t, double s, loop_point *p)
{
    for (int j = 0; j < 7; j++)
        p->q[j] = q[j] + s * t[j];
    if (fabs(s) > LOOP_CHORD && !(om_polish(&ls->pose, LOOP_CORRECT, p->q) <= LOOP_ON_POSE))
        return false;
    _measure(ls, p);
    return true;
}

/* The loop's closest approach to the half-line near its point b (within reach, in |dq|) and
 * psi's crossings around it. The approach may pass the half-line at rho (a straight pass:
 * `across` turns by pi within a few rho / v) or fold back by it (|h| about rho + |h''| s^2 /
 * 2: a full turn, or none, within sqrt(2 rho / |h''|)); the ends of a trace step see neither.
 * The closest approach s* (Newton on h . h' = 0 along the tangent, from the last pass's point
 * on the loop), then points of the loop at s* +- sigma 2^k out to reach, or to `scales` times
 * the smaller turning scale, sigma a quarter of it, whose consecutive pairs are searched as
 * any segment (_segment_roots: a part whose turn is not calm yet is split). Returns the root
 * count. */
static int _pass_roots(loop_search *ls, const loop_point *b, double reach, double scales, double *roots, int count)
{
    const om_problem *pb = ls->pb;
    double t[7];
    loop_point centre = *b;
    vec3 h = v3(NAN, NAN, NAN), d1, d2;
    for (int pass = 0; pass < LOOP_PASSES; pass++) {
        if (!_tangent(pb, centre.q, NULL, t))
            return count;
        double s = 0.0;
        for (int it = 0; it < LOOP_NEWTON; it++) {
            h = _across_derivatives(pb, centre.q, t, s, &d1, &d2);
            double slope = v_dot(d1, d1) + v_dot(h, d2);
            double next = py_min(py_max(s - v_dot(h, d1) / slope, -reach), reach);
            if (!(slope > 0.0) || !isfinite(next) || next == s)
                break;
            s = next;
        }
        loop_point moved;
        if (!_loop_point_at(ls, centre.q, t, s, &moved))
            return count;
        centre = moved;
        if (fabs(s) <= LOOP_CHORD)
            break;
    }
    h = _across_derivatives(pb, centre.q, t, 0.0, &d1, &d2);
    double rho = v_norm(h), scale = rho / py_max(v_norm(d1), sqrt(0.5 * rho * v_norm(d2)));
    double sigma = py_max(0.25 * scale, LOOP_OFFSET_MIN);
    if (!isfinite(sigma))
        return count;
    reach = py_min(reach, 4.0 * scales * sigma); /* sigma: a quarter of the scale, at least LOOP_OFFSET_MIN */
    for (int side = -1; side <= 1; side += 2) { /* centre, then outward to one side */
        loop_point inner = centre, outer;
        for (double s = sigma; s < 2.0 * reach; s *= 2.0) {
            if (!_loop_point_at(ls, centre.q, t, (double)side * py_min(s, reach), &outer))
                continue;
            count = _segment_roots(ls, &inner, &outer, roots, count);
            inner = outer;
        }
    }
    return count;
}

/* The search around the closest approach near the trace point a where a is below the
 * horizon, within LOOP_NEAR of the half-line and a local minimum of the line angle between
 * its neighbours before and after (_pass_roots, out to them). Returns the root count. */
static int _near_pass(loop_search *ls, const loop_point *before, const loop_point *a, const loop_point *after,
                      double *roots, int count)
{
    if (!(a->below && a->angle < LOOP_NEAR && a->angle < before->angle && a->angle <= after->angle))
        return count;
    double reach = sqrt(7.0) * py_max(om_wrapped_distance_max(before->q, a->q, 7), om_wrapped_distance_max(after->q, a->q, 7)); /* |dq| bound */
    return _pass_roots(ls, a, reach, INFINITY, roots, count);
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
    if (!_tangent(pb, q0, NULL, t0))
        return count;
    memcpy(start.q, q0, sizeof start.q);
    _measure(ls, &start);
    for (int way = 0; way < 2; way++) {
        loop_point before = start, a = start, b;
        double t[7], tb[7], h = LOOP_STEP, length = 0.0;
        for (int j = 0; j < 7; j++)
            t[j] = (way == 0 ? 1.0 : -1.0) * t0[j];
        while (length < LOOP_LENGTH && h >= LOOP_STEP_MIN) {
            double drift = 0.0, turn = 0.0;
            for (int j = 0; j < 7; j++)
                b.q[j] = a.q[j] + h * t[j];
            bool on = om_polish(&ls->pose, LOOP_CORRECT, b.q) <= LOOP_ON_POSE && _tangent(pb, b.q, t, tb);
            for (int j = 0; on && j < 7; j++) {
                drift = py_max(drift, fabs(b.q[j] - a.q[j] - h * t[j]));
                turn += tb[j] * t[j];
            }
            if (!on || drift > LOOP_DRIFT * h || turn < LOOP_BEND) {
                h *= 0.5;
                continue;
            }
            _measure(ls, &b);
            count = _segment_roots(ls, &a, &b, roots, count);
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
                count = _segment_roots(ls, &a, &start, roots, count);
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
    loop_search ls = _search(pb, malloc((size_t)LOOP_POINTS * 7 * sizeof(double)));
    if (!ls.seen)
        return count;
    double starts[OM_MAX_ROOTS * OM_MAX_DOF];
    /* psi + pi first, then + pi / 2 and - pi / 2, ...: the farthest from the requested one */
    static const int order[LOOP_STARTS - 1] = {4, 2, 6, 1, 3, 5, 7};
    for (int i = 0; i < LOOP_STARTS - 1 && count == 0; i++) {
        double psi = om_wrap(pb->redundancy[0] + 2.0 * OM_PI * (double)order[i] / (double)LOOP_STARTS);
        om_problem other = om_problem_at(pb, pb->signs, &psi);
        int n = om_all_roots(&other, s->scan_points, starts, pb->q_prev, INFINITY);
        pb->counter += other.counter;
        for (int r = 0; r < n; r++)
            if (!_seen(&ls, starts + 7 * r))
                count = _trace(&ls, starts + 7 * r, roots, count);
    }
    free(ls.seen);
    return count;
}

bool om_loop_pass(om_problem *pb, double *q, double *pos, double *ori)
{
    loop_search ls = _search(pb, NULL);
    double roots[OM_MAX_ROOTS * OM_MAX_DOF];
    loop_point b;
    memcpy(b.q, q, sizeof b.q);
    _measure(&ls, &b);
    if (_pass_roots(&ls, &b, LOOP_STEP, LOOP_PASS_SCALES, roots, 0) == 0)
        return false;
    memcpy(q, roots, sizeof b.q);
    return om_verify(pb, q, pos, ori);
}
