/* SPDX-License-Identifier: MIT */
/* The VDB bake of `bumpgrad volume`: a height function and its gradient into
 * an OpenVDB file (FloatGrid "height" + Vec3SGrid "gradient"), densely over a
 * box or only in a narrow band around a sphere. Voxels are visited row by row
 * and gathered into batches that are evaluated in parallel with the batch
 * kernels, then added to the grids from this thread (the VDB tree is not
 * thread-safe to fill). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bake/volume.h"
#include "bumpgrad/volume.h"
#include "common/parallel.h"

/* Voxels per batch: big enough to keep all workers busy, small enough (28 MB of
 * coordinates and results) to bake boxes far larger than memory allows densely. */
#define VOL_BATCH ((size_t)1 << 20)
#define VOL_CHUNK 4096
/* Refuse bakes above this many voxels (and band rows to visit). A count, not
 * the memory bound: a full leaf costs about 16 bytes per voxel for the two
 * grids (2^28 voxels: about 4 GB), but a thin box fills each 8^3 leaf with
 * few voxels, so check_memory bounds the leaves against the allocation cap. */
#define VOL_MAX_VOXELS ((uint64_t)1 << 28)

/* The option spelling of the CLI, for the grid metadata. */
static const char *function_name(bg_function f)
{
    static const char *const names[] = {"noise", "fbm", "turbulence"};
    return (unsigned)f < 3 ? names[f] : "?";
}

/* Narrow [*a, *b] to the voxels whose centre lies within r of c on one axis,
 * widened (by 1e-9 r and one voxel) so that rounding never drops a voxel the
 * exact band test would keep. An empty result leaves *b = *a - 1. */
static void clip_range(double c, double r, double voxel, long long *a, long long *b)
{
    r += 1e-9 * r;
    const double lo = floor((c - r) / voxel) - 1.0, hi = ceil((c + r) / voxel) + 1.0;
    if (lo > (double)*a)
        *a = lo > (double)*b ? *b + 1 : (long long)lo;
    if (hi < (double)*b)
        *b = hi < (double)*a ? *a - 1 : (long long)hi;
}

typedef struct batch {
    const bgt_height *height;
    double voxel;
    int32_t *i, *j, *k;
    float *px, *py, *pz, *h, *gx, *gy, *gz;
} batch;

static void eval_range(void *ctx, size_t begin, size_t end, int worker)
{
    (void)worker;
    batch *b = ctx;
    for (size_t t = begin; t < end; t++) {
        b->px[t] = (float)(b->voxel * b->i[t]);
        b->py[t] = (float)(b->voxel * b->j[t]);
        b->pz[t] = (float)(b->voxel * b->k[t]);
    }
    bgt_height_gradient(b->height, b->px + begin, b->py + begin, b->pz + begin, end - begin,
                        b->h + begin, b->gx + begin, b->gy + begin, b->gz + begin);
}

/* What a bake visits: the voxel centres inside the box (lo..hi, each within
 * OpenVDB's int32), and the part of it a band can reach (ilo..ihi, `rows`
 * rows of x). */
typedef struct vol_plan {
    long long lo[3], hi[3], ilo[3], ihi[3];
    uint64_t rows;
} vol_plan;

/* The options that need no arithmetic: voxel size, band, output, box order. */
static bg_status check_opts(const bgt_volume_opts *o, bgt_err *e)
{
    const double *bbox = o->bbox, *band = o->band, voxel = o->voxel;
    if (!(voxel > 0.0 && isfinite(voxel)))
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "--voxel-size: must be finite and > 0, got %g",
                        voxel);
    if (o->have_band && (!(band[3] >= 0.0) || !(band[4] >= 0.0)))
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--band-sphere: radius and width must be >= 0, got %g, %g", band[3],
                        band[4]);
    /* Elsewhere "-" is standard output; here it silently made a file named "-". */
    if (strcmp(o->output, "-") == 0)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--output: a VDB file cannot go to standard output (\"-\")");
    if (o->bricks < 0 || o->bricks > 1000000 ||
        (o->bricks > 1 && (o->brick < 0 || o->brick >= o->bricks)))
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--brick: I/N needs 1 <= N <= 1000000 and 0 <= I < N, got %d/%d", o->brick,
                        o->bricks);
    if (o->height->grid_path)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--height-grid: volume bakes a height function, not a grid");
    for (int a = 0; a < 3; a++)
        if (!(bbox[a] <= bbox[a + 3]))
            return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                            "--bbox: min must not exceed max on axis %c", "xyz"[a]);
    return BG_OK;
}

/* The index range of voxel centres inside the box, refused past the dense cap. */
static bg_status box_range(const bgt_volume_opts *o, vol_plan *p, bgt_err *e)
{
    const double *bbox = o->bbox, voxel = o->voxel;
    uint64_t dense = 1;
    p->rows = 1;
    for (int a = 0; a < 3; a++) {
        const double l = ceil(bbox[a] / voxel), h = floor(bbox[a + 3] / voxel);
        if (!(fabs(l) < 1e9 && fabs(h) < 1e9))
            return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                            "--bbox / --voxel-size: axis %c spans more than 1e9 voxels from the "
                            "origin", "xyz"[a]);
        p->lo[a] = p->ilo[a] = (long long)l;
        p->hi[a] = p->ihi[a] = (long long)h;
        if (p->hi[a] < p->lo[a])
            return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                            "--bbox: no voxel centre (multiple of %g) inside the box on axis %c",
                            voxel, "xyz"[a]);
    }
    if (o->bricks > 1) {
        /* Brick b of N: leaf slabs L0 + n b / N .. L0 + n (b + 1) / N - 1 along z. */
        const long long l0 = (long long)floor((double)p->lo[2] / 8),
                        n = (long long)floor((double)p->hi[2] / 8) - l0 + 1;
        const long long s0 = l0 + n * o->brick / o->bricks,
                        s1 = l0 + n * (o->brick + 1) / o->bricks;
        const long long k0 = s0 * 8, k1 = s1 * 8 - 1;
        if (k0 > p->lo[2])
            p->lo[2] = p->ilo[2] = k0;
        if (k1 < p->hi[2])
            p->hi[2] = p->ihi[2] = k1;
    }
    for (int a = 0; a < 3; a++) {
        const uint64_t d = p->hi[a] >= p->lo[a] ? (uint64_t)(p->hi[a] - p->lo[a] + 1) : 0;
        if (a > 0)
            p->rows *= d;
        dense = d && dense > UINT64_MAX / d ? UINT64_MAX : dense * d;
    }
    if (!o->have_band && dense > VOL_MAX_VOXELS)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "%llu voxels exceed the limit of %llu: raise --voxel-size, shrink --bbox "
                        "or use --band-sphere",
                        (unsigned long long)dense, (unsigned long long)VOL_MAX_VOXELS);
    return BG_OK;
}

/* Visit only the voxels the band can reach (ilo..ihi, and per row an x span,
 * row_span): the advice above is a big box with a band, and scanning the whole
 * box for a small sphere would take hours. The exact band test still decides
 * each voxel, so the result is the same as a full scan. */
static bg_status band_range(const bgt_volume_opts *o, vol_plan *p, bgt_err *e)
{
    const double *band = o->band;
    p->rows = 1;
    for (int a = 0; a < 3; a++)
        clip_range(band[a], band[3] + band[4], o->voxel, &p->ilo[a], &p->ihi[a]);
    for (int a = 0; a < 3; a++) {
        if (p->ihi[a] < p->ilo[a]) {
            p->rows = 0;
            break;
        }
        if (a > 0)
            p->rows *= (uint64_t)(p->ihi[a] - p->ilo[a] + 1);
    }
    /* Each row costs time even if the band misses it; a sphere this wide
     * would also have more band voxels than the limit. */
    if (p->rows > VOL_MAX_VOXELS)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--band-sphere: %llu rows of voxels to visit exceed the limit of "
                        "%llu: raise --voxel-size or shrink the sphere",
                        (unsigned long long)p->rows, (unsigned long long)VOL_MAX_VOXELS);
    return BG_OK;
}

/* Memory goes by 8^3 leaves, not voxels: a box one voxel thick fills each
 * leaf with 8 voxels at the cost of 512 (about 8.5 KB per leaf for the float
 * and the vec3 grid). Count the leaves the box (or the band's shell, widened
 * by a leaf) can touch and check them against the one cap, with the batch
 * arrays of the longest row. */
static bg_status check_memory(const bgt_volume_opts *o, const vol_plan *p, bgt_err *e)
{
    double leaves = 1;
    if (!o->have_band) {
        for (int a = 0; a < 3; a++)
            leaves *= floor((double)p->hi[a] / 8) - floor((double)p->lo[a] / 8) + 1;
    } else {
        const double *band = o->band;
        const double pi = 3.14159265358979323846, leaf = 8 * o->voxel;
        const double ro = band[3] + band[4] + leaf, ri = band[3] - band[4] - leaf;
        const double shell = 4.0 / 3.0 * pi * (ro * ro * ro - (ri > 0 ? ri * ri * ri : 0));
        leaves = ceil(shell / (leaf * leaf * leaf)) + 1;
    }
    const double row = (double)(p->ihi[0] - p->ilo[0] + 1);
    return bgt_check_alloc(leaves * 8704.0 + (VOL_BATCH + row) * 40.0, "this volume", e);
}

static void batch_free(batch *b)
{
    void *ptrs[] = {b->i, b->j, b->k, b->px, b->py, b->pz, b->h, b->gx, b->gy, b->gz};
    for (size_t a = 0; a < sizeof ptrs / sizeof ptrs[0]; a++)
        free(ptrs[a]);
}

/* Room for a full batch plus the longest row (a row is never split). */
static int batch_alloc(batch *b, size_t cap)
{
    b->i = malloc(cap * sizeof *b->i);
    b->j = malloc(cap * sizeof *b->j);
    b->k = malloc(cap * sizeof *b->k);
    b->px = malloc(cap * sizeof *b->px);
    b->py = malloc(cap * sizeof *b->py);
    b->pz = malloc(cap * sizeof *b->pz);
    b->h = malloc(cap * sizeof *b->h);
    b->gx = malloc(cap * sizeof *b->gx);
    b->gy = malloc(cap * sizeof *b->gy);
    b->gz = malloc(cap * sizeof *b->gz);
    return b->i && b->j && b->k && b->px && b->py && b->pz && b->h && b->gx && b->gy && b->gz;
}

/* The grids' writer, with the height's parameters riding along in the file,
 * so a grid says what it holds. */
static bg_status writer_open(const bgt_height *height, double voxel, bg_vdb_writer **w, bgt_err *e)
{
    bg_status st = bg_vdb_writer_create(voxel, NULL, NULL, NULL, w);
    if (st != BG_OK)
        return st == BG_ERR_IO ? bgt_fail(e, BG_ERR_IO, "the I/O module (OpenVDB) cannot be loaded")
               : st == BG_ERR_INVALID_ARGUMENT
                   ? bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                              "--voxel-size %g: OpenVDB refuses a transform this fine "
                              "(measured with OpenVDB 10: voxels below about 1.5e-5 fail)", voxel)
                   : bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    const bg_height *hh = &height->h;
    char text[256];
    snprintf(text, sizeof text,
             "%s octaves=%d lacunarity=%.9g gain=%.9g amplitude=%.9g frequency=%.9g "
             "gradient=%s",
             function_name(hh->fractal.function), hh->fractal.octaves,
             (double)hh->fractal.lacunarity, (double)hh->fractal.gain, (double)hh->amplitude,
             (double)hh->frequency, hh->gradient == BG_GRADIENT_CENTRAL ? "central" : "analytic");
    bg_vdb_writer_set_meta(*w, "bumpgrad:height", text);
    return BG_OK;
}

/* Row (j, k)'s voxels into the batch: the box's x range, or with a band the x
 * span of the outer sphere on this row minus the part inside the inner sphere
 * (radius R - W), shrunk by a voxel, and then the exact band test. */
static void fill_row(const bgt_volume_opts *o, const vol_plan *p, int32_t j, int32_t k, batch *b,
                     size_t *fill)
{
    const double *band = o->band, voxel = o->voxel;
    long long i0 = p->ilo[0], i1 = p->ihi[0], hole0 = 0, hole1 = -1;
    if (o->have_band) {
        /* The 1e-12 R^2 terms cover the cancellation in R^2 - q at tangent rows. */
        const double dy = voxel * j - band[1], dz = voxel * k - band[2];
        const double q = dy * dy + dz * dz, ro = band[3] + band[4], ri = band[3] - band[4];
        clip_range(band[0], sqrt(fmax(ro * ro - q, 0.0) + 1e-12 * ro * ro), voxel, &i0, &i1);
        const double inner = ri * ri - q - 1e-12 * ri * ri;
        if (ri > 0.0 && inner > 0.0) {
            const double si = sqrt(inner);
            const double h0 = ceil((band[0] - si) / voxel) + 1.0,
                         h1 = floor((band[0] + si) / voxel) - 1.0;
            hole0 = h0 > (double)i0 ? (long long)fmin(h0, (double)i1 + 1.0) : i0;
            hole1 = h1 < (double)i1 ? (long long)fmax(h1, (double)i0 - 1.0) : i1;
        }
    }
    for (long long i = i0; i <= i1; i++) {
        if (i == hole0 && hole0 <= hole1) {
            i = hole1;
            continue;
        }
        if (o->have_band) {
            /* Band test in double, on the same voxel centres the bake uses. */
            const double dx = voxel * (double)i - band[0], dy = voxel * j - band[1],
                         dz = voxel * k - band[2];
            if (!(fabs(sqrt(dx * dx + dy * dy + dz * dz) - band[3]) <= band[4]))
                continue;
        }
        b->i[*fill] = (int32_t)i;
        b->j[*fill] = j;
        b->k[*fill] = k;
        ++*fill;
    }
}

/* Evaluate the batch's `fill` voxels in parallel and add them to the grids
 * (from this thread: the VDB tree is not thread-safe to fill). */
static bg_status flush_batch(const bgt_volume_opts *o, batch *b, size_t fill, bg_vdb_writer *w,
                             uint64_t *total, bgt_err *e)
{
    bgt_parallel_for(fill, VOL_CHUNK, o->threads, eval_range, b);
    if (bg_vdb_writer_add(w, b->i, b->j, b->k, fill, b->h, b->gx, b->gy, b->gz) != BG_OK)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory while filling the grids");
    *total += fill;
    if (*total > VOL_MAX_VOXELS)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "more than %llu active voxels: raise --voxel-size or narrow the band",
                        (unsigned long long)VOL_MAX_VOXELS);
    return BG_OK;
}

/* Every row of the plan, batch by batch, with progress by rows. */
static bg_status bake_rows(const bgt_volume_opts *o, const vol_plan *p, batch *b,
                           bg_vdb_writer *w, bgt_err *e)
{
    bgt_progress_begin(o->progress, "baking rows", (size_t)p->rows);
    size_t fill = 0, rows_done = 0;
    uint64_t total = 0;
    const long long ny = p->ihi[1] - p->ilo[1] + 1;
    bg_status st = BG_OK;
    for (uint64_t row = 0; row <= p->rows; row++) {
        /* Flush a full batch, and whatever is left after the last row. */
        if (fill >= VOL_BATCH || (row == p->rows && fill > 0)) {
            if ((st = flush_batch(o, b, fill, w, &total, e)) != BG_OK)
                break;
            fill = 0;
            bgt_progress_update(o->progress, rows_done);
        }
        if (row == p->rows)
            break;
        const int32_t k = (int32_t)(p->ilo[2] + (long long)(row / (uint64_t)ny));
        const int32_t j = (int32_t)(p->ilo[1] + (long long)(row % (uint64_t)ny));
        fill_row(o, p, j, k, b, &fill);
        rows_done++;
    }
    bgt_progress_end(o->progress);
    return st;
}

bg_status bgt_volume_run(const bgt_volume_opts *o, bgt_volume_result *r, bgt_err *e)
{
    if (!o || !o->height || !o->output || !r)
        return bgt_fail(e, BG_ERR_NULL_POINTER, "no height, output or result given");
    memset(r, 0, sizeof *r);
    bg_status st = bgt_io_ready(e);
    if (st != BG_OK)
        return st;
    vol_plan p;
    if ((st = check_opts(o, e)) != BG_OK || (st = box_range(o, &p, e)) != BG_OK ||
        (o->have_band && (st = band_range(o, &p, e)) != BG_OK) ||
        (st = check_memory(o, &p, e)) != BG_OK)
        return st;
    bgt_height height = *o->height;
    height.grid = NULL;
    if ((st = bgt_height_open(&height, e)) != BG_OK)
        return st;

    bg_vdb_writer *w = NULL;
    batch b = {.height = &height, .voxel = o->voxel};
    if (!batch_alloc(&b, VOL_BATCH + (size_t)(p.ihi[0] - p.ilo[0] + 1)))
        st = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    else if ((st = writer_open(&height, o->voxel, &w, e)) == BG_OK &&
             /* The gradient grid exists also when no voxel is baked (an empty
              * brick has the grids of the others, so it merges). */
             (st = bg_vdb_writer_add(w, b.i, b.j, b.k, 0, b.h, b.gx, b.gy, b.gz) == BG_OK
                       ? BG_OK
                       : bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory")) == BG_OK &&
             (st = bake_rows(o, &p, &b, w, e)) == BG_OK) {
        char err[1024];
        bg_status ws = bg_vdb_writer_write(w, o->output, err, sizeof err);
        if (ws != BG_OK) {
            st = bgt_fail(e, ws == BG_ERR_OUT_OF_MEMORY ? BG_ERR_OUT_OF_MEMORY : BG_ERR_IO, "%s",
                          err);
        } else {
            r->voxels = bg_vdb_writer_voxel_count(w);
            for (int a = 0; a < 3; a++) {
                r->lo[a] = p.lo[a];
                r->hi[a] = p.hi[a];
            }
        }
    }
    bg_vdb_writer_free(w);
    batch_free(&b);
    bgt_height_close(&height);
    return st;
}
