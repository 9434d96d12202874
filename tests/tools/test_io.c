/* SPDX-License-Identifier: MIT */
/* Unit tests of the I/O shim (include/bumpgrad/image.h, volume.h).
 * Usage: test_io {image|volume|errors} SCRATCH_DIR
 * Expected values come from the formulas (quantization rules, the sRGB curve,
 * exact linear fields, Perlin noise through the core library's analytic
 * gradient), never from files saved by an earlier run. */
#define _GNU_SOURCE /* mkdtemp */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "bumpgrad.h"
#include "bumpgrad/image.h"
#include "bumpgrad/volume.h"
#include "scratch.h"

static long file_size(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 ? (long)st.st_size : -1;
}

static void write_bytes(const char *p, const void *data, size_t n)
{
    FILE *f = fopen(p, "wb");
    if (f) {
        fwrite(data, 1, n, f);
        fclose(f);
    }
}

/* ---- images ------------------------------------------------------------- */

static float pattern(int x, int y, int c)
{
    /* Values covering [0, 1] including both ends, distinct per channel. */
    return (float)((x * 7 + y * 13 + c * 5) % 31) / 30.0f;
}

static double srgb(double v)
{
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

static void test_image(void)
{
    const int w = 11, h = 7, nc = 3;
    bg_image img;
    char err[1024];
    CHECK(bg_image_alloc(&img, w, h, nc) == BG_OK, "alloc");
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < nc; c++)
                img.pixels[(y * w + x) * nc + c] = pattern(x, y, c);

    struct {
        const char *name;
        bg_pixel_type type;
        double tol; /* largest allowed |read - written| */
    } cases[] = {
        {"img8.png", BG_PIXEL_U8, 0.5 / 255 + 1e-6},
        {"img16.png", BG_PIXEL_U16, 0.5 / 65535 + 1e-7},
        {"img16.tif", BG_PIXEL_U16, 0.5 / 65535 + 1e-7},
        {"imgh.exr", BG_PIXEL_HALF, 1.0 / 2048}, /* half: 11-bit significand */
        {"imgf.exr", BG_PIXEL_F32, 0.0},
        {"imgf.tif", BG_PIXEL_F32, 0.0},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const char *p = path_in(cases[k].name);
        bg_status st = bg_image_write(p, &img, cases[k].type, 0, err, sizeof err);
        CHECK(st == BG_OK, "write %s: %s", p, err);
        bg_image r;
        st = bg_image_read(p, &r, err, sizeof err);
        CHECK(st == BG_OK, "read %s: %s", p, err);
        if (st != BG_OK)
            continue;
        CHECK(r.width == w && r.height == h && r.channels == nc, "%s: shape %dx%dx%d", p,
              r.width, r.height, r.channels);
        double worst = 0;
        for (int i = 0; i < w * h * nc; i++)
            worst = fmax(worst, fabs((double)r.pixels[i] - img.pixels[i]));
        CHECK(worst <= cases[k].tol, "%s: round trip error %g > %g", p, worst, cases[k].tol);
        bg_image_free(&r);
    }

    /* sRGB flag: each stored byte is round(255 * srgb(v)), independently computed. */
    {
        const char *p = path_in("srgb.png");
        CHECK(bg_image_write(p, &img, BG_PIXEL_U8, 1, err, sizeof err) == BG_OK, "srgb: %s", err);
        bg_image r;
        if (bg_image_read(p, &r, err, sizeof err) == BG_OK) {
            int bad = 0;
            for (int i = 0; i < w * h * nc; i++) {
                double want = floor(255.0 * srgb(img.pixels[i]) + 0.5) / 255.0;
                if (fabs(r.pixels[i] - want) > 1.01 / 255.0 * 0.5)
                    bad++;
            }
            CHECK(bad == 0, "srgb: %d samples differ from round(255 srgb(v))", bad);
            /* A mid-gray must come out visibly brighter: srgb(0.5) = 0.7354 -> 188. */
            bg_image_free(&r);
        } else {
            CHECK(0, "srgb read: %s", err);
        }
    }

    /* Text for labelled panels: draws somewhere, changes nothing far away. */
    {
        bg_image t;
        bg_image_alloc(&t, 64, 24, 3);
        const float white[3] = {1, 1, 1};
        bg_status st = bg_image_draw_text(&t, 2, 2, "Ag", white, 16, err, sizeof err);
        if (st == BG_OK) {
            double sum_text = 0, sum_far = 0;
            for (int y = 0; y < 24; y++)
                for (int x = 0; x < 64; x++) {
                    double v = t.pixels[(y * 64 + x) * 3];
                    if (x < 30)
                        sum_text += v;
                    else if (x > 45)
                        sum_far += v;
                }
            CHECK(sum_text > 5.0, "draw_text drew nothing (sum %g)", sum_text);
            CHECK(sum_far == 0.0, "draw_text drew beyond its text (sum %g)", sum_far);
        } else {
            printf("  note: no font for bg_image_draw_text (%s)\n", err);
        }
        bg_image_free(&t);
    }
    bg_image_free(&img);
    CHECK(temp_leftovers() == 0, "temporary files left in %s", dir);
}

/* ---- errors --------------------------------------------------------------- */

static void test_errors(void)
{
    char err[1024];
    bg_image img, r;
    bg_image_alloc(&img, 4, 4, 3);

    /* Missing file: I/O error naming it. */
    const char *missing = path_in("no_such_image.png");
    CHECK(bg_image_read(missing, &r, err, sizeof err) == BG_ERR_IO, "missing: %s", err);
    CHECK(strstr(err, "no_such_image.png") != NULL, "missing: message lacks the name: %s", err);

    /* Not an image / corrupt / truncated: format error naming it. */
    const char *junk = path_in("junk.png");
    write_bytes(junk, "\x89PNG\r\n\x1a\nthis is not a png at all", 32);
    CHECK(bg_image_read(junk, &r, err, sizeof err) == BG_ERR_FORMAT, "corrupt: %s", err);
    CHECK(strstr(err, "junk.png") != NULL, "corrupt: message lacks the name: %s", err);
    const char *good = path_in("good.png");
    bg_image big;
    bg_image_alloc(&big, 64, 64, 3);
    for (int i = 0; i < 64 * 64 * 3; i++)
        big.pixels[i] = (float)((i * 2654435761u) % 1000) / 999.0f; /* incompressible */
    CHECK(bg_image_write(good, &big, BG_PIXEL_U8, 0, err, sizeof err) == BG_OK, "good: %s", err);
    {
        FILE *f = fopen(good, "rb");
        static unsigned char buf[1 << 16];
        size_t n = f ? fread(buf, 1, sizeof buf, f) : 0;
        if (f)
            fclose(f);
        const char *cut = path_in("cut.png");
        write_bytes(cut, buf, n / 2);
        CHECK(bg_image_read(cut, &r, err, sizeof err) == BG_ERR_FORMAT, "truncated: %s", err);
        CHECK(strstr(err, "cut.png") != NULL, "truncated: message lacks the name: %s", err);
    }
    bg_image_free(&big);

    /* Unwritable folder: I/O error naming the file. */
    CHECK(bg_image_write("/proc/bumpgrad_no_write.png", &img, BG_PIXEL_U8, 0, err, sizeof err) ==
              BG_ERR_IO,
          "unwritable: %s", err);
    CHECK(strstr(err, "bumpgrad_no_write.png") != NULL, "unwritable: message: %s", err);
    CHECK(bg_image_write(path_in("nodir/x.png"), &img, BG_PIXEL_U8, 0, err, sizeof err) ==
              BG_ERR_IO,
          "missing folder: %s", err);
    /* Unknown extension: refused before anything is created. */
    CHECK(bg_image_write(path_in("x.notaformat"), &img, BG_PIXEL_U8, 0, err, sizeof err) ==
              BG_ERR_INVALID_ARGUMENT,
          "unknown extension: %s", err);

    /* A write that fails after the temporary file exists (PNG cannot hold 5
     * channels) leaves the old file byte for byte and no temporary file. */
    {
        const char *old = path_in("old.png");
        CHECK(bg_image_write(old, &img, BG_PIXEL_U8, 0, err, sizeof err) == BG_OK, "old: %s", err);
        long before = file_size(old);
        bg_image five;
        bg_image_alloc(&five, 4, 4, 5);
        CHECK(bg_image_write(old, &five, BG_PIXEL_U8, 0, err, sizeof err) == BG_ERR_IO,
              "5-channel png should fail: %s", err);
        CHECK(file_size(old) == before, "old output changed size");
        CHECK(bg_image_read(old, &r, err, sizeof err) == BG_OK && r.channels == 3,
              "old output no longer readable: %s", err);
        bg_image_free(&r);
        bg_image_free(&five);
    }
    /* Destination is a folder: rename fails, the temporary file is removed. */
    {
        const char *d = path_in("adir.png");
        mkdir(d, 0755);
        CHECK(bg_image_write(d, &img, BG_PIXEL_U8, 0, err, sizeof err) == BG_ERR_IO,
              "folder as output: %s", err);
        rmdir(d);
    }
    CHECK(temp_leftovers() == 0, "temporary files left in %s", dir);

    /* VDB reader errors. */
    bg_vdb_height *h = NULL;
    CHECK(bg_vdb_height_open(path_in("none.vdb"), NULL, &h, err, sizeof err) == BG_ERR_IO,
          "missing vdb: %s", err);
    CHECK(strstr(err, "none.vdb") != NULL, "missing vdb: message: %s", err);
    CHECK(bg_vdb_height_open(junk, NULL, &h, err, sizeof err) == BG_ERR_FORMAT, "png as vdb: %s",
          err);
    /* A small baked file, then the grid errors and truncations. */
    const char *vdb = path_in("small.vdb");
    {
        bg_vdb_writer *w;
        CHECK(bg_vdb_writer_create(0.1, NULL, NULL, NULL, &w) == BG_OK, "writer");
        int32_t ii[512], jj[512], kk[512];
        float hv[512], gx[512], gy[512], gz[512];
        size_t n = 0;
        for (int k = 0; k < 8; k++)
            for (int j = 0; j < 8; j++)
                for (int i = 0; i < 8; i++, n++) {
                    ii[n] = i;
                    jj[n] = j;
                    kk[n] = k;
                    hv[n] = (float)((i * 31 + j * 17 + k * 7) % 23); /* incompressible-ish */
                    gx[n] = gy[n] = gz[n] = (float)n;
                }
        bg_vdb_writer_add(w, ii, jj, kk, n, hv, gx, gy, gz);
        CHECK(bg_vdb_writer_write(w, vdb, err, sizeof err) == BG_OK, "write vdb: %s", err);
        CHECK(bg_vdb_writer_write(w, "/proc/bumpgrad_no_write.vdb", err, sizeof err) == BG_ERR_IO,
              "unwritable vdb: %s", err);
        CHECK(strstr(err, "bumpgrad_no_write.vdb") != NULL, "unwritable vdb: message: %s", err);
        bg_vdb_writer_free(w);
    }
    CHECK(bg_vdb_height_open(vdb, "gradient", &h, err, sizeof err) == BG_ERR_FORMAT,
          "vec3s grid accepted: %s", err);
    CHECK(strstr(err, "vec3s") != NULL && strstr(err, "gradient") != NULL, "wrong type msg: %s",
          err);
    CHECK(bg_vdb_height_open(vdb, "density", &h, err, sizeof err) == BG_ERR_FORMAT,
          "missing grid accepted: %s", err);
    CHECK(strstr(err, "density") != NULL, "missing grid msg: %s", err);
    CHECK(bg_vdb_height_open(vdb, NULL, &h, err, sizeof err) == BG_OK, "open: %s", err);
    bg_vdb_height_close(h);
    {
        FILE *f = fopen(vdb, "rb");
        static unsigned char buf[1 << 20];
        size_t n = f ? fread(buf, 1, sizeof buf, f) : 0;
        if (f)
            fclose(f);
        /* Cuts anywhere (header, descriptors, either grid's data) must fail
         * cleanly: the reader checks the whole file, not just the grid asked for. */
        for (int pc = 5; pc <= 95; pc += 5) {
            const char *cut = path_in("cut.vdb");
            write_bytes(cut, buf, n * (size_t)pc / 100);
            h = NULL;
            bg_status st = bg_vdb_height_open(cut, "height", &h, err, sizeof err);
            CHECK(st == BG_ERR_FORMAT, "vdb cut at %d%% gave %d: %s", pc, (int)st, err);
            CHECK(h == NULL, "handle returned on failure");
            bg_vdb_height_close(h);
        }
    }
    CHECK(temp_leftovers() == 0, "temporary files left in %s", dir);
    bg_image_free(&img);
}

/* ---- volumes -------------------------------------------------------------- */

typedef struct {
    double voxel;
    int n; /* voxels per axis, from index 0 */
} bake_spec;

/* Bake h = noise(p) (amplitude 1, frequency 1) with its analytic gradient. */
static int bake_noise(const char *path, bake_spec s)
{
    bg_vdb_writer *w;
    if (bg_vdb_writer_create(s.voxel, NULL, "height", "gradient", &w) != BG_OK)
        return 0;
    size_t row = (size_t)s.n;
    int32_t *ii = malloc(row * sizeof *ii), *jj = malloc(row * sizeof *jj),
            *kk = malloc(row * sizeof *kk);
    float *hv = malloc(row * sizeof *hv), *gx = malloc(row * sizeof *gx),
          *gy = malloc(row * sizeof *gy), *gz = malloc(row * sizeof *gz);
    for (int k = 0; k < s.n; k++)
        for (int j = 0; j < s.n; j++) {
            for (int i = 0; i < s.n; i++) {
                bg_vec3 g;
                ii[i] = i;
                jj[i] = j;
                kk[i] = k;
                hv[i] = bg_noise3_grad((float)(s.voxel * i), (float)(s.voxel * j),
                                       (float)(s.voxel * k), &g);
                gx[i] = g.x;
                gy[i] = g.y;
                gz[i] = g.z;
            }
            bg_vdb_writer_add(w, ii, jj, kk, row, hv, gx, gy, gz);
        }
    char err[1024];
    int ok = bg_vdb_writer_write(w, path, err, sizeof err) == BG_OK;
    if (!ok)
        printf("  bake: %s\n", err);
    CHECK(bg_vdb_writer_voxel_count(w) == (uint64_t)s.n * s.n * s.n, "voxel count");
    bg_vdb_writer_free(w);
    free(ii), free(jj), free(kk), free(hv), free(gx), free(gy), free(gz);
    return ok;
}

#define NPTS 4000
static float qx[NPTS], qy[NPTS], qz[NPTS];

/* Largest height and gradient error of the grid against the analytic noise. */
static void grid_error(const char *path, double *eh, double *eg)
{
    char err[1024];
    bg_vdb_height *h;
    *eh = *eg = INFINITY;
    if (bg_vdb_height_open(path, NULL, &h, err, sizeof err) != BG_OK) {
        CHECK(0, "open %s: %s", path, err);
        return;
    }
    static float hv[NPTS], gx[NPTS], gy[NPTS], gz[NPTS];
    bg_vdb_height_sample_batch(h, qx, qy, qz, NPTS, hv, gx, gy, gz);
    *eh = *eg = 0;
    for (int t = 0; t < NPTS; t++) {
        bg_vec3 g;
        float v = bg_noise3_grad(qx[t], qy[t], qz[t], &g);
        *eh = fmax(*eh, fabs((double)hv[t] - v));
        *eg = fmax(*eg, fmax(fabs((double)gx[t] - g.x),
                             fmax(fabs((double)gy[t] - g.y), fabs((double)gz[t] - g.z))));
    }
    bg_vdb_height_close(h);
}

typedef struct {
    const bg_vdb_height *h;
    float *out;
} thread_job;

static void *sample_thread(void *p)
{
    thread_job *j = p;
    for (int rep = 0; rep < 5; rep++)
        bg_vdb_height_sample_batch(j->h, qx, qy, qz, NPTS, j->out, j->out + NPTS,
                                   j->out + 2 * NPTS, j->out + 3 * NPTS);
    return NULL;
}

static void test_volume(void)
{
    char err[1024];
    /* Points well inside [0, 2]^3 (one voxel of margin at the coarse size). */
    unsigned s = 12345;
    for (int t = 0; t < NPTS; t++) {
        float *c[3] = {&qx[t], &qy[t], &qz[t]};
        for (int a = 0; a < 3; a++) {
            s = s * 1664525u + 1013904223u;
            *c[a] = 0.15f + 1.7f * (float)(s >> 8) / 16777216.0f;
        }
    }
    /* The same noise baked at two voxel sizes: errors small, and shrinking at
     * the second-order rate of trilinear interpolation and central differences. */
    const char *coarse = path_in("noise16.vdb"), *fine = path_in("noise32.vdb");
    CHECK(bake_noise(coarse, (bake_spec){1.0 / 16, 33}), "bake coarse");
    CHECK(bake_noise(fine, (bake_spec){1.0 / 32, 65}), "bake fine");
    double eh16, eg16, eh32, eg32;
    grid_error(coarse, &eh16, &eg16);
    grid_error(fine, &eh32, &eg32);
    printf("  noise grid error: voxel 1/16 height %.3g gradient %.3g; voxel 1/32 height %.3g "
           "gradient %.3g\n",
           eh16, eg16, eh32, eg32);
    /* Bounds: trilinear error <= h^2/8 |H''|, central-difference error ~ h^2/24 |H'''|
     * plus the interpolation's; noise has |H''| up to ~20, |H'''| ~ 200 at f = 1. */
    const double v32 = 1.0 / 32;
    CHECK(eh32 <= 4.0 * v32 * v32, "height error %g above 4 h^2 = %g", eh32, 4.0 * v32 * v32);
    CHECK(eg32 <= 40.0 * v32 * v32, "gradient error %g above 40 h^2 = %g", eg32,
          40.0 * v32 * v32);
    CHECK(eg16 / eg32 > 2.5, "gradient error does not fall ~4x when the voxel halves: %g -> %g",
          eg16, eg32);
    CHECK(eh16 / eh32 > 2.5, "height error does not fall ~4x when the voxel halves: %g -> %g",
          eh16, eh32);

    bg_vdb_height *h;
    if (bg_vdb_height_open(fine, NULL, &h, err, sizeof err) == BG_OK) {
        bg_vdb_height_info in;
        bg_vdb_height_get_info(h, &in);
        CHECK(in.active_voxels == 65u * 65u * 65u, "info voxels %llu",
              (unsigned long long)in.active_voxels);
        CHECK(fabs(in.voxel_size[0] - v32) < 1e-12 && in.index_min[0] == 0 && in.index_max[2] == 64,
              "info voxel size / bbox");
        CHECK(strcmp(in.name, "height") == 0, "info name %s", in.name);
        CHECK(fabs(in.world_max[1] - 2.0) < 1e-9, "info world max %g", in.world_max[1]);

        /* Concurrent calls give the serial bits. */
        static float serial[4 * NPTS], par[4][4 * NPTS];
        bg_vdb_height_sample_batch(h, qx, qy, qz, NPTS, serial, serial + NPTS, serial + 2 * NPTS,
                                   serial + 3 * NPTS);
        pthread_t tid[4];
        thread_job jobs[4];
        for (int t = 0; t < 4; t++) {
            jobs[t] = (thread_job){h, par[t]};
            pthread_create(&tid[t], NULL, sample_thread, &jobs[t]);
        }
        for (int t = 0; t < 4; t++) {
            pthread_join(tid[t], NULL);
            CHECK(memcmp(serial, par[t], sizeof serial) == 0, "thread %d differs from serial", t);
        }
        /* Non-finite positions: NaN out; far away: background 0, gradient 0. */
        float x[2] = {NAN, 1e30f}, y[2] = {0.5f, 0.5f}, z[2] = {0.5f, 0.5f}, hv[2], g[6];
        bg_vdb_height_sample_batch(h, x, y, z, 2, hv, g, g + 2, g + 4);
        CHECK(isnan(hv[0]) && isnan(g[0]), "NaN position: %g %g", hv[0], g[0]);
        CHECK(hv[1] == 0.0f && g[1] == 0.0f && g[3] == 0.0f, "far position: %g %g", hv[1], g[1]);
        bg_vdb_height_close(h);
    } else {
        CHECK(0, "open fine: %s", err);
    }

    /* A linear field is reproduced exactly (up to float rounding), with an
     * origin offset and a non-unit voxel: checks the index<->world maps. */
    {
        const char *lin = path_in("linear.vdb");
        const double origin[3] = {-1.25, 0.5, 2.0}, vs = 0.2;
        bg_vdb_writer *w;
        CHECK(bg_vdb_writer_create(vs, origin, NULL, NULL, &w) == BG_OK, "linear writer");
        for (int k = 0; k < 10; k++)
            for (int j = 0; j < 10; j++)
                for (int i = 0; i < 10; i++) {
                    int32_t a = i, b = j, c = k;
                    double px = origin[0] + vs * i, py = origin[1] + vs * j, pz = origin[2] + vs * k;
                    float v = (float)(0.5 * px - 2.0 * py + 0.25 * pz + 1.0);
                    bg_vdb_writer_add(w, &a, &b, &c, 1, &v, NULL, NULL, NULL);
                }
        CHECK(bg_vdb_writer_write(w, lin, err, sizeof err) == BG_OK, "linear: %s", err);
        bg_vdb_writer_free(w);
        if (bg_vdb_height_open(lin, NULL, &h, err, sizeof err) == BG_OK) {
            double worst_h = 0, worst_g = 0;
            for (int t = 0; t < 200; t++) {
                float px = (float)(origin[0] + 0.3 + 1.2 * (t % 17) / 17.0);
                float py = (float)(origin[1] + 0.3 + 1.2 * (t % 13) / 13.0);
                float pz = (float)(origin[2] + 0.3 + 1.2 * (t % 11) / 11.0);
                float hv, gx, gy, gz;
                bg_vdb_height_sample_batch(h, &px, &py, &pz, 1, &hv, &gx, &gy, &gz);
                worst_h = fmax(worst_h, fabs(hv - (0.5 * px - 2.0 * py + 0.25 * pz + 1.0)));
                worst_g = fmax(worst_g, fmax(fabs(gx - 0.5), fmax(fabs(gy + 2.0), fabs(gz - 0.25))));
            }
            CHECK(worst_h < 2e-5, "linear field height error %g", worst_h);
            CHECK(worst_g < 2e-4, "linear field gradient error %g", worst_g);
            bg_vdb_height_close(h);
        } else {
            CHECK(0, "open linear: %s", err);
        }
    }
    CHECK(temp_leftovers() == 0, "temporary files left in %s", dir);
}

int main(int argc, char **argv)
{
    static const scratch_group groups[] = {
        {"image", test_image},
        {"volume", test_volume},
        {"errors", test_errors}};
    return scratch_main(argc, argv, "test_io", groups, sizeof groups / sizeof groups[0]);
}
