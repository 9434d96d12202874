/* SPDX-License-Identifier: MIT */
/* .npy reader and writer (npy.h). The host must be little-endian for the
 * fast copy; a big-endian host swaps bytes (checked at run time). */
#define _POSIX_C_SOURCE 200809L
#include "npy.h"
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define NPY_BLOCK_BYTES (1u << 20)

int bgt_npy_path(const char *path)
{
    size_t n = strlen(path);
    return n >= 4 && path[n - 4] == '.' && tolower((unsigned char)path[n - 3]) == 'n' &&
           tolower((unsigned char)path[n - 2]) == 'p' && tolower((unsigned char)path[n - 1]) == 'y';
}

static int host_le(void)
{
    const uint16_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 1;
}

static bg_status bad(bgt_npy_in *a, size_t off, const char *what)
{
    return bgt_fail(a->err, BG_ERR_FORMAT, "%s: byte %zu: %s", a->name, off, what);
}

/* The value of 'key' in a header dict: a pointer just after "'key':" and blanks;
 * NULL if the key is absent or the header ends there (no value). */
static const char *dict_value(const char *h, const char *key)
{
    char pat[32];
    snprintf(pat, sizeof pat, "'%s'", key);
    const char *p = strstr(h, pat);
    if (!p)
        return NULL;
    p += strlen(pat);
    while (*p == ' ')
        p++;
    if (*p != ':')
        return NULL;
    p++;
    while (*p == ' ')
        p++;
    return *p ? p : NULL;
}

bg_status bgt_npy_open(bgt_npy_in *a, bgt_err *err, const char *path, int allow_nonfinite,
                       const size_t *want_cols, int nwant)
{
    memset(a, 0, sizeof *a);
    a->err = err;
    a->name = path;
    a->allow_nonfinite = allow_nonfinite;
    a->fp = fopen(path, "rb");
    if (!a->fp)
        return bgt_fail(err, BG_ERR_INVALID_ARGUMENT, "cannot open input %s: %s", path,
                        strerror(errno));
    struct stat st;
    if (fstat(fileno(a->fp), &st) == 0 && S_ISREG(st.st_mode))
        a->size = (size_t)st.st_size;
    unsigned char pre[12];
    size_t got = fread(pre, 1, 10, a->fp);
    if (got < 10 || memcmp(pre, "\x93NUMPY", 6) != 0)
        return bad(a, 0, "not a .npy file (no \\x93NUMPY magic)");
    size_t hlen, hoff;
    if (pre[6] == 1) {
        hlen = (size_t)pre[8] | (size_t)pre[9] << 8;
        hoff = 10;
    } else if (pre[6] == 2 || pre[6] == 3) {
        if (fread(pre + 10, 1, 2, a->fp) != 2)
            return bad(a, 10, "truncated header");
        hlen = (size_t)pre[8] | (size_t)pre[9] << 8 | (size_t)pre[10] << 16 |
               (size_t)pre[11] << 24;
        hoff = 12;
    } else {
        return bad(a, 6, "unsupported .npy version (1.0, 2.0 and 3.0 are read)");
    }
    if (hlen > 65536)
        return bad(a, 8, "header longer than 64 KiB");
    char *h = malloc(hlen + 1);
    if (!h)
        return bgt_fail(err, BG_ERR_OUT_OF_MEMORY, "out of memory");
    if (fread(h, 1, hlen, a->fp) != hlen) {
        free(h);
        return bad(a, hoff, "truncated header");
    }
    h[hlen] = '\0';
    bg_status rc = 0;
    const char *d = dict_value(h, "descr"), *fo = dict_value(h, "fortran_order"),
               *sh = dict_value(h, "shape");
    char msg[160];
    if (!d || !fo || !sh) {
        rc = bad(a, hoff, "header lacks 'descr', 'fortran_order' or 'shape'");
    } else if (strncmp(d, "'<f4'", 5) == 0 || (strncmp(d, "'=f4'", 5) == 0 && host_le())) {
        a->f64 = 0;
    } else if (strncmp(d, "'<f8'", 5) == 0 || (strncmp(d, "'=f8'", 5) == 0 && host_le())) {
        a->f64 = 1;
    } else {
        size_t dl = strcspn(d + 1, "'") + 2;
        snprintf(msg, sizeof msg, "dtype %.*s is not little-endian float32 ('<f4') or float64 "
                                  "('<f8')", (int)(dl < 24 ? dl : 24), d);
        rc = bad(a, hoff + (size_t)(d - h), msg);
    }
    if (!rc && strncmp(fo, "False", 5) != 0)
        rc = bad(a, hoff + (size_t)(fo - h), "Fortran-order array (save it C-contiguous)");
    if (!rc) {
        unsigned long long n, k;
        int used = 0;
        if (sscanf(sh, "(%llu , %llu )%n", &n, &k, &used) < 2 || used == 0 ||
            memchr(sh, '-', (size_t)used)) { /* %llu reads "-1" as 2^64 - 1 */
            rc = bad(a, hoff + (size_t)(sh - h), "shape is not (N, K)");
        } else if (k && n > SIZE_MAX / k / 8) { /* the byte count below must not wrap */
            snprintf(msg, sizeof msg, "shape (%llu, %llu) is too large", n, k);
            rc = bad(a, hoff + (size_t)(sh - h), msg);
        } else {
            int ok = 0;
            for (int i = 0; i < nwant; i++)
                ok |= k == want_cols[i];
            if (!ok) {
                snprintf(msg, sizeof msg, "shape (%llu, %llu): expected %zu columns", n, k,
                         want_cols[nwant - 1]);
                rc = bad(a, hoff + (size_t)(sh - h), msg);
            }
            a->rows = (size_t)n, a->cols = (size_t)k;
        }
    }
    free(h);
    if (rc)
        return rc;
    a->data_off = hoff + hlen;
    size_t need = a->rows * a->cols * (a->f64 ? 8 : 4);
    if (a->size && a->size - a->data_off < need) {
        snprintf(msg, sizeof msg, "file is truncated: the shape needs %zu data bytes, %zu present",
                 need, a->size - a->data_off);
        return bad(a, a->size, msg);
    }
    /* The block buffer holds what the shape needs, up to NPY_BLOCK_BYTES: a
     * file of a few rows does not cost a 1 MiB allocation (and its page
     * faults) per open. */
    a->buf_bytes = need < NPY_BLOCK_BYTES ? (need ? need : 1) : NPY_BLOCK_BYTES;
    a->buf = malloc(a->buf_bytes);
    if (!a->buf)
        return bgt_fail(err, BG_ERR_OUT_OF_MEMORY, "out of memory");
    return 0;
}

bg_status bgt_npy_read(bgt_npy_in *a, int dbl, float *const *fcols, double *const *dcols,
                       size_t max, size_t *rows)
{
    size_t es = a->f64 ? 8 : 4, rb = a->cols * es;
    size_t want = a->rows - a->row;
    if (want > max)
        want = max;
    if (want > a->buf_bytes / rb)
        want = a->buf_bytes / rb;
    *rows = 0;
    if (want == 0)
        return 0;
    size_t got = fread(a->buf, rb, want, a->fp);
    if (got < want) {
        if (ferror(a->fp))
            return bgt_fail(a->err, BG_ERR_IO, "reading %s failed: %s", a->name, strerror(errno));
        return bad(a, a->data_off + (a->row + got) * rb, "file ends before the shape's last row");
    }
    int swap = !host_le();
    for (size_t r = 0; r < got; r++)
        for (size_t k = 0; k < a->cols; k++) {
            unsigned char *p = a->buf + r * rb + k * es, t[8];
            if (swap) {
                for (size_t b = 0; b < es; b++)
                    t[b] = p[es - 1 - b];
                p = t;
            }
            double v;
            if (a->f64) {
                memcpy(&v, p, 8);
            } else {
                float f;
                memcpy(&f, p, 4);
                v = f;
            }
            if (!a->allow_nonfinite && !isfinite(v)) {
                char msg[128];
                snprintf(msg, sizeof msg, "non-finite value at row %zu, column %zu "
                                          "(--allow-nonfinite accepts NaN and Inf)",
                         a->row + r, k);
                return bad(a, a->data_off + (a->row + r) * rb + k * es, msg);
            }
            if (dbl) {
                dcols[k][r] = v;
            } else {
                float f = (float)v;
                if (a->f64 && isfinite(v) && !isfinite(f)) {
                    char msg[128];
                    snprintf(msg, sizeof msg, "value %g at row %zu, column %zu is out of the range "
                                              "of float (use --precision double?)",
                             v, a->row + r, k);
                    return bad(a, a->data_off + (a->row + r) * rb + k * es, msg);
                }
                fcols[k][r] = f;
            }
        }
    a->row += got;
    *rows = got;
    return 0;
}

void bgt_npy_close(bgt_npy_in *a)
{
    if (a->fp)
        fclose(a->fp);
    a->fp = NULL;
    free(a->buf);
    a->buf = NULL;
}

/* The header, padded so the data starts at a multiple of 64 bytes; the row
 * count is printed in a fixed width of 20 digits' room. */
static void header(FILE *fp, int f64, size_t cols, size_t rows, int final)
{
    char dict[128];
    int n = snprintf(dict, sizeof dict, "{'descr': '<f%d', 'fortran_order': False, 'shape': (%zu, %zu), }",
                     f64 ? 8 : 4, rows, cols);
    (void)final;
    /* total = 10 + hlen, hlen includes the padding and the final '\n' */
    size_t hlen = 128 - 10; /* fits any row count: the dict is < 100 bytes */
    fwrite("\x93NUMPY\x01\x00", 1, 8, fp);
    unsigned char l[2] = {(unsigned char)(hlen & 0xff), (unsigned char)(hlen >> 8)};
    fwrite(l, 1, 2, fp);
    fwrite(dict, 1, (size_t)n, fp);
    for (size_t k = (size_t)n; k + 1 < hlen; k++)
        fputc(' ', fp);
    fputc('\n', fp);
}

bg_status bgt_npy_begin(bgt_npy_out *o, FILE *fp, int f64, size_t cols, bgt_err *err)
{
    (void)err;
    o->fp = fp;
    o->f64 = f64;
    o->cols = cols;
    o->rows = 0;
    header(fp, f64, cols, 0, 0);
    return 0;
}

void bgt_npy_write(bgt_npy_out *o, const float *const *fcols, const double *const *dcols,
                   size_t rows)
{
    unsigned char buf[8 * 16];
    size_t es = o->f64 ? 8 : 4;
    int swap = !host_le();
    for (size_t r = 0; r < rows; r++) {
        for (size_t k = 0; k < o->cols; k++) {
            unsigned char *p = buf + k * es;
            if (o->f64)
                memcpy(p, &dcols[k][r], 8);
            else
                memcpy(p, &fcols[k][r], 4);
            if (swap)
                for (size_t b = 0; b < es / 2; b++) {
                    unsigned char t = p[b];
                    p[b] = p[es - 1 - b];
                    p[es - 1 - b] = t;
                }
        }
        fwrite(buf, es, o->cols, o->fp);
    }
    o->rows += rows;
}

bg_status bgt_npy_finish(bgt_npy_out *o, const char *name, bgt_err *err)
{
    if (fflush(o->fp) != 0 || fseek(o->fp, 0, SEEK_SET) != 0)
        return bgt_fail(err, BG_ERR_IO, "%s: cannot rewrite the .npy header (a .npy output must "
                                        "be a regular file): %s", name, strerror(errno));
    header(o->fp, o->f64, o->cols, o->rows, 1);
    if (fflush(o->fp) != 0 || fseek(o->fp, 0, SEEK_END) != 0)
        return bgt_fail(err, BG_ERR_IO, "writing %s failed: %s", name, strerror(errno));
    return 0;
}
