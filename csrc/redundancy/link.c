/* The solution paths of one branch through its roots at the grid psi, in one call: paths.py's
 * _link (its loop, _joined, _back_to_end and _same) for a 7-DOF arm's compiled solver, the same
 * follows (om_follow_path, follow.c) in the same order and the same decisions.
 *
 * Rows: the grid roots are rows 0 .. M-1, counts[k] of them at grid psi_k in order (their psi
 * psi_k, their joints and tangents given); the points that following adds are rows M, M + 1,
 * ... Every row lies on one path: a root on the path that takes it or starts there, a point
 * that following added on the path that was followed.
 *
 * Grid psi by grid psi, each path that reached the previous one (in the order they reached it)
 * moves on: where psi_k has a single root that continues the path (om_continues) to it;
 * else it is followed to psi_k: where it ends on the way, the point reached is its last; where
 * it arrives, at the root that is the same solution (the nearest within OM_PATH_SAME, max-norm of the
 * joint step), else at a new root (one the bounded search did not list), which it takes unless
 * another path took it first (then two paths met: this one stops at psi_{k-1}). The roots no
 * path took start paths. Then the paths that reached the last grid psi are followed across
 * +-pi to psi_0 + 2 pi and joined to the path starting at psi_0 with the same solution (one
 * not yet joined to); the chains of joined paths are output from their heads, then the closed
 * ones as loops; in front of a chain that is not a loop, where its first path ends, followed
 * back from its first sample towards the grid psi before. (Its binding: csrc/binding/paths.c.) */
#include <stdlib.h>
#include <string.h>

#include "om_paths.h"

#define TURN (2.0 * OM_PI)   /* (om_redundant/angles.py's TURN) */

/* The branch, the rows and the paths being linked. */
typedef struct {
    om_branch branch;
    int64_t n_roots, n_rows, capacity; /* capacity: of the rows following adds */
    const double *root_psi, *root_q, *root_t;
    double *new_psi, *new_q, *new_t;
    double x_psi, x_q[OM_MAX_DOF], x_t[OM_MAX_DOF]; /* the point the last follow reached */
    int64_t *next;                                  /* per row, the next on its path (-1: none) */
    int64_t n_paths, *head, *tail, *first;          /* per path, its first and last rows, first's grid index */
} linker;

enum { REACHED = -1 }; /* the row index of the point the last follow reached (x_psi, x_q, x_t) */

static double row_psi(const linker *l, int64_t r) {
    return r == REACHED ? l->x_psi : r < l->n_roots ? l->root_psi[r] : l->new_psi[r - l->n_roots];
}
static const double *row_q(const linker *l, int64_t r) {
    return r == REACHED ? l->x_q : r < l->n_roots ? l->root_q + 7 * r : l->new_q + 7 * (r - l->n_roots);
}
static const double *row_t(const linker *l, int64_t r) {
    return r == REACHED ? l->x_t : r < l->n_roots ? l->root_t + 7 * r : l->new_t + 7 * (r - l->n_roots);
}

/* Follow from row r towards target into x_*: the status, *reached the row reached (r itself
 * where no step was taken, else REACHED). */
static int follow_from(linker *l, int64_t r, double target, int64_t *reached) {
    int steps;
    l->x_psi = row_psi(l, r);
    memcpy(l->x_q, row_q(l, r), sizeof(double) * 7);
    memcpy(l->x_t, row_t(l, r), sizeof(double) * 7);
    int status = om_follow_path(&l->branch, &l->x_psi, l->x_q, l->x_t, target, OM_END_TOLERANCE, &steps);
    *reached = steps == 0 ? r : REACHED;
    return status;
}

/* The point the last follow reached as a new row (-1 where the rows are full). */
static int64_t add_reached(linker *l) {
    int64_t i = l->n_rows - l->n_roots;
    if (i >= l->capacity) return -1;
    l->new_psi[i] = l->x_psi;
    memcpy(l->new_q + 7 * i, l->x_q, sizeof(double) * 7);
    memcpy(l->new_t + 7 * i, l->x_t, sizeof(double) * 7);
    l->next[l->n_rows] = -1;
    return l->n_rows++;
}

static void append(linker *l, int64_t path, int64_t r) {
    l->next[l->tail[path]] = r, l->next[r] = -1, l->tail[path] = r;
}

static int64_t start_path(linker *l, int64_t k, int64_t r) {
    l->head[l->n_paths] = l->tail[l->n_paths] = r, l->first[l->n_paths] = k, l->next[r] = -1;
    return l->n_paths++;
}

/* The index of the candidate row that is the same solution as row r (itself, else the first
 * nearest within OM_PATH_SAME: paths.py's _same), -1 if none. */
static int64_t same(const linker *l, int64_t r, const int64_t *candidates, int64_t n) {
    for (int64_t j = 0; j < n; j++)
        if (candidates[j] == r) return j;
    int64_t best = -1;
    double nearest = 0.0;
    for (int64_t j = 0; j < n; j++) {
        double step = om_largest_joint_step(7, row_q(l, r), row_q(l, candidates[j]), l->branch.cyclic);
        if (best < 0 || step < nearest) best = j, nearest = step;
    }
    return best >= 0 && nearest <= OM_PATH_SAME ? best : -1;
}

/* What work (8 N entries, N = the rows' capacity) holds while linking. */
typedef struct {
    int64_t *ongoing, *reaching, *candidates, *taken, *following, *joined, *seen, *chain;
} scratch;

/* The paths through the grid roots (the top of this file) into l, the joined ones and their
 * order into members/paths as link_paths outputs them. */
static int link_roots(linker *l, int64_t n, const double *grid, const int64_t *counts, scratch *w,
                      int64_t *members, int64_t *paths) {
    int64_t n_ongoing = 0, start = 0, reached;
    for (int64_t k = 0; k < n; k++) {
        int64_t n_candidates = 0, n_reaching = 0;
        for (int64_t r = start; r < start + counts[k]; r++)
            w->candidates[n_candidates] = r, w->taken[n_candidates++] = 0;
        start += counts[k];
        for (int64_t o = 0; o < n_ongoing; o++) {
            int64_t i = w->ongoing[o], last = l->tail[i], only = n_candidates == 1 ? w->candidates[0] : -1;
            bool arrived = only >= 0 && om_continues(7, row_q(l, last), row_q(l, only), row_t(l, last),
                                                     row_psi(l, only) - row_psi(l, last), l->branch.cyclic);
            if (arrived) /* the only solution, and it continues the path */
                reached = only;
            else {
                int status = follow_from(l, last, grid[k], &reached);
                arrived = status == OM_FOLLOW_ARRIVED;
            }
            if (!arrived) {
                if (reached == REACHED) {
                    int64_t r = add_reached(l);
                    if (r < 0) return OM_LINK_FULL;
                    append(l, i, r);
                }
                continue;
            }
            int64_t j = same(l, reached, w->candidates, n_candidates);
            if (j < 0) { /* a solution the bounded search did not list (a follow's: grid[k] is not last's psi) */
                int64_t r = add_reached(l);
                if (r < 0) return OM_LINK_FULL;
                w->candidates[n_candidates] = r, w->taken[n_candidates] = 0, j = n_candidates++;
            }
            if (!w->taken[j]) { /* (else two paths met: this one stops here) */
                w->taken[j] = 1;
                append(l, i, w->candidates[j]);
                w->reaching[n_reaching++] = i;
            }
        }
        for (int64_t j = 0; j < n_candidates; j++)
            if (!w->taken[j]) w->reaching[n_reaching++] = start_path(l, k, w->candidates[j]);
        int64_t *swap = w->ongoing;
        w->ongoing = w->reaching, w->reaching = swap, n_ongoing = n_reaching;
    }
    /* _joined: following[i], the path that path i continues into across +-pi (-1: none) */
    for (int64_t i = 0; i < l->n_paths; i++) w->following[i] = -1, w->joined[i] = 0, w->seen[i] = 0;
    int64_t *keys = w->reaching, n_keys = 0, *starts = w->candidates, *heads = w->taken;
    for (int64_t o = 0; o < n_ongoing; o++) {
        int64_t i = w->ongoing[o];
        int status = follow_from(l, l->tail[i], grid[0] + TURN, &reached);
        if (status == OM_FOLLOW_ARRIVED) {
            int64_t n_starts = 0;
            for (int64_t j = 0; j < l->n_paths; j++)
                if (l->first[j] == 0 && !w->joined[j]) starts[n_starts] = j, heads[n_starts++] = l->head[j];
            int64_t j = same(l, reached, heads, n_starts);
            if (j >= 0) w->following[i] = starts[j], w->joined[starts[j]] = 1, keys[n_keys++] = i;
        } else if (reached == REACHED) {
            int64_t r = add_reached(l);
            if (r < 0) return OM_LINK_FULL;
            append(l, i, r);
        }
    }
    /* the chains from their heads (the paths not joined to), then the loops */
    int64_t n_out = 0, n_members = 0;
    for (int64_t h = 0; h < l->n_paths + n_keys; h++) {
        int64_t head = h < l->n_paths ? h : keys[h - l->n_paths];
        if ((h < l->n_paths && w->joined[head]) || w->seen[head]) continue;
        int64_t n_chain = 1, *chain = w->chain;
        chain[0] = head;
        for (;;) {
            int64_t to = w->following[chain[n_chain - 1]];
            bool in_chain = to < 0;
            for (int64_t c = 0; c < n_chain && !in_chain; c++) in_chain = chain[c] == to;
            if (in_chain) break;
            chain[n_chain++] = to;
        }
        for (int64_t c = 0; c < n_chain; c++) w->seen[chain[c]] = 1;
        bool loop = w->following[chain[n_chain - 1]] == chain[0];
        if (!loop) { /* _back_to_end: where it ends before its first grid sample */
            int64_t k = l->first[chain[0]], first_row = l->head[chain[0]];
            follow_from(l, first_row, k > 0 ? grid[k - 1] : grid[n - 1] - TURN, &reached);
            if (reached == REACHED) {
                int64_t r = add_reached(l);
                if (r < 0) return OM_LINK_FULL;
                l->next[r] = first_row, l->head[chain[0]] = r;
            }
        }
        for (int64_t c = 0; c < n_chain; c++)
            for (int64_t r = l->head[chain[c]]; r >= 0; r = l->next[r], n_members++)
                members[2 * n_members] = r, members[2 * n_members + 1] = c;
        paths[2 * n_out] = n_members, paths[2 * n_out + 1] = loop ? n_chain : 0, n_out++;
    }
    l->n_paths = n_out;
    return OM_LINK_DONE;
}

/* (om_paths.h) The scratch and the roots' psi allocated here, the linker set up over job. */
int om_link_paths(const om_link_job *job, int64_t *added, int64_t *n_paths) {
    int64_t m = job->m, rows = m + job->capacity;
    int64_t *work = malloc(sizeof(int64_t) * (size_t)(12 * rows + 1));
    double *root_psi = malloc(sizeof(double) * (size_t)(m + 1));
    *added = 0, *n_paths = 0;
    if (!work || !root_psi) {
        free(work), free(root_psi);
        return OM_LINK_NO_MEMORY;
    }
    for (int64_t k = 0, r = 0; k < job->n; k++)
        for (int64_t c = 0; c < job->counts[k]; c++) root_psi[r++] = job->grid[k];
    linker l = {.branch = job->branch, .n_roots = m, .n_rows = m, .capacity = job->capacity, .root_psi = root_psi,
                .root_q = job->q, .root_t = job->t, .new_psi = job->new_psi, .new_q = job->new_q,
                .new_t = job->new_t, .next = work, .n_paths = 0, .head = work + rows, .tail = work + 2 * rows,
                .first = work + 3 * rows};
    scratch w = {work + 4 * rows, work + 5 * rows, work + 6 * rows, work + 7 * rows,
                 work + 8 * rows, work + 9 * rows, work + 10 * rows, work + 11 * rows};
    int status = link_roots(&l, job->n, job->grid, job->counts, &w, job->members, job->paths);
    *added = l.n_rows - m, *n_paths = status == OM_LINK_DONE ? l.n_paths : 0;
    free(work), free(root_psi);
    return status;
}
