/* SPDX-License-Identifier: MIT */
/* The face of `bumpgrad heightmap` (heightmap.c, tools build only): an image
 * into a tangent-space normal map, or a normal map into a derivative map. */
#ifndef BUMPGRAD_TOOLS_BAKE_HEIGHTMAP_H
#define BUMPGRAD_TOOLS_BAKE_HEIGHTMAP_H

#include "bumpgrad.h"
#include "common/tool.h"

/* ---- heightmap: image -> tangent-space normal map, or normal map -> derivative map ---- */
typedef enum bgt_gray { BGT_GRAY_SEED = 0, BGT_GRAY_REC709 = 1 } bgt_gray;

typedef struct bgt_heightmap_opts {
    const char *input, *output; /* any image OpenImageIO reads / writes; may be the same file */
    bgt_gray gray;              /* gray level of a colour input (from the stored values) */
    float strength;             /* slope factor S, finite (negative inverts bumps) */
    int wrap;                   /* neighbours beyond the border: 0 clamp, 1 wrap around */
    int y_down;                 /* green = +y down (DirectX) */
    int to_derivative;          /* input is a normal map 0.5*m+0.5; output (dh/du, dh/dv, 0) */
    int bits;                   /* 8, 16, 32 (float), or 0: 8, or float with to_derivative */
    const char *format;         /* OUT's format (an OpenImageIO name or extension: "png",
                                 * "exr", "tif", ...): for OUT "-" (NULL: PNG); with a file
                                 * its extension decides and a different format is refused */
    const char *input_format;   /* IN's reader (NULL: by extension and content; IN "-" by
                                 * content, and a content no reader claims is refused
                                 * asking for it) */
} bgt_heightmap_opts;

/* Read (bg_image_read_as), convert and write (bg_image_write_as: temp + rename,
 * or standard output). BG_ERR_INVALID_ARGUMENT or BG_ERR_FORMAT for bad input
 * (a depth the output format cannot store, a format against OUT's extension,
 * a format the stream cannot carry, a missing or unreadable input, a NaN/Inf
 * sample, a normal map with fewer than 3 channels, an output name without an
 * image format); BG_ERR_IO or BG_ERR_OUT_OF_MEMORY when the run fails. */
bg_status bgt_heightmap_run(const bgt_heightmap_opts *o, bgt_err *e);

#endif
