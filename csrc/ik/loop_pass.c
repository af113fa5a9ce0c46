/* The real arm's self-motion loop next to psi's singular half-line: its points (psi's miss,
 * gradient and `across`), psi's crossings on a segment of it (split where psi turns, bisected
 * where its miss changes sign), and the search around the loop's closest approach to the
 * half-line, where psi turns by 2 pi within a few rho / v: for the traces of loop_search.c,
 * and for a candidate that meets the pose but not psi next to the line (om_loop_pass). */
#include "loop_search.h"

#define LOOP_TURN (OM_PI / 4.0) /* psi's turn across a calm segment (its bound, as its ends show) */
#define LOOP_CHORD 1e-7      /* |dq| below which a segment's midpoint is the chord's (off the loop by 1.3e-15 |q''|) */
#define LOOP_PASSES 3       /* Newton passes to a closest approach, each from the last one's on the loop */
#define LOOP_NEWTON 6       /* Newton steps of a pass along the tangent line */
#define LOOP_DIFFERENCE 1e-6 /* step (|dq|) of the central differences of `across` along the tangent */
#define LOOP_PASS_SCALES 64.0 /* a candidate's pass (om_loop_pass) is searched out to this many turning scales */
#define LOOP_OFFSET_MIN 1e-16 /* the smallest offset from a closest approach: below it q does not move */
#define LOOP_SPLITS 100000   /* midpoints per problem: a bound on the work (a loop by the line takes a few hundred) */

/* psi's miss and gradient at p->q. */
void om_loop_measure(const loop_search *ls, loop_point *p)
{
    const om_problem *pb = ls->pb;
    om_arm_angle_gradient(pb->s->params, pb->s->model_table, pb->s->n_model_rows, p->q, p->grad);
    double psi = om_srs_half_line_psi(pb->s->params, p->q, (double)pb->signs[1], &p->across, &p->angle);
    p->below = p->angle < 0.5 * OM_PI;
    p->miss = om_wrap(psi - pb->redundancy[0]);
}

/* The unit null vector of the real Jacobian at q, turned toward `along` (NULL: as it comes);
 * false where J has lost rank (a branch point of the loop). */
bool om_loop_tangent(const om_problem *pb, const double *q, const double *along, double *t)
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
 * segment again, up to the budget, as deep in the recursion of om_loop_segment_roots). */
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
    om_loop_measure(ls, m);
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
int om_loop_segment_roots(loop_search *ls, const loop_point *a, const loop_point *b, double *roots, int count)
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
        count = om_loop_segment_roots(ls, a, &m, roots, count);
        return om_loop_segment_roots(ls, &m, b, roots, count);
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
    om_loop_measure(ls, p);
    return true;
}

/* The loop's closest approach to the half-line near its point b (within reach, in |dq|) and
 * psi's crossings around it. The approach may pass the half-line at rho (a straight pass:
 * `across` turns by pi within a few rho / v) or fold back by it (|h| about rho + |h''| s^2 /
 * 2: a full turn, or none, within sqrt(2 rho / |h''|)); the ends of a trace step see neither.
 * The closest approach s* (Newton on h . h' = 0 along the tangent, from the last pass's point
 * on the loop), then points of the loop at s* +- sigma 2^k out to reach, or to `scales` times
 * the smaller turning scale, sigma a quarter of it, whose consecutive pairs are searched as
 * any segment (om_loop_segment_roots: a part whose turn is not calm yet is split). Returns the root
 * count. */
int om_loop_pass_roots(loop_search *ls, const loop_point *b, double reach, double scales, double *roots, int count)
{
    const om_problem *pb = ls->pb;
    double t[7];
    loop_point centre = *b;
    vec3 h = v3(NAN, NAN, NAN), d1, d2;
    for (int pass = 0; pass < LOOP_PASSES; pass++) {
        if (!om_loop_tangent(pb, centre.q, NULL, t))
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
            count = om_loop_segment_roots(ls, &inner, &outer, roots, count);
            inner = outer;
        }
    }
    return count;
}

bool om_loop_pass(om_problem *pb, double *q, double *pos, double *ori)
{
    loop_search ls = om_loop_search(pb, NULL);
    double roots[OM_MAX_ROOTS * OM_MAX_DOF];
    loop_point b;
    memcpy(b.q, q, sizeof b.q);
    om_loop_measure(&ls, &b);
    if (om_loop_pass_roots(&ls, &b, LOOP_STEP, LOOP_PASS_SCALES, roots, 0) == 0)
        return false;
    memcpy(q, roots, sizeof b.q);
    return om_verify(pb, q, pos, ori);
}
