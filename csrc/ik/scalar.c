/* Root and extremum finders in one unknown w, on the residual g of the circle
 * (the method: om_redundant/ik/kernel_data.py). */
#include "om_system.h"

#define LAST_STEP 1e-8 /* a secant step (rad) below which the next iterate is evaluated with every joint */
#define REACH_PROBES 8 /* probes each way around the circle for a reachable first point */
#define BACKTRACK 4    /* halvings of a secant step that leaves the model's reach */
#define STALL 4        /* secant steps in a row without PROGRESS after which it gives up */
#define PROGRESS 0.9   /* the factor by which a step must lower the least |g| so far */

static double _secant_from(om_problem *pb, double w0, double g0, double *q);

/* The secant (1-D Broyden) method from w0. Its first step is one of the fixed-point
 * iteration of system (9), w <- q_J(w) = w + g(w) (the secant with slope -1: g' = -1 +
 * dq_J/dw, and q_J turns little with w where dp is small against the arm); where that step
 * does not halve |g|, the secant starts again from w0 with a finite-difference slope. A step
 * that leaves the model's reach is halved (BACKTRACK times at most). It stops at |g| below
 * OM_ROOT_TOL or before a step below rounding, and gives up after STALL steps without PROGRESS (g near an extremum that
 * does not cross zero, or a root beyond the edge of reach). Returns |g| at the end, q
 * holding the model IK (every joint) at the last iterate. */
double om_secant(om_problem *pb, double w0, double *q)
{
    return _secant_from(pb, w0, om_g(pb, w0, q, false), q);
}

/* om_secant from w0, or where the model does not reach p_d + R delta(w0), from the nearest
 * reachable of REACH_PROBES probes each way around the circle (spaced pi / REACH_PROBES). */
double om_secant_in_reach(om_problem *pb, double w0, double *q)
{
    double g0 = om_g(pb, w0, q, false);
    for (int k = 1; k <= REACH_PROBES && isnan(g0) && pb->s->mode == OM_CIRCLE; k++) {
        for (int side = 1; side >= -1 && isnan(g0); side -= 2) {
            double w = w0 + (double)side * OM_PI * (double)k / (double)REACH_PROBES;
            g0 = om_g(pb, w, q, false);
            if (!isnan(g0))
                w0 = w;
        }
    }
    return _secant_from(pb, w0, g0, q);
}

static double _secant_from(om_problem *pb, double w0, double g0, double *q)
{
    if (pb->s->mode == OM_FIXED || isnan(g0))
        return fabs(g0);
    double w = w0, gw = g0, slope = -1.0;
    if (g0 != 0.0) {
        double step = fabs(g0) > 0.5 ? 0.5 * om_sign(g0) : g0;
        double g1 = om_g(pb, w0 + step, q, false);
        if (fabs(g1) <= 0.5 * fabs(g0)) { /* false for NaN */
            slope = (g1 - g0) / step;
            w = w0 + step;
            gw = g1;
        } else {
            double h = 1e-7;
            double gh = om_g(pb, w0 + h, q, false);
            slope = !isnan(gh) ? (gh - g0) / h : -1.0;
        }
    }
    bool complete = false; /* whether q holds every joint at w */
    /* near a family every evaluation of G writes every joint (om_model_ik_at) */
    bool every = pb->s->nominal_table && !pb->nominal && !pb->wrist;
    double best = fabs(gw);
    int stalled = 0;
    for (int it = 0; it < 40 && stalled < STALL; it++) {
        if (gw == 0.0 || slope == 0.0 || isnan(slope))
            break;
        double step = -gw / slope;
        if (fabs(step) < 1e-15 * py_max(1.0, fabs(w)))
            break;
        if (fabs(step) > 0.5)
            step = 0.5 * om_sign(step);
        bool last = fabs(step) < LAST_STEP;
        double g_new = om_g(pb, w + step, q, last);
        for (int k = 0; k < BACKTRACK && isnan(g_new); k++) {
            step *= 0.5;
            last = fabs(step) < LAST_STEP;
            g_new = om_g(pb, w + step, q, last);
        }
        if (isnan(g_new)) {
            complete = false;
            break;
        }
        slope = (g_new - gw) / step;
        w = w + step;
        gw = g_new;
        complete = last || every;
        if (fabs(gw) < OM_ROOT_TOL) /* q_J and w agree to 1e-13 rad: dp to about 1e-14 m */
            break;
        stalled = fabs(gw) < PROGRESS * best ? 0 : stalled + 1;
        best = py_min(best, fabs(gw));
    }
    if (!complete)
        gw = om_g(pb, w, q, true);
    return fabs(gw);
}

/* Illinois regula falsi on a sign-changing bracket; returns the root estimate. A gap of
 * reach inside the bracket shrinks it to the side whose edge keeps the sign change. */
double om_refine_bracket(om_problem *pb, double a, double ga, double b, double gb, double *q)
{
    int side = 0;
    for (int it = 0; it < 100; it++) {
        double c = (a * gb - b * ga) / (gb - ga);
        double gc = om_g(pb, c, q, false);
        if (isnan(gc)) {
            double e = om_reach_edge(pb, a, c, q);
            double ge = om_g(pb, e, q, false);
            if (ge * ga <= 0.0) {
                b = e;
                gb = ge;
            } else {
                e = om_reach_edge(pb, b, c, q);
                ge = om_g(pb, e, q, false);
                if (ge * gb > 0.0) /* no sign change on either side: none to refine */
                    return c;
                a = e;
                ga = ge;
            }
            side = 0;
            continue;
        }
        if (gc == 0.0 || fabs(b - a) < 1e-15)
            return c;
        if (om_sign(gc) == om_sign(gb)) {
            b = c;
            gb = gc;
            if (side == -1)
                ga *= 0.5;
            side = -1;
        } else {
            a = c;
            ga = gc;
            if (side == 1)
                gb *= 0.5;
            side = 1;
        }
    }
    return 0.5 * (a + b);
}

/* A reachable point next to the edge of the model's reach, between inside and outside:
 * Illinois regula falsi on the reach margin. */
double om_reach_edge(om_problem *pb, double inside, double outside, double *q)
{
    double fi = om_reach_margin(pb, inside, q) + OM_REACH_SLACK;
    double fo = om_reach_margin(pb, outside, q) + OM_REACH_SLACK;
    int side = 0;
    for (int it = 0; it < 80; it++) {
        if (fabs(outside - inside) <= 4e-16 * py_max(1.0, fabs(inside)))
            break;
        double c = (inside * fo - outside * fi) / (fo - fi);
        if (!(py_min(inside, outside) < c && c < py_max(inside, outside)))
            c = 0.5 * (inside + outside);
        double fc = om_reach_margin(pb, c, q) + OM_REACH_SLACK;
        if (fc >= 0.0) {
            inside = c;
            fi = fc;
            if (side == 1)
                fo *= 0.5;
            side = 1;
        } else {
            outside = c;
            fo = fc;
            if (side == -1)
                fi *= 0.5;
            side = -1;
        }
    }
    return inside;
}

/* sign * g(w) (unreachable: -inf), or the reach margin; and g (NaN where only the margin
 * is sought) and the margin. */
static double _objective(om_problem *pb, double w, double sign, bool of_margin, double *q, double *g_out,
                         double *m_out)
{
    if (of_margin) {
        *g_out = NAN;
        *m_out = om_reach_margin(pb, w, q);
        return *m_out;
    }
    double gw = om_g_margin(pb, w, q, false, m_out);
    *g_out = gw;
    return isnan(gw) ? -INFINITY : sign * gw;
}

/* Brent's search, from x0, for the maximum of sign * g (or of the reach margin) on [a, b];
 * stops at the first point that settles the caller's question. Returns the argmax, with g
 * and the margin there in *g_out and *margin_out (either may be NULL). */
double om_extremum(om_problem *pb, double a, double b, double x0, double sign, bool of_margin, double *q,
                   double *g_out, double *margin_out)
{
    const double golden = 0.3819660112501051;
    double x = x0, w = x0, v = x0;
    double gx, mx;
    double fx = _objective(pb, x, sign, of_margin, q, &gx, &mx);
    double fw = fx, fv = fx;
    double d = 0.0, e = 0.0;
    for (int it = 0; it < 60; it++) {
        if (!of_margin ? fx > 0.0 : mx >= -OM_REACH_SLACK)
            break;
        double xm = 0.5 * (a + b);
        double tol = 1e-10 * fabs(x) + 1e-11;
        if (fabs(x - xm) <= 2.0 * tol - 0.5 * (b - a))
            break;
        bool parabolic = false;
        if (fabs(e) > tol) { /* a parabola through x, w, v (NaN with an unreachable point: skipped) */
            double r = (x - w) * (fx - fv);
            double p_ = (x - v) * (fx - fw);
            double den = 2.0 * (p_ - r);
            double num = (x - v) * p_ - (x - w) * r;
            if (den > 0.0)
                num = -num;
            den = fabs(den);
            if (fabs(num) < fabs(0.5 * den * e) && num > den * (a - x) && num < den * (b - x)) {
                e = d;
                d = num / den;
                parabolic = true;
                if ((x + d) - a < 2.0 * tol || b - (x + d) < 2.0 * tol)
                    d = xm >= x ? tol : -tol;
            }
        }
        if (!parabolic) {
            e = x >= xm ? (a - x) : (b - x);
            d = golden * e;
        }
        double u = x + (fabs(d) >= tol ? d : (d > 0.0 ? tol : -tol));
        double gu, mu;
        double fu = _objective(pb, u, sign, of_margin, q, &gu, &mu);
        if (fu >= fx) {
            if (u >= x)
                a = x;
            else
                b = x;
            v = w;
            fv = fw;
            w = x;
            fw = fx;
            x = u;
            fx = fu;
            gx = gu;
            mx = mu;
        } else {
            if (u < x)
                a = u;
            else
                b = u;
            if (fu >= fw || w == x) {
                v = w;
                fv = fw;
                w = u;
                fw = fu;
            } else if (fu >= fv || v == x || v == w) {
                v = u;
                fv = fu;
            }
        }
    }
    /* q must belong to the returned point. */
    gx = om_g_margin(pb, x, q, false, &mx);
    if (g_out)
        *g_out = gx;
    if (margin_out)
        *margin_out = mx;
    return x;
}

/* The secant on the wrist's consistency residual (om_wrist_residual) from w0, a steep crossing
 * of g at a singular wrist of a 6-DOF circle arm. Returns |residual| at the end (NaN out of
 * reach); q holds the model IK there. */
double om_wrist_secant(om_problem *pb, double w0, double *q)
{
    double h = 1e-7, w = w0;
    double f = om_wrist_residual(pb, w, q);
    if (isnan(f))
        return f;
    double slope = (om_wrist_residual(pb, w + h, q) - f) / h;
    for (int it = 0; it < 40; it++) {
        if (f == 0.0 || slope == 0.0 || isnan(slope))
            break;
        double step = -f / slope;
        if (fabs(step) > 0.5)
            step = 0.5 * om_sign(step);
        double f_new = om_wrist_residual(pb, w + step, q);
        if (isnan(f_new))
            break;
        slope = (f_new - f) / step;
        w += step;
        f = f_new;
        if (fabs(step) < 1e-15 * (fabs(w) > 1.0 ? fabs(w) : 1.0) || fabs(f) < 1e-16)
            break;
    }
    return fabs(om_wrist_residual(pb, w, q)); /* q must belong to the final iterate */
}
