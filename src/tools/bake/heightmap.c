/* SPDX-License-Identifier: MIT */
/* The conversions of `bumpgrad heightmap`: an image read as a height field ->
 * a tangent-space normal map, after the seed "bump map generation from a
 * diffuse texture" (gray = weighted sum of R, G, B; s = (1, 0, dH/ds),
 * t = (0, 1, dH/dt), n = normalize(s x t) = normalize(-dH/ds, -dH/dt, 1)).
 * With to_derivative, the reverse direction of the surface-gradient
 * framework: a tangent-space normal map -> a derivative map (dh/du, dh/dv) =
 * (-m.x/m.z, -m.y/m.z). */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "bake/heightmap.h"
#include "bake/bake_internal.h"
#include "bumpgrad/framework.h"
#include "bumpgrad/image.h"

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

/* OUT's format as a lower-case extension into e (len bytes): `format` for
 * "-" (standard output; PNG without one, as bg_image_write_as writes it),
 * else the file's extension, which decides: a `format` that names another is
 * refused, as by render --format. */
static bg_status out_format(const char *path, const char *format, char *e, size_t len,
                            bgt_err *err)
{
    if (format && *format == '.')
        format++;
    if (format && (!*format || strlen(format) >= len))
        return bgt_fail(err, BG_ERR_INVALID_ARGUMENT, "--format: \"%s\": not an image format",
                        format);
    if (strcmp(path, "-") != 0) {
        lower_ext(path, e, len);
        if (format && strcasecmp(format, e) != 0)
            return bgt_fail(err, BG_ERR_INVALID_ARGUMENT,
                            "--format %s disagrees with the extension of OUT \"%s\" (the "
                            "extension decides; --format is for OUT -)",
                            format, path);
        return BG_OK;
    }
    const char *f = format ? format : "png";
    size_t i = 0;
    for (; f[i] && i + 1 < len; i++)
        e[i] = (char)tolower((unsigned char)f[i]);
    e[i] = '\0';
    return BG_OK;
}

/* Formats that store only 8 bits or at most 16: OpenImageIO would silently
 * narrow a wider request, so refuse it here. Unknown formats are allowed.
 * `e`: OUT's format (out_format). */
static int max_bits_for(const char *e)
{
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
        bg_vec3 m = {2.0f * s[0] - 1.0f, 2.0f * s[1] - 1.0f, 2.0f * s[2] - 1.0f};
        if (y_down)
            m.y = -m.y;
        /* The one rule of the library (framework.h): m.z mirrored to the
         * visible side, slopes bounded by 128 along their own direction. */
        const bg_vec2 d = bg_tangent_normal_to_derivs(m);
        out[3 * p + 0] = d.x;
        out[3 * p + 1] = d.y;
        out[3 * p + 2] = 0.0f;
    }
}

/* The options that need no file: bits (0 becomes the default: float for
 * --to-derivative, else 8), strength, and the output's format and depth. */
static bg_status check_opts(const bgt_heightmap_opts *o, int *bits, bgt_err *e)
{
    const char *out_path = o->output;
    *bits = o->bits;
    if (*bits != 0 && *bits != 8 && *bits != 16 && *bits != 32)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "--bits: expected 8, 16 or float, got %d",
                        *bits);
    if (!isfinite(o->strength))
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "--strength: must be finite, got %g",
                        (double)o->strength);
    if (*bits == 0)
        *bits = o->to_derivative ? 32 : 8;
    if (o->to_derivative && *bits != 32)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "--to-derivative writes float derivatives in [-128, 128]: "
                                    "use --bits float (the default) and an .exr or .tif output");
    char ext[16];
    bg_status st = out_format(out_path, o->format, ext, sizeof ext, e);
    if (st != BG_OK)
        return st;
    if (*bits > max_bits_for(ext))
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        strcmp(out_path, "-") == 0
                            ? "'%s': %s cannot store %s samples; use --format exr or tif"
                            : "'%s': this format (%s) cannot store %s samples; use .exr or .tif",
                        out_path, ext, *bits == 32 ? "float" : "16-bit");
    return BG_OK;
}

/* The input image. Missing, unreadable or not an image: bad input (2); only
 * running out of memory is a runtime failure (1). Standard input has no
 * name to tell its format by: say how to give it. */
static bg_status read_input(const bgt_heightmap_opts *o, bg_image *in, bgt_err *e)
{
    char err[1024];
    const char *in_path = o->input;
    bg_status st = bg_image_read_as(in_path, o->input_format, in, err, sizeof err);
    if (st == BG_OK)
        return BG_OK;
    return bgt_fail(e, bgt_read_status(st), "%s%s%s",
                    st == BG_ERR_INVALID_ARGUMENT && o->input_format ? "--input-format: " : "",
                    err,
                    st == BG_ERR_FORMAT && !o->input_format && strcmp(in_path, "-") == 0
                        ? "; name its format with --input-format FMT (png, tga, exr, ...)"
                        : "");
}

/* --to-derivative: a tangent-space normal map into derivatives (3 channels,
 * every texel finite). */
static bg_status normals_to_derivs(const bgt_heightmap_opts *o, const bg_image *in, float *out,
                                   bgt_err *e)
{
    if (in->channels < 3)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "'%s': a normal map needs 3 channels, this image has %d",
                        o->input, in->channels);
    const size_t bad = first_bad_normal(in);
    if (bad != (size_t)-1)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "'%s': pixel (%zu, %zu) is NaN, infinite or beyond float "
                                  "range: a normal map needs finite values",
                        o->input, bad % (size_t)in->width, bad / (size_t)in->width);
    to_derivative_map(in, o->y_down, out);
    return BG_OK;
}

/* A height image (its gray value: Rec. 709 luma, or the seed document's
 * 0.33/0.66/0.11 weights) into a normal map. */
static bg_status height_to_normals(const bgt_heightmap_opts *o, const bg_image *in, float *out,
                                   bgt_err *e)
{
    const int w = in->width, h = in->height;
    float *hgt = malloc(sizeof *hgt * (size_t)w * h);
    if (!hgt)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "'%s': out of memory for a %dx%d image", o->input, w, h);
    const int seed_gray = o->gray == BGT_GRAY_SEED;
    const float wr = seed_gray ? 0.33f : 0.2126f, wg = seed_gray ? 0.66f : 0.7152f,
                wb = seed_gray ? 0.11f : 0.0722f;
    const int c = in->channels;
    for (size_t p = 0; p < (size_t)w * h; p++) {
        const float *s = in->pixels + p * c;
        hgt[p] = c >= 3 ? wr * s[0] + wg * s[1] + wb * s[2] : s[0];
    }
    /* A NaN or Inf height (float input, or a gray sum past FLT_MAX) would
     * make NaN normals around it: refuse it, naming the first pixel. */
    for (size_t p = 0; p < (size_t)w * h; p++)
        if (!isfinite(hgt[p])) {
            free(hgt);
            return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "'%s': pixel (%zu, %zu) is NaN, infinite or beyond "
                                      "float range: a height image needs finite values",
                            o->input, p % (size_t)w, p / (size_t)w);
        }
    to_normal_map(hgt, w, h, o->strength, o->wrap, o->y_down, out);
    free(hgt);
    return BG_OK;
}

bg_status bgt_heightmap_run(const bgt_heightmap_opts *o, bgt_err *e)
{
    if (!o || !o->input || !o->output)
        return bgt_fail(e, BG_ERR_NULL_POINTER, "expected IN OUT");
    bg_status rc = bgt_io_ready(e);
    if (rc != BG_OK)
        return rc;
    int bits;
    if ((rc = check_opts(o, &bits, e)) != BG_OK)
        return rc;
    bg_image in;
    if ((rc = read_input(o, &in, e)) != BG_OK)
        return rc;
    const int w = in.width, h = in.height;
    bg_image out;
    if (bg_image_alloc(&out, w, h, 3) != BG_OK) {
        bg_image_free(&in);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "'%s': out of memory for a %dx%d image", o->input, w, h);
    }
    rc = o->to_derivative ? normals_to_derivs(o, &in, out.pixels, e)
                          : height_to_normals(o, &in, out.pixels, e);
    if (rc == BG_OK)
        rc = bake_write_image(o->output, o->format, &out, bits, e);
    bg_image_free(&in);
    bg_image_free(&out);
    return rc;
}
