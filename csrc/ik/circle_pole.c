/* The guard of the circle's scan at psi's singular half-line (S-R-S arms): which scan cells
 * the wrist centre passes close below the shoulder in, where psi's reference, q_J and g turn
 * by up to 2 pi within a fraction of the cell, and where such a cell is split (see pole_guard
 * in circle.h; the method: om_redundant/ik/kernel_data.py). */
#include "circle.h"

#define POLE_TURN (0.25 * OM_PI) /* rad: the most w_hat's azimuth about up turns in one cell below the shoulder */
#define POLE_BUDGET 65536        /* evaluations after which a scan splits no more cells (a pose far from
                                  * orthonormal splits every cell to POLE_DEPTH: exponential); the most
                                  * a whole solve takes on random poses is ~1,400 at 1,024 scan points */
#define POLE_NEWTON 8            /* Newton steps to the closest pass of h to zero in a cell */
#define POLE_ROUNDING 1e-15      /* relative rounding of W - S: of |e| + |u1| + |u2| (DBL_EPSILON 2.2e-16) */

/* The part of x across up. */
static vec3 _across(const pole_guard *pole, vec3 x)
{
    return v_sub(x, v_scale(v_dot(pole->up, x), pole->up));
}

/* The guard of the circle for scan cells of width L: active unless every cell keeps the
 * azimuth's turn below POLE_TURN (the whole ellipse above the shoulder, or h everywhere at
 * least M = |e across| - sigma from zero: its turn across a cell is at most sigma L / M, and
 * its chords keep 3 sigma L^2 / 8 clear of zero where M exceeds that). */
pole_guard om_pole_guard(om_problem *pb, double L)
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
 * the last bit). A part that is still not calm is split again (om_run_roots' depth). Returns
 * the count. */
int om_pole_splits(const pole_guard *pole, double a, double b, double *split)
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
