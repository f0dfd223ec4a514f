/* The ballistic estimator's time to the catch surface, compiled (replay/control/catching/
 * estimator.py BallisticEstimator.time_to_radius): the fitted arc carried to t, the quartic
 * |d + v s + g s^2 / 2|^2 = R^2 and its first root by Newton's method from s = 0 where that
 * provably finds it (_first_root_newton). The same operations in the same order as the Python,
 * which stays the reference and the fallback (the companion matrix's eigenvalues) when Newton's
 * method cannot decide; tests/replay/control/catching/test_one_sample_paths.py holds them
 * together. Plain C: no NumPy headers.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>

#include "_pyfloats.h"

/* _first_root_newton: 1 and *root = the smallest root s >= 0 of c[0] s^4 + ... + c[4], 0 when
 * Newton's method from 0 does not provably find it. */
static int first_root_newton(const double c[5], double *root) {
    const double c4 = c[0], c3 = c[1], c2 = c[2], c1 = c[3], c0 = c[4];
    double s = 0.0;
    int settled = 0;
    for (int k = 0; k < 60; k++) {
        double f = (((c4 * s + c3) * s + c2) * s + c1) * s + c0;
        double fp = ((4.0 * c4 * s + 3.0 * c3) * s + 2.0 * c2) * s + c1;
        if (!(fp < 0.0)) return 0;
        double step = f / fp;
        s -= step;
        double scale = 1e-3 > s ? 1e-3 : s; /* max(s, 1e-3) */
        if (fabs(step) <= 1e-15 * scale) {
            settled = 1;
            break;
        }
    }
    if (!settled || !(s >= 0.0)) return 0;
    /* h'' = 12 c4 s^2 + 6 c3 s + 2 c2 must stay positive on [0, s]: its minimum there */
    double cand[3] = {0.0, s, 0.0};
    int nc = 2;
    if (c4 > 0.0) {
        double x = -c3 / (4.0 * c4);
        if (0.0 < x && x < s) cand[nc++] = x;
    }
    double m = 0.0;
    for (int i = 0; i < nc; i++) {
        double x = cand[i], h = (12.0 * c4 * x + 6.0 * c3) * x + 2.0 * c2;
        if (i == 0 || h < m) m = h; /* min(): the first of equal ones */
    }
    if (m <= 0.0) return 0;
    *root = s;
    return 1;
}

static PyObject *py_time_to_radius(PyObject *self, PyObject *args) {
    double t, t_last, radius, r0[3], v[3], g[3], o[3];
    PyObject *R0, *V, *G, *O;
    if (!PyArg_ParseTuple(args, "ddOOOOd", &t, &t_last, &R0, &V, &G, &O, &radius)) return NULL;
    if (!seq_doubles(R0, r0, 3, "floats", "r0") ||
        !seq_doubles(V, v, 3, "floats", "v") ||
        !seq_doubles(G, g, 3, "floats", "g") ||
        !seq_doubles(O, o, 3, "floats", "origin"))
        return NULL;
    /* BallisticEstimator.state_f(t, from_fit=True) */
    const double dt = t - t_last;
    double r[3], w[3];
    for (int k = 0; k < 3; k++) {
        r[k] = r0[k] + v[k] * dt + 0.5 * g[k] * dt * dt;
        w[k] = v[k] + g[k] * dt;
    }
    const double dx = r[0] - o[0], dy = r[1] - o[1], dz = r[2] - o[2];
    const double dd = dx * dx + dy * dy + dz * dz;
    if (dd <= radius * radius) return PyFloat_FromDouble(t);
    const double gx = g[0], gy = g[1], gz = g[2], vx = w[0], vy = w[1], vz = w[2];
    const double c[5] = {
        0.25 * (gx * gx + gy * gy + gz * gz),
        vx * gx + vy * gy + vz * gz,
        (vx * vx + vy * vy + vz * vz) + (dx * gx + dy * gy + dz * gz),
        2.0 * (dx * vx + dy * vy + dz * vz),
        dd - radius * radius,
    };
    double s;
    if (first_root_newton(c, &s)) return PyFloat_FromDouble(t + s);
    Py_RETURN_NONE;
}

static PyMethodDef methods[] = {
    {"time_to_radius", py_time_to_radius, METH_VARARGS,
     "the fitted arc's first time on a sphere, by Newton's method"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_ballistic",
                                    "The ballistic estimator's time to the catch surface.", -1,
                                    methods};

PyMODINIT_FUNC PyInit__ballistic(void) { return PyModule_Create(&module); }
