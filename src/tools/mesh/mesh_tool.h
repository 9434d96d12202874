/* SPDX-License-Identifier: MIT */
/* Internal interface of `bumpgrad mesh` (cmd_mesh.c): mesh-level vertex
 * normals and tangents (mesh_frames.c), the PLY writer (mesh_ply.c) and the
 * UV-space normal-map baker (mesh_bake.c). Tools build only. */
#ifndef BUMPGRAD_TOOLS_MESH_TOOL_H
#define BUMPGRAD_TOOLS_MESH_TOOL_H

#include <stddef.h>
#include <stdint.h>
#include "bumpgrad/image.h"
#include "bumpgrad/mesh.h"
#include "cli.h"

/* ---- degenerate input ----
 * A triangle is "unusable" when an index repeats, a corner position is NaN/Inf,
 * or its area is zero (the cross product of its edges is 0 in double). Unusable
 * triangles add nothing to vertex normals, tangents or the bake; they stay in
 * the output PLY as they were. */
int mesh_triangle_usable(const bg_mesh *m, size_t t);

/* Normalize the normals in place with the rule of surfgrad.h: a zero or
 * non-finite normal becomes (0,0,0), the "no normal" sentinel. Returns how
 * many sentinels there are. */
size_t mesh_normalize_normals(size_t n, float *nx, float *ny, float *nz);

/* Angle-weighted vertex normals (Thürmer and Wüthrich 1998): the sum over the
 * usable triangles around a vertex of (corner angle) * (unit face normal),
 * normalized. Face normals follow the winding (counter-clockwise = front).
 * A vertex with no usable triangle gets the (0,0,0) sentinel. Returns the
 * number of sentinels, or (size_t)-1 when out of memory. */
size_t mesh_vertex_normals(const bg_mesh *m, float *nx, float *ny, float *nz);

/* Per-vertex tangents from UV set 0 in the mikkTSpace convention (see
 * docs/MESH.md): per triangle the direction of dP/du, projected onto each
 * corner's normal plane, normalized and weighted by the corner angle, summed
 * per vertex, then Gram-Schmidt against the vertex normal. Triangles whose UV
 * map mirrors (negative signed UV area) are accumulated apart from the others,
 * as mikkTSpace splits vertices by handedness: frame[0] is for sign +1,
 * frame[1] for sign -1, and the bitangent is sign * cross(n, t). A vertex
 * whose accumulated tangent vanishes gets a fixed unit vector orthogonal to n. */
typedef struct mesh_tangents {
    float *t[2][3]; /* t[s][axis][vertex]: unit tangents for sign +1 (s=0) and -1 (s=1) */
} mesh_tangents;
/* 0, or CLI_FAIL when out of memory (after printing). m->u/m->v must be set. */
int mesh_vertex_tangents(const char *cmd, const bg_mesh *m, const float *nx, const float *ny,
                         const float *nz, mesh_tangents *out);
void mesh_tangents_free(mesh_tangents *t);
/* Signed UV area (twice) of triangle t: > 0 keeps orientation, < 0 mirrors. */
double mesh_uv_signed_area(const bg_mesh *m, size_t t);

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

/* ---- normal-map bake ---- */
typedef enum mesh_bake_space { MESH_BAKE_TANGENT = 0, MESH_BAKE_OBJECT = 1 } mesh_bake_space;
typedef struct mesh_bake_opts {
    int width, height;
    mesh_bake_space space;
    int padding;
    bg_perturb_method method;
    int threads;
} mesh_bake_opts;
typedef struct mesh_bake_stats {
    size_t covered;      /* texels inside some triangle */
    size_t padded;       /* texels filled by the dilation */
    size_t skipped;      /* unusable triangles or triangles with zero / non-finite UV area */
} mesh_bake_stats;
/* Rasterize the mesh in UV space into `img` (allocated here, 3 channels,
 * encoded 0.5 * m + 0.5). `nx/ny/nz` are the unit vertex normals. 0 or
 * CLI_FAIL (out of memory, printed). */
int mesh_bake(const char *cmd, const bg_mesh *m, const float *nx, const float *ny,
              const float *nz, const cli_height *h, const mesh_bake_opts *o, bg_image *img,
              mesh_bake_stats *stats);

#endif
