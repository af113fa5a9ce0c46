/* The binding of the clearance kernels (csrc/redundancy/clearance.c): the arm's links and the geoms' cores
 * are read from a record (om_redundant._core.ArmCores) by name, the distances written into the
 * named arrays of another (om_redundant._core.PairDistances). */
#include <string.h>

#include "binding.h"
#include "redundancy.h"

/* The fields of an ArmCores record: the arm's links (all arm_geom_poses reads), then the cores. */
enum { C_TABLE, C_START, C_LINK, C_OFFSET, C_SLIDE, C_LINKS, C_OBSTACLE_POS = C_LINKS, C_OBSTACLE_MAT, C_KIND,
       C_RADIUS, C_HALF, C_PAIRS, C_BOUNDS, C_N };
static const char *const cores_names[C_N] = {"table", "start",  "link",   "offset", "slide", "obstacle_pos",
                                             "obstacle_mat", "kind", "radius", "half", "pairs", "bounds"};
static const buffer_spec cores_spec[C_N] = {
    {F64, -1, 0, "table"},        {F64, 12, 0, "start"}, {I64, -1, 0, "link"},   {F64, -1, 0, "offset"},
    {U8, -1, 0, "slide"},         {F64, -1, 0, "obstacle_pos"}, {F64, -1, 0, "obstacle_mat"},
    {I64, -1, 0, "kind"},         {F64, -1, 0, "radius"}, {F64, -1, 0, "half"},  {I64, -1, 0, "pairs"},
    {F64, -1, 0, "bounds"}};

/* The first n fields of a cores record (n = C_LINKS: the links only) into views; -1 with an error. */
static int get_cores(PyObject *record, Py_buffer *views, int n, const char *what) {
    PyObject *f[C_N];
    if (get_fields(record, cores_names, n, f, what) < 0) return -1;
    int got = get_buffers(f, views, cores_spec, n);
    release_fields(f, n);
    return got;
}

/* The arm's links checked (table rows of 6, offsets of 12 per geom, links within 0..dof) into
 * *arm, and q's rows of dof into *M; -1 with a ValueError. */
static int check_links(const Py_buffer *v, const Py_buffer *q, om_arm_links *arm, Py_ssize_t *M, const char *what) {
    Py_ssize_t n_rows = v[C_TABLE].len / 48, joints = table_joints(&v[C_TABLE]), A = v[C_LINK].len / 8;
    int bad = v[C_TABLE].len != n_rows * 48 || joints < 1 || joints > OM_MAX_DOF || v[C_OFFSET].len != A * 96 ||
              v[C_SLIDE].len != joints || q->len % (joints * 8) != 0;
    bad = bad || !indices_within(v[C_LINK].buf, A, 1, 0, joints + 1);
    if (bad) {
        PyErr_Format(PyExc_ValueError, "%s: sizes of the chain, geoms and joint vectors disagree", what);
        return -1;
    }
    *arm = (om_arm_links){v[C_TABLE].buf, v[C_START].buf, v[C_OFFSET].buf, (int)n_rows, (int)joints,
                          v[C_LINK].buf,  v[C_SLIDE].buf, A};
    *M = q->len / (joints * 8);
    return 0;
}

/* The geoms' cores of the views v (C_N, the arm's links checked into *arm) checked into *geoms,
 * with *work (PyMem_RawFree) holding the poses of all G geoms (12 G) and copies of the pairs
 * and links, checked here with the GIL held: the kernels index by them with the GIL released,
 * while the caller's arrays may change. -1 with a ValueError naming `what`, or MemoryError. */
static int open_cores(const Py_buffer *v, om_arm_links *arm, om_geom_cores *geoms, double **work, const char *what) {
    Py_ssize_t A = arm->A, G = v[C_KIND].len / 8, P = v[C_PAIRS].len / 16;
    const int64_t *pairs = v[C_PAIRS].buf;
    int bad = A > G || v[C_OBSTACLE_POS].len != (G - A) * 24 || v[C_OBSTACLE_MAT].len != (G - A) * 72 ||
              v[C_RADIUS].len != G * 8 || v[C_HALF].len != G * 24 || v[C_PAIRS].len != P * 16 ||
              v[C_BOUNDS].len != P * 8;
    bad = bad || !indices_within(pairs, P, 2, 0, A) || !indices_within(pairs + 1, P, 2, A, G);
    if (bad) {
        PyErr_Format(PyExc_ValueError, "%s: sizes of the geoms, pairs and outputs disagree", what);
        return -1;
    }
    *work = PyMem_RawMalloc(((size_t)G * 12 + (size_t)(2 * P + A)) * sizeof(double));
    if (!*work) {
        PyErr_NoMemory();
        return -1;
    }
    int64_t *pairs_copy = (int64_t *)(*work + 12 * G), *link = pairs_copy + 2 * P;
    memcpy(pairs_copy, pairs, (size_t)(2 * P) * sizeof(int64_t));
    memcpy(link, arm->link, (size_t)A * sizeof(int64_t));
    arm->link = link;
    *geoms = (om_geom_cores){v[C_OBSTACLE_POS].buf, v[C_OBSTACLE_MAT].buf, v[C_RADIUS].buf, v[C_HALF].buf,
                             v[C_BOUNDS].buf,       v[C_KIND].buf,         pairs_copy,      G,
                             P};
    return 0;
}

/* arm_geom_poses(links, q, xpos, xmat): the world poses (M, A, 3) and (M, A, 3, 3) of the arm's A
 * geoms at each of the M rows of q (M, dof); links: a record with the fields table, start, link,
 * offset and slide (an ArmCores, or an ArmLinks). */
static PyObject *om_arm_geom_poses_py(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    static const char *const names[] = {"links", "q", "xpos", "xmat"};
    static const arg_spec spec = {"arm_geom_poses", names, 4, 4};
    PyObject *a[4];
    if (bind_args(args, nargs, kwnames, &spec, a) < 0) return NULL;
    Py_buffer v[C_LINKS + 3];
    if (get_cores(a[0], v, C_LINKS, "arm_geom_poses' links") < 0) return NULL;
    const buffer_spec sp[3] = {{F64, -1, 0, "q"}, {F64, -1, 1, "xpos"}, {F64, -1, 1, "xmat"}};
    if (get_buffers(a + 1, v + C_LINKS, sp, 3) < 0) {
        release_buffers(v, C_LINKS);
        return NULL;
    }
    om_arm_links arm;
    Py_ssize_t M;
    const Py_buffer *q = &v[C_LINKS], *xpos = &v[C_LINKS + 1], *xmat = &v[C_LINKS + 2];
    if (check_links(v, q, &arm, &M, "arm_geom_poses") < 0 || xpos->len != M * arm.A * 24 ||
        xmat->len != M * arm.A * 72) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "arm_geom_poses: A poses per joint vector");
        release_buffers(v, C_LINKS + 3);
        return NULL;
    }
    for (Py_ssize_t m = 0; m < M; m++)
        om_arm_geom_poses(&arm, (const double *)q->buf + m * arm.dof, (double *)xpos->buf + 3 * arm.A * m,
                          (double *)xmat->buf + 9 * arm.A * m);
    release_buffers(v, C_LINKS + 3);
    Py_RETURN_NONE;
}

/* The fields of a PairDistances record. */
enum { D_DIST, D_FROMTO, D_GRAD, D_N };
static const char *const distances_names[D_N] = {"dist", "fromto", "grad"};

/* arm_clearance(cores, q, reach, near, out, given) -> left: the geoms are the arm's A and the
 * O obstacles (poses (O, 3) and (O, 9)), G = A + O; for each row m of q (M, dof), the arm's
 * geoms placed (in this call's own work array: calls may run in parallel), each pair's
 * distance out.dist (M, P) capped at reach and nearest points out.fromto (M, P, 6) (nan: the
 * `left` pairs MuJoCo must compute), and unless out.grad is None their gradients (M, P, dof),
 * in a row with a pair nearer than `near` only those of the pairs nearer than it (the others
 * 0). given true: dist and fromto are read, not written, for the gradients of pairs MuJoCo
 * computed. Pairs (P, 2) index the geoms, an arm geom first. */
static PyObject *om_arm_clearance_py(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    static const char *const names[] = {"cores", "q", "reach", "near", "out", "given"};
    static const arg_spec spec = {"arm_clearance", names, 6, 6};
    enum { Q = C_N, DIST, FROMTO, GRAD, N }; /* the views: the cores', q, out's */
    PyObject *a[6], *d[D_N];
    if (bind_args(args, nargs, kwnames, &spec, a) < 0) return NULL;
    double reach = PyFloat_AsDouble(a[2]), near = PyFloat_AsDouble(a[3]);
    if (PyErr_Occurred()) return NULL;
    int given = PyObject_IsTrue(a[5]);
    if (given < 0) return NULL;
    if (get_fields(a[4], distances_names, D_N, d, "arm_clearance's out") < 0) return NULL;
    int with_grad = d[D_GRAD] != Py_None, n_views = with_grad ? N : N - 1;
    Py_buffer v[N];
    const buffer_spec sp[N - C_N] = {
        {F64, -1, 0, "q"}, {F64, -1, !given, "dist"}, {F64, -1, !given, "fromto"}, {F64, -1, 1, "grad"}};
    PyObject *const objs[N - C_N] = {a[1], d[D_DIST], d[D_FROMTO], d[D_GRAD]};
    PyObject *result = NULL;
    if (given && !with_grad) {
        PyErr_SetString(PyExc_ValueError, "arm_clearance: given distances need grad");
        goto done;
    }
    if (get_cores(a[0], v, C_N, "arm_clearance's cores") < 0) goto done;
    if (get_buffers(objs, v + C_N, sp, n_views - C_N) < 0) {
        release_buffers(v, C_N);
        goto done;
    }
    om_arm_links arm;
    Py_ssize_t M;
    if (check_links(v, &v[Q], &arm, &M, "arm_clearance") < 0) goto release;
    om_geom_cores geoms;
    double *work;
    if (open_cores(v, &arm, &geoms, &work, "arm_clearance") < 0) goto release;
    Py_ssize_t P = geoms.P;
    if (v[DIST].len != M * P * 8 || v[FROMTO].len != M * P * 48 || (with_grad && v[GRAD].len != M * P * arm.dof * 8)) {
        PyMem_RawFree(work);
        PyErr_SetString(PyExc_ValueError, "arm_clearance: sizes of the geoms, pairs and outputs disagree");
        goto release;
    }
    double *dist = v[DIST].buf, *fromto = v[FROMTO].buf, *grad = with_grad ? v[GRAD].buf : NULL;
    const double *q = v[Q].buf;
    long left;
    Py_BEGIN_ALLOW_THREADS left = om_arm_clearance(&arm, &geoms, M, q, reach, near, dist, fromto, grad, given, work);
    Py_END_ALLOW_THREADS PyMem_RawFree(work);
    result = PyLong_FromLong(left);
release:
    release_buffers(v, n_views);
done:
    release_fields(d, D_N);
    return result;
}

/* The fields of a Segment record, and of a SegmentCheck record. */
enum { S_FROM, S_TO, S_ROWS, S_DIST, S_FROMTO, S_N };
static const char *const segment_names[S_N] = {"q_from", "q_to", "rows", "dist", "fromto"};
enum { K_LIPSCHITZ, K_FLOOR, K_BUDGET, K_TOLERANCE, K_REACH, K_N };
static const char *const check_names[K_N] = {"lipschitz", "floor", "budget", "tolerance", "reach"};

/* What segment_minimum's distances read: the arm and geoms (open_cores), the distances' cap,
 * the segment's rows and outputs, and the fill of the pairs left to MuJoCo. */
typedef struct {
    om_arm_links arm;
    om_geom_cores geoms;
    double *work, reach, *rows, *dist, *fromto;
    PyObject *fill;
} segment_context;

/* om_segment's distances: rows start .. stop - 1 by om_arm_clearance (the GIL released), then
 * fill(start, stop) where it left pairs (nan) to MuJoCo; -1 with the error. */
static int segment_distances(void *context, ptrdiff_t start, ptrdiff_t stop) {
    segment_context *c = context;
    ptrdiff_t P = c->geoms.P, dof = c->arm.dof;
    long left;
    Py_BEGIN_ALLOW_THREADS left = om_arm_clearance(&c->arm, &c->geoms, stop - start, c->rows + start * dof, c->reach,
                                                   INFINITY, c->dist + start * P, c->fromto + start * P * 6, NULL,
                                                   false, c->work);
    Py_END_ALLOW_THREADS if (left == 0) return 0;
    PyObject *filled = PyObject_CallFunction(c->fill, "nn", (Py_ssize_t)start, (Py_ssize_t)stop);
    if (!filled) return -1;
    Py_DECREF(filled);
    return 0;
}

/* segment_minimum(cores, segment, check, fill) -> float: the clearance along the segment from
 * segment.q_from to segment.q_to (dof each) as far as it matters against check.floor
 * (om_segment_minimum with check.lipschitz, check.tolerance; NaN where check.budget samples
 * inside it left it undecided), the pairs' distances capped at check.reach; segment.rows (R, dof), dist (R, P) and
 * fromto (R, P, 6) its samples' rows and outputs, the ends first (None where the samples
 * outgrow them); fill(start, stop) fills the distances of rows start .. stop - 1 that
 * arm_clearance left (nan) to MuJoCo. */
static PyObject *om_segment_minimum_py(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    static const char *const names[] = {"cores", "segment", "check", "fill"};
    static const arg_spec spec = {"segment_minimum", names, 4, 4};
    PyObject *a[4], *f[S_N], *k[K_N];
    if (bind_args(args, nargs, kwnames, &spec, a) < 0) return NULL;
    if (get_fields(a[2], check_names, K_N, k, "segment_minimum's check") < 0) return NULL;
    double numbers[K_N];
    for (int i = 0; i < K_N; i++) numbers[i] = PyFloat_AsDouble(k[i]);
    release_fields(k, K_N);
    if (PyErr_Occurred()) return NULL;
    double lipschitz = numbers[K_LIPSCHITZ], floor = numbers[K_FLOOR], budget = numbers[K_BUDGET];
    double tolerance = numbers[K_TOLERANCE], reach = numbers[K_REACH];
    if (!PyCallable_Check(a[3])) {
        PyErr_SetString(PyExc_TypeError, "segment_minimum: fill must be callable");
        return NULL;
    }
    if (get_fields(a[1], segment_names, S_N, f, "segment_minimum's segment") < 0) return NULL;
    Py_buffer v[C_N + S_N];
    const buffer_spec sp[S_N] = {{F64, -1, 0, "q_from"}, {F64, -1, 0, "q_to"}, {F64, -1, 1, "rows"},
                                 {F64, -1, 1, "dist"},   {F64, -1, 1, "fromto"}};
    PyObject *result = NULL;
    if (get_cores(a[0], v, C_N, "segment_minimum's cores") < 0) goto done;
    if (get_buffers(f, v + C_N, sp, S_N) < 0) {
        release_buffers(v, C_N);
        goto done;
    }
    segment_context c = {.reach = reach, .fill = a[3]};
    Py_ssize_t M;
    if (check_links(v, &v[C_N + S_FROM], &c.arm, &M, "segment_minimum") < 0) goto release;
    if (open_cores(v, &c.arm, &c.geoms, &c.work, "segment_minimum") < 0) goto release;
    Py_ssize_t dof = c.arm.dof, P = c.geoms.P, R = v[C_N + S_ROWS].len / (dof * 8);
    if (M != 1 || v[C_N + S_TO].len != dof * 8 || v[C_N + S_ROWS].len != R * dof * 8 ||
        v[C_N + S_DIST].len != R * P * 8 || v[C_N + S_FROMTO].len != R * P * 48 || !(lipschitz >= 0.0) ||
        !(budget >= 0.0) || !(tolerance >= 0.0)) {
        PyMem_RawFree(c.work);
        PyErr_SetString(PyExc_ValueError, "segment_minimum: sizes of the segment, its rows and outputs disagree");
        goto release;
    }
    c.rows = v[C_N + S_ROWS].buf, c.dist = v[C_N + S_DIST].buf, c.fromto = v[C_N + S_FROMTO].buf;
    om_segment segment = {(int)dof, P, R, v[C_N + S_FROM].buf, v[C_N + S_TO].buf, c.rows, c.dist,
                          segment_distances, &c};
    int status;
    double least = om_segment_minimum(&segment, lipschitz, floor, budget, tolerance, &status);
    PyMem_RawFree(c.work);
    if (status == OM_SEGMENT_OK)
        result = PyFloat_FromDouble(least);
    else if (status == OM_SEGMENT_FULL)
        result = Py_NewRef(Py_None);
    else if (status == OM_SEGMENT_NO_MEMORY)
        PyErr_NoMemory(); /* (OM_SEGMENT_FAILED: fill's error is set) */
release:
    release_buffers(v, C_N + S_N);
done:
    release_fields(f, S_N);
    return result;
}

/* The fields of a GeomPose record. */
enum { G_POS, G_MAT, G_HALF, G_RADIUS, G_N };
static const char *const geom_names[G_N] = {"pos", "mat", "half", "radius"};

/* box_overlap(geom, box, fromto) -> distance: om_box_overlap of a sphere or capsule geom at
 * geom.pos (3; rotation geom.mat, 9 row-major; half sizes geom.half, 3: a capsule's (0, 0, l);
 * radius geom.radius) and a box (box.pos, box.mat, box.half; its radius not read), in the
 * world; fromto (6). */
static PyObject *om_box_overlap_py(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    static const char *const names[] = {"geom", "box", "fromto"};
    static const arg_spec spec = {"box_overlap", names, 3, 3};
    PyObject *a[3], *f[G_N], *b[G_N - 1];
    if (bind_args(args, nargs, kwnames, &spec, a) < 0) return NULL;
    if (get_fields(a[0], geom_names, G_N, f, "box_overlap's geom") < 0) return NULL;
    PyObject *result = NULL;
    double radius = PyFloat_AsDouble(f[G_RADIUS]);
    if ((radius == -1.0 && PyErr_Occurred()) || get_fields(a[1], geom_names, G_N - 1, b, "box_overlap's box") < 0)
        goto done;
    PyObject *const objs[7] = {f[G_POS], f[G_MAT], f[G_HALF], b[G_POS], b[G_MAT], b[G_HALF], a[2]};
    const buffer_spec sp[7] = {{F64, 3, 0, "pos"},     {F64, 9, 0, "mat"},     {F64, 3, 0, "half"},
                               {F64, 3, 0, "box_pos"}, {F64, 9, 0, "box_mat"}, {F64, 3, 0, "box_half"},
                               {F64, 6, 1, "fromto"}};
    Py_buffer v[7];
    if (get_buffers(objs, v, sp, 7) == 0) {
        double distance = om_box_overlap(v[0].buf, v[1].buf, v[2].buf, radius, v[3].buf, v[4].buf, v[5].buf, v[6].buf);
        release_buffers(v, 7);
        result = PyFloat_FromDouble(distance);
    }
    release_fields(b, G_N - 1);
done:
    release_fields(f, G_N);
    return result;
}

static PyMethodDef functions[] = {
    {"box_overlap", (PyCFunction)(void (*)(void))om_box_overlap_py, METH_FASTCALL | METH_KEYWORDS,
     "box_overlap(geom, box, fromto) -> distance"},
    {"arm_geom_poses", (PyCFunction)(void (*)(void))om_arm_geom_poses_py, METH_FASTCALL | METH_KEYWORDS,
     "arm_geom_poses(links, q, xpos, xmat)"},
    {"arm_clearance", (PyCFunction)(void (*)(void))om_arm_clearance_py, METH_FASTCALL | METH_KEYWORDS,
     "arm_clearance(cores, q, reach, near, out, given) -> pairs left to MuJoCo"},
    {"segment_minimum", (PyCFunction)(void (*)(void))om_segment_minimum_py, METH_FASTCALL | METH_KEYWORDS,
     "segment_minimum(cores, segment, check, fill) -> float or None"},
    {NULL, NULL, 0, NULL},
};

int om_clearance_init(PyObject *module) {
    static const int_constant kinds[] = {{"CORE_MUJOCO", OM_CORE_MUJOCO}, {"CORE_POINT", OM_CORE_POINT},
                 {"CORE_SEGMENT", OM_CORE_SEGMENT}, {"CORE_BOX", OM_CORE_BOX}};
    if (PyModule_AddFunctions(module, functions) < 0) return -1;
    return add_int_constants(module, kinds, sizeof kinds / sizeof kinds[0]);
}
