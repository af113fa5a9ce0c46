/* What the circle's bounded search (circle.c), its samples (circle_samples.c), its guard at
 * psi's half-line (circle_pole.c) and its roots on runs of reach (circle_runs.c) share. */
#ifndef OM_CIRCLE_H
#define OM_CIRCLE_H

#include "om_system.h"

#define POLE_SPLITS 3            /* split points on either side of a close pass: azimuth steps of pi / 8 */
#define POLE_SPREAD 60           /* then offsets doubling out to the cell's ends (g's own slope beside the turn) */

/* An arm near a family scans its nominal arm's g~ and searches G in windows (near.c): G may
 * cross zero where it is within NEAR_DIFFERENCE times its difference from g~ of it. */
#define NEAR_DIFFERENCE 4.0

/* How near to zero a near arm's g~, reach margin or branch quantity comes for G's to reach it. */
static inline double circle_near(const om_problem *pb) { return OM_NEAR_SENSITIVITY * pb->s->near_deviation; }

/* The scan memo of one ELBOW branch (circle_samples.c). */
typedef struct scan_memo scan_memo;
/* g and the reach margin at the scan's points ws[k] = lo + h k, k < n_pts, into gs and ms (a near
 * arm's branch quantities into bs); returns the memo's branch, now this scan's (NULL: none). */
scan_memo *om_circle_sample(om_problem *pb, double lo, double h, int n_pts, double *ws, double *gs, double *ms,
                            double *bs, double *q);
/* The model's parts at the samples of the memo's scan. */
const om_srs_elbow *om_scan_memo_parts(const scan_memo *memo);
/* The edge of reach om_reach_edge(inside, outside) and g there into *g, through memo (NULL: none). */
double om_circle_edge(om_problem *pb, scan_memo *memo, double inside, double outside, double *q, double *g);

/* psi's singular half-line on the circle. The model's shoulder-wrist vector is x(w) = W(w) -
 * S = e + u1 cos w + u2 sin w (om_srs_wrist_circle), an ellipse: its part across up, h(w), and
 * its height z(w) = up . x(w). Where x passes close by -up (the wrist centre straight below the
 * shoulder), psi's reference n(w_hat) = R(up -> w_hat) r turns by about twice the azimuth of h,
 * a full turn within a fraction of a scan cell when h passes close by zero, and with it q_J
 * and g: a root there is not bracketed by the samples. Such a cell is split until the azimuth
 * turns by at most POLE_TURN in each part, by a bound: on a cell [a, b] of width L, h stays
 * within sigma L^2 t (1 - t) / 2 of its chord h(a) + t (h(b) - h(a)) (|h''| <= sigma, the
 * largest singular value of u1, u2 across up), so where the chord keeps farther than that
 * from zero, the azimuth of h turns across the cell as the chord's ends show. */
typedef struct {
    bool active; /* some cell may be one to split (a bound over the whole ellipse) */
    vec3 up, e, u1, u2;
    double sigma;   /* bounds |h'| and |h''| */
    double sigma_z; /* bounds |z''| */
    double slack;   /* rounding of x(w) (m) */
    int64_t until;  /* pb->counter from which no cell is split (POLE_BUDGET) */
} pole_guard;


/* The guard of the circle for scan cells of width L (circle_pole.c). */
pole_guard om_pole_guard(om_problem *pb, double L);
/* Where the cell [a, b] is to be split at psi's half-line: the split points into split
 * (2 (POLE_SPLITS + POLE_SPREAD) + 1); returns the count, 0 where the cell is calm. */
int om_pole_splits(const pole_guard *pole, double a, double b, double *split);

/* A near arm's window of G: the cells [a, b] scanned again on G in points points, candidates
 * into out[n:]; returns the new count. */
typedef int (*circle_window)(om_problem *pb, double a, double b, int points, double *q, double *out, int n, int cap);

/* What a scan's runs are searched with: its guard at psi's half-line, its near arm's window of G
 * (circle.c's, which scans the window as the circle: passed down to the runs, which do not call
 * up), and a root known already (w, a hinted solve's window's incumbent; NaN: none), which a
 * sign change of the scanned function on a cell that holds it alone is not refined to again. */
typedef struct {
    pole_guard pole;
    circle_window window;
    double known;
} circle_scan;

/* Add the roots on a run of reachable points (w ascending) to out[n:]; returns the count
 * (circle_runs.c). */
int om_run_roots(om_problem *pb, const circle_scan *scan, int depth, const double *pw, const double *pg, int L,
                 bool cyclic, double *curvatures, double *q, double *out, int n, int cap);

#endif
