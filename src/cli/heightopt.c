/* SPDX-License-Identifier: MIT */
/* The height-function options shared by every command that bumps a surface,
 * parsed into a bg_height so each command evaluates exactly what the library's
 * fused kernel evaluates: h(p) = A F(f p), grad h = (A f) F'(f p). */
#include "cli.h"
#include <ctype.h>
#include <stdlib.h>
#include <string.h>
#if BG_HAVE_TOOLS
#include "bumpgrad/volume.h"
#endif

/* Points per call into the batch kernels from cli_height_gradient: the scaled
 * positions live on the stack, and 1024 keeps them inside L1. */
#define HEIGHT_BLOCK 1024

void cli_height_init(cli_height *h)
{
    memset(h, 0, sizeof *h);
    h->h = bg_height_default();
}

static int parse_gradient(const char *cmd, const char *text, bg_gradient_mode *out)
{
    if (strcmp(text, "analytic") == 0)
        *out = BG_GRADIENT_ANALYTIC;
    else if (strcmp(text, "central") == 0)
        *out = BG_GRADIENT_CENTRAL;
    else
        return cli_usage_error(cmd, "--gradient: expected analytic or central, got \"%s\"", text);
    return 0;
}

/* "FILE.vdb:GRID" names a grid inside the file; the split is taken only after a
 * ".vdb" so that a path which itself contains ':' still works without a grid name.
 * The argument string is split in place (argv strings are writable and outlive
 * the options), so nothing needs freeing. */
static void split_grid(char *text, const char **path, const char **name)
{
    *path = text;
    *name = NULL;
    char *colon = strrchr(text, ':');
    if (!colon || colon - text < 4)
        return;
    const char *ext = colon - 4;
    if (ext[0] == '.' && tolower((unsigned char)ext[1]) == 'v' &&
        tolower((unsigned char)ext[2]) == 'd' && tolower((unsigned char)ext[3]) == 'b') {
        *colon = '\0';
        *name = colon[1] ? colon + 1 : NULL;
    }
}

int cli_height_option(const char *cmd, cli_height *h, int argc, char **argv, int *i)
{
    const char *o = argv[*i], *v;
    float f;
    long l;
    int rc;
#define VALUE()                                                                                    \
    do {                                                                                           \
        if ((rc = cli_need_value(cmd, argc, argv, i, &v)))                                         \
            return rc;                                                                             \
    } while (0)
    if (strcmp(o, "--function") == 0) {
        VALUE();
        /* Only the kind changes: --octaves given earlier must survive. */
        return cli_parse_function(cmd, "--function", v, &h->h.fractal.function) ? CLI_USAGE : 1;
    }
    if (strcmp(o, "--octaves") == 0) {
        VALUE();
        if (cli_parse_int(cmd, o, v, 1, BG_MAX_OCTAVES, &l))
            return CLI_USAGE;
        h->h.fractal.octaves = (int)l;
        return 1;
    }
    if (strcmp(o, "--lacunarity") == 0) {
        VALUE();
        if (cli_parse_float(cmd, o, v, &f))
            return CLI_USAGE;
        if (!(f > 0))
            return cli_usage_error(cmd, "%s: must be > 0, got \"%s\"", o, v);
        h->h.fractal.lacunarity = f;
        return 1;
    }
    if (strcmp(o, "--gain") == 0) {
        VALUE();
        if (cli_parse_float(cmd, o, v, &h->h.fractal.gain))
            return CLI_USAGE;
        return 1;
    }
    if (strcmp(o, "--amplitude") == 0) {
        VALUE();
        if (cli_parse_float(cmd, o, v, &h->h.amplitude))
            return CLI_USAGE;
        return 1;
    }
    if (strcmp(o, "--frequency") == 0) {
        VALUE();
        if (cli_parse_float(cmd, o, v, &f))
            return CLI_USAGE;
        if (!(f > 0))
            return cli_usage_error(cmd, "%s: must be > 0, got \"%s\"", o, v);
        h->h.frequency = f;
        return 1;
    }
    if (strcmp(o, "--gradient") == 0) {
        VALUE();
        return parse_gradient(cmd, v, &h->h.gradient) ? CLI_USAGE : 1;
    }
    if (strcmp(o, "--step") == 0) {
        VALUE();
        if (cli_parse_float(cmd, o, v, &f))
            return CLI_USAGE;
        if (!(f >= 0))
            return cli_usage_error(cmd, "%s: must be >= 0 (0 = default %g), got \"%s\"", o,
                                   (double)BG_DEFAULT_CENTRAL_STEP, v);
        h->h.step = f;
        return 1;
    }
    if (strcmp(o, "--height-grid") == 0) {
        VALUE();
        if (!*v)
            return cli_usage_error(cmd, "--height-grid: empty file name");
        split_grid(argv[*i], &h->grid_path, &h->grid_name);
        return 1;
    }
#undef VALUE
    return 0;
}

void cli_height_help(FILE *fp)
{
    fprintf(fp,
            "Height function h(p) = A * F(f * p):\n"
            "  --function NAME     noise, fbm or turbulence (default turbulence)\n"
            "  --octaves N         octaves of fbm/turbulence, 1..%d (default %d)\n"
            "  --lacunarity L      frequency ratio between octaves, > 0 (default 2)\n"
            "  --gain G            amplitude ratio between octaves (default 0.5)\n"
            "  --amplitude A       height scale A (default 0.1; negative flips bumps)\n"
            "  --frequency F       spatial frequency f, > 0 (default 1)\n"
            "  --gradient MODE     analytic (default) or central differences\n"
            "  --step H            central-difference step in noise space (0 = %g)\n"
            "  --height-grid FILE.vdb[:GRID]\n"
            "                      use a VDB FloatGrid as the height (tools build only)\n",
            BG_MAX_OCTAVES, BG_DEFAULT_OCTAVES, (double)BG_DEFAULT_CENTRAL_STEP);
}

int cli_height_open(const char *cmd, cli_height *h)
{
    if (bg_height_validate(&h->h) != BG_OK)
        return cli_usage_error(cmd, "invalid height function parameters");
    if (h->grid_path) {
#if BG_HAVE_TOOLS
        /* Like an input table that cannot be opened, a missing, unreadable or
         * malformed grid file (or a missing / wrongly typed grid) is bad input
         * (2); only running out of memory is a runtime failure (1). */
        char err[1024];
        bg_vdb_height *g = NULL;
        bg_status st = bg_vdb_height_open(h->grid_path, h->grid_name, &g, err, sizeof err);
        if (st == BG_ERR_OUT_OF_MEMORY)
            return cli_fail(cmd, "--height-grid: %s", err);
        if (st != BG_OK)
            return cli_usage_error(cmd, "--height-grid: %s", err);
        h->grid = g;
        return 0;
#else
        return cli_usage_error(cmd, "--height-grid needs the tools build (OpenVDB)");
#endif
    }
    return 0;
}

void cli_height_close(cli_height *h)
{
    /* The VDB grid, when there is one, is released here (tools build). */
#if BG_HAVE_TOOLS
    bg_vdb_height_close((bg_vdb_height *)h->grid);
#endif
    h->grid = NULL;
}

void cli_height_gradient(const cli_height *h, const float *px, const float *py, const float *pz,
                         size_t n, float *height, float *gx, float *gy, float *gz)
{
    /* Same operations in the same order as the fused kernel and bg_height_eval
     * (q = f p, grad = (A f) F', height = A F), so the two paths agree bit for bit. */
#if BG_HAVE_TOOLS
    /* A grid is the height itself, in world units: the fractal options do not
     * apply; its gradient is the grid's stencil gradient (volume.h). */
    if (h->grid) {
        bg_vdb_height_sample_batch((const bg_vdb_height *)h->grid, px, py, pz, n, height, gx, gy,
                                   gz);
        return;
    }
#endif
    const bg_height *hh = &h->h;
    const float f = hh->frequency, a = hh->amplitude, af = hh->amplitude * hh->frequency;
    const float step = hh->step > 0 ? hh->step : BG_DEFAULT_CENTRAL_STEP;
    float qx[HEIGHT_BLOCK], qy[HEIGHT_BLOCK], qz[HEIGHT_BLOCK];
    for (size_t b = 0; b < n; b += HEIGHT_BLOCK) {
        size_t m = n - b < HEIGHT_BLOCK ? n - b : HEIGHT_BLOCK;
        for (size_t k = 0; k < m; k++) {
            qx[k] = px[b + k] * f;
            qy[k] = py[b + k] * f;
            qz[k] = pz[b + k] * f;
        }
        float *hv = height ? height + b : NULL;
        if (hh->gradient == BG_GRADIENT_CENTRAL)
            bg_fractal3_grad_central_batch(&hh->fractal, step, qx, qy, qz, m, hv, gx + b, gy + b,
                                           gz + b);
        else
            bg_fractal3_grad_batch(&hh->fractal, qx, qy, qz, m, hv, gx + b, gy + b, gz + b);
        for (size_t k = 0; k < m; k++) {
            gx[b + k] = af * gx[b + k];
            gy[b + k] = af * gy[b + k];
            gz[b + k] = af * gz[b + k];
            if (hv)
                hv[k] = a * hv[k];
        }
    }
}

void cli_height_perturb(const cli_height *h, bg_perturb_method m, const float *px, const float *py,
                        const float *pz, const float *nx, const float *ny, const float *nz,
                        size_t n, float *height, float *ox, float *oy, float *oz)
{
#if BG_HAVE_TOOLS
    /* Grid: its volume gradient, then the same perturbation as the fused kernel
     * (eq. 2 and 4 for BG_PERTURB_SURFGRAD) through bg_perturb_batch. */
    if (h->grid) {
        float gx[HEIGHT_BLOCK], gy[HEIGHT_BLOCK], gz[HEIGHT_BLOCK];
        for (size_t b = 0; b < n; b += HEIGHT_BLOCK) {
            size_t k = n - b < HEIGHT_BLOCK ? n - b : HEIGHT_BLOCK;
            bg_vdb_height_sample_batch((const bg_vdb_height *)h->grid, px + b, py + b, pz + b, k,
                                       height ? height + b : NULL, gx, gy, gz);
            bg_perturb_batch(m, nx + b, ny + b, nz + b, gx, gy, gz, k, ox + b, oy + b, oz + b);
        }
        return;
    }
#endif
    bg_perturb_height_batch(&h->h, m, px, py, pz, nx, ny, nz, n, height, ox, oy, oz);
}
