/* The stick estimator's running least-squares sums and fit (replay/control/stick/estimator.py
 * StickEstimator._sum and _refit), compiled: the same operations in the same order, so the fit
 * is the Python one's to the bit (its reference: StickEstimator._sum_reference and
 * _refit_reference, tests/replay/control/stick/test_fit_kernel.py). Plain C over the buffer
 * protocol, no NumPy headers.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>

static int sums_of(PyObject *obj, Py_buffer *b) {
    if (PyObject_GetBuffer(obj, b, PyBUF_WRITABLE | PyBUF_C_CONTIGUOUS) < 0) return 0;
    if (b->len != 12 * (Py_ssize_t)sizeof(double)) {
        PyBuffer_Release(b);
        PyErr_SetString(PyExc_ValueError, "sums: 12 float64");
        return 0;
    }
    return 1;
}

/* add(sums, anchor, sample, sign): StickEstimator._sum: the sample (t, x, y, theta) relative to
 * the anchor, its count, t, t^2 and each value's v, t v, v^2 added to sums times sign. */
static PyObject *py_add(PyObject *self, PyObject *args) {
    PyObject *sums;
    double t0, x0, y0, th0, ts, xs, ys, ths, sign;
    if (!PyArg_ParseTuple(args, "O(dddd)(dddd)d", &sums, &t0, &x0, &y0, &th0, &ts, &xs, &ys,
                          &ths, &sign))
        return NULL;
    Py_buffer b;
    if (!sums_of(sums, &b)) return NULL;
    double *s = b.buf, t = ts - t0, v;
    s[0] += sign;
    s[1] += sign * t;
    s[2] += sign * t * t;
    v = xs - x0;
    s[3] += sign * v;
    s[4] += sign * t * v;
    s[5] += sign * v * v;
    v = ys - y0;
    s[6] += sign * v;
    s[7] += sign * t * v;
    s[8] += sign * v * v;
    v = ths - th0;
    s[9] += sign * v;
    s[10] += sign * t * v;
    s[11] += sign * v * v;
    PyBuffer_Release(&b);
    Py_RETURN_NONE;
}

/* fit(sums, anchor, n, t_ref): StickEstimator._refit for n >= 2 samples: (x, vx, y, vy, theta,
 * omega, rms_xy, rms_theta) of the least squares value at t_ref + rate (t - t_ref). */
static PyObject *py_fit(PyObject *self, PyObject *args) {
    PyObject *sums;
    double a[4], t_ref;
    Py_ssize_t n_samples;
    if (!PyArg_ParseTuple(args, "O(dddd)nd", &sums, &a[0], &a[1], &a[2], &a[3], &n_samples,
                          &t_ref))
        return NULL;
    Py_buffer b;
    if (!sums_of(sums, &b)) return NULL;
    const double *s = b.buf, n = (double)n_samples;
    double tm = s[1] / n, s_tt = s[2] - s[1] * tm, dt_ref = (t_ref - a[0]) - tm, out[9];
    for (int k = 0; k < 3; k++) {
        int i = 3 + 3 * k;
        double vm = s[i] / n, s_tv = s[i + 1] - s[1] * vm;
        double rate = s_tt > 0.0 ? s_tv / s_tt : 0.0;
        double rss = s[i + 2] - s[i] * vm - rate * s_tv;
        if (0.0 > rss) rss = 0.0; /* max(rss, 0.0) as Python's max */
        out[3 * k] = a[1 + k] + vm + rate * dt_ref;
        out[3 * k + 1] = rate;
        out[3 * k + 2] = rss;
    }
    PyBuffer_Release(&b);
    return Py_BuildValue("(dddddddd)", out[0], out[1], out[3], out[4], out[6], out[7],
                         sqrt((out[2] + out[5]) / n), sqrt(out[8] / n));
}

static PyMethodDef fit_methods[] = {
    {"add", py_add, METH_VARARGS, "a sample into the estimator's running sums"},
    {"fit", py_fit, METH_VARARGS, "the estimator's fit from its running sums"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef fit_module = {PyModuleDef_HEAD_INIT, "_fit",
                                        "The stick estimator's running sums and fit.", -1,
                                        fit_methods};

PyMODINIT_FUNC PyInit__fit(void) { return PyModule_Create(&fit_module); }
