/* The stereo ball camera's per-frame steps in one call each (replay/sensors/stereo.py
 * StereoBallCamera.measure, noise-free): the window around the silhouettes, the background fill,
 * exact-coverage compositing, quantising and the blob's moments of one camera (frame); the two
 * triangulations around the sphere's bias correction and the depth checks (locate). They are the
 * kernels of _pixels.c (included here unchanged: py_composite, py_quantise and py_triangulate
 * are called as they are from Python, and blob_of is ball_blob's core), so the results are those of the Python glue they replace, kept in
 * stereo.py as the reference (measure_reference;
 * tests/replay/sensors/test_fast_cameras.py holds the two together). Plain C over the buffer
 * protocol: no NumPy headers.
 */
#include "_pixels.c"
#include "_silhouette.c" /* sphere_outline */

/* call a _pixels kernel with a new argument tuple (stolen); NULL with an exception set */
static PyObject *call(PyObject *(*kernel)(PyObject *, PyObject *), PyObject *args) {
    if (!args) return NULL;
    PyObject *ret = kernel(NULL, args);
    Py_DECREF(args);
    return ret;
}

/* (image, window, blob) of one noise-free camera (see frame below) from the polygons (a list of
 * float64 (n, 2) buffers, far first), their grey levels (a list of floats) and boxes (4 a
 * polygon: umin, vmin, umax, vmax); a new reference, or NULL with an exception set. */
static PyObject *frame_core(PyObject *polys, PyObject *greys, const double *boxes, Py_ssize_t nb,
                            double grey, int W, int H, double thr, int min_pixels, int binary,
                            double default_bg) {
    PyObject *ret = NULL, *image = NULL, *view = NULL, *view8 = NULL, *blob = NULL, *r = NULL;
    float *img = NULL;
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    if (nb) {
        double b[4];
        for (Py_ssize_t i = 0; i < nb; i++) {
            const double *v = boxes + 4 * i;
            for (int k = 0; k < 4; k++)
                if (!isfinite(v[k])) {
                    PyErr_SetString(PyExc_ValueError, "frame: a box is not finite");
                    return NULL;
                }
            if (i == 0) {
                memcpy(b, v, sizeof b);
            } else { /* min/max as Python's min(a, b), max(a, b) */
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
    return ret;
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
    PyObject *ret = NULL;
    Py_ssize_t nb = PySequence_Fast_GET_SIZE(bseq);
    double *b = malloc((size_t)(nb ? nb : 1) * 4 * sizeof(double));
    if (!b) {
        PyErr_NoMemory();
        goto done;
    }
    for (Py_ssize_t i = 0; i < nb; i++) {
        double *v = b + 4 * i;
        if (!PyArg_ParseTuple(PySequence_Fast_GET_ITEM(bseq, i), "dddd", v, v + 1, v + 2, v + 3))
            goto done;
    }
    ret = frame_core(polys, greys, b, nb, grey, W, H, thr, min_pixels, binary, default_bg);
done:
    free(b);
    Py_DECREF(bseq);
    return ret;
}

/* spheres(cams, prims, cos, sin, scale, grey, W, H, threshold, min_pixels, binary, default_bg):
 * frame() of both cameras for a scene of spheres only, their silhouettes drawn here as
 * silhouette.drawables draws them (sphere_polygon, far first by the distance of the centre from
 * the optical centre, ties in scene order): ((image, window, blob), (image, window, blob)).
 * cams: float64 32, per camera R (9, row-major camera-to-world), o (3), fx, fy, cx, cy; prims: a
 * sequence of objects with position (3 floats), radius and albedo; cos, sin, scale: the
 * polygon's tables and area scale (silhouette._COS, _SIN, _AREA_SCALE). */
static PyObject *py_spheres(PyObject *self, PyObject *args) {
    Py_buffer Cm, Ct, St;
    PyObject *prims;
    double scale, grey, thr, default_bg;
    int W, H, min_pixels, binary;
    if (!PyArg_ParseTuple(args, "y*Oy*y*ddiidiid", &Cm, &prims, &Ct, &St, &scale, &grey, &W, &H,
                          &thr, &min_pixels, &binary, &default_bg))
        return NULL;
    PyObject *ret = NULL, *seq = NULL, *out[2] = {NULL, NULL}, *polys = NULL, *greys = NULL;
    double *S = NULL, *poly = NULL, *boxes = NULL, *dist = NULL;
    Py_ssize_t *order = NULL;
    Py_ssize_t nv = Ct.len / (Py_ssize_t)sizeof(double);
    if (!check(&Cm, sizeof(double), 32, "cams") || !check(&St, sizeof(double), nv, "sin"))
        goto done;
    seq = PySequence_Fast(prims, "prims: not a sequence");
    if (!seq) goto done;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq), m = n ? n : 1;
    S = malloc((size_t)m * 5 * sizeof(double));
    poly = malloc((size_t)m * 2 * nv * sizeof(double) + 1);
    boxes = malloc((size_t)m * 4 * sizeof(double));
    dist = malloc((size_t)m * sizeof(double));
    order = malloc((size_t)m * sizeof(Py_ssize_t));
    if (!S || !poly || !boxes || !dist || !order) {
        PyErr_NoMemory();
        goto done;
    }
    for (Py_ssize_t i = 0; i < n; i++) { /* (x, y, z, radius, 255 albedo) */
        PyObject *p = PySequence_Fast_GET_ITEM(seq, i);
        PyObject *pos = PyObject_GetAttrString(p, "position");
        PyObject *rad = pos ? PyObject_GetAttrString(p, "radius") : NULL;
        PyObject *alb = rad ? PyObject_GetAttrString(p, "albedo") : NULL;
        PyObject *xyz = alb ? PySequence_Tuple(pos) : NULL; /* a tuple, list or array */
        int ok = xyz && PyArg_ParseTuple(xyz, "ddd", S + 5 * i, S + 5 * i + 1, S + 5 * i + 2);
        Py_XDECREF(xyz);
        if (ok) {
            S[5 * i + 3] = PyFloat_AsDouble(rad);
            S[5 * i + 4] = 255.0 * PyFloat_AsDouble(alb);
            ok = !PyErr_Occurred();
        }
        Py_XDECREF(pos);
        Py_XDECREF(rad);
        Py_XDECREF(alb);
        if (!ok) goto done;
    }
    const double *cams = Cm.buf;
    for (int c = 0; c < 2; c++) {
        const double *K = cams + 16 * c, *R = K, *o = K + 9;
        Py_ssize_t nd = 0;
        for (Py_ssize_t i = 0; i < n; i++) {
            const double *sp = S + 5 * i;
            if (!sphere_outline(R, o, K[12], K[13], K[14], K[15], sp[0], sp[1], sp[2], sp[3],
                                Ct.buf, St.buf, nv, scale, poly + 2 * nv * i, boxes + 4 * i))
                continue;
            double dx = sp[0] - o[0], dy = sp[1] - o[1], dz = sp[2] - o[2];
            dist[i] = sqrt(dx * dx + dy * dy + dz * dz);
            /* insertion: far first, the earlier of equal distances first */
            Py_ssize_t k = nd++;
            while (k > 0 && dist[order[k - 1]] < dist[i]) {
                order[k] = order[k - 1];
                k--;
            }
            order[k] = i;
        }
        polys = PyList_New(nd);
        greys = polys ? PyList_New(nd) : NULL;
        if (!greys) goto done;
        double *bx = malloc((size_t)(nd ? nd : 1) * 4 * sizeof(double));
        if (!bx) {
            PyErr_NoMemory();
            goto done;
        }
        int ok = 1;
        for (Py_ssize_t k = 0; k < nd && ok; k++) {
            Py_ssize_t i = order[k];
            PyObject *raw = PyMemoryView_FromMemory((char *)(poly + 2 * nv * i),
                                                    (Py_ssize_t)(2 * nv * sizeof(double)),
                                                    PyBUF_READ);
            PyObject *v = raw ? PyObject_CallMethod(raw, "cast", "s", "d") : NULL; /* float64 */
            Py_XDECREF(raw);
            PyObject *g = v ? PyFloat_FromDouble(S[5 * i + 4]) : NULL;
            if (!g) {
                Py_XDECREF(v);
                ok = 0;
                break;
            }
            PyList_SET_ITEM(polys, k, v);
            PyList_SET_ITEM(greys, k, g);
            memcpy(bx + 4 * k, boxes + 4 * i, 4 * sizeof(double));
        }
        if (ok)
            out[c] = frame_core(polys, greys, bx, nd, grey, W, H, thr, min_pixels, binary,
                                default_bg);
        free(bx);
        Py_CLEAR(polys);
        Py_CLEAR(greys);
        if (!out[c]) goto done;
    }
    ret = PyTuple_Pack(2, out[0], out[1]);
done:
    Py_XDECREF(out[0]);
    Py_XDECREF(out[1]);
    Py_XDECREF(polys);
    Py_XDECREF(greys);
    Py_XDECREF(seq);
    free(S);
    free(poly);
    free(boxes);
    free(dist);
    free(order);
    PyBuffer_Release(&Cm);
    PyBuffer_Release(&Ct);
    PyBuffer_Release(&St);
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
    {"spheres", py_spheres, METH_VARARGS, "both cameras' frames of a scene of spheres"},
    {"locate", py_locate, METH_VARARGS, "the ball centre from its two centroids"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef stereo_module = {
    PyModuleDef_HEAD_INIT, "_stereo", "The stereo ball camera's per-frame steps.", -1,
    stereo_methods};

PyMODINIT_FUNC PyInit__stereo(void) { return PyModule_Create(&stereo_module); }
