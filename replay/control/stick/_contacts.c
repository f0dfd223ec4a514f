/* The contact solver of the stick-capture strategies (replay/control/stick/collision.py
 * contact_options, Higashimori et al. 2007 eqs. 22, 25, 26, 28), compiled: the roots of
 * F_omega,i / F_V,i on each side, each root's J_i u (eq. 22) and C_i (eq. 26), the same
 * operations in the same order as collision.py's f_omega, f_v, quadratic_roots
 * (replay/robot/stick_impact.py), _terms, _after and approach_speed, which stay the reference
 * (contact_options_reference; tests/replay/control/stick/test_contacts_kernel.py holds them equal
 * to the bit). Plain C, no NumPy headers.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>

/* stick_impact.quadratic_roots: the real roots of a r^2 + b r + c = 0, ascending, into r;
 * their count (0, 1 or 2) */
static int quadratic_roots(double a, double b, double c, double *r) {
    double scale = fabs(a); /* max(|a|, |b|, |c|, 1e-300) as Python's max: the first largest */
    if (fabs(b) > scale) scale = fabs(b);
    if (fabs(c) > scale) scale = fabs(c);
    if (1e-300 > scale) scale = 1e-300;
    if (fabs(a) <= 1e-12 * scale) {
        if (fabs(b) <= 1e-12 * scale) return 0;
        r[0] = -c / b;
        return 1;
    }
    double disc = b * b - 4.0 * a * c;
    if (disc < 0.0) return 0;
    double q = -0.5 * (b + copysign(sqrt(disc), b));
    if (q == 0.0) {
        r[0] = 0.0;
        return 1;
    }
    double r0 = q / a, r1 = c / q;
    if (r1 < r0) { /* sorted((r0, r1)) */
        double tmp = r0;
        r0 = r1, r1 = tmp;
    }
    r[0] = r0, r[1] = r1;
    return 2;
}

/* options(m, inertia, e, theta, vx, vy, omega, target, is_speed, speed, sides): for each side
 * in sides (a sequence of numbers, > 0 for +1), the roots of F_V,i(target) (is_speed; speed = |v|, as
 * math.hypot gives it) or F_omega,i(target), and for each root passing eq. 26 (C_i > tol for
 * e > 0, else an approaching contact) the tuple (side sign, r_x, (vx, vy, omega) after, the
 * side's roots, C_i); a list of them, in collision.py contact_options' order. */
static PyObject *py_options(PyObject *self, PyObject *args) {
    double m, inertia, e, theta, u0, u1, u2, target, speed;
    int is_speed;
    PyObject *sides_obj;
    if (!PyArg_ParseTuple(args, "dddddddd" "pdO", &m, &inertia, &e, &theta, &u0, &u1, &u2,
                          &target, &is_speed, &speed, &sides_obj))
        return NULL;
    PyObject *sides = PySequence_Fast(sides_obj, "sides: not a sequence");
    if (!sides) return NULL;
    PyObject *out = PyList_New(0);
    if (!out) goto fail;
    const double c = cos(theta), s = sin(theta);
    const double tol = 1e-12 * fmax(1.0, sqrt(u0 * u0 + u1 * u1 + u2 * u2));
    for (Py_ssize_t i = 0; i < PySequence_Fast_GET_SIZE(sides); i++) {
        double side = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(sides, i));
        if (side == -1.0 && PyErr_Occurred()) goto fail;
        const double sign = side > 0 ? 1.0 : -1.0;
        const double nx = side > 0 ? s : -s, ny = side > 0 ? -c : c; /* normal(theta, side) */
        double roots[2];
        int nr;
        if (is_speed) { /* f_v */
            if (speed == 0.0) continue;
            double a2 = m * (target + speed);
            double b2 = (1.0 + e) * inertia * u2 * sign * (nx * u0 + ny * u1) / speed;
            double c2 = inertia * (target - e * speed);
            nr = quadratic_roots(a2, b2, c2, roots);
        } else { /* f_omega */
            double a1 = m * (target + e * u2);
            double b1 = -(1.0 + e) * m * sign * (nx * u0 + ny * u1);
            double c1 = inertia * (target - u2);
            nr = quadratic_roots(a1, b1, c1, roots);
        }
        PyObject *roots_t = NULL;
        for (int k = 0; k < nr; k++) {
            const double r = roots[k], r_y = 0.0;
            /* _terms(m, inertia, c, s, r, 0.0, side) */
            double ax = c * r - s * r_y, ay = s * r + c * r_y;
            double k11 = 1.0 / m + ay * ay / inertia, k12 = -ax * ay / inertia,
                   k22 = 1.0 / m + ax * ax / inertia;
            double det = k11 * k22 - k12 * k12;
            double wx = (k22 * nx - k12 * ny) / det, wy = (k11 * ny - k12 * nx) / det;
            double g0 = wx / m, g1 = wy / m, g2 = (-ay * wx + ax * wy) / inertia;
            double h0 = nx, h1 = ny, h2 = -ay * nx + ax * ny;
            /* _after */
            double kk = (1.0 + e) * (h0 * u0 + h1 * u1 + h2 * u2);
            double a0 = u0 - kk * g0, a1 = u1 - kk * g1, a2 = u2 - kk * g2;
            double condition = h0 * a0 + h1 * a1 + h2 * a2;
            if (e > 0.0) {
                if (!(condition > tol)) continue;
            } else { /* approach_speed(theta, r, side, u) > 1e-12 */
                double px = cos(theta) * r, py = sin(theta) * r;
                if (!(-(nx * u0 + ny * u1 + (-py * nx + px * ny) * u2) > 1e-12)) continue;
            }
            if (!roots_t) {
                roots_t = nr == 2 ? Py_BuildValue("(dd)", roots[0], roots[1])
                                  : Py_BuildValue("(d)", roots[0]);
                if (!roots_t) goto fail;
            }
            PyObject *item = Py_BuildValue("(id(ddd)Od)", side > 0 ? 1 : -1, r, a0, a1, a2,
                                           roots_t, condition);
            if (!item || PyList_Append(out, item) < 0) {
                Py_XDECREF(item);
                Py_DECREF(roots_t);
                goto fail;
            }
            Py_DECREF(item);
        }
        Py_XDECREF(roots_t);
    }
    Py_DECREF(sides);
    return out;
fail:
    Py_XDECREF(out);
    Py_DECREF(sides);
    return NULL;
}

static PyMethodDef contacts_methods[] = {
    {"options", py_options, METH_VARARGS, "contact_options' roots, J_i u and C_i"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef contacts_module = {
    PyModuleDef_HEAD_INIT, "_contacts", "The stick strategies' contact solver, compiled.", -1,
    contacts_methods};

PyMODINIT_FUNC PyInit__contacts(void) { return PyModule_Create(&contacts_module); }
