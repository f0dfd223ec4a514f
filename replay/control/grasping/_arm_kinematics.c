/* The arm task's per-step linear algebra (replay/control/grasping/arm_control.py documents it;
 * that module is the only caller and keeps the NumPy version as the reference): the DH chain's
 * forward kinematics and geometric Jacobian, the grasp point's Jacobian (``chain``), and eq. 2's
 * terms: the damped pseudo-inverse applied to its two task vectors, the damping, J^T F and the
 * clipped sum (``terms``); F^a from the wrist sensor (``wrench``). Plain C over the buffer
 * protocol and sequences of floats: no NumPy headers.
 *
 * Matrices are row-major float64. The chain's constants are n rows of (cos alpha, sin alpha, a,
 * d, theta offset); base and tool are 4 x 4 rigid transforms (last row 0 0 0 1).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <string.h>

#include "_pyfloats.h"

#define MAXJ 16

static int get_buffer(PyObject *obj, Py_buffer *view, Py_ssize_t n, int writable, const char *what) {
    if (PyObject_GetBuffer(obj, view, PyBUF_C_CONTIGUOUS | (writable ? PyBUF_WRITABLE : 0)) < 0)
        return -1;
    if (view->len < n * (Py_ssize_t)sizeof(double)) {
        PyErr_Format(PyExc_ValueError, "%s: expected %zd float64 values", what, n);
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

/* T (3 x 4 of a rigid transform) = A B */
static void affine_mul(const double *A, const double *B, double *T) {
    for (int r = 0; r < 3; r++) {
        const double a0 = A[4 * r], a1 = A[4 * r + 1], a2 = A[4 * r + 2], a3 = A[4 * r + 3];
        T[4 * r] = a0 * B[0] + a1 * B[4] + a2 * B[8];
        T[4 * r + 1] = a0 * B[1] + a1 * B[5] + a2 * B[9];
        T[4 * r + 2] = a0 * B[2] + a1 * B[6] + a2 * B[10];
        T[4 * r + 3] = a0 * B[3] + a1 * B[7] + a2 * B[11] + a3;
    }
}

/* chain(q, n, consts, base, tool, grasp_point, J, Jg) -> (R00..R22, p0..p2, g0..g2): the tool
 * pose (R row-major, p), the grasp point g = p + grasp_point R[:, 2]; writes the tool's 6 x n
 * geometric Jacobian J (rows vx vy vz wx wy wz) and the grasp point's Jg (v_g = v + w x (g - p)). */
static PyObject *py_chain(PyObject *self, PyObject *args) {
    PyObject *qo, *co, *bo, *to, *jo, *jgo;
    Py_ssize_t n;
    double gp;
    if (!PyArg_ParseTuple(args, "OnOOOdOO", &qo, &n, &co, &bo, &to, &gp, &jo, &jgo)) return NULL;
    if (n < 1 || n > MAXJ) {
        PyErr_SetString(PyExc_ValueError, "chain: 1..16 joints");
        return NULL;
    }
    double q[MAXJ];
    if (!seq_doubles_head(qo, q, n, "floats", "chain: q")) return NULL;
    Py_buffer vc, vb, vt, vj, vjg;
    if (get_buffer(co, &vc, 5 * n, 0, "chain: consts") < 0) return NULL;
    if (get_buffer(bo, &vb, 16, 0, "chain: base") < 0) goto fail_c;
    if (get_buffer(to, &vt, 16, 0, "chain: tool") < 0) goto fail_b;
    if (get_buffer(jo, &vj, 6 * n, 1, "chain: J") < 0) goto fail_t;
    if (get_buffer(jgo, &vjg, 6 * n, 1, "chain: Jg") < 0) goto fail_j;
    const double *c = vc.buf;
    double *J = vj.buf, *Jg = vjg.buf;
    double T[12], N[12], M[12], Z[3 * MAXJ], O[3 * MAXJ];
    memcpy(T, vb.buf, sizeof T);
    for (Py_ssize_t i = 0; i < n; i++) {
        const double ca = c[5 * i], sa = c[5 * i + 1], a = c[5 * i + 2], d = c[5 * i + 3];
        const double th = q[i] + c[5 * i + 4], ct = cos(th), st = sin(th);
        for (int r = 0; r < 3; r++) {
            Z[3 * i + r] = T[4 * r + 2];
            O[3 * i + r] = T[4 * r + 3];
        }
        M[0] = ct, M[1] = -st * ca, M[2] = st * sa, M[3] = a * ct;
        M[4] = st, M[5] = ct * ca, M[6] = -ct * sa, M[7] = a * st;
        M[8] = 0.0, M[9] = sa, M[10] = ca, M[11] = d;
        affine_mul(T, M, N);
        memcpy(T, N, sizeof T);
    }
    affine_mul(T, (const double *)vt.buf, N);
    const double px = N[3], py = N[7], pz = N[11];
    const double rx = gp * N[2], ry = gp * N[6], rz = gp * N[10]; /* g - p */
    for (Py_ssize_t i = 0; i < n; i++) {
        const double zx = Z[3 * i], zy = Z[3 * i + 1], zz = Z[3 * i + 2];
        const double dx = px - O[3 * i], dy = py - O[3 * i + 1], dz = pz - O[3 * i + 2];
        const double vx = zy * dz - zz * dy, vy = zz * dx - zx * dz, vz = zx * dy - zy * dx;
        J[i] = vx, J[n + i] = vy, J[2 * n + i] = vz;
        J[3 * n + i] = zx, J[4 * n + i] = zy, J[5 * n + i] = zz;
        Jg[i] = vx - (ry * zz - rz * zy);
        Jg[n + i] = vy - (rz * zx - rx * zz);
        Jg[2 * n + i] = vz - (rx * zy - ry * zx);
        Jg[3 * n + i] = zx, Jg[4 * n + i] = zy, Jg[5 * n + i] = zz;
    }
    PyBuffer_Release(&vjg);
    PyBuffer_Release(&vj);
    PyBuffer_Release(&vt);
    PyBuffer_Release(&vb);
    PyBuffer_Release(&vc);
    return Py_BuildValue("(ddddddddddddddd)", N[0], N[1], N[2], N[4], N[5], N[6], N[8], N[9],
                         N[10], px, py, pz, px + rx, py + ry, pz + rz);
fail_j:
    PyBuffer_Release(&vj);
fail_t:
    PyBuffer_Release(&vt);
fail_b:
    PyBuffer_Release(&vb);
fail_c:
    PyBuffer_Release(&vc);
    return NULL;
}

/* terms(Jg, J, n, lam2, b1, b2, qd, F, K_ap, K_av, K_af, vlim) -> (track, reach, damp, force,
 * command): eq. 2's joint-velocity terms. track = K_ap Jg+ b1 and reach = K_ap Jg+ b2 with the
 * damped pseudo-inverse Jg+ = Jg^T (Jg Jg^T + lam2 I)^-1 (Cholesky of the 6 x 6 SPD matrix; b1
 * = S K^a1 e_track, b2 = (I - S) K^a2 e_reach), damp = -K_av qd, force = K_af J^T F; command =
 * their sum ((track + reach) + damp) + force, clipped to +-vlim (NaN passes, as np.clip). */
static PyObject *py_terms(PyObject *self, PyObject *args) {
    PyObject *jgo, *jo, *b1o, *b2o, *qdo, *fo, *vlo;
    Py_ssize_t n;
    double lam2, K_ap, K_av, K_af;
    if (!PyArg_ParseTuple(args, "OOndOOOOdddO", &jgo, &jo, &n, &lam2, &b1o, &b2o, &qdo, &fo,
                          &K_ap, &K_av, &K_af, &vlo))
        return NULL;
    if (n < 1 || n > MAXJ) {
        PyErr_SetString(PyExc_ValueError, "terms: 1..16 joints");
        return NULL;
    }
    double b[2][6], f[6], qd[MAXJ], vlim[MAXJ];
    if (!seq_doubles_head(b1o, b[0], 6, "floats", "terms: b1") ||
        !seq_doubles_head(b2o, b[1], 6, "floats", "terms: b2") ||
        !seq_doubles_head(fo, f, 6, "floats", "terms: F") ||
        !seq_doubles_head(qdo, qd, n, "floats", "terms: qd") ||
        !seq_doubles_head(vlo, vlim, n, "floats", "terms: vlim"))
        return NULL;
    Py_buffer vjg, vj;
    if (get_buffer(jgo, &vjg, 6 * n, 0, "terms: Jg") < 0) return NULL;
    if (get_buffer(jo, &vj, 6 * n, 0, "terms: J") < 0) {
        PyBuffer_Release(&vjg);
        return NULL;
    }
    const double *Jg = vjg.buf, *J = vj.buf;
    double A[6][6], L[6][6];
    for (int r = 0; r < 6; r++)
        for (int s = 0; s <= r; s++) {
            double acc = 0.0;
            for (Py_ssize_t k = 0; k < n; k++) acc += Jg[r * n + k] * Jg[s * n + k];
            A[r][s] = A[s][r] = acc + (r == s ? lam2 : 0.0);
        }
    for (int r = 0; r < 6; r++) {
        for (int s = 0; s <= r; s++) {
            double acc = A[r][s];
            for (int k = 0; k < s; k++) acc -= L[r][k] * L[s][k];
            if (r == s) {
                if (!(acc > 0.0)) {
                    PyBuffer_Release(&vj);
                    PyBuffer_Release(&vjg);
                    PyErr_SetString(PyExc_ValueError, "terms: J J^T + lambda^2 I not positive definite");
                    return NULL;
                }
                L[r][r] = sqrt(acc);
            } else {
                L[r][s] = acc / L[s][s];
            }
        }
    }
    double x[5][MAXJ]; /* track, reach, damp, force, command */
    for (int m = 0; m < 2; m++) {
        double y[6];
        for (int r = 0; r < 6; r++) { /* L y = b */
            double acc = b[m][r];
            for (int k = 0; k < r; k++) acc -= L[r][k] * y[k];
            y[r] = acc / L[r][r];
        }
        for (int r = 5; r >= 0; r--) { /* L^T z = y */
            double acc = y[r];
            for (int k = r + 1; k < 6; k++) acc -= L[k][r] * y[k];
            y[r] = acc / L[r][r];
        }
        for (Py_ssize_t k = 0; k < n; k++) {
            double acc = 0.0;
            for (int r = 0; r < 6; r++) acc += Jg[r * n + k] * y[r];
            x[m][k] = K_ap * acc;
        }
    }
    for (Py_ssize_t k = 0; k < n; k++) {
        double acc = 0.0;
        for (int r = 0; r < 6; r++) acc += J[r * n + k] * f[r];
        x[2][k] = -K_av * qd[k];
        x[3][k] = K_af * acc;
        const double c = x[0][k] + x[1][k] + x[2][k] + x[3][k], v = vlim[k];
        x[4][k] = c > v ? v : (c < -v ? -v : c);
    }
    PyBuffer_Release(&vj);
    PyBuffer_Release(&vjg);
    PyObject *out = PyTuple_New(5);
    if (out == NULL) return NULL;
    for (int m = 0; m < 5; m++) {
        PyObject *l = list_of_doubles(x[m], n);
        if (l == NULL) {
            Py_DECREF(out);
            return NULL;
        }
        PyTuple_SET_ITEM(out, m, l);
    }
    return out;
}

/* wrench(R, force, torque, w_hand, com, bias, filtered, a, deadband) -> (ext, filtered, F): the
 * wrist sensor's wrench turned into the world (R: the tool's rotation, row-major) minus the
 * hand's weight w_hand acting at R com: ext = (R f - w, R m - (R com) x w); bias None: this ext
 * is the tare (bias = ext, the filter starts at 0); filtered += a ((ext - bias) - filtered); F =
 * filtered, or 0 when its force is below the deadband. */
static PyObject *py_wrench(PyObject *self, PyObject *args) {
    PyObject *Ro, *fo, *mo, *wo, *co, *bo, *flo;
    double a, deadband;
    if (!PyArg_ParseTuple(args, "OOOOOOOdd", &Ro, &fo, &mo, &wo, &co, &bo, &flo, &a, &deadband))
        return NULL;
    double R[9], f[3], m[3], w[3], c[3], b[6], fl[6], ext[6], out[6];
    if (!seq_doubles_head(Ro, R, 9, "floats", "wrench: R") ||
        !seq_doubles_head(fo, f, 3, "floats", "wrench: force") ||
        !seq_doubles_head(mo, m, 3, "floats", "wrench: torque") ||
        !seq_doubles_head(wo, w, 3, "floats", "wrench: w_hand") ||
        !seq_doubles_head(co, c, 3, "floats", "wrench: com") ||
        !seq_doubles_head(flo, fl, 6, "floats", "wrench: filtered"))
        return NULL;
    double r[3];
    for (int i = 0; i < 3; i++) {
        r[i] = R[3 * i] * c[0] + R[3 * i + 1] * c[1] + R[3 * i + 2] * c[2];
        ext[i] = R[3 * i] * f[0] + R[3 * i + 1] * f[1] + R[3 * i + 2] * f[2] - w[i];
    }
    const double rxw[3] = {r[1] * w[2] - r[2] * w[1], r[2] * w[0] - r[0] * w[2],
                           r[0] * w[1] - r[1] * w[0]};
    for (int i = 0; i < 3; i++)
        ext[3 + i] = R[3 * i] * m[0] + R[3 * i + 1] * m[1] + R[3 * i + 2] * m[2] - rxw[i];
    if (bo == Py_None) {
        for (int i = 0; i < 6; i++) b[i] = ext[i], fl[i] = 0.0;
    } else if (!seq_doubles_head(bo, b, 6, "floats", "wrench: bias")) {
        return NULL;
    }
    for (int i = 0; i < 6; i++) fl[i] = fl[i] + a * (ext[i] - b[i] - fl[i]);
    const int quiet = sqrt(fl[0] * fl[0] + fl[1] * fl[1] + fl[2] * fl[2]) < deadband;
    for (int i = 0; i < 6; i++) out[i] = quiet ? 0.0 : fl[i];
    PyObject *e = list_of_doubles(ext, 6), *g = list_of_doubles(fl, 6);
    PyObject *F = list_of_doubles(out, 6);
    if (e == NULL || g == NULL || F == NULL) {
        Py_XDECREF(e);
        Py_XDECREF(g);
        Py_XDECREF(F);
        return NULL;
    }
    return Py_BuildValue("(NNN)", e, g, F);
}

static PyMethodDef methods[] = {
    {"chain", py_chain, METH_VARARGS, "DH chain: tool pose, grasp point, J and Jg"},
    {"terms", py_terms, METH_VARARGS, "eq. 2's joint-velocity terms and the command"},
    {"wrench", py_wrench, METH_VARARGS, "F^a: the wrist wrench in the world, tared, filtered"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_arm_kinematics",
                                    "The grasping arm task's per-step linear algebra.", -1,
                                    methods};

PyMODINIT_FUNC PyInit__arm_kinematics(void) { return PyModule_Create(&module); }
