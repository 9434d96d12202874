/* SPDX-License-Identifier: MIT */
/* The face of the points tools, `bumpgrad eval` and `perturb`: stream a table
 * of points (CSV or .npy) through the library in constant memory and write a
 * table of results (CSV or .npy), through the safe file writer. */
#ifndef BUMPGRAD_TOOLS_POINTS_H
#define BUMPGRAD_TOOLS_POINTS_H

#include "bumpgrad.h"
#include "common/tool.h"
#include "height_source.h"

/* A row range of a .npy input (`--rows A:B`): rows begin..end-1 only, the
 * output holding just those rows, so a big table splits into jobs whose
 * outputs, concatenated in order, equal the whole run's. */
typedef struct bgt_row_range {
    int have;
    size_t begin, end; /* end: SIZE_MAX for "to the last row" */
} bgt_row_range;

/* What a run saw (optional): rows is updated before each progress update. */
typedef struct bgt_points_stats {
    size_t rows;
    size_t inward;       /* perturb: rows with dot(n', n) <= 0 */
    int grid;            /* perturb with a VDB height: in_grid and grid_box are set */
    size_t in_grid;      /* rows inside the grid's active box (one voxel of margin) */
    double grid_box[6];  /* world box of the active voxel centres, min then max */
} bgt_points_stats;

typedef struct bgt_eval_opts {
    const char *input, *output; /* "-": standard input / output */
    bg_fractal fractal;
    bg_domain domain; /* periods and seed (noise.h); zero: Perlin's lattice */
    int central;   /* central differences (step) instead of the analytic gradient */
    int dbl;       /* double precision entry points */
    double step;   /* central step, > 0 */
    int threads;   /* 0: all cores */
    int allow_nonfinite;
    bgt_row_range rows; /* .npy input only */
    const bgt_progress *progress; /* counts input bytes (total: the file size, 0 for a pipe) */
    bgt_points_stats *stats;      /* may be NULL */
} bgt_eval_opts;

/* Columns x,y,z in; x,y,z,value,dx,dy,dz out (%.9g float, %.17g double: both
 * round-trip exactly). Errors name FILE:LINE:COLUMN. */
bg_status bgt_eval_run(const bgt_eval_opts *o, bgt_err *e);

typedef struct bgt_perturb_opts {
    const char *input, *output;
    const bgt_height *height; /* the height parameters, NOT opened: bgt_perturb_run
                                 opens it (bgt_height_open) and closes it */
    bg_perturb_method method;
    int threads;
    int allow_nonfinite;
    bgt_row_range rows; /* .npy input only */
    const bgt_progress *progress; /* as for eval */
    bgt_points_stats *stats;      /* may be NULL */
} bgt_perturb_opts;

/* Columns x,y,z,nx,ny,nz in; x,y,z,nx,ny,nz,height,px,py,pz,inward out. */
bg_status bgt_perturb_run(const bgt_perturb_opts *o, bgt_err *e);

#endif
