/* SPDX-License-Identifier: MIT */
/* Bakes of the tools library (tools build only): a height function and its
 * gradient into an OpenVDB file (volume.c, behind `bumpgrad volume`), and an
 * image into a normal map or a normal map into a derivative map (heightmap.c,
 * behind `bumpgrad heightmap`). */
#ifndef BUMPGRAD_TOOLS_BAKE_H
#define BUMPGRAD_TOOLS_BAKE_H

#include <stdint.h>
#include "bumpgrad.h"
#include "common/tool.h"
#include "height_source.h"

/* ---- volume: FloatGrid "height" + Vec3SGrid "gradient" ---- */
typedef struct bgt_volume_opts {
    const bgt_height *height; /* the height parameters, NOT opened (a grid is refused):
                               * bgt_volume_run opens and closes its own copy */
    const char *output;       /* FILE.vdb, written through a temporary + rename */
    double bbox[6];           /* X0,Y0,Z0,X1,Y1,Z1: the voxels whose centre is inside */
    double voxel;             /* voxel edge, finite and > 0; voxel (i,j,k) is at S*(i,j,k) */
    int have_band;            /* nonzero: only the narrow band of band[] */
    double band[5];           /* CX,CY,CZ,R,W: voxels with | |p - C| - R | <= W */
    int threads;              /* 0 = all cores */
    const bgt_progress *progress; /* "baking rows", counted in rows of voxels; may be NULL */
} bgt_volume_opts;

typedef struct bgt_volume_result {
    uint64_t voxels;          /* active voxels written (height + gradient) */
    long long lo[3], hi[3];   /* index box of the voxel centres inside bbox */
} bgt_volume_result;

/* Check the box, the band and the voxel count (at most 2^28 active voxels),
 * open the height, bake row by row in batches evaluated in parallel and write
 * the file (bg_vdb_writer: temp + rename). BG_ERR_INVALID_ARGUMENT for bad
 * parameters or too many voxels; BG_ERR_IO (file not written, the OpenVDB
 * module missing) or BG_ERR_OUT_OF_MEMORY when the run fails. */
bg_status bgt_volume_run(const bgt_volume_opts *o, bgt_volume_result *r, bgt_err *e);

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
