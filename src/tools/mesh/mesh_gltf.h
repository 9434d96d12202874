/* SPDX-License-Identifier: MIT */
/* glTF 2.0 output of `bumpgrad mesh` (mesh_gltf.c). */
#ifndef BUMPGRAD_TOOLS_MESH_GLTF_H
#define BUMPGRAD_TOOLS_MESH_GLTF_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include "common/tool.h"

typedef struct mesh_gltf_in {
    size_t vertex_count, triangle_count;
    const float *px, *py, *pz;
    const float *nx, *ny, *nz;     /* unit normals, or the (0,0,0) sentinel */
    const float *u, *v;            /* NULL: no TEXCOORD_0 */
    const float *corner_tangents;  /* 4 per corner (bgt_mikk_tangents), NULL: no TANGENT */
    const uint32_t *indices;
    const char *generator;         /* asset.generator, plain ASCII without quotes */
} mesh_gltf_in;

/* Write a .glb (binary != 0) or a .gltf with an embedded buffer into an open
 * stream. BG_OK, BG_ERR_IO (write error), BG_ERR_OUT_OF_MEMORY or
 * BG_ERR_INVALID_ARGUMENT (too large for the format), with *e set. */
bg_status mesh_gltf_write(FILE *fp, int binary, const mesh_gltf_in *d, bgt_err *e);

#endif
