/* SPDX-License-Identifier: MIT */
/* `bumpgrad render`: ray-cast the paper's scenes (Mikkelsen 2010, section 6)
 * with a chosen normal-perturbation method, or several side by side with a
 * heat map of each one's angle error against the analytic surface gradient
 * (eq. 2 and 4, Listing 3), and the presets that reproduce Figures 1, 2, 3.
 * The renderer fills float RGB buffers; only the final step writes a file,
 * through bg_image_write (temporary file + rename: a failure leaves any old
 * output untouched). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>
#include "bumpgrad/image.h"
#include "cli.h"
#include "render.h"

static const char *const CMD = "render";

typedef enum render_preset { PRESET_NONE = 0, PRESET_FIG1, PRESET_FIG2, PRESET_FIG3 } render_preset;

typedef struct render_opts {
    render_shape shape;
    int grid;
    int width, height, ss;
    float distance, zoom, heat_max;
    float light[3];
    int threads;
    int nmethods, compare;
    render_method methods[RENDER_MAX_METHODS];
    int closeup; /* magnification of the close-up row, 0 = none */
    int sweep;   /* print the error against pixel density */
    const char *output;
    render_preset preset;
    cli_height h;
} render_opts;

static void render_help(FILE *fp)
{
    fputs("Usage: bumpgrad render [options] --output FILE.png|FILE.exr\n"
          "       bumpgrad render --preset fig1|fig2|fig3 --output FILE.png\n"
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
          "                    fades out smoothly (bg_perturb_height_footprint_batch)\n"
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
          "  --zoom Z            focal-length factor (default 1; 2 = twice as close-up)\n"
          "  --light X,Y,Z       point-light position (default -5,4,3; camera on +z)\n"
          "  --closeup K         add a row with a K-times magnified crop (Figure 3c/d)\n"
          "  --heat-max DEG      angle error shown at the top of the heat map (default 20)\n"
          "  --sweep             print the error against surfgrad at 1/4..4x pixel density\n"
          "  --threads N         worker threads (default: all cores)\n"
          "  --preset P          fig1, fig2 or fig3: the paper's figures (any other\n"
          "                      option given overrides the preset's setting)\n"
          "  --output FILE       .png (8-bit sRGB) or .exr (32-bit float, linear)\n"
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
                               "listing1, listing1-coarse, additive, flat or surfgrad-footprint)",
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

/* The presets set a scene and height; the numbers were chosen by looking at
 * the renders (docs/FIGURES.md) so that each shows what its figure shows. */
static void apply_preset(render_opts *o)
{
    bg_height *h = &o->h.h;
    switch (o->preset) {
    case PRESET_FIG1:
        /* Figure 1: a coarse isosurface so the facets of (a) are visible; the
         * height detail is 6-octave turbulence as in section 6. */
        o->shape = RENDER_BLOB;
        o->grid = 14;
        h->fractal = bg_fractal_default(BG_FUNC_TURBULENCE);
        h->frequency = 1.5f;
        h->amplitude = 0.03f;
        o->nmethods = 2, o->compare = 1;
        o->methods[0] = RENDER_FLAT, o->methods[1] = RENDER_LISTING1;
        break;
    case PRESET_FIG2:
        /* Figure 2: low-frequency noise, strong enough that n.grad h exceeds 1
         * where the slope faces away, the case where additive turns inward. */
        o->shape = RENDER_SPHERE;
        h->fractal = bg_fractal_default(BG_FUNC_NOISE);
        h->frequency = 1.5f;
        h->amplitude = 0.4f;
        o->heat_max = 60.0f;
        /* A frontal light, so that the inward normals of (a) show as black
         * where (b) is lit. */
        o->light[0] = -4.0f, o->light[1] = 5.0f, o->light[2] = 6.0f;
        o->nmethods = 2, o->compare = 1;
        o->methods[0] = RENDER_ADDITIVE, o->methods[1] = RENDER_SURFGRAD;
        break;
    case PRESET_FIG3:
        /* Figure 3: 6-octave turbulence on a sphere; the close-up row magnifies
         * a crop, where Listing 1's quad derivatives show (3c vs 3d). */
        o->shape = RENDER_SPHERE;
        h->fractal = bg_fractal_default(BG_FUNC_TURBULENCE);
        h->frequency = 0.5f;
        h->amplitude = 0.12f;
        o->nmethods = 2, o->compare = 1;
        o->methods[0] = RENDER_LISTING1, o->methods[1] = RENDER_SURFGRAD;
        o->closeup = 4;
        o->sweep = 1;
        break;
    case PRESET_NONE:
        break;
    }
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
            else
                return cli_usage_error(CMD, "--preset: expected fig1, fig2 or fig3, got \"%s\"", v);
        }
    apply_preset(o);
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
        static const char *const with_value[] = {
            "--preset", "--method", "--compare", "--scene", "--grid",  "--size",     "--spp",
            "--distance", "--zoom", "--closeup", "--heat-max", "--threads", "--output", "-o",
            "--light"};
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
        } else if (strcmp(a, "--light") == 0) {
            char *e1, *e2, *e3;
            double x = strtod(v, &e1), y = *e1 == ',' ? strtod(e1 + 1, &e2) : 0,
                   z = (*e1 == ',' && *e2 == ',') ? strtod(e2 + 1, &e3) : 0;
            if (*e1 != ',' || *e2 != ',' || *e3 || !isfinite(x) || !isfinite(y) || !isfinite(z))
                return cli_usage_error(CMD, "--light: expected X,Y,Z, got \"%s\"", v);
            o->light[0] = (float)x, o->light[1] = (float)y, o->light[2] = (float)z;
        } else if (strcmp(a, "--zoom") == 0) {
            if (cli_parse_float(CMD, a, v, &o->zoom))
                return CLI_USAGE;
            if (!(o->zoom > 0) || !isfinite(o->zoom))
                return cli_usage_error(CMD, "--zoom: must be > 0, got \"%s\"", v);
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
        } else {
            return cli_usage_error(CMD, "unknown option \"%s\" (see bumpgrad render --help)", a);
        }
    }
    if (!o->output)
        return cli_usage_error(CMD, "--output FILE is required (.png or .exr)");
    return 0;
}

static const char *extension(const char *path)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    return dot && (!slash || dot > slash) ? dot : "";
}

/* A writable folder is checked before rendering so that a long render does not
 * end in an I/O error; bg_image_write still reports any later failure. */
static int check_output(const char *path, bg_pixel_type *type, int *srgb)
{
    const char *ext = extension(path);
    if (strcasecmp(ext, ".png") == 0)
        *type = BG_PIXEL_U8, *srgb = 1;
    else if (strcasecmp(ext, ".exr") == 0)
        *type = BG_PIXEL_F32, *srgb = 0;
    else
        return cli_usage_error(CMD, "--output: \"%s\": expected a .png or .exr file name", path);
    char *dir = malloc(strlen(path) + 2);
    if (!dir)
        return cli_fail(CMD, "out of memory");
    strcpy(dir, path);
    char *slash = strrchr(dir, '/');
    if (!slash)
        strcpy(dir, ".");
    else if (slash == dir)
        dir[1] = '\0';
    else
        *slash = '\0';
    int ok = access(dir, W_OK | X_OK) == 0;
    if (!ok) {
        int rc = cli_fail(CMD, "cannot write \"%s\": folder \"%s\" is missing or not writable", path, dir);
        free(dir);
        return rc;
    }
    free(dir);
    return 0;
}

static void label(render_canvas *c, int x, int y, int size, const char *text, const float col[3])
{
    /* OpenImageIO's text renderer when a font is available, else our 5x7 font
     * (the panel layout is the same either way). */
    bg_image img = {c->w, c->h, 3, c->rgb};
    char err[256];
    if (getenv("BUMPGRAD_BITMAP_FONT") == NULL &&
        bg_image_draw_text(&img, x, y, text, col, size, err, sizeof err) == BG_OK)
        return;
    render_canvas_text(c, x, y + (size - 7 * (size / 8 > 0 ? size / 8 : 1)) / 2, text,
                       size / 8 > 0 ? size / 8 : 1, col);
}

/* The panel: one column per method; row 1 the renders, row 2 (optional) the
 * magnified crops, last row the heat maps of the error against surfgrad. */
static int compose_panel(const render_opts *o, const render_job *job, const render_stats *st,
                         render_canvas *c)
{
    static const float bgc[3] = {0.0f, 0.0f, 0.0f}, fg[3] = {0.85f, 0.85f, 0.85f};
    static const float inward_color[3] = {0.0f, 0.85f, 1.0f};
    const int W = job->width, H = job->height_px, n = job->nmethods;
    const int fsz = W >= 256 ? 16 : W >= 128 ? 10 : 8; /* label font height in pixels */
    const int pad = 4, lab = fsz + 6, rows = o->closeup ? 3 : 2;
    const int cw = W + pad, ch = lab + H + pad;
    const int bar = lab + 10;
    if (render_canvas_alloc(c, n * cw + pad, rows * ch + pad + bar, bgc))
        return CLI_FAIL;
    float *heat = malloc((size_t)W * H * 3 * sizeof(float));
    float *crop = NULL;
    int kw = 0, kh = 0, kx = 0, ky = 0, mag = o->closeup;
    if (o->closeup) {
        kw = W / o->closeup, kh = H / o->closeup;
        if (kw < 1)
            kw = 1;
        if (kh < 1)
            kh = 1;
        /* Tiny images: never magnify a crop past its cell. */
        if (kw * mag > W)
            mag = W / kw;
        if (kh * mag > H)
            mag = H / kh;
        /* Right of and below the centre: half-lit (the detail reads best away
         * from the highlight) and away from the silhouette. */
        kx = (int)(0.40 * W) - kw / 2, ky = (int)(0.56 * H) - kh / 2;
        crop = malloc((size_t)kw * kh * 3 * sizeof(float));
    }
    if (!heat || (o->closeup && !crop)) {
        free(heat);
        free(crop);
        render_canvas_free(c);
        return cli_fail(CMD, "out of memory");
    }
    char text[128];
    for (int m = 0; m < n; m++) {
        int x = pad + m * cw, y = pad;
        snprintf(text, sizeof text, "(%c) %s", 'a' + m, render_method_name(job->methods[m]));
        label(c, x, y, fsz, text, fg);
        render_canvas_blit(c, x, y + lab, job->rgb[m], W, H, 1);
        y += ch;
        if (o->closeup) {
            for (int j = 0; j < kh; j++)
                memcpy(crop + (size_t)j * kw * 3, job->rgb[m] + ((size_t)(ky + j) * W + kx) * 3,
                       (size_t)kw * 3 * sizeof(float));
            snprintf(text, sizeof text, "(%c) close-up x%d", 'a' + n + m, mag);
            label(c, x, y, fsz, text, fg);
            render_canvas_blit(c, x, y + lab, crop, kw, kh, mag);
            y += ch;
        }
        for (size_t i = 0; i < (size_t)W * H; i++) {
            float e = job->heat[m][i];
            if (e == e)
                render_heat_color(e, o->heat_max, heat + i * 3);
            else
                memcpy(heat + i * 3, bgc, sizeof bgc);
        }
        /* Pixels with an inward perturbed normal (dot(n', n) <= 0, the failure
         * of Figure 2a) in cyan, a colour the heat ramp never takes. */
        const int ss = job->ss;
        const size_t SW = (size_t)W * ss;
        for (size_t g = 0; g < job->nsamples; g++)
            if (job->inward[m][g]) {
                size_t px = (g % SW) / (size_t)ss, py = (g / SW) / (size_t)ss;
                memcpy(heat + (py * W + px) * 3, inward_color, sizeof inward_color);
            }
        if (W >= 192)
            snprintf(text, sizeof text, "error %.2f deg, inward %.1f%%", st[m].mean_deg,
                     100.0 * st[m].inward_fraction);
        else if (W >= 128)
            snprintf(text, sizeof text, "%.2f deg, inward %.1f%%", st[m].mean_deg,
                     100.0 * st[m].inward_fraction);
        else
            snprintf(text, sizeof text, "%.1f, %.1f%%", st[m].mean_deg,
                     100.0 * st[m].inward_fraction);
        label(c, x, y, fsz, text, fg);
        render_canvas_blit(c, x, y + lab, heat, W, H, 1);
    }
    /* The colour bar: 0 .. heat_max degrees of angle to analytic surfgrad. */
    int y0 = rows * ch + pad, x0 = pad, bw = n * cw - pad;
    for (int i = 0; i < bw; i++) {
        float col[3];
        render_heat_color((float)i / (float)(bw - 1) * o->heat_max, o->heat_max, col);
        for (int j = 0; j < 8; j++)
            memcpy(c->rgb + ((size_t)(y0 + j) * c->w + x0 + i) * 3, col, sizeof col);
    }
    snprintf(text, sizeof text, "angle to surfgrad 0..%g deg", (double)o->heat_max);
    int tw = render_text_width(text, 1);
    label(c, x0, y0 + 10, fsz, text, fg);
    if (bw > 2 * tw * fsz / 8 + 80)
        label(c, x0 + bw / 2, y0 + 10, fsz, "cyan: inward", inward_color);
    free(heat);
    free(crop);
    return 0;
}

static void fill_job(const render_opts *o, const render_scene *scene, render_job *job, int width,
                     int height, int ss)
{
    memset(job, 0, sizeof *job);
    job->scene = scene;
    job->height = &o->h;
    job->width = width, job->height_px = height, job->ss = ss;
    job->nmethods = o->nmethods;
    memcpy(job->methods, o->methods, sizeof o->methods);
    job->threads = o->threads;
    job->progress = NULL; /* TEMPORARY */
}

/* Section 6: Listing 1 "depends on the pixel density across the surface
 * relative to the frequency level of the height function". Same view at
 * 1/4, 1/2, 1, 2 and 4 times the sample density (smaller images, then s x s
 * supersampling), each method's error against analytic surfgrad. */
static int density_sweep(const render_opts *o, const render_scene *scene)
{
    static const struct {
        double density;
        int div, ss;
    } steps[] = {{0.25, 4, 1}, {0.5, 2, 1}, {1, 1, 1}, {2, 1, 2}, {4, 1, 4}};
    for (size_t s = 0; s < sizeof steps / sizeof steps[0]; s++) {
        int w = o->width / steps[s].div, h = o->height / steps[s].div;
        if (w < 2 || h < 2)
            continue;
        render_job job;
        fill_job(o, scene, &job, w, h, steps[s].ss);
        if (render_run(&job))
            return cli_fail(CMD, "out of memory");
        for (int m = 0; m < job.nmethods; m++) {
            render_stats st;
            if (job.methods[m] == RENDER_SURFGRAD)
                continue; /* the reference itself */
            if (render_stats_compute(&job, m, &st)) {
                render_job_free(&job);
                return cli_fail(CMD, "out of memory");
            }
            printf("sweep method=%s density=%g size=%dx%d spp=%d mean_deg=%.4f p99_deg=%.4f "
                   "max_deg=%.4f inward=%.6f hits=%zu\n",
                   render_method_name(job.methods[m]), steps[s].density, w, h,
                   steps[s].ss * steps[s].ss, st.mean_deg, st.p99_deg, st.max_deg,
                   st.inward_fraction, st.hits);
        }
        render_job_free(&job);
    }
    return 0;
}

int cmd_render(int argc, char **argv)
{
    render_opts o;
    memset(&o, 0, sizeof o);
    o.shape = RENDER_SPHERE;
    o.grid = 48;
    o.width = o.height = 384;
    o.ss = 1;
    o.distance = 4.0f;
    o.zoom = 1.0f;
    o.heat_max = 20.0f;
    /* Left, above and in front: grazing enough to show the bumps. */
    o.light[0] = -5.0f, o.light[1] = 4.0f, o.light[2] = 3.0f;
    o.nmethods = 1;
    o.methods[0] = RENDER_SURFGRAD;
    cli_height_init(&o.h);
    /* A default that reads well on the unit sphere: detail a few pixels wide. */
    o.h.h.frequency = 1.0f;
    o.h.h.amplitude = 0.06f;
    int rc = parse_args(argc, argv, &o);
    if (rc == -1)
        return CLI_OK;
    if (rc)
        return rc;
    bg_pixel_type type = BG_PIXEL_U8;
    int srgb = 1;
    if ((rc = check_output(o.output, &type, &srgb)) != 0)
        return rc;
    if ((rc = cli_height_open(CMD, &o.h)) != 0)
        return rc;

    render_mesh mesh;
    memset(&mesh, 0, sizeof mesh);
    render_scene scene;
    memset(&scene, 0, sizeof scene);
    scene.shape = o.shape;
    if (o.shape != RENDER_SPHERE) {
        if (render_mesh_build(o.shape, o.grid, &mesh)) {
            cli_height_close(&o.h);
            return cli_fail(CMD, "cannot build the %s mesh: out of memory", render_shape_name(o.shape));
        }
        scene.mesh = &mesh;
    }
    render_scene_camera(&scene, o.distance, o.zoom);
    memcpy(scene.light, o.light, sizeof scene.light);

    const bg_height *h = &o.h.h;
    printf("render scene=%s", render_shape_name(o.shape));
    if (scene.mesh)
        printf(" grid=%d triangles=%zu", o.grid, mesh.ntri);
    printf(" size=%dx%d spp=%d function=%s octaves=%d frequency=%g amplitude=%g\n", o.width,
           o.height, o.ss * o.ss, cli_function_name(h->fractal.function), h->fractal.octaves,
           (double)h->frequency, (double)h->amplitude);

    render_job job;
    fill_job(&o, &scene, &job, o.width, o.height, o.ss);
    render_stats st[RENDER_MAX_METHODS];
    render_canvas canvas = {0, 0, NULL};
    rc = CLI_OK;
    if (render_run(&job)) {
        rc = cli_fail(CMD, "out of memory");
        goto done;
    }
    for (int m = 0; m < job.nmethods; m++) {
        if (render_stats_compute(&job, m, &st[m])) {
            rc = cli_fail(CMD, "out of memory");
            goto done;
        }
        printf("stats method=%s mean_deg=%.4f p99_deg=%.4f max_deg=%.4f inward=%.6f hits=%zu\n",
               render_method_name(job.methods[m]), st[m].mean_deg, st[m].p99_deg, st[m].max_deg,
               st[m].inward_fraction, st[m].hits);
    }
    bg_image img;
    if (o.compare) {
        if ((rc = compose_panel(&o, &job, st, &canvas)) != 0)
            goto done;
        img.width = canvas.w, img.height = canvas.h, img.pixels = canvas.rgb;
    } else {
        img.width = job.width, img.height = job.height_px, img.pixels = job.rgb[0];
    }
    img.channels = 3;
    char err[512];
    if (bg_image_write(o.output, &img, type, srgb, err, sizeof err) != BG_OK) {
        rc = cli_fail(CMD, "%s", err);
        goto done;
    }
    printf("wrote %s %dx%d\n", o.output, img.width, img.height);
    fflush(stdout);
    if (o.sweep)
        rc = density_sweep(&o, &scene);
done:
    render_canvas_free(&canvas);
    render_job_free(&job);
    render_mesh_free(&mesh);
    cli_height_close(&o.h);
    return rc;
}
