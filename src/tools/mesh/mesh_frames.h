/* SPDX-License-Identifier: MIT */
/* Vertex normals and triangle checks of a loaded mesh (mesh_frames.c), shared
 * by the mesh tool and `render --mesh`. Tools build only. */
#ifndef BUMPGRAD_TOOLS_MESH_FRAMES_H
#define BUMPGRAD_TOOLS_MESH_FRAMES_H

#include <stddef.h>
#include "bumpgrad/mesh.h"

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

/* Tangent frames: per corner, in the mikkTSpace convention (mikktspace.h,
 * bgt_mikk_tangents); the bake and the glTF output use them. */
/* Signed UV area (twice) of triangle t: > 0 keeps orientation, < 0 mirrors. */
double mesh_uv_signed_area(const bg_mesh *m, size_t t);

/* ---- the model frame: one unit convention for `mesh` and `render --mesh` ----
 * A point p of the file is at (p - c) / r in the model frame, with c the
 * centre of the bounding box of the finite vertices and r the radius of the
 * sphere about c through the farthest of them (mesh_bounding_sphere): the
 * model scaled into the unit sphere. --frequency and --amplitude then count
 * per model radius, whatever the file's units. */
double mesh_bounding_sphere(const bg_mesh *bm, double c[3]);
static inline float mesh_model_coord(float p, double c, double r)
{
    return (float)((p - c) / r);
}

#endif
