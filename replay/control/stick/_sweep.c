/* The stick planners' predicted-sweep checks (replay/control/stick/sweep.py and plan.py document
 * them; those modules are the only callers and keep the NumPy versions as the reference, which
 * tests/replay/control/stick/test_sweep_kernel.py compares with these). Plain C over the buffer
 * protocol: no NumPy headers, no start-up cost.
 *
 * The same floating-point operations, in the same order, as the NumPy code: sample times as
 * np.linspace makes them (j * step + t0, the last one t1), the stick's pose as Motion.poses
 * (constant velocities, switching to u_after at t_switch), stick-frame coordinates as
 * sweep.covered_along, the hand along a route as hand_model.route_configs / route_tips. The
 * cosines and sines are libm's, as NumPy's float64 ones are on the machines this runs on (the
 * test checks that too).
 *
 * A motion is the tuple (x, y, theta, vx, vy, omega, t_ref, t_switch, u0, u1, u2); t_switch may be
 * inf (no planned contact).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>

typedef struct {
    double x, y, th, vx, vy, w, t_ref, ts, u0, u1, u2;
    int switches;
} motion_t;

static int parse_motion(PyObject *o, motion_t *m) {
    if (!PyArg_ParseTuple(o, "ddddddddddd;motion: 11 floats", &m->x, &m->y, &m->th, &m->vx,
                          &m->vy, &m->w, &m->t_ref, &m->ts, &m->u0, &m->u1, &m->u2))
        return 0;
    m->switches = isfinite(m->ts);
    return 1;
}

/* Motion.poses at one time (the array version's operations, element by element). */
static void pose(const motion_t *m, double t, double *cx, double *cy, double *th) {
    double t1 = (t < m->ts ? t : m->ts) - m->t_ref;
    double x = m->x + m->vx * t1, y = m->y + m->vy * t1, a = m->th + m->w * t1;
    if (m->switches) {
        double t2 = t - m->ts;
        if (!(t2 > 0.0)) t2 = 0.0;
        x += m->u0 * t2;
        y += m->u1 * t2;
        a = a + m->u2 * t2;
    }
    *cx = x;
    *cy = y;
    *th = a;
}

/* sweep.sample_times(t0, t1) with n samples (np.linspace(t0, t1, n); n == 1: just t0). */
typedef struct {
    double t0, t1, step, delta, div;
    Py_ssize_t n;
    int zero;
} samples_t;

static void samples_init(samples_t *s, double t0, double t1, Py_ssize_t n) {
    s->t0 = t0;
    s->t1 = t1;
    s->n = n;
    s->div = (double)(n - 1);
    s->delta = t1 - t0;
    s->step = n > 1 ? s->delta / s->div : 0.0;
    s->zero = s->step == 0.0;
}

static double sample(const samples_t *s, Py_ssize_t j) {
    if (s->n > 1 && j == s->n - 1) return s->t1;
    if (s->n <= 1) return s->t0;
    if (s->zero) return (double)j / s->div * s->delta + s->t0;
    return (double)j * s->step + s->t0;
}

/* The point (px, py) within (hl, hw) (already grown) of the stick rectangle posed (cx, cy, c, s). */
static int inside(double px, double py, double cx, double cy, double cs, double sn, double hl,
                  double hw) {
    double dx = px - cx, dy = py - cy;
    double xb = dx * cs + dy * sn;
    double yb = -dx * sn + dy * cs;
    return fabs(xb) <= hl && fabs(yb) <= hw;
}

/* Squared reach of a rectangle of half-sizes (hl, hw), a little beyond its corners: a point
 * farther than that from the centre is outside whatever the orientation (the rotation keeps
 * |d| to within a few ulps), so the cosine and sine are only needed for points nearer. */
static double corner2(double hl, double hw) { return (hl * hl + hw * hw) * (1.0 + 1e-9) + 1e-300; }

static int far_from(double px, double py, double cx, double cy, double r2) {
    double dx = px - cx, dy = py - cy;
    return dx * dx + dy * dy > r2;
}

/* covered_index(motion, t0, t1, n, px, py, half_length, half_width, grow, last): the index and time
 * of the first (last = 0) or last (last = 1) sample at which the fixed point (px, py) is within
 * grow of the stick rectangle (sweep.covered for one point), or None. */
static PyObject *py_covered_index(PyObject *self, PyObject *args) {
    PyObject *mo;
    double t0, t1, px, py, hl, hw, grow;
    Py_ssize_t n;
    int last;
    motion_t m;
    samples_t s;
    if (!PyArg_ParseTuple(args, "Oddndddddp", &mo, &t0, &t1, &n, &px, &py, &hl, &hw, &grow,
                          &last))
        return NULL;
    if (!parse_motion(mo, &m)) return NULL;
    samples_init(&s, t0, t1, n);
    const double gl = hl + grow, gw = hw + grow, r2 = corner2(gl, gw);
    Py_ssize_t found = -1;
    for (Py_ssize_t j = 0; j < n; j++) {
        Py_ssize_t i = last ? n - 1 - j : j;
        double cx, cy, th;
        pose(&m, sample(&s, i), &cx, &cy, &th);
        if (far_from(px, py, cx, cy, r2)) continue;
        if (inside(px, py, cx, cy, cos(th), sin(th), gl, gw)) {
            found = i;
            break;
        }
    }
    if (found < 0) Py_RETURN_NONE;
    return Py_BuildValue("(nd)", found, sample(&s, found));
}

/* route_hit(motion, t0, t1, n, segments, speeds, geometry, k, t_guard, half_length, half_width,
 *           grow_active, check_idle, arrival, grow_far):
 * ContactPlanner.route_clear's sweep test along a route. segments: float64 (S, 13), each row
 * (t_start, 6 axes from, 6 axes to), axes = base x, y, finger 0 q1, q2, finger 1 q1, q2; speeds:
 * (base, joint) speed limits; geometry: (l1, l2, root0 x, y, root1 x, y). At the n samples of
 * [t0, t1] the hand is where route_configs puts it; finger k's tip is hit when within grow_active
 * of the stick at a sample <= t_guard; with check_idle the idle tip is hit when within grow_far,
 * or while moving (sample < arrival) within the clearance it has at t0 (the NumPy code's on_way:
 * max(grow_active, min(grow_far, gap - 1e-4))). True when a tip is hit. */
static PyObject *py_route_hit(PyObject *self, PyObject *args) {
    PyObject *mo;
    Py_buffer SEG;
    double t0, t1, bs, js, l1, l2, r0x, r0y, r1x, r1y, t_guard, hl, hw, g_act, arrival, g_far;
    Py_ssize_t n;
    int k, check_idle;
    motion_t m;
    samples_t s;
    if (!PyArg_ParseTuple(args, "Oddny*(dd)(dddddd)iddddpdd", &mo, &t0, &t1, &n, &SEG, &bs, &js,
                          &l1, &l2, &r0x, &r0y, &r1x, &r1y, &k, &t_guard, &hl, &hw, &g_act,
                          &check_idle, &arrival, &g_far))
        return NULL;
    PyObject *ret = NULL;
    if (!parse_motion(mo, &m)) goto done;
    Py_ssize_t S = SEG.len / (13 * (Py_ssize_t)sizeof(double));
    if (S < 1 || SEG.len != S * 13 * (Py_ssize_t)sizeof(double) || (k != 0 && k != 1) || n < 1) {
        PyErr_SetString(PyExc_ValueError, "route_hit: segments (S >= 1, 13) float64, k 0 or 1");
        goto done;
    }
    samples_init(&s, t0, t1, n);
    const double *seg = SEG.buf;
    const double speed[6] = {bs, bs, js, js, js, js};
    const double rx[2] = {r0x, r1x}, ry[2] = {r0y, r1y};
    const int j = 1 - k;
    const double al = hl + g_act, aw = hw + g_act, ar2 = corner2(al, aw);
    double fl = hl + g_far, fw = hw + g_far, ml = 0.0, mw = 0.0, fr2 = corner2(fl, fw), mr2 = 0.0;
    double q[6], prev[6], tip[2][2] = {{0.0, 0.0}, {0.0, 0.0}};
    int have = 0, hit = 0;
    /* route_configs' segments: segment i is written at samples lo_i <= j < hi_i, lo_0 = 0,
     * lo_i = the first sample at or after its start (searchsorted 'left'), hi_i = lo_(i+1)
     * (the last: n), a later segment overwriting an earlier one (starts may step back by the
     * 1e-9 s route_clear allows) */
    Py_ssize_t *lo = PyMem_Malloc(2 * (size_t)S * sizeof(Py_ssize_t));
    if (!lo) {
        PyErr_NoMemory();
        goto done;
    }
    Py_ssize_t *hi = lo + S;
    lo[0] = 0;
    for (Py_ssize_t i = 1; i < S; i++) { /* the samples ascend: a binary search */
        Py_ssize_t a = 0, b = n;
        while (a < b) {
            Py_ssize_t mid = a + (b - a) / 2;
            if (sample(&s, mid) < seg[13 * i])
                a = mid + 1;
            else
                b = mid;
        }
        lo[i] = a;
    }
    for (Py_ssize_t i = 0; i < S; i++) hi[i] = i + 1 < S ? lo[i + 1] : n;
    for (Py_ssize_t i = 0; i < n && !hit; i++) {
        double t = sample(&s, i);
        Py_ssize_t i_seg = 0;
        for (Py_ssize_t g = S - 1; g >= 0; g--)
            if (lo[g] <= i && i < hi[g]) {
                i_seg = g;
                break;
            }
        const double *row = seg + 13 * i_seg;
        double tau = t - row[0];
        if (!(tau > 0.0)) tau = 0.0;
        for (int a = 0; a < 6; a++) {
            double va = row[1 + a], vb = row[7 + a], step = tau * speed[a];
            double d = vb - va;
            if (!(d >= -step)) d = -step; /* np.maximum(vb - va, -step) */
            if (!(d <= step)) d = step;   /* np.minimum(.., step) */
            q[a] = va + d;
        }
        int same = have;
        for (int a = 0; a < 6 && same; a++) same = q[a] == prev[a];
        if (!same) {
            for (int f = 0; f < 2; f++) {
                double q1 = q[2 + 2 * f], q12 = q[2 + 2 * f] + q[3 + 2 * f];
                double x = l1 * cos(q1) + l2 * cos(q12), y = l1 * sin(q1) + l2 * sin(q12);
                tip[f][0] = x + (rx[f] + q[0]);
                tip[f][1] = y + (ry[f] + q[1]);
            }
            for (int a = 0; a < 6; a++) prev[a] = q[a];
            have = 1;
        }
        double cx, cy, th, cs = 0.0, sn = 0.0;
        int trig = 0; /* cs, sn made (only for a tip near the stick) */
        pose(&m, t, &cx, &cy, &th);
        if (i == 0 && check_idle) { /* the idle tip's clearance now (plan._body_point) */
            cs = cos(th);
            sn = sin(th);
            trig = 1;
            double dx = tip[j][0] - cx, dy = tip[j][1] - cy;
            double xb = dx * cs + dy * sn, yb = -dx * sn + dy * cs;
            double gx = fabs(xb) - hl, gy = fabs(yb) - hw;
            double gap = (gy > gx ? gy : gx) - 1e-4;      /* max(gx, gy) - 1e-4 */
            double near = gap < g_far ? gap : g_far;         /* min(grow_far, gap) */
            double on_way = near > g_act ? near : g_act;     /* max(grow_active, ..) */
            ml = hl + on_way;
            mw = hw + on_way;
            mr2 = corner2(ml, mw);
        }
        if (t <= t_guard && !far_from(tip[k][0], tip[k][1], cx, cy, ar2)) {
            if (!trig) {
                cs = cos(th);
                sn = sin(th);
                trig = 1;
            }
            hit = inside(tip[k][0], tip[k][1], cx, cy, cs, sn, al, aw);
        }
        if (check_idle && !hit) {
            int moving = t < arrival;
            double gl = moving ? ml : fl, gw = moving ? mw : fw;
            if (!far_from(tip[j][0], tip[j][1], cx, cy, moving ? mr2 : fr2)) {
                if (!trig) {
                    cs = cos(th);
                    sn = sin(th);
                }
                hit = inside(tip[j][0], tip[j][1], cx, cy, cs, sn, gl, gw);
            }
        }
    }
    PyMem_Free(lo);
    ret = PyBool_FromLong(hit);
done:
    PyBuffer_Release(&SEG);
    return ret;
}

static PyMethodDef methods[] = {
    {"covered_index", py_covered_index, METH_VARARGS, "first or last sample covering a point"},
    {"route_hit", py_route_hit, METH_VARARGS, "a fingertip hit by the sweep along a route"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_sweep",
                                    "The stick planners' predicted-sweep checks.", -1, methods};

PyMODINIT_FUNC PyInit__sweep(void) { return PyModule_Create(&module); }
