/* SPDX-License-Identifier: MIT */
/* `bumpgrad render`: ray-cast the paper's scenes (Mikkelsen 2010, section 6)
 * with a chosen normal-perturbation method, or several side by side with a
 * heat map of each one's angle error against the analytic surface gradient
 * (eq. 2 and 4, Listing 3), and the presets that reproduce Figures 1, 2, 3.
 * This file parses the options (one table, args.h) into a render_opts, calls
 * bgt_render_run (src/tools/render) and prints its statistics. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <strings.h>
#include <unistd.h>
#include "args.h"
#include "cli.h"
#include "json.h"
#include "render/render.h"

static const char *const CMD = "render";

/* Everything `bumpgrad render` parses: the tool's options and what only the
 * command does with the results (--json, --fail-above). */
typedef struct render_args {
    render_opts o;
    int json;
    float fail_above; /* < 0: off */
} render_args;

_Static_assert(sizeof(render_shape) == sizeof(int), "render_shape is stored as int");
_Static_assert(sizeof(render_tracer) == sizeof(int), "render_tracer is stored as int");
_Static_assert(sizeof(render_preset) == sizeof(int), "render_preset is stored as int");

static const char *const preset_choices[] = {"fig1", "fig2", "fig3", "fig4", NULL};
static const int preset_values[] = {PRESET_FIG1, PRESET_FIG2, PRESET_FIG3, PRESET_FIG4};
static const char *const shape_choices[] = {"sphere", "blob", "torus", NULL};
static const int shape_values[] = {RENDER_SPHERE, RENDER_BLOB, RENDER_TORUS};
static const char *const tracer_choices[] = {"auto", "bvh", "embree", NULL};
static const int tracer_values[] = {TRACER_AUTO, TRACER_BVH, TRACER_EMBREE};

static void render_defaults(void *p)
{
    render_args *a = p;
    memset(a, 0, sizeof *a);
    render_opts_default(&a->o);
    a->fail_above = -1.0f;
}

/* --preset is set before every other option (CLI_FIRST), so that any other
 * option given overrides the preset's setting. */
static int parse_preset(const char *cmd, const char *opt, char *text, void *field)
{
    render_opts *o = field;
    for (int k = 0; preset_choices[k]; k++)
        if (strcmp(text, preset_choices[k]) == 0) {
            o->preset = (render_preset)preset_values[k];
            render_apply_preset(o);
            return 0;
        }
    return cli_usage_error(cmd, "%s: expected fig1, fig2, fig3 or fig4, got \"%s\"", opt, text);
}

static int add_method(const char *cmd, render_opts *o, const char *name)
{
    render_method m;
    if (render_method_parse(name, &m) != 0)
        return cli_usage_error(cmd,
                               "unknown method \"%s\" (expected none, surfgrad, surfgrad-central, "
                               "listing1, listing1-coarse, additive, flat, surfgrad-footprint, "
                               "listing1-heightmap, listing1-heightmap-central, normalmap, "
                               "surfgrad-heightmap or detail)",
                               name);
    if (o->nmethods == RENDER_MAX_METHODS)
        return cli_usage_error(cmd, "--compare: at most %d methods", RENDER_MAX_METHODS);
    o->methods[o->nmethods++] = m;
    return 0;
}

static int parse_method(const char *cmd, const char *opt, char *text, void *field)
{
    (void)opt;
    render_opts *o = field;
    o->nmethods = 0, o->compare = 0;
    return add_method(cmd, o, text);
}

static int format_method(const void *field, char *buf, size_t len)
{
    const render_opts *o = field;
    if (o->compare || o->nmethods != 1)
        return 0;
    snprintf(buf, len, "%s", render_method_name(o->methods[0]));
    return 1;
}

static int parse_compare(const char *cmd, const char *opt, char *text, void *field)
{
    render_opts *o = field;
    if (!*text)
        return cli_usage_error(cmd, "%s: bad list \"%s\"", opt, text);
    o->nmethods = 0;
    for (char *s = text, *e; s; s = e) {
        e = strchr(s, ',');
        if (e)
            *e++ = '\0';
        if (add_method(cmd, o, s))
            return CLI_USAGE;
    }
    o->compare = 1;
    return 0;
}

static int parse_size(const char *cmd, const char *opt, char *text, void *field)
{
    render_opts *o = field;
    return cli_parse_size(cmd, opt, text, 2, 0, "pixels", &o->width, &o->height);
}

static int format_size(const void *field, char *buf, size_t len)
{
    const render_opts *o = field;
    snprintf(buf, len, "%dx%d", o->width, o->height);
    return 1;
}

static int parse_spp(const char *cmd, const char *opt, char *text, void *field)
{
    long l;
    if (cli_parse_int(cmd, opt, text, 1, 256, &l))
        return CLI_USAGE;
    int s = (int)lround(sqrt((double)l));
    if ((long)s * s != l)
        return cli_usage_error(cmd, "%s: must be a square (1, 4, 9, 16, ...), got %ld", opt, l);
    *(int *)field = s;
    return 0;
}

static int format_spp(const void *field, char *buf, size_t len)
{
    int s = *(const int *)field;
    snprintf(buf, len, "%d", s * s);
    return 1;
}

/* X,Y,Z into three floats, all finite. */
static int parse_xyz(const char *cmd, const char *opt, const char *text, float v[3])
{
    char *e1, *e2 = NULL, *e3 = NULL;
    double x = strtod(text, &e1), y = *e1 == ',' ? strtod(e1 + 1, &e2) : 0,
           z = (*e1 == ',' && *e2 == ',') ? strtod(e2 + 1, &e3) : 0;
    if (*e1 != ',' || *e2 != ',' || *e3 || !isfinite(x) || !isfinite(y) || !isfinite(z))
        return cli_usage_error(cmd, "%s: expected X,Y,Z, got \"%s\"", opt, text);
    v[0] = (float)x, v[1] = (float)y, v[2] = (float)z;
    return 0;
}

static int parse_light(const char *cmd, const char *opt, char *text, void *field)
{
    return parse_xyz(cmd, opt, text, field) ? CLI_USAGE : 0;
}

static int format_light(const void *field, char *buf, size_t len)
{
    const float *v = field;
    snprintf(buf, len, "%g,%g,%g", (double)v[0], (double)v[1], (double)v[2]);
    return 1;
}

static int parse_view(const char *cmd, const char *opt, char *text, void *field)
{
    render_opts *o = field;
    float v[3] = {0, 0, 0};
    if (parse_xyz(cmd, opt, text, v))
        return CLI_USAGE;
    if (v[0] == 0 && v[1] == 0 && v[2] == 0)
        return cli_usage_error(cmd, "%s: must not be 0,0,0", opt);
    memcpy(o->view, v, sizeof v);
    o->view_set = 1;
    return 0;
}

static int parse_zoom(const char *cmd, const char *opt, char *text, void *field)
{
    render_opts *o = field;
    float z;
    if (cli_parse_float(cmd, opt, text, &z))
        return CLI_USAGE;
    if (!(z > 0))
        return cli_usage_error(cmd, "%s: must be > 0, got \"%s\"", opt, text);
    o->zoom = z;
    o->zoom_set = 1;
    return 0;
}

static int format_zoom(const void *field, char *buf, size_t len)
{
    snprintf(buf, len, "%g", (double)((const render_opts *)field)->zoom);
    return 1;
}

#define A(m) offsetof(render_args, m)
#define O(m) offsetof(render_args, o.m)
static const cli_opt render_opts_table[] = {
    {.name = "output", .short_name = 'o', .kind = CLI_KIND_STRING, .offset = O(output),
     .metavar = "FILE", .help = "the image (required): .png (8-bit sRGB) or .exr (32-bit float, "
                                "linear); also .tif/.hdr (float, linear), .jpg/.ppm/.bmp/.tga "
                                "(8-bit sRGB); - for standard output (--format, the report then on stderr)",
     .flags = CLI_FILE | CLI_NO_DEFAULT, .complete_ext = "png|exr|tif|hdr|jpg|ppm|bmp|tga"},
    {.name = "format", .kind = CLI_KIND_STRING, .offset = O(format), .metavar = "EXT",
     .help = "the format of -o - (standard output): png (the default), exr, tif, hdr, jpg, "
             "ppm, bmp or tga; with a file output the extension decides, and a --format that "
             "disagrees with it is an error",
     .flags = CLI_NO_DEFAULT},
    {.name = "method", .kind = CLI_KIND_CUSTOM, .offset = A(o), .metavar = "M",
     .help = "perturbation method (see above)", .parse = parse_method, .format = format_method},
    {.name = "compare", .kind = CLI_KIND_CUSTOM, .offset = A(o), .metavar = "M1,M2,..",
     .help = "side-by-side panel of up to 8 methods with heat maps of the angle error against "
             "analytic surfgrad",
     .parse = parse_compare},
    {.name = "preset", .kind = CLI_KIND_CUSTOM, .offset = A(o), .metavar = "P",
     .help = "fig1, fig2, fig3 or fig4: the paper's figures (any other option given overrides "
             "the preset's setting); fig4 uses assimp-testmodels' OBJ/spider.obj unless --mesh "
             "is given",
     .flags = CLI_FIRST, .parse = parse_preset, .choices = preset_choices},
    {.name = "scene", .kind = CLI_KIND_CHOICE, .offset = O(shape), .metavar = "S",
     .help = "sphere, blob or torus (isosurfaces)", .choices = shape_choices,
     .choice_values = shape_values},
    {.name = "grid", .kind = CLI_KIND_INT, .offset = O(grid), .metavar = "N",
     .help = "marching-tetrahedra cells per axis, 4..400", .lo = 4, .hi = 400},
    {.name = "size", .kind = CLI_KIND_CUSTOM, .offset = A(o), .metavar = "WxH",
     .help = "image size in pixels (per method)", .parse = parse_size, .format = format_size},
    {.name = "spp", .kind = CLI_KIND_CUSTOM, .offset = O(ss), .metavar = "N",
     .help = "samples per pixel, a square 1, 4, 9, .. 256; a regular s x s grid, i.e. s times "
             "the pixel density",
     .parse = parse_spp, .format = format_spp},
    {.name = "distance", .kind = CLI_KIND_FLOAT, .offset = O(distance), .metavar = "D",
     .help = "camera distance from the centre, > 1.5 (outside the object)", .flags = CLI_GT_LO,
     .lo = 1.5},
    {.name = "zoom", .kind = CLI_KIND_CUSTOM, .offset = A(o), .metavar = "Z",
     .help = "focal-length factor, > 0 (2 = twice as close-up; a --mesh is framed automatically "
             "unless --zoom is given)",
     .parse = parse_zoom, .format = format_zoom},
    {.name = "light", .kind = CLI_KIND_CUSTOM, .offset = O(light), .metavar = "X,Y,Z",
     .help = "point-light position (camera on +z)", .parse = parse_light, .format = format_light},
    {.name = "view", .kind = CLI_KIND_CUSTOM, .offset = A(o), .metavar = "X,Y,Z",
     .help = "camera direction from the centre (default 0,0.28,1)", .parse = parse_view},
    {.name = "closeup", .kind = CLI_KIND_INT, .offset = O(closeup), .metavar = "K",
     .help = "add a row with a K-times magnified crop (Figure 3c/d), 0 = none", .lo = 0, .hi = 16,
     .flags = CLI_ZERO_NONE},
    {.name = "heat-max", .kind = CLI_KIND_FLOAT, .offset = O(heat_max), .metavar = "DEG",
     .help = "angle error shown at the top of the heat map, > 0", .flags = CLI_GT_LO, .lo = 0},
    {.name = "sweep", .kind = CLI_KIND_FLAG, .offset = O(sweep),
     .help = "print the error against surfgrad at 1/4..4x pixel density"},
    CLI_OPT_INCLUDE(O(threads), cli_threads_opts, NULL),
    {.name = "mesh", .kind = CLI_KIND_STRING, .offset = O(mesh_path), .metavar = "FILE",
     .help = "render a mesh file (any format assimp reads) instead of --scene; centred and "
             "scaled into the unit sphere",
     .flags = CLI_FILE},
    {.name = "height-map", .kind = CLI_KIND_STRING, .offset = O(height_map), .metavar = "IMG",
     .help = "height texture (gray level); default: the OBJ material's bump map, else the gray "
             "of its albedo (map_Kd)",
     .flags = CLI_FILE},
    {.name = "normal-map", .kind = CLI_KIND_STRING, .offset = O(normal_map), .metavar = "IMG",
     .help = "tangent-space normal map (OpenGL +y); default: the material's, else baked from "
             "the height texture. IMG with <UDIM> (here and in --height-map, --albedo): the "
             "tile set `bumpgrad mesh` writes (n.1001.png, n.1002.png, ...)",
     .flags = CLI_FILE},
    {.name = "albedo", .kind = CLI_KIND_STRING, .offset = O(albedo_map), .metavar = "IMG",
     .help = "albedo texture; default: the material's map_Kd", .flags = CLI_FILE},
    {.name = "no-albedo", .kind = CLI_KIND_FLAG, .offset = O(no_albedo),
     .help = "shade with the plain grey albedo"},
    {.name = "tex-amplitude", .kind = CLI_KIND_FLOAT, .offset = O(tex_amplitude), .metavar = "A",
     .help = "height of texel value 1, in bounding radii, > 0", .flags = CLI_GT_LO, .lo = 0},
    {.name = "st-scale", .kind = CLI_KIND_FLOAT, .offset = O(st_scale), .metavar = "S",
     .help = "texture coordinates times S, > 0 (< 1 magnifies)", .flags = CLI_GT_LO, .lo = 0},
    {.name = "tracer", .kind = CLI_KIND_CHOICE, .offset = O(tracer), .metavar = "T",
     .help = "auto (embree for --mesh, bvh for the built-in scenes), bvh or embree",
     .choices = tracer_choices, .choice_values = tracer_values},
    {.name = "json", .kind = CLI_KIND_FLAG, .offset = A(json),
     .help = "print the statistics as one JSON object instead of lines"},
    {.name = "fail-above", .kind = CLI_KIND_FLOAT, .offset = A(fail_above), .metavar = "DEG",
     .help = "exit 3 when a method's mean angle to surfgrad exceeds DEG (idiff -fail style, for "
             "CI; the image is still written)",
     .flags = CLI_GE_LO | CLI_NO_DEFAULT, .lo = 0},
    CLI_OPT_INCLUDE(O(h), cli_height_opts, cli_height_heading),
    CLI_OPT_END,
};
#undef A
#undef O

CLI_SPEC(render,
    .summary = "ray-cast the paper's scenes with a bump method; --compare, --preset fig1..4",
    .usage = "[options] --output FILE.png|FILE.exr\n"
             "--preset fig1|fig2|fig3|fig4 --output FILE.png\n"
             "--mesh FILE [--compare M1,M2,..] --output FILE.png",
    .about =
        "Ray-casts a sphere or a triangulated isosurface with a solid height field\n"
        "h(p) = A * F(f * p) and one point light (diffuse + Blinn-Phong), perturbing\n"
        "the normal with one of the methods of Mikkelsen (2010):\n"
        "  none              the unperturbed, interpolated normal\n"
        "  surfgrad          normalize(n - grad_S h), analytic gradient (eq. 4, Listing 3)\n"
        "  surfgrad-central  the same with a central-difference gradient (--step)\n"
        "  listing1          Listing 1: ddx_fine/ddy_fine of position and height on\n"
        "                    2x2 pixel quads, as a GPU computes them\n"
        "  listing1-coarse   Listing 1 with one derivative per quad (ddx_coarse)\n"
        "  additive          Perlin's normalize(n - grad h) (Figure 2a)\n"
        "  flat              cross(tau_s, tau_t) of the displaced position (Figure 1a)\n"
        "  surfgrad-footprint  surfgrad without the octaves finer than each sample's\n"
        "                    footprint (from its ray differential); the last kept octave\n"
        "                    fades out smoothly (bg_perturb_height_footprint_batch)\n"
        "With --mesh FILE (a mesh with UVs and a height texture):\n"
        "  listing1-heightmap  Listing 1 fed by Listing 2's forward taps of the height\n"
        "                    texture (ddx/ddy of position and UV on 2x2 quads)\n"
        "  listing1-heightmap-central  the same with Listing 2's central taps\n"
        "  normalmap         tangent-space normal map with interpolated per-vertex\n"
        "                    tangents (from the UVs; --normal-map, or baked from the height)\n"
        "  surfgrad-heightmap  eq. 3 on the UV chart with bicubic texture derivatives:\n"
        "                    the reference of a textured --compare\n"
        "  detail            the Listing 1/2 height plus the solid --function height\n"
        "                    (footprint-aware octaves from ray differentials), blended\n"
        "                    with the surface-gradient resolve\n",
    .opts = render_opts_table,
    .more = "Prints one line per method: stats method=M mean_deg p99_deg max_deg (angle\n"
            "to analytic surfgrad, over the samples that hit) and inward (fraction of\n"
            "samples whose perturbed normal has dot(n', n) <= 0). The reference, surfgrad\n"
            "and additive use the analytic gradient and surfgrad-central central\n"
            "differences with --step, whatever --gradient says. The defaults above are\n"
            "those without a preset.\n"
            "\n"
            "Exit status: 0 success, 1 I/O failure, 2 bad input or usage, 3 --fail-above\n"
            "exceeded.\n"
            "\n"
            "Examples:\n"
            "  bumpgrad render --preset fig2 --output fig2.png\n"
            "  bumpgrad render --compare surfgrad,listing1,additive --size 256x256 -o cmp.png\n",
);


static void print_json(const render_opts *o, const render_result *r, double seconds)
{
    cli_json j;
    cli_json_begin(&j, stdout);
    cli_json_common(&j, CMD, seconds);
    cli_json_str(&j, "output", o->output);
    cli_json_int(&j, "width", r->out_width);
    cli_json_int(&j, "height", r->out_height);
    cli_json_int(&j, "triangles", (long long)r->triangles);
    cli_json_object(&j, "methods");
    for (int m = 0; m < r->nmethods; m++) {
        cli_json_object(&j, render_method_name(r->methods[m]));
        cli_json_num(&j, "mean_deg", r->stats[m].mean_deg);
        cli_json_num(&j, "p99_deg", r->stats[m].p99_deg);
        cli_json_num(&j, "max_deg", r->stats[m].max_deg);
        cli_json_num(&j, "inward_fraction", r->stats[m].inward_fraction);
        cli_json_int(&j, "hits", (long long)r->stats[m].hits);
        cli_json_close(&j);
    }
    cli_json_close(&j);
    if (r->grid) {
        cli_json_int(&j, "grid_points", (long long)r->grid_points);
        cli_json_int(&j, "in_grid", (long long)r->grid_in_box);
        cli_json_int(&j, "grid_zero", (long long)r->grid_zero);
        cli_json_nums(&j, "grid_active_box", r->grid_box, 6);
    }
    cli_json_object(&j, "parameters");
    cli_json_str(&j, "scene", o->mesh_path ? "mesh" : render_shape_name(o->shape));
    cli_json_str(&j, "mesh", o->mesh_path);
    cli_json_int(&j, "spp", o->ss * o->ss);
    cli_json_num(&j, "distance", o->distance);
    cli_json_num(&j, "zoom", o->zoom);
    cli_json_nums(&j, "light", (const double[3]){o->light[0], o->light[1], o->light[2]}, 3);
    cli_json_int(&j, "closeup", o->closeup);
    cli_json_height(&j, "height", &o->h);
    cli_json_close(&j);
    if (r->nsweep) {
        cli_json_object(&j, "sweep");
        for (int k = 0; k < r->nsweep; k++) {
            char key[96];
            snprintf(key, sizeof key, "%s@%g", render_method_name(r->sweep[k].method),
                     r->sweep[k].density);
            cli_json_object(&j, key);
            cli_json_num(&j, "mean_deg", r->sweep[k].st.mean_deg);
            cli_json_num(&j, "p99_deg", r->sweep[k].st.p99_deg);
            cli_json_int(&j, "spp", r->sweep[k].spp);
            cli_json_close(&j);
        }
        cli_json_close(&j);
    }
    cli_json_end(&j);
}


/* The report: a header line, the statistics of every method, the file
 * written, the density sweep, and what a --height-grid reached. */
static void print_text(FILE *fp, const render_opts *o, const render_result *r)
{
    const bg_height *h = &o->h.h;
    if (o->mesh_path)
        fprintf(fp, "render mesh=%s triangles=%zu", o->mesh_path, r->triangles);
    else
        fprintf(fp, "render scene=%s", render_shape_name(o->shape));
    if (!o->mesh_path && o->shape != RENDER_SPHERE)
        fprintf(fp, " grid=%d triangles=%zu", o->grid, r->triangles);
    fprintf(fp, " size=%dx%d spp=%d", o->width, o->height, o->ss * o->ss);
    if (o->h.grid_path)
        fprintf(fp, " height-grid=%s%s%s\n", o->h.grid_path, o->h.grid_name ? ":" : "",
                o->h.grid_name ? o->h.grid_name : "");
    else
        fprintf(fp, " function=%s octaves=%d frequency=%g amplitude=%g\n",
                cli_function_name(h->fractal.function), h->fractal.octaves, (double)h->frequency,
                (double)h->amplitude);
    if (o->mesh_path || o->tracer != TRACER_AUTO)
        fprintf(fp, "timing tracer=%s load_s=%.3f build_s=%.4f render_s=%.3f%s%s\n", r->tracer,
                r->load_seconds, r->build_seconds, r->render_seconds, r->textures[0] ? " textures:" : "",
                r->textures);
    for (int m = 0; m < r->nmethods; m++)
        fprintf(fp, "stats %s%.*s%smethod=%s mean_deg=%.4f p99_deg=%.4f max_deg=%.4f inward=%.6f hits=%zu\n",
                r->labels[m] ? "panel=" : "", r->labels[m] ? 1 : 0, &"abcdef"[m < 6 ? m : 0],
                r->labels[m] ? " " : "", render_method_name(r->methods[m]), r->stats[m].mean_deg, r->stats[m].p99_deg,
                r->stats[m].max_deg, r->stats[m].inward_fraction, r->stats[m].hits);
    fprintf(fp, "wrote %s %dx%d\n", o->output, r->out_width, r->out_height);
    for (int k = 0; k < r->nsweep; k++) {
        const render_sweep_row *w = &r->sweep[k];
        fprintf(fp, "sweep method=%s density=%g size=%dx%d spp=%d mean_deg=%.4f p99_deg=%.4f "
                "max_deg=%.4f inward=%.6f hits=%zu\n",
                render_method_name(w->method), w->density, w->width, w->height, w->spp,
                w->st.mean_deg, w->st.p99_deg, w->st.max_deg, w->st.inward_fraction, w->st.hits);
    }
    if (r->grid) {
        const double *b = r->grid_box;
        fprintf(fp, "grid points=%zu in_active_box=%zu zero_height=%zu active_box=%g,%g,%g,%g,%g,%g\n",
                r->grid_points, r->grid_in_box, r->grid_zero, b[0], b[1], b[2], b[3], b[4], b[5]);
    }
}

/* On stderr, text or JSON: a --height-grid that bumped nothing. */
static void warn_grid(const render_opts *o, const render_result *r)
{
    const double *b = r->grid_box;
    if (r->grid && r->grid_points > 0 && r->grid_zero == r->grid_points)
        cli_warn(CMD, "the height of %s is 0 at all %zu hit points (they lie outside its active "
                      "voxels, centres in [%g,%g,%g]..[%g,%g,%g]): nothing is bumped",
                 o->h.grid_path, r->grid_points, b[0], b[1], b[2], b[3], b[4], b[5]);
}

static int run_render(void *args, const char *const *pos, int npos)
{
    (void)pos, (void)npos;
    const render_args *a = args;
    render_opts o = a->o;
    if (!o.output)
        return cli_usage_error(CMD, "--output FILE is required (.png or .exr)");
    const int to_stdout = strcmp(o.output, "-") == 0;
    if (a->json && to_stdout)
        return cli_usage_error(CMD, "--json writes to standard output: give --output a file");
    /* the image owns standard output: the report goes to stderr */
    FILE *fp = to_stdout ? stderr : stdout;
    bgt_err err;
    cli_progress prog;
    bgt_progress sink = cli_progress_sink(&prog);
    o.progress = &sink;
    render_result r;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    bg_status s = bgt_render_run(&o, &r, &err);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (s != BG_OK && r.out_width == 0)
        return cli_report(CMD, s, &err);
    if (a->json)
        print_json(&o, &r, (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
    else
        print_text(fp, &o, &r);
    warn_grid(&o, &r);
    /* A sweep that failed after the image was written: the image stands, the
     * run still fails. */
    if (s != BG_OK)
        return cli_report(CMD, s, &err);
    if (a->fail_above >= 0)
        for (int m = 0; m < r.nmethods; m++)
            if (r.stats[m].mean_deg > a->fail_above) {
                fflush(stdout);
                fprintf(stderr, "bumpgrad render: FAIL: %s mean angle %.4f deg > --fail-above %g\n",
                        render_method_name(r.methods[m]), r.stats[m].mean_deg,
                        (double)a->fail_above);
                return 3;
            }
    return CLI_OK;
}
