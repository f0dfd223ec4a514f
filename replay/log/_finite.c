/* Whether a payload holds no NaN or infinity (replay/log/writer.py's encode is the only caller
 * and documents it; its _finite is the reference). Plain C, no NumPy headers.
 *
 * orjson writes NaN and infinity as null, so a message whose JSON holds "null" has its numbers
 * checked: floats (and float subclasses), in dicts (values), lists, tuples and the fields of
 * objects with a __dict__ (dataclasses: what orjson serialises by their fields). Returns True,
 * False, or None for an object it does not look into (a dataclass with slots, say): the Python
 * reference then decides. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>

#define UNKNOWN (-1)

static int all_finite(PyObject *v, int depth) {
    if (PyFloat_CheckExact(v) || PyFloat_Check(v)) return isfinite(PyFloat_AS_DOUBLE(v)) ? 1 : 0;
    if (v == Py_None || PyLong_Check(v) || PyUnicode_Check(v) || PyBool_Check(v)) return 1;
    if (depth > 64) return UNKNOWN;
    if (PyList_Check(v)) {
        for (Py_ssize_t i = 0; i < PyList_GET_SIZE(v); i++) {
            int r = all_finite(PyList_GET_ITEM(v, i), depth + 1);
            if (r != 1) return r;
        }
        return 1;
    }
    if (PyTuple_Check(v)) {
        for (Py_ssize_t i = 0; i < PyTuple_GET_SIZE(v); i++) {
            int r = all_finite(PyTuple_GET_ITEM(v, i), depth + 1);
            if (r != 1) return r;
        }
        return 1;
    }
    PyObject *d;
    if (PyDict_Check(v)) {
        d = v;
        Py_INCREF(d);
    } else {
        d = PyObject_GetAttrString(v, "__dict__");
        if (d == NULL || !PyDict_Check(d)) {
            PyErr_Clear();
            Py_XDECREF(d);
            return UNKNOWN;
        }
    }
    Py_ssize_t pos = 0;
    PyObject *key, *value;
    int r = 1;
    while (r == 1 && PyDict_Next(d, &pos, &key, &value)) r = all_finite(value, depth + 1);
    Py_DECREF(d);
    return r;
}

static PyObject *py_finite(PyObject *self, PyObject *obj) {
    int r = all_finite(obj, 0);
    if (r == UNKNOWN) Py_RETURN_NONE;
    return PyBool_FromLong(r);
}

static PyMethodDef methods[] = {
    {"finite", py_finite, METH_O, "no NaN or infinity in a payload (None: cannot tell)"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_finite",
                                    "Whether a payload holds no NaN or infinity.", -1, methods};

PyMODINIT_FUNC PyInit__finite(void) { return PyModule_Create(&module); }
