/* SPDX-License-Identifier: MIT */
/* The mesh tool's pieces (its face is mesh.h): the PLY writer (mesh_ply.c),
 * the UV-space normal-map baker (mesh_bake.c), the output formats and the
 * path checks of bgt_mesh_run (mesh_job.c). Included only by the files of
 * src/tools/mesh/. Tools build only. */
#ifndef BUMPGRAD_TOOLS_MESH_INTERNAL_H
#define BUMPGRAD_TOOLS_MESH_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include "mesh/mesh.h"
#include "mesh/mesh_frames.h"

/* ---- PLY output ---- */
typedef struct mesh_ply_out {
    size_t vertex_count, triangle_count;
    const float *px, *py, *pz;
    const float *nx, *ny, *nz;    /* perturbed unit normal */
    const float *ox, *oy, *oz;    /* original unit normal */
    const float *height;
    const float *compare;         /* NULL, or the surfgrad/additive angle (degrees) */
    const float *u, *v;           /* NULL when the mesh has no UVs */
    const uint32_t *indices;
    const char *comment;          /* one header comment line, or NULL */
    int ascii;
} mesh_ply_out;
/* Write the PLY into an open stream. 0, or nonzero on a write error. */
int mesh_ply_write(FILE *fp, const mesh_ply_out *d);

/* Receives each finished tile (3 channels, encoded 0.5 * m + 0.5), in UDIM
 * order; the image is freed after the call. A status other than BG_OK stops
 * the bake and is returned. */
typedef bg_status (*mesh_bake_sink)(void *ctx, int udim, const bg_image *img, bgt_err *e);
/* Rasterize the mesh in UV space, one tile after the other (tile (a, b)
 * holds u in [a, a + 1], v in [b, b + 1]; the tangent frames are computed once
 * from the unshifted UVs). `nx/ny/nz` are the unit vertex normals; `h` is
 * opened. BG_OK; BG_ERR_INVALID_ARGUMENT when a tile's memory exceeds the cap
 * (bgt_check_alloc) or the UVs span more than MESH_UDIM_MAX_TILES tiles;
 * BG_ERR_OUT_OF_MEMORY (also for more than INT32_MAX triangles); or the
 * sink's status; with a message in *e. */
bg_status mesh_bake(const bg_mesh *m, const float *nx, const float *ny, const float *nz,
                    const bgt_height *h, const mesh_bake_opts *o, mesh_bake_sink sink,
                    void *sink_ctx, mesh_bake_stats *stats, bgt_err *e);
/* The tangent frame of every corner (4 floats: xyz and the bitangent sign)
 * that a tangent-space bake with `o` encodes in: the file's per-vertex frames
 * (o->tangents == MESH_TANGENTS_FILE) or mikkTSpace's of the unit vertex
 * normals nx..nz. *ctan (malloc'd) stays NULL in object space. */
bg_status mesh_bake_corner_tangents(const bg_mesh *m, const float *nx, const float *ny,
                                    const float *nz, const mesh_bake_opts *o, float **ctan,
                                    mesh_bake_stats *stats, bgt_err *e);
/* The bytes a W x H tile needs while baking (per-texel buffers + the image). */
double mesh_bake_tile_bytes(int width, int height);

/* Mesh output formats, chosen by OUT's extension (case-insensitive); "-" and
 * a device (/dev/null, a FIFO) get PLY. */
typedef enum mesh_out_format {
    MESH_OUT_PLY = 0,
    MESH_OUT_GLB = 1,  /* binary glTF 2.0 (mesh_gltf.c), TANGENT when IN has UVs */
    MESH_OUT_GLTF = 2, /* glTF 2.0 with the buffer embedded */
    MESH_OUT_OBJ = 3,  /* Wavefront OBJ without a material file (assimp's exporter) */
    MESH_OUT_UNKNOWN = -1
} mesh_out_format;
mesh_out_format mesh_out_format_of(const char *path);
const char *mesh_out_format_name(mesh_out_format f, int ascii);

/* The checks on the paths of `o` that bgt_mesh_run makes before anything else
 * (so a caller may make them before its own preparations, e.g. opening the
 * height): one file named for OUT.ply and the map; OUT.ply over a non-PLY
 * input; a map path that exists and is not a regular file. BG_OK or
 * BG_ERR_INVALID_ARGUMENT. */
bg_status bgt_mesh_check(const bgt_mesh_opts *o, bgt_err *e);

#endif
