/* The MCAP chunk being built (replay/log/chunks.py is the only caller and documents the file):
 * its records, and per channel id its messages' (log time, offset) pairs for the message index
 * and its message count. Plain C, no NumPy headers.
 *
 * Chunk(chunk_size, on_full): message(channel_id, log_time, publish_time, data) appends one
 * Message record (MCAP spec: opcode 0x05, record length, channel id u16, sequence u32 = the
 * channel's count so far, log time u64, publish time u64, data; little endian) and calls
 * on_full() when the chunk has grown beyond chunk_size; append(record) adds other records
 * (schemas, channels); take() returns the chunk and its indexes and starts a new one;
 * json(topic, payload, t_ns) is a JSON message encoded and appended in one call (below), json_all
 * those of a dict.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    uint64_t *pairs; /* log time, offset, log time, offset, ... */
    size_t n, cap;   /* pairs used (2 a message), allocated */
} Index;

typedef struct {
    PyObject_HEAD uint8_t *buf;
    size_t len, cap;
    Py_ssize_t chunk_size;
    PyObject *on_full;
    PyObject *json_channels, *dumps, *finite; /* json(): topic -> id, encoder, check */
    Index *index; /* per channel id */
    uint64_t *counts;
    size_t channels; /* ids 0 .. channels - 1 allocated */
    uint64_t total;
    size_t in_chunk; /* messages in the chunk being built */
} Chunk;

static int reserve(Chunk *c, size_t extra) {
    if (c->len + extra <= c->cap) return 0;
    size_t cap = c->cap ? c->cap : 4096;
    while (cap < c->len + extra) cap *= 2;
    uint8_t *b = realloc(c->buf, cap);
    if (!b) {
        PyErr_NoMemory();
        return -1;
    }
    c->buf = b;
    c->cap = cap;
    return 0;
}

static int channel_slot(Chunk *c, size_t id) {
    if (id < c->channels) return 0;
    size_t n = id + 1 > 2 * c->channels ? id + 1 : 2 * c->channels;
    Index *ix = realloc(c->index, n * sizeof(Index));
    if (!ix) {
        PyErr_NoMemory();
        return -1;
    }
    c->index = ix;
    uint64_t *counts = realloc(c->counts, n * sizeof(uint64_t));
    if (!counts) {
        PyErr_NoMemory();
        return -1;
    }
    c->counts = counts;
    for (size_t i = c->channels; i < n; i++) {
        c->index[i] = (Index){NULL, 0, 0};
        c->counts[i] = 0;
    }
    c->channels = n;
    return 0;
}

static inline void le(uint8_t *p, uint64_t v, int n) {
    for (int i = 0; i < n; i++) p[i] = (uint8_t)(v >> (8 * i));
}

/* one Message record appended (its index entry kept); on_full() called once the chunk has grown
 * beyond chunk_size; -1 with an exception set on failure */
static int append_message(Chunk *c, unsigned long long ch, unsigned long long lt,
                          unsigned long long pt, const void *data, size_t len) {
    if (ch > 0xFFFF) {
        PyErr_SetString(PyExc_ValueError, "channel id beyond u16");
        return -1;
    }
    if (channel_slot(c, (size_t)ch) < 0 || reserve(c, 31 + len) < 0) return -1;
    Index *ix = &c->index[ch];
    if (ix->n + 2 > ix->cap) {
        size_t cap = ix->cap ? 2 * ix->cap : 64;
        uint64_t *p = realloc(ix->pairs, cap * sizeof(uint64_t));
        if (!p) {
            PyErr_NoMemory();
            return -1;
        }
        ix->pairs = p;
        ix->cap = cap;
    }
    ix->pairs[ix->n++] = lt;
    ix->pairs[ix->n++] = c->len;
    uint8_t *p = c->buf + c->len;
    p[0] = 0x05;
    le(p + 1, 2 + 4 + 8 + 8 + (uint64_t)len, 8);
    le(p + 9, ch, 2);
    le(p + 11, c->counts[ch], 4);
    le(p + 15, lt, 8);
    le(p + 23, pt, 8);
    memcpy(p + 31, data, len);
    c->len += 31 + len;
    c->counts[ch]++;
    c->total++;
    c->in_chunk++;
    if ((Py_ssize_t)c->len > c->chunk_size) {
        PyObject *r = PyObject_CallNoArgs(c->on_full);
        if (!r) return -1;
        Py_DECREF(r);
    }
    return 0;
}

static PyObject *Chunk_message(Chunk *c, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 4) {
        PyErr_SetString(PyExc_TypeError, "message(channel_id, log_time, publish_time, data)");
        return NULL;
    }
    unsigned long long ch = PyLong_AsUnsignedLongLong(args[0]);
    unsigned long long lt = PyLong_AsUnsignedLongLong(args[1]);
    unsigned long long pt = PyLong_AsUnsignedLongLong(args[2]);
    if (PyErr_Occurred()) return NULL;
    Py_buffer D;
    if (PyObject_GetBuffer(args[3], &D, PyBUF_SIMPLE) < 0) return NULL;
    int r = append_message(c, ch, lt, pt, D.buf, (size_t)D.len);
    PyBuffer_Release(&D);
    if (r < 0) return NULL;
    Py_RETURN_NONE;
}

/* One JSON message of a topic whose channel is known (replay/log/writer.py's LogWriter.write and
 * encode are the reference): the channel from the `json_channels` dict, the bytes from
 * `dumps(payload)`, and when they hold "null" (orjson's NaN and infinity) `finite(payload)` must
 * say True; then one Message record at log and publish time t. 1 when written; 0, with nothing
 * written, for the Python path to decide (a topic without a channel yet, a TypeError of dumps, a
 * "null" not known finite); -1 with an exception set. */
static int json_one(Chunk *c, PyObject *topic, PyObject *payload, unsigned long long t) {
    PyObject *channel = PyDict_GetItemWithError(c->json_channels, topic); /* borrowed */
    if (!channel) return PyErr_Occurred() ? -1 : 0;
    unsigned long long ch = PyLong_AsUnsignedLongLong(channel);
    if (ch == (unsigned long long)-1 && PyErr_Occurred()) return -1;
    PyObject *data = PyObject_CallOneArg(c->dumps, payload);
    if (!data) {
        if (!PyErr_ExceptionMatches(PyExc_TypeError)) return -1;
        PyErr_Clear();
        return 0;
    }
    if (!PyBytes_Check(data)) {
        Py_DECREF(data);
        PyErr_SetString(PyExc_TypeError, "json(): dumps must return bytes");
        return -1;
    }
    const char *buf = PyBytes_AS_STRING(data);
    size_t len = (size_t)PyBytes_GET_SIZE(data);
    if (len >= 4 && memmem(buf, len, "null", 4)) {
        PyObject *ok = PyObject_CallOneArg(c->finite, payload);
        if (ok != Py_True) {
            Py_DECREF(data);
            if (!ok) return -1;
            Py_DECREF(ok);
            return 0;
        }
        Py_DECREF(ok);
    }
    int r = append_message(c, ch, t, t, buf, len);
    Py_DECREF(data);
    return r < 0 ? -1 : 1;
}

static int json_ready(Chunk *c) {
    if (c->json_channels && c->dumps && c->finite) return 0;
    PyErr_SetString(PyExc_RuntimeError, "json(): use_json(channels, dumps, finite) first");
    return -1;
}

/* json(topic, payload, t_ns): json_one in one call; True when written, False for Python. */
static PyObject *Chunk_json(Chunk *c, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 3) {
        PyErr_SetString(PyExc_TypeError, "json(topic, payload, t_ns)");
        return NULL;
    }
    if (json_ready(c) < 0) return NULL;
    unsigned long long t = PyLong_AsUnsignedLongLong(args[2]);
    if (t == (unsigned long long)-1 && PyErr_Occurred()) return NULL;
    int r = json_one(c, args[0], args[1], t);
    if (r < 0) return NULL;
    return PyBool_FromLong(r);
}

/* json_all(messages, start, t_ns): json_one of each (topic, payload) of the dict `messages`, in
 * its order, from its item `start` on; stops at the first that is a list or that json_one leaves
 * to Python and returns that item's index (the caller writes it and calls again from the next),
 * -1 when all were written. The same records, in the same order, as json() of each. */
static PyObject *Chunk_json_all(Chunk *c, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 3 || !PyDict_Check(args[0])) {
        PyErr_SetString(PyExc_TypeError, "json_all(messages: dict, start, t_ns)");
        return NULL;
    }
    if (json_ready(c) < 0) return NULL;
    Py_ssize_t start = PyLong_AsSsize_t(args[1]);
    if (start == -1 && PyErr_Occurred()) return NULL;
    unsigned long long t = PyLong_AsUnsignedLongLong(args[2]);
    if (t == (unsigned long long)-1 && PyErr_Occurred()) return NULL;
    Py_ssize_t pos = 0, i = 0;
    PyObject *topic, *payload; /* borrowed */
    while (PyDict_Next(args[0], &pos, &topic, &payload)) {
        if (i >= start) {
            if (PyList_Check(payload)) return PyLong_FromSsize_t(i);
            Py_INCREF(topic); /* (on_full runs Python: keep them alive) */
            Py_INCREF(payload);
            int r = json_one(c, topic, payload, t);
            Py_DECREF(topic);
            Py_DECREF(payload);
            if (r < 0) return NULL;
            if (r == 0) return PyLong_FromSsize_t(i);
        }
        i++;
    }
    return PyLong_FromLong(-1);
}

static PyObject *Chunk_use_json(Chunk *c, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 3 || !PyDict_Check(args[0]) || !PyCallable_Check(args[1]) ||
        !PyCallable_Check(args[2])) {
        PyErr_SetString(PyExc_TypeError, "use_json(channels: dict, dumps, finite)");
        return NULL;
    }
    Py_INCREF(args[0]);
    Py_XSETREF(c->json_channels, args[0]);
    Py_INCREF(args[1]);
    Py_XSETREF(c->dumps, args[1]);
    Py_INCREF(args[2]);
    Py_XSETREF(c->finite, args[2]);
    Py_RETURN_NONE;
}

static PyObject *Chunk_append(Chunk *c, PyObject *arg) {
    Py_buffer D;
    if (PyObject_GetBuffer(arg, &D, PyBUF_SIMPLE) < 0) return NULL;
    if (reserve(c, (size_t)D.len) < 0) {
        PyBuffer_Release(&D);
        return NULL;
    }
    memcpy(c->buf + c->len, D.buf, (size_t)D.len);
    c->len += (size_t)D.len;
    PyBuffer_Release(&D);
    return PyLong_FromSize_t(c->len);
}

/* (records, [(first offset, channel id, message index entries, min log time, max log time),
 * ...] in channel id order) of the chunk, which starts again empty; None (the chunk kept) while
 * it holds no message */
static PyObject *Chunk_take(Chunk *c, PyObject *unused) {
    if (c->in_chunk == 0) Py_RETURN_NONE;
    PyObject *list = PyList_New(0);
    if (!list) return NULL;
    for (size_t id = 0; id < c->channels; id++) {
        Index *ix = &c->index[id];
        if (ix->n == 0) continue;
        uint64_t lo = UINT64_MAX, hi = 0;
        PyObject *entries = PyBytes_FromStringAndSize(NULL, (Py_ssize_t)(8 * ix->n));
        if (!entries) goto fail;
        uint8_t *e = (uint8_t *)PyBytes_AS_STRING(entries);
        for (size_t i = 0; i < ix->n; i++) le(e + 8 * i, ix->pairs[i], 8);
        for (size_t i = 0; i < ix->n; i += 2) {
            if (ix->pairs[i] < lo) lo = ix->pairs[i];
            if (ix->pairs[i] > hi) hi = ix->pairs[i];
        }
        PyObject *item = Py_BuildValue("(KnNKK)", (unsigned long long)ix->pairs[1], (Py_ssize_t)id,
                                       entries, (unsigned long long)lo, (unsigned long long)hi);
        if (!item || PyList_Append(list, item) < 0) {
            Py_XDECREF(item);
            goto fail;
        }
        Py_DECREF(item);
    }
    PyObject *raw = PyBytes_FromStringAndSize((const char *)c->buf, (Py_ssize_t)c->len);
    if (!raw) goto fail;
    c->len = 0;
    c->in_chunk = 0;
    for (size_t id = 0; id < c->channels; id++) c->index[id].n = 0;
    return Py_BuildValue("(NN)", raw, list);
fail:
    Py_DECREF(list);
    return NULL;
}

static PyObject *Chunk_count(Chunk *c, PyObject *arg) {
    size_t id = PyLong_AsSize_t(arg);
    if (PyErr_Occurred()) return NULL;
    return PyLong_FromUnsignedLongLong(id < c->channels ? c->counts[id] : 0);
}

static PyObject *Chunk_get_total(Chunk *c, void *closure) {
    return PyLong_FromUnsignedLongLong(c->total);
}

static PyObject *Chunk_get_size(Chunk *c, void *closure) { return PyLong_FromSize_t(c->len); }

static int Chunk_init(Chunk *c, PyObject *args, PyObject *kw) {
    Py_ssize_t size;
    PyObject *on_full;
    if (!PyArg_ParseTuple(args, "nO", &size, &on_full)) return -1;
    if (!PyCallable_Check(on_full)) {
        PyErr_SetString(PyExc_TypeError, "on_full must be callable");
        return -1;
    }
    c->chunk_size = size;
    Py_INCREF(on_full);
    Py_XSETREF(c->on_full, on_full);
    return 0;
}

static int Chunk_traverse(Chunk *c, visitproc visit, void *arg) {
    Py_VISIT(c->on_full);
    Py_VISIT(c->json_channels);
    Py_VISIT(c->dumps);
    Py_VISIT(c->finite);
    return 0;
}

static int Chunk_clear(Chunk *c) {
    Py_CLEAR(c->on_full);
    Py_CLEAR(c->json_channels);
    Py_CLEAR(c->dumps);
    Py_CLEAR(c->finite);
    return 0;
}

static void Chunk_dealloc(Chunk *c) {
    PyObject_GC_UnTrack(c);
    Chunk_clear(c);
    free(c->buf);
    for (size_t i = 0; i < c->channels; i++) free(c->index[i].pairs);
    free(c->index);
    free(c->counts);
    Py_TYPE(c)->tp_free((PyObject *)c);
}

static PyMethodDef Chunk_methods[] = {
    {"message", (PyCFunction)(void (*)(void))Chunk_message, METH_FASTCALL,
     "append one Message record"},
    {"json_all", (PyCFunction)(void (*)(void))Chunk_json_all, METH_FASTCALL,
     "json() of a dict's (topic, payload) items from one on; where it stopped or -1"},
    {"json", (PyCFunction)(void (*)(void))Chunk_json, METH_FASTCALL,
     "a JSON message of a known topic in one call (False: not written, the caller decides)"},
    {"use_json", (PyCFunction)(void (*)(void))Chunk_use_json, METH_FASTCALL,
     "the channels dict, the encoder and the finite check json() uses"},
    {"append", (PyCFunction)Chunk_append, METH_O, "append other records; returns the size"},
    {"take", (PyCFunction)Chunk_take, METH_NOARGS, "the chunk and its indexes, then empty"},
    {"count", (PyCFunction)Chunk_count, METH_O, "messages of a channel id so far"},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef Chunk_getset[] = {
    {"total", (getter)Chunk_get_total, NULL, "messages so far", NULL},
    {"size", (getter)Chunk_get_size, NULL, "bytes of the chunk being built", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyTypeObject ChunkType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "replay.log._chunk.Chunk",
    .tp_basicsize = sizeof(Chunk),
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_HAVE_GC,
    .tp_doc = "The MCAP chunk being built: its records and message indexes.",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Chunk_init,
    .tp_dealloc = (destructor)Chunk_dealloc,
    .tp_traverse = (traverseproc)Chunk_traverse,
    .tp_clear = (inquiry)Chunk_clear,
    .tp_methods = Chunk_methods,
    .tp_getset = Chunk_getset,
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_chunk",
                                    "The MCAP chunk being built.", -1, NULL};

PyMODINIT_FUNC PyInit__chunk(void) {
    if (PyType_Ready(&ChunkType) < 0) return NULL;
    PyObject *m = PyModule_Create(&module);
    if (!m) return NULL;
    Py_INCREF(&ChunkType);
    if (PyModule_AddObject(m, "Chunk", (PyObject *)&ChunkType) < 0) {
        Py_DECREF(&ChunkType);
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
