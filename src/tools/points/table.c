/* SPDX-License-Identifier: MIT */
/* CSV or .npy input of eval and perturb (table.h). */
#include "table.h"
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include "common/parallel.h"
#include "common/safe_file.h"

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

bg_status bgt_table_run(const bgt_table_pass *p, bgt_err *e)
{
    bgt_table_in tin;
    bg_status rc;
    if ((rc = bgt_table_open(&tin, e, p->input, p->allow_nonfinite, p->names, p->count)))
        return rc;
    const bgt_csv *inp = &tin.csv;
    const int npy_out = bgt_npy_path(p->output);
    void *mem = malloc(p->mem_bytes);
    if (!mem) {
        bgt_table_close(&tin);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    }
    p->bind(p->ctx, mem);

    bgt_safe_file out;
    if ((rc = bgt_safe_open(&out, p->output, e))) {
        free(mem);
        bgt_table_close(&tin);
        return rc;
    }
    static char obuf[1 << 16];
    setvbuf(out.fp, obuf, _IOFBF, sizeof obuf);
    bgt_npy_out nout;
    if (npy_out)
        bgt_npy_begin(&nout, out.fp, p->dbl, (size_t)p->npy_cols, e);
    else
        bgt_csv_write_header(out.fp, inp, p->csv_header);

    bgt_progress_begin(p->progress, p->label, bgt_table_size(&tin));
    size_t total_rows = 0;
    for (;;) {
        size_t rows;
        rc = bgt_table_read(&tin, p->count, p->dbl, p->fcols, p->dcols, p->block, &rows);
        if (rc || rows == 0)
            break;
        bgt_parallel_for(rows, p->chunk, p->threads, p->chunk_fn, p->ctx);
        p->write(p->ctx, out.fp, inp, npy_out ? &nout : NULL, rows);
        if (ferror(out.fp)) {
            rc = bgt_fail(e, BG_ERR_IO, "writing %s failed: %s",
                          strcmp(p->output, "-") ? p->output : "standard output", strerror(errno));
            break;
        }
        total_rows += rows;
        if (p->rows)
            *p->rows = total_rows;
        bgt_progress_update(p->progress, bgt_table_consumed(&tin));
    }
    bgt_progress_end(p->progress);
    bgt_table_close(&tin);
    free(mem);
    if (!rc && npy_out)
        rc = bgt_npy_finish(&nout, p->output, e);
    if (rc) {
        bgt_safe_abort(&out);
        return rc;
    }
    return bgt_safe_commit(&out, e);
}
