/* SPDX-License-Identifier: MIT */
/* bgt_perturb_run (points.h): bump the normals of a CSV table of surface
 * points with the height source, through the library's fused height -> normal
 * kernel (Mikkelsen 2010, eq. 2 and 4) or Perlin's additive rule. The `inward`
 * column marks rows whose bumped normal faces away from the surface normal. */
#include "points.h"
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include "common/csv.h"
#include "common/npy.h"
#include "table.h"
#include "common/parallel.h"
#include "common/safe_file.h"
#if BG_HAVE_TOOLS
#include "bumpgrad/volume.h"
#endif

#define PERTURB_BLOCK 8192
#define PERTURB_CHUNK 1024


static const char *const perturb_header[] = {"x", "y", "z", "nx", "ny", "nz"};

typedef struct perturb_job {
    const bgt_height *h;
    bg_perturb_method method;
    float *c[10]; /* x y z nx ny nz height px py pz */
} perturb_job;

static void perturb_chunk(void *ctx, size_t b, size_t e, int worker)
{
    (void)worker;
    perturb_job *j = ctx;
    float **c = j->c;
    bgt_height_perturb(j->h, j->method, c[0] + b, c[1] + b, c[2] + b, c[3] + b, c[4] + b, c[5] + b,
                       e - b, c[6] + b, c[7] + b, c[8] + b, c[9] + b);
}

/* dot(n', n) in double: n may be any finite length, and the sign is what counts. */
static int is_inward(float nx, float ny, float nz, float px, float py, float pz)
{
    double d = (double)nx * px + (double)ny * py + (double)nz * pz;
    double r2 = (double)px * px + (double)py * py + (double)pz * pz;
    return r2 == 0 || !(d > 0);
}

bg_status bgt_perturb_run(const bgt_perturb_opts *o, bgt_err *e)
{
    bgt_table_in tin;
    bg_status rc;
    if ((rc = bgt_table_open(&tin, e, o->input, o->allow_nonfinite, perturb_header, 6)))
        return rc;
    const bgt_csv *inp = &tin.csv;
    const int npy_out = bgt_npy_path(o->output);
    perturb_job job = {.h = o->height, .method = o->method};
    float *mem = malloc(11 * PERTURB_BLOCK * sizeof(float));
    if (!mem) {
        bgt_table_close(&tin);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    }
    for (int k = 0; k < 10; k++)
        job.c[k] = mem + (size_t)k * PERTURB_BLOCK;
    float *inward_col = mem + (size_t)10 * PERTURB_BLOCK; /* for .npy output */

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
        bgt_npy_begin(&nout, out.fp, 0, 11, e);
    else
        bgt_csv_write_header(out.fp, inp, "x,y,z,nx,ny,nz,height,px,py,pz,inward");

    bgt_progress_begin(o->progress, "perturb", bgt_table_size(&tin));
    size_t total_rows = 0;
    /* A VDB height is zero (and flat) outside its active voxels: count the
     * points inside their world box, one voxel of margin (the stencil's reach),
     * so that a table that misses the grid entirely can be reported. */
    int grid = 0;
    double box[6] = {0};
#if BG_HAVE_TOOLS
    if (o->height->grid) {
        bg_vdb_height_info info;
        bg_vdb_height_get_info((const bg_vdb_height *)o->height->grid, &info);
        for (int k = 0; k < 3; k++) {
            box[k] = info.world_min[k] - info.voxel_size[k];
            box[3 + k] = info.world_max[k] + info.voxel_size[k];
        }
        grid = 1;
        if (o->stats) {
            o->stats->grid = 1;
            for (int k = 0; k < 3; k++) {
                o->stats->grid_box[k] = info.world_min[k];
                o->stats->grid_box[3 + k] = info.world_max[k];
            }
        }
    }
#endif
    for (;;) {
        size_t rows;
        rc = bgt_table_read(&tin, 6, 0, job.c, NULL, PERTURB_BLOCK, &rows);
        if (rc || rows == 0)
            break;
        bgt_parallel_for(rows, PERTURB_CHUNK, o->threads, perturb_chunk, &job);
        float **c = job.c;
        size_t block_inward = 0, block_in_grid = 0;
        if (grid)
            for (size_t r = 0; r < rows; r++)
                block_in_grid += c[0][r] >= box[0] && c[0][r] <= box[3] && c[1][r] >= box[1] &&
                                 c[1][r] <= box[4] && c[2][r] >= box[2] && c[2][r] <= box[5];
        for (size_t r = 0; r < rows && npy_out; r++) {
            int inward = is_inward(c[3][r], c[4][r], c[5][r], c[7][r], c[8][r], c[9][r]);
            block_inward += (size_t)inward;
            inward_col[r] = (float)inward;
        }
        if (npy_out) {
            const float *cols[11];
            for (int k = 0; k < 10; k++)
                cols[k] = c[k];
            cols[10] = inward_col;
            bgt_npy_write(&nout, cols, NULL, rows);
        }
        for (size_t r = 0; r < rows && !npy_out; r++) {
            const char *x;
            size_t xl;
            bgt_csv_write_row_prefix(out.fp, inp, r, &x, &xl);
            int inward = is_inward(c[3][r], c[4][r], c[5][r], c[7][r], c[8][r], c[9][r]);
            block_inward += (size_t)inward;
            fprintf(out.fp, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d",
                    (double)c[0][r], (double)c[1][r], (double)c[2][r], (double)c[3][r],
                    (double)c[4][r], (double)c[5][r], (double)c[6][r], (double)c[7][r],
                    (double)c[8][r], (double)c[9][r], inward);
            bgt_csv_write_row_suffix(out.fp, inp, x, xl);
        }
        if (ferror(out.fp)) {
            rc = bgt_fail(e, BG_ERR_IO, "writing %s failed: %s",
                          strcmp(o->output, "-") ? o->output : "standard output", strerror(errno));
            break;
        }
        total_rows += rows;
        if (o->stats) {
            o->stats->rows = total_rows;
            o->stats->inward += block_inward;
            o->stats->in_grid += block_in_grid;
        }
        bgt_progress_update(o->progress, bgt_table_consumed(&tin));
    }
    bgt_progress_end(o->progress);
    bgt_table_close(&tin);
    free(mem);
    if (!rc && npy_out)
        rc = bgt_npy_finish(&nout, o->output, e);
    if (rc) {
        bgt_safe_abort(&out);
        return rc;
    }
    return bgt_safe_commit(&out, e);
}
