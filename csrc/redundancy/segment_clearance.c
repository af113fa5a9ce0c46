/* The clearance along a straight joint-space segment, certified by a Lipschitz bound
 * (om_redundant/redundancy/objective/segment_clearance.py's segment_minimum, whose docstring has
 * the rule; tests/reference/segment_clearance.py is the same in numpy, its oracle): pieces of
 * the segment whose bound (D_0 + D_1 - L h) / 2 is below the floor are halved, a round at a
 * time (every midpoint of a round in one call of `distances`), until an end falls below the
 * floor or a piece is within the tolerance of its ends. */
#include <stdlib.h>

#include "redundancy.h"

typedef struct {
    double t0, t1, d0, d1;
} piece;

/* The least distance of a row of P pairs (numpy's minimum: a NaN is the answer; the pieces'
 * minima below are py_min's, Python's min of two floats, as the reference takes them). */
static double least_of(const double *d, ptrdiff_t P) {
    double r = INFINITY;
    for (ptrdiff_t k = 0; k < P; k++) r = om_least(r, d[k]);
    return r;
}

double om_segment_minimum(const om_segment *s, double lipschitz, double floor, double budget, double tolerance,
                          int *status) {
    int dof = s->dof;
    ptrdiff_t P = s->pairs, used = 2; /* rows 0 and 1: the ends */
    double *rows = s->rows, delta[OM_MAX_DOF];
    *status = OM_SEGMENT_OK;
    if (s->capacity < 2) return (*status = OM_SEGMENT_FULL, NAN); /* (before the ends are written) */
    for (int j = 0; j < dof; j++) {
        rows[j] = s->q_from[j], rows[dof + j] = s->q_to[j];
        delta[j] = s->q_to[j] - s->q_from[j];
    }
    if (s->distances(s->context, 0, 2) < 0) return (*status = OM_SEGMENT_FAILED, NAN);
    /* each round's pieces (at most twice the rows that can be sampled, two per split), then the next's */
    ptrdiff_t room = 2 * s->capacity;
    piece *pieces = malloc((size_t)(2 * room) * sizeof(piece));
    if (!pieces) return (*status = OM_SEGMENT_NO_MEMORY, NAN);
    piece *now = pieces, *next = pieces + room;
    ptrdiff_t n = 1;
    now[0] = (piece){0.0, 1.0, least_of(s->dist, P), least_of(s->dist + P, P)};
    double least = INFINITY, answer;
    for (;;) {
        double lowest = py_min(now[0].d0, now[0].d1);
        for (ptrdiff_t i = 1; i < n; i++) lowest = py_min(lowest, py_min(now[i].d0, now[i].d1));
        if (lowest < floor) {
            answer = lowest;
            break;
        }
        ptrdiff_t split = 0;
        for (ptrdiff_t i = 0; i < n; i++) {
            piece p = now[i];
            double bound = 0.5 * (p.d0 + p.d1 - lipschitz * (p.t1 - p.t0));
            if (bound >= floor || lipschitz * (p.t1 - p.t0) <= tolerance)
                least = py_min(least, bound);
            else
                now[split++] = p; /* (in order, over the pieces already read) */
        }
        if (split == 0) {
            answer = least;
            break;
        }
        if ((double)split > budget || used + split > s->capacity) {
            answer = NAN; /* (undecided within the budget; or the caller's rows are too few) */
            *status = (double)split > budget ? OM_SEGMENT_OK : OM_SEGMENT_FULL;
            break;
        }
        budget -= (double)split;
        for (ptrdiff_t i = 0; i < split; i++) {
            double t = 0.5 * (now[i].t0 + now[i].t1), *row = rows + (used + i) * dof;
            for (int j = 0; j < dof; j++) row[j] = s->q_from[j] + t * delta[j];
        }
        if (s->distances(s->context, used, used + split) < 0) {
            answer = NAN, *status = OM_SEGMENT_FAILED;
            break;
        }
        for (ptrdiff_t i = 0; i < split; i++) {
            piece p = now[i];
            double tm = 0.5 * (p.t0 + p.t1), dm = least_of(s->dist + (used + i) * P, P);
            next[2 * i] = (piece){p.t0, tm, p.d0, dm};
            next[2 * i + 1] = (piece){tm, p.t1, dm, p.d1};
        }
        used += split, n = 2 * split;
        piece *swap = now;
        now = next, next = swap;
    }
    free(pieces);
    return answer;
}
