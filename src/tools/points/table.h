/* SPDX-License-Identifier: MIT */
/* The input table of eval and perturb (table.c): CSV (columns by name) or a
 * .npy array of shape (N, count), chosen by the file name's extension. */
#ifndef BUMPGRAD_TOOLS_POINTS_TABLE_H
#define BUMPGRAD_TOOLS_POINTS_TABLE_H

#include "common/csv.h"
#include "common/npy.h"
#include "common/tool.h"

typedef struct bgt_table_in {
    int npy;
    bgt_csv csv; /* for CSV; zeroed (no id, no extras) for .npy */
    bgt_npy_in np;
} bgt_table_in;

bg_status bgt_table_open(bgt_table_in *t, bgt_err *e, const char *path, int allow_nonfinite,
                         const char *const *names, int count);
bg_status bgt_table_read(bgt_table_in *t, int count, int dbl, float *const *fcols,
                         double *const *dcols, size_t max, size_t *rows);
size_t bgt_table_size(const bgt_table_in *t);     /* bytes, 0 if unknown */
size_t bgt_table_consumed(const bgt_table_in *t); /* bytes read so far */
void bgt_table_close(bgt_table_in *t);

/* One pass of a points tool (eval, perturb) over its input table, in constant
 * memory: open the input (columns `names`) and the output (safe_file.h), then
 * per block of up to `block` rows: read into the columns, run `chunk_fn` over
 * them in parallel (chunks of `chunk` rows), and `write` the block (.npy when
 * the output name says so, else CSV rows around the input's id and extra
 * columns); progress counts input bytes. The output is committed only after
 * every block was written. */
typedef struct bgt_table_pass {
    const char *label; /* progress label */
    const char *input, *output;
    int allow_nonfinite;
    const char *const *names;
    int count; /* input columns */
    int dbl;   /* read (and write .npy) in double */
    int npy_cols;
    const char *csv_header; /* the tool's output columns, comma-separated */
    size_t block, chunk;
    int threads;
    size_t mem_bytes;                    /* the tool's working memory, allocated here */
    void (*bind)(void *ctx, void *mem);  /* point the tool's columns into mem */
    float *const *fcols;                 /* the input columns (set by bind) */
    double *const *dcols;
    void (*chunk_fn)(void *ctx, size_t begin, size_t end, int worker);
    /* Write a block of `rows` results: to npy if not NULL, else CSV rows to fp
     * (bgt_csv_write_row_prefix / _suffix around each row of `in`). */
    void (*write)(void *ctx, FILE *fp, const bgt_csv *in, bgt_npy_out *npy, size_t rows);
    void *ctx;
    const bgt_progress *progress;
    size_t *rows; /* rows done so far, updated after each block (may be NULL) */
} bgt_table_pass;

bg_status bgt_table_run(const bgt_table_pass *p, bgt_err *e);

#endif
