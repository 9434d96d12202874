/* SPDX-License-Identifier: MIT */
/* `bumpgrad volume`: bake a height function and its gradient into an OpenVDB
 * file (FloatGrid "height" + Vec3SGrid "gradient"), densely over a box or only
 * in a narrow band around a sphere. Voxels are visited row by row and gathered
 * into batches that are evaluated in parallel with the batch kernels, then
 * added to the grids from this thread (the VDB tree is not thread-safe to fill). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "bumpgrad/volume.h"
#include "cli.h"

#define CMD "volume"

/* Voxels per batch: big enough to keep all workers busy, small enough (28 MB of
 * coordinates and results) to bake boxes far larger than memory allows densely. */
#define VOL_BATCH ((size_t)1 << 20)
#define VOL_CHUNK 4096
/* Refuse bakes above this many active voxels: OpenVDB needs about 16 bytes per
 * voxel for the two grids, so 2^28 voxels is already about 4 GB. */
#define VOL_MAX_VOXELS ((uint64_t)1 << 28)

static void volume_help(FILE *fp)
{
    fputs("Usage: bumpgrad volume --bbox X0,Y0,Z0,X1,Y1,Z1 --voxel-size S\n"
          "                       [height options] [--band-sphere CX,CY,CZ,R,W]\n"
          "                       --output FILE.vdb\n"
          "\n"
          "Bake the height h(p) and its gradient into an OpenVDB file: a FloatGrid\n"
          "\"height\" and a Vec3SGrid \"gradient\" (world units, covariant). Voxel\n"
          "(i,j,k) sits at world position S*(i,j,k); the baked voxels are those whose\n"
          "centre lies in the box (inclusive). Read it back with --height-grid.\n"
          "\n"
          "Options:\n"
          "  --bbox X0,Y0,Z0,X1,Y1,Z1  world box to bake, X0 <= X1 etc. (required)\n"
          "  --voxel-size S            voxel edge in world units, > 0 (required)\n"
          "  --band-sphere CX,CY,CZ,R,W\n"
          "                            narrow band: only voxels whose centre is within\n"
          "                            W of the sphere of centre C and radius R\n"
          "                            (| |p - C| - R | <= W); others stay inactive\n"
          "                            (background 0). Sample at least one voxel inside\n"
          "                            the band's edge.\n"
          "  -o, --output FILE.vdb     output (required); written to a temporary file\n"
          "                            and renamed on success\n"
          "  --threads N               worker threads (default: all cores)\n"
          "  -h, --help                this help\n"
          "\n",
          fp);
    cli_height_help(fp);
    fputs("(--height-grid is not accepted here: volume bakes a function.)\n"
          "\n"
          "Prints the number of active voxels. Exit status: 0 success, 1 the output\n"
          "cannot be written (or out of memory), 2 bad usage.\n"
          "\n"
          "Example:\n"
          "  bumpgrad volume --function fbm --octaves 4 --bbox -1,-1,-1,1,1,1 \\\n"
          "      --voxel-size 0.02 --band-sphere 0,0,0,0.8,0.06 --output ball.vdb\n",
          fp);
}

/* "a,b,c,..." with exactly n numbers. */
static int parse_list(const char *opt, const char *text, int n, double *out)
{
    char buf[512];
    if (strlen(text) >= sizeof buf)
        return cli_usage_error(CMD, "%s: value too long", opt);
    strcpy(buf, text);
    int count = 0;
    char *p = buf;
    for (;;) {
        char *comma = strchr(p, ',');
        if (comma)
            *comma = '\0';
        if (count >= n)
            return cli_usage_error(CMD, "%s: expected %d comma-separated numbers, got \"%s\"",
                                   opt, n, text);
        if (cli_parse_double(CMD, opt, p, &out[count]))
            return CLI_USAGE;
        if (!isfinite(out[count]))
            return cli_usage_error(CMD, "%s: numbers must be finite, got \"%s\"", opt, text);
        count++;
        if (!comma)
            break;
        p = comma + 1;
    }
    if (count != n)
        return cli_usage_error(CMD, "%s: expected %d comma-separated numbers, got \"%s\"", opt, n,
                               text);
    return 0;
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
    const cli_height *height;
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
    cli_height_gradient(b->height, b->px + begin, b->py + begin, b->pz + begin, end - begin,
                        b->h + begin, b->gx + begin, b->gy + begin, b->gz + begin);
}

int cmd_volume(int argc, char **argv)
{
    cli_height height;
    cli_height_init(&height);
    const char *out_path = NULL;
    double bbox[6], voxel = 0.0, band[5];
    int have_bbox = 0, have_band = 0;
    long threads = 0;
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i], *v;
        int rc = cli_height_option(CMD, &height, argc, argv, &i);
        if (rc == 1)
            continue;
        if (rc != 0)
            return rc;
        if (strcmp(o, "-h") == 0 || strcmp(o, "--help") == 0) {
            volume_help(stdout);
            return CLI_OK;
        } else if (strcmp(o, "--bbox") == 0) {
            if (cli_need_value(CMD, argc, argv, &i, &v) || parse_list(o, v, 6, bbox))
                return CLI_USAGE;
            have_bbox = 1;
        } else if (strcmp(o, "--voxel-size") == 0) {
            if (cli_need_value(CMD, argc, argv, &i, &v) || cli_parse_double(CMD, o, v, &voxel))
                return CLI_USAGE;
            if (!(voxel > 0.0 && isfinite(voxel)))
                return cli_usage_error(CMD, "--voxel-size: must be finite and > 0, got \"%s\"", v);
        } else if (strcmp(o, "--band-sphere") == 0) {
            if (cli_need_value(CMD, argc, argv, &i, &v) || parse_list(o, v, 5, band))
                return CLI_USAGE;
            if (!(band[3] >= 0.0) || !(band[4] >= 0.0))
                return cli_usage_error(CMD, "--band-sphere: radius and width must be >= 0, got "
                                            "\"%s\"", v);
            have_band = 1;
        } else if (strcmp(o, "-o") == 0 || strcmp(o, "--output") == 0) {
            if (cli_need_value(CMD, argc, argv, &i, &out_path))
                return CLI_USAGE;
        } else if (strcmp(o, "--threads") == 0) {
            if (cli_need_value(CMD, argc, argv, &i, &v) ||
                cli_parse_int(CMD, o, v, 1, 4096, &threads))
                return CLI_USAGE;
        } else {
            return cli_usage_error(CMD, "unknown argument \"%s\" (see bumpgrad volume --help)", o);
        }
    }
    if (!have_bbox)
        return cli_usage_error(CMD, "--bbox is required");
    if (voxel == 0.0)
        return cli_usage_error(CMD, "--voxel-size is required");
    if (!out_path)
        return cli_usage_error(CMD, "--output is required");
    /* Elsewhere "-" is standard output; here it silently made a file named "-". */
    if (strcmp(out_path, "-") == 0)
        return cli_usage_error(CMD, "--output: a VDB file cannot go to standard output (\"-\")");
    if (height.grid_path)
        return cli_usage_error(CMD, "--height-grid: volume bakes a height function, not a grid");
    for (int a = 0; a < 3; a++)
        if (!(bbox[a] <= bbox[a + 3]))
            return cli_usage_error(CMD, "--bbox: min must not exceed max on axis %c",
                                   "xyz"[a]);
    /* Index range of voxel centres inside the box; each must fit OpenVDB's int32. */
    long long lo[3], hi[3];
    uint64_t rows = 1, dense = 1;
    for (int a = 0; a < 3; a++) {
        const double l = ceil(bbox[a] / voxel), h = floor(bbox[a + 3] / voxel);
        if (!(fabs(l) < 1e9 && fabs(h) < 1e9))
            return cli_usage_error(CMD, "--bbox / --voxel-size: axis %c spans more than 1e9 "
                                        "voxels from the origin", "xyz"[a]);
        lo[a] = (long long)l;
        hi[a] = (long long)h;
        if (hi[a] < lo[a])
            return cli_usage_error(CMD, "--bbox: no voxel centre (multiple of %g) inside the box "
                                        "on axis %c", voxel, "xyz"[a]);
        const uint64_t d = (uint64_t)(hi[a] - lo[a] + 1);
        if (a > 0)
            rows *= d;
        dense = dense > UINT64_MAX / d ? UINT64_MAX : dense * d;
    }
    if (!have_band && dense > VOL_MAX_VOXELS)
        return cli_usage_error(CMD, "%llu voxels exceed the limit of %llu: raise --voxel-size, "
                                    "shrink --bbox or use --band-sphere",
                               (unsigned long long)dense, (unsigned long long)VOL_MAX_VOXELS);
    /* Visit only the voxels the band can reach (ilo..ihi, and per row an x span
     * below): the advice above is a big box with a band, and scanning the whole
     * box for a small sphere would take hours. The exact band test still decides
     * each voxel, so the result is the same as a full scan. */
    long long ilo[3] = {lo[0], lo[1], lo[2]}, ihi[3] = {hi[0], hi[1], hi[2]};
    if (have_band) {
        rows = 1;
        for (int a = 0; a < 3; a++) {
            clip_range(band[a], band[3] + band[4], voxel, &ilo[a], &ihi[a]);
            if (a > 0)
                rows *= (uint64_t)(ihi[a] - ilo[a] + 1);
        }
        if (ihi[0] < ilo[0])
            rows = 0;
        /* Each row costs time even if the band misses it; a sphere this wide
         * would also have more band voxels than the limit. */
        if (rows > VOL_MAX_VOXELS)
            return cli_usage_error(CMD, "--band-sphere: %llu rows of voxels to visit exceed the "
                                        "limit of %llu: raise --voxel-size or shrink the sphere",
                                   (unsigned long long)rows, (unsigned long long)VOL_MAX_VOXELS);
    }
    int rc = cli_height_open(CMD, &height);
    if (rc)
        return rc;

    bg_vdb_writer *w = NULL;
    batch b = {.height = &height, .voxel = voxel};
    const size_t cap = VOL_BATCH + (size_t)(ihi[0] - ilo[0] + 1);
    b.i = malloc(cap * sizeof *b.i);
    b.j = malloc(cap * sizeof *b.j);
    b.k = malloc(cap * sizeof *b.k);
    b.px = malloc(cap * sizeof *b.px);
    b.py = malloc(cap * sizeof *b.py);
    b.pz = malloc(cap * sizeof *b.pz);
    b.h = malloc(cap * sizeof *b.h);
    b.gx = malloc(cap * sizeof *b.gx);
    b.gy = malloc(cap * sizeof *b.gy);
    b.gz = malloc(cap * sizeof *b.gz);
    if (!b.i || !b.j || !b.k || !b.px || !b.py || !b.pz || !b.h || !b.gx || !b.gy || !b.gz) {
        rc = cli_fail(CMD, "out of memory");
        goto done;
    }
    {
        bg_status st = bg_vdb_writer_create(voxel, NULL, NULL, NULL, &w);
        if (st != BG_OK) {
            rc = cli_fail(CMD, "%s", st == BG_ERR_IO ? "the I/O module (OpenVDB) cannot be loaded"
                                                     : "out of memory");
            goto done;
        }
    }
    {
        /* The parameters ride along in the file, so a grid says what it holds. */
        const bg_height *hh = &height.h;
        char text[256];
        snprintf(text, sizeof text,
                 "%s octaves=%d lacunarity=%.9g gain=%.9g amplitude=%.9g frequency=%.9g "
                 "gradient=%s",
                 cli_function_name(hh->fractal.function), hh->fractal.octaves, (double)hh->fractal.lacunarity,
                 (double)hh->fractal.gain, (double)hh->amplitude, (double)hh->frequency,
                 hh->gradient == BG_GRADIENT_CENTRAL ? "central" : "analytic");
        bg_vdb_writer_set_meta(w, "bumpgrad:height", text);
    }

    cli_progress prog;
    cli_progress_begin(&prog, "baking rows", (size_t)rows);
    size_t fill = 0, rows_done = 0;
    uint64_t total = 0;
    const long long ny = ihi[1] - ilo[1] + 1;
    for (uint64_t r = 0; r <= rows; r++) {
        /* Flush a full batch, and whatever is left after the last row. */
        if (fill >= VOL_BATCH || (r == rows && fill > 0)) {
            cli_parallel_for(fill, VOL_CHUNK, (int)threads, eval_range, &b);
            if (bg_vdb_writer_add(w, b.i, b.j, b.k, fill, b.h, b.gx, b.gy, b.gz) != BG_OK) {
                cli_progress_end(&prog);
                rc = cli_fail(CMD, "out of memory while filling the grids");
                goto done;
            }
            total += fill;
            fill = 0;
            cli_progress_update(&prog, rows_done);
            if (total > VOL_MAX_VOXELS) {
                cli_progress_end(&prog);
                rc = cli_usage_error(CMD, "more than %llu active voxels: raise --voxel-size or "
                                          "narrow the band", (unsigned long long)VOL_MAX_VOXELS);
                goto done;
            }
        }
        if (r == rows)
            break;
        const int32_t k = (int32_t)(ilo[2] + (long long)(r / (uint64_t)ny));
        const int32_t j = (int32_t)(ilo[1] + (long long)(r % (uint64_t)ny));
        long long i0 = ilo[0], i1 = ihi[0], hole0 = 0, hole1 = -1;
        if (have_band) {
            /* The x span of the outer sphere on this row, and the part of it
             * inside the inner sphere (radius R - W), shrunk by a voxel. The
             * 1e-12 R^2 terms cover the cancellation in R^2 - q at tangent rows. */
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
            if (have_band) {
                /* Band test in double, on the same voxel centres the bake uses. */
                const double dx = voxel * (double)i - band[0], dy = voxel * j - band[1],
                             dz = voxel * k - band[2];
                if (!(fabs(sqrt(dx * dx + dy * dy + dz * dz) - band[3]) <= band[4]))
                    continue;
            }
            b.i[fill] = (int32_t)i;
            b.j[fill] = j;
            b.k[fill] = k;
            fill++;
        }
        rows_done++;
    }
    cli_progress_end(&prog);

    {
        char err[1024];
        bg_status st = bg_vdb_writer_write(w, out_path, err, sizeof err);
        if (st != BG_OK) {
            rc = cli_fail(CMD, "%s", err);
            goto done;
        }
    }
    printf("%s: %llu active voxels (height + gradient), voxel size %g, index box "
           "[%lld,%lld,%lld]..[%lld,%lld,%lld]\n",
           out_path, (unsigned long long)bg_vdb_writer_voxel_count(w), voxel, lo[0], lo[1], lo[2],
           hi[0], hi[1], hi[2]);
done:
    bg_vdb_writer_free(w);
    free(b.i);
    free(b.j);
    free(b.k);
    free(b.px);
    free(b.py);
    free(b.pz);
    free(b.h);
    free(b.gx);
    free(b.gy);
    free(b.gz);
    cli_height_close(&height);
    return rc;
}
