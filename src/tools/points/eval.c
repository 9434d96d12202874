/* SPDX-License-Identifier: MIT */
/* bgt_eval_run (points.h): noise / fBm / turbulence value and gradient at
 * every row of a table, float or double, analytic or central (the table pass,
 * table.c, reads and writes the tables). */
#include "points.h"
#include "points_internal.h"

#define EVAL_BLOCK 8192
#define EVAL_CHUNK 1024


static const char *const eval_header[] = {"x", "y", "z"};

typedef struct eval_job {
    const bg_fractal *f;
    const bg_domain *d;
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
            bg_fractal3d_domain_grad_batch(j->f, j->d, c[0] + b, c[1] + b, c[2] + b, n, c[3] + b,
                                           c[4] + b, c[5] + b, c[6] + b);
        }
    } else {
        float **c = j->fc;
        if (j->central)
            bg_fractal3_domain_grad_central_batch(j->f, j->d, (float)j->step, c[0] + b, c[1] + b,
                                                  c[2] + b, n, c[3] + b, c[4] + b, c[5] + b,
                                                  c[6] + b);
        else
            bg_fractal3_domain_grad_batch(j->f, j->d, c[0] + b, c[1] + b, c[2] + b, n, c[3] + b,
                                          c[4] + b, c[5] + b, c[6] + b);
    }
}

static void eval_bind(void *ctx, void *mem)
{
    eval_job *j = ctx;
    size_t elem = j->dbl ? sizeof(double) : sizeof(float);
    for (int k = 0; k < 7; k++) {
        j->fc[k] = (float *)(void *)((char *)mem + (size_t)k * EVAL_BLOCK * elem);
        j->dc[k] = (double *)(void *)((char *)mem + (size_t)k * EVAL_BLOCK * elem);
    }
}

bg_status bgt_eval_run(const bgt_eval_opts *o, bgt_err *e)
{
    eval_job job = {.f = &o->fractal, .d = &o->domain, .central = o->central, .dbl = o->dbl, .step = o->step};
    bgt_table_pass p = {
        .label = "eval", .input = o->input, .output = o->output,
        .allow_nonfinite = o->allow_nonfinite, .range = o->rows, .names = eval_header, .count = 3, .dbl = o->dbl,
        .cols = 7, .csv_header = "x,y,z,value,dx,dy,dz", .block = EVAL_BLOCK,
        .chunk = EVAL_CHUNK, .threads = o->threads,
        .mem_bytes = 7 * EVAL_BLOCK * (o->dbl ? sizeof(double) : sizeof(float)),
        .bind = eval_bind, .fcols = job.fc, .dcols = job.dc, .chunk_fn = eval_chunk,
        .ctx = &job, .progress = o->progress,
        .rows = o->stats ? &o->stats->rows : NULL};
    return bgt_table_run(&p, e);
}
