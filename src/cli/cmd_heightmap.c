/* SPDX-License-Identifier: MIT */
/* `bumpgrad heightmap`: an image read as a height field -> a tangent-space
 * normal map (the seed's "bump map generation from a diffuse texture"), or
 * with --to-derivative a tangent-space normal map -> a derivative map. This
 * file parses the options and runs the conversion (bgt_heightmap_run,
 * src/tools/bake/heightmap.c). */
#include <math.h>
#include <string.h>
#include "bake/bake.h"
#include "cli.h"

#define CMD "heightmap"

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
          "                       (.exr or .tif, --bits float, the default here). As in\n"
          "                       the library (bg_tangent_normal_to_derivs): |m.z| is\n"
          "                       used (an inward normal is mirrored), raised to\n"
          "                       max(|m.x|,|m.y|)/128 when smaller, so both ratios\n"
          "                       stay within [-128, 128] along their own direction.\n"
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
    bgt_heightmap_opts opts = {.input = in_path, .output = out_path,
                               .gray = seed_gray ? BGT_GRAY_SEED : BGT_GRAY_REC709,
                               .strength = strength, .wrap = wrap, .y_down = y_down,
                               .to_derivative = to_deriv, .bits = bits};
    bgt_err err;
    return cli_report(CMD, bgt_heightmap_run(&opts, &err), &err);
}
