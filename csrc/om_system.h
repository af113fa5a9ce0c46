/* Private helpers of the OM system's kernels (residual.c ... solve.c): Python's float
 * semantics where the algorithm relies on them. Not part of the binding's contract. */
#ifndef OM_SYSTEM_H
#define OM_SYSTEM_H

#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "om_kernels.h"


/* Python's a % n for n > 0 (never negative). */
static inline int py_mod(int a, int n) { int r = a % n; return r < 0 ? r + n : r; }

/* One model IK of system (9), eval's: for an arm near a family, at the fixed point of its
 * correction (om_near_settle); for an arm in its family, and in a near arm's scan of its
 * nominal arm (pb->nominal), eval itself (inlined). */
static inline double om_near_ik(om_problem *pb, om_model_eval eval, const void *args, double *q)
{
    double residual;
    if (!pb->s->nominal_table || pb->nominal)
        return eval(pb, args, q, false, &residual);
    return om_near_settle(pb, eval, args, q);
}

/* near.c: the local solve's root of an arm near a family from its nominal arm's root q (every
 * joint), by Gauss-Newton steps on the exact chain; q replaced, and its errors into *pos, *ori,
 * only where the root reached verifies. Returns whether it did. */
bool om_near_newton(om_problem *pb, double *q, double *pos, double *ori);
/* near.c: om_near_polish of a verified root q whose errors *pos, *ori hold (not verified again). */
void om_near_finish(om_problem *pb, double *q, double *pos, double *ori);
/* polish.c: `steps` Newton steps on the exact chain with the start's Jacobian (the chord
 * method), q in place, untested (the caller verifies it). */
void om_polish_chord(const om_polish_task *t, int steps, double *q);

/* Whether solver s is an arm near a family whose searches take its nominal arm's residual g~
 * first, and the real arm's G where they may differ (near.c): up to OM_NEAR_SCAN. */
static inline bool om_scans_nominal(const om_solver_data *s)
{
    return s->nominal_table && s->near_deviation <= OM_NEAR_SCAN;
}

/* A scratch joint vector starts as NaN: a check of joints never written (a local solve whose
 * first point is out of reach) then always fails, never depends on what a previous call left. */
static inline void nan_fill(double *q, int n) { for (int j = 0; j < n; j++) q[j] = NAN; }

#endif
