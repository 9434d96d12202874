/* SPDX-License-Identifier: MIT */
/* CSV or .npy input of eval and perturb (table.h). */
#include "table.h"
#include <string.h>

bg_status bgt_table_open(bgt_table_in *t, bgt_err *e, const char *path, int allow_nonfinite,
                         const char *const *names, int count)
{
    memset(t, 0, sizeof *t);
    bg_status rc;
    if (strcmp(path, "-") != 0 && bgt_npy_path(path)) {
        size_t want = (size_t)count;
        t->npy = 1;
        if ((rc = bgt_npy_open(&t->np, e, path, allow_nonfinite, &want, 1)))
            bgt_npy_close(&t->np);
        return rc;
    }
    if ((rc = bgt_csv_open(&t->csv, e, path, allow_nonfinite)))
        return rc;
    if ((rc = bgt_csv_header_map(&t->csv, names, count)))
        bgt_csv_close(&t->csv);
    return rc;
}

bg_status bgt_table_read(bgt_table_in *t, int count, int dbl, float *const *fcols,
                         double *const *dcols, size_t max, size_t *rows)
{
    if (t->npy)
        return bgt_npy_read(&t->np, dbl, fcols, dcols, max, rows);
    return dbl ? bgt_csv_read_double(&t->csv, count, dcols, max, rows)
               : bgt_csv_read_float(&t->csv, count, fcols, max, rows);
}

size_t bgt_table_size(const bgt_table_in *t)
{
    return t->npy ? t->np.size : t->csv.size;
}

size_t bgt_table_consumed(const bgt_table_in *t)
{
    if (t->npy)
        return t->np.data_off + t->np.row * t->np.cols * (t->np.f64 ? 8 : 4);
    return t->csv.consumed;
}

void bgt_table_close(bgt_table_in *t)
{
    if (t->npy)
        bgt_npy_close(&t->np);
    else
        bgt_csv_close(&t->csv);
}
