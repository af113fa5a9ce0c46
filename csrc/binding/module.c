/* The CPython binding of om_redundant's compiled core: om_redundant.ckernels.
 *
 * Arrays cross as buffers (numpy arrays), checked here for dtype, C-contiguity and size:
 * a wrong one raises TypeError or ValueError naming the argument, never reads past its end.
 * Configurations cross as the tuples of om.Configuration. Every kernel call releases the
 * GIL, so threads solve in parallel.
 */
#include "binding.h"

PyObject *om_status_names;

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "ckernels", "om_redundant's compiled core (see csrc/ik/om_kernels.h).", -1, om_kernel_functions,
};

PyMODINIT_FUNC PyInit_ckernels(void) {
    PyObject *m = PyModule_Create(&module);
    if (!m) return NULL;
    /* The codes and layouts Python reads from here (om_redundant._core): each written once, in C. */
    static const int_constant constants[] = {
        {"MAX_ROOTS", OM_MAX_ROOTS}, {"MAX_DOF", OM_MAX_DOF},
        {"MIN_SCAN_POINTS", OM_MIN_SCAN_POINTS}, {"MAX_SCAN_POINTS", OM_MAX_SCAN_POINTS},
        {"SD_A1", SD_A1}, {"SD_D1", SD_D1}, {"SD_SIGMA1", SD_SIGMA1}, {"SD_THETA1", SD_THETA1},
        {"SD_LATERAL", SD_LATERAL}, {"SD_A2", SD_A2}, {"SD_THETA2", SD_THETA2}, {"SD_ELL3", SD_ELL3},
        {"SD_BETA", SD_BETA}, {"SD_THETA3", SD_THETA3}, {"SD_SIGMA2", SD_SIGMA2}, {"SD_D3", SD_D3},
        {"SD_SIGMA4", SD_SIGMA4}, {"SD_SIGMA5", SD_SIGMA5}, {"SD_THETA4", SD_THETA4}, {"SD_THETA5", SD_THETA5},
        {"SD_THETA6", SD_THETA6}, {"SD_WRIST_CENTRE", SD_WRIST_CENTRE}, {"SD_E_ROT", SD_E_ROT},
        {"SD_WRIST_ROW", SD_WRIST_ROW}, {"SD_WRIST_OFFSET", SD_WRIST_OFFSET}, {"SD_AXIS4", SD_AXIS4},
        {"SD_AXIS6", SD_AXIS6}, {"SD_WRIST_TORUS", SD_WRIST_TORUS},
        {"SD_N_PARAMS", SD_N_PARAMS},
        {"SRS_SIGMA1", SRS_SIGMA1}, {"SRS_SIGMA2", SRS_SIGMA2}, {"SRS_SIGMA5", SRS_SIGMA5},
        {"SRS_SIN_BETA", SRS_SIN_BETA}, {"SRS_THETA", SRS_THETA}, {"SRS_SHOULDER", SRS_SHOULDER},
        {"SRS_WRIST", SRS_WRIST}, {"SRS_S3", SRS_S3}, {"SRS_U", SRS_U}, {"SRS_K0", SRS_K0}, {"SRS_K", SRS_K},
        {"SRS_PHI_STAR", SRS_PHI_STAR}, {"SRS_R_PRE", SRS_R_PRE}, {"SRS_X3", SRS_X3}, {"SRS_X4", SRS_X4},
        {"SRS_E_ROT", SRS_E_ROT}, {"SRS_UP", SRS_UP}, {"SRS_REF", SRS_REF}, {"SRS_BEND", SRS_BEND},
        {"SRS_COS_BETA", SRS_COS_BETA},
        {"SRS_COS_PHI_STAR", SRS_COS_PHI_STAR}, {"SRS_SIN_PHI_STAR", SRS_SIN_PHI_STAR}, {"SRS_N_PARAMS", SRS_N_PARAMS},
        {"RRR_SPHERICAL_WRIST", OM_RRR_SPHERICAL_WRIST}, {"RRP_SPHERICAL_WRIST", OM_RRP_SPHERICAL_WRIST},
        {"SRS", OM_SRS}, {"FIXED", OM_FIXED}, {"CIRCLE", OM_CIRCLE}, {"TORUS", OM_TORUS}, {"OK", OM_OK},
        {"UNREACHABLE", OM_UNREACHABLE}, {"NO_SOLUTION_IN_CONFIGURATION", OM_NO_SOLUTION_IN_CONFIGURATION},
        {"FOLLOW_ARRIVED", OM_FOLLOW_ARRIVED}, {"FOLLOW_ENDED", OM_FOLLOW_ENDED},
        {"FOLLOW_STALLED", OM_FOLLOW_STALLED}, {"FOLLOW_MAX_ATTEMPTS", OM_FOLLOW_MAX_ATTEMPTS},
        {"FOLLOW_CRAWL_STEPS", OM_FOLLOW_CRAWL_STEPS},
        {"DH_A", OM_DH_A}, {"DH_D", OM_DH_D}, {"DH_THETA", OM_DH_THETA}, {"DH_COS_ALPHA", OM_DH_COS_ALPHA},
        {"DH_SIN_ALPHA", OM_DH_SIN_ALPHA}, {"DH_KIND", OM_DH_KIND}, {"DH_COLUMNS", OM_DH_COLUMNS},
        {"JOINT_REVOLUTE", OM_JOINT_REVOLUTE}, {"JOINT_PRISMATIC", OM_JOINT_PRISMATIC},
        {"JOINT_FIXED", OM_JOINT_FIXED},
        {"LINK_DONE", OM_LINK_DONE}, {"LINK_FULL", OM_LINK_FULL},
    };
    if (om_solver_init(m) < 0) goto fail;
    if (PyModule_AddFunctions(m, om_closed_form_functions) < 0 || om_closed_forms_init(m) < 0) goto fail;
    if (om_tracking_init(m) < 0 || om_clearance_init(m) < 0) goto fail;
    if (PyModule_AddFunctions(m, om_path_functions) < 0 || om_paths_init(m) < 0) goto fail;
    if (PyModule_AddFunctions(m, om_objective_functions) < 0) goto fail;
    if (PyModule_AddFunctions(m, om_cell_functions) < 0) goto fail;
    if (om_box_qp_init(m) < 0) goto fail;
    if (PyModule_AddFunctions(m, om_start_bound_functions) < 0) goto fail;
    if (PyModule_AddFunctions(m, om_traces_functions) < 0) goto fail;
    if (add_int_constants(m, constants, sizeof constants / sizeof constants[0]) < 0) goto fail;
    const struct {
        const char *name;
        double value;
    } floats[] = {
        {"REACH_SLACK", OM_REACH_SLACK}, {"BRANCH_BAND", OM_BRANCH_BAND}, {"ORTHONORMALITY_TOLERANCE", OM_ORTHONORMALITY_TOL},
        {"END_TOLERANCE", OM_END_TOLERANCE}, {"PATH_SAME", OM_PATH_SAME}, {"PATH_JUMP", OM_PATH_JUMP},
        {"FOLLOW_AIM", OM_FOLLOW_AIM},
        {"FOLLOW_CRAWL", OM_FOLLOW_CRAWL}};
    for (size_t i = 0; i < sizeof floats / sizeof floats[0]; i++) {
        PyObject *v = PyFloat_FromDouble(floats[i].value);
        if (!v || PyModule_AddObject(m, floats[i].name, v) < 0) {
            Py_XDECREF(v);
            goto fail;
        }
    }
    /* By status code: OM_OK, OM_UNREACHABLE, OM_NO_SOLUTION_IN_CONFIGURATION. */
    if (!om_status_names)
        om_status_names = Py_BuildValue("(sss)", "ok", "unreachable", "no solution in this configuration");
    if (!om_status_names || PyModule_AddObjectRef(m, "STATUS_NAMES", om_status_names) < 0) goto fail;
    return m;
fail:
    Py_DECREF(m);
    return NULL;
}
