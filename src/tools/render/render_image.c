/* SPDX-License-Identifier: MIT */
/* render_image (render.h): one `bumpgrad render` job from options to file.
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
#include <unistd.h>
#include "bumpgrad/image.h"
#include "render/render.h"

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
    bgt_height_init(&o->h);
    /* A default that reads well on the unit sphere: detail a few pixels wide. */
    o->h.h.frequency = 1.0f;
    o->h.h.amplitude = 0.06f;
}

/* The presets set a scene and height; the numbers were chosen by looking at
 * the renders (docs/FIGURES.md) so that each shows what its figure shows. */
void render_apply_preset(render_opts *o)
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

static const char *extension(const char *path)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    return dot && (!slash || dot > slash) ? dot : "";
}

/* A writable folder is checked before rendering so that a long render does not
 * end in an I/O error; bg_image_write still reports any later failure. */
static bg_status check_output(const char *path, bg_pixel_type *type, int *srgb, bgt_err *e)
{
    const char *ext = extension(path);
    if (strcasecmp(ext, ".png") == 0)
        *type = BG_PIXEL_U8, *srgb = 1;
    else if (strcasecmp(ext, ".exr") == 0)
        *type = BG_PIXEL_F32, *srgb = 0;
    else
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "--output: \"%s\": expected a .png or .exr file name", path);
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

/* The panel: one column per method; row 1 the renders, row 2 (optional) the
 * magnified crops, last row the heat maps of the error against surfgrad. */
static bg_status compose_panel(const render_opts *o, const render_job *job, const render_stats *st,
                               render_canvas *c, bgt_err *e)
{
    static const float bgc[3] = {0.0f, 0.0f, 0.0f}, fg[3] = {0.85f, 0.85f, 0.85f};
    static const float inward_color[3] = {0.0f, 0.85f, 1.0f};
    const int W = job->width, H = job->height_px, n = job->nmethods;
    const int fsz = W >= 256 ? 16 : W >= 128 ? 10 : 8; /* label font height in pixels */
    const int pad = 4, lab = fsz + 6, rows = o->closeup ? 3 : 2;
    const int cw = W + pad, ch = lab + H + pad;
    const int bar = lab + 10;
    if (render_canvas_alloc(c, n * cw + pad, rows * ch + pad + bar, bgc))
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
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
        /* A large crop (--closeup 1 or 2) would start left of or end below the
         * image: keep it inside (it read outside the buffer once). */
        if (kx > W - kw)
            kx = W - kw;
        if (ky > H - kh)
            ky = H - kh;
        if (kx < 0)
            kx = 0;
        if (ky < 0)
            ky = 0;
        crop = malloc((size_t)kw * kh * 3 * sizeof(float));
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

bg_status render_image(const render_opts *o, render_result *r, bgt_err *e)
{
    bg_pixel_type type = BG_PIXEL_U8;
    int srgb = 1;
    bg_status rc;
    memset(r, 0, sizeof *r);
    if ((rc = check_output(o->output, &type, &srgb, e)) != BG_OK)
        return rc;
    if ((rc = bgt_io_ready(e)) != BG_OK)
        return rc;
    {
        /* What render_run and the panel will allocate, checked against the one
         * cap first: per method an RGB and a heat image, and per sample an
         * error and an inward flag; the panel about (rows x methods) images. */
        const double px = (double)o->width * o->height, ns = px * o->ss * o->ss;
        const double per_method = px * 4.0 * 4.0 + ns * 5.0;
        const double panel = o->compare ? (o->closeup ? 3.0 : 2.0) * px * 12.0 * 1.3 : 0.0;
        if ((rc = bgt_check_alloc(o->nmethods * (per_method + panel), "this render", e)) != BG_OK)
            return rc;
    }

    render_mesh mesh;
    memset(&mesh, 0, sizeof mesh);
    render_scene scene;
    memset(&scene, 0, sizeof scene);
    scene.shape = o->shape;
    if (o->shape != RENDER_SPHERE) {
        if (render_mesh_build(o->shape, o->grid, &mesh))
            return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "cannot build the %s mesh: out of memory",
                            render_shape_name(o->shape));
        scene.mesh = &mesh;
    }
    render_scene_camera(&scene, o->distance, o->zoom);
    memcpy(scene.light, o->light, sizeof scene.light);

    r->triangles = scene.mesh ? mesh.ntri : 0;

    render_job job;
    fill_job(o, &scene, &job, o->width, o->height, o->ss);
    render_stats st[RENDER_MAX_METHODS];
    render_canvas canvas = {0, 0, NULL};
    rc = BG_OK;
    if (render_run(&job)) {
        rc = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    for (int m = 0; m < job.nmethods; m++) {
        if (render_stats_compute(&job, m, &st[m])) {
            rc = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
            goto done;
        }
        r->methods[m] = job.methods[m];
        r->stats[m] = st[m];
    }
    r->nmethods = job.nmethods;
    bg_image img;
    if (o->compare) {
        if ((rc = compose_panel(o, &job, st, &canvas, e)) != BG_OK)
            goto done;
        img.width = canvas.w, img.height = canvas.h, img.pixels = canvas.rgb;
    } else {
        img.width = job.width, img.height = job.height_px, img.pixels = job.rgb[0];
    }
    img.channels = 3;
    char err[512];
    if ((rc = bg_image_write(o->output, &img, type, srgb, err, sizeof err)) != BG_OK) {
        /* Any write failure is a failed run (exit 1), whatever the shim says. */
        rc = bgt_fail(e, rc == BG_ERR_OUT_OF_MEMORY ? rc : BG_ERR_IO, "%s", err);
        goto done;
    }
    r->out_width = img.width, r->out_height = img.height;
    if (o->sweep)
        rc = density_sweep(o, &scene, r, e);
done:
    render_canvas_free(&canvas);
    render_job_free(&job);
    render_mesh_free(&mesh);
    return rc;
}
