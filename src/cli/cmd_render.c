/* SPDX-License-Identifier: MIT */
/* `bumpgrad render`: ray-cast the paper's scenes (Mikkelsen 2010, section 6)
 * with a chosen normal-perturbation method, or several side by side with a
 * heat map of each one's angle error against the analytic surface gradient
 * (eq. 2 and 4, Listing 3), and the presets that reproduce Figures 1, 2, 3.
 * This file parses the options into a render_opts, calls render_image
 * (src/tools/render) and prints its statistics. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <strings.h>
#include <unistd.h>
#include "cli.h"
#include "json.h"
#include "render/render.h"

static const char *const CMD = "render";

/* What only the command does with the results: --json, --fail-above. */
static struct {
    int json;
    float fail_above; /* < 0: off */
} render_cli = {0, -1.0f};

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


static void render_help(FILE *fp)
{
    fputs("Usage: bumpgrad render [options] --output FILE.png|FILE.exr\n"
          "       bumpgrad render --preset fig1|fig2|fig3|fig4 --output FILE.png\n"
          "       bumpgrad render --mesh FILE [--compare M1,M2,..] --output FILE.png\n"
          "\n"
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
          "                    fades out smoothly (bg_perturb_height_footprint_batch)\n",
          fp);
    fputs("With --mesh FILE (a mesh with UVs and a height texture):\n"
          "  listing1-heightmap  Listing 1 fed by Listing 2's forward taps of the height\n"
          "                    texture (ddx/ddy of position and UV on 2x2 quads)\n"
          "  listing1-heightmap-central  the same with Listing 2's central taps\n"
          "  normalmap         tangent-space normal map with interpolated per-vertex\n"
          "                    tangents (from the UVs; --normal-map, or baked from the height)\n"
          "  surfgrad-heightmap  eq. 3 on the UV chart with bicubic texture derivatives:\n"
          "                    the reference of a textured --compare\n"
          "  detail            the Listing 1/2 height plus the solid --function height\n"
          "                    (footprint-aware octaves from ray differentials), blended\n"
          "                    with the surface-gradient resolve\n"
          "\n"
          "Options:\n"
          "  --method M          perturbation method (default surfgrad)\n"
          "  --compare M1,M2,..  side-by-side panel of up to 8 methods with heat maps of\n"
          "                      the angle error against analytic surfgrad\n"
          "  --scene S           sphere (default), blob or torus (isosurfaces)\n"
          "  --grid N            marching-tetrahedra cells per axis, 4..400 (default 48)\n"
          "  --size WxH          image size in pixels (default 384x384; per method)\n"
          "  --spp N             samples per pixel, a square 1, 4, 9, .. 256 (default 1);\n"
          "                      a regular s x s grid, i.e. s times the pixel density\n"
          "  --distance D        camera distance from the centre (default 4)\n"
          "  --zoom Z            focal-length factor (default 1; 2 = twice as close-up;\n"
          "                      a --mesh is framed automatically unless --zoom is given)\n",
          fp);
    fputs(
          "  --light X,Y,Z       point-light position (default -5,4,3; camera on +z)\n"
          "  --closeup K         add a row with a K-times magnified crop (Figure 3c/d)\n"
          "  --heat-max DEG      angle error shown at the top of the heat map (default 20)\n"
          "  --sweep             print the error against surfgrad at 1/4..4x pixel density\n"
          "  --threads N         worker threads (default: all cores)\n"
          "  --preset P          fig1, fig2, fig3 or fig4: the paper's figures (any other\n"
          "                      option given overrides the preset's setting); fig4 uses\n"
          "                      assimp-testmodels' OBJ/spider.obj unless --mesh is given\n"
          "  --mesh FILE         render a mesh file (any format assimp reads) instead of\n"
          "                      --scene; centred and scaled into the unit sphere\n"
          "  --height-map IMG    height texture (gray level); default: the OBJ material's\n"
          "                      bump map, else the gray of its albedo (map_Kd)\n"
          "  --normal-map IMG    tangent-space normal map (OpenGL +y); default: the\n"
          "                      material's, else baked from the height texture\n"
          "  --albedo IMG        albedo texture; default: the material's map_Kd\n"
          "  --no-albedo         shade with the plain grey albedo\n"
          "  --tex-amplitude A   height of texel value 1, in bounding radii (default 0.004)\n"
          "  --st-scale S        texture coordinates times S (< 1 magnifies; default 1)\n"
          "  --view X,Y,Z        camera direction from the centre (default 0,0.28,1)\n"
          "  --tracer T          auto (default: embree for --mesh, bvh for the built-in\n"
          "                      scenes), bvh or embree\n"
          "  --output FILE       .png (8-bit sRGB) or .exr (32-bit float, linear); also\n"
          "                      .tif/.hdr (float, linear), .jpg/.ppm/.bmp/.tga (8-bit sRGB)\n"
          "  --json              print the statistics as one JSON object instead of lines\n"
          "  --fail-above DEG    exit 3 when a method's mean angle to surfgrad exceeds DEG\n"
          "                      (idiff -fail style, for CI; the image is still written)\n"
          "\n"
          "Prints one line per method: stats method=M mean_deg p99_deg max_deg (angle\n"
          "to analytic surfgrad, over the samples that hit) and inward (fraction of\n"
          "samples whose perturbed normal has dot(n', n) <= 0). The reference, surfgrad\n"
          "and additive use the analytic gradient and surfgrad-central central\n"
          "differences with --step, whatever --gradient says. Without a preset the\n"
          "height defaults to --frequency 1 --amplitude 0.06 (6-octave turbulence).\n"
          "\n",
          fp);
    cli_height_help(fp);
}

static int add_method(render_opts *o, const char *name)
{
    render_method m;
    if (render_method_parse(name, &m) != 0)
        return cli_usage_error(CMD,
                               "unknown method \"%s\" (expected none, surfgrad, surfgrad-central, "
                               "listing1, listing1-coarse, additive, flat, surfgrad-footprint, "
                               "listing1-heightmap, listing1-heightmap-central, normalmap, "
                               "surfgrad-heightmap or detail)",
                               name);
    if (o->nmethods == RENDER_MAX_METHODS)
        return cli_usage_error(CMD, "--compare: at most %d methods", RENDER_MAX_METHODS);
    o->methods[o->nmethods++] = m;
    return 0;
}

static int parse_method_list(render_opts *o, const char *text)
{
    char buf[256];
    if (strlen(text) >= sizeof buf || !*text)
        return cli_usage_error(CMD, "--compare: bad list \"%s\"", text);
    strcpy(buf, text);
    o->nmethods = 0;
    for (char *s = buf, *e; s; s = e) {
        e = strchr(s, ',');
        if (e)
            *e++ = '\0';
        if (add_method(o, s))
            return CLI_USAGE;
    }
    return 0;
}

static int parse_size(const char *text, int *w, int *h)
{
    char *end;
    long a = strtol(text, &end, 10);
    if (end == text || (*end != 'x' && *end != 'X'))
        return cli_usage_error(CMD, "--size: expected WxH (e.g. 384x384), got \"%s\"", text);
    const char *s2 = end + 1;
    long b = strtol(s2, &end, 10);
    if (end == s2 || *end || a < 2 || b < 2 || a > 16384 || b > 16384)
        return cli_usage_error(CMD, "--size: expected WxH with 2..16384 each, got \"%s\"", text);
    *w = (int)a, *h = (int)b;
    return 0;
}

static int parse_args(int argc, char **argv, render_opts *o)
{
    /* The preset goes first so that any other option overrides it. */
    for (int i = 1; i < argc; i++)
        if (strcmp(argv[i], "--preset") == 0) {
            const char *v;
            int rc = cli_need_value(CMD, argc, argv, &i, &v);
            if (rc)
                return rc;
            if (strcmp(v, "fig1") == 0)
                o->preset = PRESET_FIG1;
            else if (strcmp(v, "fig2") == 0)
                o->preset = PRESET_FIG2;
            else if (strcmp(v, "fig3") == 0)
                o->preset = PRESET_FIG3;
            else if (strcmp(v, "fig4") == 0)
                o->preset = PRESET_FIG4;
            else
                return cli_usage_error(CMD, "--preset: expected fig1, fig2, fig3 or fig4, got \"%s\"", v);
        }
    render_apply_preset(o);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v;
        int rc = cli_height_option(CMD, &o->h, argc, argv, &i);
        if (rc == 1)
            continue;
        if (rc != 0)
            return rc;
        long l;
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            render_help(stdout);
            return -1;
        }
        if (strcmp(a, "--sweep") == 0) {
            o->sweep = 1;
            continue;
        }
        if (strcmp(a, "--json") == 0) {
            render_cli.json = 1;
            continue;
        }
        if (strcmp(a, "--no-albedo") == 0) {
            o->no_albedo = 1;
            continue;
        }
        static const char *const with_value[] = {
            "--preset", "--method", "--compare", "--scene", "--grid",  "--size",     "--spp",
            "--distance", "--zoom", "--closeup", "--heat-max", "--threads", "--output", "-o",
            "--light", "--mesh", "--height-map", "--normal-map", "--albedo", "--tex-amplitude",
            "--st-scale", "--view", "--tracer", "--fail-above"};
        int known = 0;
        for (size_t k = 0; k < sizeof with_value / sizeof with_value[0]; k++)
            known |= strcmp(a, with_value[k]) == 0;
        if (!known) {
            if (a[0] != '-')
                return cli_usage_error(CMD, "unexpected argument \"%s\"", a);
            return cli_usage_error(CMD, "unknown option \"%s\" (see bumpgrad render --help)", a);
        }
        if ((rc = cli_need_value(CMD, argc, argv, &i, &v)) != 0)
            return rc;
        if (strcmp(a, "--preset") == 0) {
            continue; /* applied above */
        } else if (strcmp(a, "--method") == 0) {
            o->nmethods = 0, o->compare = 0;
            if (add_method(o, v))
                return CLI_USAGE;
        } else if (strcmp(a, "--compare") == 0) {
            if (parse_method_list(o, v))
                return CLI_USAGE;
            o->compare = 1;
        } else if (strcmp(a, "--scene") == 0) {
            if (render_shape_parse(v, &o->shape) != 0)
                return cli_usage_error(CMD, "--scene: expected sphere, blob or torus, got \"%s\"", v);
        } else if (strcmp(a, "--grid") == 0) {
            if (cli_parse_int(CMD, a, v, 4, 400, &l))
                return CLI_USAGE;
            o->grid = (int)l;
        } else if (strcmp(a, "--size") == 0) {
            if (parse_size(v, &o->width, &o->height))
                return CLI_USAGE;
        } else if (strcmp(a, "--spp") == 0) {
            if (cli_parse_int(CMD, a, v, 1, 256, &l))
                return CLI_USAGE;
            int s = (int)lround(sqrt((double)l));
            if ((long)s * s != l)
                return cli_usage_error(CMD, "--spp: must be a square (1, 4, 9, 16, ...), got %ld", l);
            o->ss = s;
        } else if (strcmp(a, "--distance") == 0) {
            if (cli_parse_float(CMD, a, v, &o->distance))
                return CLI_USAGE;
            if (!(o->distance > 1.5f) || !isfinite(o->distance))
                return cli_usage_error(CMD, "--distance: must be > 1.5 (outside the object), got \"%s\"", v);
        } else if (strcmp(a, "--light") == 0 || strcmp(a, "--view") == 0) {
            char *e1, *e2 = NULL, *e3 = NULL;
            double x = strtod(v, &e1), y = *e1 == ',' ? strtod(e1 + 1, &e2) : 0,
                   z = (*e1 == ',' && *e2 == ',') ? strtod(e2 + 1, &e3) : 0;
            if (*e1 != ',' || *e2 != ',' || *e3 || !isfinite(x) || !isfinite(y) || !isfinite(z))
                return cli_usage_error(CMD, "%s: expected X,Y,Z, got \"%s\"", a, v);
            if (a[2] == 'v') {
                if (x == 0 && y == 0 && z == 0)
                    return cli_usage_error(CMD, "--view: must not be 0,0,0");
                o->view[0] = (float)x, o->view[1] = (float)y, o->view[2] = (float)z;
                o->view_set = 1;
            } else {
                o->light[0] = (float)x, o->light[1] = (float)y, o->light[2] = (float)z;
            }
        } else if (strcmp(a, "--mesh") == 0) {
            o->mesh_path = v;
        } else if (strcmp(a, "--height-map") == 0) {
            o->height_map = v;
        } else if (strcmp(a, "--normal-map") == 0) {
            o->normal_map = v;
        } else if (strcmp(a, "--albedo") == 0) {
            o->albedo_map = v;
        } else if (strcmp(a, "--tex-amplitude") == 0 || strcmp(a, "--st-scale") == 0) {
            float f;
            if (cli_parse_float(CMD, a, v, &f))
                return CLI_USAGE;
            if (!(f > 0) || !isfinite(f))
                return cli_usage_error(CMD, "%s: must be > 0, got \"%s\"", a, v);
            *(a[2] == 't' ? &o->tex_amplitude : &o->st_scale) = f;
        } else if (strcmp(a, "--tracer") == 0) {
            if (strcmp(v, "auto") == 0)
                o->tracer = TRACER_AUTO;
            else if (strcmp(v, "bvh") == 0)
                o->tracer = TRACER_BVH;
            else if (strcmp(v, "embree") == 0)
                o->tracer = TRACER_EMBREE;
            else
                return cli_usage_error(CMD, "--tracer: expected auto, bvh or embree, got \"%s\"", v);
        } else if (strcmp(a, "--zoom") == 0) {
            if (cli_parse_float(CMD, a, v, &o->zoom))
                return CLI_USAGE;
            if (!(o->zoom > 0) || !isfinite(o->zoom))
                return cli_usage_error(CMD, "--zoom: must be > 0, got \"%s\"", v);
            o->zoom_set = 1;
        } else if (strcmp(a, "--closeup") == 0) {
            if (cli_parse_int(CMD, a, v, 0, 16, &l))
                return CLI_USAGE;
            o->closeup = (int)l;
        } else if (strcmp(a, "--heat-max") == 0) {
            if (cli_parse_float(CMD, a, v, &o->heat_max))
                return CLI_USAGE;
            if (!(o->heat_max > 0) || !isfinite(o->heat_max))
                return cli_usage_error(CMD, "--heat-max: must be > 0, got \"%s\"", v);
        } else if (strcmp(a, "--threads") == 0) {
            if (cli_parse_int(CMD, a, v, 0, 1024, &l))
                return CLI_USAGE;
            o->threads = (int)l;
        } else if (strcmp(a, "--output") == 0 || strcmp(a, "-o") == 0) {
            o->output = v;
        } else if (strcmp(a, "--fail-above") == 0) {
            float deg;
            if (cli_parse_float(CMD, a, v, &deg))
                return CLI_USAGE;
            if (!(deg >= 0))
                return cli_usage_error(CMD, "--fail-above: must be >= 0, got \"%s\"", v);
            render_cli.fail_above = deg;
        } else {
            return cli_usage_error(CMD, "unknown option \"%s\" (see bumpgrad render --help)", a);
        }
    }
    if (!o->output)
        return cli_usage_error(CMD, "--output FILE is required (.png or .exr)");
    return 0;
}

int cmd_render(int argc, char **argv)
{
    render_opts o;
    render_opts_default(&o);
    int rc = parse_args(argc, argv, &o);
    if (rc == -1)
        return CLI_OK;
    if (rc)
        return rc;
    bgt_err err;
    bg_status s = bgt_height_open(&o.h, &err);
    if (s != BG_OK)
        return cli_report(CMD, s, &err);
    cli_progress prog;
    bgt_progress sink = cli_progress_sink(&prog);
    o.progress = &sink;
    render_result r;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    s = render_image(&o, &r, &err);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    bgt_height_close(&o.h);
    if (s != BG_OK && r.out_width == 0)
        return cli_report(CMD, s, &err);
    if (render_cli.json) {
        print_json(&o, &r, (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
        goto verdict;
    }
    const bg_height *h = &o.h.h;
    if (o.mesh_path)
        printf("render mesh=%s triangles=%zu", o.mesh_path, r.triangles);
    else
        printf("render scene=%s", render_shape_name(o.shape));
    if (!o.mesh_path && o.shape != RENDER_SPHERE)
        printf(" grid=%d triangles=%zu", o.grid, r.triangles);
    printf(" size=%dx%d spp=%d function=%s octaves=%d frequency=%g amplitude=%g\n", o.width,
           o.height, o.ss * o.ss, cli_function_name(h->fractal.function), h->fractal.octaves,
           (double)h->frequency, (double)h->amplitude);
    if (o.mesh_path || o.tracer != TRACER_AUTO)
        printf("timing tracer=%s load_s=%.3f build_s=%.4f render_s=%.3f%s%s\n", r.tracer,
               r.load_seconds, r.build_seconds, r.render_seconds, r.textures[0] ? " textures:" : "",
               r.textures);
    for (int m = 0; m < r.nmethods; m++)
        printf("stats %s%.*s%smethod=%s mean_deg=%.4f p99_deg=%.4f max_deg=%.4f inward=%.6f hits=%zu\n",
               r.labels[m] ? "panel=" : "", r.labels[m] ? 1 : 0, "abcdef" + (m < 6 ? m : 0),
               r.labels[m] ? " " : "", render_method_name(r.methods[m]), r.stats[m].mean_deg, r.stats[m].p99_deg,
               r.stats[m].max_deg, r.stats[m].inward_fraction, r.stats[m].hits);
    printf("wrote %s %dx%d\n", o.output, r.out_width, r.out_height);
    for (int k = 0; k < r.nsweep; k++) {
        const render_sweep_row *w = &r.sweep[k];
        printf("sweep method=%s density=%g size=%dx%d spp=%d mean_deg=%.4f p99_deg=%.4f "
               "max_deg=%.4f inward=%.6f hits=%zu\n",
               render_method_name(w->method), w->density, w->width, w->height, w->spp,
               w->st.mean_deg, w->st.p99_deg, w->st.max_deg, w->st.inward_fraction, w->st.hits);
    }
verdict:
    /* A sweep that failed after the image was written: the image stands, the
     * run still fails. */
    if (s != BG_OK)
        return cli_report(CMD, s, &err);
    if (render_cli.fail_above >= 0)
        for (int m = 0; m < r.nmethods; m++)
            if (r.stats[m].mean_deg > render_cli.fail_above) {
                fflush(stdout);
                fprintf(stderr, "bumpgrad render: FAIL: %s mean angle %.4f deg > --fail-above %g\n",
                        render_method_name(r.methods[m]), r.stats[m].mean_deg,
                        (double)render_cli.fail_above);
                return 3;
            }
    return CLI_OK;
}
