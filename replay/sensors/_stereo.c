/* The stereo ball camera's per-frame steps in one call each (replay/sensors/stereo.py
 * StereoBallCamera.measure, noise-free): the window around the silhouettes, the background fill,
 * exact-coverage compositing, quantising and the blob's moments of one camera (frame); the two
 * triangulations around the sphere's bias correction and the depth checks (locate). They are the
 * kernels of _pixels.c (included here unchanged: py_composite, py_quantise and py_triangulate
 * are called as they are from Python; its blob helpers make blob_of, ball_blob with the median
 * from a histogram), so the results are those of the Python glue they replace, kept in
 * stereo.py as the reference (measure_reference;
 * tests/replay/sensors/test_fast_cameras.py holds the two together). Plain C over the buffer
 * protocol: no NumPy headers.
 */
#include "_pixels.c"

/* call a _pixels kernel with a new argument tuple (stolen); NULL with an exception set */
static PyObject *call(PyObject *(*kernel)(PyObject *, PyObject *), PyObject *args) {
    if (!args) return NULL;
    PyObject *ret = kernel(NULL, args);
    Py_DECREF(args);
    return ret;
}

/* _pixels.c's ball_blob on a w x h uint8 window img whose first pixel is (ox, oy) of the
 * fw x fh image, with the local background's (upper) median taken from a histogram of the ring's
 * grey levels (O(n), where sorting them was most of the blob's time; the same value: the
 * (n/2)-th smallest). 1 and *out = (u, v, area, background) if found, 0 if not, -1 out of memory. */
static int blob_of(const uint8_t *img, int w, int h, double thr, int min_pixels, int binary,
                   double default_bg, int ox, int oy, int fw, int fh, double *out) {
    int ex0, ey0, ex1, ey1, found = 0;
    if (w == 0 || h == 0 || !bright_box(img, w, h, thr, &ex0, &ey0, &ex1, &ey1)) return 0;
    int32_t *lab = calloc((size_t)w * h, sizeof(int32_t));
    int32_t *stack = malloc((size_t)w * h * sizeof(int32_t));
    double *wt = NULL;
    if (!lab || !stack) goto nomem;
    Blob b = largest_component(img, w, h, thr, ex0, ey0, ex1, ey1, lab, stack);
    if (b.area < min_pixels) goto done;
    if (b.x + ox == 0 || b.y + oy == 0 || b.x + ox + b.w == fw || b.y + oy + b.h == fh)
        goto done; /* cut by the image border */
    int x0 = b.x - 4 > 0 ? b.x - 4 : 0, y0 = b.y - 4 > 0 ? b.y - 4 : 0;
    int x1 = b.x + b.w + 4 < w ? b.x + b.w + 4 : w, y1 = b.y + b.h + 4 < h ? b.y + b.h + 4 : h;
    int bw = x1 - x0, bh = y1 - y0;
    wt = malloc((size_t)bw * bh * sizeof(double) + 2 * (size_t)bw * bh);
    if (!wt) goto nomem;
    uint8_t *near = (uint8_t *)(wt + (size_t)bw * bh), *tmp = near + (size_t)bw * bh;
    dilate_blob(lab, w, b.label, x0, y0, x1, y1, near, tmp);
    double background = NAN;
    if (binary) {
        for (int r = 0; r < bh; r++)
            for (int c = 0; c < bw; c++)
                wt[(size_t)r * bw + c] = lab[(size_t)(r + y0) * w + c + x0] == b.label;
    } else {
        int hist[256] = {0}, nr = 0;
        for (int r = y0; r < y1; r++)
            for (int c = x0; c < x1; c++) {
                int32_t L = lab[(size_t)r * w + c];
                int region = L == b.label ||
                             (L == 0 && near[(size_t)(r - y0) * bw + c - x0]);
                if (!region && L == 0) hist[img[(size_t)r * w + c]]++, nr++;
                wt[(size_t)(r - y0) * bw + c - x0] = region ? 1.0 : 0.0;
            }
        if (nr) {
            int k = 0, seen = hist[0];
            while (seen <= nr / 2) seen += hist[++k];
            background = k;
        } else {
            background = default_bg;
        }
        /* signed weights: zero-mean noise around the blob leaves the centroid unbiased */
        const float bg = (float)background;
        for (int r = 0; r < bh; r++)
            for (int c = 0; c < bw; c++) {
                size_t k = (size_t)r * bw + c;
                wt[k] = wt[k] != 0.0 ? (float)img[(size_t)(r + y0) * w + c + x0] - bg : 0.0f;
            }
    }
    Moments m = moments_of(wt, bw, bh);
    if (m.m00 > 0.0) {
        out[0] = ox + x0 + m.m10 / m.m00, out[1] = oy + y0 + m.m01 / m.m00;
        out[2] = b.area, out[3] = background;
        found = 1;
    }
    goto done;
nomem:
    found = -1;
done:
    free(lab);
    free(stack);
    free(wt);
    return found;
}

/* frame(polys, greys, boxes, grey, W, H, threshold, min_pixels, binary, default_bg):
 * (image, window, blob) of one noise-free camera: window = (x0, y0, x1, y1), the box around the
 * silhouettes' boxes (umin, vmin, umax, vmax) plus 6 px (StereoBallCamera._window), (0, 0, 0, 0)
 * if there are none; image: a bytearray of its (y1 - y0) x (x1 - x0) uint8 pixels, the
 * polygons of grey levels greys composited far first on the grey background and quantised;
 * blob: ball_blob's (u, v, area, background) or None. */
static PyObject *py_frame(PyObject *self, PyObject *args) {
    PyObject *polys, *greys, *boxes;
    double grey, thr, default_bg;
    int W, H, min_pixels, binary;
    if (!PyArg_ParseTuple(args, "OOOdiidiid", &polys, &greys, &boxes, &grey, &W, &H, &thr,
                          &min_pixels, &binary, &default_bg))
        return NULL;
    PyObject *bseq = PySequence_Fast(boxes, "boxes: not a sequence");
    if (!bseq) return NULL;
    PyObject *ret = NULL, *image = NULL, *view = NULL, *view8 = NULL, *blob = NULL, *r = NULL;
    float *img = NULL;
    Py_ssize_t nb = PySequence_Fast_GET_SIZE(bseq);
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    if (nb) {
        double b[4] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
        for (Py_ssize_t i = 0; i < nb; i++) {
            double v[4];
            if (!PyArg_ParseTuple(PySequence_Fast_GET_ITEM(bseq, i), "dddd", v, v + 1, v + 2,
                                  v + 3))
                goto done;
            for (int k = 0; k < 4; k++)
                if (!isfinite(v[k])) {
                    PyErr_SetString(PyExc_ValueError, "frame: a box is not finite");
                    goto done;
                }
            if (i == 0) {
                memcpy(b, v, sizeof b);
            } else {
                b[0] = v[0] < b[0] ? v[0] : b[0], b[1] = v[1] < b[1] ? v[1] : b[1];
                b[2] = v[2] > b[2] ? v[2] : b[2], b[3] = v[3] > b[3] ? v[3] : b[3];
            }
        }
        const int m = 6; /* the polygon's pixels reach 1 px beyond its box, the moments 4 px */
        double fx0 = floor(b[0]) - m, fy0 = floor(b[1]) - m;
        double fx1 = ceil(b[2]) + m + 1, fy1 = ceil(b[3]) + m + 1;
        fx0 = fx0 > 0 ? fx0 : 0, fy0 = fy0 > 0 ? fy0 : 0;
        fx1 = fx1 < W ? fx1 : W, fy1 = fy1 < H ? fy1 : H;
        if (fx1 > fx0 && fy1 > fy0) x0 = (int)fx0, y0 = (int)fy0, x1 = (int)fx1, y1 = (int)fy1;
    }
    int w = x1 - x0, h = y1 - y0;
    image = PyByteArray_FromStringAndSize(NULL, (Py_ssize_t)w * h);
    if (!image) goto done;
    if (w && h) {
        img = malloc((size_t)w * h * sizeof(float));
        if (!img) {
            PyErr_NoMemory();
            goto done;
        }
        const float g = (float)grey; /* np.full(..., grey, np.float32) */
        for (size_t i = 0; i < (size_t)w * h; i++) img[i] = g;
        view = PyMemoryView_FromMemory((char *)img, (Py_ssize_t)(w * h * sizeof(float)),
                                       PyBUF_WRITE);
        view8 = view ? PyMemoryView_FromObject(image) : NULL;
        if (!view8) goto done;
        if (nb) {
            r = call(py_composite, Py_BuildValue("(OOiiOii)", polys, greys, x0, y0, view, w, h));
            if (!r) goto done;
            Py_CLEAR(r);
        }
        r = call(py_quantise, Py_BuildValue("(OO)", view, view8));
        if (!r) goto done;
        Py_CLEAR(r);
        double found[4];
        int got = blob_of((const uint8_t *)PyByteArray_AS_STRING(image), w, h, thr, min_pixels,
                          binary, default_bg, x0, y0, W, H, found);
        if (got < 0) {
            PyErr_NoMemory();
            goto done;
        }
        if (got) {
            blob = Py_BuildValue("(ddid)", found[0], found[1], (int)found[2], found[3]);
            if (!blob) goto done;
        } else {
            Py_INCREF(Py_None);
            blob = Py_None;
        }
    } else {
        Py_INCREF(Py_None);
        blob = Py_None;
    }
    ret = Py_BuildValue("(O(iiii)O)", image, x0, y0, x1, y1, blob);
done:
    Py_XDECREF(view8);
    if (view) { /* the memory view must not outlive img */
        PyObject *rel = PyObject_CallMethod(view, "release", NULL);
        if (!rel) Py_CLEAR(ret);
        Py_XDECREF(rel);
        Py_DECREF(view);
    }
    free(img);
    Py_XDECREF(blob);
    Py_XDECREF(image);
    Py_DECREF(bseq);
    return ret;
}

/* locate(P0, P1, u0, v0, u1, v1, radius, axes, centres): the ball centre (x, y, z) from its
 * centroids in the two images (StereoBallCamera.locate + measure's checks): triangulated; with
 * radius > 0 each centroid scaled back towards its principal point by (Z^2 - r^2) / Z^2 (Z: that
 * camera's depth of the first estimate) and triangulated again; None at infinity, non-finite or
 * behind either camera. axes: float64 12, each camera's optical centre and axis; centres:
 * float64 4, the principal points (cx, cy) of both. */
static PyObject *py_locate(PyObject *self, PyObject *args) {
    PyObject *P0, *P1;
    Py_buffer Ab, Cb;
    double u[2], v[2], radius;
    if (!PyArg_ParseTuple(args, "OOdddddy*y*", &P0, &P1, u, v, u + 1, v + 1, &radius, &Ab, &Cb))
        return NULL;
    PyObject *ret = NULL, *X = NULL;
    if (!check(&Ab, sizeof(double), 12, "axes") || !check(&Cb, sizeof(double), 4, "centres"))
        goto done;
    const double *ax = Ab.buf, *cc = Cb.buf;
    double p[3], z[2];
    for (int pass = 0; pass < 2; pass++) {
        X = call(py_triangulate, Py_BuildValue("(OOdddd)", P0, P1, u[0], v[0], u[1], v[1]));
        if (!X || X == Py_None) goto done;
        if (!PyArg_ParseTuple(X, "ddd", p, p + 1, p + 2)) goto done;
        Py_CLEAR(X);
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) goto none;
        for (int i = 0; i < 2; i++) { /* StereoBallCamera._depth */
            const double *a = ax + 6 * i;
            z[i] = (p[0] - a[0]) * a[3] + (p[1] - a[1]) * a[4] + (p[2] - a[2]) * a[5];
        }
        if (pass == 1 || !(radius > 0.0) || z[0] <= radius || z[1] <= radius) break;
        const double r2 = radius * radius;
        for (int i = 0; i < 2; i++) { /* correct_sphere_centroid */
            double s = (z[i] * z[i] - r2) / (z[i] * z[i]);
            u[i] = cc[2 * i] + (u[i] - cc[2 * i]) * s;
            v[i] = cc[2 * i + 1] + (v[i] - cc[2 * i + 1]) * s;
        }
    }
    if (z[0] <= 0.0 || z[1] <= 0.0) goto none; /* a mismatch behind a camera */
    ret = Py_BuildValue("(ddd)", p[0], p[1], p[2]);
    goto done;
none:
    Py_INCREF(Py_None);
    ret = Py_None;
done:
    if (X == Py_None) {
        ret = X;
        X = NULL;
    }
    Py_XDECREF(X);
    PyBuffer_Release(&Ab);
    PyBuffer_Release(&Cb);
    return ret;
}

static PyMethodDef stereo_methods[] = {
    {"frame", py_frame, METH_VARARGS, "one camera's window, image and blob"},
    {"locate", py_locate, METH_VARARGS, "the ball centre from its two centroids"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef stereo_module = {
    PyModuleDef_HEAD_INIT, "_stereo", "The stereo ball camera's per-frame steps.", -1,
    stereo_methods};

PyMODINIT_FUNC PyInit__stereo(void) { return PyModule_Create(&stereo_module); }
