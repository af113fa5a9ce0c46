/* Private helpers of the OM system's kernels (residual.c ... solve.c): Python's float
 * semantics where the algorithm relies on them. Not part of the binding's contract. */

/* The system's files by the calls between them, bottom to top: a file calls only files on the
 * lines above its own (no cycles: issue 33). Where a lower file must reach a higher one, the
 * higher passes its function down: om_near_settle's model IK (residual.c's evaluations, near.c),
 * a near arm's window of G (circle.c's, to circle_runs.c as circle_scan.window).
 *   common.c kinematics.c wrist_offset.c
 *   six_dof.c srs.c
 *   srs_arm_angle.c
 *   families.c polish.c
 *   problem.c verify.c
 *   near.c
 *   residual.c self_motion.c
 *   scalar.c circle_pole.c loop_pass.c torus_newton.c
 *   boundary.c circle_samples.c circle_runs.c
 *   circle.c contraction.c torus_half_line.c
 *   torus.c wrist_offset_bands.c
 *   search.c
 *   loop_search.c
 *   bands.c
 *   solve.c */
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

/* near.c: a local root from w on the circle (the secant on g, om_secant_in_reach if in_reach,
 * else om_secant): for an arm near a family that scans its nominal arm, the nominal arm's root
 * from w first and Newton's steps on the exact chain from it, returning true with q that
 * verified root (its errors into *pos, *ori; NULL: not wanted); where they fail (and for every
 * other arm), the secant on G from the nominal root (from w where it touched no zero): false,
 * q its model IK at the end. */
bool om_near_secant(om_problem *pb, double w, bool in_reach, double *q, double *pos, double *ori);
/* near.c: a local root from start (every joint) on the torus of an arm near a family: the nominal
 * arm's root (damped Newton on its lifted system, one model IK an evaluation) and Newton's steps
 * on the exact chain from it, returning true with q that verified root (its errors into *pos,
 * *ori); false where either fails (q as they left it). */
bool om_near_lifted(om_problem *pb, const double *start, double *q, double *pos, double *ori);
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
