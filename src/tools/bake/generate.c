/* SPDX-License-Identifier: MIT */
/* `bumpgrad heightmap --generate`: a height, normal or derivative map made
 * from the height function alone. The image spans exactly one period of a
 * tileable height (noise.h bg_domain) in x and y, so the map repeats without
 * a seam: pixel (i, j) (row 0 at the top, +y up) samples the plane z = 0 at
 * world p = ((i + 1/2) Tx / W, (H - j - 1/2) Ty / H, 0), T = P / frequency
 * the world size of one period, and its neighbour across the right edge is
 * column 0 of the next copy. Heights and gradients come from the height
 * source (the fused library path); normals from bg_perturb_batch with the
 * flat normal (0, 0, 1): normalize(-dh/dx, -dh/dy, 1) (eq. 2 and 4). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "generate.h"
#include "bake_internal.h"
#include "common/parallel.h"
#include "bumpgrad/image.h"

typedef struct gen_job {
    const bgt_generate_opts *o;
    const bgt_height *h;
    float *pix;
    float *scratch; /* 12 rows of floats per worker */
    int w, hgt;
    double tx, ty;
} gen_job;

/* One row per call: its points, the height source, then the pixels. */
static void gen_rows(void *ctx, size_t b, size_t e, int worker)
{
    gen_job *g = ctx;
    const int w = g->w;
    float *px = g->scratch + (size_t)worker * 12 * (size_t)w;
    float *py = px + w, *pz = py + w, *hv = pz + w, *gx = hv + w, *gy = gx + w, *gz = gy + w;
    float *nx = gz + w, *ny = nx + w, *nz = ny + w, *ox = nz + w, *oy = ox + w;
    float *oz = px; /* reused after the samples: px is not read again */
    for (size_t j = b; j < e; j++) {
        float y = (float)(((double)g->hgt - (double)j - 0.5) * g->ty / g->hgt);
        for (int i = 0; i < w; i++) {
            px[i] = (float)(((double)i + 0.5) * g->tx / w);
            py[i] = y, pz[i] = 0;
            nx[i] = 0, ny[i] = 0, nz[i] = 1;
        }
        bgt_height_gradient(g->h, px, py, pz, (size_t)w, hv, gx, gy, gz);
        float *row = g->pix + j * (size_t)w * 3;
        if (g->o->map == BGT_MAP_NORMAL) {
            bg_perturb_batch(BG_PERTURB_SURFGRAD, nx, ny, nz, gx, gy, gz, (size_t)w, ox, oy, oz);
            for (int i = 0; i < w; i++) {
                row[3 * i] = 0.5f * ox[i] + 0.5f;
                row[3 * i + 1] = 0.5f * (g->o->y_down ? -oy[i] : oy[i]) + 0.5f;
                row[3 * i + 2] = 0.5f * oz[i] + 0.5f;
            }
        } else if (g->o->map == BGT_MAP_DERIVATIVE) {
            for (int i = 0; i < w; i++) {
                row[3 * i] = gx[i];
                row[3 * i + 1] = g->o->y_down ? -gy[i] : gy[i];
                row[3 * i + 2] = 0;
            }
        } else {
            for (int i = 0; i < w; i++) {
                float v = g->o->bits == 32 ? hv[i] : 0.5f + hv[i];
                row[3 * i] = row[3 * i + 1] = row[3 * i + 2] = v;
            }
        }
    }
}

bg_status bgt_generate_run(const bgt_generate_opts *o, bgt_err *e)
{
    if (!o || !o->output || !o->height)
        return bgt_fail(e, BG_ERR_NULL_POINTER, "expected OUT");
    if (o->width < 1 || o->height_px < 1 || o->width > 65536 || o->height_px > 65536)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "--generate: size %dx%d outside 1..65536",
                        o->width, o->height_px);
    if (o->height->grid_path)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--generate samples the noise: --height-grid does not apply");
    const bg_height *hh = &o->height->h;
    if (!hh->domain.period[0] || !hh->domain.period[1])
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--generate needs periods along x and y (--period X,Y[,Z]): the map "
                        "spans one period so that it tiles");
    if (!(hh->frequency > 0))
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "--generate needs --frequency > 0");
    bg_status rc = bgt_check_alloc((double)o->width * o->height_px * 3 * sizeof(float),
                                   "--generate image", e);
    if (rc != BG_OK)
        return rc;
    if ((rc = bgt_io_ready(e)) != BG_OK)
        return rc;
    bgt_height h = *o->height;
    if ((rc = bgt_height_open(&h, e)) != BG_OK)
        return rc;
    int threads = o->threads > 0 ? o->threads : bgt_threads_default();
    float *scratch = malloc((size_t)threads * 12 * (size_t)o->width * sizeof(float));
    bg_image img;
    if (!scratch || bg_image_alloc(&img, o->width, o->height_px, 3) != BG_OK) {
        free(scratch);
        bgt_height_close(&h);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for a %dx%d image", o->width,
                        o->height_px);
    }
    gen_job g = {.o = o, .h = &h, .pix = img.pixels, .scratch = scratch, .w = o->width, .hgt = o->height_px,
                 .tx = hh->domain.period[0] / (double)hh->frequency,
                 .ty = hh->domain.period[1] / (double)hh->frequency};
    bgt_parallel_for((size_t)o->height_px, 4, threads, gen_rows, &g);
    free(scratch);
    bgt_height_close(&h);
    int bits = o->bits ? o->bits : (o->map == BGT_MAP_DERIVATIVE ? 32 : 8);
    rc = bake_write_image(o->output, o->format, &img, bits, e);
    bg_image_free(&img);
    return rc;
}
