/* Per-pixel kernels of the cameras: the optional accelerator of replay/sensors/raster.py,
 * silhouette.py, stick_camera.py and stereo.py (their Python paths are the algorithms, which
 * these repeat and the tests hold them to; replay.accel loads this module where it is built).
 * Plain C over the buffer protocol: no NumPy headers, no start-up cost.
 *
 * Image conventions (replay/sensors/pinhole.py): integer pixel coordinates are pixel centres,
 * pixel (i, j) spans [i - 0.5, i + 0.5] x [j - 0.5, j + 0.5].
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* An ellipse's n-gon and its box: out[k] = (u + a c cos_k - b s sin_k, v + a s cos_k + b c sin_k)
 * for the tables ct, st (n each) into out (2n); box = (umin, vmin, umax, vmax). The operations
 * and order of replay/sensors/silhouette.py Ellipse.polygon_and_box. */
static void ellipse_ngon(const double *ct, const double *st, Py_ssize_t n, double u, double v,
                         double a, double b, double c, double s, double *out, double *box) {
    double ac = a * c, bs = b * s, as = a * s, bc = b * c;
    double umin = INFINITY, vmin = INFINITY, umax = -INFINITY, vmax = -INFINITY;
    for (Py_ssize_t k = 0; k < n; k++) {
        double pu = u + ac * ct[k] - bs * st[k], pv = v + as * ct[k] + bc * st[k];
        out[2 * k] = pu, out[2 * k + 1] = pv;
        if (pu < umin) umin = pu;
        if (pu > umax) umax = pu;
        if (pv < vmin) vmin = pv;
        if (pv > vmax) vmax = pv;
    }
    box[0] = umin, box[1] = vmin, box[2] = umax, box[3] = vmax;
}

/* Signed-area accumulation of one polygon (n vertices xy[2n], pixels of the full image) into
 * acc (h rows of w + 1) of the block whose first pixel is (ox, oy): each edge is cut where it
 * crosses a pixel boundary, so every piece lies in one pixel; a piece rising dy at mean distance
 * f from its pixel's left side adds dy (1 - f) to that pixel and dy f to the next one in its row,
 * and the running sum along each row is then the exact covered area of each pixel (the integral
 * of the winding number over the pixel). Pieces left of the block count at its left edge, pieces
 * right of it or outside its rows are dropped. *r0, *r1, *c0, *c1: the rows and columns outside
 * which the polygon covers nothing in the block (acc is written only there, columns c0..c1). */
/* (the largest |coordinate|, px, a vertex may have: every cut stays in int range) */
#define COORD_MAX 1e9

static int accumulate(const double *xy, Py_ssize_t n, double ox, double oy, double *acc,
                      int w, int h, int *r0, int *r1, int *c0, int *c1) {
    /* a NaN or infinite vertex would make the cut loops below run for ever, a huge one
     * overflow their ints: refused, nothing accumulated, ValueError set, -1 */
    for (Py_ssize_t i = 0; i < 2 * n; i++)
        if (!(fabs(xy[i]) <= COORD_MAX)) { /* NaN too */
            char *text = PyOS_double_to_string(xy[i], 'r', 0, 0, NULL);
            PyErr_Format(PyExc_ValueError,
                         "polygon vertex %zd: %s = %s is not a finite pixel coordinate "
                         "within +-1e9",
                         i / 2, i % 2 ? "y" : "x", text ? text : "?");
            PyMem_Free(text);
            *r0 = *r1 = *c0 = *c1 = 0;
            return -1;
        }
    const double bx = ox - 0.5, by = oy - 0.5; /* block coordinates: pixel (c, r) = [c, c+1] x [r, r+1] */
    const int stride = w + 1;
    double area2 = 0.0, xmin = INFINITY, xmax = -INFINITY;
    for (Py_ssize_t i = 0; i < n; i++) {
        Py_ssize_t j = i + 1 < n ? i + 1 : 0;
        double xi = xy[2 * i] - bx, yi = xy[2 * i + 1] - by;
        double xj = xy[2 * j] - bx, yj = xy[2 * j + 1] - by;
        area2 += xi * yj - xj * yi;
        if (xi < xmin) xmin = xi;
        if (xi > xmax) xmax = xi;
    }
    const double sign = area2 >= 0.0 ? -1.0 : 1.0;
    int rlo = h, rhi = 0;
    for (Py_ssize_t i = 0; i < n; i++) {
        Py_ssize_t j = i + 1 < n ? i + 1 : 0;
        double xa = xy[2 * i] - bx, ya = xy[2 * i + 1] - by;
        double xb = xy[2 * j] - bx, yb = xy[2 * j + 1] - by;
        if (ya == yb) continue;
        double ylo = ya < yb ? ya : yb, yhi = ya < yb ? yb : ya;
        if (yhi <= 0.0 || ylo >= h) continue;
        int ra = (int)floor(ylo), rb = (int)ceil(yhi);
        if (ra < 0) ra = 0;
        if (rb > h) rb = h;
        if (ra < rlo) rlo = ra;
        if (rb > rhi) rhi = rb;
        const double k = (xb - xa) / (yb - ya);
        const int up = yb > ya;
        for (int r = ra; r < rb; r++) {
            double *row = acc + (size_t)r * stride;
            double ys, ye; /* the edge's part in the band [r, r + 1], in the edge's direction */
            if (up) {
                ys = ya > r ? ya : (double)r;
                ye = yb < r + 1.0 ? yb : r + 1.0;
            } else {
                ys = ya < r + 1.0 ? ya : r + 1.0;
                ye = yb > r ? yb : (double)r;
            }
            if (ys == ye) continue;
            double xs = ys == ya ? xa : xa + (ys - ya) * k;
            double xe = ye == yb ? xb : xa + (ye - ya) * k;
            /* cut at integer x walking from xs to xe: parts right of the block change nothing
             * in it, parts left of it all count at its left edge */
            int step, c;
            if (xe > xs) {
                step = 1;
                c = (int)floor(xs) + 1;
                if (c < 0) c = 0;
            } else if (xe < xs) {
                step = -1;
                c = (int)ceil(xs) - 1;
                if (c > w) c = w;
            } else {
                step = 0;
                c = 0;
            }
            double xp = xs, yp = ys;
            for (;;) {
                double xq;
                if ((step == 1 && c < xe && c <= w) || (step == -1 && c > xe && c >= 0))
                    xq = (double)c;
                else
                    xq = xe;
                double yq = xq == xe ? ye : ys + (xq - xs) * (ye - ys) / (xe - xs);
                double dy = (yq - yp) * sign, xm = 0.5 * (xp + xq), col = floor(xm);
                if (col < 0.0) {
                    row[0] += dy;
                } else if (col < w) {
                    int ci = (int)col;
                    double f = xm - col;
                    row[ci] += dy * (1.0 - f);
                    row[ci + 1] += dy * f;
                }
                if (xq == xe) break;
                if (step == 1 && xq >= w) break; /* the rest lies right of the block */
                if (step == -1 && xq <= 0.0) {   /* the rest lies left of it */
                    row[0] += (ye - yq) * sign;
                    break;
                }
                xp = xq;
                yp = yq;
                c += step;
            }
        }
    }
    int cl = (int)floor(xmin) - 1, ch = (int)ceil(xmax) + 1;
    cl = cl < 0 ? 0 : (cl > w ? w : cl);
    ch = ch > w ? w : ch;
    if (ch < cl) ch = cl;
    *r0 = rlo;
    *r1 = rhi;
    *c0 = cl;
    *c1 = ch;
    return 0;
}

static int sizes_ok(int w, int h) {
    if (w < 0 || h < 0) {
        PyErr_Format(PyExc_ValueError, "negative image size %d x %d", w, h);
        return 0;
    }
    return 1;
}

static int check(Py_buffer *b, Py_ssize_t itemsize, Py_ssize_t count, const char *what) {
    if (b->len != itemsize * count) {
        PyErr_Format(PyExc_ValueError, "%s: %zd bytes, expected %zd", what, b->len,
                     itemsize * count);
        return 0;
    }
    return 1;
}

/* coverage(xy, ox, oy, out, w, h): exact covered area of one polygon (float64 x, y pairs) in
 * each pixel of out (float64, h x w), the block whose first pixel is (ox, oy). */
static PyObject *py_coverage(PyObject *self, PyObject *args) {
    Py_buffer P, O;
    int ox, oy, w, h;
    if (!PyArg_ParseTuple(args, "y*iiw*ii", &P, &ox, &oy, &O, &w, &h)) return NULL;
    PyObject *ret = NULL;
    Py_ssize_t n = P.len / (2 * (Py_ssize_t)sizeof(double));
    if (!sizes_ok(w, h) || !check(&O, sizeof(double), (Py_ssize_t)w * h, "out")) goto done;
    double *acc = calloc((size_t)h * (w + 1) + 1, sizeof(double));
    if (!acc) {
        PyErr_NoMemory();
        goto done;
    }
    int r0, r1, c0, c1;
    if (n >= 3 && accumulate(P.buf, n, ox, oy, acc, w, h, &r0, &r1, &c0, &c1) < 0) {
        free(acc);
        goto done;
    }
    double *out = O.buf;
    for (int r = 0; r < h; r++) {
        double s = 0.0;
        for (int c = 0; c < w; c++) out[(size_t)r * w + c] = (s += acc[(size_t)r * (w + 1) + c]);
    }
    free(acc);
    Py_INCREF(Py_None);
    ret = Py_None;
done:
    PyBuffer_Release(&P);
    PyBuffer_Release(&O);
    return ret;
}

/* composite's blending of one polygon onto the float32 image img (w wide) from the coverage
 * accumulate left in acc (rows r0..r1, columns c0..c1; acc is zeroed there again, as calloc
 * left it): img += alpha (grey - img), alpha the running sum along the row clipped to [0, 1],
 * in float32. */
static void blend(double *acc, float *img, int w, int r0, int r1, int c0, int c1, float grey) {
    for (int r = r0; r < r1; r++) {
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
        row[c1] = 0.0; /* the last column accumulate writes */
    }
}

/* quantise's core over C arrays: out = clip(rint(in), 0, 255) as uint8, n pixels */
static void quantise_c(const float *in, uint8_t *out, size_t n) {
    for (size_t i = 0; i < n; i++) {
        float v = in[i];
        /* clip, then round half to even by the float32 magic number (exact below 2^22) */
        if (!(v > 0.0f)) /* NaN too */
            out[i] = 0;
        else if (v >= 255.0f)
            out[i] = 255;
        else {
            float t = v + 12582912.0f; /* 1.5 * 2^23 */
            out[i] = (uint8_t)(t - 12582912.0f);
        }
    }
}

/* composite(polygons, greys, ox, oy, img, w, h): alpha-composite polygons (a sequence of
 * C-contiguous float64 (n, 2) vertex arrays, pixels of the full image) of grey levels greys (a
 * sequence of floats) onto the float32 image img (h x w, whose first pixel is (ox, oy) of the
 * full image) in place, far first: img += alpha (grey - img), alpha each pixel's exact covered
 * area clipped to [0, 1], in float32 (as NumPy's compositing did). */
static PyObject *py_composite(PyObject *self, PyObject *args) {
    PyObject *polys, *greys;
    Py_buffer I;
    int ox, oy, w, h;
    if (!PyArg_ParseTuple(args, "OOiiw*ii", &polys, &greys, &ox, &oy, &I, &w, &h)) return NULL;
    PyObject *ret = NULL, *pseq = NULL, *gseq = NULL;
    double *acc = NULL;
    if (!sizes_ok(w, h) || !check(&I, sizeof(float), (Py_ssize_t)w * h, "img")) goto done;
    pseq = PySequence_Fast(polys, "polygons: not a sequence");
    gseq = pseq ? PySequence_Fast(greys, "greys: not a sequence") : NULL;
    if (!gseq) goto done;
    Py_ssize_t npoly = PySequence_Fast_GET_SIZE(pseq);
    if (PySequence_Fast_GET_SIZE(gseq) != npoly) {
        PyErr_SetString(PyExc_ValueError, "one grey level per polygon");
        goto done;
    }
    acc = calloc((size_t)h * (w + 1) + 1, sizeof(double));
    if (!acc) {
        PyErr_NoMemory();
        goto done;
    }
    float *img = I.buf;
    for (Py_ssize_t i = 0; i < npoly; i++) {
        Py_buffer P;
        if (PyObject_GetBuffer(PySequence_Fast_GET_ITEM(pseq, i), &P, PyBUF_C_CONTIGUOUS) < 0)
            goto done;
        double greyd = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(gseq, i));
        if (greyd == -1.0 && PyErr_Occurred()) {
            PyBuffer_Release(&P);
            goto done;
        }
        if (P.itemsize != sizeof(double) || P.len % (2 * sizeof(double))) {
            PyBuffer_Release(&P);
            PyErr_SetString(PyExc_ValueError, "polygons: float64 (n, 2) arrays");
            goto done;
        }
        Py_ssize_t n = P.len / (2 * (Py_ssize_t)sizeof(double));
        if (n >= 3) {
            int r0, r1, c0, c1;
            if (accumulate(P.buf, n, ox, oy, acc, w, h, &r0, &r1, &c0, &c1) < 0) {
                PyBuffer_Release(&P);
                goto done;
            }
            blend(acc, img, w, r0, r1, c0, c1, (float)greyd);
        }
        PyBuffer_Release(&P);
    }
    Py_INCREF(Py_None);
    ret = Py_None;
done:
    free(acc);
    Py_XDECREF(pseq);
    Py_XDECREF(gseq);
    PyBuffer_Release(&I);
    return ret;
}

/* quantise(img, out): out = clip(rint(img), 0, 255) as uint8 (img float32, out uint8, same
 * number of pixels); rint rounds half to even, as np.rint. */
static PyObject *py_quantise(PyObject *self, PyObject *args) {
    Py_buffer I, O;
    if (!PyArg_ParseTuple(args, "y*w*", &I, &O)) return NULL;
    PyObject *ret = NULL;
    Py_ssize_t n = O.len;
    if (!check(&I, sizeof(float), n, "img")) goto done;
    const float *in = I.buf;
    uint8_t *out = O.buf;
    quantise_c(in, out, (size_t)n);
    Py_INCREF(Py_None);
    ret = Py_None;
done:
    PyBuffer_Release(&I);
    PyBuffer_Release(&O);
    return ret;
}

/* project_hull(body, q, p, R, o, fx, fy, cx, cy, out): the convex hull in pixels of body points
 * (float64 (n, 3), body frame) of a rigid body at position p, orientation quaternion q = (x, y,
 * z, w), seen by a pinhole at o (float64 (3,)) with camera-to-world rotation R (float64 3 x 3,
 * row-major); the
 * projected points are rounded to float32 first (as cv2.convexHull of float32 points took
 * them). The hull (counter-clockwise in image axes, no collinear vertices) is written to out
 * (float64 (n, 2)); returns (count, umin, vmin, umax, vmax), or None if a point is not in front
 * of the camera (depth <= 1e-6 m). */
static int cmp_pt(const void *a, const void *b) {
    const double *p = a, *q = b;
    if (p[0] != q[0]) return (p[0] > q[0]) - (p[0] < q[0]);
    return (p[1] > q[1]) - (p[1] < q[1]);
}

static double cross3(const double *o, const double *a, const double *b) {
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

static PyObject *py_project_hull(PyObject *self, PyObject *args) {
    Py_buffer B, RB, OB, O;
    double qx, qy, qz, qw, px, py, pz, fx, fy, cx, cy;
    if (!PyArg_ParseTuple(args, "y*(dddd)(ddd)y*y*ddddw*", &B, &qx, &qy, &qz, &qw, &px, &py, &pz,
                          &RB, &OB, &fx, &fy, &cx, &cy, &O))
        return NULL;
    PyObject *ret = NULL;
    double *pts = NULL;
    Py_ssize_t n = B.len / (3 * (Py_ssize_t)sizeof(double));
    if (!check(&B, sizeof(double), 3 * n, "body") || !check(&RB, sizeof(double), 9, "R") ||
        !check(&OB, sizeof(double), 3, "o") || !check(&O, sizeof(double), 2 * n, "out"))
        goto done;
    const double ox = ((const double *)OB.buf)[0], oy = ((const double *)OB.buf)[1],
                 oz = ((const double *)OB.buf)[2];
    double nq = qx * qx + qy * qy + qz * qz + qw * qw;
    if (nq == 0.0) {
        PyErr_SetString(PyExc_ValueError, "zero quaternion");
        goto done;
    }
    double s = 2.0 / nq; /* replay.spatial.quaternion_matrix */
    double q[9] = {1 - s * (qy * qy + qz * qz), s * (qx * qy - qz * qw), s * (qx * qz + qy * qw),
                   s * (qx * qy + qz * qw),     1 - s * (qx * qx + qz * qz), s * (qy * qz - qx * qw),
                   s * (qx * qz - qy * qw),     s * (qy * qz + qx * qw),     1 - s * (qx * qx + qy * qy)};
    const double *R = RB.buf, *b = B.buf;
    /* the points, then the chain (up to 2 n - 1 points before the repeated first is dropped) */
    pts = malloc((size_t)(n ? n : 1) * 6 * sizeof(double));
    if (!pts) {
        PyErr_NoMemory();
        goto done;
    }
    /* The products of 3-vectors as NumPy's matmul (OpenBLAS) computes them here, fused
     * multiply-adds in ascending order, and in the order NumPy did it before (world = body R^T +
     * p, then (world - o) R), so that the pixels are the same to the bit (a float32 ulp moved
     * the stick camera's uint8 pixels now and then and, through the closed loop, a run). */
    const double pos[3] = {px, py, pz}, org[3] = {ox, oy, oz};
    for (Py_ssize_t i = 0; i < n; i++) {
        const double *v = b + 3 * i;
        double d[3];
        for (int k = 0; k < 3; k++) /* world point minus the optical centre */
            d[k] = (fma(v[2], q[3 * k + 2], fma(v[1], q[3 * k + 1], v[0] * q[3 * k])) + pos[k]) -
                   org[k];
        double X = fma(d[2], R[6], fma(d[1], R[3], d[0] * R[0])); /* p_cam = R^T d */
        double Y = fma(d[2], R[7], fma(d[1], R[4], d[0] * R[1]));
        double Z = fma(d[2], R[8], fma(d[1], R[5], d[0] * R[2]));
        if (!(Z > 1e-6)) {
            Py_INCREF(Py_None);
            ret = Py_None;
            goto done;
        }
        /* rounded to float32 for real (a plain cast may be elided: GCC's default
         * -fexcess-precision=fast) */
        volatile float fu = (float)(fx * X / Z + cx), fv = (float)(fy * Y / Z + cy);
        if (!(isfinite(fu) && isfinite(fv))) { /* NaN or beyond float32: no hull of it (the
                                                * chain below would outgrow out) */
            PyErr_Format(PyExc_ValueError, "project_hull: body point %zd projects to a pixel "
                         "that is not finite (a non-finite or huge pose)", i);
            goto done;
        }
        pts[2 * i] = fu;
        pts[2 * i + 1] = fv;
    }
    /* Andrew's monotone chain */
    qsort(pts, n, 2 * sizeof(double), cmp_pt);
    double *hull = pts + 2 * n;
    Py_ssize_t k = 0;
    for (Py_ssize_t i = 0; i < n; i++) {
        while (k >= 2 && cross3(hull + 2 * (k - 2), hull + 2 * (k - 1), pts + 2 * i) <= 0.0) k--;
        hull[2 * k] = pts[2 * i], hull[2 * k + 1] = pts[2 * i + 1], k++;
    }
    for (Py_ssize_t i = n - 2, t = k + 1; i >= 0; i--) {
        while (k >= t && cross3(hull + 2 * (k - 2), hull + 2 * (k - 1), pts + 2 * i) <= 0.0) k--;
        hull[2 * k] = pts[2 * i], hull[2 * k + 1] = pts[2 * i + 1], k++;
    }
    if (k > 1) k--; /* the first point is repeated at the end */
    if (k > n) { /* cannot happen for finite points; never written past out */
        PyErr_SetString(PyExc_RuntimeError, "project_hull: hull longer than its points");
        goto done;
    }
    memcpy(O.buf, hull, (size_t)k * 2 * sizeof(double));
    double umin = INFINITY, vmin = INFINITY, umax = -INFINITY, vmax = -INFINITY;
    for (Py_ssize_t i = 0; i < k; i++) {
        if (hull[2 * i] < umin) umin = hull[2 * i];
        if (hull[2 * i] > umax) umax = hull[2 * i];
        if (hull[2 * i + 1] < vmin) vmin = hull[2 * i + 1];
        if (hull[2 * i + 1] > vmax) vmax = hull[2 * i + 1];
    }
    ret = Py_BuildValue("(ndddd)", k, umin, vmin, umax, vmax);
done:
    free(pts);
    PyBuffer_Release(&B);
    PyBuffer_Release(&RB);
    PyBuffer_Release(&OB);
    PyBuffer_Release(&O);
    return ret;
}

/* --- blobs ------------------------------------------------------------------------------ */

typedef struct {
    int label, area, x, y, w, h; /* the largest component: its label, pixels and bounding box */
} Blob;

/* Bounding box [x0, x1) x [y0, y1) of the pixels brighter than thr; 0 if there are none. */
static int bright_box(const uint8_t *img, int w, int h, double thr, int *x0, int *y0, int *x1,
                      int *y1) {
    int xa = w, ya = h, xb = -1, yb = -1;
    for (int r = 0; r < h; r++)
        for (int c = 0; c < w; c++)
            if (img[(size_t)r * w + c] > thr) {
                if (c < xa) xa = c;
                if (c > xb) xb = c;
                if (r < ya) ya = r;
                yb = r;
            }
    if (xb < 0) return 0;
    *x0 = xa, *y0 = ya, *x1 = xb + 1, *y1 = yb + 1;
    return 1;
}

/* 8-connected components of the pixels brighter than thr in the box [x0, x1) x [y0, y1),
 * labelled 1, 2, ... in raster order of their first pixel into lab (w x h, zero outside the
 * components); the largest (the first of equal ones), as cv2.connectedComponentsWithStats and
 * argmax over its areas give it. stack: w * h ints of scratch. */
static Blob largest_component(const uint8_t *img, int w, int h, double thr, int x0, int y0,
                              int x1, int y1, int32_t *lab, int32_t *stack) {
    Blob best = {0, 0, 0, 0, 0, 0};
    int next = 0;
    for (int r = y0; r < y1; r++)
        for (int c = x0; c < x1; c++) {
            size_t i = (size_t)r * w + c;
            if (lab[i] || !(img[i] > thr)) continue;
            int L = ++next, top = 0, area = 0, bx0 = c, bx1 = c, by0 = r, by1 = r;
            lab[i] = L;
            stack[top++] = (int32_t)i;
            while (top) {
                int32_t k = stack[--top];
                int kr = k / w, kc = k % w;
                area++;
                if (kc < bx0) bx0 = kc;
                if (kc > bx1) bx1 = kc;
                if (kr < by0) by0 = kr;
                if (kr > by1) by1 = kr;
                for (int dr = -1; dr <= 1; dr++) {
                    int nr = kr + dr;
                    if (nr < y0 || nr >= y1) continue;
                    for (int dc = -1; dc <= 1; dc++) {
                        int nc = kc + dc;
                        if (nc < x0 || nc >= x1) continue;
                        size_t j = (size_t)nr * w + nc;
                        if (!lab[j] && img[j] > thr) {
                            lab[j] = L;
                            stack[top++] = (int32_t)j;
                        }
                    }
                }
            }
            if (area > best.area) {
                best.label = L, best.area = area;
                best.x = bx0, best.y = by0, best.w = bx1 - bx0 + 1, best.h = by1 - by0 + 1;
            }
        }
    return best;
}

/* near[(r - y0) * bw + c - x0] = whether pixel (c, r) of the box [x0, x1) x [y0, y1) is within
 * 2 px (Chebyshev) of the blob L in it: the blob dilated by a 5 x 5 square, as cv2.dilate of the
 * box draws it (separably: rows, then columns). tmp: bw * bh bytes of scratch. */
static void dilate_blob(const int32_t *lab, int w, int L, int x0, int y0, int x1, int y1,
                        uint8_t *near, uint8_t *tmp) {
    int bw = x1 - x0, bh = y1 - y0;
    for (int r = 0; r < bh; r++) { /* rows: a running count of blob pixels in [c - 2, c + 2] */
        const int32_t *row = lab + (size_t)(r + y0) * w + x0;
        uint8_t *t = tmp + (size_t)r * bw;
        int n = 0;
        for (int c = 0; c < 2 && c < bw; c++) n += row[c] == L;
        for (int c = 0; c < bw; c++) {
            if (c + 2 < bw) n += row[c + 2] == L;
            if (c - 3 >= 0) n -= row[c - 3] == L;
            t[c] = n > 0;
        }
    }
    for (int c = 0; c < bw; c++) { /* columns, the same on the rows' result */
        int n = 0;
        for (int r = 0; r < 2 && r < bh; r++) n += tmp[(size_t)r * bw + c];
        for (int r = 0; r < bh; r++) {
            if (r + 2 < bh) n += tmp[(size_t)(r + 2) * bw + c];
            if (r - 3 >= 0) n -= tmp[(size_t)(r - 3) * bw + c];
            near[(size_t)r * bw + c] = n > 0;
        }
    }
}

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

typedef struct {
    double m00, m10, m01, mu20, mu11, mu02; /* moments; central ones about the centroid */
} Moments;

/* Moments of the weights wt (n_w x n_h box, row-major) with pixel (c, r) at (c, r). */
static Moments moments_of(const double *wt, int bw, int bh) {
    Moments m = {0, 0, 0, 0, 0, 0};
    for (int r = 0; r < bh; r++)
        for (int c = 0; c < bw; c++) {
            double v = wt[(size_t)r * bw + c];
            m.m00 += v, m.m10 += v * c, m.m01 += v * r;
        }
    if (m.m00 == 0.0) return m;
    double cx = m.m10 / m.m00, cy = m.m01 / m.m00;
    for (int r = 0; r < bh; r++)
        for (int c = 0; c < bw; c++) {
            double v = wt[(size_t)r * bw + c], dx = c - cx, dy = r - cy;
            m.mu20 += v * dx * dx, m.mu11 += v * dx * dy, m.mu02 += v * dy * dy;
        }
    return m;
}

/* Whether the blob b of a window whose first pixel is (ox, oy) touches the fw x fh image's
 * border (then it is cut by it, and not measured). */
static int cut_by_border(Blob b, int ox, int oy, int fw, int fh) {
    return b.x + ox == 0 || b.y + oy == 0 || b.x + ox + b.w == fw || b.y + oy + b.h == fh;
}

/* The box [*x0, *x1) x [*y0, *y1) of the blob b grown by pad px, clipped to the w x h window. */
static void grown_box(Blob b, int pad, int w, int h, int *x0, int *y0, int *x1, int *y1) {
    *x0 = b.x - pad > 0 ? b.x - pad : 0, *y0 = b.y - pad > 0 ? b.y - pad : 0;
    *x1 = b.x + b.w + pad < w ? b.x + b.w + pad : w;
    *y1 = b.y + b.h + pad < h ? b.y + b.h + pad : h;
}

/* The marker's background in the w x h uint8 img: the median of 9 pixels 2-4 px beyond each
 * end (at amax and amin along the axis (ex, ey) from the centroid (cx, cy)), the brighter end
 * winning. 0 if no such pixel is in the image, else 1 and *background. */
static int marker_background(const uint8_t *img, int w, int h, double cx, double cy, double ex,
                             double ey, double amax, double amin, double *background) {
    const double nx = -ey, ny = ex;
    int have = 0;
    double ends[2] = {amax, amin};
    *background = -INFINITY;
    for (int e = 0; e < 2; e++) {
        double sgn = ends[e] > 0 ? 1.0 : -1.0, vals[9];
        int nv = 0;
        for (int si = 0; si < 3; si++)
            for (int oi = 0; oi < 3; oi++) {
                double s = 2.0 + si, o = -1.0 + oi;
                double px = cx + (ends[e] + sgn * s) * ex + o * nx;
                double py = cy + (ends[e] + sgn * s) * ey + o * ny;
                double ix = rint(px), iy = rint(py);
                if (ix >= 0 && ix < w && iy >= 0 && iy < h)
                    vals[nv++] = img[(size_t)iy * w + (size_t)ix];
            }
        if (!nv) continue;
        qsort(vals, nv, sizeof(double), cmp_double);
        double med = nv % 2 ? vals[nv / 2] : 0.5 * (vals[nv / 2 - 1] + vals[nv / 2]);
        if (!have || med > *background) *background = med;
        have = 1;
    }
    return have;
}

/* marker_moments' result from the grey-level moments m of the box whose first pixel is (x0, y0)
 * of a window whose first pixel is (ox, oy) of the image */
static PyObject *marker_result(Moments m, int ox, int oy, int x0, int y0, int area,
                               double background) {
    return Py_BuildValue("(dddidddddd)", ox + x0 + m.m10 / m.m00, oy + y0 + m.m01 / m.m00,
                         0.5 * atan2(2.0 * m.mu11, m.mu20 - m.mu02), area, background, m.m00,
                         m.m10, m.m01, m.mu20, m.mu11, m.mu02);
}

/* marker_moments(img, w, h, threshold, min_pixels, ox, oy, full_w, full_h): the stick
 * camera's marker measurement (replay/sensors/stick_camera.py StickCamera.marker_moments says
 * what and why) on the uint8 image img (h x w, a window of the full_w x full_h image whose
 * first pixel is (ox, oy)). None, or (u, v, angle, pixels, background, m00, m10, m01, mu20,
 * mu11, mu02) with u, v in full-image pixels and the moments in those of the blob's box. */
static PyObject *py_marker_moments(PyObject *self, PyObject *args) {
    Py_buffer I;
    int w, h, min_pixels, ox, oy, fw, fh;
    double thr;
    if (!PyArg_ParseTuple(args, "y*iidiiiii", &I, &w, &h, &thr, &min_pixels, &ox, &oy, &fw, &fh))
        return NULL;
    PyObject *ret = NULL;
    int32_t *lab = NULL, *stack = NULL;
    double *wt = NULL;
    if (!sizes_ok(w, h) || !check(&I, 1, (Py_ssize_t)w * h, "img")) goto done;
    if (w == 0 || h == 0) goto none; /* an empty window: nothing seen */
    const uint8_t *img = I.buf;
    int ex0, ey0, ex1, ey1;
    if (!bright_box(img, w, h, thr, &ex0, &ey0, &ex1, &ey1)) goto none;
    lab = calloc((size_t)w * h, sizeof(int32_t));
    stack = malloc((size_t)w * h * sizeof(int32_t));
    if (!lab || !stack) goto nomem;
    Blob b = largest_component(img, w, h, thr, ex0, ey0, ex1, ey1, lab, stack);
    if (b.area < min_pixels) goto none;
    if (cut_by_border(b, ox, oy, fw, fh)) goto none;
    int x0, y0, x1, y1;
    grown_box(b, 3, w, h, &x0, &y0, &x1, &y1);
    int bw = x1 - x0, bh = y1 - y0;
    wt = malloc((size_t)bw * bh * sizeof(double) + 2 * (size_t)bw * bh);
    if (!wt) goto nomem;
    uint8_t *near = (uint8_t *)(wt + (size_t)bw * bh), *tmp = near + (size_t)bw * bh;
    dilate_blob(lab, w, b.label, x0, y0, x1, y1, near, tmp);
    /* the blob's binary moments: its centroid and axis */
    for (int r = 0; r < bh; r++)
        for (int c = 0; c < bw; c++)
            wt[(size_t)r * bw + c] = lab[(size_t)(r + y0) * w + c + x0] == b.label;
    Moments mb = moments_of(wt, bw, bh);
    double a = 0.5 * atan2(2.0 * mb.mu11, mb.mu20 - mb.mu02);
    double ex = cos(a), ey = sin(a);
    double cx = x0 + mb.m10 / mb.m00, cy = y0 + mb.m01 / mb.m00;
    double amax = -INFINITY, amin = INFINITY;
    for (int r = y0; r < y1; r++)
        for (int c = x0; c < x1; c++)
            if (lab[(size_t)r * w + c] == b.label) {
                double al = (c - cx) * ex + (r - cy) * ey;
                if (al > amax) amax = al;
                if (al < amin) amin = al;
            }
    /* the background beyond the ends */
    double background;
    if (!marker_background(img, w, h, cx, cy, ex, ey, amax, amin, &background)) goto none;
    /* moments of the grey level above the background within the blob dilated by 2 px */
    const float bg = (float)background;
    for (int r = 0; r < bh; r++)
        for (int c = 0; c < bw; c++) {
            double v = 0.0;
            if (near[(size_t)r * bw + c]) {
                float d = (float)img[(size_t)(r + y0) * w + c + x0] - bg;
                v = d > 0.0f ? d : 0.0f;
            }
            wt[(size_t)r * bw + c] = v;
        }
    Moments m = moments_of(wt, bw, bh);
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
    free(wt);
    PyBuffer_Release(&I);
    return ret;
}

/* The stereo camera's blob measurement (replay/sensors/stereo.py StereoBallCamera.blob says what
 * and why) on a w x h uint8 window img whose first pixel is (ox, oy) of the fw x fh image. The
 * local background is the (upper) median of the free grey levels around the grown blob, taken
 * from a histogram (O(n); the (n/2)-th smallest, as sorting them gives). 1 and *out = (u, v, area,
 * background; NaN for binary moments) in full-image pixels if found, 0 if not, -1 out of memory. */
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
    if (cut_by_border(b, ox, oy, fw, fh)) goto done;
    int x0, y0, x1, y1;
    grown_box(b, 4, w, h, &x0, &y0, &x1, &y1);
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

/* ball_blob(img, w, h, threshold, min_pixels, binary, default_background, ox, oy, full_w,
 * full_h): blob_of on the uint8 image img (h x w, a window of the full_w x full_h image whose
 * first pixel is (ox, oy)). None, or (u, v, area, background) in full-image pixels, background
 * NaN for binary moments. */
static PyObject *py_ball_blob(PyObject *self, PyObject *args) {
    Py_buffer I;
    int w, h, min_pixels, binary, ox, oy, fw, fh;
    double thr, default_bg, out[4];
    if (!PyArg_ParseTuple(args, "y*iidiidiiii", &I, &w, &h, &thr, &min_pixels, &binary,
                          &default_bg, &ox, &oy, &fw, &fh))
        return NULL;
    PyObject *ret = NULL;
    if (sizes_ok(w, h) && check(&I, 1, (Py_ssize_t)w * h, "img")) {
        int found = blob_of(I.buf, w, h, thr, min_pixels, binary, default_bg, ox, oy, fw, fh, out);
        if (found < 0)
            PyErr_NoMemory();
        else if (found == 0)
            ret = Py_NewRef(Py_None);
        else
            ret = Py_BuildValue("(ddid)", out[0], out[1], (int)out[2], out[3]);
    }
    PyBuffer_Release(&I);
    return ret;
}

/* pack_rows(bits, w, h): a 0/1 byte image (h x w, bool or uint8, w <= 63) as (h ints, bit u of
 * row v = bits[v, u], as replay.messages.pack_rows packs them; pixels set). */
static PyObject *py_pack_rows(PyObject *self, PyObject *args) {
    Py_buffer B;
    int w, h;
    if (!PyArg_ParseTuple(args, "y*ii", &B, &w, &h)) return NULL;
    PyObject *ret = NULL, *rows = NULL;
    if (w < 0 || w > 63 || h < 0) { /* replay.messages.pack_rows packs into int64 */
        PyErr_SetString(PyExc_ValueError, "pack_rows: 0 <= w <= 63");
        goto done;
    }
    if (!check(&B, 1, (Py_ssize_t)w * h, "bits")) goto done;
    rows = PyList_New(h);
    if (!rows) goto done;
    const uint8_t *b = B.buf;
    long count = 0;
    for (int r = 0; r < h; r++) {
        unsigned long long x = 0;
        for (int c = 0; c < w; c++)
            if (b[(size_t)r * w + c]) x |= 1ULL << c, count++;
        PyObject *v = PyLong_FromUnsignedLongLong(x);
        if (!v) goto done;
        PyList_SET_ITEM(rows, r, v);
    }
    ret = Py_BuildValue("(Ol)", rows, count);
done:
    Py_XDECREF(rows);
    PyBuffer_Release(&B);
    return ret;
}

/* --- geometry --------------------------------------------------------------------------- */

/* ellipse_polygon(cos, sin, u, v, a, b, c, s, out): out[k] = (u + a c cos_k - b s sin_k,
 * v + a s cos_k + b c sin_k) for the tables cos, sin (float64, n each) into out (float64 (n, 2))
 * (replay/sensors/silhouette.py Ellipse.polygon, the same operations in the same order);
 * returns its box (umin, vmin, umax, vmax). */
static PyObject *py_ellipse_polygon(PyObject *self, PyObject *args) {
    Py_buffer C, S, O;
    double u, v, a, b, c, s;
    if (!PyArg_ParseTuple(args, "y*y*ddddddw*", &C, &S, &u, &v, &a, &b, &c, &s, &O)) return NULL;
    PyObject *ret = NULL;
    Py_ssize_t n = C.len / (Py_ssize_t)sizeof(double);
    if (!check(&S, sizeof(double), n, "sin") || !check(&O, sizeof(double), 2 * n, "out"))
        goto done;
    double box[4];
    ellipse_ngon(C.buf, S.buf, n, u, v, a, b, c, s, O.buf, box);
    ret = Py_BuildValue("(dddd)", box[0], box[1], box[2], box[3]);
done:
    PyBuffer_Release(&C);
    PyBuffer_Release(&S);
    PyBuffer_Release(&O);
    return ret;
}

/* triangulate(P0, P1, u0, v0, u1, v1): the linear (DLT) triangulation of cv2.triangulatePoints
 * from pixels (u0, v0), (u1, v1) of two cameras with 3 x 4 projection matrices P0, P1 (float64,
 * row-major): the homogeneous X minimising |A X| (|X| = 1), A = [u0 P0[2] - P0[0]; v0 P0[2] -
 * P0[1]; u1 P1[2] - P1[0]; v1 P1[2] - P1[1]], i.e. the eigenvector of the smallest eigenvalue of
 * A^T A (cyclic Jacobi). Returns (x, y, z), or None if X is at infinity. */
static PyObject *py_triangulate(PyObject *self, PyObject *args) {
    Py_buffer B0, B1;
    double u0, v0, u1, v1;
    if (!PyArg_ParseTuple(args, "y*y*dddd", &B0, &B1, &u0, &v0, &u1, &v1)) return NULL;
    PyObject *ret = NULL;
    if (!check(&B0, sizeof(double), 12, "P0") || !check(&B1, sizeof(double), 12, "P1")) goto done;
    const double *P0 = B0.buf, *P1 = B1.buf;
    double A[4][4], M[4][4], V[4][4];
    for (int j = 0; j < 4; j++) {
        A[0][j] = u0 * P0[8 + j] - P0[j];
        A[1][j] = v0 * P0[8 + j] - P0[4 + j];
        A[2][j] = u1 * P1[8 + j] - P1[j];
        A[3][j] = v1 * P1[8 + j] - P1[4 + j];
    }
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double t = 0.0;
            for (int k = 0; k < 4; k++) t += A[k][i] * A[k][j];
            M[i][j] = t;
            V[i][j] = i == j;
        }
    for (int sweep = 0; sweep < 60; sweep++) {
        double off = 0.0, diag = 0.0;
        for (int i = 0; i < 4; i++) {
            diag += M[i][i] * M[i][i];
            for (int j = i + 1; j < 4; j++) off += M[i][j] * M[i][j];
        }
        if (off <= 1e-34 * diag) break;
        for (int p = 0; p < 3; p++)
            for (int q = p + 1; q < 4; q++) {
                if (M[p][q] == 0.0) continue;
                double theta = (M[q][q] - M[p][p]) / (2.0 * M[p][q]);
                double t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 4; k++) { /* M <- J^T M J, V <- V J */
                    double mkp = M[k][p], mkq = M[k][q];
                    M[k][p] = c * mkp - s * mkq;
                    M[k][q] = s * mkp + c * mkq;
                }
                for (int k = 0; k < 4; k++) {
                    double mpk = M[p][k], mqk = M[q][k];
                    M[p][k] = c * mpk - s * mqk;
                    M[q][k] = s * mpk + c * mqk;
                }
                for (int k = 0; k < 4; k++) {
                    double vkp = V[k][p], vkq = V[k][q];
                    V[k][p] = c * vkp - s * vkq;
                    V[k][q] = s * vkp + c * vkq;
                }
            }
    }
    int m = 0;
    for (int i = 1; i < 4; i++)
        if (M[i][i] < M[m][m]) m = i;
    if (V[3][m] == 0.0) {
        Py_INCREF(Py_None);
        ret = Py_None;
    } else {
        ret = Py_BuildValue("(ddd)", V[0][m] / V[3][m], V[1][m] / V[3][m], V[2][m] / V[3][m]);
    }
done:
    PyBuffer_Release(&B0);
    PyBuffer_Release(&B1);
    return ret;
}

static PyMethodDef methods[] = {
    {"coverage", py_coverage, METH_VARARGS, "exact coverage of one polygon in a block"},
    {"composite", py_composite, METH_VARARGS, "exact-coverage alpha compositing of polygons"},
    {"quantise", py_quantise, METH_VARARGS, "float32 grey levels to uint8 (rint, clip)"},
    {"project_hull", py_project_hull, METH_VARARGS, "convex hull of a body's projected points"},
    {"pack_rows", py_pack_rows, METH_VARARGS, "a binary image as one int a row"},
    {"ellipse_polygon", py_ellipse_polygon, METH_VARARGS, "an ellipse's polygon and box"},
    {"triangulate", py_triangulate, METH_VARARGS, "linear two-view triangulation (DLT)"},
    {"marker_moments", py_marker_moments, METH_VARARGS, "the stick camera's marker moments"},
    {"ball_blob", py_ball_blob, METH_VARARGS, "the stereo camera's ball blob moments"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_pixels",
                                    "Per-pixel kernels of the cameras.", -1, methods};

PyMODINIT_FUNC PyInit__pixels(void) { return PyModule_Create(&module); }
