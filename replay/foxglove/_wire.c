/* Foxglove messages' hot parts in the protobuf wire format (replay/foxglove/wire.py is the only
 * caller, documents the fields and keeps the Python references): a Timestamp field, the frame
 * transforms of a FrameTransforms and the joints of a JointStates. Plain C, no NumPy headers.
 *
 * timestamp(t_ns): field 1 holding google.protobuf.Timestamp (seconds 1, nanos 2, each left
 * out at 0). frame_transforms(frames, ts): for each frame (attributes parent, child: str;
 * position: 3 floats; orientation: 4 floats, x y z w) field 1 of FrameTransforms, a
 * FrameTransform of ts (a timestamp field's bytes), parent 2, child 3, translation 4 and
 * rotation 5 with every double written. joint_states(names, position, velocity, effort, ts):
 * ts, then per joint (as zip: up to the shortest) field 2, a JointState of name 1, position 2,
 * velocity 3, effort 5. body_transforms(primitives, head, sphere) and scene_update(primitives,
 * head, shape_fields, sphere): the primitives' frame transforms and scene entities (below).
 * Doubles little endian (fixed64), lengths as varints.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* a frame's attribute names, interned once */
static PyObject *NAME_PARENT, *NAME_CHILD, *NAME_POSITION, *NAME_ORIENTATION, *NAME_NAME;

typedef struct {
    uint8_t *buf;
    size_t len, cap;
} Out;

static int grow(Out *o, size_t extra) {
    if (o->len + extra <= o->cap) return 0;
    size_t cap = o->cap ? o->cap : 1024;
    while (cap < o->len + extra) cap *= 2;
    uint8_t *b = realloc(o->buf, cap);
    if (!b) {
        PyErr_NoMemory();
        return -1;
    }
    o->buf = b;
    o->cap = cap;
    return 0;
}

static size_t varint_size(uint64_t v) {
    size_t n = 1;
    while (v >= 0x80) v >>= 7, n++;
    return n;
}

static uint8_t *put_varint(uint8_t *p, uint64_t v) {
    while (v >= 0x80) {
        *p++ = (uint8_t)(v | 0x80);
        v >>= 7;
    }
    *p++ = (uint8_t)v;
    return p;
}

static uint8_t *put_double(uint8_t *p, uint8_t tag, double d) {
    uint64_t u;
    memcpy(&u, &d, 8);
    *p++ = tag;
    for (int i = 0; i < 8; i++) p[i] = (uint8_t)(u >> (8 * i));
    return p + 8;
}

/* the timestamp field's bytes (at most 2 + 1 + 10 + 1 + 5) */
static size_t timestamp_bytes(uint8_t *out, unsigned long long t_ns) {
    const uint64_t sec = t_ns / 1000000000ull, nsec = t_ns % 1000000000ull;
    uint8_t body[20], *p = body;
    if (sec) *p++ = 0x08, p = put_varint(p, sec);
    if (nsec) *p++ = 0x10, p = put_varint(p, nsec);
    const size_t n = (size_t)(p - body);
    out[0] = 0x0A;
    out[1] = (uint8_t)n;
    memcpy(out + 2, body, n);
    return 2 + n;
}

static PyObject *py_timestamp(PyObject *self, PyObject *arg) {
    unsigned long long t = PyLong_AsUnsignedLongLong(arg);
    if (t == (unsigned long long)-1 && PyErr_Occurred()) return NULL;
    uint8_t out[32];
    return PyBytes_FromStringAndSize((const char *)out, (Py_ssize_t)timestamp_bytes(out, t));
}

/* n doubles of a sequence (a tuple, a list or any sequence of floats) */
static int doubles(PyObject *seq, double *out, Py_ssize_t n, const char *what) {
    PyObject *fast = PySequence_Fast(seq, what);
    if (!fast) return -1;
    if (PySequence_Fast_GET_SIZE(fast) != n) {
        Py_DECREF(fast);
        PyErr_Format(PyExc_ValueError, "%s: expected %zd numbers", what, n);
        return -1;
    }
    for (Py_ssize_t i = 0; i < n; i++) {
        out[i] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(fast, i));
        if (out[i] == -1.0 && PyErr_Occurred()) {
            Py_DECREF(fast);
            return -1;
        }
    }
    Py_DECREF(fast);
    return 0;
}

/* a str attribute's or item's UTF-8 */
static const char *utf8(PyObject *s, Py_ssize_t *n) {
    if (!PyUnicode_Check(s)) {
        PyErr_SetString(PyExc_TypeError, "wire: a frame or joint name must be str");
        return NULL;
    }
    return PyUnicode_AsUTF8AndSize(s, n);
}

/* a length-delimited field: tag, length n, the n bytes of s */
static uint8_t *put_bytes(uint8_t *p, uint8_t tag, const void *s, size_t n) {
    *p++ = tag;
    p = put_varint(p, (uint64_t)n);
    memcpy(p, s, n);
    return p + n;
}

/* a Vector3 (field vtag) of v[0..2] and a Quaternion (field qtag) of v[3..6], every double
 * written */
static uint8_t *put_vector_quaternion(uint8_t *p, uint8_t vtag, uint8_t qtag, const double v[7]) {
    *p++ = vtag;
    *p++ = 27;
    p = put_double(p, 9, v[0]);
    p = put_double(p, 17, v[1]);
    p = put_double(p, 25, v[2]);
    *p++ = qtag;
    *p++ = 36;
    p = put_double(p, 9, v[3]);
    p = put_double(p, 17, v[4]);
    p = put_double(p, 25, v[5]);
    return put_double(p, 33, v[6]);
}

/* the bytes written to o (b"" when none) */
static PyObject *out_bytes(const Out *o) {
    return PyBytes_FromStringAndSize(o->buf ? (const char *)o->buf : "", (Py_ssize_t)o->len);
}

/* room in o for a message field tag of body bytes, the first of which are head's, written
 * up to the end of head: where the rest goes, or NULL out of memory */
static uint8_t *start_message(Out *o, uint8_t tag, size_t body, const Py_buffer *head) {
    if (grow(o, 1 + 10 + body) < 0) return NULL;
    uint8_t *p = o->buf + o->len;
    *p++ = tag;
    p = put_varint(p, body);
    memcpy(p, head->buf, (size_t)head->len);
    return p + head->len;
}

/* appends item's message to o after the shared bytes head (a buffer); 0, or -1 with an
 * exception set. args: the call's arguments. */
typedef int (*Encoder)(Out *o, PyObject *item, const Py_buffer *head, PyObject *const *args);

/* a call of want arguments (usage: its signature), the first the items (an iterable), the
 * second head (an object with the buffer protocol): each item encoded by encode after head, one
 * after another, as bytes; NULL with an exception set */
static PyObject *encode_each(PyObject *const *args, Py_ssize_t nargs, Py_ssize_t want,
                             const char *usage, Encoder encode) {
    if (nargs != want) {
        PyErr_SetString(PyExc_TypeError, usage);
        return NULL;
    }
    Py_buffer head;
    if (PyObject_GetBuffer(args[1], &head, PyBUF_SIMPLE) < 0) return NULL;
    PyObject *it = PyObject_GetIter(args[0]), *item = NULL, *ret = NULL;
    Out o = {NULL, 0, 0};
    if (!it) goto done;
    while ((item = PyIter_Next(it))) {
        if (encode(&o, item, &head, args) < 0) goto done;
        Py_CLEAR(item);
    }
    if (!PyErr_Occurred()) ret = out_bytes(&o);
done:
    Py_XDECREF(item);
    Py_XDECREF(it);
    PyBuffer_Release(&head);
    free(o.buf);
    return ret;
}

/* frame f as a FrameTransform (field 1) of timestamp field ts */
static int frame_transform(Out *o, PyObject *f, const Py_buffer *ts, PyObject *const *args) {
    PyObject *parent = NULL, *child = NULL, *pos = NULL, *rot = NULL;
    int rc = -1;
    double v[7];
    Py_ssize_t np, nc;
    const char *sp, *sc;
    if (!(parent = PyObject_GetAttr(f, NAME_PARENT)) ||
        !(child = PyObject_GetAttr(f, NAME_CHILD)) ||
        !(pos = PyObject_GetAttr(f, NAME_POSITION)) ||
        !(rot = PyObject_GetAttr(f, NAME_ORIENTATION)) ||
        !(sp = utf8(parent, &np)) || !(sc = utf8(child, &nc)) ||
        doubles(pos, v, 3, "frame position") < 0 ||
        doubles(rot, v + 3, 4, "frame orientation") < 0)
        goto done;
    /* the transform's body: ts, parent, child, translation (2 + 27), rotation (2 + 36) */
    const size_t body = (size_t)ts->len + 1 + varint_size((uint64_t)np) + (size_t)np + 1 +
                        varint_size((uint64_t)nc) + (size_t)nc + 29 + 38;
    uint8_t *p = start_message(o, 0x0A, body, ts);
    if (!p) goto done;
    p = put_bytes(p, 0x12, sp, (size_t)np);
    p = put_bytes(p, 0x1A, sc, (size_t)nc);
    p = put_vector_quaternion(p, 0x22, 0x2A, v);
    o->len = (size_t)(p - o->buf);
    rc = 0;
done:
    Py_XDECREF(parent);
    Py_XDECREF(child);
    Py_XDECREF(pos);
    Py_XDECREF(rot);
    return rc;
}

static PyObject *py_frame_transforms(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    return encode_each(args, nargs, 2, "frame_transforms(frames, ts)", frame_transform);
}

static PyObject *py_joint_states(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 5) {
        PyErr_SetString(PyExc_TypeError,
                        "joint_states(names, position, velocity, effort, ts)");
        return NULL;
    }
    Py_buffer ts;
    if (PyObject_GetBuffer(args[4], &ts, PyBUF_SIMPLE) < 0) return NULL;
    PyObject *seq[4] = {NULL, NULL, NULL, NULL}, *ret = NULL;
    Out o = {NULL, 0, 0};
    Py_ssize_t n = PY_SSIZE_T_MAX;
    for (int k = 0; k < 4; k++) {
        seq[k] = PySequence_Fast(args[k], "joint_states: names and values are sequences");
        if (!seq[k]) goto done;
        if (PySequence_Fast_GET_SIZE(seq[k]) < n) n = PySequence_Fast_GET_SIZE(seq[k]);
    }
    if (grow(&o, (size_t)ts.len) < 0) goto done;
    memcpy(o.buf, ts.buf, (size_t)ts.len);
    o.len = (size_t)ts.len;
    for (Py_ssize_t i = 0; i < n; i++) {
        Py_ssize_t nn;
        const char *s = utf8(PySequence_Fast_GET_ITEM(seq[0], i), &nn);
        if (!s) goto done;
        double v[3];
        for (int k = 0; k < 3; k++) {
            v[k] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(seq[k + 1], i));
            if (v[k] == -1.0 && PyErr_Occurred()) goto done;
        }
        const size_t joint = 1 + varint_size((uint64_t)nn) + (size_t)nn + 27;
        if (grow(&o, 1 + 10 + joint) < 0) goto done;
        uint8_t *p = o.buf + o.len;
        *p++ = 0x12;
        p = put_varint(p, joint);
        p = put_bytes(p, 0x0A, s, (size_t)nn);
        p = put_double(p, 0x11, v[0]);
        p = put_double(p, 0x19, v[1]);
        p = put_double(p, 0x29, v[2]);
        o.len = (size_t)(p - o.buf);
    }
    ret = out_bytes(&o);
done:
    for (int k = 0; k < 4; k++) Py_XDECREF(seq[k]);
    PyBuffer_Release(&ts);
    free(o.buf);
    return ret;
}

/* a primitive's name, position and orientation (unrotated for a sphere); 0, or -1 */
static int primitive_pose(PyObject *p, PyObject *sphere, PyObject **name, double v[7]) {
    PyObject *pos = NULL, *rot = NULL;
    int sph = PyObject_IsInstance(p, sphere);
    if (sph < 0) return -1;
    if (!(*name = PyObject_GetAttr(p, NAME_NAME)) || !(pos = PyObject_GetAttr(p, NAME_POSITION)) ||
        (!sph && !(rot = PyObject_GetAttr(p, NAME_ORIENTATION))) ||
        doubles(pos, v, 3, "primitive position") < 0 ||
        (!sph && doubles(rot, v + 3, 4, "primitive orientation") < 0)) {
        Py_CLEAR(*name);
        Py_XDECREF(pos);
        Py_XDECREF(rot);
        return -1;
    }
    if (sph) v[3] = v[4] = v[5] = 0.0, v[6] = 1.0;
    Py_DECREF(pos);
    Py_XDECREF(rot);
    return 0;
}

/* primitive p as a FrameTransform (field 1) of head (its timestamp and parent fields) and its
 * name as the child; args[2]: the sphere class */
static int body_transform(Out *o, PyObject *p, const Py_buffer *head, PyObject *const *args) {
    PyObject *name = NULL;
    int rc = -1;
    double v[7];
    Py_ssize_t nc;
    const char *sc;
    if (primitive_pose(p, args[2], &name, v) < 0 || !(sc = utf8(name, &nc))) goto done;
    const size_t body = (size_t)head->len + 1 + varint_size((uint64_t)nc) + (size_t)nc + 67;
    uint8_t *q = start_message(o, 0x0A, body, head);
    if (!q) goto done;
    q = put_bytes(q, 0x1A, sc, (size_t)nc);
    q = put_vector_quaternion(q, 0x22, 0x2A, v);
    o->len = (size_t)(q - o->buf);
    rc = 0;
done:
    Py_XDECREF(name);
    return rc;
}

/* body_transforms(primitives, head, sphere): each primitive as a FrameTransform (field 1) of
 * head (its timestamp and parent fields) and its name as the child */
static PyObject *py_body_transforms(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    return encode_each(args, nargs, 3, "body_transforms(primitives, head, sphere)",
                       body_transform);
}

/* primitive p, if args[2] (shape_fields) gives it (mid, tail), as an entity (field 2) of head,
 * mid, its pose and tail; args[3]: the sphere class */
static int scene_entity(Out *o, PyObject *p, const Py_buffer *head, PyObject *const *args) {
    PyObject *fields = NULL, *name = NULL;
    int rc = -1;
    if (!(fields = PyObject_CallOneArg(args[2], p))) goto done;
    if (fields != Py_None) {
        double v[7];
        if (!PyTuple_Check(fields) || PyTuple_GET_SIZE(fields) != 2 ||
            !PyBytes_Check(PyTuple_GET_ITEM(fields, 0)) ||
            !PyBytes_Check(PyTuple_GET_ITEM(fields, 1))) {
            PyErr_SetString(PyExc_TypeError, "scene_update: shape_fields gives (bytes, bytes)");
            goto done;
        }
        if (primitive_pose(p, args[3], &name, v) < 0) goto done;
        PyObject *mid = PyTuple_GET_ITEM(fields, 0), *tail = PyTuple_GET_ITEM(fields, 1);
        const size_t nm = (size_t)PyBytes_GET_SIZE(mid), nt = (size_t)PyBytes_GET_SIZE(tail);
        const size_t body = (size_t)head->len + 69 + nm + nt;
        uint8_t *q = start_message(o, 0x12, body, head);
        if (!q) goto done;
        memcpy(q, PyBytes_AS_STRING(mid), nm);
        q += nm;
        *q++ = 0x0A;
        *q++ = 67;
        q = put_vector_quaternion(q, 0x0A, 0x12, v);
        memcpy(q, PyBytes_AS_STRING(tail), nt);
        q += nt;
        o->len = (size_t)(q - o->buf);
    }
    rc = 0;
done:
    Py_XDECREF(name);
    Py_XDECREF(fields);
    return rc;
}

/* scene_update(primitives, head, shape_fields, sphere): each primitive of which
 * shape_fields(p) gives (mid, tail) (None: left out) as an entity (field 2): head (its
 * timestamp and frame id), mid (its id and primitive field up to the pose), the pose (field 1:
 * position 1, orientation 2), tail */
static PyObject *py_scene_update(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    return encode_each(args, nargs, 4, "scene_update(primitives, head, shape_fields, sphere)",
                       scene_entity);
}

static PyMethodDef methods[] = {
    {"timestamp", py_timestamp, METH_O, "a Timestamp of t_ns as field 1"},
    {"frame_transforms", (PyCFunction)(void (*)(void))py_frame_transforms, METH_FASTCALL,
     "FrameTransforms' transforms of frames at a timestamp field"},
    {"joint_states", (PyCFunction)(void (*)(void))py_joint_states, METH_FASTCALL,
     "JointStates of names, position, velocity, effort after a timestamp field"},
    {"body_transforms", (PyCFunction)(void (*)(void))py_body_transforms, METH_FASTCALL,
     "FrameTransforms' transforms of primitives as frames of their names"},
    {"scene_update", (PyCFunction)(void (*)(void))py_scene_update, METH_FASTCALL,
     "SceneUpdate's entities of primitives at their poses"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_wire",
                                    "Foxglove messages' hot parts in the protobuf wire format.",
                                    -1, methods};

PyMODINIT_FUNC PyInit__wire(void) {
    if (!(NAME_PARENT = PyUnicode_InternFromString("parent")) ||
        !(NAME_CHILD = PyUnicode_InternFromString("child")) ||
        !(NAME_POSITION = PyUnicode_InternFromString("position")) ||
        !(NAME_ORIENTATION = PyUnicode_InternFromString("orientation")) ||
        !(NAME_NAME = PyUnicode_InternFromString("name")))
        return NULL;
    return PyModule_Create(&module);
}
