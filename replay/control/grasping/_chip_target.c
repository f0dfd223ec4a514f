/* The recognition task's per-frame kernels. ``target_blob``: one pass over the chip's packed
 * rows (bit u of rows[v] = pixel (u, v)), Self Windowing and the target's features; the Python
 * versions are the reference (replay/control/grasping/self_window.py track_rows, features.py
 * blob_rows, which document the algorithms; tests hold them equal): the same integer sums, the
 * same float operations in the same order, the same libm functions. ``plane_geometry``: the
 * target's point on the constraint plane, its axis there and the head's image Jacobian, with
 * recognition.py's Camera (NumPy) as the reference. Plain C: no NumPy headers.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>

#define MAXROWS 64
#define MAXDIRS 64

static int read_rows(PyObject *obj, uint64_t *out, Py_ssize_t *n, const char *what) {
    PyObject *seq = PySequence_Fast(obj, what);
    if (seq == NULL) return -1;
    Py_ssize_t m = PySequence_Fast_GET_SIZE(seq);
    if (m > MAXROWS) {
        PyErr_Format(PyExc_ValueError, "%s: at most %d rows", what, MAXROWS);
        Py_DECREF(seq);
        return -1;
    }
    PyObject **items = PySequence_Fast_ITEMS(seq);
    for (Py_ssize_t i = 0; i < m; i++) {
        out[i] = PyLong_AsUnsignedLongLong(items[i]);
        if (out[i] == (uint64_t)-1 && PyErr_Occurred()) {
            Py_DECREF(seq);
            return -1;
        }
    }
    *n = m;
    Py_DECREF(seq);
    return 0;
}

/* target_blob(previous, rows, width, fill, dirs) -> (target rows, reacquired, features): the
 * Self Windowing of track_rows, then blob_rows' features of the target: None when it is empty,
 * else (area, u, v, phi, elongation, length, width, fill, touches_border), fill NaN unless
 * ``fill``. previous: None or as many rows as ``rows``; width <= 63; dirs: float64 triples
 * (cos, sin, a pixel's extent) of the bounding boxes' directions. */
static PyObject *py_target_blob(PyObject *self, PyObject *args) {
    PyObject *prev_o, *rows_o, *dirs_o;
    int width, want_fill;
    if (!PyArg_ParseTuple(args, "OOipO", &prev_o, &rows_o, &width, &want_fill, &dirs_o))
        return NULL;
    if (width < 1 || width > 63) {
        PyErr_SetString(PyExc_ValueError, "target_blob: width 1..63");
        return NULL;
    }
    uint64_t rows[MAXROWS], prev[MAXROWS], t[MAXROWS];
    Py_ssize_t h, hp = 0;
    if (read_rows(rows_o, rows, &h, "target_blob: rows") < 0) return NULL;
    int any_prev = 0;
    if (prev_o != Py_None) {
        if (read_rows(prev_o, prev, &hp, "target_blob: previous") < 0) return NULL;
        for (Py_ssize_t v = 0; v < hp; v++) any_prev |= prev[v] != 0;
        if (any_prev && hp != h) {
            PyErr_SetString(PyExc_ValueError, "target_blob: previous and rows differ in height");
            return NULL;
        }
    }
    const uint64_t mask = (((uint64_t)1) << width) - 1;
    for (Py_ssize_t v = 0; v < h; v++) {
        if (!any_prev) {
            t[v] = rows[v];
        } else {
            const uint64_t p = prev[v], a = v > 0 ? prev[v - 1] : 0, b = v + 1 < h ? prev[v + 1] : 0;
            t[v] = (p | p << 1 | p >> 1 | a | b) & mask & rows[v];
        }
    }
    PyObject *target = PyList_New(h);
    if (target == NULL) return NULL;
    for (Py_ssize_t v = 0; v < h; v++) {
        PyObject *x = PyLong_FromUnsignedLongLong(t[v]);
        if (x == NULL) {
            Py_DECREF(target);
            return NULL;
        }
        PyList_SET_ITEM(target, v, x);
    }
    /* the moments as exact integer sums; each non-empty row's first and last pixel */
    long long n = 0, su = 0, sv = 0, suu = 0, svv = 0, suv = 0;
    uint64_t ors = 0;
    int ev[MAXROWS], elo[MAXROWS], ehi[MAXROWS], ne = 0;
    for (Py_ssize_t v = 0; v < h; v++) {
        uint64_t r = t[v];
        if (!r) continue;
        long long c = 0, s = 0, q = 0;
        for (uint64_t x = r; x; x &= x - 1) {
            const long long u = __builtin_ctzll(x);
            c += 1;
            s += u;
            q += u * u;
        }
        n += c;
        su += s;
        suu += q;
        sv += v * c;
        svv += (long long)v * v * c;
        suv += v * s;
        ors |= r;
        ev[ne] = (int)v;
        elo[ne] = __builtin_ctzll(r);
        ehi[ne] = 63 - __builtin_clzll(r);
        ne++;
    }
    PyObject *reacquired = any_prev ? Py_False : Py_True;
    if (n == 0) return Py_BuildValue("(NOO)", target, reacquired, Py_None);
    Py_buffer vd;
    if (PyObject_GetBuffer(dirs_o, &vd, PyBUF_C_CONTIGUOUS) < 0) {
        Py_DECREF(target);
        return NULL;
    }
    const double *dirs = vd.buf;
    Py_ssize_t nd = vd.len / (Py_ssize_t)(3 * sizeof(double));
    if (nd > MAXDIRS) nd = MAXDIRS;
    const double u0 = (double)su / (double)n, v0 = (double)sv / (double)n;
    const double nn = (double)(n * n);
    const double mu20 = (double)(n * suu - su * su) / nn, mu02 = (double)(n * svv - sv * sv) / nn,
                 mu11 = (double)(n * suv - su * sv) / nn;
    const double phi = 0.5 * atan2(2.0 * mu11, mu20 - mu02);
    const double mean = 0.5 * (mu20 + mu02), rad = hypot(0.5 * (mu20 - mu02), mu11);
    const double lam1 = mean + rad + 1.0 / 12.0, lam2 = mean - rad + 1.0 / 12.0;
    const double c = cos(phi), s = sin(phi);
    double pu[2 * MAXROWS], pv[2 * MAXROWS];
    int np = 0;
    for (int i = 0; i < ne; i++) {
        const double dv = ev[i] - v0;
        pu[np] = elo[i] - u0, pv[np] = dv, np++;
        if (ehi[i] != elo[i]) pu[np] = ehi[i] - u0, pv[np] = dv, np++;
    }
    double amax = -INFINITY, amin = INFINITY, cmax = -INFINITY, cmin = INFINITY;
    for (int i = 0; i < np; i++) {
        const double a = pu[i] * c + pv[i] * s, b = -pu[i] * s + pv[i] * c;
        if (a > amax) amax = a;
        if (a < amin) amin = a;
        if (b > cmax) cmax = b;
        if (b < cmin) cmin = b;
    }
    const double ext = fabs(c) + fabs(s);
    double fill = NAN;
    if (want_fill) {
        double best = INFINITY;
        for (Py_ssize_t k = 0; k < nd; k++) {
            const double dc = dirs[3 * k], ds = dirs[3 * k + 1], e = dirs[3 * k + 2];
            double xmax = -INFINITY, xmin = INFINITY, ymax = -INFINITY, ymin = INFINITY;
            for (int i = 0; i < np; i++) {
                const double a = pu[i] * dc + pv[i] * ds, b = pu[i] * -ds + pv[i] * dc;
                if (a > xmax) xmax = a;
                if (a < xmin) xmin = a;
                if (b > ymax) ymax = b;
                if (b < ymin) ymin = b;
            }
            const double box = (xmax - xmin + e) * (ymax - ymin + e);
            if (box < best) best = box;
        }
        fill = (double)n / best;
    }
    PyBuffer_Release(&vd);
    const int border = (ors & 1) || ((ors >> (width - 1)) & 1) || ev[0] == 0 || ev[ne - 1] == h - 1;
    return Py_BuildValue("(NO(LdddddddO))", target, reacquired, n, u0, v0, phi,
                         sqrt(lam1 / (lam2 > 1e-12 ? lam2 : 1e-12)), amax - amin + ext,
                         cmax - cmin + ext, fill, border ? Py_True : Py_False);
}

/* the ray through pixel (x, y) of the camera (R row-major, centre o) meets the plane n . X =
 * n . P where s > 0 along it: recognition.py's Camera.ray + meet_plane. po = n . (P - o). */
static int on_plane(const double *R, const double *o, const double *n, double po, double f,
                    double cx, double cy, double x, double y, double *X) {
    x = (x - cx) / f, y = (y - cy) / f;
    const double d0 = R[0] * x + R[1] * y + R[2], d1 = R[3] * x + R[4] * y + R[5],
                 d2 = R[6] * x + R[7] * y + R[8];
    const double denom = d0 * n[0] + d1 * n[1] + d2 * n[2];
    if (fabs(denom) < 1e-12) return 0;
    const double s = po / denom;
    if (!(s > 0.0)) return 0;
    X[0] = o[0] + s * d0, X[1] = o[1] + s * d1, X[2] = o[2] + s * d2;
    return 1;
}

/* plane_geometry(yaw, pan, tilt, head, offset, f, cx, cy, P, n, pu, pv, u, v, phi) -> None
 * (the ray through (u, v) misses the plane) or (X0, X1, X2, axis, distance, J00, J01, J10, J11):
 * the camera pose of replay.robot.head.camera_pose at (pan, tilt); X where the ray through the
 * target's centre (u, v) meets the constraint plane (point P, unit normal n); axis =
 * atan2(e . pv, e . pu) of e = X' - X, X' that of (u + cos phi, v + sin phi) (NaN if it misses);
 * distance = |X - o|; J = d (u, v) / d (pan, tilt) of X (Camera.jacobian: the point in the camera
 * frame moves by -R^T (k x (X - h)) per radian about k = z and k = (-sin a, cos a, 0)). */
static PyObject *py_plane_geometry(PyObject *self, PyObject *args) {
    double yaw, pan, tilt, off, f, cx, cy, u, v, phi, h[3], P[3], n[3], pu[3], pv[3];
    if (!PyArg_ParseTuple(args, "ddd(ddd)dddd(ddd)(ddd)(ddd)(ddd)ddd", &yaw, &pan, &tilt, &h[0],
                          &h[1], &h[2], &off, &f, &cx, &cy, &P[0], &P[1], &P[2], &n[0], &n[1],
                          &n[2], &pu[0], &pu[1], &pu[2], &pv[0], &pv[1], &pv[2], &u, &v, &phi))
        return NULL;
    const double a = yaw + pan, ca = cos(a), sa = sin(a), ct = cos(tilt), st = sin(tilt);
    const double R[9] = {sa, -st * ca, ca * ct, -ca, -st * sa, sa * ct, 0.0, -ct, -st};
    const double o[3] = {h[0] + off * ca * ct, h[1] + off * sa * ct, h[2] - off * st};
    const double po = (P[0] - o[0]) * n[0] + (P[1] - o[1]) * n[1] + (P[2] - o[2]) * n[2];
    double X[3], X2[3];
    if (!on_plane(R, o, n, po, f, cx, cy, u, v, X)) Py_RETURN_NONE;
    double axis = NAN;
    if (on_plane(R, o, n, po, f, cx, cy, u + cos(phi), v + sin(phi), X2)) {
        const double e0 = X2[0] - X[0], e1 = X2[1] - X[1], e2 = X2[2] - X[2];
        axis = atan2(e0 * pv[0] + e1 * pv[1] + e2 * pv[2], e0 * pu[0] + e1 * pu[1] + e2 * pu[2]);
    }
    const double w0 = X[0] - o[0], w1 = X[1] - o[1], w2 = X[2] - o[2];
    const double dist = sqrt(w0 * w0 + w1 * w1 + w2 * w2);
    double pc[3];
    for (int i = 0; i < 3; i++) pc[i] = R[i] * w0 + R[3 + i] * w1 + R[6 + i] * w2;
    const double r0 = X[0] - h[0], r1 = X[1] - h[1], r2 = X[2] - h[2];
    const double ks[2][3] = {{0.0, 0.0, 1.0}, {-sa, ca, 0.0}};
    double J[2][2];
    const double z2 = pc[2] * pc[2];
    for (int i = 0; i < 2; i++) {
        const double k0 = ks[i][0], k1 = ks[i][1], k2 = ks[i][2];
        const double kx0 = k1 * r2 - k2 * r1, kx1 = k2 * r0 - k0 * r2, kx2 = k0 * r1 - k1 * r0;
        double d[3];
        for (int j = 0; j < 3; j++) d[j] = -(R[j] * kx0 + R[3 + j] * kx1 + R[6 + j] * kx2);
        J[0][i] = f * (d[0] * pc[2] - pc[0] * d[2]) / z2;
        J[1][i] = f * (d[1] * pc[2] - pc[1] * d[2]) / z2;
    }
    return Py_BuildValue("(ddddddddd)", X[0], X[1], X[2], axis, dist, J[0][0], J[0][1], J[1][0],
                         J[1][1]);
}

static PyMethodDef methods[] = {
    {"target_blob", py_target_blob, METH_VARARGS, "Self Windowing and the target's features"},
    {"plane_geometry", py_plane_geometry, METH_VARARGS, "x_o on the plane and the image Jacobian"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_chip_target",
                                    "The recognition task's per-frame kernels.",
                                    -1, methods};

PyMODINIT_FUNC PyInit__chip_target(void) { return PyModule_Create(&module); }
