/* SPDX-License-Identifier: MIT */
/* bgt_perturb_run (points.h): bump the normals of a table of surface
 * points with the height source, through the library's fused height -> normal
 * kernel (Mikkelsen 2010, eq. 2 and 4) or Perlin's additive rule. The `inward`
 * column marks rows whose bumped normal faces away from the surface normal. */
#include "points.h"
#include "points_internal.h"
#if BG_HAVE_TOOLS
#include "bumpgrad/volume.h"
#endif

#define PERTURB_BLOCK 8192
#define PERTURB_CHUNK 1024


static const char *const perturb_header[] = {"x", "y", "z", "nx", "ny", "nz"};

typedef struct perturb_job {
    const bgt_height *h;
    bg_perturb_method method;
    float *c[11]; /* x y z nx ny nz height px py pz, and inward (for .npy) */
    int grid;      /* a VDB height: count the rows inside box (min xyz, max xyz) */
    double box[6];
    bgt_points_stats *stats;
} perturb_job;



/* dot(n', n) in double: n may be any finite length, and the sign is what counts. */
static int is_inward(float nx, float ny, float nz, float px, float py, float pz)
{
    double d = (double)nx * px + (double)ny * py + (double)nz * pz;
    double r2 = (double)px * px + (double)py * py + (double)pz * pz;
    return r2 == 0 || !(d > 0);
}

static void perturb_chunk(void *ctx, size_t b, size_t e, int worker)
{
    (void)worker;
    perturb_job *j = ctx;
    float **c = j->c;
    bgt_height_perturb(j->h, j->method, c[0] + b, c[1] + b, c[2] + b, c[3] + b, c[4] + b, c[5] + b,
                       e - b, c[6] + b, c[7] + b, c[8] + b, c[9] + b);
    for (size_t r = b; r < e; r++)
        c[10][r] = (float)is_inward(c[3][r], c[4][r], c[5][r], c[7][r], c[8][r], c[9][r]);
}
static void perturb_bind(void *ctx, void *mem)
{
    perturb_job *j = ctx;
    for (int k = 0; k < 11; k++)
        j->c[k] = (float *)mem + (size_t)k * PERTURB_BLOCK;
}

/* The block's statistics: rows inward, rows inside a grid's active box. */
static void perturb_block_done(void *ctx, size_t rows)
{
    perturb_job *j = ctx;
    float **c = j->c;
    const double *box = j->box;
    size_t block_inward = 0, block_in_grid = 0;
    if (j->grid)
        for (size_t r = 0; r < rows; r++)
            block_in_grid += c[0][r] >= box[0] && c[0][r] <= box[3] && c[1][r] >= box[1] &&
                             c[1][r] <= box[4] && c[2][r] >= box[2] && c[2][r] <= box[5];
    for (size_t r = 0; r < rows; r++)
        block_inward += c[10][r] != 0.0f;
    if (j->stats) {
        j->stats->inward += block_inward;
        j->stats->in_grid += block_in_grid;
    }
}

bg_status bgt_perturb_run(const bgt_perturb_opts *o, bgt_err *e)
{
    bgt_height h = *o->height;
    bg_status rc = bgt_height_open(&h, e);
    if (rc != BG_OK)
        return rc;
    perturb_job job = {.h = &h, .method = o->method, .stats = o->stats};
    /* A VDB height is zero (and flat) outside its active voxels: count the
     * points inside their world box, one voxel of margin (the stencil's reach),
     * so that a table that misses the grid entirely can be reported. */
#if BG_HAVE_TOOLS
    if (h.grid) {
        bg_vdb_height_info info;
        bg_vdb_height_get_info((const bg_vdb_height *)h.grid, &info);
        for (int k = 0; k < 3; k++) {
            job.box[k] = info.world_min[k] - info.voxel_size[k];
            job.box[3 + k] = info.world_max[k] + info.voxel_size[k];
        }
        job.grid = 1;
        if (o->stats) {
            o->stats->grid = 1;
            for (int k = 0; k < 3; k++) {
                o->stats->grid_box[k] = info.world_min[k];
                o->stats->grid_box[3 + k] = info.world_max[k];
            }
        }
    }
#endif
    bgt_table_pass p = {
        .label = "perturb", .input = o->input, .output = o->output,
        .allow_nonfinite = o->allow_nonfinite, .range = o->rows, .names = perturb_header, .count = 6, .dbl = 0,
        .cols = 11, .flag_cols = 1, .csv_header = "x,y,z,nx,ny,nz,height,px,py,pz,inward",
        .block = PERTURB_BLOCK, .chunk = PERTURB_CHUNK, .threads = o->threads,
        .mem_bytes = 11 * PERTURB_BLOCK * sizeof(float), .bind = perturb_bind, .fcols = job.c,
        .dcols = NULL, .chunk_fn = perturb_chunk, .block_done = perturb_block_done, .ctx = &job,
        .progress = o->progress, .rows = o->stats ? &o->stats->rows : NULL};
    rc = bgt_table_run(&p, e);
    bgt_height_close(&h);
    return rc;
}
