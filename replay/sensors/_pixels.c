/* Per-pixel kernels of the cameras (replay/sensors/pixels.py documents them; that module is the
 * only caller). Plain C over the buffer protocol: no NumPy headers, no start-up cost.
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

/* Signed-area accumulation of one polygon (n vertices xy[2n], pixels of the full image) into
 * acc (h rows of w + 1) of the block whose first pixel is (ox, oy): each edge is cut where it
 * crosses a pixel boundary, so every piece lies in one pixel; a piece rising dy at mean distance
 * f from its pixel's left side adds dy (1 - f) to that pixel and dy f to the next one in its row,
 * and the running sum along each row is then the exact covered area of each pixel (the integral
 * of the winding number over the pixel). Pieces left of the block count at its left edge, pieces
 * right of it or outside its rows are dropped. *r0, *r1, *c0, *c1: the rows and columns outside
 * which the polygon covers nothing in the block (acc is written only there, columns c0..c1). */
static void accumulate(const double *xy, Py_ssize_t n, double ox, double oy, double *acc,
                       int w, int h, int *r0, int *r1, int *c0, int *c1) {
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
    if (w < 0 || h < 0 || !check(&O, sizeof(double), (Py_ssize_t)w * h, "out")) goto done;
    double *acc = calloc((size_t)h * (w + 1) + 1, sizeof(double));
    if (!acc) {
        PyErr_NoMemory();
        goto done;
    }
    int r0, r1, c0, c1;
    if (n >= 3) accumulate(P.buf, n, ox, oy, acc, w, h, &r0, &r1, &c0, &c1);
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

/* composite(xy, starts, greys, ox, oy, img, w, h): alpha-composite polygons
 * xy[starts[i]:starts[i+1]] (int64 starts, vertex indices) of grey levels greys (float64) onto
 * the float32 image img (h x w, whose first pixel is (ox, oy) of the full image) in place, far
 * first: img += alpha (grey - img), alpha each pixel's exact covered area clipped to [0, 1], in
 * float32 (as NumPy's compositing did). */
static PyObject *py_composite(PyObject *self, PyObject *args) {
    Py_buffer P, S, G, I;
    int ox, oy, w, h;
    if (!PyArg_ParseTuple(args, "y*y*y*iiw*ii", &P, &S, &G, &ox, &oy, &I, &w, &h)) return NULL;
    PyObject *ret = NULL;
    Py_ssize_t npoly = S.len / (Py_ssize_t)sizeof(int64_t) - 1;
    Py_ssize_t nv = P.len / (2 * (Py_ssize_t)sizeof(double));
    const int64_t *starts = S.buf;
    const double *greys = G.buf;
    double *acc = NULL;
    if (w < 0 || h < 0 || npoly < 0 || !check(&I, sizeof(float), (Py_ssize_t)w * h, "img") ||
        !check(&G, sizeof(double), npoly, "greys"))
        goto done;
    for (Py_ssize_t i = 0; i <= npoly; i++)
        if (starts[i] < 0 || starts[i] > nv || (i && starts[i] < starts[i - 1])) {
            PyErr_SetString(PyExc_ValueError, "starts: not increasing vertex indices");
            goto done;
        }
    acc = calloc((size_t)h * (w + 1) + 1, sizeof(double));
    if (!acc) {
        PyErr_NoMemory();
        goto done;
    }
    float *img = I.buf;
    for (Py_ssize_t i = 0; i < npoly; i++) {
        Py_ssize_t n = starts[i + 1] - starts[i];
        if (n < 3) continue;
        int r0, r1, c0, c1;
        accumulate((const double *)P.buf + 2 * starts[i], n, ox, oy, acc, w, h, &r0, &r1, &c0,
                   &c1);
        const float grey = (float)greys[i];
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
    Py_INCREF(Py_None);
    ret = Py_None;
done:
    free(acc);
    PyBuffer_Release(&P);
    PyBuffer_Release(&S);
    PyBuffer_Release(&G);
    PyBuffer_Release(&I);
    return ret;
}

static PyMethodDef methods[] = {
    {"coverage", py_coverage, METH_VARARGS, "exact coverage of one polygon in a block"},
    {"composite", py_composite, METH_VARARGS, "exact-coverage alpha compositing of polygons"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_pixels",
                                    "Per-pixel kernels of the cameras.", -1, methods};

PyMODINIT_FUNC PyInit__pixels(void) { return PyModule_Create(&module); }
