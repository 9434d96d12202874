/* SPDX-License-Identifier: MIT */
/**
 * @file volume.h
 * @brief Baked height volumes in OpenVDB files (libbumpgrad_io, C++ inside, C
 *        interface; tools only, not part of the core library).
 *
 * A baked volume holds a FloatGrid of heights and, optionally, a Vec3SGrid of
 * the volume gradient (world units, marked covariant). Voxel (i,j,k) sits at
 * world position origin + voxel_size * (i,j,k) (OpenVDB's cell-centred index
 * space with a uniform linear transform). Voxels not written are inactive and
 * read as the background value 0, so a narrow-band bake should be sampled only
 * well inside its band (at least one voxel from its edge).
 */
#ifndef BUMPGRAD_VOLUME_H
#define BUMPGRAD_VOLUME_H

#include <stdint.h>
#include "common.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- writing ------------------------------------------------------------- */

/** A grid pair being filled in memory; opaque. */
typedef struct bg_vdb_writer bg_vdb_writer;

/** Start a bake. `voxel_size` finite and > 0; `origin` (may be NULL for 0,0,0)
 *  is the world position of voxel (0,0,0). `height_name` (NULL: "height") and
 *  `gradient_name` (NULL: "gradient") name the grids; the gradient grid is
 *  written only if some voxel was added with a gradient.
 *  BG_ERR_INVALID_ARGUMENT, BG_ERR_OUT_OF_MEMORY, BG_OK, or BG_ERR_IO if the
 *  I/O module cannot be loaded (nothing is printed: bg_io_available in io.h
 *  gives the reason, and a program calls it before starting work). */
BG_API bg_status bg_vdb_writer_create(double voxel_size, const double origin[3],
                                      const char *height_name, const char *gradient_name,
                                      bg_vdb_writer **out);

/** Set active voxels (i[t], j[t], k[t]) to height[t] and, if gx is not NULL, the
 *  gradient (gx[t], gy[t], gz[t]), for t in [0, n). A voxel added twice keeps
 *  the last value. Not thread-safe on one writer: callers that evaluate in
 *  parallel add the results from one thread (e.g. slab by slab). */
BG_API bg_status bg_vdb_writer_add(bg_vdb_writer *w, const int32_t *i, const int32_t *j,
                                   const int32_t *k, size_t n, const float *height,
                                   const float *gx, const float *gy, const float *gz);

/** Attach a string metadata item to every grid written (e.g. the generator's
 *  parameters). */
BG_API bg_status bg_vdb_writer_set_meta(bg_vdb_writer *w, const char *key, const char *value);

/** Number of active height voxels so far. */
BG_API uint64_t bg_vdb_writer_voxel_count(const bg_vdb_writer *w);

/** Write the grids to `path` (a .vdb file) through a temporary file in the same
 *  folder renamed into place: a failure leaves no partial file and an old file
 *  untouched. BG_ERR_IO with a message naming the file on failure. The writer
 *  stays valid (it may be written again). */
BG_API bg_status bg_vdb_writer_write(const bg_vdb_writer *w, const char *path, char *err,
                                     size_t errlen);

BG_API void bg_vdb_writer_free(bg_vdb_writer *w);

/** Merge the grids of `n` VDB files baked on one voxel lattice (bricks of one
 *  volume, e.g. from `bumpgrad volume --brick I/N`) into `output`, with
 *  OpenVDB's tree merge (Tree::merge, MERGE_ACTIVE_STATES). Every file must
 *  hold the same grids (name and type) with the same transform and the same
 *  "bumpgrad:height" metadata, and the bricks must not share an active voxel
 *  (BG_ERR_INVALID_ARGUMENT: "the bricks overlap"). Each input is checked as
 *  bg_vdb_height_open checks a file; the output is written through a temporary
 *  renamed into place. BG_ERR_IO / BG_ERR_FORMAT with a message naming the file. */
BG_API bg_status bg_vdb_merge(const char *const *inputs, size_t n, const char *output, char *err,
                              size_t errlen);

/* ---- reading ------------------------------------------------------------- */

/** An opened FloatGrid used as a height field; opaque, immutable after open. */
typedef struct bg_vdb_height bg_vdb_height;

/** Open the FloatGrid `grid_name` of a .vdb file (NULL or "": the first FloatGrid
 *  in the file) and load it into memory. The whole file is read (every grid,
 *  no delayed loading) so that a file truncated or cut anywhere fails here,
 *  not while sampling; grids other than the chosen one are then dropped.
 *  Errors, each with a message
 *  naming the file and the grid: missing or unreadable file (BG_ERR_IO); not a
 *  VDB file, corrupt or truncated, no grid of that name, a grid of another
 *  type (e.g. a Vec3SGrid), no FloatGrid at all, or a non-linear (frustum)
 *  transform (BG_ERR_FORMAT). */
BG_API bg_status bg_vdb_height_open(const char *path, const char *grid_name, bg_vdb_height **out,
                                    char *err, size_t errlen);

BG_API void bg_vdb_height_close(bg_vdb_height *h);

/** Facts about an opened grid. */
typedef struct bg_vdb_height_info {
    double voxel_size[3];  /**< world size of a voxel along i, j, k */
    uint64_t active_voxels;
    int32_t index_min[3], index_max[3]; /**< bounding box of active voxels (inclusive);
                                             min > max for an empty grid */
    double world_min[3], world_max[3];  /**< world box of the active voxel centres */
    char name[128];                     /**< grid name (truncated) */
} bg_vdb_height_info;

BG_API void bg_vdb_height_get_info(const bg_vdb_height *h, bg_vdb_height_info *info);

/** Height and world-space volume gradient at n world positions (SoA).
 *  Height: trilinear interpolation of the voxel values. Gradient: central
 *  differences of that trilinear interpolant at +-half a voxel along each
 *  index axis, mapped to world space with the inverse-transpose Jacobian of
 *  the grid transform: exact for a field linear over the 3x3x3 voxels around
 *  the point, O(voxel^2) for a smooth one, and continuous where the plain
 *  derivative of the trilinear interpolant jumps at voxel faces.
 *  A position with a NaN/Inf coordinate gives NaN height and NaN gradient.
 *  `height` and/or gx,gy,gz may be NULL (gx,gy,gz are all NULL or all set).
 *  Thread-safe: concurrent calls on one handle are fine (each call uses its
 *  own accessor). The surface gradient is then g - n (n.g) (surfgrad.h, eq. 2). */
BG_API void bg_vdb_height_sample_batch(const bg_vdb_height *h, const float *px, const float *py,
                                       const float *pz, size_t n, float *height, float *gx,
                                       float *gy, float *gz);

#ifdef __cplusplus
}
#endif

#endif /* BUMPGRAD_VOLUME_H */
