/* The stick camera's whole noise-free frame in one call (replay/sensors/stick_camera.py
 * StickCamera.measure documents the steps; measure_reference there is the Python glue this
 * replaces, kept as the reference of tests/replay/sensors/test_stick_frame.py): the marker's
 * silhouette and the window around it, the bounding-sphere test of the other primitives, their
 * silhouettes, far-to-near exact-coverage compositing, quantising and the marker's moments. The
 * kernels are _pixels.c's (included here unchanged: py_project_hull is called as it is from
 * Python; accumulate, blend and quantise_c are composite's and quantise's cores;
 * marker_moments_fast is py_marker_moments with less work), so the pixels and the moments are
 * those of the Python path to the bit; the primitives are read from the scene and the pose
 * worked out from the moments here too (py_measure). Plain C over the buffer protocol: no NumPy
 * headers.
 */
#include "_pixels.c"

/* _pixels.c marker_moments on the uint8 window img (w x h, whose first pixel is (ox, oy) of the
 * fw x fh image), the same numbers by the same operations in the same order, with less work:
 * the threshold compared as an integer (for a uint8 v, v > thr is v > floor(thr)), and the sums
 * of the moments taken over the pixels of nonzero weight only (a zero weight adds +-0 to a sum
 * of non-negative or mixed terms, which changes no sum but +-0 itself: never, as each sum
 * starts at +0 and +0 + -0 = +0). py_marker_moments is its reference
 * (tests/replay/sensors/test_stick_frame.py); the returned tuple is its. */
typedef struct {
    int c, r;   /* box-local pixel */
    double v;   /* weight */
} Weight;

static Moments moments_sparse(const Weight *wt, int n) {
    Moments m = {0, 0, 0, 0, 0, 0};
    for (int i = 0; i < n; i++) {
        double v = wt[i].v;
        m.m00 += v, m.m10 += v * wt[i].c, m.m01 += v * wt[i].r;
    }
    if (m.m00 == 0.0) return m;
    double cx = m.m10 / m.m00, cy = m.m01 / m.m00;
    for (int i = 0; i < n; i++) {
        double v = wt[i].v, dx = wt[i].c - cx, dy = wt[i].r - cy;
        m.mu20 += v * dx * dx, m.mu11 += v * dx * dy, m.mu02 += v * dy * dy;
    }
    return m;
}

static PyObject *marker_moments_fast(const uint8_t *img, int w, int h, double thr,
                                     int min_pixels, int ox, int oy, int fw, int fh) {
    PyObject *ret = NULL;
    int32_t *lab = NULL, *stack = NULL;
    uint8_t *near = NULL;
    Weight *wt = NULL;
    if (w == 0 || h == 0 || isnan(thr) || thr >= 255.0) goto none;
    const int ti = thr < 0.0 ? -1 : (int)floor(thr); /* v > thr <=> v > ti */
    int ex0 = w, ey0 = h, ex1 = -1, ey1 = -1;         /* bright_box */
    for (int r = 0; r < h; r++) {
        const uint8_t *row = img + (size_t)r * w;
        int lo = -1, hi = -1;
        for (int c = 0; c < w; c++)
            if (row[c] > ti) {
                if (lo < 0) lo = c;
                hi = c;
            }
        if (lo < 0) continue;
        if (lo < ex0) ex0 = lo;
        if (hi > ex1) ex1 = hi;
        if (r < ey0) ey0 = r;
        ey1 = r;
    }
    if (ex1 < 0) goto none;
    lab = calloc((size_t)w * h, sizeof(int32_t));
    stack = malloc((size_t)w * h * sizeof(int32_t));
    if (!lab || !stack) goto nomem;
    Blob b = largest_component(img, w, h, thr, ex0, ey0, ex1 + 1, ey1 + 1, lab, stack);
    if (b.area < min_pixels) goto none;
    if (cut_by_border(b, ox, oy, fw, fh)) goto none;
    int x0, y0, x1, y1;
    grown_box(b, 3, w, h, &x0, &y0, &x1, &y1);
    int bw = x1 - x0, bh = y1 - y0;
    near = malloc(2 * (size_t)bw * bh);
    wt = malloc((size_t)bw * bh * sizeof(Weight));
    if (!near || !wt) goto nomem;
    dilate_blob(lab, w, b.label, x0, y0, x1, y1, near, near + (size_t)bw * bh);
    /* the blob's binary moments (weights 1, in raster order) */
    int n = 0;
    for (int r = 0; r < bh; r++) {
        const int32_t *row = lab + (size_t)(r + y0) * w + x0;
        for (int c = 0; c < bw; c++)
            if (row[c] == b.label) wt[n].c = c, wt[n].r = r, wt[n].v = 1.0, n++;
    }
    Moments mb = moments_sparse(wt, n);
    double a = 0.5 * atan2(2.0 * mb.mu11, mb.mu20 - mb.mu02);
    double ex = cos(a), ey = sin(a);
    double cx = x0 + mb.m10 / mb.m00, cy = y0 + mb.m01 / mb.m00;
    double amax = -INFINITY, amin = INFINITY;
    for (int i = 0; i < n; i++) {
        double al = (wt[i].c + x0 - cx) * ex + (wt[i].r + y0 - cy) * ey;
        if (al > amax) amax = al;
        if (al < amin) amin = al;
    }
    /* the background: as py_marker_moments */
    double background;
    if (!marker_background(img, w, h, cx, cy, ex, ey, amax, amin, &background)) goto none;
    /* the grey level above the background within the blob dilated by 2 px */
    const float bg = (float)background;
    n = 0;
    for (int r = 0; r < bh; r++) {
        const uint8_t *row = img + (size_t)(r + y0) * w + x0, *nr = near + (size_t)r * bw;
        for (int c = 0; c < bw; c++)
            if (nr[c]) {
                float d = (float)row[c] - bg;
                if (d > 0.0f) wt[n].c = c, wt[n].r = r, wt[n].v = d, n++;
            }
    }
    Moments m = moments_sparse(wt, n);
    if (m.m00 <= 0.0) goto none;
    ret = marker_result(m, ox, oy, x0, y0, b.area, background);
    goto done;
nomem:
    PyErr_NoMemory();
    goto done;
none:
    Py_INCREF(Py_None);
    ret = Py_None;
done:
    free(lab);
    free(stack);
    free(near);
    free(wt);
    return ret;
}

/* moments(img, w, h, threshold, min_pixels, ox, oy, full_w, full_h): marker_moments_fast, for
 * its test against _pixels.marker_moments (the same arguments and result) */
static PyObject *py_moments(PyObject *self, PyObject *args) {
    Py_buffer I;
    int w, h, min_pixels, ox, oy, fw, fh;
    double thr;
    if (!PyArg_ParseTuple(args, "y*iidiiiii", &I, &w, &h, &thr, &min_pixels, &ox, &oy, &fw, &fh))
        return NULL;
    PyObject *ret = NULL;
    if (sizes_ok(w, h) && check(&I, 1, (Py_ssize_t)w * h, "img"))
        ret = marker_moments_fast(I.buf, w, h, thr, min_pixels, ox, oy, fw, fh);
    PyBuffer_Release(&I);
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

/* The frame of the primitives prims[0..n) (marker: the marker's index) seen by the camera (R:
 * float64 3 x 3, camera to world, row-major; o: float64 (3,), its position; fx, fy, cx, cy;
 * width W x height H): (image, (x0, y0, x1, y1), moments): the quantised window (a bytearray,
 * rows of x1 - x0 pixels), the window and _pixels.marker_moments of it (marker_moments_fast; or
 * None); or None when the marker has no silhouette or no window (the caller's reference path
 * does that rare frame: the whole image). A new reference, or NULL with an exception set. */
static PyObject *frame_core(Prim *prims, Py_ssize_t n, int marker, PyObject *R, PyObject *o,
                            double fx, double fy, double cx, double cy, int W, int H,
                            double background, double thr, int min_pixels) {
    PyObject *ret = NULL, *image = NULL, *found = NULL;
    float *img = NULL;
    double *acc = NULL;
    Py_buffer RB = {0}, OB = {0};
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
        int bad = accumulate(P.buf, p->count, win[0], win[1], acc, w, h, &r0, &r1, &c0, &c1);
        PyBuffer_Release(&P);
        if (bad) goto done; /* a vertex it refused: ValueError set */
        blend(acc, img, w, r0, r1, c0, c1, (float)(255.0 * p->albedo));
    }
    uint8_t *out = (uint8_t *)PyByteArray_AS_STRING(image);
    quantise_c(img, out, (size_t)w * h);

    /* the marker's moments */
    found = marker_moments_fast(out, w, h, thr, min_pixels, win[0], win[1], W, H);
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
    return ret;
}


static PyObject *s_position, *s_orientation, *s_albedo, *s_name, *s_size, *s_radius, *s_length;

/* stick_camera.StickCamera._to_height: world (x, y) where pixel (u, v)'s ray meets the plane at
 * height z (the same operations); 0 when it does not */
static int to_height(const double *R, const double *o, double fx, double fy, double cx,
                     double cy, double u, double v, double z, double *x, double *y) {
    double a = (u - cx) / fx, b = (v - cy) / fy;
    double dx = R[0] * a + R[1] * b + R[2], dy = R[3] * a + R[4] * b + R[5],
           dz = R[6] * a + R[7] * b + R[8];
    double nn = sqrt(dx * dx + dy * dy + dz * dz);
    double s = dz != 0.0 ? (z - o[2]) / dz : NAN;
    if (!(fabs(dz / nn) > 1e-12 && s > 0.0)) return 0;
    *x = o[0] + s * dx, *y = o[1] + s * dy;
    return 1;
}

/* measure(prims, shapes, camera): StickCamera.measure's noise-free frame of scene.primitives
 * prims in one call: each primitive's (body points, bounding radius, hull buffer) from the dict
 * shapes by the key (i, Box, size) or (i, Cylinder, radius, length), its distance from the
 * camera by camera's dist (math.dist), the marker the first primitive named so, frame_core and
 * the pose (StickCamera._pose: the centroid and a point 10 px along the axis back-projected
 * onto the marker's height, theta wrapped to (-pi/2, pi/2], the offset added). camera: (R, o,
 * fx, fy, cx, cy, width, height, background, threshold, min_pixels, marker name, Box,
 * Cylinder, o as a tuple, dist, offset x, offset y). Returns (image, window, moments, pose or
 * None); (None, i, key) when shapes has no entry for primitive i yet (the caller adds it and
 * calls again); None for the reference path (another primitive type, no marker, or frame_core's
 * None). */
static PyObject *py_measure(PyObject *self, PyObject *args) {
    PyObject *prims_in, *shapes, *camera;
    if (!PyArg_ParseTuple(args, "OO!O!", &prims_in, &PyDict_Type, &shapes, &PyTuple_Type,
                          &camera))
        return NULL;
    PyObject *R, *o, *name, *box_t, *cyl_t, *o_tuple, *dist;
    double fx, fy, cx, cy, background, thr, off_x, off_y;
    int W, H, min_pixels;
    if (!PyArg_ParseTuple(camera, "OOddddiiddiOOOOOdd", &R, &o, &fx, &fy, &cx, &cy, &W, &H,
                          &background, &thr, &min_pixels, &name, &box_t, &cyl_t, &o_tuple,
                          &dist, &off_x, &off_y))
        return NULL;
    PyObject *seq = PySequence_Fast(prims_in, "prims: not a sequence");
    if (!seq) return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    PyObject *ret = NULL, *framed = NULL, *owned[2 * MAX_PRIMS];
    int n_owned = 0, marker = -1;
    Prim prims[MAX_PRIMS];
    if (n > MAX_PRIMS) goto reference;
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *prim = PySequence_Fast_GET_ITEM(seq, i), *key;
        Prim *p = &prims[i];
        if ((PyObject *)Py_TYPE(prim) == box_t) {
            PyObject *size = PyObject_GetAttr(prim, s_size);
            key = size ? Py_BuildValue("(nON)", i, box_t, size) : NULL;
        } else if ((PyObject *)Py_TYPE(prim) == cyl_t) {
            PyObject *r = PyObject_GetAttr(prim, s_radius);
            PyObject *l = r ? PyObject_GetAttr(prim, s_length) : NULL;
            key = l ? Py_BuildValue("(nONN)", i, cyl_t, r, l) : NULL;
            if (!l) Py_XDECREF(r);
        } else {
            goto reference; /* a sphere: the reference path */
        }
        if (!key) goto done;
        PyObject *shape = PyDict_GetItemWithError(shapes, key); /* borrowed */
        if (!shape) {
            if (!PyErr_Occurred()) ret = Py_BuildValue("(OnO)", Py_None, i, key);
            Py_DECREF(key);
            goto done;
        }
        Py_DECREF(key);
        if (!PyArg_ParseTuple(shape, "OdO", &p->body, &p->rb, &p->out)) goto done;
        p->pos = owned[n_owned++] = PyObject_GetAttr(prim, s_position);
        if (!p->pos) goto done;
        p->q = owned[n_owned++] = PyObject_GetAttr(prim, s_orientation);
        if (!p->q) goto done;
        PyObject *albedo = PyObject_GetAttr(prim, s_albedo);
        if (!albedo) goto done;
        p->albedo = PyFloat_AsDouble(albedo);
        Py_DECREF(albedo);
        if (p->albedo == -1.0 && PyErr_Occurred()) goto done;
        PyObject *d = PyObject_CallFunctionObjArgs(dist, p->pos, o_tuple, NULL);
        if (!d) goto done;
        p->distance = PyFloat_AsDouble(d);
        Py_DECREF(d);
        if (p->distance == -1.0 && PyErr_Occurred()) goto done;
        if (marker < 0) {
            PyObject *pname = PyObject_GetAttr(prim, s_name);
            if (!pname) goto done;
            int same = PyObject_RichCompareBool(pname, name, Py_EQ);
            Py_DECREF(pname);
            if (same < 0) goto done;
            if (same) marker = (int)i;
        }
    }
    if (marker < 0) goto reference;
    framed = frame_core(prims, n, marker, R, o, fx, fy, cx, cy, W, H, background, thr,
                        min_pixels);
    if (!framed) goto done;
    if (framed == Py_None) goto reference;
    PyObject *image = PyTuple_GET_ITEM(framed, 0), *window = PyTuple_GET_ITEM(framed, 1),
             *found = PyTuple_GET_ITEM(framed, 2);
    PyObject *pose = Py_None;
    Py_INCREF(pose);
    if (found != Py_None) { /* StickCamera._pose */
        Py_buffer RB, OB;
        double u = PyFloat_AS_DOUBLE(PyTuple_GET_ITEM(found, 0)),
               v = PyFloat_AS_DOUBLE(PyTuple_GET_ITEM(found, 1)),
               a = PyFloat_AS_DOUBLE(PyTuple_GET_ITEM(found, 2));
        PyObject *zo = PySequence_GetItem(prims[marker].pos, 2);
        double z = zo ? PyFloat_AsDouble(zo) : -1.0;
        Py_XDECREF(zo);
        if ((z == -1.0 && PyErr_Occurred()) || PyObject_GetBuffer(R, &RB, PyBUF_C_CONTIGUOUS) < 0) {
            Py_DECREF(pose);
            goto done;
        }
        if (PyObject_GetBuffer(o, &OB, PyBUF_C_CONTIGUOUS) < 0) {
            PyBuffer_Release(&RB);
            Py_DECREF(pose);
            goto done;
        }
        const double step = 10.0; /* px along the axis, for its angle */
        double x0, y0, x1, y1;
        if (to_height(RB.buf, OB.buf, fx, fy, cx, cy, u, v, z, &x0, &y0) &&
            to_height(RB.buf, OB.buf, fx, fy, cx, cy, u + step * cos(a), v + step * sin(a), z,
                      &x1, &y1)) {
            double th = fmod(atan2(y1 - y0, x1 - x0), M_PI); /* spatial.wrap_half_pi */
            if (th <= -M_PI / 2.0)
                th += M_PI;
            else if (th > M_PI / 2.0)
                th -= M_PI;
            Py_DECREF(pose);
            pose = Py_BuildValue("(ddd)", x0 + off_x, y0 + off_y, th);
        }
        PyBuffer_Release(&RB);
        PyBuffer_Release(&OB);
        if (!pose) goto done;
    }
    ret = Py_BuildValue("(OOON)", image, window, found, pose);
    goto done;
reference:
    Py_INCREF(Py_None);
    ret = Py_None;
done:
    Py_XDECREF(framed);
    for (int i = 0; i < n_owned; i++) Py_XDECREF(owned[i]);
    Py_DECREF(seq);
    return ret;
}

static PyMethodDef stick_frame_methods[] = {
    {"measure", py_measure, METH_VARARGS, "the stick camera's noise-free frame and pose"},
    {"moments", py_moments, METH_VARARGS, "_pixels.marker_moments with less work"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef stick_frame_module = {
    PyModuleDef_HEAD_INIT, "_stick_frame", "The stick camera's whole frame in one call.", -1,
    stick_frame_methods};

PyMODINIT_FUNC PyInit__stick_frame(void) {
    const char *names[] = {"position", "orientation", "albedo", "name", "size", "radius", "length"};
    PyObject **slots[] = {&s_position, &s_orientation, &s_albedo, &s_name,
                          &s_size,     &s_radius,      &s_length};
    for (int i = 0; i < 7; i++)
        if (!(*slots[i] = PyUnicode_InternFromString(names[i]))) return NULL;
    return PyModule_Create(&stick_frame_module);
}
