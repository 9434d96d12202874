/* SPDX-License-Identifier: MIT */
/* `bumpgrad heightmap`: an image read as a height field -> a tangent-space
 * normal map (the method of the article "Bump Map Generation": a normal map
 * from a diffuse texture), or
 * with --to-derivative a tangent-space normal map -> a derivative map. This
 * file parses the options and runs the conversion (bgt_heightmap_run,
 * src/tools/bake/heightmap.c). */
#include <math.h>
#include <string.h>
#include "args.h"
#include "bake/heightmap.h"
#include "cli.h"
#include "json.h"

#define CMD "heightmap"

typedef struct heightmap_args {
    int gray, wrap, y_down, to_derivative, bits, json;
    float strength;
    const char *format, *input_format;
} heightmap_args;

_Static_assert(sizeof(bgt_gray) == sizeof(int), "bgt_gray is stored as int");

static void heightmap_defaults(void *p)
{
    heightmap_args *a = p;
    memset(a, 0, sizeof *a);
    a->gray = BGT_GRAY_SEED;
    a->strength = 1.0f;
}

static const char *const gray_choices[] = {"diffuse", "rec709", NULL};
static const int gray_values[] = {BGT_GRAY_SEED, BGT_GRAY_REC709};
static const char *const edge_choices[] = {"clamp", "wrap", NULL};
static const char *const bits_choices[] = {"8", "16", "float", NULL};
static const int bits_values[] = {8, 16, 32};

#define A(m) offsetof(heightmap_args, m)
static const cli_opt heightmap_opts[] = {
    {.name = "gray", .kind = CLI_KIND_CHOICE, .offset = A(gray), .metavar = "diffuse|rec709",
     .help = "gray level of a colour input from its stored values (no decoding of sRGB): diffuse "
             "= 0.33 R + 0.66 G + 0.11 B (the weights of \"Bump Map Generation\"; they sum "
             "to 1.1, so H may exceed 1), rec709 = "
             "0.2126 R + 0.7152 G + 0.0722 B. One- and two-channel inputs use their first "
             "channel as H.",
     .choices = gray_choices, .choice_values = gray_values},
    {.name = "strength", .kind = CLI_KIND_FLOAT, .offset = A(strength), .metavar = "S",
     .help = "slope factor S (negative inverts bumps)"},
    {.name = "edge", .kind = CLI_KIND_CHOICE, .offset = A(wrap), .metavar = "clamp|wrap",
     .help = "neighbours beyond the border: repeat the edge pixel or wrap around (tileable "
             "textures)",
     .choices = edge_choices},
    {.name = "bits", .kind = CLI_KIND_CHOICE, .offset = A(bits), .metavar = "8|16|float",
     .help = "storage of OUT (default 8, float with --to-derivative; float needs .exr or .tif)",
     .choices = bits_choices, .choice_values = bits_values},
    {.name = "format", .kind = CLI_KIND_STRING, .offset = A(format), .metavar = "FMT",
     .help = "the format of OUT - (standard output): png (the default), exr, tif, hdr, jpg, "
             "ppm, tga, bmp, ... (any OpenImageIO writes to memory); with a file OUT the "
             "extension decides, and a --format that disagrees with it is an error",
     .flags = CLI_NO_DEFAULT},
    {.name = "input-format", .kind = CLI_KIND_STRING, .offset = A(input_format),
     .metavar = "FMT",
     .help = "read IN as this format (png, tga, exr, ...; any OpenImageIO reads): for IN - "
             "(standard input) whose content no reader recognizes, e.g. TGA; default: by the "
             "content (and a file's extension)",
     .flags = CLI_NO_DEFAULT},
    {.name = "y-down", .kind = CLI_KIND_FLAG, .offset = A(y_down),
     .help = "green = +y down (DirectX convention)"},
    {.name = "to-derivative", .kind = CLI_KIND_FLAG, .offset = A(to_derivative),
     .help = "IN is a tangent-space normal map stored as 0.5*m+0.5 (in any bit depth); OUT gets "
             "the derivative map R = dh/du = -m.x/m.z, G = dh/dv = -m.y/m.z as float (.exr or "
             ".tif, --bits float, the default here). As in the library "
             "(bg_tangent_normal_to_derivs): |m.z| is used (an inward normal is mirrored), "
             "raised to max(|m.x|,|m.y|)/128 when smaller, so both ratios stay within [-128, "
             "128] along their own direction."},
    {.name = "json", .kind = CLI_KIND_FLAG, .offset = A(json),
     .help = "print one JSON object on standard output: time, ISA and every parameter"},
    CLI_OPT_END,
};
#undef A

CLI_SPEC(heightmap,
    .summary = "image -> tangent-space normal map (central differences); normal map -> derivative map",
    .usage = "IN OUT [options]\nIN OUT --to-derivative [--bits float]",
    .about = "Turn any image OpenImageIO reads into a tangent-space normal map, treating\n"
             "its gray level as a height H (the method of the article \"Bump Map Generation\"):\n"
             "  a = H[x+1,y] - H[x-1,y],  b = H[x,y-1] - H[x,y+1]   (y-1 is the row above)\n"
             "  n = normalize(-S*a, -S*b, 1)\n"
             "The differences are NOT divided by 2, as in that article: they span two pixels,\n"
             "so --strength 0.5 gives the per-pixel slope. +x is right, +y is up (the\n"
             "OpenGL / \"Y+\" convention; --y-down flips green for DirectX), +z points\n"
             "out of the surface. Stored as 0.5*n + 0.5 in R, G, B (no sRGB curve).\n",
    .opts = heightmap_opts,
    .more = "A NaN or infinite sample in IN (float images), or a gray level or unpacked\n"
            "normal beyond float range, is an error naming the pixel (exit status 2).\n"
            "\n"
            "OUT is written to a temporary file next to it and renamed on success: a\n"
            "failure never leaves a partial file or replaces an old one. IN and OUT may\n"
            "be the same file. IN \"-\" reads standard input (any format OpenImageIO\n"
            "reads from memory, found by its content, or named by --input-format; a\n"
            "content no reader recognizes is an error asking for it); OUT \"-\" writes\n"
            "to standard output in the --format given, PNG without one (8 or 16 bits:\n"
            "--bits float needs --format exr or tif).\n"
            "\n"
            "Exit status: 0 success, 1 the output cannot be written (or out of memory),\n"
            "2 bad usage or an input that is missing, unreadable or not an image.\n"
            "\n"
            "Examples:\n"
            "  bumpgrad heightmap diffuse.png normal.png --strength 2 --edge wrap\n"
            "  bumpgrad heightmap normal.png deriv.exr --to-derivative\n"
            "  bumpgrad heightmap - - --input-format tga --format exr --bits float \\\n"
            "      < height.tga > normal.exr\n",
    .max_positional = 2,
);

/* The image is the output: the text is one line with -v, nothing else. */
static void print_text(const char *in, const char *out, double dt)
{
    cli_info(CMD, "%s -> %s in %.3f s", in, out, dt);
}

/* One JSON object of the run and its parameters (--json). */
static void print_json(const heightmap_args *a, const char *in, const char *out, double dt)
{
    cli_json j;
    cli_json_begin(&j, stdout);
    cli_json_common(&j, CMD, dt);
    cli_json_object(&j, "parameters");
    cli_json_str(&j, "input", in);
    cli_json_str(&j, "output", out);
    cli_json_str(&j, "gray", a->gray == BGT_GRAY_REC709 ? "rec709" : "diffuse");
    cli_json_float(&j, "strength", a->strength);
    cli_json_str(&j, "edge", a->wrap ? "wrap" : "clamp");
    cli_json_bool(&j, "y_down", a->y_down);
    cli_json_bool(&j, "to_derivative", a->to_derivative);
    if (a->format)
        cli_json_str(&j, "format", a->format);
    if (a->input_format)
        cli_json_str(&j, "input_format", a->input_format);
    if (a->bits)
        cli_json_int(&j, "bits", a->bits);
    else
        cli_json_str(&j, "bits", "default");
    cli_json_close(&j);
    cli_json_end(&j);
}

static int run_heightmap(void *args, const char *const *pos, int npos)
{
    heightmap_args a = *(heightmap_args *)args;
    if (npos != 2)
        return cli_usage_error(CMD, "expected IN OUT (see bumpgrad heightmap --help)");
    if (a.json && strcmp(pos[1], "-") == 0)
        return cli_usage_error(CMD, "--json writes to standard output: give OUT a file name");
    if (!isfinite(a.strength))
        return cli_usage_error(CMD, "--strength: must be finite");
    bgt_heightmap_opts opts = {.input = pos[0], .output = pos[1], .gray = (bgt_gray)a.gray,
                               .strength = a.strength, .wrap = a.wrap, .y_down = a.y_down,
                               .to_derivative = a.to_derivative, .bits = a.bits,
                               .format = a.format, .input_format = a.input_format};
    bgt_err err;
    double t0 = cli_now();
    bg_status st = bgt_heightmap_run(&opts, &err);
    double dt = cli_now() - t0;
    if (st != BG_OK)
        return cli_report(CMD, st, &err);
    if (a.json)
        print_json(&a, pos[0], pos[1], dt);
    else
        print_text(pos[0], pos[1], dt);
    return CLI_OK;
}
