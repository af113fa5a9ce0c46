/* Distances between an arm's geoms and obstacle geoms, and their gradients, for many joint
 * vectors in one call (om_redundant/redundancy/objective/clearance.py).
 *
 * Placement: the arm's links are the frames of its DH chain (csrc/ik/kinematics.c's rows) started
 * from the world pose of DH frame 0; link l (l = 0..dof) is the frame just before joint l+1's
 * row (the chain's end for l = dof), which joints 1..l move, and joint l+1 turns about its z
 * axis through its origin. A geom on link l sits at the fixed offset G in it, X = F_l(q) G,
 * both taken once from the model (clearance.py). Obstacles do not move.
 *
 * Each geom is a core and a radius: a sphere is its centre and radius, a capsule the segment
 * of its axis and radius, a box itself and 0. The distance of two geoms that do not touch is
 * the distance of their cores less both radii; the cores' nearest points c1, c2 give the
 * direction n = (c2 - c1)/|c2 - c1| and the geoms' nearest points c1 + r1 n, c2 - r2 n.
 * Segment to segment: the minimiser of the convex quadratic |c1(s) - c2(t)|^2 over the unit
 * square (Ericson, Real-Time Collision Detection, 5.1.9). Segment to box, in the box's frame:
 * |p(t) - clamp(p(t))|^2 is a quadratic between the parameters where p(t) crosses a face's
 * plane, minimised on each piece in closed form. Pairs of other kinds, pairs whose cores
 * touch and boxes touched are left to MuJoCo (marked nan).
 *
 * Gradient of pair k, its arm point p moving with link l: the distance changes by -n . dp,
 * with dp/dq_j = a_j x (p - o_j) for a revolute joint j <= l (axis a_j through o_j) and a_j
 * for a prismatic one. */
#include <string.h>

#include "redundancy.h"

enum { CORE_MUJOCO = OM_CORE_MUJOCO, CORE_POINT = OM_CORE_POINT, CORE_SEGMENT = OM_CORE_SEGMENT, CORE_BOX = OM_CORE_BOX };
#define CORES_TOUCH 1e-9 /* m: cores nearer than this touch (their pair is MuJoCo's) */

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static double clamp01(double x) { return x < 0.0 ? 0.0 : x > 1.0 ? 1.0 : x; }

/* The nearest points c1 of segment p1-q1 and c2 of p2-q2 (either may be a point). */
static void segments(const double *p1, const double *q1, const double *p2, const double *q2, double *c1,
                     double *c2) {
    double d1[3], d2[3], r[3], s = 0.0, t = 0.0;
    for (int i = 0; i < 3; i++) d1[i] = q1[i] - p1[i], d2[i] = q2[i] - p2[i], r[i] = p1[i] - p2[i];
    double a = dot3(d1, d1), e = dot3(d2, d2), f = dot3(d2, r);
    if (a == 0.0 && e > 0.0)
        t = clamp01(f / e);
    else if (a > 0.0) {
        double c = dot3(d1, r);
        if (e == 0.0)
            s = clamp01(-c / a);
        else {
            double b = dot3(d1, d2), denom = a * e - b * b;
            if (denom > 1e-14 * a * e) {
                s = clamp01((b * f - c * e) / denom);
                t = (b * s + f) / e;
                if (t < 0.0)
                    t = 0.0, s = clamp01(-c / a);
                else if (t > 1.0)
                    t = 1.0, s = clamp01((b - c) / a);
            } else { /* (nearly) parallel: the nearest pair has an end of either segment */
                double ends[4][2] = {{0.0, clamp01(f / e)}, {1.0, clamp01((b + f) / e)},
                                     {clamp01(-c / a), 0.0}, {clamp01((b - c) / a), 1.0}};
                double least = INFINITY;
                for (int k = 0; k < 4; k++) {
                    double gap = 0.0;
                    for (int i = 0; i < 3; i++) {
                        double v = r[i] + ends[k][0] * d1[i] - ends[k][1] * d2[i];
                        gap += v * v;
                    }
                    if (gap < least) least = gap, s = ends[k][0], t = ends[k][1];
                }
            }
        }
    }
    for (int i = 0; i < 3; i++) c1[i] = p1[i] + s * d1[i], c2[i] = p2[i] + t * d2[i];
}

/* The nearest points c1 of segment p-q and c2 of the box of half sizes h, all in the box's frame. */
static void segment_box(const double *p, const double *q, const double *h, double *c1, double *c2) {
    double u[3], ts[8] = {0.0, 1.0}, best = INFINITY;
    int n = 2;
    for (int i = 0; i < 3; i++) {
        u[i] = q[i] - p[i];
        for (int side = -1; side <= 1 && u[i] != 0.0; side += 2) {
            double t = (side * h[i] - p[i]) / u[i];
            if (t > 0.0 && t < 1.0) ts[n++] = t;
        }
    }
    for (int i = 1; i < n; i++) /* insertion sort */
        for (int j = i; j > 0 && ts[j] < ts[j - 1]; j--) {
            double x = ts[j];
            ts[j] = ts[j - 1], ts[j - 1] = x;
        }
    for (int k = 0; k + 1 < n; k++) {
        double lo = ts[k], hi = ts[k + 1], mid = 0.5 * (lo + hi), num = 0.0, den = 0.0;
        for (int i = 0; i < 3; i++) { /* the faces p(t) lies beyond on this piece */
            double x = p[i] + mid * u[i];
            if (x > h[i] || x < -h[i]) num += (x > h[i] ? p[i] - h[i] : p[i] + h[i]) * u[i], den += u[i] * u[i];
        }
        double t = den > 0.0 ? fmin(fmax(-num / den, lo), hi) : lo, point[3], near[3], d2 = 0.0;
        for (int i = 0; i < 3; i++) {
            point[i] = p[i] + t * u[i];
            near[i] = fmin(fmax(point[i], -h[i]), h[i]);
            d2 += (point[i] - near[i]) * (point[i] - near[i]);
        }
        if (!(d2 >= best)) { /* nan too: left to MuJoCo */
            best = d2;
            memcpy(c1, point, sizeof point);
            memcpy(c2, near, sizeof near);
        }
    }
}

/* The core of geom g: its segment (a point: both ends equal) in world coordinates. */
static void core(const double *xpos, const double *xmat, const double *half, int g, double *a, double *b) {
    const double *pos = xpos + 3 * g, *mat = xmat + 9 * g, l = half[3 * g + 2];
    for (int i = 0; i < 3; i++) a[i] = pos[i] - l * mat[3 * i + 2], b[i] = pos[i] + l * mat[3 * i + 2];
}

/* Point x in the frame of a box at pos (rotation R, row-major): R^T (x - pos). */
static void to_box(const double *pos, const double *R, const double *x, double *out) {
    double d[3] = {x[0] - pos[0], x[1] - pos[1], x[2] - pos[2]};
    for (int i = 0; i < 3; i++) out[i] = R[i] * d[0] + R[3 + i] * d[1] + R[6 + i] * d[2];
}

/* Point k of a box's frame in the world: pos + R k. */
static void from_box(const double *pos, const double *R, const double *k, double *out) {
    for (int i = 0; i < 3; i++) out[i] = pos[i] + dot3(R + 3 * i, k);
}

/* The signed distance of geoms g1 (point or segment core) and g2 (any core but MuJoCo's),
 * their nearest points into fromto: negative where a sphere or capsule overlaps one whose
 * core it does not touch (the depth MuJoCo gives); nan where the cores touch, or a box is
 * touched (MuJoCo's depth in a box is not the cores' distance). */
static double pair_distance(const int64_t *kind, const double *radius, const double *half, const double *xpos,
                            const double *xmat, int g1, int g2, double *fromto) {
    double a1[3], b1[3], c1[3], c2[3];
    core(xpos, xmat, half, g1, a1, b1);
    if (kind[g2] == CORE_BOX) {
        const double *pos = xpos + 3 * g2, *R = xmat + 9 * g2;
        double a[3], b[3], k1[3] = {0.0}, k2[3] = {0.0};
        to_box(pos, R, a1, a), to_box(pos, R, b1, b);
        segment_box(a, b, half + 3 * g2, k1, k2);
        from_box(pos, R, k1, c1), from_box(pos, R, k2, c2);
    } else {
        double a2[3], b2[3];
        core(xpos, xmat, half, g2, a2, b2);
        segments(a1, b1, a2, b2, c1, c2);
    }
    double v[3] = {c2[0] - c1[0], c2[1] - c1[1], c2[2] - c1[2]}, length = sqrt(dot3(v, v));
    double dist = length - radius[g1] - radius[g2];
    /* cores within rounding of touching (a nearly parallel pair's nearest points are found to
     * 1e-12 or so) are touching: MuJoCo's depth */
    if (!(length > CORES_TOUCH) || (kind[g2] == CORE_BOX && !(dist > 0.0))) return NAN;
    for (int i = 0; i < 3; i++) {
        double n = v[i] / length;
        fromto[i] = c1[i] + radius[g1] * n;
        fromto[3 + i] = c2[i] - radius[g2] * n;
    }
    return dist;
}

/* The signed distance (<= 0) of a sphere or capsule (core p-q, radius r) that overlaps the box
 * at pos (rotation R, half sizes h), exactly, with its nearest points (arm, box) into fromto:
 * for the pairs whose overlap MuJoCo's distance contradicts (clearance.py). Where the core
 * stays outside the box, at distance l from it, the distance is l - r (the capsule is the core
 * swollen by r). Where it touches the box, it is -(depth + r), the depth that of the core in
 * the box: the least, over the separating axes n of a segment and a box (the box's axes e_i and
 * u x e_i for the segment's direction u: the normals of their Minkowski difference's faces), of
 * how far the core must move along +-n to leave the box; the arm point is the core's point
 * deepest along that escape direction (across an edge, its point nearest the edge), less r,
 * the box point where it leaves the box: the points whose motion moves the depth. */
static double overlap_with_box(const double *p, const double *q, double r, const double *pos, const double *R,
                               const double *h, double *fromto) {
    double a[3], b[3], k1[3] = {0.0}, k2[3] = {0.0}, v[3], arm[3], box[3], distance;
    to_box(pos, R, p, a), to_box(pos, R, q, b);
    segment_box(a, b, h, k1, k2);
    for (int i = 0; i < 3; i++) v[i] = k2[i] - k1[i];
    double length = sqrt(dot3(v, v));
    if (length > 0.0) {
        for (int i = 0; i < 3; i++) arm[i] = k1[i] + r * v[i] / length, box[i] = k2[i];
        distance = length - r;
    } else {
        double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, depth = INFINITY, escape[3] = {0.0}, deepest[3];
        const double *end = a;
        int axis = 0;
        for (int m = 0; m < 6; m++) {
            double n[3] = {0.0, 0.0, 0.0};
            if (m < 3)
                n[m] = 1.0;
            else { /* u x e_{m-3}, where u is not along e_{m-3} */
                int j = m - 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
                n[j1] = u[j2], n[j2] = -u[j1];
                double size = sqrt(dot3(n, n));
                if (!(size > 1e-12 * sqrt(dot3(u, u)))) continue;
                for (int i = 0; i < 3; i++) n[i] /= size;
            }
            double sa = dot3(a, n), sb = dot3(b, n), extent = fabs(n[0]) * h[0] + fabs(n[1]) * h[1] + fabs(n[2]) * h[2];
            for (int side = -1; side <= 1; side += 2) { /* escaping along side n: the overlap to clear */
                double overlap = side < 0 ? fmax(sa, sb) + extent : extent - fmin(sa, sb);
                if (overlap < depth) {
                    depth = overlap, axis = m;
                    for (int i = 0; i < 3; i++) escape[i] = side * n[i];
                    end = side * (sa - sb) < 0.0 ? a : b;
                }
            }
        }
        memcpy(deepest, end, sizeof deepest);
        if (axis >= 3) {
            /* across an edge of the box along e_j: the whole core projects to one point on u x e_j,
             * and the deepest point is the core's nearest that edge (the one the box's support
             * along the escape direction runs along), where a turn of the core moves the depth */
            int j = axis - 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            double c[3], w[3];
            c[j] = 0.0, c[j1] = copysign(h[j1], escape[j1]), c[j2] = copysign(h[j2], escape[j2]);
            for (int i = 0; i < 3; i++) w[i] = a[i] - c[i];
            double t = (u[j] * w[j] - dot3(u, w)) / (dot3(u, u) - u[j] * u[j]);
            t = fmin(1.0, fmax(0.0, t));
            for (int i = 0; i < 3; i++) deepest[i] = a[i] + t * u[i];
        }
        for (int i = 0; i < 3; i++) box[i] = deepest[i] + depth * escape[i], arm[i] = deepest[i] - r * escape[i];
        distance = -(depth + r);
    }
    from_box(pos, R, arm, fromto), from_box(pos, R, box, fromto + 3);
    return distance;
}

/* The world poses of links 0..dof at q (rows of R (9) and p (3) in frames, (dof + 1) x 12):
 * the chain's rows applied from start, the pose of DH frame 0. */
static void link_frames(const double *table, int n_rows, const double *start, const double *q, double *frames) {
    double R[9], p[3];
    memcpy(R, start, sizeof R);
    memcpy(p, start + 9, sizeof p);
    int dof = om_chain(table, n_rows, q, n_rows, R, p, frames, NULL);
    memcpy(frames + 12 * dof, R, sizeof R);
    memcpy(frames + 12 * dof + 9, p, sizeof p);
}

/* The world pose of each arm geom a (xpos 3, xmat 9 per geom), on link link[a] at offset[a]
 * (R 9, p 3): X = F G. */
static void place(const double *frames, const int64_t *link, const double *offset, ptrdiff_t A, double *xpos,
                  double *xmat) {
    for (ptrdiff_t a = 0; a < A; a++) {
        const double *F = frames + 12 * link[a], *G = offset + 12 * a;
        for (int i = 0; i < 3; i++) {
            xpos[3 * a + i] = F[9 + i] + F[3 * i] * G[9] + F[3 * i + 1] * G[10] + F[3 * i + 2] * G[11];
            for (int j = 0; j < 3; j++)
                xmat[9 * a + 3 * i + j] = F[3 * i] * G[j] + F[3 * i + 1] * G[3 + j] + F[3 * i + 2] * G[6 + j];
        }
    }
}

/* Each pair's distance capped at reach (reach without computing it where the bounding
 * spheres are that far apart) and nearest points; nan for the pairs MuJoCo must compute,
 * counted in the return value. */
static long distances(const int64_t *kind, const double *radius, const double *half, const double *xpos,
                      const double *xmat, const int64_t *pairs, const double *bounds, ptrdiff_t P, double reach,
                      double *dist, double *fromto) {
    long left = 0;
    for (ptrdiff_t k = 0; k < P; k++) {
        int g1 = (int)pairs[2 * k], g2 = (int)pairs[2 * k + 1];
        double *ft = fromto + 6 * k, w[3];
        for (int i = 0; i < 3; i++) w[i] = xpos[3 * g1 + i] - xpos[3 * g2 + i];
        memset(ft, 0, 6 * sizeof(double));
        if (sqrt(dot3(w, w)) - bounds[k] >= reach)
            dist[k] = reach;
        else if ((kind[g1] == CORE_POINT || kind[g1] == CORE_SEGMENT) && kind[g2] != CORE_MUJOCO) {
            double d = pair_distance(kind, radius, half, xpos, xmat, g1, g2, ft);
            dist[k] = d < reach ? d : isnan(d) ? d : reach;
        } else if (kind[g1] == CORE_BOX && (kind[g2] == CORE_POINT || kind[g2] == CORE_SEGMENT)) {
            /* an arm box (a gripper's pad) and a sphere or capsule: the obstacle's core against
             * the box, its nearest points turned round (the arm's first) */
            double d = pair_distance(kind, radius, half, xpos, xmat, g2, g1, ft);
            for (int i = 0; i < 3; i++) {
                double t = ft[i];
                ft[i] = ft[3 + i], ft[3 + i] = t;
            }
            dist[k] = d < reach ? d : isnan(d) ? d : reach;
        } else
            dist[k] = NAN;
        left += isnan(dist[k]);
    }
    return left;
}

/* The gradient over the dof joints of each pair's distance (zero where capped at reach, 0 or
 * left to MuJoCo, and, where some pair of the row is nearer than `near`, for the pairs at
 * `near` or farther: what the objective does not read); the first link[a] joints move arm
 * geom a, the first of the pair. */
static void gradients(const double *dist, const double *fromto, const int64_t *pairs, const int64_t *link,
                      const double *frames, const uint8_t *slide, ptrdiff_t P, int dof, double reach, double near,
                      double *grad) {
    double least = INFINITY;
    for (ptrdiff_t k = 0; k < P; k++) least = fmin(least, dist[k]);
    if (!(least < near)) near = INFINITY;
    for (ptrdiff_t k = 0; k < P; k++) {
        double *row = grad + k * dof;
        const double *p = fromto + 6 * k;
        memset(row, 0, dof * sizeof(double));
        if (!(dist[k] < reach && dist[k] != 0.0 && dist[k] < near)) continue;
        double nk[3] = {(p[3] - p[0]) / dist[k], (p[4] - p[1]) / dist[k], (p[5] - p[2]) / dist[k]};
        for (int j = 0; j < link[pairs[2 * k]]; j++) {
            const double *F = frames + 12 * j;
            double a[3] = {F[2], F[5], F[8]}, r[3] = {p[0] - F[9], p[1] - F[10], p[2] - F[11]};
            double dp[3] = {a[1] * r[2] - a[2] * r[1], a[2] * r[0] - a[0] * r[2], a[0] * r[1] - a[1] * r[0]};
            row[j] = -dot3(nk, slide[j] ? a : dp);
        }
    }
}

void om_arm_geom_poses(const om_arm_links *arm, const double *q, double *xpos, double *xmat) {
    double frames[12 * (OM_MAX_DOF + 1)];
    link_frames(arm->table, arm->n_rows, arm->start, q, frames);
    place(frames, arm->link, arm->offset, arm->A, xpos, xmat);
}

long om_arm_clearance(const om_arm_links *arm, const om_geom_cores *geoms, ptrdiff_t M, const double *q,
                      double reach, double near, double *dist, double *fromto, double *grad, bool given,
                      double *work) {
    ptrdiff_t A = arm->A, G = geoms->G, P = geoms->P;
    int dof = arm->dof;
    double *xpos = work, *xmat = work + 3 * G;
    memcpy(xpos + 3 * A, geoms->obstacle_pos, (size_t)(G - A) * 3 * sizeof(double));
    memcpy(xmat + 9 * A, geoms->obstacle_mat, (size_t)(G - A) * 9 * sizeof(double));
    long left = 0;
    for (ptrdiff_t m = 0; m < M; m++) {
        double frames[12 * (OM_MAX_DOF + 1)], *d = dist + m * P, *ft = fromto + 6 * m * P;
        link_frames(arm->table, arm->n_rows, arm->start, q + m * dof, frames);
        if (!given) {
            place(frames, arm->link, arm->offset, A, xpos, xmat);
            left += distances(geoms->kind, geoms->radius, geoms->half, xpos, xmat, geoms->pairs, geoms->bounds, P,
                              reach, d, ft);
        }
        if (grad) gradients(d, ft, geoms->pairs, arm->link, frames, arm->slide, P, dof, reach, near, grad + m * P * dof);
    }
    return left;
}

double om_box_overlap(const double *pos, const double *mat, const double *half, double radius,
                      const double *box_pos, const double *box_mat, const double *box_half, double *fromto) {
    double p[3], q[3];
    core(pos, mat, half, 0, p, q);
    return overlap_with_box(p, q, radius, box_pos, box_mat, box_half, fromto);
}
