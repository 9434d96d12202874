/* SPDX-License-Identifier: MIT */
/* `bumpgrad heightmap`: an image read as a height field -> a tangent-space
 * normal map, after the seed "bump map generation from a diffuse texture"
 * (gray = weighted sum of R, G, B; s = (1, 0, dH/ds), t = (0, 1, dH/dt),
 * n = normalize(s x t) = normalize(-dH/ds, -dH/dt, 1)). With --to-derivative,
 * the reverse direction of the surface-gradient framework: a tangent-space
 * normal map -> a derivative map (dh/du, dh/dv) = (-m.x/m.z, -m.y/m.z). */
#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "bumpgrad/image.h"
#include "cli.h"

#define CMD "heightmap"

/* The framework's bound on a derivative-map ratio: beyond 128 the normal is
 * within half a degree of the tangent plane, and the clamp keeps the surface
 * gradient finite where m.z is 0 or negative. */
#define DERIV_LIMIT 128.0f

static void heightmap_help(FILE *fp)
{
    fputs("Usage: bumpgrad heightmap IN OUT [options]\n"
          "       bumpgrad heightmap IN OUT --to-derivative [--bits float]\n"
          "\n"
          "Turn any image OpenImageIO reads into a tangent-space normal map, treating\n"
          "its gray level as a height H (the seed's \"bump map from a diffuse texture\"):\n"
          "  a = H[x+1,y] - H[x-1,y],  b = H[x,y-1] - H[x,y+1]   (y-1 is the row above)\n"
          "  n = normalize(-S*a, -S*b, 1)\n"
          "The differences are NOT divided by 2, as in the seed: they span two pixels,\n"
          "so --strength 0.5 gives the per-pixel slope. +x is right, +y is up (the\n"
          "OpenGL / \"Y+\" convention; --y-down flips green for DirectX), +z points\n"
          "out of the surface. Stored as 0.5*n + 0.5 in R, G, B (no sRGB curve).\n"
          "\n"
          "Options:\n"
          "  --gray seed|rec709   gray level of a colour input from its stored values\n"
          "                       (no decoding of sRGB): seed = 0.33 R + 0.66 G + 0.11 B\n"
          "                       (default; the weights sum to 1.1, so H may exceed 1),\n"
          "                       rec709 = 0.2126 R + 0.7152 G + 0.0722 B. One- and\n"
          "                       two-channel inputs use their first channel as H.\n"
          "  --strength S         slope factor S (default 1; negative inverts bumps)\n"
          "  --edge clamp|wrap    neighbours beyond the border: repeat the edge pixel\n"
          "                       (default) or wrap around (tileable textures)\n"
          "  --bits 8|16|float    storage of OUT (default 8; float needs .exr or .tif)\n"
          "  --y-down             green = +y down (DirectX convention)\n"
          "  --to-derivative      IN is a tangent-space normal map stored as 0.5*m+0.5\n"
          "                       (in any bit depth); OUT gets the derivative map\n"
          "                       R = dh/du = -m.x/m.z, G = dh/dv = -m.y/m.z as float\n"
          "                       (.exr or .tif, --bits float, the default here). m.z is\n"
          "                       kept positive (raised to max(|m.x|,|m.y|)/128 when\n"
          "                       smaller) so each ratio stays within [-128, 128].\n"
          "  -h, --help           this help\n"
          "\n"
          "A NaN or infinite sample in IN (float images), or a gray level or unpacked\n"
          "normal beyond float range, is an error naming the pixel (exit status 2).\n"
          "\n"
          "OUT is written to a temporary file next to it and renamed on success: a\n"
          "failure never leaves a partial file or replaces an old one. IN and OUT may\n"
          "be the same file.\n"
          "\n"
          "Exit status: 0 success, 1 the output cannot be written (or out of memory),\n"
          "2 bad usage or an input that is missing, unreadable or not an image.\n"
          "\n"
          "Examples:\n"
          "  bumpgrad heightmap diffuse.png normal.png --strength 2 --edge wrap\n"
          "  bumpgrad heightmap normal.png deriv.exr --to-derivative\n",
          fp);
}

/* Extension of a path in lower case ("" if none), for format checks. */
static void lower_ext(const char *path, char *out, size_t len)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(path, '.');
    out[0] = '\0';
    if (!dot || (slash && dot < slash))
        return;
    size_t i = 0;
    for (dot++; *dot && i + 1 < len; dot++)
        out[i++] = (char)tolower((unsigned char)*dot);
    out[i] = '\0';
}

/* Formats that store only 8 bits or at most 16: OpenImageIO would silently
 * narrow a wider request, so refuse it here. Unknown formats are allowed. */
static int max_bits_for(const char *path)
{
    char e[16];
    lower_ext(path, e, sizeof e);
    static const char *const eight[] = {"jpg", "jpeg", "bmp", "tga", "gif", "webp", "ico"};
    static const char *const sixteen[] = {"png", "ppm", "pgm", "pnm", "sgi", "rgb", "jp2"};
    for (size_t i = 0; i < sizeof eight / sizeof eight[0]; i++)
        if (strcmp(e, eight[i]) == 0)
            return 8;
    for (size_t i = 0; i < sizeof sixteen / sizeof sixteen[0]; i++)
        if (strcmp(e, sixteen[i]) == 0)
            return 16;
    return 32;
}

static inline int edge_index(int i, int n, int wrap)
{
    if (wrap)
        return ((i % n) + n) % n;
    return i < 0 ? 0 : (i >= n ? n - 1 : i);
}

static void to_normal_map(const float *hgt, int w, int h, float strength, int wrap, int y_down,
                          float *out)
{
    for (int y = 0; y < h; y++) {
        const int up = edge_index(y - 1, h, wrap), down = edge_index(y + 1, h, wrap);
        for (int x = 0; x < w; x++) {
            const int l = edge_index(x - 1, w, wrap), r = edge_index(x + 1, w, wrap);
            const double a = (double)hgt[(size_t)y * w + r] - hgt[(size_t)y * w + l];
            double b = (double)hgt[(size_t)up * w + x] - hgt[(size_t)down * w + x];
            if (y_down)
                b = -b;
            /* s x t with s = (1,0,S a), t = (0,1,S b). */
            const double nx = -strength * a, ny = -strength * b, nz = 1.0;
            const double inv = 1.0 / sqrt(nx * nx + ny * ny + nz * nz);
            float *o = out + 3 * ((size_t)y * w + x);
            o[0] = (float)(0.5 * nx * inv + 0.5);
            o[1] = (float)(0.5 * ny * inv + 0.5);
            o[2] = (float)(0.5 * nz * inv + 0.5);
        }
    }
}

/* First texel whose unpacked normal 2*s-1 is not finite, or (size_t)-1. Such
 * a texel has no slope: without this check it came out as an arbitrary
 * +-128 or 0 (NaN slipping through the clamps). */
static size_t first_bad_normal(const bg_image *in)
{
    const size_t n = (size_t)in->width * in->height;
    for (size_t p = 0; p < n; p++) {
        const float *s = in->pixels + p * in->channels;
        if (!isfinite(2.0f * s[0] - 1.0f) || !isfinite(2.0f * s[1] - 1.0f) ||
            !isfinite(2.0f * s[2] - 1.0f))
            return p;
    }
    return (size_t)-1;
}

static void to_derivative_map(const bg_image *in, int y_down, float *out)
{
    const size_t n = (size_t)in->width * in->height;
    const int c = in->channels;
    for (size_t p = 0; p < n; p++) {
        const float *s = in->pixels + p * c;
        float mx = 2.0f * s[0] - 1.0f, my = 2.0f * s[1] - 1.0f, mz = 2.0f * s[2] - 1.0f;
        if (y_down)
            my = -my;
        float lim = fmaxf(fabsf(mx), fabsf(my)) / DERIV_LIMIT;
        /* m.z at or below the bound (including negative: a normal pointing
         * inward) is raised to it, so the ratios saturate at +-128 instead of
         * flipping sign; an all-zero texel has no slope. */
        if (!(mz > lim))
            mz = lim;
        float du = 0.0f, dv = 0.0f;
        if (mz > 0.0f) {
            du = fminf(fmaxf(-mx / mz, -DERIV_LIMIT), DERIV_LIMIT);
            dv = fminf(fmaxf(-my / mz, -DERIV_LIMIT), DERIV_LIMIT);
        }
        out[3 * p + 0] = du;
        out[3 * p + 1] = dv;
        out[3 * p + 2] = 0.0f;
    }
}

int cmd_heightmap(int argc, char **argv)
{
    const char *in_path = NULL, *out_path = NULL;
    int seed_gray = 1, wrap = 0, y_down = 0, to_deriv = 0, bits = 0;
    float strength = 1.0f;
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i], *v;
        if (strcmp(o, "-h") == 0 || strcmp(o, "--help") == 0) {
            heightmap_help(stdout);
            return CLI_OK;
        } else if (strcmp(o, "--gray") == 0) {
            if (cli_need_value(CMD, argc, argv, &i, &v))
                return CLI_USAGE;
            if (strcmp(v, "seed") == 0)
                seed_gray = 1;
            else if (strcmp(v, "rec709") == 0)
                seed_gray = 0;
            else
                return cli_usage_error(CMD, "--gray: expected seed or rec709, got \"%s\"", v);
        } else if (strcmp(o, "--strength") == 0) {
            if (cli_need_value(CMD, argc, argv, &i, &v) ||
                cli_parse_float(CMD, o, v, &strength))
                return CLI_USAGE;
            if (!isfinite(strength))
                return cli_usage_error(CMD, "--strength: must be finite, got \"%s\"", v);
        } else if (strcmp(o, "--edge") == 0) {
            if (cli_need_value(CMD, argc, argv, &i, &v))
                return CLI_USAGE;
            if (strcmp(v, "clamp") == 0)
                wrap = 0;
            else if (strcmp(v, "wrap") == 0)
                wrap = 1;
            else
                return cli_usage_error(CMD, "--edge: expected clamp or wrap, got \"%s\"", v);
        } else if (strcmp(o, "--bits") == 0) {
            if (cli_need_value(CMD, argc, argv, &i, &v))
                return CLI_USAGE;
            if (strcmp(v, "8") == 0)
                bits = 8;
            else if (strcmp(v, "16") == 0)
                bits = 16;
            else if (strcmp(v, "float") == 0)
                bits = 32;
            else
                return cli_usage_error(CMD, "--bits: expected 8, 16 or float, got \"%s\"", v);
        } else if (strcmp(o, "--y-down") == 0) {
            y_down = 1;
        } else if (strcmp(o, "--to-derivative") == 0) {
            to_deriv = 1;
        } else if (o[0] == '-' && o[1] != '\0') {
            return cli_usage_error(CMD, "unknown option \"%s\" (see bumpgrad heightmap --help)", o);
        } else if (!in_path) {
            in_path = o;
        } else if (!out_path) {
            out_path = o;
        } else {
            return cli_usage_error(CMD, "unexpected argument \"%s\": expected IN OUT", o);
        }
    }
    if (!in_path || !out_path)
        return cli_usage_error(CMD, "expected IN OUT (see bumpgrad heightmap --help)");
    if (bits == 0)
        bits = to_deriv ? 32 : 8;
    if (to_deriv && bits != 32)
        return cli_usage_error(CMD, "--to-derivative writes float derivatives in [-128, 128]: "
                                    "use --bits float (the default) and an .exr or .tif output");
    if (bits > max_bits_for(out_path))
        return cli_usage_error(CMD, "'%s': this format cannot store %s samples; use .exr or .tif",
                               out_path, bits == 32 ? "float" : "16-bit");

    char err[1024];
    bg_image in;
    bg_status st = bg_image_read(in_path, &in, err, sizeof err);
    if (st == BG_ERR_OUT_OF_MEMORY)
        return cli_fail(CMD, "%s", err);
    if (st != BG_OK)
        return cli_usage_error(CMD, "%s", err);

    const int w = in.width, h = in.height;
    bg_image out;
    if (bg_image_alloc(&out, w, h, 3) != BG_OK) {
        bg_image_free(&in);
        return cli_fail(CMD, "'%s': out of memory for a %dx%d image", in_path, w, h);
    }
    int rc = CLI_OK;
    if (to_deriv) {
        if (in.channels < 3) {
            rc = cli_usage_error(CMD, "'%s': a normal map needs 3 channels, this image has %d",
                                 in_path, in.channels);
            goto done;
        }
        const size_t bad = first_bad_normal(&in);
        if (bad != (size_t)-1) {
            rc = cli_usage_error(CMD, "'%s': pixel (%zu, %zu) is NaN, infinite or beyond float "
                                      "range: a normal map needs finite values",
                                 in_path, bad % (size_t)w, bad / (size_t)w);
            goto done;
        }
        to_derivative_map(&in, y_down, out.pixels);
    } else {
        float *hgt = malloc(sizeof *hgt * (size_t)w * h);
        if (!hgt) {
            rc = cli_fail(CMD, "'%s': out of memory for a %dx%d image", in_path, w, h);
            goto done;
        }
        const float wr = seed_gray ? 0.33f : 0.2126f, wg = seed_gray ? 0.66f : 0.7152f,
                    wb = seed_gray ? 0.11f : 0.0722f;
        const int c = in.channels;
        for (size_t p = 0; p < (size_t)w * h; p++) {
            const float *s = in.pixels + p * c;
            hgt[p] = c >= 3 ? wr * s[0] + wg * s[1] + wb * s[2] : s[0];
        }
        /* A NaN or Inf height (float input, or a gray sum past FLT_MAX) would
         * make NaN normals around it: refuse it, naming the first pixel. */
        for (size_t p = 0; p < (size_t)w * h; p++)
            if (!isfinite(hgt[p])) {
                free(hgt);
                rc = cli_usage_error(CMD, "'%s': pixel (%zu, %zu) is NaN, infinite or beyond "
                                          "float range: a height image needs finite values",
                                     in_path, p % (size_t)w, p / (size_t)w);
                goto done;
            }
        to_normal_map(hgt, w, h, strength, wrap, y_down, out.pixels);
        free(hgt);
    }
    {
        const bg_pixel_type type =
            bits == 8 ? BG_PIXEL_U8 : (bits == 16 ? BG_PIXEL_U16 : BG_PIXEL_F32);
        st = bg_image_write(out_path, &out, type, 0, err, sizeof err);
        if (st == BG_ERR_INVALID_ARGUMENT)
            rc = cli_usage_error(CMD, "%s", err);
        else if (st != BG_OK)
            rc = cli_fail(CMD, "%s", err);
    }
done:
    bg_image_free(&in);
    bg_image_free(&out);
    return rc;
}
