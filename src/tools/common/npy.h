/* SPDX-License-Identifier: MIT */
/* NumPy .npy arrays for `eval` and `perturb` (npy.c): a streaming reader of
 * 2-D little-endian float32/float64 arrays in C order (shape (N, K)), and a
 * streaming writer that leaves room in the header for the row count and
 * fills it in when the array is complete (the output is a regular file: the
 * safe writer's temporary). Format: numpy's NEP 1 (versions 1.0, 2.0, 3.0).
 * Errors name FILE: byte offset N (BG_ERR_FORMAT; BG_ERR_IO for I/O). */
#ifndef BUMPGRAD_TOOLS_NPY_H
#define BUMPGRAD_TOOLS_NPY_H

#include <stddef.h>
#include <stdio.h>
#include "tool.h"

/* 1 if `path` ends in ".npy" (any case). */
int bgt_npy_path(const char *path);

typedef struct bgt_npy_in {
    bgt_err *err;
    const char *name;
    FILE *fp;
    int f64;          /* '<f8' (else '<f4') */
    size_t rows, cols; /* shape */
    size_t row;       /* rows read so far */
    size_t data_off;  /* byte offset of the data */
    size_t size;      /* file size */
    int allow_nonfinite;
    unsigned char *buf;
    size_t buf_bytes; /* min(the shape's data bytes, NPY_BLOCK_BYTES), at least 1 */
} bgt_npy_in;

/* Open and validate the header: magic, version, '<f4' or '<f8', C order,
 * shape (N, cols) with cols one of want_cols[0..nwant). */
bg_status bgt_npy_open(bgt_npy_in *a, bgt_err *err, const char *path, int allow_nonfinite,
                       const size_t *want_cols, int nwant);
/* Up to `max` rows into column arrays (float or double; values converted if the
 * file's type differs: float64 -> float rounds to nearest). *rows = 0 at the end.
 * A NaN/Inf without allow_nonfinite, or a truncated file, is BG_ERR_FORMAT. */
bg_status bgt_npy_read(bgt_npy_in *a, int dbl, float *const *fcols, double *const *dcols,
                       size_t max, size_t *rows);
void bgt_npy_close(bgt_npy_in *a);

typedef struct bgt_npy_out {
    FILE *fp;
    int f64;
    size_t cols, rows;
} bgt_npy_out;

/* Write a header for shape (?, cols) with room for any row count. */
bg_status bgt_npy_begin(bgt_npy_out *o, FILE *fp, int f64, size_t cols, bgt_err *err);
/* Append `rows` rows from column arrays. */
void bgt_npy_write(bgt_npy_out *o, const float *const *fcols, const double *const *dcols,
                   size_t rows);
/* Rewrite the header with the final row count (seeks back: a regular file). */
bg_status bgt_npy_finish(bgt_npy_out *o, const char *name, bgt_err *err);

#endif
