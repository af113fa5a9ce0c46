/* The binding of the self-motion a batch traced, kept for the follows after it (torus.c,
 * om_torus_memo_take; om_problem.traces): torus_traces(solver) -> a TorusTraces capsule, empty
 * until a batch of solve_all_rows keeps its traces there (SolveAllBatch.traces), which follow
 * and link_paths then read (FollowWork.traces); None for a solver whose searches trace none. */
#include "binding.h"

static const char *const CAPSULE = "om_redundant.ckernels.TorusTraces";

/* A capsule's pointer: the traces and the solver they belong to (a reference held: its data
 * outlives them). */
typedef struct {
    PyObject *solver;
    om_torus_memo *memo;
} kept_traces;

static void free_traces(PyObject *capsule) {
    kept_traces *kept = PyCapsule_GetPointer(capsule, CAPSULE);
    if (!kept) return;
    om_torus_memo_free(kept->memo);
    Py_XDECREF(kept->solver);
    PyMem_Free(kept);
}

/* torus_traces(solver) -> TorusTraces or None */
static PyObject *om_torus_traces(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 1, "torus_traces") < 0) return NULL;
    PyObject *solver = args[0];
    if (!PyObject_TypeCheck(solver, &om_SolverType)) {
        PyErr_SetString(PyExc_TypeError, "torus_traces: solver must be a ckernels.Solver");
        return NULL;
    }
    const om_solver_data *s = om_solver_ready((om_Solver *)solver);
    if (!s) return NULL;
    om_torus_memo *memo = om_torus_memo_new(s);
    if (!memo) Py_RETURN_NONE; /* (no terms, no trace: or out of memory, where the windows take their grid) */
    kept_traces *kept = PyMem_Malloc(sizeof *kept);
    PyObject *capsule = kept ? PyCapsule_New(kept, CAPSULE, free_traces) : NULL;
    if (!capsule) {
        om_torus_memo_free(memo);
        PyMem_Free(kept);
        return PyErr_Occurred() ? NULL : PyErr_NoMemory();
    }
    kept->solver = Py_NewRef(solver);
    kept->memo = memo;
    return capsule;
}

om_torus_memo *om_traces_of(PyObject *obj, const om_solver_data *s, const char *what) {
    if (obj == Py_None) return NULL;
    kept_traces *kept = PyCapsule_IsValid(obj, CAPSULE) ? PyCapsule_GetPointer(obj, CAPSULE) : NULL;
    if (!kept) {
        PyErr_Format(PyExc_TypeError, "%s: traces must be None or a ckernels.torus_traces(solver)", what);
        return NULL;
    }
    if (om_solver_ready((om_Solver *)kept->solver) != s) {
        PyErr_Format(PyExc_ValueError, "%s: the traces belong to another solver", what);
        return NULL;
    }
    return kept->memo;
}

PyMethodDef om_traces_functions[] = {
    {"torus_traces", (PyCFunction)(void (*)(void))om_torus_traces, METH_FASTCALL,
     "torus_traces(solver) -> TorusTraces or None: where a batch keeps the self-motion it traced for the "
     "follows after it"},
    {NULL, NULL, 0, NULL},
};
