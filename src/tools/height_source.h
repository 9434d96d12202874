/* SPDX-License-Identifier: MIT */
/* The height field a bumping tool samples (height_source.c): the library's
 * fractal bg_height, or a VDB FloatGrid (tools build). The CLI fills it from
 * --function/--octaves/.../--height-grid (src/cli/heightopt.c). */
#ifndef BUMPGRAD_TOOLS_HEIGHT_SOURCE_H
#define BUMPGRAD_TOOLS_HEIGHT_SOURCE_H

#include <stddef.h>
#include "bumpgrad.h"
#include "common/tool.h"

typedef struct bgt_height {
    bg_height h;
    const char *grid_path; /* non-NULL: a VDB FloatGrid is the height (tools only) */
    const char *grid_name; /* NULL: the first FloatGrid of the file */
    void *grid;            /* opened grid (bg_vdb_height *), set by bgt_height_open */
} bgt_height;

/* bg_height_default(), no grid. */
void bgt_height_init(bgt_height *h);
/* Validate the parameters and open the grid if one was named.
 * BG_ERR_INVALID_ARGUMENT (bad parameters, unreadable or malformed grid, grid
 * without the tools build) or BG_ERR_OUT_OF_MEMORY, with a message in *e. */
bg_status bgt_height_open(bgt_height *h, bgt_err *e);
void bgt_height_close(bgt_height *h);
/* Height and volume gradient at n points (SoA): the fractal kernels, or the
 * grid (gradient by a stencil on the grid). `height` may be NULL. */
void bgt_height_gradient(const bgt_height *h, const float *px, const float *py, const float *pz,
                         size_t n, float *height, float *gx, float *gy, float *gz);
/* Height and perturbed normal (fused kernel, or grid gradient + bg_perturb_batch). */
void bgt_height_perturb(const bgt_height *h, bg_perturb_method m, const float *px,
                        const float *py, const float *pz, const float *nx, const float *ny,
                        const float *nz, size_t n, float *height, float *ox, float *oy, float *oz);

#endif
