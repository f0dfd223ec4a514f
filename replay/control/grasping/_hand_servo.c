/* The hand task's per-step arithmetic on its 14 joints (replay/control/grasping/hand_control.py
 * documents it and keeps the float version, ``eq4_reference``, as the reference): F^h's
 * low-pass and eq. 4 with theta_d^h between the preshape and the grip. The same float
 * operations in the same order as the reference. Plain C: no NumPy headers.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>

#define MAXJ 32

static int read_seq(PyObject *obj, double *out, Py_ssize_t n, const char *what) {
    PyObject *seq = PySequence_Fast(obj, what);
    if (seq == NULL) return -1;
    if (PySequence_Fast_GET_SIZE(seq) != n) {
        PyErr_Format(PyExc_ValueError, "%s: expected %zd values", what, n);
        Py_DECREF(seq);
        return -1;
    }
    PyObject **items = PySequence_Fast_ITEMS(seq);
    for (Py_ssize_t i = 0; i < n; i++) {
        out[i] = PyFloat_AsDouble(items[i]);
        if (out[i] == -1.0 && PyErr_Occurred()) {
            Py_DECREF(seq);
            return -1;
        }
    }
    Py_DECREF(seq);
    return 0;
}

static PyObject *list_of(const double *x, Py_ssize_t n) {
    PyObject *out = PyList_New(n);
    if (out == NULL) return NULL;
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *f = PyFloat_FromDouble(x[i]);
        if (f == NULL) {
            Py_DECREF(out);
            return NULL;
        }
        PyList_SET_ITEM(out, i, f);
    }
    return out;
}

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
    if (read_seq(xo, x, n, "lowpass: load") < 0 || read_seq(to, tau, n, "lowpass: torque") < 0)
        return NULL;
    for (Py_ssize_t i = 0; i < n; i++) x[i] = x[i] + a * (-tau[i] - x[i]);
    return list_of(x, n);
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
    if (read_seq(preo, td, n, "eq4: pre") < 0 || read_seq(qo, q, n, "eq4: q") < 0 ||
        read_seq(qdo, qd, n, "eq4: qd") < 0 || read_seq(lo, load, n, "eq4: load") < 0)
        return NULL;
    if (gripo != Py_None) {
        if (read_seq(gripo, grip, n, "eq4: grip") < 0) return NULL;
        for (Py_ssize_t i = 0; i < n; i++) td[i] = td[i] + c * (grip[i] - td[i]);
    }
    double deficit = -INFINITY;
    for (Py_ssize_t i = 0; i < n; i++) {
        const double x = K_hg * (td[i] - q[i]) - K_hv * qd[i] + K_hf * load[i];
        cmd[i] = x > vmax ? vmax : (x < -vmax ? -vmax : x);
        const double d = fabs(td[i] - q[i]);
        if (d > deficit) deficit = d;
    }
    PyObject *a = list_of(td, n);
    if (a == NULL) return NULL;
    PyObject *b = list_of(cmd, n);
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
