/* The redundancy optimiser's objective at joint vectors (om_redundant/redundancy/objective/objective.py's
 * Objective.evaluate and evaluations, which call it): the normalised joint-limit margin
 * M = min_i min((q_i - l_i)/h_i, (u_i - q_i)/h_i), the clearance D = min_k d_k (the pairs'
 * distances, computed by MuJoCo and clearance.c), the singularity distance
 * S = min_k |sin(q_{j_k} + c_k)|, and
 *   f = w_m M + w_c min(1, D/d_cap) + w_s min(1, S/s_cap),  slack = min(M, (D - d_min)/d_cap),
 * each sum and quotient in the order objective.py's numpy reference rounds them. No limited joint
 * (L = 0), no obstacle (P = 0) or no singularity (K = 0): no such term. */
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
