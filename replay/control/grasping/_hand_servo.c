/* The hand task's per-step arithmetic on its 14 joints (replay/control/grasping/hand_control.py
 * documents it and keeps the float version, ``eq4_reference``, as the reference): F^h's
 * low-pass and eq. 4 with theta_d^h between the preshape and the grip. The same float
 * operations in the same order as the reference. Plain C: no NumPy headers.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>

#include "_pyfloats.h"

#define MAXJ 32

static Py_ssize_t length(PyObject *obj) {
    Py_ssize_t n = PySequence_Size(obj);
    if (n < 0) return -1;
    if (n > MAXJ) {
        PyErr_Format(PyExc_ValueError, "at most %d joints", MAXJ);
        return -1;
    }
    return n;
}

/* lowpass(load, torque, a) -> [x + a (-tau - x)]: F^h (the load: minus the drive's torque),
 * first-order low-passed with gain a. */
static PyObject *py_lowpass(PyObject *self, PyObject *args) {
    PyObject *xo, *to;
    double a;
    if (!PyArg_ParseTuple(args, "OOd", &xo, &to, &a)) return NULL;
    Py_ssize_t n = length(xo);
    if (n < 0) return NULL;
    double x[MAXJ], tau[MAXJ];
    if (!seq_doubles(xo, x, n, "floats", "lowpass: load") ||
        !seq_doubles(to, tau, n, "floats", "lowpass: torque"))
        return NULL;
    for (Py_ssize_t i = 0; i < n; i++) x[i] = x[i] + a * (-tau[i] - x[i]);
    return list_of_doubles(x, n);
}

/* eq4(pre, grip, c, q, qd, load, K_hg, K_hv, K_hf, vmax) -> (theta_d, command, deficit):
 * theta_d = pre + c (grip - pre) (grip None: theta_d = pre), eq. 4's command K_hg (theta_d - q)
 * - K_hv qd + K_hf load clipped to +-vmax (NaN passes, as np.clip), deficit = max |theta_d - q|.
 */
static PyObject *py_eq4(PyObject *self, PyObject *args) {
    PyObject *preo, *gripo, *qo, *qdo, *lo;
    double c, K_hg, K_hv, K_hf, vmax;
    if (!PyArg_ParseTuple(args, "OOdOOOdddd", &preo, &gripo, &c, &qo, &qdo, &lo, &K_hg, &K_hv,
                          &K_hf, &vmax))
        return NULL;
    Py_ssize_t n = length(preo);
    if (n < 0) return NULL;
    double td[MAXJ], grip[MAXJ], q[MAXJ], qd[MAXJ], load[MAXJ], cmd[MAXJ];
    if (!seq_doubles(preo, td, n, "floats", "eq4: pre") ||
        !seq_doubles(qo, q, n, "floats", "eq4: q") ||
        !seq_doubles(qdo, qd, n, "floats", "eq4: qd") ||
        !seq_doubles(lo, load, n, "floats", "eq4: load"))
        return NULL;
    if (gripo != Py_None) {
        if (!seq_doubles(gripo, grip, n, "floats", "eq4: grip")) return NULL;
        for (Py_ssize_t i = 0; i < n; i++) td[i] = td[i] + c * (grip[i] - td[i]);
    }
    double deficit = -INFINITY;
    for (Py_ssize_t i = 0; i < n; i++) {
        const double x = K_hg * (td[i] - q[i]) - K_hv * qd[i] + K_hf * load[i];
        cmd[i] = x > vmax ? vmax : (x < -vmax ? -vmax : x);
        const double d = fabs(td[i] - q[i]);
        if (d > deficit) deficit = d;
    }
    PyObject *a = list_of_doubles(td, n);
    if (a == NULL) return NULL;
    PyObject *b = list_of_doubles(cmd, n);
    if (b == NULL) {
        Py_DECREF(a);
        return NULL;
    }
    return Py_BuildValue("(NNd)", a, b, deficit);
}

static PyMethodDef methods[] = {
    {"lowpass", py_lowpass, METH_VARARGS, "F^h's first-order low-pass"},
    {"eq4", py_eq4, METH_VARARGS, "eq. 4: theta_d^h, the clipped command, the closure deficit"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_hand_servo",
                                    "The grasping hand task's per-step arithmetic.", -1,
                                    methods};

PyMODINIT_FUNC PyInit__hand_servo(void) { return PyModule_Create(&module); }
