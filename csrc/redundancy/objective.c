/* The redundancy optimiser's objective at joint vectors (om_redundant/redundancy/objective/objective.py's
 * Objective.evaluate and evaluations, which call it): the normalised joint-limit margin
 * M = min_i min((q_i - l_i)/h_i, (u_i - q_i)/h_i), the clearance D = min_k d_k (the pairs'
 * distances, computed by MuJoCo and clearance.c), the singularity distance
 * S = min_k |sin(q_{j_k} + c_k)|, and
 *   f = w_m M + w_c min(1, D/d_cap) + w_s min(1, S/s_cap),  slack = min(M, (D - d_min)/d_cap),
 * each sum and quotient in the order the numpy groups of tests/reference/objective.py round
 * them. No limited joint (L = 0), no obstacle (P = 0) or no singularity (K = 0): no such term.
 * And the pieces of those terms with their rates along the self-motion, which the climb's QP
 * linearises (om_linearise). */
#include "redundancy.h"

om_evaluation om_evaluate(const om_objective_terms *o, const double *q, const double *d, ptrdiff_t P) {
    double value = 0.0, slack = INFINITY, margin = INFINITY, clearance = INFINITY, singular = INFINITY;
    if (o->L > 0) {
        for (ptrdiff_t i = 0; i < o->L; i++) {
            double x = q[o->limited[i]], a = (x - o->lower[i]) / o->half[i], b = (o->upper[i] - x) / o->half[i];
            margin = fmin(margin, fmin(a, b));
        }
        value += o->margin_weight * margin;
        slack = fmin(slack, margin - 0.0);
    }
    if (P > 0) {
        double least = d[0];
        for (ptrdiff_t k = 1; k < P; k++) least = fmin(least, d[k]);
        double scaled = least / o->clearance_cap;
        value += o->clearance_weight * fmin(1.0, scaled);
        slack = fmin(slack, scaled - o->min_clearance / o->clearance_cap);
        clearance = scaled * o->clearance_cap;
    }
    if (o->K > 0) {
        double least = INFINITY;
        for (ptrdiff_t k = 0; k < o->K; k++) least = fmin(least, fabs(sin(q[o->joints[k]] + o->offsets[k])));
        double scaled = least / o->singularity_cap;
        value += o->singularity_weight * fmin(1.0, scaled);
        singular = scaled * o->singularity_cap;
    }
    return (om_evaluation){value, margin, clearance, slack, singular};
}

void om_linearise(const om_objective_terms *o, ptrdiff_t dof, const double *q, const double *t, const double *d,
                  const double *grad, ptrdiff_t P, double *v, double *a) {
    for (ptrdiff_t i = 0; i < o->L; i++) { /* (1/h) t_i: the numpy groups' (e_i / h) . t */
        double h = o->half[i], x = q[o->limited[i]], inv = 1.0 / h;
        v[i] = (x - o->lower[i]) / h, a[i] = inv * t[o->limited[i]];
        v[o->L + i] = (o->upper[i] - x) / h, a[o->L + i] = -inv * t[o->limited[i]];
    }
    ptrdiff_t n = 2 * o->L;
    double cap = o->clearance_cap, reach = 2.0 * cap, least = INFINITY;
    for (ptrdiff_t k = 0; k < P; k++) least = isnan(least) || d[k] >= least ? least : d[k]; /* (NaN stays) */
    for (ptrdiff_t k = 0; k < P; k++, n++) {
        if (least < reach && !(d[k] < reach)) { /* beyond the reach where a pair is within it */
            v[n] = reach / cap, a[n] = 0.0;
            continue;
        }
        double rate = 0.0;
        for (ptrdiff_t i = 0; i < dof; i++) rate += (grad[k * dof + i] / cap) * t[i];
        v[n] = d[k] / cap, a[n] = rate;
    }
    for (ptrdiff_t k = 0; k < o->K; k++, n++) {
        double x = q[o->joints[k]] + o->offsets[k], sine = sin(x), slope = cos(x);
        if (sine < 0.0) slope = -slope; /* sign(sin x) cos x; +cos x where sin x = 0 */
        v[n] = fabs(sine) / o->singularity_cap, a[n] = (slope / o->singularity_cap) * t[o->joints[k]];
    }
}
