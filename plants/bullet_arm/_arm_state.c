/* The arm plant's once-a-step state arithmetic (plants/bullet_arm/arm_state.py keeps the Python
 * version of each function as its reference; a seeded test holds them equal to the bit):
 *
 * - joint_state: PyBullet's getJointStates tuple -> the arm's (q, qd) (locked joints at their
 *   lock value, zero speed) and the hand's (q, qd, applied torque), lists of the same floats;
 * - limit_flags: finite state?, and each arm joint over its speed limit / at a position limit,
 *   or None when finite and no flag changed (the usual step);
 * - palm_frame: the object in the palm frame (CatchWatch.observe's arithmetic, same operations
 *   in the same order).
 *
 * Right after PyBullet's step the CPU caches hold the engine's data: a few compact C loops here
 * cost less than the interpreter's many small objects. Plain C, no NumPy headers.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>

#include "_pyfloats.h"

#define MAXJ 64

/* joint_state(states, na, pick, locked) -> ((q, qd), (hq, hqd, heff))
 * states: getJointStates' tuple (per joint: position, velocity, reaction, applied torque), the
 * arm's na read joints first, then the hand's; pick: per arm joint its read joint's index, or
 * -1 for a locked joint (q from locked[i], qd 0.0). */
static PyObject *py_joint_state(PyObject *self, PyObject *args) {
    PyObject *states, *pick, *locked;
    Py_ssize_t na;
    if (!PyArg_ParseTuple(args, "O!nO!O!", &PyTuple_Type, &states, &na, &PyTuple_Type, &pick,
                          &PyList_Type, &locked))
        return NULL;
    Py_ssize_t n = PyTuple_GET_SIZE(states), dof = PyTuple_GET_SIZE(pick);
    if (na < 0 || na > n || PyList_GET_SIZE(locked) != dof) {
        PyErr_SetString(PyExc_ValueError, "joint_state: inconsistent sizes");
        return NULL;
    }
    for (Py_ssize_t j = 0; j < n; j++) {
        PyObject *s = PyTuple_GET_ITEM(states, j);
        if (!PyTuple_Check(s) || PyTuple_GET_SIZE(s) < 4) {
            PyErr_SetString(PyExc_TypeError, "joint_state: a joint's state is a 4-tuple");
            return NULL;
        }
    }
    PyObject *q = PyList_New(dof), *qd = PyList_New(dof);
    PyObject *hq = PyList_New(n - na), *hqd = PyList_New(n - na), *he = PyList_New(n - na);
    PyObject *zero = PyFloat_FromDouble(0.0);
    if (!q || !qd || !hq || !hqd || !he || !zero) goto fail;
    for (Py_ssize_t i = 0; i < dof; i++) {
        Py_ssize_t k = PyLong_AsSsize_t(PyTuple_GET_ITEM(pick, i));
        if (k == -1 && PyErr_Occurred()) goto fail;
        PyObject *a, *b;
        if (k >= 0) {
            if (k >= na) {
                PyErr_SetString(PyExc_IndexError, "joint_state: pick beyond the arm's joints");
                goto fail;
            }
            PyObject *s = PyTuple_GET_ITEM(states, k);
            a = PyTuple_GET_ITEM(s, 0);
            b = PyTuple_GET_ITEM(s, 1);
        } else {
            a = PyList_GET_ITEM(locked, i);
            b = zero;
        }
        Py_INCREF(a);
        Py_INCREF(b);
        PyList_SET_ITEM(q, i, a);
        PyList_SET_ITEM(qd, i, b);
    }
    for (Py_ssize_t j = na; j < n; j++) {
        PyObject *s = PyTuple_GET_ITEM(states, j);
        PyObject *a = PyTuple_GET_ITEM(s, 0), *b = PyTuple_GET_ITEM(s, 1);
        PyObject *c = PyTuple_GET_ITEM(s, 3);
        Py_INCREF(a);
        Py_INCREF(b);
        Py_INCREF(c);
        PyList_SET_ITEM(hq, j - na, a);
        PyList_SET_ITEM(hqd, j - na, b);
        PyList_SET_ITEM(he, j - na, c);
    }
    Py_DECREF(zero);
    return Py_BuildValue("(NN)(NNN)", q, qd, hq, hqd, he);
fail:
    Py_XDECREF(q);
    Py_XDECREF(qd);
    Py_XDECREF(hq);
    Py_XDECREF(hqd);
    Py_XDECREF(he);
    Py_XDECREF(zero);
    return NULL;
}

/* each element's truth of a list of bools (n of them); -1 with an exception otherwise */
static int flags(PyObject *obj, int *out, Py_ssize_t n, const char *what) {
    if (!PyList_Check(obj) || PyList_GET_SIZE(obj) != n) {
        PyErr_Format(PyExc_ValueError, "%s: a list of %zd bools", what, n);
        return -1;
    }
    for (Py_ssize_t i = 0; i < n; i++) {
        int t = PyObject_IsTrue(PyList_GET_ITEM(obj, i));
        if (t < 0) return -1;
        out[i] = t;
    }
    return 0;
}

static PyObject *bool_list(const int *x, Py_ssize_t n) {
    PyObject *out = PyList_New(n);
    if (out == NULL) return NULL;
    for (Py_ssize_t i = 0; i < n; i++) PyList_SET_ITEM(out, i, PyBool_FromLong(x[i]));
    return out;
}

/* limit_flags(q, qd, pos, v, vlim, lower, upper, over0, at0) -> None | (finite, over, at)
 * finite: every q, qd (and pos, v of the object: None without one) finite; over[i]: |qd| >
 * vlim; at[i]: q <= lower or q >= upper (limits already moved inwards by the caller). None when
 * finite and over, at equal over0, at0 (the last step's); over and at are None when not finite. */
static PyObject *py_limit_flags(PyObject *self, PyObject *args) {
    PyObject *qo, *qdo, *po, *vo, *limo, *loo, *hio, *over0o, *at0o;
    if (!PyArg_ParseTuple(args, "OOOOOOOOO", &qo, &qdo, &po, &vo, &limo, &loo, &hio, &over0o,
                          &at0o))
        return NULL;
    Py_ssize_t n = PySequence_Size(qo);
    if (n < 0) return NULL;
    if (n > MAXJ) {
        PyErr_Format(PyExc_ValueError, "at most %d joints", MAXJ);
        return NULL;
    }
    double q[MAXJ], qd[MAXJ], lim[MAXJ], lo[MAXJ], hi[MAXJ], p[3], v[3];
    int over[MAXJ], at[MAXJ], over0[MAXJ], at0[MAXJ];
    if (!seq_doubles(qo, q, n, "floats", "q") || !seq_doubles(qdo, qd, n, "floats", "qd"))
        return NULL;
    int finite = 1;
    for (Py_ssize_t i = 0; i < n; i++) finite = finite && isfinite(q[i]) && isfinite(qd[i]);
    if (po != Py_None) {
        if (!seq_doubles(po, p, 3, "floats", "pos") || !seq_doubles(vo, v, 3, "floats", "v"))
            return NULL;
        for (int i = 0; i < 3; i++) finite = finite && isfinite(p[i]) && isfinite(v[i]);
    }
    if (!finite) return Py_BuildValue("(OOO)", Py_False, Py_None, Py_None);
    if (!seq_doubles(limo, lim, n, "floats", "vlim") ||
        !seq_doubles(loo, lo, n, "floats", "lower") ||
        !seq_doubles(hio, hi, n, "floats", "upper") || flags(over0o, over0, n, "over0") ||
        flags(at0o, at0, n, "at0"))
        return NULL;
    int same = 1;
    for (Py_ssize_t i = 0; i < n; i++) {
        over[i] = fabs(qd[i]) > lim[i];
        at[i] = q[i] <= lo[i] || q[i] >= hi[i];
        same = same && over[i] == over0[i] && at[i] == at0[i];
    }
    if (same) Py_RETURN_NONE;
    return Py_BuildValue("(ONN)", Py_True, bool_list(over, n), bool_list(at, n));
}

/* palm_frame(obj_pos, obj_vel, palm_pos, palm_quat, palm_vel, palm_omega, thickness)
 *   -> (lx, ly, lz, speed, angle, d, dist2)
 * The object centre from the palm face centre d (world) and in the palm frame (lx, ly, lz),
 * its speed relative to the palm point under it, the angle (deg) of that velocity from the
 * palm's inward normal, |d|^2: CatchWatch.observe's arithmetic (outcome.py). */
static PyObject *py_palm_frame(PyObject *self, PyObject *args) {
    PyObject *oo, *uo, *po, *qo, *vo, *wo;
    double th;
    if (!PyArg_ParseTuple(args, "OOOOOOd", &oo, &uo, &po, &qo, &vo, &wo, &th)) return NULL;
    double o[3], u[3], pp[3], qq[4], pv[3], w[3];
    if (!seq_doubles(oo, o, 3, "floats", "obj_pos") ||
        !seq_doubles(uo, u, 3, "floats", "obj_vel") ||
        !seq_doubles(po, pp, 3, "floats", "palm_pos") ||
        !seq_doubles(qo, qq, 4, "floats", "palm_quat") ||
        !seq_doubles(vo, pv, 3, "floats", "palm_vel") ||
        !seq_doubles(wo, w, 3, "floats", "palm_omega"))
        return NULL;
    double qx = qq[0], qy = qq[1], qz = qq[2], qw = qq[3];
    double nq = qx * qx + qy * qy + qz * qz + qw * qw;
    double k = 2.0 / nq;
    double X[3] = {1 - k * (qy * qy + qz * qz), k * (qx * qy + qz * qw), k * (qx * qz - qy * qw)};
    double Y[3] = {k * (qx * qy - qz * qw), 1 - k * (qx * qx + qz * qz), k * (qy * qz + qx * qw)};
    double Z[3] = {k * (qx * qz + qy * qw), k * (qy * qz - qx * qw), 1 - k * (qx * qx + qy * qy)};
    double ox = o[0], oy = o[1], oz = o[2], px = pp[0], py = pp[1], pz = pp[2];
    double d0 = ox - px - Z[0] * th, d1 = oy - py - Z[1] * th, d2 = oz - pz - Z[2] * th;
    double lx = X[0] * d0 + X[1] * d1 + X[2] * d2;
    double ly = Y[0] * d0 + Y[1] * d1 + Y[2] * d2;
    double lz = Z[0] * d0 + Z[1] * d1 + Z[2] * d2;
    double wx = w[0], wy = w[1], wz = w[2];
    double ax = ox - px, ay = oy - py, az = oz - pz;
    double r0 = u[0] - pv[0] - (wy * az - wz * ay);
    double r1 = u[1] - pv[1] - (wz * ax - wx * az);
    double r2 = u[2] - pv[2] - (wx * ay - wy * ax);
    double speed = sqrt(r0 * r0 + r1 * r1 + r2 * r2);
    double inward = -(Z[0] * r0 + Z[1] * r1 + Z[2] * r2);
    double angle = 0.0;
    if (speed > 0) {
        double c = inward / speed;
        c = c < 1.0 ? c : 1.0; /* min(1.0, c), as Python's min picks */
        c = c > -1.0 ? c : -1.0;
        angle = acos(c) * (180.0 / Py_MATH_PI); /* math.degrees */
    }
    double dist2 = d0 * d0 + d1 * d1 + d2 * d2;
    return Py_BuildValue("(ddddd(ddd)d)", lx, ly, lz, speed, angle, d0, d1, d2, dist2);
}

static PyMethodDef methods[] = {
    {"joint_state", py_joint_state, METH_VARARGS, "the arm's and hand's joint state lists"},
    {"limit_flags", py_limit_flags, METH_VARARGS, "finite?, over the speed / at a limit"},
    {"palm_frame", py_palm_frame, METH_VARARGS, "the object in the palm frame"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_arm_state", "The arm plant's once-a-step state arithmetic.", -1,
    methods,
};

PyMODINIT_FUNC PyInit__arm_state(void) { return PyModule_Create(&module); }
