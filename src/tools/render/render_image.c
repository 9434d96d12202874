/* SPDX-License-Identifier: MIT */
/* bgt_render_run (render.h): one `bumpgrad render` job from options to file.
 * The renderer fills float RGB buffers; only the final step writes a file,
 * through bg_image_write (temporary file + rename: a failure leaves any old
 * output untouched). Also the presets that reproduce Figures 1, 2, 3 and the
 * default options. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <unistd.h>
#include "bumpgrad/image.h"
#if BG_HAVE_TOOLS
#include "bumpgrad/volume.h"
#endif
#include "render/render_internal.h"
#include "vecmath.h"

void render_opts_default(render_opts *o)
{
    memset(o, 0, sizeof *o);
    o->shape = RENDER_SPHERE;
    o->grid = 48;
    o->width = o->height = 384;
    o->ss = 1;
    o->distance = 4.0f;
    o->zoom = 1.0f;
    o->heat_max = 20.0f;
    /* Left, above and in front: grazing enough to show the bumps. */
    o->light[0] = -5.0f, o->light[1] = 4.0f, o->light[2] = 3.0f;
    o->nmethods = 1;
    o->methods[0] = RENDER_SURFGRAD;
    o->tex_amplitude = 0.004f;
    o->st_scale = 1.0f;
    o->fig4_zoom = 12.0f;
    o->fig4_target[0] = 0.70f, o->fig4_target[1] = 0.42f;
    bgt_height_init(&o->h);
    /* A default that reads well on the unit sphere: detail a few pixels wide. */
    o->h.h.frequency = 1.0f;
    o->h.h.amplitude = 0.06f;
}

/* The presets set a scene and height; the numbers were chosen by looking at
 * the renders (docs/FIGURES.md) so that each shows what its figure shows. */
/* A two-method comparison of a built-in scene with a solid height. */
static void preset_solid(render_opts *o, render_shape shape, bg_function func, float frequency,
                         float amplitude, render_method a, render_method b)
{
    o->shape = shape;
    o->h.h.fractal = bg_fractal_default(func);
    o->h.h.frequency = frequency;
    o->h.h.amplitude = amplitude;
    o->nmethods = 2, o->compare = 1;
    o->methods[0] = a, o->methods[1] = b;
}

void render_apply_preset(render_opts *o)
{
    bg_height *h = &o->h.h;
    switch (o->preset) {
    case PRESET_FIG1:
        /* Figure 1: a coarse isosurface so the facets of (a) are visible; the
         * height detail is 6-octave turbulence as in section 6. */
        preset_solid(o, RENDER_BLOB, BG_FUNC_TURBULENCE, 1.5f, 0.03f, RENDER_FLAT, RENDER_LISTING1);
        o->grid = 14;
        break;
    case PRESET_FIG2:
        /* Figure 2: low-frequency noise, strong enough that n.grad h exceeds 1
         * where the slope faces away, the case where additive turns inward. */
        preset_solid(o, RENDER_SPHERE, BG_FUNC_NOISE, 1.5f, 0.4f, RENDER_ADDITIVE, RENDER_SURFGRAD);
        o->heat_max = 60.0f;
        /* A frontal light, so that the inward normals of (a) show as black
         * where (b) is lit. */
        o->light[0] = -4.0f, o->light[1] = 5.0f, o->light[2] = 6.0f;
        break;
    case PRESET_FIG3:
        /* Figure 3: 6-octave turbulence on a sphere; the close-up row magnifies
         * a crop, where Listing 1's quad derivatives show (3c vs 3d). */
        preset_solid(o, RENDER_SPHERE, BG_FUNC_TURBULENCE, 0.5f, 0.12f, RENDER_LISTING1,
                     RENDER_SURFGRAD);
        o->closeup = 4;
        o->sweep = 1;
        break;
    case PRESET_FIG4:
        /* Figure 4: a textured model (assimp-testmodels' spider by default),
         * Listing 1 with its height texture against normal mapping, the
         * unperturbed model, the albedo, and a close-up where the magnified
         * texture turns piecewise flat, then hidden by turbulence detail. */
        if (!o->mesh_path)
            o->mesh_path = "/usr/share/assimp/models/OBJ/spider.obj";
        o->width = o->height = 256;
        h->fractal = bg_fractal_default(BG_FUNC_TURBULENCE);
        h->frequency = 24.0f;
        h->amplitude = 0.0015f;
        o->tex_amplitude = 0.008f;
        o->nmethods = 6, o->compare = 1;
        o->methods[0] = RENDER_LISTING1_HEIGHTMAP, o->methods[1] = RENDER_NORMALMAP;
        o->methods[2] = RENDER_NONE, o->methods[3] = RENDER_LISTING1_HEIGHTMAP;
        o->methods[4] = RENDER_LISTING1_HEIGHTMAP, o->methods[5] = RENDER_DETAIL;
        o->heat_max = 10.0f;
        break;
    case PRESET_NONE:
        break;
    }
}

static const char *extension(const char *path)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    return dot && (!slash || dot > slash) ? dot : "";
}

/* A writable folder is checked before rendering so that a long render does not
 * end in an I/O error; bg_image_write still reports any later failure. */
static bg_status check_output(const char *path, const char *format, bg_pixel_type *type,
                              int *srgb, bgt_err *e)
{
    /* The bit depth each format holds sensibly: float (linear) where the format
     * stores floats, 8-bit sRGB for the display formats. */
    static const struct {
        const char *ext;
        bg_pixel_type type;
        int srgb;
    } formats[] = {{".png", BG_PIXEL_U8, 1},  {".exr", BG_PIXEL_F32, 0},
                   {".tif", BG_PIXEL_F32, 0}, {".tiff", BG_PIXEL_F32, 0},
                   {".hdr", BG_PIXEL_F32, 0}, {".jpg", BG_PIXEL_U8, 1},
                   {".jpeg", BG_PIXEL_U8, 1}, {".ppm", BG_PIXEL_U8, 1},
                   {".bmp", BG_PIXEL_U8, 1},  {".tga", BG_PIXEL_U8, 1}};
    int to_stdout = strcmp(path, "-") == 0;
    char fmt_ext[16] = ".png";
    if (format && *format == '.')
        format++;
    if (format && (strlen(format) + 2 > sizeof fmt_ext || !*format))
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "--format: \"%s\": not an image format",
                        format);
    if (format)
        snprintf(fmt_ext, sizeof fmt_ext, ".%s", format);
    const char *ext = to_stdout ? fmt_ext : extension(path);
    if (!to_stdout && format && strcasecmp(ext, fmt_ext) != 0)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--format %s disagrees with the extension of --output \"%s\" (the "
                        "extension decides; --format is for --output -)", format, path);
    size_t k = 0, nf = sizeof formats / sizeof formats[0];
    while (k < nf && strcasecmp(ext, formats[k].ext) != 0)
        k++;
    if (k == nf && to_stdout)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--format: \"%s\": expected png or exr (or tif, hdr, jpg, ppm, bmp, "
                        "tga)", format);
    if (k == nf)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--output: \"%s\": expected a .png or .exr file name (or .tif, .hdr, "
                        ".jpg, .ppm, .bmp, .tga)", path);
    *type = formats[k].type, *srgb = formats[k].srgb;
    if (to_stdout) /* no folder to check: bg_image_write_as reports a bad stream */
        return BG_OK;
    char *dir = malloc(strlen(path) + 2);
    if (!dir)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
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
        bgt_fail(e, BG_ERR_IO, "cannot write \"%s\": folder \"%s\" is missing or not writable", path, dir);
        free(dir);
        return BG_ERR_IO;
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

/* Greedy word wrap of the parameter stamp into at most 4 lines of `maxc` characters. */
static int wrap_stamp(const char *text, int maxc, char lines[4][256])
{
    int n = 0;
    const char *s = text;
    if (maxc < 8)
        maxc = 8;
    if (maxc > 255)
        maxc = 255;
    while (*s && n < 4) {
        while (*s == ' ')
            s++;
        int len = (int)strlen(s), cut = len;
        if (len > maxc) {
            cut = maxc;
            while (cut > 0 && s[cut] != ' ')
                cut--;
            if (cut == 0)
                cut = maxc;
        }
        if (cut < 1 || cut > 255)
            cut = cut < 1 ? 1 : 255;
        memcpy(lines[n], s, (size_t)cut);
        lines[n][cut] = '\0';
        if (cut > 0)
            n++;
        s += cut;
    }
    return n;
}

/* Character budget of a line of width w at label size `size` (the bitmap font's
 * 6 px per character at size 8, which the FreeType font does not exceed). */
static int stamp_chars(int w, int size)
{
    int bitmap = 6 * (size / 8 > 0 ? size / 8 : 1), freetype = (size * 3 + 3) / 4;
    return w / (bitmap > freetype ? bitmap : freetype);
}

/* The close-up: a crop of 1/closeup of the image, magnified closeup times
 * (never past its cell on tiny images). */
typedef struct closeup_rect {
    int kw, kh, kx, ky, mag;
} closeup_rect;

static closeup_rect closeup_of(int W, int H, int closeup)
{
    closeup_rect r = {W / closeup, H / closeup, 0, 0, closeup};
    if (r.kw < 1)
        r.kw = 1;
    if (r.kh < 1)
        r.kh = 1;
    if (r.kw * r.mag > W)
        r.mag = W / r.kw;
    if (r.kh * r.mag > H)
        r.mag = H / r.kh;
    /* Right of and below the centre: half-lit (the detail reads best away
     * from the highlight) and away from the silhouette. */
    r.kx = (int)(0.40 * W) - r.kw / 2, r.ky = (int)(0.56 * H) - r.kh / 2;
    /* A large crop (--closeup 1 or 2) would start left of or end below the
     * image: keep it inside (it read outside the buffer once). */
    if (r.kx > W - r.kw)
        r.kx = W - r.kw;
    if (r.ky > H - r.kh)
        r.ky = H - r.kh;
    if (r.kx < 0)
        r.kx = 0;
    if (r.ky < 0)
        r.ky = 0;
    return r;
}

static const float panel_bg[3] = {0.0f, 0.0f, 0.0f}, panel_fg[3] = {0.85f, 0.85f, 0.85f};
static const float inward_color[3] = {0.0f, 0.85f, 1.0f};

/* Method m's heat map: the angle to the reference on the heat ramp, black
 * where there is none, and the pixels with an inward perturbed normal
 * (dot(n', n) <= 0, the failure of Figure 2a) in cyan, a colour the ramp
 * never takes. */
static void heat_image(const render_opts *o, const render_job *job, int m, float *heat)
{
    const int W = job->width, H = job->height_px;
    for (size_t i = 0; i < (size_t)W * H; i++) {
        float e = job->heat[m][i];
        if (e == e)
            render_heat_color(e, o->heat_max, heat + i * 3);
        else
            memcpy(heat + i * 3, panel_bg, sizeof panel_bg);
    }
    const int ss = job->ss;
    const size_t SW = (size_t)W * ss;
    for (size_t g = 0; g < job->nsamples; g++)
        if (job->inward[m][g]) {
            size_t px = (g % SW) / (size_t)ss, py = (g / SW) / (size_t)ss;
            memcpy(heat + (py * W + px) * 3, inward_color, sizeof inward_color);
        }
}

/* The heat map's caption, as long as the column's width allows. */
static void error_caption(char *text, size_t n, int W, const render_stats *st)
{
    if (W >= 192)
        snprintf(text, n, "error %.2f deg, inward %.1f%%", st->mean_deg,
                 100.0 * st->inward_fraction);
    else if (W >= 128)
        snprintf(text, n, "%.2f deg, inward %.1f%%", st->mean_deg, 100.0 * st->inward_fraction);
    else
        snprintf(text, n, "%.1f, %.1f%%", st->mean_deg, 100.0 * st->inward_fraction);
}

/* The colour bar at (x0, y0), bw wide: 0 .. heat_max degrees of angle to
 * the reference, ticks at 0, 1/4, .. 1 of the range with their values, and
 * the caption. */
static void colour_bar(const render_opts *o, render_canvas *c, int x0, int y0, int bw, int fsz,
                       const char *ref_name)
{
    const int lab = fsz + 6;
    char text[128];
    for (int i = 0; i < bw; i++) {
        float col[3];
        render_heat_color((float)i / (float)(bw - 1) * o->heat_max, o->heat_max, col);
        for (int j = 0; j < 8; j++)
            memcpy(c->rgb + ((size_t)(y0 + j) * c->w + x0 + i) * 3, col, sizeof col);
    }
    for (int k = 0; k <= 4; k++) {
        int tx = x0 + (int)lround((double)(bw - 1) * k / 4.0);
        for (int j = 8; j < 12; j++)
            for (int dx = 0; dx < 2; dx++) {
                int px = tx + (k == 4 ? -dx : dx);
                if (px < 0 || px >= c->w || y0 + j >= c->h)
                    continue;
                float *dst = c->rgb + ((size_t)(y0 + j) * (size_t)c->w + (size_t)px) * 3;
                dst[0] = panel_fg[0], dst[1] = panel_fg[1], dst[2] = panel_fg[2];
            }
        snprintf(text, sizeof text, "%g", (double)o->heat_max * k / 4.0);
        int w = render_text_width(text, fsz / 8 > 0 ? fsz / 8 : 1);
        int lx = k == 0 ? tx : k == 4 ? tx - w : tx - w / 2;
        label(c, lx, y0 + 12, fsz, text, panel_fg);
    }
    snprintf(text, sizeof text, "angle to %s (deg)", ref_name);
    int tw = render_text_width(text, 1);
    label(c, x0, y0 + 12 + lab, fsz, text, panel_fg);
    if (bw > 2 * tw * fsz / 8 + 80)
        label(c, x0 + bw / 2, y0 + 12 + lab, fsz, "cyan: inward", inward_color);
}

/* The panel: one column per method; row 1 the renders, row 2 (optional) the
 * magnified crops, last row the heat maps of the error against the
 * reference; under them the colour bar and the parameter stamp. */
static bg_status compose_panel(const render_opts *o, const render_job *job, const render_stats *st,
                               const char *stamp, const char *ref_name, render_canvas *c, bgt_err *e)
{
    const int W = job->width, H = job->height_px, n = job->nmethods;
    const int fsz = W >= 256 ? 16 : W >= 128 ? 10 : 8; /* label font height in pixels */
    const int pad = 4, lab = fsz + 6, rows = o->closeup ? 3 : 2;
    const int cw = W + pad, ch = lab + H + pad;
    /* Colour bar (8 px), tick marks (4 px), tick values and caption (a label
     * row each), then the render parameters stamped in up to 4 lines. */
    const int bar = 12 + 2 * lab + 2;
    char lines[4][256];
    const int stamp_size = fsz >= 16 ? 12 : 8, stamp_lab = stamp_size + 4;
    const int nlines = stamp ? wrap_stamp(stamp, stamp_chars(n * cw - pad, stamp_size), lines) : 0;
    if (render_canvas_alloc(c, n * cw + pad, rows * ch + pad + bar + nlines * stamp_lab, panel_bg))
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    float *heat = malloc((size_t)W * H * 3 * sizeof(float));
    float *crop = NULL;
    closeup_rect k = {0, 0, 0, 0, 0};
    if (o->closeup) {
        k = closeup_of(W, H, o->closeup);
        crop = malloc((size_t)k.kw * k.kh * 3 * sizeof(float));
    }
    if (!heat || (o->closeup && !crop)) {
        free(heat);
        free(crop);
        render_canvas_free(c);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    }
    char text[128];
    for (int m = 0; m < n; m++) {
        int x = pad + m * cw, y = pad;
        snprintf(text, sizeof text, "(%c) %s", 'a' + m, render_method_name(job->methods[m]));
        label(c, x, y, fsz, text, panel_fg);
        render_canvas_blit(c, x, y + lab, job->rgb[m], W, H, 1);
        y += ch;
        if (o->closeup) {
            for (int j = 0; j < k.kh; j++)
                memcpy(crop + (size_t)j * k.kw * 3,
                       job->rgb[m] + ((size_t)(k.ky + j) * W + k.kx) * 3,
                       (size_t)k.kw * 3 * sizeof(float));
            snprintf(text, sizeof text, "(%c) close-up x%d", 'a' + n + m, k.mag);
            label(c, x, y, fsz, text, panel_fg);
            render_canvas_blit(c, x, y + lab, crop, k.kw, k.kh, k.mag);
            y += ch;
        }
        heat_image(o, job, m, heat);
        error_caption(text, sizeof text, W, &st[m]);
        label(c, x, y, fsz, text, panel_fg);
        render_canvas_blit(c, x, y + lab, heat, W, H, 1);
    }
    const int y0 = rows * ch + pad, x0 = pad, bw = n * cw - pad;
    colour_bar(o, c, x0, y0, bw, fsz, ref_name);
    for (int i = 0; i < nlines; i++)
        label(c, x0, y0 + bar + i * stamp_lab, stamp_size, lines[i], panel_fg);
    free(heat);
    free(crop);
    return BG_OK;
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
    job->progress = o->progress;
    job->albedo_mask = o->albedo_mask;
}

/* Section 6: Listing 1 "depends on the pixel density across the surface
 * relative to the frequency level of the height function". Same view at
 * 1/4, 1/2, 1, 2 and 4 times the sample density (smaller images, then s x s
 * supersampling), each method's error against analytic surfgrad. */
static bg_status density_sweep(const render_opts *o, const render_scene *scene, render_result *r,
                               bgt_err *e)
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
            return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
        for (int m = 0; m < job.nmethods; m++) {
            render_stats st;
            if (job.methods[m] == RENDER_SURFGRAD)
                continue; /* the reference itself */
            if (render_stats_compute(&job, m, &st)) {
                render_job_free(&job);
                return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
            }
            render_sweep_row *row = &r->sweep[r->nsweep++];
            row->method = job.methods[m];
            row->density = steps[s].density;
            row->width = w, row->height = h, row->spp = steps[s].ss * steps[s].ss;
            row->st = st;
        }
        render_job_free(&job);
    }
    return 0;
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The parameters of the render, stamped under the panels (issue 15 item 6). */
/* What a grid height did to the main render (render_result.grid*). */
static void report_grid(const render_opts *o, const render_job *job, render_result *r)
{
#if BG_HAVE_TOOLS
    if (!o->h.grid)
        return;
    bg_vdb_height_info info;
    bg_vdb_height_get_info((const bg_vdb_height *)o->h.grid, &info);
    r->grid = 1;
    r->grid_points = job->grid_points;
    r->grid_in_box = job->grid_in_box;
    r->grid_zero = job->grid_zero;
    for (int k = 0; k < 3; k++) {
        r->grid_box[k] = info.world_min[k];
        r->grid_box[3 + k] = info.world_max[k];
    }
#else
    (void)o, (void)job, (void)r;
#endif
}

static void make_stamp(const render_opts *o, const render_result *r, char *out, size_t len)
{
    const bg_height *h = &o->h.h;
    static const char *const fn[] = {"noise", "fbm", "turbulence", "ridged"};
    size_t n = 0;
    if (o->mesh_path) {
        const char *base = strrchr(o->mesh_path, '/');
        n += (size_t)snprintf(out + n, len - n, "mesh=%s (%zu tri) tex-amplitude=%g st-scale=%g",
                              base ? base + 1 : o->mesh_path, r->triangles,
                              (double)o->tex_amplitude, (double)o->st_scale);
    } else {
        n += (size_t)snprintf(out + n, len - n, "scene=%s", render_shape_name(o->shape));
        if (o->shape != RENDER_SPHERE && n < len)
            n += (size_t)snprintf(out + n, len - n, " grid=%d (%zu tri)", o->grid, r->triangles);
    }
    if (n < len)
        n += (size_t)snprintf(out + n, len - n, " | %dx%d spp=%d | ", o->width, o->height,
                              o->ss * o->ss);
    if (n < len && o->h.grid_path) {
        const char *base = strrchr(o->h.grid_path, '/');
        n += (size_t)snprintf(out + n, len - n, "height-grid=%s", base ? base + 1 : o->h.grid_path);
    } else if (n < len) {
        n += (size_t)snprintf(out + n, len - n, "%s octaves=%d frequency=%g amplitude=%g",
                              (unsigned)h->fractal.function < 4 ? fn[h->fractal.function] : "?",
                              h->fractal.octaves, (double)h->frequency, (double)h->amplitude);
    }
    if (n < len)
        n += (size_t)snprintf(out + n, len - n, " | light=%g,%g,%g distance=%g zoom=%g | tracer=%s",
                              (double)o->light[0], (double)o->light[1], (double)o->light[2],
                              (double)o->distance, (double)o->zoom, r->tracer);
}

/* Figure 4: six renders in two rows of three, each labelled with the paper's
 * caption and its mean angle to surfgrad-heightmap, then the stamp. */
static const char *const fig4_caption[6] = {
    "(a) Listing 1, height map", "(b) normal mapping", "(c) no perturbation",
    "(d) Listing 1 + albedo",    "(e) undersampling",  "(f) with detail"};
static const char *const fig4_sub[6] = {
    "Listing 2 taps", "mikkTSpace frames", "unperturbed normals", "albedo texture",
    "close-up, magnified texture", "+ turbulence, resolved"};

static bg_status compose_fig4(const render_job *full, const render_job *close,
                              const render_stats *st, const char *stamp, render_canvas *c,
                              bgt_err *e)
{
    static const float bgc[3] = {0.0f, 0.0f, 0.0f}, fg[3] = {0.85f, 0.85f, 0.85f};
    const int W = full->width, H = full->height_px;
    const int fsz = W >= 256 ? 16 : W >= 128 ? 10 : 8, pad = 4, lab = fsz + 6;
    const int cw = W + pad, ch = 2 * lab + H + pad;
    char lines[4][256];
    const int stamp_size = fsz >= 16 ? 12 : 8, stamp_lab = stamp_size + 4;
    const int nlines = wrap_stamp(stamp, stamp_chars(3 * cw - pad, stamp_size), lines);
    if (render_canvas_alloc(c, 3 * cw + pad, 2 * ch + pad + nlines * stamp_lab + 2, bgc))
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    char text[160];
    for (int k = 0; k < 6; k++) {
        int x = pad + (k % 3) * cw, y = pad + (k / 3) * ch;
        const render_job *J = k < 4 ? full : close;
        int m = k < 4 ? k : k - 4;
        label(c, x, y, fsz, fig4_caption[k], fg);
        if (k == 2 || k == 3)
            snprintf(text, sizeof text, "%s", fig4_sub[k]);
        else
            snprintf(text, sizeof text, "%s, %.2f deg", fig4_sub[k], st[k].mean_deg);
        label(c, x, y + lab, fsz * 3 / 4 > 8 ? fsz * 3 / 4 : 8, text, fg);
        render_canvas_blit(c, x, y + 2 * lab, J->rgb[m], W, H, 1);
    }
    for (int i = 0; i < nlines; i++)
        label(c, pad, 2 * ch + pad + i * stamp_lab, stamp_size, lines[i], fg);
    return BG_OK;
}

static bg_status write_image(const char *path, const char *format, const bg_image *img,
                             bg_pixel_type type, int srgb, bgt_err *e)
{
    char err[512];
    bg_status rc = bg_image_write_as(path, format, img, type, srgb, err, sizeof err);
    if (rc != BG_OK)
        /* Any write failure is a failed run (exit 1), whatever the shim says. */
        return bgt_fail(e, rc == BG_ERR_OUT_OF_MEMORY ? rc : BG_ERR_IO, "%s", err);
    return BG_OK;
}

/* The options bgt_render_run refuses before any work, and what render_run and
 * the panel will allocate, checked against the one cap first: per method an
 * RGB and a heat image, and per sample an error and an inward flag; the panel
 * about (rows x methods) images. */
static bg_status check_render(const render_opts *o, bg_pixel_type *type, int *srgb, bgt_err *e)
{
    bg_status rc;
    if ((rc = check_output(o->output, o->format, type, srgb, e)) != BG_OK)
        return rc;
    for (int m = 0; m < o->nmethods; m++)
        if (render_method_textured(o->methods[m]) && !o->mesh_path)
            return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                            "method %s needs --mesh FILE (a mesh with texture coordinates)",
                            render_method_name(o->methods[m]));
    if (o->preset == PRESET_FIG4 && o->sweep)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "--sweep does not apply to --preset fig4");
    if ((rc = bgt_io_ready(e)) != BG_OK)
        return rc;
    const double px = (double)o->width * o->height, ns = px * o->ss * o->ss;
    const double per_method = px * 4.0 * 4.0 + ns * 5.0;
    const double panel = o->compare ? (o->closeup ? 3.0 : 2.0) * px * 12.0 * 1.3 : 0.0;
    return bgt_check_alloc(o->nmethods * (per_method + panel), "this render", e);
}

/* What bgt_render_run holds while it runs (render_state_free frees it all). */
typedef struct render_state {
    render_mesh mesh;
    render_textures tex;
    render_embree *rtc;
    render_scene scene;
} render_state;

static void render_state_free(render_state *s)
{
    render_embree_free(s->rtc);
    render_textures_free(&s->tex);
    render_mesh_free(&s->mesh);
}

/* The geometry and its tracer: the --mesh file with its textures, or a
 * built-in isosurface; Embree for a loaded mesh when built with it, while the
 * built-in isosurfaces keep their BVH unless --tracer embree
 * (docs/FIGURES.md has the measurements and the agreement between the two). */
static bg_status load_scene(render_opts *o, render_state *s, render_result *r, bgt_err *e)
{
    bg_status rc;
    s->scene.shape = o->shape;
    int use_embree = o->tracer == TRACER_EMBREE ||
                     (o->tracer == TRACER_AUTO && o->mesh_path && render_embree_available());
    double t0 = now_seconds();
    if (o->mesh_path) {
        if ((rc = render_load_mesh(o, &s->mesh, &s->tex, r->textures, sizeof r->textures, e)) !=
            BG_OK)
            return rc;
        s->scene.mesh = &s->mesh;
        s->scene.tex = &s->tex;
        if (o->preset == PRESET_FIG4)
            o->albedo_mask = 1u << 3;
        else
            o->albedo_mask = o->no_albedo ? 0u : ~0u;
    }
    r->load_seconds = now_seconds() - t0;
    if (!o->mesh_path && o->shape != RENDER_SPHERE) {
        /* Timed with its BVH: build_s of the isosurface is marching tetrahedra + BVH. */
        double tb = now_seconds();
        if (render_mesh_build(o->shape, o->grid, &s->mesh))
            return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "cannot build the %s mesh: out of memory",
                            render_shape_name(o->shape));
        r->load_seconds = now_seconds() - tb;
        s->scene.mesh = &s->mesh;
    }
    r->tracer = "analytic";
    if (s->scene.mesh && use_embree) {
        if ((rc = render_embree_build(&s->mesh, o->threads, &s->rtc, &r->build_seconds, e)) != BG_OK)
            return rc;
        s->scene.embree = s->rtc;
        r->tracer = "embree";
    } else if (s->scene.mesh) {
        if (o->mesh_path) {
            double tb = now_seconds();
            if (render_mesh_bvh(&s->mesh) != BG_OK)
                return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the BVH");
            r->build_seconds = now_seconds() - tb;
        }
        r->tracer = "bvh";
    }
    r->triangles = s->scene.mesh ? s->mesh.ntri : 0;
    return BG_OK;
}

/* The camera of --view (or the default view) at zoom, and the light. */
static void set_camera(const render_opts *o, render_scene *scene, float zoom)
{
    if (o->view_set)
        render_scene_camera_dir(scene, o->view, o->distance, zoom);
    else
        render_scene_camera(scene, o->distance, zoom);
    memcpy(scene->light, o->light, sizeof scene->light);
}

/* Automatic framing of a --mesh without --zoom: the zoom at which the mesh's
 * silhouette (its vertices' projections) fills 90% of the image's shorter
 * half-extent. */
static void frame_mesh(render_opts *o, render_state *s)
{
    const float aspect = (float)o->width / (float)o->height;
    const render_scene *sc = &s->scene;
    float need = 0;
    for (size_t i = 0; i < s->mesh.ntri * 3; i++) {
        const float *p = s->mesh.pos + i * 3;
        float w[3] = {p[0] - sc->eye[0], p[1] - sc->eye[1], p[2] - sc->eye[2]};
        float z = bg_f3_dot(w, sc->fwd);
        if (!(z > 1e-3f))
            continue;
        float x = fabsf(bg_f3_dot(w, sc->right)) / (z * aspect), y = fabsf(bg_f3_dot(w, sc->up)) / z;
        need = fmaxf(need, fmaxf(x, y));
    }
    if (need > 0) {
        o->zoom = 0.36397023f / (need / 0.9f);
        set_camera(o, &s->scene, o->zoom);
    }
}

/* Figure 4 (e), (f): the same model seen through a longer lens, so that the
 * height texture is magnified until its bilinear reconstruction is piecewise
 * flat (section 6), aimed at the surface under fig4_target of the full view
 * (the spider's abdomen): the camera moves parallel to itself onto it. */
static void aim_closeup(const render_opts *o, const render_state *s, render_scene *close)
{
    const render_scene *sc = &s->scene;
    set_camera(o, close, o->zoom * o->fig4_zoom);
    const float aspect = (float)o->width / (float)o->height;
    float u = (2.0f * o->fig4_target[0] - 1.0f) * aspect * sc->tan_half;
    float v = (1.0f - 2.0f * o->fig4_target[1]) * sc->tan_half, d[3];
    for (int a = 0; a < 3; a++)
        d[a] = sc->fwd[a] + u * sc->right[a] + v * sc->up[a];
    bg_f3_normalize(d);
    render_hit hh;
    int hit = s->rtc ? render_embree_intersect(s->rtc, sc->eye, d, &hh)
                     : render_mesh_intersect(&s->mesh, sc->eye, d, INFINITY, &hh);
    if (hit)
        for (int a = 0; a < 3; a++)
            close->eye[a] += sc->eye[a] + hh.t * d[a];
}

/* The per-method statistics into r (Figure 4's last two from the close-up). */
static bg_status collect_stats(const render_opts *o, const render_job *job, const render_job *job2,
                               render_stats *st, render_result *r, bgt_err *e)
{
    const int fig4 = o->preset == PRESET_FIG4;
    for (int m = 0; m < o->nmethods && m < (fig4 ? 6 : job->nmethods); m++) {
        const render_job *J = fig4 && m >= 4 ? job2 : job;
        if (render_stats_compute(J, fig4 && m >= 4 ? m - 4 : m, &st[m]))
            return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
        r->methods[m] = o->methods[m];
        r->stats[m] = st[m];
        r->nmethods = m + 1;
        if (fig4)
            r->labels[m] = fig4_caption[m];
    }
    return BG_OK;
}

/* The picture to write: Figure 4's layout, the --compare panel, or the one
 * method's image. */
static bg_status compose_output(const render_opts *o, const render_state *s, const render_job *job,
                                const render_job *job2, const render_stats *st, const char *stamp,
                                render_canvas *canvas, bg_image *img, bgt_err *e)
{
    bg_status rc;
    if (o->preset == PRESET_FIG4) {
        if ((rc = compose_fig4(job, job2, st, stamp, canvas, e)) != BG_OK)
            return rc;
        img->width = canvas->w, img->height = canvas->h, img->pixels = canvas->rgb;
    } else if (o->compare) {
        int texref = 0;
        for (int m = 0; m < job->nmethods; m++)
            texref |= render_method_textured(job->methods[m]) && s->tex.any_height; /* render_run */
        if ((rc = compose_panel(o, job, st, stamp, texref ? "surfgrad-heightmap" : "surfgrad",
                                canvas, e)) != BG_OK)
            return rc;
        img->width = canvas->w, img->height = canvas->h, img->pixels = canvas->rgb;
    } else {
        img->width = job->width, img->height = job->height_px, img->pixels = job->rgb[0];
    }
    img->channels = 3;
    return BG_OK;
}

bg_status bgt_render_run(const render_opts *o_in, render_result *r, bgt_err *e)
{
    bg_pixel_type type = BG_PIXEL_U8;
    int srgb = 1;
    bg_status rc;
    memset(r, 0, sizeof *r);
    render_opts oo = *o_in, *o = &oo;
    if ((rc = bgt_height_open(&o->h, e)) != BG_OK)
        return rc;
    if ((rc = check_render(o, &type, &srgb, e)) != BG_OK) {
        bgt_height_close(&o->h);
        return rc;
    }

    render_state s;
    memset(&s, 0, sizeof s);
    render_job job, job2;
    memset(&job, 0, sizeof job);
    memset(&job2, 0, sizeof job2);
    render_canvas canvas = {0, 0, NULL};
    if ((rc = load_scene(o, &s, r, e)) != BG_OK)
        goto done;
    set_camera(o, &s.scene, o->zoom);
    if (o->mesh_path && !o->zoom_set)
        frame_mesh(o, &s);

    const int fig4 = o->preset == PRESET_FIG4;
    render_scene close_scene = s.scene;
    fill_job(o, &s.scene, &job, o->width, o->height, o->ss);
    if (fig4)
        job.nmethods = 4;
    double tr = now_seconds();
    if (render_run(&job)) {
        rc = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    if (fig4) {
        aim_closeup(o, &s, &close_scene);
        fill_job(o, &close_scene, &job2, o->width, o->height, o->ss);
        job2.nmethods = 2;
        job2.methods[0] = o->methods[4], job2.methods[1] = o->methods[5];
        job2.albedo_mask = 0;
        if (render_run(&job2)) {
            rc = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
            goto done;
        }
    }
    r->render_seconds = now_seconds() - tr;
    report_grid(o, &job, r);
    render_stats st[RENDER_MAX_METHODS];
    if ((rc = collect_stats(o, &job, &job2, st, r, e)) != BG_OK)
        goto done;
    char stamp[640];
    make_stamp(o, r, stamp, sizeof stamp);
    bg_image img;
    if ((rc = compose_output(o, &s, &job, &job2, st, stamp, &canvas, &img, e)) != BG_OK ||
        (rc = write_image(o->output, o->format, &img, type, srgb, e)) != BG_OK)
        goto done;
    r->out_width = img.width, r->out_height = img.height;
    if (o->sweep)
        rc = density_sweep(o, &s.scene, r, e);
done:
    render_canvas_free(&canvas);
    render_job_free(&job);
    render_job_free(&job2);
    render_state_free(&s);
    bgt_height_close(&o->h);
    return rc;
}
