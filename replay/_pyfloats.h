/* Floats between Python and the extension modules' C arrays, one definition for all of them
 * (included: each module compiles its own static copy; setup.py puts replay/ on the include
 * path). Plain C over the CPython API. */
#ifndef REPLAY_PYFLOATS_H
#define REPLAY_PYFLOATS_H

#include <Python.h>

/* out[0..n) = the first n floats of the sequence obj (a list, tuple or 1-D array; ints too),
 * which has exactly n items (at_least: n or more); 1, or 0 with an exception set: "name" when obj
 * is not a sequence, "expected [at least] n NOUN, got m (name)" when its length does not fit */
static inline int seq_doubles_n(PyObject *obj, double *out, Py_ssize_t n, int at_least,
                                const char *noun, const char *name) {
    PyObject *seq = PySequence_Fast(obj, name);
    if (seq == NULL) return 0;
    Py_ssize_t m = PySequence_Fast_GET_SIZE(seq);
    if (at_least ? m < n : m != n) {
        PyErr_Format(PyExc_ValueError, "expected %s%zd %s, got %zd (%s)",
                     at_least ? "at least " : "", n, noun, m, name);
        Py_DECREF(seq);
        return 0;
    }
    PyObject **items = PySequence_Fast_ITEMS(seq);
    for (Py_ssize_t i = 0; i < n; i++) {
        out[i] = PyFloat_AsDouble(items[i]);
        if (out[i] == -1.0 && PyErr_Occurred()) {
            Py_DECREF(seq);
            return 0;
        }
    }
    Py_DECREF(seq);
    return 1;
}

/* the n floats of a sequence of exactly n (seq_doubles_n) */
static inline int seq_doubles(PyObject *obj, double *out, Py_ssize_t n, const char *noun,
                              const char *name) {
    return seq_doubles_n(obj, out, n, 0, noun, name);
}

/* the first n floats of a sequence of n or more (seq_doubles_n) */
static inline int seq_doubles_head(PyObject *obj, double *out, Py_ssize_t n, const char *noun,
                                   const char *name) {
    return seq_doubles_n(obj, out, n, 1, noun, name);
}

/* a new list of the n floats x[0..n), or NULL with an exception set */
static inline PyObject *list_of_doubles(const double *x, Py_ssize_t n) {
    PyObject *out = PyList_New(n);
    if (out == NULL) return NULL;
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *f = PyFloat_FromDouble(x[i]);
        if (f == NULL) {
            Py_DECREF(out);
            return NULL;
        }
        PyList_SET_ITEM(out, i, f);
    }
    return out;
}

#endif
