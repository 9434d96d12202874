/* SPDX-License-Identifier: MIT */
/* Test helper for tests/mesh/test_mesh.py: a thin bridge from Python to the
 * library's public single-point API, so that the test can recompute every
 * vertex and texel the `bumpgrad mesh` command wrote, without the command's
 * code (no batch kernels, no bgt_height_*, no mesh_* helpers of src/tools).
 *
 *   mesh_oracle perturb IN.f32 OUT.f32 N --method M [height options]
 *       IN: N records of 6 float32 (px py pz nx ny nz), native byte order.
 *       OUT: N records of 4 float32 (h, n'x, n'y, n'z) from bg_height_eval and
 *       bg_perturb(M, n, grad h).
 *   mesh_oracle gradient IN.f32 OUT.f32 N [height options]
 *       IN: N records of 3 float32 (px py pz). OUT: N records of 4 float32
 *       (h, gx, gy, gz) from bg_height_eval.
 *   mesh_oracle image FILE OUT.f32
 *       OUT: int32 width, height, channels, then the float pixels as
 *       bg_image_read returns them (row 0 at the top).
 * Height options: --function noise|fbm|turbulence --octaves N --lacunarity L
 * --gain G --amplitude A --frequency F --gradient analytic|central --step H. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bumpgrad.h"
#include "bumpgrad/image.h"

static int fail(const char *msg, const char *arg)
{
    fprintf(stderr, "mesh_oracle: %s%s%s\n", msg, arg ? " " : "", arg ? arg : "");
    return 1;
}

static int parse_height(int argc, char **argv, int i, bg_height *h, bg_perturb_method *m)
{
    *h = bg_height_default();
    *m = BG_PERTURB_SURFGRAD;
    for (; i < argc; i++) {
        const char *o = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v)
            return fail("option without value:", o);
        i++;
        if (strcmp(o, "--method") == 0) {
            if (strcmp(v, "surfgrad") == 0)
                *m = BG_PERTURB_SURFGRAD;
            else if (strcmp(v, "additive") == 0)
                *m = BG_PERTURB_ADDITIVE;
            else if (strcmp(v, "additive-perlin") == 0)
                *m = BG_PERTURB_ADDITIVE_PERLIN;
            else
                return fail("bad method", v);
        } else if (strcmp(o, "--function") == 0) {
            h->fractal.function = strcmp(v, "noise") == 0 ? BG_FUNC_NOISE
                                  : strcmp(v, "fbm") == 0 ? BG_FUNC_FBM
                                                          : BG_FUNC_TURBULENCE;
        } else if (strcmp(o, "--octaves") == 0) {
            h->fractal.octaves = atoi(v);
        } else if (strcmp(o, "--lacunarity") == 0) {
            h->fractal.lacunarity = strtof(v, NULL);
        } else if (strcmp(o, "--gain") == 0) {
            h->fractal.gain = strtof(v, NULL);
        } else if (strcmp(o, "--amplitude") == 0) {
            h->amplitude = strtof(v, NULL);
        } else if (strcmp(o, "--frequency") == 0) {
            h->frequency = strtof(v, NULL);
        } else if (strcmp(o, "--gradient") == 0) {
            h->gradient = strcmp(v, "central") == 0 ? BG_GRADIENT_CENTRAL : BG_GRADIENT_ANALYTIC;
        } else if (strcmp(o, "--step") == 0) {
            h->step = strtof(v, NULL);
        } else {
            return fail("unknown option", o);
        }
    }
    return bg_height_validate(h) == BG_OK ? 0 : fail("invalid height parameters", NULL);
}

/* One record of a row command: `nin` floats of IN to the 4 floats of OUT. */
typedef void (*row_fn)(const bg_height *h, bg_perturb_method m, const float *r, float w[4]);

/* h, then n' = bg_perturb(m, n, grad h), from (px py pz nx ny nz). */
static void perturb_row(const bg_height *h, bg_perturb_method m, const float *r, float w[4])
{
    bg_vec3 p = {r[0], r[1], r[2]}, nn = {r[3], r[4], r[5]}, g;
    w[0] = bg_height_eval(h, p, &g);
    bg_vec3 q = bg_perturb(m, nn, g);
    w[1] = q.x, w[2] = q.y, w[3] = q.z;
}

/* h and grad h from (px py pz). */
static void gradient_row(const bg_height *h, bg_perturb_method m, const float *r, float w[4])
{
    (void)m;
    bg_vec3 g;
    w[0] = bg_height_eval(h, (bg_vec3){r[0], r[1], r[2]}, &g);
    w[1] = g.x, w[2] = g.y, w[3] = g.z;
}

/* The row commands: `cmd IN OUT N [options]`, N records of `nin` floats in,
 * N records of 4 floats out through `row`. */
static int map_rows(int argc, char **argv, const char *usage, size_t nin, row_fn row)
{
    if (argc < 5)
        return fail(usage, NULL);
    bg_height h;
    bg_perturb_method m;
    if (parse_height(argc, argv, 5, &h, &m))
        return 1;
    size_t n = (size_t)strtoull(argv[4], NULL, 10);
    FILE *in = fopen(argv[2], "rb"), *out = fopen(argv[3], "wb");
    if (!in || !out)
        return fail("cannot open", !in ? argv[2] : argv[3]);
    for (size_t i = 0; i < n; i++) {
        float r[6], w[4];
        if (fread(r, sizeof(float) * nin, 1, in) != 1)
            return fail("short input", argv[2]);
        row(&h, m, r, w);
        if (fwrite(w, sizeof w, 1, out) != 1)
            return fail("write error", argv[3]);
    }
    fclose(in);
    return fclose(out) != 0 ? fail("write error", argv[3]) : 0;
}

static int do_image(int argc, char **argv)
{
    if (argc != 4)
        return fail("usage: image FILE OUT", NULL);
    bg_image img;
    char err[512];
    if (bg_image_read(argv[2], &img, err, sizeof err) != BG_OK)
        return fail(err, NULL);
    FILE *out = fopen(argv[3], "wb");
    if (!out)
        return fail("cannot open", argv[3]);
    int32_t hdr[3] = {img.width, img.height, img.channels};
    size_t n = (size_t)img.width * (size_t)img.height * (size_t)img.channels;
    int bad = fwrite(hdr, sizeof hdr, 1, out) != 1 || fwrite(img.pixels, sizeof(float), n, out) != n;
    bad |= fclose(out) != 0;
    bg_image_free(&img);
    return bad ? fail("write error", argv[3]) : 0;
}

int main(int argc, char **argv)
{
    if (argc >= 2 && strcmp(argv[1], "perturb") == 0)
        return map_rows(argc, argv, "usage: perturb IN OUT N [options]", 6, perturb_row);
    if (argc >= 2 && strcmp(argv[1], "gradient") == 0)
        return map_rows(argc, argv, "usage: gradient IN OUT N [options]", 3, gradient_row);
    if (argc >= 2 && strcmp(argv[1], "image") == 0)
        return do_image(argc, argv);
    return fail("usage: mesh_oracle perturb|gradient|image ...", NULL);
}
