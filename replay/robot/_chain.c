/* One configuration of a revolute serial chain, compiled: the frames, a point's position and the
 * recursive Newton-Euler inverse dynamics of replay/robot/serial_chain.py (SerialChain._frames_f,
 * point and rnea_floats are the same operations in the same order, kept there as the reference;
 * tests/replay/robot/test_chain_compiled.py holds them together). Plain C over the buffer
 * protocol: no NumPy headers.
 *
 * rows: float64, 18 a joint: (cos alpha, sin alpha, a, d, theta offset, mass, com (3, frame i),
 * inertia about the com (3 x 3, row-major, frame i axes)); base: float64 12: the world axes
 * X, Y, Z and origin of frame 0. Standard (Spong) DH: T_i = T_{i-1} Rz(q_i + offset) Tz(d) Tx(a)
 * Rx(alpha).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>

#include "_pyfloats.h"

#define ROW 18
#define MAXJ 16

typedef struct {
    double X[3], Y[3], Z[3], o[3];
} Frame;

/* frames 0..n of configuration q (F: n + 1 frames) */
static void frames(const double *rows, const double *base, int n, const double *q, Frame *F) {
    double xx = base[0], xy = base[1], xz = base[2], yx = base[3], yy = base[4], yz = base[5];
    double zx = base[6], zy = base[7], zz = base[8], px = base[9], py = base[10], pz = base[11];
    for (int k = 0; k < 3; k++) {
        F[0].X[k] = base[k], F[0].Y[k] = base[3 + k], F[0].Z[k] = base[6 + k];
        F[0].o[k] = base[9 + k];
    }
    for (int i = 0; i < n; i++) {
        const double *r = rows + (size_t)i * ROW;
        double ca = r[0], sa = r[1], a = r[2], d = r[3], off = r[4];
        double th = q[i] + off, ct = cos(th), st = sin(th);
        double x1x = ct * xx + st * yx, x1y = ct * xy + st * yy, x1z = ct * xz + st * yz;
        double y1x = ct * yx - st * xx, y1y = ct * yy - st * xy, y1z = ct * yz - st * xz;
        px = px + d * zx + a * x1x, py = py + d * zy + a * x1y, pz = pz + d * zz + a * x1z;
        double nyx = ca * y1x + sa * zx, nyy = ca * y1y + sa * zy, nyz = ca * y1z + sa * zz;
        double nzx = ca * zx - sa * y1x, nzy = ca * zy - sa * y1y, nzz = ca * zz - sa * y1z;
        yx = nyx, yy = nyy, yz = nyz, zx = nzx, zy = nzy, zz = nzz;
        xx = x1x, xy = x1y, xz = x1z;
        Frame *f = &F[i + 1];
        f->X[0] = xx, f->X[1] = xy, f->X[2] = xz;
        f->Y[0] = yx, f->Y[1] = yy, f->Y[2] = yz;
        f->Z[0] = zx, f->Z[1] = zy, f->Z[2] = zz;
        f->o[0] = px, f->o[1] = py, f->o[2] = pz;
    }
}

/* the chain's rows and base buffers; n joints, 0 with an exception set if they do not fit */
static int chain_of(Py_buffer *R, Py_buffer *B, int *n) {
    if (R->len % (ROW * (Py_ssize_t)sizeof(double)) || R->len / (ROW * sizeof(double)) > MAXJ ||
        B->len != 12 * (Py_ssize_t)sizeof(double)) {
        PyErr_SetString(PyExc_ValueError, "rows: float64 18 a joint (at most 16); base: 12");
        return 0;
    }
    *n = (int)(R->len / (ROW * (Py_ssize_t)sizeof(double)));
    return 1;
}

/* point(rows, base, q, p): world position of the point p (3 floats, last DH frame) at q. */
static PyObject *py_point(PyObject *self, PyObject *args) {
    Py_buffer R, B;
    PyObject *qo;
    double u, v, w;
    if (!PyArg_ParseTuple(args, "y*y*O(ddd)", &R, &B, &qo, &u, &v, &w)) return NULL;
    PyObject *ret = NULL;
    int n;
    double q[MAXJ];
    Frame F[MAXJ + 1];
    if (!chain_of(&R, &B, &n) || !seq_doubles(qo, q, n, "joint values", "q")) goto done;
    frames(R.buf, B.buf, n, q, F);
    const Frame *f = &F[n];
    ret = Py_BuildValue("(ddd)", f->o[0] + u * f->X[0] + v * f->Y[0] + w * f->Z[0],
                        f->o[1] + u * f->X[1] + v * f->Y[1] + w * f->Z[1],
                        f->o[2] + u * f->X[2] + v * f->Y[2] + w * f->Z[2]);
done:
    PyBuffer_Release(&R);
    PyBuffer_Release(&B);
    return ret;
}

/* rnea(rows, base, q, qd, qdd, g): tau = M qdd + H qd + g(q) (n floats), gravity g (3 floats):
 * SerialChain.rnea_floats' recursion (world coordinates, the inertia applied as R I R^T v). */
static PyObject *py_rnea(PyObject *self, PyObject *args) {
    Py_buffer R, B;
    PyObject *qo, *qdo, *qddo;
    double gx, gy, gz;
    if (!PyArg_ParseTuple(args, "y*y*OOO(ddd)", &R, &B, &qo, &qdo, &qddo, &gx, &gy, &gz))
        return NULL;
    PyObject *ret = NULL;
    int n;
    double q[MAXJ], qd[MAXJ], qdd[MAXJ], fw[MAXJ][12];
    Frame F[MAXJ + 1];
    if (!chain_of(&R, &B, &n) ||
        !seq_doubles(qo, q, n, "joint values", "q") ||
        !seq_doubles(qdo, qd, n, "joint values", "qd") ||
        !seq_doubles(qddo, qdd, n, "joint values", "qdd"))
        goto done;
    const double *rows = R.buf;
    frames(rows, B.buf, n, q, F);
    double wx = 0.0, wy = 0.0, wz = 0.0, dwx = 0.0, dwy = 0.0, dwz = 0.0;
    double ax = -gx, ay = -gy, az = -gz; /* acceleration of o_{i-1} */
    for (int i = 0; i < n; i++) {
        const double qdi = qd[i], qddi = qdd[i];
        const double zx = F[i].Z[0], zy = F[i].Z[1], zz = F[i].Z[2];
        const double ox = F[i].o[0], oy = F[i].o[1], oz = F[i].o[2];
        const double *X = F[i + 1].X, *Y = F[i + 1].Y, *Z = F[i + 1].Z;
        const double o1x = F[i + 1].o[0], o1y = F[i + 1].o[1], o1z = F[i + 1].o[2];
        const double *row = rows + (size_t)i * ROW;
        const double c0 = row[6], c1 = row[7], c2 = row[8];
        double cx = o1x + c0 * X[0] + c1 * Y[0] + c2 * Z[0];
        double cy = o1y + c0 * X[1] + c1 * Y[1] + c2 * Z[1];
        double cz = o1z + c0 * X[2] + c1 * Y[2] + c2 * Z[2];
        double zqx = zx * qdi, zqy = zy * qdi, zqz = zz * qdi;
        dwx += zx * qddi + wy * zqz - wz * zqy;
        dwy += zy * qddi + wz * zqx - wx * zqz;
        dwz += zz * qddi + wx * zqy - wy * zqx;
        wx = wx + zqx, wy = wy + zqy, wz = wz + zqz;
        double rx = cx - ox, ry = cy - oy, rz = cz - oz;
        double ux = wy * rz - wz * ry, uy = wz * rx - wx * rz, uz = wx * ry - wy * rx;
        double acx = ax + dwy * rz - dwz * ry + wy * uz - wz * uy;
        double acy = ay + dwz * rx - dwx * rz + wz * ux - wx * uz;
        double acz = az + dwx * ry - dwy * rx + wx * uy - wy * ux;
        rx = o1x - ox, ry = o1y - oy, rz = o1z - oz;
        ux = wy * rz - wz * ry, uy = wz * rx - wx * rz, uz = wx * ry - wy * rx;
        ax += dwy * rz - dwz * ry + wy * uz - wz * uy;
        ay += dwz * rx - dwx * rz + wz * ux - wx * uz;
        az += dwx * ry - dwy * rx + wx * uy - wy * ux;
        double *f = fw[i];
        f[0] = cx, f[1] = cy, f[2] = cz, f[3] = acx, f[4] = acy, f[5] = acz;
        f[6] = wx, f[7] = wy, f[8] = wz, f[9] = dwx, f[10] = dwy, f[11] = dwz;
    }
    double tau[MAXJ];
    double fx = 0.0, fy = 0.0, fz = 0.0, nx = 0.0, ny = 0.0, nz = 0.0;
    for (int i = n - 1; i >= 0; i--) {
        const double *f = fw[i];
        const double cx = f[0], cy = f[1], cz = f[2], acx = f[3], acy = f[4], acz = f[5];
        const double wx_ = f[6], wy_ = f[7], wz_ = f[8], dwx_ = f[9], dwy_ = f[10], dwz_ = f[11];
        const double zx = F[i].Z[0], zy = F[i].Z[1], zz = F[i].Z[2];
        const double ox = F[i].o[0], oy = F[i].o[1], oz = F[i].o[2];
        const double *X = F[i + 1].X, *Y = F[i + 1].Y, *Z = F[i + 1].Z;
        const double o1x = F[i + 1].o[0], o1y = F[i + 1].o[1], o1z = F[i + 1].o[2];
        const double *row = rows + (size_t)i * ROW;
        const double m = row[5], *I = row + 9;
        double lw0 = X[0] * wx_ + X[1] * wy_ + X[2] * wz_;
        double lw1 = Y[0] * wx_ + Y[1] * wy_ + Y[2] * wz_;
        double lw2 = Z[0] * wx_ + Z[1] * wy_ + Z[2] * wz_;
        double ld0 = X[0] * dwx_ + X[1] * dwy_ + X[2] * dwz_;
        double ld1 = Y[0] * dwx_ + Y[1] * dwy_ + Y[2] * dwz_;
        double ld2 = Z[0] * dwx_ + Z[1] * dwy_ + Z[2] * dwz_;
        double u0 = I[0] * lw0 + I[1] * lw1 + I[2] * lw2;
        double u1 = I[3] * lw0 + I[4] * lw1 + I[5] * lw2;
        double u2 = I[6] * lw0 + I[7] * lw1 + I[8] * lw2;
        double e0 = I[0] * ld0 + I[1] * ld1 + I[2] * ld2;
        double e1 = I[3] * ld0 + I[4] * ld1 + I[5] * ld2;
        double e2 = I[6] * ld0 + I[7] * ld1 + I[8] * ld2;
        double Iwx = u0 * X[0] + u1 * Y[0] + u2 * Z[0];
        double Iwy = u0 * X[1] + u1 * Y[1] + u2 * Z[1];
        double Iwz = u0 * X[2] + u1 * Y[2] + u2 * Z[2];
        double Idx = e0 * X[0] + e1 * Y[0] + e2 * Z[0];
        double Idy = e0 * X[1] + e1 * Y[1] + e2 * Z[1];
        double Idz = e0 * X[2] + e1 * Y[2] + e2 * Z[2];
        double max_ = m * acx, may = m * acy, maz = m * acz;
        double rcx = cx - ox, rcy = cy - oy, rcz = cz - oz;
        double rx = o1x - ox, ry = o1y - oy, rz = o1z - oz;
        double nnx = Idx + wy_ * Iwz - wz_ * Iwy + rcy * maz - rcz * may + nx + ry * fz - rz * fy;
        double nny = Idy + wz_ * Iwx - wx_ * Iwz + rcz * max_ - rcx * maz + ny + rz * fx - rx * fz;
        double nnz = Idz + wx_ * Iwy - wy_ * Iwx + rcx * may - rcy * max_ + nz + rx * fy - ry * fx;
        nx = nnx, ny = nny, nz = nnz;
        fx = max_ + fx, fy = may + fy, fz = maz + fz;
        tau[i] = zx * nx + zy * ny + zz * nz;
    }
    ret = PyTuple_New(n);
    if (!ret) goto done;
    for (int i = 0; i < n; i++) {
        PyObject *v = PyFloat_FromDouble(tau[i]);
        if (!v) {
            Py_CLEAR(ret);
            goto done;
        }
        PyTuple_SET_ITEM(ret, i, v);
    }
done:
    PyBuffer_Release(&R);
    PyBuffer_Release(&B);
    return ret;
}

static PyMethodDef methods[] = {
    {"point", py_point, METH_VARARGS, "world position of a point of the last frame"},
    {"rnea", py_rnea, METH_VARARGS, "recursive Newton-Euler inverse dynamics"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_chain",
                                    "One configuration of a serial chain, compiled.", -1,
                                    methods};

PyMODINIT_FUNC PyInit__chain(void) { return PyModule_Create(&module); }
