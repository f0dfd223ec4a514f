/* The air table's once-a-step body input/output, compiled (plants/airtable/body_state.py
 * documents it and keeps the Python version, the reference of
 * tests/plants/airtable/test_bodies_kernel.py). Plain C over the buffer protocol, no NumPy or
 * Chipmunk headers: Chipmunk's own functions are called through the addresses Pymunk's cffi
 * binding gives (body_state.py passes them), so the numbers are Chipmunk's, read and written
 * exactly as the Python path does.
 *
 * ptrs: uint64 buffer of 10 addresses: cpBodyGetPosition, cpBodyGetVelocity, cpBodyGetAngle,
 * cpBodyGetAngularVelocity, cpBodySetVelocity, then the bodies: the stick, tip 0, tip 1, then
 * cpSpaceStep and the space (0, 0 when the engine is only called through Python). state: float64 buffer of 10: x, y, vx, vy, angle, omega of the stick, then
 * the tips' x, y.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>

typedef struct {
    double x, y;
} vect_t; /* cpVect (cpFloat = double) */

typedef vect_t (*get_vect_fn)(const void *);
typedef double (*get_float_fn)(const void *);
typedef void (*set_vect_fn)(void *, vect_t);
typedef void (*space_step_fn)(void *, double);

typedef struct {
    get_vect_fn position, velocity;
    get_float_fn angle, omega;
    set_vect_fn set_velocity;
    void *stick, *tip[2];
    space_step_fn space_step; /* cpSpaceStep and the space, or NULL */
    void *space;
} table_t;

static int unpack(Py_buffer *P, table_t *t) {
    if (P->len != 10 * (Py_ssize_t)sizeof(uint64_t)) {
        PyErr_SetString(PyExc_ValueError, "ptrs: 10 uint64 addresses");
        return 0;
    }
    const uint64_t *a = P->buf;
    t->position = (get_vect_fn)(uintptr_t)a[0];
    t->velocity = (get_vect_fn)(uintptr_t)a[1];
    t->angle = (get_float_fn)(uintptr_t)a[2];
    t->omega = (get_float_fn)(uintptr_t)a[3];
    t->set_velocity = (set_vect_fn)(uintptr_t)a[4];
    t->stick = (void *)(uintptr_t)a[5];
    t->tip[0] = (void *)(uintptr_t)a[6];
    t->tip[1] = (void *)(uintptr_t)a[7];
    t->space_step = (space_step_fn)(uintptr_t)a[8];
    t->space = (void *)(uintptr_t)a[9];
    if (!a[8] != !a[9]) {
        PyErr_SetString(PyExc_ValueError, "ptrs: cpSpaceStep and the space, or neither");
        return 0;
    }
    for (int i = 0; i < 8; i++)
        if (!a[i]) {
            PyErr_SetString(PyExc_ValueError, "ptrs: a null address");
            return 0;
        }
    return 1;
}

static void read_state(const table_t *t, double *s) {
    vect_t p = t->position(t->stick), v = t->velocity(t->stick);
    s[0] = p.x;
    s[1] = p.y;
    s[2] = v.x;
    s[3] = v.y;
    s[4] = t->angle(t->stick);
    s[5] = t->omega(t->stick);
    for (int k = 0; k < 2; k++) {
        vect_t q = t->position(t->tip[k]);
        s[6 + 2 * k] = q.x;
        s[7 + 2 * k] = q.y;
    }
}

static int state_ok(Py_buffer *S) {
    if (S->len != 10 * (Py_ssize_t)sizeof(double)) {
        PyErr_SetString(PyExc_ValueError, "state: 10 float64");
        return 0;
    }
    return 1;
}

/* read(ptrs, state): the stick's and the tips' state now, into state. */
static PyObject *py_read(PyObject *self, PyObject *args) {
    Py_buffer P, S;
    if (!PyArg_ParseTuple(args, "y*w*", &P, &S)) return NULL;
    PyObject *ret = NULL;
    table_t t;
    if (unpack(&P, &t) && state_ok(&S)) {
        read_state(&t, S.buf);
        Py_INCREF(Py_None);
        ret = Py_None;
    }
    PyBuffer_Release(&P);
    PyBuffer_Release(&S);
    return ret;
}

/* One engine step with the tips' targets tx, ty (py_step and py_step_hand say what); the "usual"
 * flag (0 or 1), or -1 with an exception set. */
static int step_core(const table_t *t, double *s, const double *tx, const double *ty,
                     PyObject *dt_obj, double dt, PyObject *space_step, double rest_v,
                     double rest_w, double hold_v, double hold_w) {
    for (int k = 0; k < 2; k++) {
        vect_t v = {(tx[k] - s[6 + 2 * k]) / dt, (ty[k] - s[7 + 2 * k]) / dt};
        t->set_velocity(t->tip[k], v);
    }
    if (space_step == Py_None) { /* the engine's step itself (body_state.TableIO says when) */
        if (!t->space) {
            PyErr_SetString(PyExc_ValueError, "space_step None: no cpSpaceStep in ptrs");
            return -1;
        }
        t->space_step(t->space, dt);
    } else {
        PyObject *r = PyObject_CallOneArg(space_step, dt_obj);
        if (!r) return -1;
        Py_DECREF(r);
    }
    read_state(t, s);
    int usual = 0;
    double sum = s[0] + s[1] + s[4] + s[2] + s[3] + s[5] + s[6] + s[7] + s[8] + s[9];
    if (isfinite(sum)) {
        double sq = s[2] * s[2] + s[3] * s[3], w = fabs(s[5]);
        double rv = rest_v * (1.0 + 1e-9), hv = hold_v * (1.0 + 1e-9);
        usual = (sq > rv * rv || w >= rest_w) && (sq > hv * hv || w >= hold_w);
    }
    return usual;
}

/* the arguments step and step_hand share, checked: *dt the float of dt_obj, *t the table of
 * P, S a state buffer; 1, or 0 with an exception set */
static int step_args(PyObject *dt_obj, double *dt, Py_buffer *P, table_t *t, Py_buffer *S) {
    *dt = PyFloat_AsDouble(dt_obj);
    if (*dt == -1.0 && PyErr_Occurred()) return 0;
    return unpack(P, t) && state_ok(S);
}

/* step_core's result (1, 0, or -1 with an exception set) as step's: True, False or NULL */
static PyObject *step_result(int usual) { return usual >= 0 ? PyBool_FromLong(usual) : NULL; }

/* step(ptrs, state, tx0, ty0, tx1, ty1, dt, space_step, rest_speed, rest_omega, hold_speed,
 *      hold_omega): each tip's velocity set to ((tx - x) / dt, (ty - y) / dt) from its position in
 * state (so that the step's position integration lands it on the target), space_step(dt) called
 * (the engine, and the collision callbacks it runs; None: cpSpaceStep(space, dt) of ptrs), and
 * the state read again into state.
 * Returns True when the state after the step is certainly the plant's usual case: every number
 * finite (their sum, in the plant's order) and the stick too fast or spinning too fast both to
 * rest (speed >= rest_speed or |omega| >= rest_omega) and to be held (the same with hold_*).
 * The speed is compared squared with a margin of 1e-9 (the plant compares math.hypot), so True
 * is never wrong; False leaves the decision to the plant's own checks. */
static PyObject *py_step(PyObject *self, PyObject *args) {
    Py_buffer P, S;
    double tx[2], ty[2], rest_v, rest_w, hold_v, hold_w;
    PyObject *dt_obj, *space_step;
    if (!PyArg_ParseTuple(args, "y*w*ddddOOdddd", &P, &S, &tx[0], &ty[0], &tx[1], &ty[1],
                          &dt_obj, &space_step, &rest_v, &rest_w, &hold_v, &hold_w))
        return NULL;
    PyObject *ret = NULL;
    table_t t;
    double dt;
    if (!step_args(dt_obj, &dt, &P, &t, &S)) goto done;
    ret = step_result(
        step_core(&t, S.buf, tx, ty, dt_obj, dt, space_step, rest_v, rest_w, hold_v, hold_w));
done:
    PyBuffer_Release(&P);
    PyBuffer_Release(&S);
    return ret;
}

/* The hand servo's state (plants/airtable/hand.py, HandServo.state): base x, y; joints q1, q2 of
 * finger 0, of finger 1; their targets (the same 6); settled (nonzero: on the targets); the
 * tips' x, y (finger 0, finger 1) and whether they are valid; the root offsets (finger 0 x, y,
 * finger 1 x, y); the link lengths l1, l2; the base's and the joints' speed limits. */
enum { H_BASE = 0, H_Q = 2, H_BT = 6, H_QT = 8, H_SETTLED = 12, H_TIPS = 13, H_TIPS_VALID = 17,
       H_ROOTS = 18, H_LINKS = 22, H_BASE_SPEED = 24, H_JOINT_SPEED = 25, H_SIZE = 26 };

/* hand.py _toward on n entries: each moves toward its target by at most max_delta, landing on
 * it when in reach; 1 when all are on their targets */
static int toward(double *cur, const double *target, int n, double max_delta) {
    int done = 1;
    for (int i = 0; i < n; i++) {
        double c = cur[i], g = target[i], d = g - c;
        if (fabs(d) <= max_delta) {
            cur[i] = g;
        } else {
            cur[i] = d > 0.0 ? c + max_delta : c - max_delta;
            done = 0;
        }
    }
    return done;
}

/* HandServo.advance(dt) then HandServo.tip_list() (replay/robot/hand2d.py _chain), on h */
static void advance_hand(double *h, double dt) {
    if (!h[H_SETTLED]) {
        int at_b = toward(h + H_BASE, h + H_BT, 2, h[H_BASE_SPEED] * dt);
        int at_q = toward(h + H_Q, h + H_QT, 4, h[H_JOINT_SPEED] * dt);
        h[H_TIPS_VALID] = 0.0;
        h[H_SETTLED] = at_b && at_q;
    }
    if (!h[H_TIPS_VALID]) {
        const double l1 = h[H_LINKS], l2 = h[H_LINKS + 1];
        for (int k = 0; k < 2; k++) {
            const double *q = h + H_Q + 2 * k;
            double rx = h[H_BASE] + h[H_ROOTS + 2 * k], ry = h[H_BASE + 1] + h[H_ROOTS + 2 * k + 1];
            double ex = rx + l1 * cos(q[0]), ey = ry + l1 * sin(q[0]);
            h[H_TIPS + 2 * k] = ex + l2 * cos(q[0] + q[1]);
            h[H_TIPS + 2 * k + 1] = ey + l2 * sin(q[0] + q[1]);
        }
        h[H_TIPS_VALID] = 1.0;
    }
}

/* step_hand(ptrs, state, hand, dt, space_step, rest_speed, rest_omega, hold_speed, hold_omega):
 * the hand servo's step on hand (its state, above: HandServo.advance(dt), then its tips), then
 * step with those tips as the targets; the same return value. */
static PyObject *py_step_hand(PyObject *self, PyObject *args) {
    Py_buffer P, S, Hb;
    double rest_v, rest_w, hold_v, hold_w;
    PyObject *dt_obj, *space_step;
    if (!PyArg_ParseTuple(args, "y*w*w*OOdddd", &P, &S, &Hb, &dt_obj, &space_step, &rest_v,
                          &rest_w, &hold_v, &hold_w))
        return NULL;
    PyObject *ret = NULL;
    table_t t;
    double dt;
    if (!step_args(dt_obj, &dt, &P, &t, &S)) goto done;
    if (Hb.len != H_SIZE * (Py_ssize_t)sizeof(double)) {
        PyErr_SetString(PyExc_ValueError, "hand: 26 float64");
        goto done;
    }
    double *h = Hb.buf;
    advance_hand(h, dt);
    const double tx[2] = {h[H_TIPS], h[H_TIPS + 2]}, ty[2] = {h[H_TIPS + 1], h[H_TIPS + 3]};
    ret = step_result(
        step_core(&t, S.buf, tx, ty, dt_obj, dt, space_step, rest_v, rest_w, hold_v, hold_w));
done:
    PyBuffer_Release(&P);
    PyBuffer_Release(&S);
    PyBuffer_Release(&Hb);
    return ret;
}

static PyMethodDef methods[] = {
    {"read", py_read, METH_VARARGS, "the stick's and the tips' state"},
    {"step", py_step, METH_VARARGS, "tip velocities, one engine step, the state after it"},
    {"step_hand", py_step_hand, METH_VARARGS, "the hand servo's step, then step to its tips"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_bodies",
                                    "The air table's once-a-step body input/output.", -1,
                                    methods};

PyMODINIT_FUNC PyInit__bodies(void) { return PyModule_Create(&module); }
