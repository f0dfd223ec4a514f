/* The direct mapping q_d = g o l_c^-1(r_o) of one object state, compiled (Namiki & Ishikawa
 * eqs. 6-8, 12, 16, 23): replay/control/catching/mapping.py DirectMapping.evaluate_one_floats
 * (CatchGeometry.inverse_one, derivatives_one, PolynomialB.coefficients_one) with the same
 * operations in the same order, kept there as the reference
 * (tests/replay/control/catching/test_one_sample_paths.py holds them together). Plain C over the
 * buffer protocol: no NumPy headers.
 *
 * geo: float64 24: O, w1, w2, c, t, x = w1 x w2 (3 each), a = t.t, b = c.t, sigma (the branch
 * through s = 0), q_alpha, ref (q1, q2) the inverse prefers. powers: int32 (n_mono, 3), the
 * monomials' powers of (p1, p2, p4 - q_alpha); A: float64 (n_mono, 3), alpha of eq. 12.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>

#include "_pyfloats.h"

#define MAXMONO 256
#define MAXPOW 32

static double dot3(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double *a, const double *b, double *out) {
    double x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2],
           z = a[0] * b[1] - a[1] * b[0];
    out[0] = x, out[1] = y, out[2] = z;
}

/* Rodrigues R(w, theta) x = x + sin (w x x) + (1 - cos) w x (w x x), given cos and sin */
static void rot_cs(const double *w, double c, double s, const double *x, double *out) {
    double k[3], kk[3], o = 1.0 - c;
    cross3(w, x, k);
    cross3(w, k, kk);
    for (int i = 0; i < 3; i++) out[i] = x[i] + s * k[i] + o * kk[i];
}

/* Python's float x % y (the sign of y) */
static double pymod(double x, double y) {
    double m = fmod(x, y);
    if (m != 0.0) {
        if ((y < 0.0) != (m < 0.0)) m += y;
    } else {
        m = copysign(0.0, y);
    }
    return m;
}

static double wrap_near(double x, double ref) {
    return ref + pymod(x - ref + M_PI, 2.0 * M_PI) - M_PI;
}

/* theta with R(w, theta) u' = v' (projections on the plane normal to w) */
static double subproblem1(const double *w, const double *u, const double *v) {
    double uw = dot3(u, w), vw = dot3(v, w), up[3], vp[3], cr[3];
    for (int i = 0; i < 3; i++) up[i] = u[i] - uw * w[i], vp[i] = v[i] - vw * w[i];
    cross3(up, vp, cr);
    return atan2(dot3(cr, w), dot3(up, vp));
}

/* x with [c0 c1 c2] x = b (Cramer); 0 if singular */
static int solve3(const double *c0, const double *c1, const double *c2, const double *b,
                  double *x) {
    double r0[3], r1[3], r2[3];
    cross3(c1, c2, r0);
    cross3(c2, c0, r1);
    cross3(c0, c1, r2);
    double det = dot3(c0, r0);
    if (det == 0.0) return 0;
    x[0] = dot3(r0, b) / det, x[1] = dot3(r1, b) / det, x[2] = dot3(r2, b) / det;
    return 1;
}

/* l_c^-1(r) (CatchGeometry.inverse_one): p = (q1, q2, q4); returns in_domain */
static int inverse_one(const double *G, const double *r, double *p) {
    const double *O = G, *w1 = G + 3, *w2 = G + 6, *c = G + 9, *t = G + 12, *x = G + 15;
    const double a = G[18], b = G[19], sigma = G[20], q_alpha = G[21], ref0 = G[22],
                 ref1 = G[23];
    double v[3] = {r[0] - O[0], r[1] - O[1], r[2] - O[2]};
    double R2 = dot3(v, v);
    double disc = b * b - a * (dot3(c, c) - R2);
    int ok = disc >= 0.0;
    double s = (-b + sigma * sqrt(disc > 0.0 ? disc : 0.0)) / a;
    double u[3] = {c[0] + t[0] * s, c[1] + t[1] * s, c[2] + t[2] * s};
    if (!ok) {
        double nR = sqrt(R2);
        double k = sqrt(dot3(u, u)) / (nR > 1e-300 ? nR : 1e-300);
        v[0] = v[0] * k, v[1] = v[1] * k, v[2] = v[2] * k;
    }
    double w12 = dot3(w1, w2);
    double den = w12 * w12 - 1.0;
    double uw2 = dot3(u, w2), vw1 = dot3(v, w1);
    double al = (w12 * uw2 - vw1) / den;
    double be = (w12 * vw1 - uw2) / den;
    double g2 = (dot3(u, u) - al * al - be * be - 2 * al * be * w12) / dot3(x, x);
    double vv = dot3(v, v);
    int ok2 = g2 > 1e-12 * (vv > 1e-300 ? vv : 1e-300);
    double g = sqrt(g2 > 0.0 ? g2 : 0.0);
    double best1 = 0.0, best2 = 0.0, bestd = 0.0;
    for (int k = 0; k < 2; k++) {
        double sg = (k == 0 ? 1.0 : -1.0) * g, z[3];
        for (int i = 0; i < 3; i++) z[i] = al * w1[i] + be * w2[i] + sg * x[i];
        double q2 = wrap_near(subproblem1(w2, u, z), ref1);
        double q1 = wrap_near(subproblem1(w1, z, v), ref0);
        if (!ok2) { /* on the J1 axis: q1 undetermined, q2 re-solved with q1 = ref0 */
            double zz[3];
            q1 = ref0;
            rot_cs(w1, cos(-q1), sin(-q1), v, zz);
            q2 = wrap_near(subproblem1(w2, u, zz), ref1);
        }
        double dist = (q1 - ref0) * (q1 - ref0) + (q2 - ref1) * (q2 - ref1);
        if (k == 0 || dist < bestd) best1 = q1, best2 = q2, bestd = dist;
    }
    p[0] = best1, p[1] = best2, p[2] = s + q_alpha;
    return ok && ok2;
}

/* dl_c/dp (columns d[0..2]) and the Hessian's blocks H00, H01, H02, H11, H12 at p */
static void derivatives_one(const double *G, const double *p, double d[3][3], double H[5][3]) {
    const double *w1 = G + 3, *w2 = G + 6, *c = G + 9, *t = G + 12, q_alpha = G[21];
    double s = p[2] - q_alpha;
    double w[3] = {c[0] + t[0] * s, c[1] + t[1] * s, c[2] + t[2] * s};
    double c1 = cos(p[0]), s1 = sin(p[0]), c2 = cos(p[1]), s2 = sin(p[1]);
    double R2w[3], R2t[3], K2R2w[3], K2R2t[3], v[3], tmp[3];
    rot_cs(w2, c2, s2, w, R2w);
    rot_cs(w2, c2, s2, t, R2t);
    cross3(w2, R2w, K2R2w);
    cross3(w2, R2t, K2R2t);
    rot_cs(w1, c1, s1, R2w, v);
    cross3(w1, v, d[0]);
    rot_cs(w1, c1, s1, K2R2w, d[1]);
    rot_cs(w1, c1, s1, R2t, d[2]);
    cross3(w1, d[0], H[0]);
    cross3(w1, d[1], H[1]);
    cross3(w1, d[2], H[2]);
    cross3(w2, K2R2w, tmp);
    rot_cs(w1, c1, s1, tmp, H[3]);
    rot_cs(w1, c1, s1, K2R2t, H[4]);
}

/* evaluate_one(geo, powers, A, r, rd, rdd): (q_d, qd_d, qdd_d, q_o, in_domain), 3-tuples of
 * floats but in_domain (eqs. 7, 23, 16 for the active joints); raises
 * numpy.linalg.LinAlgError-like ValueError("Singular matrix") if J_c is singular. */
static PyObject *py_evaluate_one(PyObject *self, PyObject *args) {
    Py_buffer Gb, Pb, Ab;
    PyObject *ro, *rdo, *rddo;
    if (!PyArg_ParseTuple(args, "y*y*y*OOO", &Gb, &Pb, &Ab, &ro, &rdo, &rddo)) return NULL;
    PyObject *ret = NULL;
    double r[3], rd[3], rdd[3];
    Py_ssize_t nm = Pb.len / (3 * (Py_ssize_t)sizeof(int32_t));
    if (Gb.len != 24 * (Py_ssize_t)sizeof(double) ||
        Pb.len != nm * 3 * (Py_ssize_t)sizeof(int32_t) || nm > MAXMONO ||
        Ab.len != nm * 3 * (Py_ssize_t)sizeof(double)) {
        PyErr_SetString(PyExc_ValueError, "geo: float64 24; powers: int32 (n, 3); A: (n, 3)");
        goto done;
    }
    if (!seq_doubles(ro, r, 3, "floats", "r") || !seq_doubles(rdo, rd, 3, "floats", "rd") ||
        !seq_doubles(rddo, rdd, 3, "floats", "rdd")) goto done;
    const double *G = Gb.buf, *A = Ab.buf;
    const int32_t *pw = Pb.buf;
    double p[3], d[3][3], H[5][3], pd[3], pdd[3];
    int ok = inverse_one(G, r, p);
    derivatives_one(G, p, d, H);
    if (!solve3(d[0], d[1], d[2], rd, pd)) goto singular;
    double a = pd[0], b = pd[1], c = pd[2];
    double aa = a * a, ab2 = 2 * a * b, ac2 = 2 * a * c, bb = b * b, bc2 = 2 * b * c, rhs[3];
    for (int i = 0; i < 3; i++)
        rhs[i] = rdd[i] - (H[0][i] * aa + H[1][i] * ab2 + H[2][i] * ac2 + H[3][i] * bb +
                           H[4][i] * bc2);
    if (!solve3(d[0], d[1], d[2], rhs, pdd)) goto singular;
    /* PolynomialB.coefficients_one: per monomial m, dm . pd, dm . pdd + pd^T d2m pd */
    double x[3] = {p[0], p[1], p[2] - G[21]};
    int top = 0;
    for (Py_ssize_t j = 0; j < 3 * nm; j++) {
        if (pw[j] < 0 || pw[j] >= MAXPOW) {
            PyErr_SetString(PyExc_ValueError, "powers: 0 <= power < 32");
            goto done;
        }
        if (pw[j] > top) top = pw[j];
    }
    double X[MAXPOW], Y[MAXPOW], Z[MAXPOW];
    X[0] = Y[0] = Z[0] = 1.0;
    for (int e = 1; e <= top; e++) X[e] = X[e - 1] * x[0], Y[e] = Y[e - 1] * x[1],
                                   Z[e] = Z[e - 1] * x[2];
    const double u0 = pd[0], u1 = pd[1], u2 = pd[2], v0 = pdd[0], v1 = pdd[1], v2 = pdd[2];
    double out[3][3] = {{p[0], p[1], p[2]}, {pd[0], pd[1], pd[2]}, {pdd[0], pdd[1], pdd[2]}};
    double acc[3][3] = {{0.0}};
    for (Py_ssize_t j = 0; j < nm; j++) {
        int ea = pw[3 * j], eb = pw[3 * j + 1], ec = pw[3 * j + 2];
        double fa = X[ea], fb = Y[eb], fc = Z[ec];
        double ga = ea ? ea * X[ea - 1] : 0.0, gb = eb ? eb * Y[eb - 1] : 0.0,
               gc = ec ? ec * Z[ec - 1] : 0.0;
        double ha = ea > 1 ? (ea * (ea - 1)) * X[ea - 2] : 0.0;
        double hb = eb > 1 ? (eb * (eb - 1)) * Y[eb - 2] : 0.0;
        double hc = ec > 1 ? (ec * (ec - 1)) * Z[ec - 2] : 0.0;
        double d0 = ga * fb * fc, d1 = fa * gb * fc, d2 = fa * fb * gc;
        double quad = ha * fb * fc * u0 * u0 + fa * hb * fc * u1 * u1 + fa * fb * hc * u2 * u2 +
                      2.0 * (ga * gb * fc * u0 * u1 + ga * fb * gc * u0 * u2 +
                             fa * gb * gc * u1 * u2);
        double row[3] = {fa * fb * fc, d0 * u0 + d1 * u1 + d2 * u2,
                         d0 * v0 + d1 * v1 + d2 * v2 + quad};
        for (int k = 0; k < 3; k++)
            for (int l = 0; l < 3; l++) acc[k][l] += row[k] * A[3 * j + l];
    }
    for (int k = 0; k < 3; k++)
        for (int l = 0; l < 3; l++) out[k][l] += acc[k][l];
    ret = Py_BuildValue("((ddd)(ddd)(ddd)(ddd)O)", out[0][0], out[0][1], out[0][2], out[1][0],
                        out[1][1], out[1][2], out[2][0], out[2][1], out[2][2], p[0], p[1], p[2],
                        ok ? Py_True : Py_False);
    goto done;
singular:
    PyErr_SetString(PyExc_ValueError, "Singular matrix");
done:
    PyBuffer_Release(&Gb);
    PyBuffer_Release(&Pb);
    PyBuffer_Release(&Ab);
    return ret;
}

static PyMethodDef methods[] = {
    {"evaluate_one", py_evaluate_one, METH_VARARGS, "the direct mapping of one object state"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_mapping",
                                    "The catching method's direct mapping, compiled.", -1,
                                    methods};

PyMODINIT_FUNC PyInit__mapping(void) { return PyModule_Create(&module); }
