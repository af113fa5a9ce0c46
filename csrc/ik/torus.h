/* What the torus search (torus.c), its damped Newton (torus_newton.c) and its search at psi's
 * half-line (torus_half_line.c) share. */
#ifndef OM_TORUS_H
#define OM_TORUS_H

#include "om_system.h"

/* Coordinates of the lifted system around a point w* of the torus where the model's w_hat is
 * -up (psi's singular half-line): y = (r, phi, phi4) for (w1, w7) = w* + M r (cos phi, sin phi),
 * M the inverse of the Jacobian of h (w_hat's part across up, in a basis across it) at w*.
 * There h is about r (cos phi, sin phi): its azimuth, which psi's reference turns with, is phi,
 * and the lifted residual, which turns by 2 pi about w* within any distance, is smooth in y. */
typedef struct {
    double w1, w7, m[2][2];
} half_line_chart;

/* x = (w1, w7, phi4) of chart coordinates y (chart NULL: y is x). */
static inline vec3 lifted_of(const half_line_chart *chart, vec3 y)
{
    if (!chart)
        return y;
    double u = y.x * cos(y.y), v = y.x * sin(y.y);
    return v3(chart->w1 + chart->m[0][0] * u + chart->m[0][1] * v, chart->w7 + chart->m[1][0] * u + chart->m[1][1] * v,
              y.z);
}

/* The joint whose angle is the torus' coordinate k (0: w1, 1: w7): q1 and q7 of a 7-DOF arm
 * with shoulder offsets; q5 and q6 of a 6-DOF arm with a PUMA-like wrist, whose lifted point
 * (w1, w7, phi4) is (q5, q6, gamma) throughout, gamma = phi3 + beta its elbow angle
 * (om_six_dof_model_ik_lifted). */
static inline int torus_joint(const om_solver_data *s, int k)
{
    if (s->family == OM_SRS)
        return k ? 6 : 0;
    return 4 + k;
}

/* The elbow's lifted angle (phi4; gamma) of the joints q. */
static inline double lifted_elbow(const om_solver_data *s, const double *q)
{
    if (s->family == OM_SRS)
        return q[3] + s->params[SRS_THETA + 3];
    return q[2] + s->params[SD_THETA3] + s->params[SD_BETA];
}

/* The lifted point (w1, w7, phi4) of the joints q: the torus' joints and the elbow's angle. */
static inline vec3 lifted_point(const om_solver_data *s, const double *q)
{
    return v3(q[torus_joint(s, 0)], q[torus_joint(s, 1)], lifted_elbow(s, q));
}

/* The elbow's lifted angle where the model's elbow is straight (its cosine x = 1; folded at
 * this plus pi): the edges of reach. */
static inline double straight_elbow(const om_solver_data *s)
{
    return s->family == OM_SRS ? s->params[SRS_PHI_STAR] : 0.0;
}

/* The distance of two points (w1, w7, phi4): the largest of their coordinates' differences, each
 * modulo 2 pi. */
static inline double lifted_distance(vec3 a, vec3 b)
{
    return py_max(py_max(fabs(om_wrap(a.x - b.x)), fabs(om_wrap(a.y - b.y))), fabs(om_wrap(a.z - b.z)));
}

/* Whether two points (w1, w7, phi4) are one: within OM_SAME_ROOT. */
static inline bool same_point(vec3 a, vec3 b)
{
    return lifted_distance(a, b) < OM_SAME_ROOT;
}

/* om_add_candidate of a copy of q, logged (log not NULL): the search's q stays as Newton left
 * it, whatever the verification's refinement, which depends on the configuration's signs,
 * makes of the copy. So the candidates, in order, are those of every configuration that
 * differs in the SHOULDER and WRIST signs alone (the lifted model IKs do not read them; a
 * 6-DOF arm's reads its ARM sign). */
static inline int torus_candidate(om_problem *pb, const double *q, double *roots, int count, om_candidate_log *log)
{
    double candidate[OM_MAX_DOF];
    memcpy(candidate, q, sizeof candidate);
    if (log) {
        int dof = pb->s->dof;
        if (log->count < log->cap)
            memcpy(log->q + (size_t)dof * (size_t)log->count, q, (size_t)dof * sizeof(double));
        log->count++;
    }
    return om_add_candidate(pb, candidate, roots, count);
}

/* Where a torus search's damped Newton run gives up (om_torus_roots): where its iterate, undeflated,
 * comes within near[k] of the known root k (n_known x 3), where it would end, a root found
 * already (the search seeks a distinct root so near as a fold partner of it: near[k] is at most
 * KNOWN_REACH, a tenth of the distance to the partner that the partner search predicts, and 0
 * until it has), and, in a window, where it leaves the square of half-width reach about (w1,
 * w7), whose roots the window does not seek (reach INFINITY: never). */
#define KNOWN_REACH 1e-3 /* rad, each lifted coordinate */
typedef struct {
    double w1, w7, reach;
    const double *known, *near;
    int n_known;
} newton_limits;

/* Whether x (lifted) lies next to one of limits' known roots, where an undeflated run gives up. */
static inline bool near_known(const newton_limits *limits, vec3 x)
{
    for (int k = 0; k < limits->n_known; k++)
        if (lifted_distance(x, v_load(limits->known, 3 * k)) < limits->near[k])
            return true;
    return false;
}

/* Damped Newton on the lifted system from x (chart not NULL: in its coordinates), deflated by
 * the first n_known rows of known, within limits (NULL: none); returns the residual's
 * max norm at the end (inf where the run gave up), *x_end the end point (lifted), q the model
 * IK there (not written where the run gave up). */
double om_lifted_newton(om_problem *pb, const half_line_chart *chart, vec3 x, double *q, const double *known,
                        int n_known, const newton_limits *limits, vec3 *x_end);
#define LINE_POINTS 8 /* points of psi's half-line kept per search */
/* The points of the grid's square (lo1, lo7, step, m nodes a side) where the model's w_hat is -up,
 * psi's singular half-line (the same at every arm angle of a pose), into charts (LINE_POINTS);
 * returns the count. */
int om_half_line_points(om_problem *pb, double lo1, double lo7, double step, int m, half_line_chart *charts);
/* Roots next to the points of psi's half-line (charts, n of them), candidates as torus_candidate's;
 * returns the root count. */
int om_half_line_roots(om_problem *pb, const half_line_chart *charts, int n, double *q, double *roots, int count,
                       om_candidate_log *log);
/* A 6-DOF arm's roots at the shoulder's edge of reach, the wrist centre h from joint 1's axis (h
 * its lateral offset; none where h = 0): Newton about the axis (torus_half_line.c) from each
 * cell of the grid (lo1, lo7, step, m nodes a side) that the edge crosses or may touch between
 * its corners (where the two ARM branches' roots meet, the reach's margin at a minimum).
 * Returns the root count. */
int om_shoulder_edge_roots(om_problem *pb, double lo1, double lo7, double step, int m, double *q, double *roots,
                           int count, om_candidate_log *log);

/* The self-motion of pb's pose and ELBOW sign traced (torus_trace.c), from the terms at the whole
 * torus' grid (lo, step, m nodes a side); NULL where a component's trace could not finish (out
 * of memory, or MAX_STEPS). Its evaluations are not counted in pb's (om_trace_evaluations: each
 * search that takes its starts counts them). */
typedef struct om_trace om_trace;
om_trace *om_trace_new(om_problem *pb, const om_srs_lifted_terms *terms, double lo, double step, int m);
void om_trace_free(om_trace *trace);
int64_t om_trace_evaluations(const om_trace *trace);
/* The starts of a search at psi (at most cap): where the trace crosses psi, into starts, and
 * each fold within FOLD_NEAR of psi, flagged in fold (its pair of roots sought from it). */
int om_trace_starts(const om_trace *trace, double psi, vec3 *starts, bool *fold, int cap);

#endif
