/* An ellipse's n-gon and its box, shared by _pixels.c (ellipse_polygon) and _silhouette.c (a
 * sphere's outline): out[k] = (u + a c cos_k - b s sin_k, v + a s cos_k + b c sin_k) for the
 * tables ct, st (n each) into out (2n); box = (umin, vmin, umax, vmax). The operations and order
 * of replay/sensors/silhouette.py Ellipse.polygon. Needs Python.h (Py_ssize_t) and math.h. */
#ifndef REPLAY_SENSORS_ELLIPSE_H
#define REPLAY_SENSORS_ELLIPSE_H

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

#endif
