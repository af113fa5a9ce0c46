/* What the search along the real arm's self-motion loops (loop_search.c) and the search
 * around a loop's closest pass by psi's half-line (loop_pass.c) share: a point of the loop
 * and the search's state, the trace's step and corrector. */
#ifndef OM_LOOP_SEARCH_H
#define OM_LOOP_SEARCH_H

#include "om_system.h"

#define LOOP_STEP 0.05       /* largest trace step (|dq|, rad) */
#define LOOP_CORRECT 8       /* Jacobians of the corrector per step and per projected midpoint */
#define LOOP_ON_POSE 1e-12   /* pose residual (m, rad) of a point on the loop */
#define LOOP_DRIFT 0.25      /* the corrector moves at most this fraction of the step */
#define LOOP_POINTS 4096     /* trace points kept (a start on a traced loop is skipped) */

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
static inline loop_search om_loop_search(om_problem *pb, double *seen)
{
    const om_solver_data *s = pb->s;
    loop_search ls = {pb, {s->real_table, s->n_real_rows, 7, NULL, NULL, 0, pb->goal.R, pb->goal_p, 0.0, 0.0, true},
                       seen, 0, 0};
    return ls;
}

/* psi's miss and gradient at p->q. */
void om_loop_measure(const loop_search *ls, loop_point *p);
/* The unit null vector of the real Jacobian at q, turned toward `along` (NULL: as it comes);
 * false where J has lost rank (a branch point of the loop). */
bool om_loop_tangent(const om_problem *pb, const double *q, const double *along, double *t);
/* psi's crossings of the requested value on the loop's segment (a, b), verified into roots
 * from count on; returns the root count. */
int om_loop_segment_roots(loop_search *ls, const loop_point *a, const loop_point *b, double *roots, int count);
/* The loop's closest approach to the half-line near its point b and psi's crossings around it
 * (out to reach, or to `scales` turning scales); returns the root count. */
int om_loop_pass_roots(loop_search *ls, const loop_point *b, double reach, double scales, double *roots, int count);

#endif
