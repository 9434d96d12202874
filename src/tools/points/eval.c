/* SPDX-License-Identifier: MIT */
/* bgt_eval_run (points.h): noise / fBm / turbulence value and gradient at
 * every row of a CSV table, float or double, analytic or central. */
#include "points.h"
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include "common/csv.h"
#include "common/npy.h"
#include "table.h"
#include "common/parallel.h"
#include "common/safe_file.h"

#define EVAL_BLOCK 8192
#define EVAL_CHUNK 1024


static const char *const eval_header[] = {"x", "y", "z"};

typedef struct eval_job {
    const bg_fractal *f;
    int central, dbl;
    double step;
    float *fc[7];
    double *dc[7];
} eval_job;

static void eval_chunk(void *ctx, size_t b, size_t e, int worker)
{
    (void)worker;
    eval_job *j = ctx;
    size_t n = e - b;
    if (j->dbl) {
        double **c = j->dc;
        if (j->central) {
            for (size_t i = b; i < e; i++) {
                bg_dvec3 g;
                c[3][i] = bg_fractal3d_grad_central(j->f, j->step, c[0][i], c[1][i], c[2][i], &g);
                c[4][i] = g.x, c[5][i] = g.y, c[6][i] = g.z;
            }
        } else {
            bg_fractal3d_grad_batch(j->f, c[0] + b, c[1] + b, c[2] + b, n, c[3] + b, c[4] + b,
                                    c[5] + b, c[6] + b);
        }
    } else {
        float **c = j->fc;
        if (j->central)
            bg_fractal3_grad_central_batch(j->f, (float)j->step, c[0] + b, c[1] + b, c[2] + b, n,
                                           c[3] + b, c[4] + b, c[5] + b, c[6] + b);
        else
            bg_fractal3_grad_batch(j->f, c[0] + b, c[1] + b, c[2] + b, n, c[3] + b, c[4] + b,
                                   c[5] + b, c[6] + b);
    }
}

bg_status bgt_eval_run(const bgt_eval_opts *o, bgt_err *e)
{
    bgt_table_in tin;
    bg_status rc;
    if ((rc = bgt_table_open(&tin, e, o->input, o->allow_nonfinite, eval_header, 3)))
        return rc;
    const bgt_csv *inp = &tin.csv;
    const int npy_out = bgt_npy_path(o->output);

    const int dbl = o->dbl;
    eval_job job = {.f = &o->fractal, .central = o->central, .dbl = dbl, .step = o->step};
    size_t elem = dbl ? sizeof(double) : sizeof(float);
    char *mem = malloc(7 * EVAL_BLOCK * elem);
    if (!mem) {
        bgt_table_close(&tin);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    }
    for (int k = 0; k < 7; k++) {
        job.fc[k] = (float *)(void *)(mem + (size_t)k * EVAL_BLOCK * elem);
        job.dc[k] = (double *)(void *)(mem + (size_t)k * EVAL_BLOCK * elem);
    }

    bgt_safe_file out;
    if ((rc = bgt_safe_open(&out, o->output, e))) {
        free(mem);
        bgt_table_close(&tin);
        return rc;
    }
    static char obuf[1 << 16];
    setvbuf(out.fp, obuf, _IOFBF, sizeof obuf);
    bgt_npy_out nout;
    if (npy_out)
        bgt_npy_begin(&nout, out.fp, dbl, 7, e);
    else
        bgt_csv_write_header(out.fp, inp, "x,y,z,value,dx,dy,dz");

    bgt_progress_begin(o->progress, "eval", bgt_table_size(&tin));
    size_t total_rows = 0;
    for (;;) {
        size_t rows;
        rc = bgt_table_read(&tin, 3, dbl, job.fc, job.dc, EVAL_BLOCK, &rows);
        if (rc || rows == 0)
            break;
        bgt_parallel_for(rows, EVAL_CHUNK, o->threads, eval_chunk, &job);
        if (npy_out) {
            bgt_npy_write(&nout, (const float *const *)job.fc, (const double *const *)job.dc,
                          rows);
        } else if (dbl) {
            double **c = job.dc;
            for (size_t r = 0; r < rows; r++) {
                const char *x;
                size_t xl;
                bgt_csv_write_row_prefix(out.fp, inp, r, &x, &xl);
                fprintf(out.fp, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", c[0][r], c[1][r],
                        c[2][r], c[3][r], c[4][r], c[5][r], c[6][r]);
                bgt_csv_write_row_suffix(out.fp, inp, x, xl);
            }
        } else {
            float **c = job.fc;
            for (size_t r = 0; r < rows; r++) {
                const char *x;
                size_t xl;
                bgt_csv_write_row_prefix(out.fp, inp, r, &x, &xl);
                fprintf(out.fp, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g", (double)c[0][r],
                        (double)c[1][r], (double)c[2][r], (double)c[3][r], (double)c[4][r],
                        (double)c[5][r], (double)c[6][r]);
                bgt_csv_write_row_suffix(out.fp, inp, x, xl);
            }
        }
        if (ferror(out.fp)) {
            rc = bgt_fail(e, BG_ERR_IO, "writing %s failed: %s",
                          strcmp(o->output, "-") ? o->output : "standard output", strerror(errno));
            break;
        }
        total_rows += rows;
        if (o->stats)
            o->stats->rows = total_rows;
        bgt_progress_update(o->progress, bgt_table_consumed(&tin));
    }
    bgt_progress_end(o->progress);
    bgt_table_close(&tin);
    if (!rc && npy_out)
        rc = bgt_npy_finish(&nout, o->output, e);
    if (rc) {
        bgt_safe_abort(&out);
        free(mem);
        return rc;
    }
    rc = bgt_safe_commit(&out, e);
    free(mem);
    return rc;
}
