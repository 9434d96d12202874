/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the .npy reader and writer of eval/perturb
 * (src/tools/common/npy.c): header parsing (magic, version 1/2/3, header
 * length, the dict), dtype / fortran_order / shape validation, the size check
 * against the file, the streaming block reads, then a round trip of whatever
 * was read through the writer.
 *
 * Input: byte 0 picks the mode (bit 0 read as double, bit 1 --allow-nonfinite,
 * bits 2-3 the accepted column counts: {3} eval's, {6} perturb's, {3, 6}, {11};
 * bits 4-6 the block size, 1..64 rows; bit 7 read through a pipe instead of a
 * regular file, so the reader has no file size and must find truncation while
 * streaming), the rest is the file.
 *
 * Checks, besides ASan/UBSan (an independent little-endian decoder of the
 * input's own bytes is the reference):
 * - a failure carries its status in err.status, is BG_ERR_FORMAT (or IO, or
 *   OUT_OF_MEMORY), its message starts "NAME: byte N:" with N within the
 *   input, and no error follows the end of the data;
 * - an accepted header has the version's header length (data_off), a column
 *   count that was asked for, and, for a regular file, data for the whole
 *   shape (computed without overflow: a shape whose byte count wraps must
 *   be refused);
 * - every block is no longer than asked and the blocks add up to the shape's
 *   rows; every value equals the reference decoding (float64 -> float rounded
 *   to nearest), is finite unless nonfinite is allowed;
 * - writing the values with bgt_npy_begin/write/finish and reading that file
 *   back gives the same shape and the same bits. */
#define _GNU_SOURCE
#include <math.h>
#include "common/npy.h"
#include "fuzz_util.h"

#define MAX_BLOCK 64
#define MAX_VALUES (1u << 20) /* values kept for the round trip (4/8 MiB) */

static const size_t col_sets[4][2] = {{3, 3}, {6, 6}, {3, 6}, {11, 11}};
static const int col_counts[4] = {1, 1, 2, 1};

static double *vals; /* every value read, row-major, for the round trip */

static void check_failure(const bgt_err *err, bg_status st, const char *name, size_t size)
{
    FUZZ_CHECK(err->status == st, "returned %d, err.status %d", (int)st, (int)err->status);
    FUZZ_CHECK(err->msg[0] != '\0', "status %d without a message", (int)st);
    FUZZ_CHECK(st == BG_ERR_FORMAT || st == BG_ERR_IO || st == BG_ERR_OUT_OF_MEMORY,
               "status %d: %s", (int)st, err->msg);
    if (st != BG_ERR_FORMAT)
        return;
    size_t nl = strlen(name);
    unsigned long long off = 0;
    FUZZ_CHECK(strncmp(err->msg, name, nl) == 0 &&
                   sscanf(err->msg + nl, ": byte %llu:", &off) == 1,
               "message does not start with \"%s: byte N:\": \"%s\"", name, err->msg);
    FUZZ_CHECK(off <= size, "byte offset %llu beyond the %zu-byte input: %s", off, size,
               err->msg);
}

static double le_value(const uint8_t *p, int f64)
{
    uint64_t u = 0;
    for (int b = (f64 ? 8 : 4) - 1; b >= 0; b--)
        u = u << 8 | p[b];
    if (f64) {
        double d;
        memcpy(&d, &u, 8);
        return d;
    }
    uint32_t u32 = (uint32_t)u;
    float f;
    memcpy(&f, &u32, 4);
    return f;
}

static int same(double a, double b)
{
    return (isnan(a) && isnan(b)) || memcmp(&a, &b, sizeof a) == 0;
}

/* Open `path` as the reader does in eval: the file's bytes are `data`. */
static bg_status open_in(bgt_npy_in *a, bgt_err *err, const char *path, int nonfinite, int set)
{
    return bgt_npy_open(a, err, path, nonfinite, col_sets[set], col_counts[set]);
}

/* Read every block; 0 or the failing status. *total: rows read. */
static bg_status read_all(bgt_npy_in *a, int dbl, int nonfinite, size_t max, const uint8_t *data,
                          size_t size, int check_bytes, size_t *total)
{
    float fbuf[11][MAX_BLOCK];
    double dbuf[11][MAX_BLOCK];
    float *fcols[11];
    double *dcols[11];
    for (int k = 0; k < 11; k++) {
        fcols[k] = fbuf[k];
        dcols[k] = dbuf[k];
    }
    const size_t es = a->f64 ? 8 : 4, cols = a->cols;
    int ended = 0;
    *total = 0;
    for (;;) {
        size_t rows = (size_t)-1;
        bg_status st = bgt_npy_read(a, dbl, fcols, dcols, max, &rows);
        if (st) {
            FUZZ_CHECK(!ended, "an error after the end of the data");
            return st;
        }
        FUZZ_CHECK(rows <= max, "%zu rows in a block of %zu", rows, max);
        for (size_t r = 0; r < rows; r++)
            for (size_t k = 0; k < cols; k++) {
                size_t row = *total + r;
                double got = dbl ? dbuf[k][r] : fbuf[k][r];
                FUZZ_CHECK(nonfinite || isfinite(got),
                           "non-finite value accepted without --allow-nonfinite (row %zu)", row);
                if (check_bytes) {
                    size_t off = a->data_off + (row * cols + k) * es;
                    FUZZ_CHECK(off + es <= size, "value at byte %zu beyond the input", off);
                    double want = le_value(data + off, a->f64);
                    if (!dbl)
                        want = (float)want;
                    FUZZ_CHECK(same(got, want), "row %zu column %zu: read %a, the bytes say %a",
                               row, k, got, want);
                }
                if (row * cols + k < MAX_VALUES)
                    vals[row * cols + k] = got;
            }
        if (rows == 0) {
            if (ended)
                break;
            ended = 1; /* one more call: still the end, no error */
        } else {
            FUZZ_CHECK(!ended, "rows after the end of the data");
            *total += rows;
        }
    }
    FUZZ_CHECK(*total == a->rows, "%zu rows read, the shape has %zu", *total, a->rows);
    return 0;
}

/* Write the values read, read them back: same shape, same bits. */
static void round_trip(size_t rows, size_t cols, int dbl, int nonfinite, int set)
{
    if (rows * cols > MAX_VALUES)
        return;
    static float fmem[MAX_VALUES];
    const float *fcols[11];
    const double *dcols[11];
    float *fbuf[11];
    double *dbuf[11];
    for (size_t k = 0; k < cols; k++) {
        /* column k of the row-major values as a column array */
        dbuf[k] = malloc((rows ? rows : 1) * sizeof(double));
        FUZZ_CHECK(dbuf[k] != NULL, "out of memory");
        fbuf[k] = fmem + k * rows;
        for (size_t r = 0; r < rows; r++) {
            dbuf[k][r] = vals[r * cols + k];
            fbuf[k][r] = (float)vals[r * cols + k];
        }
        fcols[k] = fbuf[k];
        dcols[k] = dbuf[k];
    }
    char path[512];
    snprintf(path, sizeof path, "%s/rt.npy", fuzz_tmpdir());
    FILE *f = fopen(path, "w+b");
    FUZZ_CHECK(f != NULL, "cannot create %s", path);
    bgt_err err;
    bgt_err_clear(&err);
    bgt_npy_out o;
    FUZZ_CHECK(bgt_npy_begin(&o, f, dbl, cols, &err) == BG_OK, "begin: %s", err.msg);
    for (size_t r = 0; r < rows; r += 7) { /* in uneven blocks */
        size_t n = rows - r < 7 ? rows - r : 7;
        const float *fc[11];
        const double *dc[11];
        for (size_t k = 0; k < cols; k++) {
            fc[k] = fcols[k] + r;
            dc[k] = dcols[k] + r;
        }
        bgt_npy_write(&o, fc, dc, n);
    }
    FUZZ_CHECK(bgt_npy_finish(&o, path, &err) == BG_OK, "finish: %s", err.msg);
    FUZZ_CHECK(fclose(f) == 0, "closing %s", path);
    for (size_t k = 0; k < cols; k++)
        free(dbuf[k]);

    bgt_npy_in a;
    bg_status st = open_in(&a, &err, path, nonfinite, set);
    FUZZ_CHECK(st == BG_OK, "the writer's own file is refused: %s", err.msg);
    FUZZ_CHECK(a.rows == rows && a.cols == cols && a.f64 == dbl,
               "wrote (%zu, %zu) f64=%d, read back (%zu, %zu) f64=%d", rows, cols, dbl, a.rows,
               a.cols, a.f64);
    FUZZ_CHECK(a.data_off % 64 == 0, "the writer's data starts at byte %zu", a.data_off);
    double *first = malloc((rows * cols ? rows * cols : 1) * sizeof(double));
    FUZZ_CHECK(first != NULL, "out of memory");
    memcpy(first, vals, rows * cols * sizeof(double));
    size_t total;
    st = read_all(&a, dbl, nonfinite, MAX_BLOCK, NULL, 0, 0, &total);
    FUZZ_CHECK(st == BG_OK, "reading the writer's own file back: %s", err.msg);
    for (size_t i = 0; i < rows * cols; i++)
        FUZZ_CHECK(same(vals[i], first[i]), "value %zu: wrote %a, read back %a", i, first[i],
                   vals[i]);
    free(first);
    bgt_npy_close(&a);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    if (!vals) {
        vals = malloc(MAX_VALUES * sizeof(double));
        FUZZ_CHECK(vals != NULL, "out of memory");
    }
    const int mode = data[0];
    const int dbl = mode & 1, nonfinite = (mode >> 1) & 1, set = (mode >> 2) & 3;
    const size_t max = (size_t)1 << ((mode >> 4) & 7) > MAX_BLOCK ? MAX_BLOCK
                                                                   : (size_t)1 << ((mode >> 4) & 7);
    /* A pipe holds 64 KiB without a reader: larger inputs go through a file. */
    const int piped = (mode >> 7) & 1 && size - 1 <= 65536;
    data++;
    size--;

    char path[512];
    int fds[2] = {-1, -1};
    if (piped) {
        FUZZ_CHECK(pipe(fds) == 0, "pipe: %s", strerror(errno));
        fcntl(fds[1], F_SETPIPE_SZ, 65536);
        FUZZ_CHECK(size == 0 || write(fds[1], data, size) == (ssize_t)size, "pipe write");
        close(fds[1]);
        snprintf(path, sizeof path, "/proc/self/fd/%d", fds[0]);
    } else {
        snprintf(path, sizeof path, "%s", fuzz_write_file("in.npy", data, size));
    }

    bgt_err err;
    bgt_err_clear(&err);
    bgt_npy_in a;
    bg_status st = open_in(&a, &err, path, nonfinite, set);
    if (fds[0] >= 0)
        close(fds[0]); /* the reader has its own descriptor */
    if (st) {
        check_failure(&err, st, path, size);
        bgt_npy_close(&a);
        return 0;
    }
    /* The header as the format defines it, decoded here. */
    FUZZ_CHECK(size >= 10 && data[6] >= 1 && data[6] <= 3, "accepted without magic/version");
    size_t hoff = data[6] == 1 ? 10 : 12;
    size_t hlen = data[6] == 1 ? (size_t)data[8] | (size_t)data[9] << 8
                               : (size_t)data[8] | (size_t)data[9] << 8 |
                                     (size_t)data[10] << 16 | (size_t)data[11] << 24;
    FUZZ_CHECK(a.data_off == hoff + hlen, "data at byte %zu, the header says %zu", a.data_off,
               hoff + hlen);
    /* A shape is of non-negative integers: "(-1, 3)" is not 2^64 - 1 rows. */
    const uint8_t *sh = memmem(data + hoff, hlen, "'shape'", 7);
    FUZZ_CHECK(sh != NULL, "accepted without a shape");
    const uint8_t *rpar = memchr(sh, ')', (size_t)(data + hoff + hlen - sh));
    FUZZ_CHECK(rpar && !memchr(sh, '-', (size_t)(rpar - sh)), "negative shape accepted: %zu rows",
               a.rows);
    int ok = 0;
    for (int i = 0; i < col_counts[set]; i++)
        ok |= a.cols == col_sets[set][i];
    FUZZ_CHECK(ok, "%zu columns accepted", a.cols);
    const size_t es = a.f64 ? 8 : 4;
    if (!piped) {
        /* Without overflow: rows <= (size - data_off) / (cols * es). */
        FUZZ_CHECK(a.data_off <= size && a.rows <= (size - a.data_off) / (a.cols * es),
                   "shape (%zu, %zu) accepted for %zu data bytes", a.rows, a.cols,
                   size - a.data_off);
    }
    size_t total;
    st = read_all(&a, dbl, nonfinite, max, data, size, 1, &total);
    bgt_npy_close(&a);
    if (st) {
        check_failure(&err, st, path, size);
        /* The size was checked at open: only a value can be refused now. */
        FUZZ_CHECK(piped || st != BG_ERR_FORMAT || strstr(err.msg, "non-finite") ||
                       strstr(err.msg, "out of the range"),
                   "a regular file failed while streaming, not on a value: %s", err.msg);
        return 0;
    }
    round_trip(total, a.cols, dbl, nonfinite, set);
    return 0;
}
