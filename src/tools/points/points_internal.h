/* SPDX-License-Identifier: MIT */
/* Inside the points tools (the face is points.h): the table pass of eval and
 * perturb (table.c). The input table is read and the output table written by
 * a reader and a writer picked once, by the file name's extension, from
 * table.c's lists (CSV with columns by name, or a .npy array of shape
 * (N, count)); the tools describe their columns and compute, and format
 * nothing themselves. */
#ifndef BUMPGRAD_TOOLS_POINTS_INTERNAL_H
#define BUMPGRAD_TOOLS_POINTS_INTERNAL_H

#include <stddef.h>
#include "common/tool.h"
#include "points.h"

/* One pass of a points tool (eval, perturb) over its input table, in constant
 * memory: open the input (columns `names`) and the output (safe_file.h), then
 * per block of up to `block` rows: read into the columns, run `chunk_fn` over
 * them in parallel (chunks of `chunk` rows), call `block_done`, and write the
 * block's `cols` output columns (a CSV row keeps the input's id and extra
 * columns around them); progress counts input bytes. The output is committed
 * only after every block was written. */
typedef struct bgt_table_pass {
    const char *label; /* progress label */
    const char *input, *output;
    int allow_nonfinite;
    bgt_row_range range; /* rows of a .npy input (CSV: refused) */
    const char *const *names;
    int count; /* input columns: the first `count` output columns */
    int dbl;   /* read and write in double (CSV %.17g, .npy float64), else float
                  (CSV %.9g, .npy float32): both read back exactly */
    int cols;  /* output columns, at most 12 */
    int flag_cols; /* the last flag_cols output columns hold 0 or 1: CSV integers */
    const char *csv_header; /* the output columns' names, comma-separated */
    size_t block, chunk;
    int threads;
    size_t mem_bytes;                    /* the tool's working memory, allocated here */
    void (*bind)(void *ctx, void *mem);  /* point the tool's columns into mem */
    float *const *fcols;                 /* the output columns (set by bind); the input */
    double *const *dcols;                /* is read into the first `count` of them */
    void (*chunk_fn)(void *ctx, size_t begin, size_t end, int worker);
    void (*block_done)(void *ctx, size_t rows); /* after chunk_fn, before the write; may be NULL */
    void *ctx;
    const bgt_progress *progress;
    size_t *rows; /* rows done so far, updated after each block (may be NULL) */
} bgt_table_pass;

bg_status bgt_table_run(const bgt_table_pass *p, bgt_err *e);

#endif
