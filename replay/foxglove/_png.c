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

static uint32_t CRC_TABLE[8][256]; /* slicing by 8: T[k][b] = T[0] applied k more times */

static void crc_init(void) {
    for (uint32_t n = 0; n < 256; n++) {
        uint32_t c = n;
        for (int k = 0; k < 8; k++) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        CRC_TABLE[0][n] = c;
    }
    for (uint32_t n = 0; n < 256; n++)
        for (int k = 1; k < 8; k++)
            CRC_TABLE[k][n] = CRC_TABLE[0][CRC_TABLE[k - 1][n] & 0xFF] ^ (CRC_TABLE[k - 1][n] >> 8);
}

static uint32_t crc32(const uint8_t *p, size_t n) {
    uint32_t c = 0xFFFFFFFFu;
    for (; n >= 8; n -= 8, p += 8) { /* eight bytes a step (the same CRC as byte by byte) */
        const uint32_t lo = c ^ ((uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 |
                                 (uint32_t)p[3] << 24);
        c = CRC_TABLE[7][lo & 0xFF] ^ CRC_TABLE[6][(lo >> 8) & 0xFF] ^
            CRC_TABLE[5][(lo >> 16) & 0xFF] ^ CRC_TABLE[4][lo >> 24] ^ CRC_TABLE[3][p[4]] ^
            CRC_TABLE[2][p[5]] ^ CRC_TABLE[1][p[6]] ^ CRC_TABLE[0][p[7]];
    }
    for (size_t i = 0; i < n; i++) c = CRC_TABLE[0][(c ^ p[i]) & 0xFF] ^ (c >> 8);
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

static inline void put(BitWriter *bw, uint32_t value, int n) { /* n <= 32, LSB first */
    bw->bits |= (uint64_t)value << bw->nbits;
    bw->nbits += n;
    if (bw->nbits >= 32) { /* (fewer than 32 bits held between calls) */
        uint8_t *o = bw->out + bw->n;
        o[0] = (uint8_t)bw->bits;
        o[1] = (uint8_t)(bw->bits >> 8);
        o[2] = (uint8_t)(bw->bits >> 16);
        o[3] = (uint8_t)(bw->bits >> 24);
        bw->n += 4;
        bw->bits >>= 32;
        bw->nbits -= 32;
    }
}

/* the bits held, the last byte padded with zero bits */
static void flush_bits(BitWriter *bw) {
    while (bw->nbits > 0) {
        bw->out[bw->n++] = (uint8_t)bw->bits;
        bw->bits >>= 8;
        bw->nbits -= 8;
    }
    bw->bits = 0;
    bw->nbits = 0;
}

/* a Huffman code of n bits, sent most significant bit first: its bits reversed */
static uint32_t reversed(uint32_t code, int n) {
    uint32_t r = 0;
    for (int i = 0; i < n; i++) r |= ((code >> i) & 1u) << (n - 1 - i);
    return r;
}

/* The fixed literal/length codes (RFC 1951, 3.2.6), reversed for `put`, and their lengths;
 * for each match length 3..258 its symbol's code and extra bits as one value (LEN_PUT, bits
 * LEN_NBITS): filled once, at import */
static uint16_t SYM_CODE[288];
static uint8_t SYM_BITS[288];
static uint32_t LEN_PUT[259];
static uint8_t LEN_NBITS[259];

static void huffman_init(void) {
    for (int sym = 0; sym < 288; sym++) {
        uint32_t code;
        int n;
        if (sym < 144)
            code = 0x30u + (uint32_t)sym, n = 8;
        else if (sym < 256)
            code = 0x190u + (uint32_t)(sym - 144), n = 9;
        else if (sym < 280)
            code = (uint32_t)(sym - 256), n = 7;
        else
            code = 0xC0u + (uint32_t)(sym - 280), n = 8;
        SYM_CODE[sym] = (uint16_t)reversed(code, n);
        SYM_BITS[sym] = (uint8_t)n;
    }
    for (int length = 3; length <= 258; length++) {
        int li = 28;
        while (LEN_BASE[li] > length) li--;
        const int sym = 257 + li, n = SYM_BITS[sym];
        LEN_PUT[length] = SYM_CODE[sym] | (uint32_t)(length - LEN_BASE[li]) << n;
        LEN_NBITS[length] = (uint8_t)(n + LEN_EXTRA[li]);
    }
}

static inline void put_symbol(BitWriter *bw, int sym) { /* fixed literal/length codes */
    put(bw, SYM_CODE[sym], SYM_BITS[sym]);
}

/* a distance's code (5 bits, reversed) and extra bits as one value for `put`, and its bits */
static inline void distance_code(int distance, uint32_t *value, int *nbits) {
    if (distance == 1) { /* (a run's copy: code 0, no extra bits) */
        *value = 0;
        *nbits = 5;
        return;
    }
    int di = 29;
    while (DIST_BASE[di] > distance) di--;
    *value = reversed((uint32_t)di, 5) | (uint32_t)(distance - DIST_BASE[di]) << 5;
    *nbits = 5 + DIST_EXTRA[di];
}

/* a copy of `length` bytes at `distance`, as matches of 3..258 bytes; a tail of 1 or 2 bytes
 * (only when length < 3) as the literals `src` (the bytes copied) */
static void put_copy(BitWriter *bw, size_t length, int distance, const uint8_t *src) {
    uint32_t dvalue = 0;
    int dbits = 0;
    if (length >= 3) distance_code(distance, &dvalue, &dbits);
    while (length >= 3) {
        size_t take = length > 258 ? 258 : length;
        if (length - take > 0 && length - take < 3) take = length - 3;
        /* the length's code and extra bits (at most 13), the distance's (at most 18) */
        put(bw, LEN_PUT[take] | dvalue << LEN_NBITS[take], LEN_NBITS[take] + dbits);
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
        if (i <= 1 && pre && b == bg) j = 1 + pre; /* (row[0], the filter byte, is 0) */
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
static PyObject *encode(const uint8_t *pix, Py_ssize_t len, int bg, int x0, int y0, int x1,
                        int y1, int w, int h, int binary, const Py_buffer *prefix,
                        const Py_buffer *suffix) {
    PyObject *ret = NULL;
    uint8_t *rows = NULL, *out = NULL;
    if (w < 1 || h < 1 || w > 32767 || bg < 0 || bg > 255 || x0 < 0 || y0 < 0 || x1 > w ||
        y1 > h || x1 < x0 || y1 < y0 || len != (Py_ssize_t)(x1 - x0) * (y1 - y0)) {
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
        /* Adler-32 over this row: s2 gains n s1 (before) + sum (n - i) b_i, s1 the row's sum;
         * reduced modulo 65521 only when large (n < 2^16, s1 < 2^41: no overflow) */
        s2 += (uint64_t)n * s1 + rt;
        s1 += rs;
        if (s1 >= (1ull << 40)) s1 %= ADLER_BASE;
        if (s2 >= (1ull << 40)) s2 %= ADLER_BASE;
    }
    s1 %= ADLER_BASE;
    s2 %= ADLER_BASE;
    if (repeat) put_copy(&bw, repeat * n, (int)n, prev);
    put_symbol(&bw, 256); /* end of block */
    flush_bits(&bw);
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

/* An image argument: a WindowedImage (a 5-tuple: height, width, background, window (x0, y0,
 * x1, y1), uint8 pixels of the window) or a whole (h, w) uint8 or bool array (bool: binary);
 * the pixels through the buffer protocol, strided ones copied to rows. ValueError for an image
 * the encoder does not take (png.py documents them). */
typedef struct {
    Py_buffer view;
    int have_view;
    uint8_t *copy; /* strided pixels as contiguous rows, or NULL */
    const uint8_t *pix;
    Py_ssize_t len;
    int bg, x0, y0, x1, y1, w, h, binary;
} Image;

static void image_release(Image *im) {
    if (im->have_view) PyBuffer_Release(&im->view);
    im->have_view = 0;
    free(im->copy);
    im->copy = NULL;
}

static int as_int(PyObject *o, int *v) {
    long x = PyLong_AsLong(o);
    if (x == -1 && PyErr_Occurred()) return -1;
    if (x < -0x7FFFFFFFL || x > 0x7FFFFFFFL) {
        PyErr_SetString(PyExc_OverflowError, "png: an image size beyond int");
        return -1;
    }
    *v = (int)x;
    return 0;
}

static int image_parse(PyObject *image, Image *im) {
    memset(im, 0, sizeof *im);
    PyObject *pixels = image;
    const int windowed = PyTuple_Check(image) && PyTuple_GET_SIZE(image) == 5;
    if (windowed) {
        if (as_int(PyTuple_GET_ITEM(image, 0), &im->h) < 0 ||
            as_int(PyTuple_GET_ITEM(image, 1), &im->w) < 0 ||
            as_int(PyTuple_GET_ITEM(image, 2), &im->bg) < 0)
            return -1;
        PyObject *win = PySequence_Fast(PyTuple_GET_ITEM(image, 3), "png: window (x0, y0, x1, y1)");
        if (!win) return -1;
        int bad = PySequence_Fast_GET_SIZE(win) != 4;
        if (bad)
            PyErr_SetString(PyExc_ValueError, "png: window (x0, y0, x1, y1)");
        else
            bad = as_int(PySequence_Fast_GET_ITEM(win, 0), &im->x0) < 0 ||
                  as_int(PySequence_Fast_GET_ITEM(win, 1), &im->y0) < 0 ||
                  as_int(PySequence_Fast_GET_ITEM(win, 2), &im->x1) < 0 ||
                  as_int(PySequence_Fast_GET_ITEM(win, 3), &im->y1) < 0;
        Py_DECREF(win);
        if (bad) return -1;
        pixels = PyTuple_GET_ITEM(image, 4);
    }
    if (PyObject_GetBuffer(pixels, &im->view, PyBUF_RECORDS_RO) < 0) return -1;
    im->have_view = 1;
    const Py_buffer *v = &im->view;
    const char *f = v->format ? v->format : "B";
    while (*f == '@' || *f == '=' || *f == '<' || *f == '>' || *f == '!') f++;
    const int u8 = strcmp(f, "B") == 0, boolean = strcmp(f, "?") == 0;
    if (v->ndim != 2) {
        PyErr_Format(PyExc_ValueError, "png: expected an (h, w) grey image, got %d dimensions",
                     v->ndim);
        goto fail;
    }
    if (v->itemsize != 1 || !(u8 || (boolean && !windowed))) {
        PyErr_Format(PyExc_ValueError, "png: expected a uint8%s image, got format %s",
                     windowed ? "" : " or bool", v->format ? v->format : "B");
        goto fail;
    }
    const Py_ssize_t rows = v->shape[0], cols = v->shape[1];
    if (windowed) {
        if (rows != (Py_ssize_t)im->y1 - im->y0 || cols != (Py_ssize_t)im->x1 - im->x0) {
            PyErr_Format(PyExc_ValueError, "png: window (%d, %d, %d, %d) with pixels %zd x %zd",
                         im->x0, im->y0, im->x1, im->y1, rows, cols);
            goto fail;
        }
    } else {
        if (rows > 0x7FFFFFFF || cols > 0x7FFFFFFF) {
            PyErr_SetString(PyExc_ValueError, "png: an image size beyond int");
            goto fail;
        }
        im->h = im->y1 = (int)rows;
        im->w = im->x1 = (int)cols;
        im->binary = boolean;
    }
    if (im->h < 1 || im->w < 1) {
        PyErr_Format(PyExc_ValueError, "png: an empty image (%d x %d) has no PNG", im->h, im->w);
        goto fail;
    }
    im->len = rows * cols;
    im->pix = v->buf;
    if (im->len && (v->strides[1] != 1 || (rows > 1 && v->strides[0] != cols))) {
        im->copy = malloc((size_t)im->len);
        if (!im->copy) {
            PyErr_NoMemory();
            goto fail;
        }
        for (Py_ssize_t r = 0; r < rows; r++)
            for (Py_ssize_t c = 0; c < cols; c++)
                im->copy[r * cols + c] =
                    *((const uint8_t *)v->buf + r * v->strides[0] + c * v->strides[1]);
        im->pix = im->copy;
    }
    return 0;
fail:
    image_release(im);
    return -1;
}

static PyObject *encode_image(const Image *im, const Py_buffer *prefix, const Py_buffer *suffix) {
    return encode(im->pix, im->len, im->bg, im->x0, im->y0, im->x1, im->y1, im->w, im->h,
                  im->binary, prefix, suffix);
}

static PyObject *py_png(PyObject *self, PyObject *image) {
    Image im;
    if (image_parse(image, &im) < 0) return NULL;
    PyObject *ret = encode_image(&im, NULL, NULL);
    image_release(&im);
    return ret;
}

static PyObject *py_message(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 3) {
        PyErr_SetString(PyExc_TypeError, "message(prefix, suffix, image)");
        return NULL;
    }
    Py_buffer pre, suf;
    Image im;
    if (PyObject_GetBuffer(args[0], &pre, PyBUF_SIMPLE) < 0) return NULL;
    if (PyObject_GetBuffer(args[1], &suf, PyBUF_SIMPLE) < 0) {
        PyBuffer_Release(&pre);
        return NULL;
    }
    PyObject *ret = NULL;
    if (image_parse(args[2], &im) == 0) {
        ret = encode_image(&im, &pre, &suf);
        image_release(&im);
    }
    PyBuffer_Release(&pre);
    PyBuffer_Release(&suf);
    return ret;
}

/* messages(message, views, frames, start, prefix, t_ns): a sensor's frame in one call. For
 * each (view, image) of the sequence frames from index start: views[view] = (channel id, suffix)
 * gives its channel and the message's fields after the PNG; the image's message (prefix, the
 * PNG, suffix, as message() makes it) goes to message(channel, t_ns, t_ns, data) (a log's
 * compiled record writer). Returns -1 when all are written, else the index of the first frame
 * whose view has no channel yet (it and those after it not written: the caller makes the channel
 * and calls again from there). */
static PyObject *py_messages(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 6 || !PyDict_Check(args[1])) {
        PyErr_SetString(PyExc_TypeError,
                        "messages(message, views: dict, frames, start, prefix, t_ns)");
        return NULL;
    }
    PyObject *message = args[0], *views = args[1], *t_ns = args[5];
    Py_ssize_t start = PyLong_AsSsize_t(args[3]);
    if (start == -1 && PyErr_Occurred()) return NULL;
    PyObject *frames = PySequence_Fast(args[2], "messages: frames is a sequence");
    if (!frames) return NULL;
    Py_buffer pre;
    if (PyObject_GetBuffer(args[4], &pre, PyBUF_SIMPLE) < 0) {
        Py_DECREF(frames);
        return NULL;
    }
    PyObject *ret = NULL;
    const Py_ssize_t n = PySequence_Fast_GET_SIZE(frames);
    Py_ssize_t i;
    for (i = start < 0 ? 0 : start; i < n; i++) {
        PyObject *frame = PySequence_Fast_GET_ITEM(frames, i);
        if (!PyTuple_Check(frame) || PyTuple_GET_SIZE(frame) != 2) {
            PyErr_SetString(PyExc_TypeError, "messages: a frame is (view, image)");
            goto done;
        }
        PyObject *slot = PyDict_GetItemWithError(views, PyTuple_GET_ITEM(frame, 0));
        if (!slot) {
            if (PyErr_Occurred()) goto done;
            break; /* a view without a channel: the caller's */
        }
        if (!PyTuple_Check(slot) || PyTuple_GET_SIZE(slot) != 2) {
            PyErr_SetString(PyExc_TypeError, "messages: views[view] is (channel, suffix)");
            goto done;
        }
        Py_buffer suf;
        if (PyObject_GetBuffer(PyTuple_GET_ITEM(slot, 1), &suf, PyBUF_SIMPLE) < 0) goto done;
        Image im;
        PyObject *data = NULL;
        if (image_parse(PyTuple_GET_ITEM(frame, 1), &im) == 0) {
            data = encode_image(&im, &pre, &suf);
            image_release(&im);
        }
        PyBuffer_Release(&suf);
        if (!data) goto done;
        PyObject *call[4] = {PyTuple_GET_ITEM(slot, 0), t_ns, t_ns, data};
        PyObject *r = PyObject_Vectorcall(message, call, 4, NULL);
        Py_DECREF(data);
        if (!r) goto done;
        Py_DECREF(r);
    }
    ret = PyLong_FromSsize_t(i < n ? i : -1);
done:
    PyBuffer_Release(&pre);
    Py_DECREF(frames);
    return ret;
}

static PyMethodDef methods[] = {
    {"png", py_png, METH_O, "a grey image (a WindowedImage or an array) as a PNG file"},
    {"message", (PyCFunction)(void (*)(void))py_message, METH_FASTCALL,
     "prefix, the image's PNG as protobuf field 2, suffix"},
    {"messages", (PyCFunction)(void (*)(void))py_messages, METH_FASTCALL,
     "a sensor's frame: each view's image message to its channel"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_png",
                                    "A grey PNG of a windowed image.", -1, methods};

PyMODINIT_FUNC PyInit__png(void) {
    crc_init();
    huffman_init();
    return PyModule_Create(&module);
}
