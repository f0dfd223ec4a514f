/* The catching controller's joint torques, compiled (replay/control/catching/controller.py
 * CatchingController._torque): tau = ff + Kp (q_d - q) + Kd (qd_d - qd) saturated at +-limit,
 * the same operations in the same order as the Python list comprehension, which stays the
 * reference (tests/replay/control/catching/test_one_sample_paths.py holds them together). Plain
 * C: no NumPy headers.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include "_pyfloats.h"

#define MAX_JOINTS 64

/* pd(ff, kp, q_d, q, kd, qd_d, qd, limit): the list of n torques (n = len(ff) <= 64) */
static PyObject *py_pd(PyObject *self, PyObject *args) {
    PyObject *o[8];
    if (!PyArg_ParseTuple(args, "OOOOOOOO", o, o + 1, o + 2, o + 3, o + 4, o + 5, o + 6, o + 7))
        return NULL;
    Py_ssize_t n = PyObject_Length(o[0]);
    if (n < 0) return NULL;
    if (n > MAX_JOINTS)
        return PyErr_Format(PyExc_ValueError, "pd: more than %d joints", MAX_JOINTS);
    static const char *what[8] = {"ff", "kp", "q_d", "q", "kd", "qd_d", "qd", "limit"};
    double v[8][MAX_JOINTS];
    for (int i = 0; i < 8; i++)
        if (!seq_doubles(o[i], v[i], n, "floats", what[i])) return NULL;
    PyObject *out = PyList_New(n);
    if (!out) return NULL;
    for (Py_ssize_t k = 0; k < n; k++) {
        double x = v[0][k] + v[1][k] * (v[2][k] - v[3][k]) + v[4][k] * (v[5][k] - v[6][k]);
        double lim = v[7][k];
        x = x > lim ? lim : (x < -lim ? -lim : x);
        PyObject *f = PyFloat_FromDouble(x);
        if (!f) {
            Py_DECREF(out);
            return NULL;
        }
        PyList_SET_ITEM(out, k, f);
    }
    return out;
}

static PyMethodDef methods[] = {
    {"pd", py_pd, METH_VARARGS, "feed-forward + PD joint torques, saturated"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_torque",
                                    "The catching controller's joint torques.", -1, methods};

PyMODINIT_FUNC PyInit__torque(void) { return PyModule_Create(&module); }
