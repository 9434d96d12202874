/* SPDX-License-Identifier: MIT */
/* volume_io: the I/O library (bumpgrad-io: io.h, volume.h, image.h) in one
 * program. It
 *  1. bakes the solid turbulence height h(p) and its analytic gradient into an
 *     OpenVDB file, in a narrow shell of voxels around the unit sphere;
 *  2. opens that file again as a height field and samples it (trilinear height,
 *     central-difference gradient) at points on the sphere, reporting how far
 *     the baked height is from the analytic one;
 *  3. shades the sphere with the VDB's gradient through the surface gradient
 *     (Mikkelsen 2010, eq. 4) and writes it as a PNG, then reads the PNG back.
 * Every file is written to a temporary name and renamed on success.
 *
 *   cc volume_io.c $(pkg-config --cflags --libs bumpgrad-io) -lm -o volume_io
 *   ./volume_io OUT_DIR [voxels-per-unit]
 */
#include <bumpgrad.h>
#include <bumpgrad/image.h>
#include <bumpgrad/io.h>
#include <bumpgrad/volume.h>

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#define SIZE 256 /* image width and height */

static int fail(const char *what, bg_status s, const char *err)
{
    fprintf(stderr, "volume_io: %s: %s%s%s\n", what, bg_status_string(s), *err ? ": " : "", err);
    return 1;
}

/* 1. Every voxel whose centre lies within `band` voxels of the unit sphere. */
static bg_status bake(const bg_height *h, double vox, int band, const char *path, char *err,
                      size_t errlen, uint64_t *count)
{
    bg_vdb_writer *w = NULL;
    bg_status s = bg_vdb_writer_create(vox, NULL, "height", "gradient", &w);
    if (s != BG_OK)
        return s;
    const int n = (int)ceil(1.0 / vox) + band + 1;
    for (int k = -n; k <= n && s == BG_OK; k++) { /* one z slab per call */
        int32_t *ijk = malloc(sizeof(int32_t) * 3 * (size_t)(2 * n + 1) * (size_t)(2 * n + 1));
        float *v = malloc(sizeof(float) * 4 * (size_t)(2 * n + 1) * (size_t)(2 * n + 1));
        if (!ijk || !v) {
            free(ijk), free(v);
            s = BG_ERR_OUT_OF_MEMORY;
            break;
        }
        size_t cap = (size_t)(2 * n + 1) * (size_t)(2 * n + 1), m = 0;
        for (int j = -n; j <= n; j++)
            for (int i = -n; i <= n; i++) {
                bg_vec3 p = {(float)(i * vox), (float)(j * vox), (float)(k * vox)}, g;
                float r = sqrtf(p.x * p.x + p.y * p.y + p.z * p.z);
                if (fabs(r - 1.0) > band * vox)
                    continue;
                ijk[m] = i, ijk[cap + m] = j, ijk[2 * cap + m] = k;
                v[m] = bg_height_eval(h, p, &g);
                v[cap + m] = g.x, v[2 * cap + m] = g.y, v[3 * cap + m] = g.z;
                m++;
            }
        s = bg_vdb_writer_add(w, ijk, ijk + cap, ijk + 2 * cap, m, v, v + cap, v + 2 * cap,
                              v + 3 * cap);
        free(ijk), free(v);
    }
    if (s == BG_OK)
        s = bg_vdb_writer_set_meta(w, "generator", "examples/volume_io.c: turbulence, 6 octaves");
    if (s == BG_OK) {
        *count = bg_vdb_writer_voxel_count(w);
        s = bg_vdb_writer_write(w, path, err, errlen);
    }
    bg_vdb_writer_free(w);
    return s;
}

int main(int argc, char **argv)
{
    if (argc < 2 || argc > 3) {
        fprintf(stderr, "usage: %s OUT_DIR [voxels-per-unit, 16..256, default 64]\n", argv[0]);
        return 2;
    }
    int per_unit = argc == 3 ? atoi(argv[2]) : 64;
    if (per_unit < 16 || per_unit > 256) {
        fprintf(stderr, "voxels-per-unit must be between 16 and 256\n");
        return 2;
    }
    char err[1024] = "", vdb_path[4096], png_path[4096];
    snprintf(vdb_path, sizeof vdb_path, "%s/height.vdb", argv[1]);
    snprintf(png_path, sizeof png_path, "%s/shaded.png", argv[1]);

    /* Fail at once, with the reason, if OpenImageIO/OpenVDB cannot be loaded. */
    bg_status s = bg_io_available(err, sizeof err);
    if (s != BG_OK)
        return fail("the I/O module", s, err);

    bg_height h = bg_height_default();
    h.frequency = 3.0f;
    h.amplitude = 0.05f;
    const double vox = 1.0 / per_unit;
    uint64_t voxels = 0;
    s = bake(&h, vox, 4, vdb_path, err, sizeof err, &voxels);
    if (s != BG_OK)
        return fail("bake", s, err);
    printf("baked %llu voxels (voxel %.4g) into %s\n", (unsigned long long)voxels, vox, vdb_path);

    /* 2. Open it again as a height field. */
    bg_vdb_height *vh = NULL;
    s = bg_vdb_height_open(vdb_path, "height", &vh, err, sizeof err);
    if (s != BG_OK)
        return fail("open", s, err);
    bg_vdb_height_info info;
    bg_vdb_height_get_info(vh, &info);
    printf("opened grid '%s': %llu active voxels, world box [%.3f, %.3f]^3\n", info.name,
           (unsigned long long)info.active_voxels, info.world_min[0], info.world_max[0]);

    /* 3. Orthographic view of the sphere, one batch of VDB samples per row. */
    bg_image img;
    s = bg_image_alloc(&img, SIZE, SIZE, 3);
    if (s != BG_OK) {
        bg_vdb_height_close(vh);
        return fail("image", s, "");
    }
    float px[SIZE], py[SIZE], pz[SIZE], hv[SIZE], gx[SIZE], gy[SIZE], gz[SIZE];
    int cols[SIZE];
    double max_err = 0, amp = 0;
    const bg_vec3 light = {-0.5f, 0.6f, 0.62f};
    for (int row = 0; row < SIZE; row++) {
        size_t m = 0;
        float y = 1.0f - 2.0f * (row + 0.5f) / SIZE;
        for (int col = 0; col < SIZE; col++) {
            float x = 2.0f * (col + 0.5f) / SIZE - 1.0f;
            if (x * x + y * y < 1.0f) {
                px[m] = x, py[m] = y, pz[m] = sqrtf(1.0f - x * x - y * y);
                cols[m++] = col;
            }
        }
        bg_vdb_height_sample_batch(vh, px, py, pz, m, hv, gx, gy, gz);
        for (size_t i = 0; i < m; i++) {
            bg_vec3 n = {px[i], py[i], pz[i]}, g = {gx[i], gy[i], gz[i]};
            float ref = bg_height_eval(&h, n, NULL);
            max_err = fmax(max_err, fabs((double)hv[i] - ref));
            amp = fmax(amp, fabs((double)ref));
            bg_vec3 b = bg_perturb_normal(n, g);
            float ndl = b.x * light.x + b.y * light.y + b.z * light.z;
            float lum = 0.05f + 0.95f * (ndl > 0 ? ndl : 0);
            float *pix = img.pixels + ((size_t)row * SIZE + (size_t)cols[i]) * 3;
            pix[0] = lum * 0.95f, pix[1] = lum * 0.80f, pix[2] = lum * 0.62f;
        }
    }
    bg_vdb_height_close(vh);
    printf("sampled the VDB on the sphere: largest |baked - analytic| height %.3g (heights up to %.3g)\n",
           max_err, amp);

    /* Linear values, sRGB-encoded into 8 bits. */
    s = bg_image_write(png_path, &img, BG_PIXEL_U8, 1, err, sizeof err);
    bg_image_free(&img);
    if (s != BG_OK)
        return fail("write", s, err);
    bg_image back;
    s = bg_image_read(png_path, &back, err, sizeof err);
    if (s != BG_OK)
        return fail("read back", s, err);
    printf("wrote %s and read it back: %dx%d, %d channels\n", png_path, back.width, back.height,
           back.channels);
    int ok = back.width == SIZE && back.height == SIZE && back.channels == 3;
    bg_image_free(&back);
    /* Trilinear interpolation misses what the voxels cannot hold (octaves finer
     * than two voxels): about a quarter of the range at 16 voxels per unit, a
     * tenth at 64. */
    return ok && max_err < 0.3 * amp ? 0 : 1;
}
