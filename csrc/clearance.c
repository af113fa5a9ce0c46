/* Distances between an arm's geoms and obstacle geoms, and their gradients, in one call each
 * (om_redundant/redundancy/clearance.py).
 *
 * Each geom is a core and a radius: a sphere is its centre and radius, a capsule the segment
 * of its axis and radius, a box itself and 0. The distance of two geoms that do not touch is
 * the distance of their cores less both radii; the cores' nearest points c1, c2 give the
 * direction n = (c2 - c1)/|c2 - c1| and the geoms' nearest points c1 + r1 n, c2 - r2 n.
 * Segment to segment: the minimiser of the convex quadratic |c1(s) - c2(t)|^2 over the unit
 * square (Ericson, Real-Time Collision Detection, 5.1.9). Segment to box, in the box's frame:
 * |p(t) - clamp(p(t))|^2 is a quadratic between the parameters where p(t) crosses a face's
 * plane, minimised on each piece in closed form. Pairs of other kinds, and pairs whose
 * geoms touch or overlap, are left to MuJoCo (marked nan).
 *
 * Gradient of pair k, its arm point p moving with the body of the arm geom: the distance
 * changes by -n . dp, with dp/dq_j = a_j x (p - o_j) for a hinge joint j (axis a_j through
 * o_j, MuJoCo's xaxis and xanchor) and a_j for a slide joint, for the joints that move it. */
#include <string.h>

#include "binding.h"

enum { CORE_MUJOCO = 0, CORE_POINT = 1, CORE_SEGMENT = 2, CORE_BOX = 3 };

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
            s = denom > 1e-14 * a * e ? clamp01((b * f - c * e) / denom) : 0.0; /* parallel: any s */
            t = (b * s + f) / e;
            if (t < 0.0)
                t = 0.0, s = clamp01(-c / a);
            else if (t > 1.0)
                t = 1.0, s = clamp01((b - c) / a);
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

/* The signed distance of geoms g1 (point or segment core) and g2 (any core but MuJoCo's),
 * their nearest points into fromto; nan where they touch. */
static double pair_distance(const int64_t *kind, const double *radius, const double *half, const double *xpos,
                            const double *xmat, int g1, int g2, double *fromto) {
    double a1[3], b1[3], c1[3], c2[3];
    core(xpos, xmat, half, g1, a1, b1);
    if (kind[g2] == CORE_BOX) {
        const double *pos = xpos + 3 * g2, *R = xmat + 9 * g2;
        double a[3], b[3], d[3], e[3], k1[3] = {0.0}, k2[3] = {0.0};
        for (int i = 0; i < 3; i++) d[i] = a1[i] - pos[i], e[i] = b1[i] - pos[i];
        for (int i = 0; i < 3; i++) /* R^T (x - pos) */
            a[i] = R[i] * d[0] + R[3 + i] * d[1] + R[6 + i] * d[2], b[i] = R[i] * e[0] + R[3 + i] * e[1] + R[6 + i] * e[2];
        segment_box(a, b, half + 3 * g2, k1, k2);
        for (int i = 0; i < 3; i++) /* back to the world */
            c1[i] = pos[i] + dot3(R + 3 * i, k1), c2[i] = pos[i] + dot3(R + 3 * i, k2);
    } else {
        double a2[3], b2[3];
        core(xpos, xmat, half, g2, a2, b2);
        segments(a1, b1, a2, b2, c1, c2);
    }
    double v[3] = {c2[0] - c1[0], c2[1] - c1[1], c2[2] - c1[2]}, length = sqrt(dot3(v, v));
    double dist = length - radius[g1] - radius[g2];
    if (!(dist > 0.0)) return NAN;
    for (int i = 0; i < 3; i++) {
        double n = v[i] / length;
        fromto[i] = c1[i] + radius[g1] * n;
        fromto[3 + i] = c2[i] - radius[g2] * n;
    }
    return dist;
}

/* geom_distances(kind, radius, half, xpos, xmat, pairs, bounds, reach, dist, fromto) -> left:
 * each pair's distance capped at reach (reach without computing it where the bounding spheres
 * are that far apart) and nearest points; nan for the `left` pairs MuJoCo must compute. */
static PyObject *om_geom_distances(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 10, "geom_distances") < 0) return NULL;
    double reach = PyFloat_AsDouble(args[7]);
    if (reach == -1.0 && PyErr_Occurred()) return NULL;
    Py_buffer v[9];
    const buffer_spec sp[9] = {{I64, -1, 0, "kind"},  {F64, -1, 0, "radius"},     {F64, -1, 0, "half"},
                               {F64, -1, 0, "xpos"},  {F64, -1, 0, "xmat"},       {I64, -1, 0, "pairs"},
                               {F64, -1, 0, "bounds"}, {F64, -1, 1, "dist"},      {F64, -1, 1, "fromto"}};
    PyObject *const objs[9] = {args[0], args[1], args[2], args[3], args[4], args[5], args[6], args[8], args[9]};
    if (get_buffers(objs, v, sp, 9) < 0) return NULL;
    Py_ssize_t G = v[0].len / 8, P = v[6].len / 8;
    const int64_t *kind = v[0].buf, *pairs = v[5].buf;
    int bad = v[1].len != G * 8 || v[2].len != G * 24 || v[3].len != G * 24 || v[4].len != G * 72 ||
              v[5].len != P * 16 || v[7].len != P * 8 || v[8].len != P * 48;
    for (Py_ssize_t k = 0; k < P && !bad; k++)
        bad = pairs[2 * k] < 0 || pairs[2 * k] >= G || pairs[2 * k + 1] < 0 || pairs[2 * k + 1] >= G;
    if (bad) {
        release_buffers(v, 9);
        PyErr_SetString(PyExc_ValueError, "geom_distances: sizes of the geoms, pairs and outputs disagree");
        return NULL;
    }
    const double *radius = v[1].buf, *half = v[2].buf, *xpos = v[3].buf, *xmat = v[4].buf, *bounds = v[6].buf;
    double *dist = v[7].buf, *fromto = v[8].buf;
    long left = 0;
    Py_BEGIN_ALLOW_THREADS for (Py_ssize_t k = 0; k < P; k++) {
        int g1 = (int)pairs[2 * k], g2 = (int)pairs[2 * k + 1];
        double *ft = fromto + 6 * k, w[3];
        for (int i = 0; i < 3; i++) w[i] = xpos[3 * g1 + i] - xpos[3 * g2 + i];
        memset(ft, 0, 6 * sizeof(double));
        if (sqrt(dot3(w, w)) - bounds[k] >= reach)
            dist[k] = reach;
        else if ((kind[g1] == CORE_POINT || kind[g1] == CORE_SEGMENT) && kind[g2] != CORE_MUJOCO) {
            double d = pair_distance(kind, radius, half, xpos, xmat, g1, g2, ft);
            dist[k] = d < reach ? d : isnan(d) ? d : reach;
        } else
            dist[k] = NAN;
        left += isnan(dist[k]);
    }
    Py_END_ALLOW_THREADS release_buffers(v, 9);
    return PyLong_FromLong(left);
}

/* distance_gradients(dist, fromto, reach, xanchor, xaxis, joints, slide, moves, grad): the
 * gradient of each pair's distance over the arm's joints (zero where capped at reach or 0). */
static PyObject *om_distance_gradients(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 9, "distance_gradients") < 0) return NULL;
    double reach = PyFloat_AsDouble(args[2]);
    if (reach == -1.0 && PyErr_Occurred()) return NULL;
    Py_buffer v[8];
    const buffer_spec sp[8] = {{F64, -1, 0, "dist"},  {F64, -1, 0, "fromto"}, {F64, -1, 0, "xanchor"},
                               {F64, -1, 0, "xaxis"}, {I64, -1, 0, "joints"}, {U8, -1, 0, "slide"},
                               {U8, -1, 0, "moves"},  {F64, -1, 1, "grad"}};
    PyObject *const objs[8] = {args[0], args[1], args[3], args[4], args[5], args[6], args[7], args[8]};
    if (get_buffers(objs, v, sp, 8) < 0) return NULL;
    Py_ssize_t P = v[0].len / 8, n = v[4].len / 8, J = v[2].len / 24;
    const int64_t *joints = v[4].buf;
    int bad = v[1].len != P * 48 || v[3].len != J * 24 || v[5].len != n || v[6].len != P * n || v[7].len != P * n * 8;
    for (Py_ssize_t j = 0; j < n && !bad; j++) bad = joints[j] < 0 || joints[j] >= J;
    if (bad) {
        release_buffers(v, 8);
        PyErr_SetString(PyExc_ValueError, "distance_gradients: sizes of the pairs, joints and outputs disagree");
        return NULL;
    }
    const double *dist = v[0].buf, *fromto = v[1].buf, *anchor = v[2].buf, *axis = v[3].buf;
    const uint8_t *slide = v[5].buf, *moves = v[6].buf;
    double *grad = v[7].buf;
    Py_BEGIN_ALLOW_THREADS for (Py_ssize_t k = 0; k < P; k++) {
        double *row = grad + k * n;
        const double *p = fromto + 6 * k;
        memset(row, 0, n * sizeof(double));
        if (!(dist[k] < reach && dist[k] != 0.0)) continue;
        double nk[3] = {(p[3] - p[0]) / dist[k], (p[4] - p[1]) / dist[k], (p[5] - p[2]) / dist[k]};
        for (Py_ssize_t j = 0; j < n; j++) {
            if (!moves[k * n + j]) continue;
            const double *a = axis + 3 * joints[j], *o = anchor + 3 * joints[j];
            double r[3] = {p[0] - o[0], p[1] - o[1], p[2] - o[2]};
            double dp[3] = {a[1] * r[2] - a[2] * r[1], a[2] * r[0] - a[0] * r[2], a[0] * r[1] - a[1] * r[0]};
            row[j] = -dot3(nk, slide[j] ? a : dp);
        }
    }
    Py_END_ALLOW_THREADS release_buffers(v, 8);
    Py_RETURN_NONE;
}

PyMethodDef om_clearance_functions[] = {
    {"geom_distances", (PyCFunction)(void (*)(void))om_geom_distances, METH_FASTCALL,
     "geom_distances(kind, radius, half, xpos, xmat, pairs, bounds, reach, dist, fromto) -> pairs left to MuJoCo"},
    {"distance_gradients", (PyCFunction)(void (*)(void))om_distance_gradients, METH_FASTCALL,
     "distance_gradients(dist, fromto, reach, xanchor, xaxis, joints, slide, moves, grad)"},
    {NULL, NULL, 0, NULL},
};
