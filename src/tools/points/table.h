/* SPDX-License-Identifier: MIT */
/* The input table of eval and perturb (table.c): CSV (columns by name) or a
 * .npy array of shape (N, count), chosen by the file name's extension. */
#ifndef BUMPGRAD_TOOLS_POINTS_TABLE_H
#define BUMPGRAD_TOOLS_POINTS_TABLE_H

#include "common/csv.h"
#include "common/npy.h"

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

#endif
