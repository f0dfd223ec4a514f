/* A sphere's silhouette polygon through a pinhole, compiled: replay/sensors/silhouette.py
 * sphere_ellipse followed by Ellipse.polygon_and_box (the same operations in the same order but
 * libm's hypot for Python's own math.hypot: equal to 1e-12 px; that Python path is kept as the
 * reference, tests/replay/sensors/test_fast_cameras.py holds them together). Plain C over the
 * buffer protocol: no NumPy headers.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>

#include "_ellipse.h"

/* The sphere of centre (x, y, z) (world) and radius seen by the camera at o (3) with
 * camera-to-world rotation R (3 x 3, row-major) and intrinsics fx, fy, cx, cy: its outline as the
 * n-gon of the tables ct, st with both semi-axes times scale into out (2n), its box into box (4).
 * 0 when the sphere is not entirely in front of the camera's plane (Z <= r), else 1. */
static int sphere_outline(const double *R, const double *o, double fx, double fy, double cx,
                          double cy, double x, double y, double z, double radius,
                          const double *ct, const double *st, Py_ssize_t n, double scale,
                          double *out, double *box) {
    double dx = x - o[0], dy = y - o[1], dz = z - o[2];
    double X = R[0] * dx + R[3] * dy + R[6] * dz; /* p_cam = R^T (p - o) */
    double Y = R[1] * dx + R[4] * dy + R[7] * dz;
    double Z = R[2] * dx + R[5] * dy + R[8] * dz;
    double r2 = radius * radius;
    double E = Z * Z - r2;
    if (radius <= 0.0 || Z <= radius * (1.0 + 1e-9) || E <= 0.0) return 0;
    double D = E + X * X + Y * Y;
    /* B in pixels: S^-1 B_n S^-1 with S = diag(fx, fy) */
    double g = E / r2;
    double baa = g * (1.0 - X * X / D) / (fx * fx);
    double bdd = g * (1.0 - Y * Y / D) / (fy * fy);
    double bh = -g * X * Y / (D * fx * fy);
    double mean = 0.5 * (baa + bdd);
    double rad = hypot(0.5 * (baa - bdd), bh);
    double lam_small = mean - rad, lam_big = mean + rad; /* semi-axes 1/sqrt(lambda) */
    double angle = 0.5 * atan2(2.0 * bh, baa - bdd) + 0.5 * M_PI; /* axis of lam_small */
    double u = fx * X * Z / E + cx, v = fy * Y * Z / E + cy;
    double a = 1.0 / sqrt(lam_small), b = 1.0 / sqrt(lam_big);
    angle = atan2(sin(angle), cos(angle));
    /* Ellipse.polygon_and_box(inset = 0, area_exact): semi-axes max(a, 0.05 a) * scale */
    a = (a > 0.05 * a ? a : 0.05 * a) * scale;
    b = (b > 0.05 * b ? b : 0.05 * b) * scale;
    ellipse_ngon(ct, st, n, u, v, a, b, cos(angle), sin(angle), out, box);
    return 1;
}

/* sphere_polygon(R, o, fx, fy, cx, cy, x, y, z, radius, cos, sin, scale, out): the exact
 * perspective outline of the sphere of centre (x, y, z) (world) and radius, seen by the camera
 * at o (float64 3) with camera-to-world rotation R (float64 3 x 3, row-major), as the N-gon of
 * the tables cos, sin (float64 N each) with both semi-axes times scale written to out (float64
 * (N, 2)); returns its box (umin, vmin, umax, vmax), or None when the sphere is not entirely in
 * front of the camera's plane (Z <= r). */
static PyObject *py_sphere_polygon(PyObject *self, PyObject *args) {
    Py_buffer Rb, Ob, Cb, Sb, Out;
    double fx, fy, cx, cy, x, y, z, radius, scale;
    if (!PyArg_ParseTuple(args, "y*y*ddddddddy*y*dw*", &Rb, &Ob, &fx, &fy, &cx, &cy, &x, &y, &z,
                          &radius, &Cb, &Sb, &scale, &Out))
        return NULL;
    PyObject *ret = NULL;
    Py_ssize_t n = Cb.len / (Py_ssize_t)sizeof(double);
    if (Rb.len != 9 * (Py_ssize_t)sizeof(double) || Ob.len != 3 * (Py_ssize_t)sizeof(double) ||
        Sb.len != Cb.len || Out.len != 2 * Cb.len) {
        PyErr_SetString(PyExc_ValueError, "R: float64 9, o: 3, cos and sin: N, out: (N, 2)");
        goto done;
    }
    double box[4];
    if (sphere_outline(Rb.buf, Ob.buf, fx, fy, cx, cy, x, y, z, radius, Cb.buf, Sb.buf, n, scale,
                       Out.buf, box)) {
        ret = Py_BuildValue("(dddd)", box[0], box[1], box[2], box[3]);
    } else {
        Py_INCREF(Py_None);
        ret = Py_None;
    }
done:
    PyBuffer_Release(&Rb);
    PyBuffer_Release(&Ob);
    PyBuffer_Release(&Cb);
    PyBuffer_Release(&Sb);
    PyBuffer_Release(&Out);
    return ret;
}

static PyMethodDef silhouette_methods[] = {
    {"sphere_polygon", py_sphere_polygon, METH_VARARGS, "a sphere's silhouette polygon and box"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef silhouette_module = {PyModuleDef_HEAD_INIT, "_silhouette",
                                               "A sphere's silhouette polygon, compiled.", -1,
                                               silhouette_methods};

PyMODINIT_FUNC PyInit__silhouette(void) { return PyModule_Create(&silhouette_module); }
