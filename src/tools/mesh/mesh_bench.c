/* SPDX-License-Identifier: MIT */
/* bgt_mesh_bake_dropped: the whole bake of a mesh without files, which the
 * whole-bake row of `bumpgrad bench` times (mesh.h). */
#include "mesh/mesh_internal.h"

static bg_status drop_tile(void *ctx, int udim, const bg_image *img, bgt_err *e)
{
    (void)ctx, (void)udim, (void)img, (void)e;
    return BG_OK;
}

bg_status bgt_mesh_bake_dropped(const bg_mesh *m, const float *nx, const float *ny,
                                const float *nz, const bgt_height *h, const mesh_bake_opts *o,
                                mesh_bake_stats *stats, bgt_err *e)
{
    return mesh_bake(m, nx, ny, nz, h, o, drop_tile, NULL, stats, e);
}
