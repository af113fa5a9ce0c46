/* The self-motion tangents dq/dpsi of many joint vectors of a 7-DOF arm in one call: the
 * samples of the global choose's sweep (om_redundant/redundancy/self_motion.py's
 * self_motion_tangents), each om_self_motion_tangent's (self_motion.c), the one that follow.c
 * gives the points it reaches. (Its binding: csrc/binding/paths.c.) */
#include "om_paths.h"

void om_self_motion_tangents(const om_solver_data *s, const double *q, double *t, ptrdiff_t rows) {
    for (ptrdiff_t k = 0; k < rows; k++)
        if (!om_self_motion_tangent(s, q + 7 * k, t + 7 * k, 0.0))
            for (int i = 0; i < 7; i++) t[7 * k + i] = NAN;
}
