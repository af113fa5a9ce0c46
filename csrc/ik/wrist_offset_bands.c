/* The bands around the wrist singularities of the dp circle of a 6-DOF arm whose wrist has
 * a4 != 0 (its geometry: wrist_offset.c), scanned like the circle (circle.c): where joint 5's
 * axis z4 swings fast with w = q1. */
#include "om_system.h"

#define STEEP_WRIST 0.3 /* |z3 x z5| below which the circle's point swings fast enough to need the bands */
#define BAND_POINTS 5   /* samples of each band (4 cells) */
#define MAX_BANDS 48    /* halvings of the band's distance to the singular w (0.3 / 2^48 < 1e-15) */

/* The bands around the singular w0 (width |n_min| / rho) within [lo, hi], scanned into
 * cands[n:]; returns the new count (see om_wrist_offset_candidates). */
static int _bands(om_problem *pb, double w0, double width, double rho, double lo, double hi, double *q, double *cands,
                  int n, int cap)
{
    double x = py_min(STEEP_WRIST / rho, OM_PI), inner = py_max(0.25 * width, 1e-15);
    for (int band = 0; band < MAX_BANDS && x > inner; band++, x *= 0.5)
        for (int side = -1; side <= 1; side += 2) {
            double u = w0 + side * 0.5 * x, v = w0 + side * x;
            double from = py_max(py_min(u, v), lo), to = py_min(py_max(u, v), hi);
            if (to > from)
                n += om_circle_candidates(pb, from, to, BAND_POINTS, false, NAN, q, cands + n, cap - n);
        }
    double from = py_max(w0 - x, lo), to = py_min(w0 + x, hi);
    if (to > from)
        n += om_circle_candidates(pb, from, to, BAND_POINTS, false, NAN, q, cands + n, cap - n);
    return n;
}

/* Candidate roots of g near the wrist singularities of the circle, into cands (capacity cap);
 * returns the count. z3(w) . z5 = a + rho cos(w - phi) (z3 turns about joint 1's axis, z5 is
 * the target's), so |z3 x z5|^2 = 1 - (z3 . z5)^2 is smallest at w0 = phi or phi + pi. Near
 * w0, n = z3 x z5 ~ n_min + n' (w - w0) and z4 = n / |n| turns through up to pi, over a width
 * of about |n_min| / rho: the uniform scan's cells may hold that swing (and an island of reach
 * narrower than a cell, where the wrist is nearly singular at the solution). The bands
 * [w0 + s x / 2, w0 + s x], x halved from STEEP_WRIST / rho down to |n_min| / (4 rho), then
 * [w0 - x, w0 + x], are scanned like the circle (om_circle_candidates on each): over a band
 * z4's angle, about atan((w - w0) rho / n_min), changes by at most atan(2u) - atan(u) <= 0.34
 * rad (0.12 rad per cell), whatever n_min's scale, and by at most 0.49 rad over the inner
 * window. Windowed solves (hi - lo < 2 pi) scan the parts inside [lo, hi] of the bands around
 * w0 and its image w0 - 2 pi (w0 taken into [lo, lo + 2 pi)). */
int om_wrist_offset_candidates(om_problem *pb, double lo, double hi, bool full_circle, double *q, double *cands,
                               int cap)
{
    const double *P = pb->s->params;
    vec3 z5 = m_mv(pb->t.R, v_load(P, SD_AXIS6));
    double a = v_dot(v_load(P, SD_AXIS4), z5), b = v_dot(v_load(P, SD_AXIS4 + 3), z5),
           c = v_dot(v_load(P, SD_AXIS4 + 6), z5);
    double rho = sqrt(b * b + c * c), phi = atan2(c, b);
    int n = 0;
    if (!(rho > 1e-12))
        return 0;
    for (int k = 0; k < 2; k++) {
        double f = a + (k ? -rho : rho), w0 = phi + (k ? OM_PI : 0.0);
        double n_min = sqrt(py_max(0.0, 1.0 - f * f));
        if (!(n_min < STEEP_WRIST))
            continue;
        if (!full_circle) /* w0 into [lo, lo + 2 pi); its image w0 - 2 pi may reach into [lo, hi] too */
            w0 = lo + (w0 - lo) - 2.0 * OM_PI * floor((w0 - lo) / (2.0 * OM_PI));
        for (int image = 0; image < (full_circle ? 1 : 2); image++)
            n = _bands(pb, w0 - 2.0 * OM_PI * image, n_min / rho, rho, full_circle ? -INFINITY : lo,
                       full_circle ? INFINITY : hi, q, cands, n, cap);
    }
    return n;
}
