/* SPDX-License-Identifier: MIT */
/* UV islands (mesh_uv.c), for the overlap report of the bake. */
#ifndef BUMPGRAD_TOOLS_MESH_UV_H
#define BUMPGRAD_TOOLS_MESH_UV_H

#include <stddef.h>
#include <stdint.h>

/* Label each triangle with its UV island (0..n-1, numbered in order of each
 * island's first triangle): triangles sharing an edge whose end points have
 * equal UVs are one island. Returns n, or (size_t)-1 when out of memory. */
size_t mesh_uv_islands(size_t triangle_count, const uint32_t *indices, const float *u,
                       const float *v, uint32_t *island);

#endif
