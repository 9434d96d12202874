/* SPDX-License-Identifier: MIT */
/* The height source every bumping tool samples: the library's fractal
 * h(p) = A F(f p), grad h = (A f) F'(f p), or a VDB FloatGrid with its stencil
 * gradient (tools build). Same operations in the same order as the fused
 * kernel and bg_height_eval, so every path agrees bit for bit. */
#include "height_source.h"
#include <string.h>
#if BG_HAVE_TOOLS
#include "bumpgrad/volume.h"
#endif

/* Points per call into the batch kernels: the scaled positions live on the
 * stack, and 1024 keeps them inside L1. */
#define HEIGHT_BLOCK 1024

void bgt_height_init(bgt_height *h)
{
    memset(h, 0, sizeof *h);
    h->h = bg_height_default();
}

bg_status bgt_height_open(bgt_height *h, bgt_err *e)
{
    if (bg_fractal_validate(&h->h.fractal) == BG_OK &&
        bg_domain_validate(&h->h.fractal, &h->h.domain) != BG_OK)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--period %d,%d,%d: needs an integer --lacunarity, and the finest "
                        "octave's period P * lacunarity^(octaves-1) at most 2^24",
                        h->h.domain.period[0], h->h.domain.period[1], h->h.domain.period[2]);
    if (bg_height_validate(&h->h) != BG_OK)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "invalid height function parameters");
    if (h->grid_path) {
#if BG_HAVE_TOOLS
        /* Like an input table that cannot be opened, a missing, unreadable or
         * malformed grid file (or a missing / wrongly typed grid) is bad input
         * (2); only running out of memory is a runtime failure (1). */
        char err[1024];
        bg_vdb_height *g = NULL;
        bg_status st = bg_vdb_height_open(h->grid_path, h->grid_name, &g, err, sizeof err);
        if (st == BG_ERR_OUT_OF_MEMORY)
            return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "--height-grid: %s", err);
        if (st != BG_OK)
            return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "--height-grid: %s", err);
        h->grid = g;
        return BG_OK;
#else
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "--height-grid needs the tools build (OpenVDB)");
#endif
    }
    return BG_OK;
}

void bgt_height_close(bgt_height *h)
{
    /* The VDB grid, when there is one, is released here (tools build). */
#if BG_HAVE_TOOLS
    bg_vdb_height_close((bg_vdb_height *)h->grid);
#endif
    h->grid = NULL;
}

void bgt_height_gradient(const bgt_height *h, const float *px, const float *py, const float *pz,
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
        /* The domain calls are the plain ones for the default (zero) domain. */
        if (hh->gradient == BG_GRADIENT_CENTRAL)
            bg_fractal3_domain_grad_central_batch(&hh->fractal, &hh->domain, step, qx, qy, qz, m,
                                                  hv, gx + b, gy + b, gz + b);
        else
            bg_fractal3_domain_grad_batch(&hh->fractal, &hh->domain, qx, qy, qz, m, hv, gx + b,
                                          gy + b, gz + b);
        for (size_t k = 0; k < m; k++) {
            gx[b + k] = af * gx[b + k];
            gy[b + k] = af * gy[b + k];
            gz[b + k] = af * gz[b + k];
            if (hv)
                hv[k] = a * hv[k];
        }
    }
}

void bgt_height_perturb(const bgt_height *h, bg_perturb_method m, const float *px, const float *py,
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
