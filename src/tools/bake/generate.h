/* SPDX-License-Identifier: MIT */
/* The face of `bumpgrad heightmap --generate` (generate.c, tools build only): a
 * height, normal or derivative map that tiles, from the height function alone. */
#ifndef BUMPGRAD_TOOLS_BAKE_GENERATE_H
#define BUMPGRAD_TOOLS_BAKE_GENERATE_H

#include "bumpgrad.h"
#include "common/tool.h"
#include "height_source.h"

/* ---- heightmap --generate: a tileable map from the height function alone ---- */
typedef enum bgt_map_kind { BGT_MAP_HEIGHT = 0, BGT_MAP_NORMAL = 1, BGT_MAP_DERIVATIVE = 2 } bgt_map_kind;

typedef struct bgt_generate_opts {
    const char *output;       /* any image OpenImageIO writes, "-": standard output */
    const bgt_height *height; /* NOT opened; a fractal with periods along x and y */
    int width, height_px;     /* 1..65536 */
    bgt_map_kind map;         /* height: 0.5 + h (float: h); normal: 0.5 n + 0.5 (tangent
                               * space, +y up); derivative: (dh/dx, dh/dy, 0), float */
    int y_down;               /* green = +y down (DirectX) */
    int bits;                 /* 8, 16, 32 (float), or 0: 8, float for a derivative map */
    const char *format;       /* OUT's format for "-" (as bgt_heightmap_opts) */
    int threads;              /* 0 = all cores */
} bgt_generate_opts;

/* The map spans one period in x and y (world size period / frequency), so it
 * tiles without a seam (generate.c). BG_ERR_INVALID_ARGUMENT for bad options
 * (no period along x or y, a VDB height, a size outside 1..65536); BG_ERR_IO or
 * BG_ERR_OUT_OF_MEMORY when the run fails. */
bg_status bgt_generate_run(const bgt_generate_opts *o, bgt_err *e);

#endif
