/* SPDX-License-Identifier: MIT */
/* The face of `bumpgrad volume` (volume.c, tools build only): a height
 * function and its gradient baked into an OpenVDB file. */
#ifndef BUMPGRAD_TOOLS_BAKE_VOLUME_H
#define BUMPGRAD_TOOLS_BAKE_VOLUME_H

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
    int brick, bricks;        /* bricks > 1: bake only brick `brick` (0..bricks-1) of the
                               * box: slabs along z on the 8-voxel leaf lattice, so bricks
                               * share no leaf; bg_vdb_merge of all bricks equals the
                               * whole bake voxel for voxel. The voxel limit is per brick */
    int threads;              /* 0 = all cores */
    const bgt_progress *progress; /* "baking rows", counted in rows of voxels; may be NULL */
} bgt_volume_opts;

typedef struct bgt_volume_result {
    uint64_t voxels;          /* active voxels written (height + gradient) */
    long long lo[3], hi[3];   /* index box of the voxel centres inside bbox (of this brick
                               * with bricks > 1; hi[2] < lo[2] for an empty brick) */
} bgt_volume_result;

/* Check the box, the band and the voxel count (at most 2^28 active voxels),
 * open the height, bake row by row in batches evaluated in parallel and write
 * the file (bg_vdb_writer: temp + rename). BG_ERR_INVALID_ARGUMENT for bad
 * parameters or too many voxels; BG_ERR_IO (file not written, the OpenVDB
 * module missing) or BG_ERR_OUT_OF_MEMORY when the run fails. */
bg_status bgt_volume_run(const bgt_volume_opts *o, bgt_volume_result *r, bgt_err *e);

#endif
