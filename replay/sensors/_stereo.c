/* The stereo ball camera's per-frame steps (replay/sensors/stereo.py StereoBallCamera.measure,
 * noise-free): a scene of spheres in one call (measure: both cameras' silhouettes, windows,
 * images and blobs and the ball centre), other scenes one camera's window, image and blob from
 * its polygons (frame) and the ball centre (locate): the window around the silhouettes, the
 * background fill, exact-coverage compositing, quantising, the blob's moments, the two
 * triangulations around the sphere's bias correction and the depth checks. They are the kernels
 * of _pixels.c (included here unchanged: accumulate, blob_of and py_triangulate as they are;
 * composite_one is accumulate and blend, py_composite's core; quantise_c py_quantise's), so the
 * results are those of the Python glue they replace, kept in stereo.py as the reference
 * (measure_reference; tests/replay/sensors/test_fast_cameras.py holds the two together, to the
 * bit). Plain C over the buffer protocol: no NumPy headers.
 */
#include "_pixels.c"
#include "_silhouette.c" /* sphere_outline */

/* py_composite's compositing of one polygon (n vertices xy, full-image pixels) of grey level
 * grey onto img (h x w, first pixel (ox, oy)) over C arrays: the same accumulate and blend.
 * acc: h (w + 1) + 1 zeros, left zero. The rows and columns it may change are added to the box
 * touched (r0, r1, c0, c1; empty when r0 >= r1). */
static void composite_one(const double *xy, Py_ssize_t n, double greyd, int ox, int oy,
                          float *img, int w, int h, double *acc, int touched[4]) {
    if (n < 3) return;
    int r0, r1, c0, c1;
    if (accumulate(xy, n, ox, oy, acc, w, h, &r0, &r1, &c0, &c1) < 0) return; /* (error set) */
    if (r0 < r1 && c0 < c1) {
        if (touched[0] >= touched[1]) {
            touched[0] = r0, touched[1] = r1, touched[2] = c0, touched[3] = c1;
        } else {
            touched[0] = r0 < touched[0] ? r0 : touched[0];
            touched[1] = r1 > touched[1] ? r1 : touched[1];
            touched[2] = c0 < touched[2] ? c0 : touched[2];
            touched[3] = c1 > touched[3] ? c1 : touched[3];
        }
    }
    blend(acc, img, w, r0, r1, c0, c1, (float)greyd);
}

typedef struct {
    PyObject *image; /* a bytearray of the window's uint8 pixels (a new reference) */
    int window[4];   /* x0, y0, x1, y1 */
    int got;         /* whether blob holds a blob */
    double blob[4];  /* u, v, area, background */
} Frame;

/* One noise-free camera: the window around the polygons' boxes (4 a polygon: umin, vmin, umax,
 * vmax) plus 6 px (StereoBallCamera._window), (0, 0, 0, 0) if there are none; the polygons
 * (npoly of nv[i] vertices xy[i], grey levels greys[i]) composited far first on the grey
 * background and quantised (py_composite, py_quantise); blob_of's blob. 0, or -1 with an
 * exception set. */
static int frame_c(const double *const *xy, const Py_ssize_t *nv, const double *greys,
                   const double *boxes, Py_ssize_t nb, double grey, int W, int H, double thr,
                   int min_pixels, int binary, double default_bg, Frame *f) {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    f->image = NULL;
    f->got = 0;
    if (nb) {
        double b[4];
        for (Py_ssize_t i = 0; i < nb; i++) {
            const double *v = boxes + 4 * i;
            for (int k = 0; k < 4; k++)
                if (!isfinite(v[k])) {
                    PyErr_SetString(PyExc_ValueError, "frame: a box is not finite");
                    return -1;
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
    f->window[0] = x0, f->window[1] = y0, f->window[2] = x1, f->window[3] = y1;
    f->image = PyByteArray_FromStringAndSize(NULL, (Py_ssize_t)w * h);
    if (!f->image) return -1;
    if (!w || !h) return 0;
    size_t np = (size_t)w * h;
    size_t nacc = (size_t)h * (w + 1) + 1, pad = np & 1; /* acc 8-byte aligned after img */
    float *img = malloc((np + pad) * sizeof(float) + nacc * sizeof(double));
    if (!img) goto nomem;
    double *acc = (double *)(img + np + pad);
    const float g = (float)grey; /* np.full(..., grey, np.float32) */
    for (size_t i = 0; i < np; i++) img[i] = g;
    int box[4] = {0, 0, 0, 0}; /* the pixels the polygons may change */
    if (nb) {
        memset(acc, 0, nacc * sizeof(double));
        for (Py_ssize_t i = 0; i < nb; i++)
            composite_one(xy[i], nv[i], greys[i], x0, y0, img, w, h, acc, box);
        if (PyErr_Occurred()) { /* a vertex accumulate refused */
            free(img);
            Py_CLEAR(f->image);
            return -1;
        }
    }
    /* quantised: the background's level outside the box (its pixels are g there, unchanged) */
    uint8_t *img8 = (uint8_t *)PyByteArray_AS_STRING(f->image), qg;
    quantise_c(&g, &qg, 1);
    memset(img8, qg, np);
    for (int r = box[0]; r < box[1]; r++)
        quantise_c(img + (size_t)r * w + box[2], img8 + (size_t)r * w + box[2],
                   (size_t)(box[3] - box[2]));
    free(img);
    int got = blob_of(img8, w, h, thr, min_pixels, binary, default_bg, x0, y0, W, H, f->blob);
    if (got < 0) goto nomem;
    f->got = got;
    return 0;
nomem:
    PyErr_NoMemory();
    Py_CLEAR(f->image);
    return -1;
}

/* A tuple of n new references (stolen, all of them even when one is NULL: then NULL with the
 * exception set) */
static PyObject *tuple_of(Py_ssize_t n, PyObject **items) {
    PyObject *t = NULL;
    for (Py_ssize_t k = 0; k < n; k++)
        if (!items[k]) goto fail;
    if (!(t = PyTuple_New(n))) goto fail;
    for (Py_ssize_t k = 0; k < n; k++) PyTuple_SET_ITEM(t, k, items[k]);
    return t;
fail:
    for (Py_ssize_t k = 0; k < n; k++) Py_XDECREF(items[k]);
    return NULL;
}

/* A frame_c's image (its reference taken), (x0, y0, x1, y1) and blob (u, v, area, background)
 * or None into out[3] as new references (NULL where one could not be made) */
static void frame_items(Frame *f, PyObject **out) {
    PyObject *win[4], *blob[4];
    for (int k = 0; k < 4; k++) win[k] = PyLong_FromLong(f->window[k]);
    out[0] = f->image;
    f->image = NULL;
    out[1] = tuple_of(4, win);
    if (f->got) {
        blob[0] = PyFloat_FromDouble(f->blob[0]);
        blob[1] = PyFloat_FromDouble(f->blob[1]);
        blob[2] = PyLong_FromLong((long)f->blob[2]);
        blob[3] = PyFloat_FromDouble(f->blob[3]);
        out[2] = tuple_of(4, blob);
    } else {
        out[2] = Py_NewRef(Py_None);
    }
}

/* (image, (x0, y0, x1, y1), blob or None) of a frame_c; a new reference (the image's is
 * taken), NULL with an exception set */
static PyObject *frame_tuple(Frame *f) {
    PyObject *items[3];
    frame_items(f, items);
    return tuple_of(3, items);
}

/* frame(polys, greys, boxes, grey, W, H, threshold, min_pixels, binary, default_bg):
 * (image, window, blob) of one noise-free camera: window = (x0, y0, x1, y1), the box around the
 * silhouettes' boxes (umin, vmin, umax, vmax) plus 6 px (StereoBallCamera._window), (0, 0, 0, 0)
 * if there are none; image: a bytearray of its (y1 - y0) x (x1 - x0) uint8 pixels, the
 * polygons (float64 (n, 2) buffers) of grey levels greys composited far first on the grey
 * background and quantised; blob: ball_blob's (u, v, area, background) or None. */
static PyObject *py_frame(PyObject *self, PyObject *args) {
    PyObject *polys, *greys, *boxes;
    double grey, thr, default_bg;
    int W, H, min_pixels, binary;
    if (!PyArg_ParseTuple(args, "OOOdiidiid", &polys, &greys, &boxes, &grey, &W, &H, &thr,
                          &min_pixels, &binary, &default_bg))
        return NULL;
    PyObject *bseq = PySequence_Fast(boxes, "boxes: not a sequence");
    PyObject *pseq = bseq ? PySequence_Fast(polys, "polygons: not a sequence") : NULL;
    PyObject *gseq = pseq ? PySequence_Fast(greys, "greys: not a sequence") : NULL;
    PyObject *ret = NULL;
    Py_buffer *bufs = NULL;
    double *b = NULL, *g = NULL;
    const double **xy = NULL;
    Py_ssize_t *nv = NULL, nb = 0, held = 0;
    if (!gseq) goto done;
    nb = PySequence_Fast_GET_SIZE(bseq);
    if (PySequence_Fast_GET_SIZE(pseq) != nb || PySequence_Fast_GET_SIZE(gseq) != nb) {
        PyErr_SetString(PyExc_ValueError, "one polygon, grey level and box each");
        goto done;
    }
    size_t m = (size_t)(nb ? nb : 1);
    bufs = malloc(m * sizeof(Py_buffer));
    b = malloc(m * 4 * sizeof(double));
    g = malloc(m * sizeof(double));
    xy = malloc(m * sizeof(double *));
    nv = malloc(m * sizeof(Py_ssize_t));
    if (!bufs || !b || !g || !xy || !nv) {
        PyErr_NoMemory();
        goto done;
    }
    for (Py_ssize_t i = 0; i < nb; i++) {
        double *v = b + 4 * i;
        if (!PyArg_ParseTuple(PySequence_Fast_GET_ITEM(bseq, i), "dddd", v, v + 1, v + 2, v + 3))
            goto done;
        g[i] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(gseq, i));
        if (g[i] == -1.0 && PyErr_Occurred()) goto done;
        Py_buffer *P = bufs + i;
        if (PyObject_GetBuffer(PySequence_Fast_GET_ITEM(pseq, i), P, PyBUF_C_CONTIGUOUS) < 0)
            goto done;
        held++;
        if (P->itemsize != sizeof(double) || P->len % (2 * sizeof(double))) {
            PyErr_SetString(PyExc_ValueError, "polygons: float64 (n, 2) arrays");
            goto done;
        }
        xy[i] = P->buf;
        nv[i] = P->len / (2 * (Py_ssize_t)sizeof(double));
    }
    Frame f;
    if (frame_c(xy, nv, g, b, nb, grey, W, H, thr, min_pixels, binary, default_bg, &f) == 0)
        ret = frame_tuple(&f);
done:
    for (Py_ssize_t i = 0; i < held; i++) PyBuffer_Release(bufs + i);
    free(bufs);
    free(b);
    free(g);
    free(xy);
    free(nv);
    Py_XDECREF(bseq);
    Py_XDECREF(pseq);
    Py_XDECREF(gseq);
    return ret;
}

/* Both cameras' frame_c for a scene of spheres, their silhouettes drawn as silhouette.drawables
 * draws them (sphere_polygon, far first by the distance of the centre from the optical centre,
 * ties in scene order). cams: 32 doubles, per camera R (9, row-major camera-to-world), o (3),
 * fx, fy, cx, cy; prims: a sequence of objects with position (3 floats), radius and albedo; ct,
 * st (nt each), scale: the polygon's tables and area scale. 0, or -1 with an exception set
 * (then no image is held). */
static int spheres_c(const double *cams, PyObject *prims, const double *ct, const double *st,
                     Py_ssize_t nt, double scale, double grey, int W, int H, double thr,
                     int min_pixels, int binary, double default_bg, Frame out[2]) {
    static PyObject *names[3] = {NULL, NULL, NULL}; /* interned once */
    static const char *const attrs[3] = {"position", "radius", "albedo"};
    for (int k = 0; k < 3; k++)
        if (!names[k] && !(names[k] = PyUnicode_InternFromString(attrs[k]))) return -1;
    int ret = -1;
    out[0].image = out[1].image = NULL;
    PyObject *seq = PySequence_Fast(prims, "prims: not a sequence");
    if (!seq) return -1;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    size_t m = (size_t)(n ? n : 1);
    /* per sphere (x, y, z, radius, 255 albedo); per drawn one its polygon, box, grey, order */
    double *S = malloc(m * (5 + 2 * nt + 4 + 4 + 2) * sizeof(double) + 1);
    Py_ssize_t *order = malloc(m * 2 * sizeof(Py_ssize_t));
    const double **xy = malloc(m * sizeof(double *));
    if (!S || !order || !xy) {
        PyErr_NoMemory();
        goto done;
    }
    double *poly = S + 5 * m, *boxes = poly + 2 * nt * m, *bx = boxes + 4 * m;
    double *dist = bx + 4 * m, *gr = dist + m;
    Py_ssize_t *nv = order + m;
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *p = PySequence_Fast_GET_ITEM(seq, i);
        PyObject *pos = PyObject_GetAttr(p, names[0]);
        PyObject *rad = pos ? PyObject_GetAttr(p, names[1]) : NULL;
        PyObject *alb = rad ? PyObject_GetAttr(p, names[2]) : NULL;
        int ok;
        if (alb && PyTuple_CheckExact(pos) && PyTuple_GET_SIZE(pos) == 3 &&
            PyFloat_CheckExact(PyTuple_GET_ITEM(pos, 0)) &&
            PyFloat_CheckExact(PyTuple_GET_ITEM(pos, 1)) &&
            PyFloat_CheckExact(PyTuple_GET_ITEM(pos, 2))) { /* the usual: a tuple of floats */
            for (int k = 0; k < 3; k++) S[5 * i + k] = PyFloat_AS_DOUBLE(PyTuple_GET_ITEM(pos, k));
            ok = 1;
        } else {
            PyObject *xyz = alb ? PySequence_Tuple(pos) : NULL; /* a tuple, list or array */
            ok = xyz && PyArg_ParseTuple(xyz, "ddd", S + 5 * i, S + 5 * i + 1, S + 5 * i + 2);
            Py_XDECREF(xyz);
        }
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
    for (int c = 0; c < 2; c++) {
        const double *K = cams + 16 * c, *R = K, *o = K + 9;
        Py_ssize_t nd = 0;
        for (Py_ssize_t i = 0; i < n; i++) {
            const double *sp = S + 5 * i;
            if (!sphere_outline(R, o, K[12], K[13], K[14], K[15], sp[0], sp[1], sp[2], sp[3], ct,
                                st, nt, scale, poly + 2 * nt * i, boxes + 4 * i))
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
        for (Py_ssize_t k = 0; k < nd; k++) {
            Py_ssize_t i = order[k];
            xy[k] = poly + 2 * nt * i;
            nv[k] = nt;
            gr[k] = S[5 * i + 4];
            memcpy(bx + 4 * k, boxes + 4 * i, 4 * sizeof(double));
        }
        if (frame_c(xy, nv, gr, bx, nd, grey, W, H, thr, min_pixels, binary, default_bg,
                    out + c) < 0) {
            if (c) Py_CLEAR(out[0].image);
            goto done;
        }
    }
    ret = 0;
done:
    Py_DECREF(seq);
    free(S);
    free(order);
    free(xy);
    return ret;
}

/* The ball centre from its centroids (u[i], v[i]) in the two images (StereoBallCamera.locate +
 * measure's checks): triangulated (py_triangulate with P0, P1); with radius > 0 each centroid
 * scaled back towards its principal point by (Z^2 - r^2) / Z^2 (Z: that camera's depth of the
 * first estimate) and triangulated again. 1 and p, 0 at infinity, non-finite or behind either
 * camera, -1 with an exception set. ax: each camera's optical centre and axis (12); cc: the
 * principal points (cx, cy) of both (4). */
static int locate_c(PyObject *P0, PyObject *P1, double u[2], double v[2], double radius,
                    const double *ax, const double *cc, double p[3]) {
    double z[2];
    for (int pass = 0; pass < 2; pass++) {
        PyObject *a[6] = {Py_NewRef(P0), Py_NewRef(P1), PyFloat_FromDouble(u[0]),
                          PyFloat_FromDouble(v[0]), PyFloat_FromDouble(u[1]),
                          PyFloat_FromDouble(v[1])};
        PyObject *X = call_kernel(py_triangulate, tuple_of(6, a));
        if (!X) return -1;
        if (X == Py_None) {
            Py_DECREF(X);
            return 0;
        }
        for (int k = 0; k < 3; k++) p[k] = PyFloat_AS_DOUBLE(PyTuple_GET_ITEM(X, k)); /* floats */
        Py_DECREF(X);
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) return 0;
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
    return z[0] > 0.0 && z[1] > 0.0; /* else a mismatch behind a camera */
}

/* locate(P0, P1, u0, v0, u1, v1, radius, axes, centres): locate_c's (x, y, z), or None.
 * P0, P1: the 3 x 4 projection matrices (float64 12); axes: float64 12; centres: float64 4. */
static PyObject *py_locate(PyObject *self, PyObject *args) {
    PyObject *P0, *P1, *ret = NULL;
    Py_buffer Ab, Cb;
    double u[2], v[2], radius, p[3];
    if (!PyArg_ParseTuple(args, "OOdddddy*y*", &P0, &P1, u, v, u + 1, v + 1, &radius, &Ab, &Cb))
        return NULL;
    if (check(&Ab, sizeof(double), 12, "axes") && check(&Cb, sizeof(double), 4, "centres")) {
        int found = locate_c(P0, P1, u, v, radius, Ab.buf, Cb.buf, p);
        if (found > 0)
            ret = Py_BuildValue("(ddd)", p[0], p[1], p[2]);
        else if (found == 0)
            ret = Py_NewRef(Py_None);
    }
    PyBuffer_Release(&Ab);
    PyBuffer_Release(&Cb);
    return ret;
}

/* measure(prims, sphere, locate, radius, cams, cos, sin, scale, grey, W, H, threshold,
 * min_pixels, binary, default_bg, P0, P1, axes, centres): the whole noise-free measurement of a
 * scene of spheres (every primitive of the type sphere, else None: not done) in one call: both
 * cameras' frame_c (spheres_c) and, when locate is true and both images hold a blob, locate_c
 * of their centroids: (image0, window0, blob0, image1, window1, blob1, (x, y, z) or None).
 * P0, P1: the projection matrices (float64 12 each). */
static PyObject *py_measure(PyObject *self, PyObject *args) {
    Py_buffer Cm, Ct, St, Ab, Cb;
    PyObject *prims, *sphere, *P0, *P1, *ret = NULL;
    double scale, grey, thr, default_bg, radius;
    int W, H, min_pixels, binary, locate;
    if (!PyArg_ParseTuple(args, "OOpdy*y*y*ddiidiidOOy*y*", &prims, &sphere, &locate, &radius,
                          &Cm, &Ct, &St, &scale, &grey, &W, &H, &thr, &min_pixels, &binary,
                          &default_bg, &P0, &P1, &Ab, &Cb))
        return NULL;
    PyObject *seq = PySequence_Fast(prims, "prims: not a sequence");
    if (!seq) goto done;
    int all = 1;
    for (Py_ssize_t i = 0; all && i < PySequence_Fast_GET_SIZE(seq); i++)
        all = (PyObject *)Py_TYPE(PySequence_Fast_GET_ITEM(seq, i)) == sphere;
    Py_DECREF(seq);
    if (!all) {
        ret = Py_NewRef(Py_None);
        goto done;
    }
    Py_ssize_t nt = Ct.len / (Py_ssize_t)sizeof(double);
    Frame f[2];
    if (!check(&Cm, sizeof(double), 32, "cams") || !check(&St, sizeof(double), nt, "sin") ||
        !check(&Ab, sizeof(double), 12, "axes") || !check(&Cb, sizeof(double), 4, "centres") ||
        spheres_c(Cm.buf, prims, Ct.buf, St.buf, nt, scale, grey, W, H, thr, min_pixels, binary,
                  default_bg, f) < 0)
        goto done;
    double p[3];
    int found = 0;
    if (locate && f[0].got && f[1].got) {
        double u[2] = {f[0].blob[0], f[1].blob[0]}, v[2] = {f[0].blob[1], f[1].blob[1]};
        found = locate_c(P0, P1, u, v, radius, Ab.buf, Cb.buf, p);
        if (found < 0) {
            Py_DECREF(f[0].image);
            Py_DECREF(f[1].image);
            goto done;
        }
    }
    PyObject *items[7];
    frame_items(f, items);
    frame_items(f + 1, items + 3);
    if (found) {
        PyObject *xyz[3];
        for (int k = 0; k < 3; k++) xyz[k] = PyFloat_FromDouble(p[k]);
        items[6] = tuple_of(3, xyz);
    } else {
        items[6] = Py_NewRef(Py_None);
    }
    ret = tuple_of(7, items);
done:
    PyBuffer_Release(&Cm);
    PyBuffer_Release(&Ct);
    PyBuffer_Release(&St);
    PyBuffer_Release(&Ab);
    PyBuffer_Release(&Cb);
    return ret;
}

static PyMethodDef stereo_methods[] = {
    {"frame", py_frame, METH_VARARGS, "one camera's window, image and blob"},
    {"locate", py_locate, METH_VARARGS, "the ball centre from its two centroids"},
    {"measure", py_measure, METH_VARARGS, "a scene of spheres' frames and ball centre"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef stereo_module = {
    PyModuleDef_HEAD_INIT, "_stereo", "The stereo ball camera's per-frame steps.", -1,
    stereo_methods};

PyMODINIT_FUNC PyInit__stereo(void) { return PyModule_Create(&stereo_module); }
