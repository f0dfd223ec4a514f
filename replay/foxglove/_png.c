/* A grey PNG (replay/foxglove/png.py is the only caller and documents it): signature, IHDR
 * (8-bit grey), one IDAT holding the zlib stream of the filtered rows, IEND; CRC-32 of each
 * chunk (ISO 3309, as zlib's). Plain C over the buffer protocol: no NumPy headers, no zlib.
 *
 * The image is (h, w) uint8, `bg` outside the window [x0, x1) x [y0, y1), where it is `pix`
 * (C-contiguous, (y1 - y0) rows of x1 - x0; with `binary`, any non-zero byte is 255). Each row
 * is filtered with type 0 (None): a 0 byte, then the row. The stream (RFC 1950) is one final
 * deflate block of fixed Huffman codes (RFC 1951, 3.2.6): a row equal to the row above joins a
 * copy of the rows above (distance w + 1); any other row is its literals, runs of 4 or more
 * equal bytes as a literal and a copy at distance 1. The encoding reads the rows only, never
 * the window: the same pixels give the same bytes however they were windowed. The Adler-32
 * of a row is (sum of bytes, sum of (n - i) b_i), so a repeated row costs O(1).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define ADLER_BASE 65521u

static uint32_t CRC_TABLE[256];

static void crc_init(void) {
    for (uint32_t n = 0; n < 256; n++) {
        uint32_t c = n;
        for (int k = 0; k < 8; k++) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        CRC_TABLE[n] = c;
    }
}

static uint32_t crc32(const uint8_t *p, size_t n) {
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) c = CRC_TABLE[(c ^ p[i]) & 0xFF] ^ (c >> 8);
    return c ^ 0xFFFFFFFFu;
}

static inline void be32(uint8_t *p, uint32_t v) {
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
}

/* PNG signature, IHDR chunk, IDAT length and tag: what comes before the zlib stream */
#define PNG_HEAD (8 + 25 + 8)

static const uint16_t LEN_BASE[29] = {3,  4,  5,  6,  7,  8,  9,  10, 11,  13,  15,  17,  19,  23, 27,
                                      31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
static const uint8_t LEN_EXTRA[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                      2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
static const uint16_t DIST_BASE[30] = {1,    2,    3,    4,    5,    7,     9,     13,    17,  25,
                                       33,   49,   65,   97,   129,  193,   257,   385,   513, 769,
                                       1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
static const uint8_t DIST_EXTRA[30] = {0, 0, 0, 0, 1, 1, 2, 2,  3,  3,  4,  4,  5,  5,  6,
                                       6, 7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13};

typedef struct {
    uint8_t *out;
    size_t n;
    uint64_t bits;
    int nbits;
} BitWriter;

static inline void put(BitWriter *bw, uint32_t value, int n) { /* n <= 24, LSB first */
    bw->bits |= (uint64_t)value << bw->nbits;
    bw->nbits += n;
    while (bw->nbits >= 8) {
        bw->out[bw->n++] = (uint8_t)bw->bits;
        bw->bits >>= 8;
        bw->nbits -= 8;
    }
}

/* a Huffman code of n bits, sent most significant bit first */
static inline void put_code(BitWriter *bw, uint32_t code, int n) {
    uint32_t r = 0;
    for (int i = 0; i < n; i++) r |= ((code >> i) & 1u) << (n - 1 - i);
    put(bw, r, n);
}

static inline void put_symbol(BitWriter *bw, int sym) { /* fixed literal/length codes */
    if (sym < 144)
        put_code(bw, 0x30u + (uint32_t)sym, 8);
    else if (sym < 256)
        put_code(bw, 0x190u + (uint32_t)(sym - 144), 9);
    else if (sym < 280)
        put_code(bw, (uint32_t)(sym - 256), 7);
    else
        put_code(bw, 0xC0u + (uint32_t)(sym - 280), 8);
}

static void put_match(BitWriter *bw, int length, int distance) { /* 3 <= length <= 258 */
    int li = 28;
    while (LEN_BASE[li] > length) li--;
    put_symbol(bw, 257 + li);
    if (LEN_EXTRA[li]) put(bw, (uint32_t)(length - LEN_BASE[li]), LEN_EXTRA[li]);
    int di = 29;
    while (DIST_BASE[di] > distance) di--;
    put_code(bw, (uint32_t)di, 5);
    if (DIST_EXTRA[di]) put(bw, (uint32_t)(distance - DIST_BASE[di]), DIST_EXTRA[di]);
}

/* a copy of `length` bytes at `distance`, as matches of 3..258 bytes; a tail of 1 or 2 bytes
 * (only when length < 3) as the literals `src` (the bytes copied) */
static void put_copy(BitWriter *bw, size_t length, int distance, const uint8_t *src) {
    while (length >= 3) {
        size_t take = length > 258 ? 258 : length;
        if (length - take > 0 && length - take < 3) take = length - 3;
        put_match(bw, (int)take, distance);
        length -= take;
        src += take;
    }
    for (size_t i = 0; i < length; i++) put_symbol(bw, src[i]);
}

/* One row of n bytes as literals, each run of 4 or more equal bytes as a literal and a copy at
 * distance 1. Bytes [1, 1 + pre) and [n - post, n) are known to be `bg` (the scan jumps over
 * them: the same symbols as scanning them byte by byte). */
static void put_row(BitWriter *bw, const uint8_t *row, size_t n, int bg, size_t pre, size_t post) {
    size_t i = 0;
    const size_t tail = n - post;
    while (i < n) {
        uint8_t b = row[i];
        size_t j = i + 1;
        if (j == 1 && pre && b == bg) j = 1 + pre;
        for (;;) {
            while (j < n && j < tail && row[j] == b) j++;
            if (j == tail && j < n && b == bg)
                j = n;
            else if (j < n && j >= tail && row[j] == b)
                j++;
            else
                break;
        }
        put_symbol(bw, b);
        size_t run = j - i - 1; /* bytes after the first equal to it */
        if (run >= 3)
            put_copy(bw, run, 1, row + i + 1);
        else
            for (size_t k = 0; k < run; k++) put_symbol(bw, b);
        i = j;
    }
}

/* (s1, s2) of Adler-32 from (0, 0) over a run of n bytes c, added to *rs, *rt */
static inline void adler_run(uint64_t *rs, uint64_t *rt, uint64_t n, uint64_t c) {
    *rt += n * *rs + c * (n * (n + 1) / 2);
    *rs += n * c;
}

/* The PNG of the image; with a prefix, the protobuf message prefix + field 2 (the PNG,
 * length-delimited) + suffix */
static PyObject *encode(Py_buffer P, int bg, int x0, int y0, int x1, int y1, int w, int h,
                        int binary, const Py_buffer *prefix, const Py_buffer *suffix) {
    PyObject *ret = NULL;
    uint8_t *rows = NULL, *out = NULL;
    if (w < 1 || h < 1 || w > 32767 || bg < 0 || bg > 255 || x0 < 0 || y0 < 0 || x1 > w ||
        y1 > h || x1 < x0 || y1 < y0 || P.len != (Py_ssize_t)(x1 - x0) * (y1 - y0)) {
        PyErr_SetString(PyExc_ValueError, "png: bad image size, window or pixels");
        goto done;
    }
    const size_t n = (size_t)w + 1;
    rows = malloc(3 * n);
    /* worst case every byte a 9-bit literal, plus the PNG's chunks, zlib header, end code and
     * Adler-32 */
    /* room for the prefix and the field's head */
    const size_t base = prefix ? (size_t)prefix->len + 1 + 5 : 0;
    const size_t cap =
        base + (size_t)h * n * 9 / 8 + PNG_HEAD + 64 + (suffix ? (size_t)suffix->len : 0);
    out = malloc(cap);
    if (!rows || !out) {
        PyErr_NoMemory();
        goto done;
    }
    uint8_t *png = out + base;
    const uint8_t *pix = P.buf;
    const int ww = x1 - x0;
    if (ww == 0) y1 = y0; /* an empty window: every row is background */
    const size_t pre = (size_t)x0, post = (size_t)(w - x1);
    uint8_t *bgrow = rows + 2 * n, *cur = rows, *prev = rows + n;
    bgrow[0] = 0;
    memset(bgrow + 1, bg, (size_t)w);
    uint64_t bg_s = 0, bg_t = 0;
    adler_run(&bg_s, &bg_t, 1, 0);
    adler_run(&bg_s, &bg_t, (uint64_t)w, (uint64_t)bg);
    bg_s %= ADLER_BASE;
    bg_t %= ADLER_BASE;
    static const uint8_t SIGNATURE[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    memcpy(png, SIGNATURE, 8);
    be32(png + 8, 13);
    memcpy(png + 12, "IHDR", 4);
    be32(png + 16, (uint32_t)w);
    be32(png + 20, (uint32_t)h);
    const uint8_t ihdr[5] = {8, 0, 0, 0, 0}; /* 8-bit grey, deflate, filter set 0, no interlace */
    memcpy(png + 24, ihdr, 5);
    be32(png + 29, crc32(png + 12, 17));
    memcpy(png + 37, "IDAT", 4);
    BitWriter bw = {png, PNG_HEAD, 0, 0};
    png[bw.n++] = 0x78; /* deflate, 32 KiB window */
    png[bw.n++] = 0x01; /* fastest; (0x78 << 8 | 0x01) % 31 == 0 */
    put(&bw, 1, 1);     /* BFINAL */
    put(&bw, 1, 2);     /* BTYPE 01: fixed Huffman codes */
    uint64_t s1 = 1, s2 = 0, rs = 0, rt = 0;
    size_t repeat = 0; /* rows equal to the one above, not yet written */
    int prev_bg = 0;   /* the row above is known to be all background */
    for (int y = 0; y < h; y++) {
        if (y < y0 || y >= y1) { /* a background row */
            if (y > 0 && (prev_bg || memcmp(prev, bgrow, n) == 0)) {
                repeat++;
            } else {
                if (repeat) put_copy(&bw, repeat * n, (int)n, prev);
                repeat = 0;
                put_row(&bw, bgrow, n, bg, 0, 0);
                memcpy(prev, bgrow, n);
                rs = bg_s;
                rt = bg_t;
            }
            prev_bg = 1;
        } else {
            const uint8_t *src = pix + (size_t)(y - y0) * ww;
            cur[0] = 0;
            memset(cur + 1, bg, pre);
            if (binary)
                for (int x = 0; x < ww; x++) cur[1 + x0 + x] = src[x] ? 255 : 0;
            else
                memcpy(cur + 1 + x0, src, (size_t)ww);
            memset(cur + 1 + x1, bg, post);
            if (y > 0 && memcmp(cur, prev, n) == 0) {
                repeat++;
            } else {
                if (repeat) put_copy(&bw, repeat * n, (int)n, prev);
                repeat = 0;
                put_row(&bw, cur, n, bg, pre, post);
                rs = rt = 0;
                adler_run(&rs, &rt, 1, 0);
                adler_run(&rs, &rt, pre, (uint64_t)bg);
                for (int x = 0; x < ww; x++) {
                    rs += cur[1 + x0 + x];
                    rt += rs;
                }
                adler_run(&rs, &rt, post, (uint64_t)bg);
                rs %= ADLER_BASE;
                rt %= ADLER_BASE;
                uint8_t *t = prev;
                prev = cur;
                cur = t;
                prev_bg = 0;
            }
        }
        /* Adler-32 over this row: s2 gains n s1 (before) + sum (n - i) b_i, s1 the row's sum */
        s2 = (s2 + (uint64_t)n % ADLER_BASE * s1 + rt) % ADLER_BASE;
        s1 = (s1 + rs) % ADLER_BASE;
    }
    if (repeat) put_copy(&bw, repeat * n, (int)n, prev);
    put_symbol(&bw, 256); /* end of block */
    if (bw.nbits) put(&bw, 0, 8 - bw.nbits);
    const uint32_t adler = (uint32_t)(s2 << 16 | s1);
    png[bw.n++] = (uint8_t)(adler >> 24);
    png[bw.n++] = (uint8_t)(adler >> 16);
    png[bw.n++] = (uint8_t)(adler >> 8);
    png[bw.n++] = (uint8_t)adler;
    be32(png + 33, (uint32_t)(bw.n - PNG_HEAD)); /* the IDAT's length */
    be32(png + bw.n, crc32(png + 37, bw.n - 37));
    bw.n += 4;
    static const uint8_t IEND[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xAE, 0x42, 0x60, 0x82};
    memcpy(png + bw.n, IEND, 12);
    bw.n += 12;
    size_t total = bw.n;
    if (prefix) {
        size_t k = (size_t)prefix->len;
        memcpy(out, prefix->buf, k);
        out[k++] = 0x12;
        for (size_t v = bw.n; ; v >>= 7) {
            out[k++] = (uint8_t)(v < 0x80 ? v : (v & 0x7F) | 0x80);
            if (v < 0x80) break;
        }
        memmove(out + k, png, bw.n);
        k += bw.n;
        memcpy(out + k, suffix->buf, (size_t)suffix->len);
        total = k + (size_t)suffix->len;
    }
    ret = PyBytes_FromStringAndSize((const char *)out, (Py_ssize_t)total);
done:
    free(rows);
    free(out);
    return ret;
}

static PyObject *py_png(PyObject *self, PyObject *args) {
    Py_buffer P;
    int bg, x0, y0, x1, y1, w, h, binary;
    if (!PyArg_ParseTuple(args, "y*iiiiiiii", &P, &bg, &x0, &y0, &x1, &y1, &w, &h, &binary))
        return NULL;
    PyObject *ret = encode(P, bg, x0, y0, x1, y1, w, h, binary, NULL, NULL);
    PyBuffer_Release(&P);
    return ret;
}

static PyObject *py_message(PyObject *self, PyObject *args) {
    Py_buffer pre, suf, P;
    int bg, x0, y0, x1, y1, w, h, binary;
    if (!PyArg_ParseTuple(args, "y*y*y*iiiiiiii", &pre, &suf, &P, &bg, &x0, &y0, &x1, &y1, &w,
                          &h, &binary))
        return NULL;
    PyObject *ret = encode(P, bg, x0, y0, x1, y1, w, h, binary, &pre, &suf);
    PyBuffer_Release(&pre);
    PyBuffer_Release(&suf);
    PyBuffer_Release(&P);
    return ret;
}

static PyMethodDef methods[] = {
    {"png", py_png, METH_VARARGS, "a windowed grey image as a PNG file"},
    {"message", py_message, METH_VARARGS, "prefix, the PNG as protobuf field 2, suffix"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_png",
                                    "A grey PNG of a windowed image.", -1, methods};

PyMODINIT_FUNC PyInit__png(void) {
    crc_init();
    return PyModule_Create(&module);
}
