/* The stick camera's whole noise-free frame in one call (replay/sensors/stick_camera.py
 * StickCamera.measure documents the steps; measure_reference there is the Python glue this
 * replaces, kept as the reference of tests/replay/sensors/test_stick_frame.py): the marker's
 * silhouette and the window around it, the bounding-sphere test of the other primitives, their
 * silhouettes, far-to-near exact-coverage compositing, quantising and the marker's moments. The
 * kernels are _pixels.c's (included here unchanged: py_project_hull and py_marker_moments are
 * called as they are from Python, accumulate is composite's core), so the pixels and the moments
 * are those of the Python path to the bit. Plain C over the buffer protocol: no NumPy headers.
 */
#include "_pixels.c"

/* call a _pixels kernel with a new argument tuple (stolen); NULL with an exception set */
static PyObject *call_kernel(PyObject *(*kernel)(PyObject *, PyObject *), PyObject *args) {
    if (!args) return NULL;
    PyObject *ret = kernel(NULL, args);
    Py_DECREF(args);
    return ret;
}

typedef struct {
    PyObject *body, *q, *pos, *out; /* borrowed: body points, quaternion, position, hull buffer */
    double albedo, rb, distance, box[4];
    Py_ssize_t count; /* hull vertices in out */
} Prim;

/* the silhouette of p (stick_camera._silhouette): 1 with p->count, p->box set, 0 when it has
 * none (behind the camera or fewer than 3 hull vertices), -1 with an exception set */
static int silhouette(Prim *p, PyObject *R, PyObject *o, double fx, double fy, double cx,
                      double cy) {
    PyObject *found = call_kernel(
        py_project_hull, Py_BuildValue("(OOOOOddddO)", p->body, p->q, p->pos, R, o, fx, fy, cx,
                                       cy, p->out));
    if (!found) return -1;
    if (found == Py_None) {
        Py_DECREF(found);
        return 0;
    }
    int ok = PyArg_ParseTuple(found, "ndddd", &p->count, &p->box[0], &p->box[1], &p->box[2],
                              &p->box[3]);
    Py_DECREF(found);
    if (!ok) return -1;
    return p->count >= 3;
}

/* stick_camera._misses: whether a primitive at (px, py, pz) with bounding radius rb certainly
 * draws nothing in the window, the same operations in the same order */
static int misses(const double *R, const double *o, double px, double py, double pz, double rb,
                  double fx, double fy, double cx, double cy, const int *win) {
    double dx = px - o[0], dy = py - o[1], dz = pz - o[2];
    double X = R[0] * dx + R[3] * dy + R[6] * dz; /* R^T d, R row-major */
    double Y = R[1] * dx + R[4] * dy + R[7] * dz;
    double Z = R[2] * dx + R[5] * dy + R[8] * dz;
    if (Z - rb <= 1e-6) return 0;
    double u = fx * X / Z + cx, v = fy * Y / Z + cy;
    double g = rb / ((Z - rb) * Z);
    double bu = fx * g * (Z + fabs(X)) + 1.0, bv = fy * g * (Z + fabs(Y)) + 1.0;
    return u + bu < win[0] - 1 || v + bv < win[1] - 1 || u - bu > win[2] || v - bv > win[3];
}

static int get_point(PyObject *seq, double *out, Py_ssize_t n, const char *what) {
    PyObject *f = PySequence_Fast(seq, what);
    if (!f) return 0;
    if (PySequence_Fast_GET_SIZE(f) != n) {
        Py_DECREF(f);
        PyErr_Format(PyExc_ValueError, "%s: %zd numbers expected", what, n);
        return 0;
    }
    for (Py_ssize_t i = 0; i < n; i++) {
        out[i] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(f, i));
        if (out[i] == -1.0 && PyErr_Occurred()) {
            Py_DECREF(f);
            return 0;
        }
    }
    Py_DECREF(f);
    return 1;
}

#define MAX_PRIMS 64

/* frame(prims, marker, R, o, fx, fy, cx, cy, width, height, background, threshold,
 *       min_pixels): prims a sequence of (body, q, position, albedo, rb, distance, out) (body
 * points float64 (n, 3), quaternion, position, albedo, bounding-sphere radius, distance of the
 * centre from the camera, a float64 (n, 2) scratch buffer for the hull), marker the index of
 * the marker's; R (float64 3 x 3, camera to world, row-major) and o (float64 (3,)) the camera's
 * rotation and position. Returns (image, (x0, y0, x1, y1), moments): the quantised window
 * (a bytearray, rows of x1 - x0 pixels), the window and _pixels.marker_moments of it (or None);
 * or None when the marker has no silhouette or no window (the caller's reference path does
 * that rare frame: the whole image). */
static PyObject *py_frame(PyObject *self, PyObject *args) {
    PyObject *prims_in, *R, *o;
    int marker, W, H, min_pixels;
    double fx, fy, cx, cy, background, thr;
    if (!PyArg_ParseTuple(args, "OiOOddddiiddi", &prims_in, &marker, &R, &o, &fx, &fy, &cx, &cy,
                          &W, &H, &background, &thr, &min_pixels))
        return NULL;
    PyObject *seq = PySequence_Fast(prims_in, "prims: not a sequence");
    if (!seq) return NULL;
    PyObject *ret = NULL, *image = NULL, *found = NULL;
    float *img = NULL;
    double *acc = NULL;
    Py_buffer RB = {0}, OB = {0};
    Prim prims[MAX_PRIMS];
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    if (n > MAX_PRIMS) {
        PyErr_Format(PyExc_ValueError, "frame: at most %d primitives", MAX_PRIMS);
        goto done;
    }
    if (marker < 0 || marker >= n) {
        PyErr_SetString(PyExc_IndexError, "frame: marker index out of range");
        goto done;
    }
    for (Py_ssize_t i = 0; i < n; i++) {
        Prim *p = &prims[i];
        if (!PyArg_ParseTuple(PySequence_Fast_GET_ITEM(seq, i), "OOOdddO", &p->body, &p->q,
                              &p->pos, &p->albedo, &p->rb, &p->distance, &p->out))
            goto done;
    }
    if (PyObject_GetBuffer(R, &RB, PyBUF_C_CONTIGUOUS) < 0 ||
        PyObject_GetBuffer(o, &OB, PyBUF_C_CONTIGUOUS) < 0)
        goto done;
    if (!check(&RB, sizeof(double), 9, "R") || !check(&OB, sizeof(double), 3, "o")) goto done;
    const double *Rm = RB.buf, *om = OB.buf;

    /* the marker's silhouette and the window around it (stick_camera.hull_window, margin 8) */
    Prim *mk = &prims[marker];
    int seen = silhouette(mk, R, o, fx, fy, cx, cy);
    if (seen < 0) goto done;
    if (!seen) goto reference;
    const int margin = 8;
    double b0 = floor(mk->box[0]) - margin, b1 = floor(mk->box[1]) - margin;
    double b2 = ceil(mk->box[2]) + margin + 1, b3 = ceil(mk->box[3]) + margin + 1;
    if (!(isfinite(b0) && isfinite(b1) && isfinite(b2) && isfinite(b3))) goto reference;
    b0 = b0 > 0 ? b0 : 0, b1 = b1 > 0 ? b1 : 0;
    b2 = b2 < W ? b2 : W, b3 = b3 < H ? b3 : H;
    if (b2 <= b0 || b3 <= b1) goto reference;
    int win[4] = {(int)b0, (int)b1, (int)b2, (int)b3};

    /* the primitives that may draw in it, far first (a stable sort by distance, descending) */
    Prim *items[MAX_PRIMS];
    int ni = 0;
    for (Py_ssize_t i = 0; i < n; i++) {
        Prim *p = &prims[i];
        if (i != marker) {
            double pos[3];
            if (!get_point(p->pos, pos, 3, "position")) goto done;
            if (misses(Rm, om, pos[0], pos[1], pos[2], p->rb, fx, fy, cx, cy, win)) continue;
            int s = silhouette(p, R, o, fx, fy, cx, cy);
            if (s < 0) goto done;
            if (!s) continue;
        }
        int j = ni++;
        while (j > 0 && -p->distance < -items[j - 1]->distance) {
            items[j] = items[j - 1];
            j--;
        }
        items[j] = p;
    }

    /* render (render_scene and raster.composite) and quantise */
    const int w = win[2] - win[0], h = win[3] - win[1];
    img = malloc((size_t)w * h * sizeof(float));
    acc = calloc((size_t)h * (w + 1) + 1, sizeof(double));
    image = PyByteArray_FromStringAndSize(NULL, (Py_ssize_t)w * h);
    if (!img || !acc) {
        PyErr_NoMemory();
        goto done;
    }
    if (!image) goto done;
    const float fill = (float)(255.0 * background);
    for (size_t i = 0; i < (size_t)w * h; i++) img[i] = fill;
    for (int it = 0; it < ni; it++) {
        const Prim *p = items[it];
        const double *bx = p->box;
        if (bx[2] < win[0] - 1 || bx[3] < win[1] - 1 || bx[0] > win[2] || bx[1] > win[3])
            continue; /* wholly outside the window */
        Py_buffer P;
        if (PyObject_GetBuffer(p->out, &P, PyBUF_C_CONTIGUOUS) < 0) goto done;
        int r0, r1, c0, c1;
        accumulate(P.buf, p->count, win[0], win[1], acc, w, h, &r0, &r1, &c0, &c1);
        PyBuffer_Release(&P);
        const float grey = (float)(255.0 * p->albedo);
        for (int r = r0; r < r1; r++) { /* py_composite's loop */
            double *row = acc + (size_t)r * (w + 1);
            float *px = img + (size_t)r * w;
            double s = 0.0;
            for (int c = c0; c < c1; c++) {
                s += row[c];
                row[c] = 0.0;
                if (s > 0.0) {
                    float a = (float)(s < 1.0 ? s : 1.0);
                    px[c] += a * (grey - px[c]);
                }
            }
            row[c1] = 0.0;
        }
    }
    uint8_t *out = (uint8_t *)PyByteArray_AS_STRING(image);
    for (size_t i = 0; i < (size_t)w * h; i++) { /* py_quantise's loop */
        float v = img[i];
        if (!(v > 0.0f))
            out[i] = 0;
        else if (v >= 255.0f)
            out[i] = 255;
        else {
            float t = v + 12582912.0f;
            out[i] = (uint8_t)(t - 12582912.0f);
        }
    }

    /* the marker's moments */
    found = call_kernel(py_marker_moments, Py_BuildValue("(Oiidiiiii)", image, w, h, thr,
                                                         min_pixels, win[0], win[1], W, H));
    if (!found) goto done;
    ret = Py_BuildValue("(O(iiii)O)", image, win[0], win[1], win[2], win[3], found);
    goto done;
reference:
    Py_INCREF(Py_None);
    ret = Py_None;
done:
    free(img);
    free(acc);
    Py_XDECREF(image);
    Py_XDECREF(found);
    if (RB.obj) PyBuffer_Release(&RB);
    if (OB.obj) PyBuffer_Release(&OB);
    Py_DECREF(seq);
    return ret;
}

static PyMethodDef stick_frame_methods[] = {
    {"frame", py_frame, METH_VARARGS, "the stick camera's noise-free frame and marker moments"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef stick_frame_module = {
    PyModuleDef_HEAD_INIT, "_stick_frame", "The stick camera's whole frame in one call.", -1,
    stick_frame_methods};

PyMODINIT_FUNC PyInit__stick_frame(void) { return PyModule_Create(&stick_frame_module); }
