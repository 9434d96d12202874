/* SPDX-License-Identifier: MIT */
/* The one record order of the mesh tools' sorts (welding and edge matching in
 * mikktspace.c, UV islands in mesh_uv.c, the glTF vertex split in
 * mesh_gltf.c): records of uint32 keys, compared lexicographically. Each sort
 * ends its keys with a unique index, so qsort's order is fully determined. */
#ifndef BUMPGRAD_TOOLS_MESH_SORT_H
#define BUMPGRAD_TOOLS_MESH_SORT_H

#include <stdint.h>
#include <string.h>

static inline int mesh_keys_cmp(const uint32_t *x, const uint32_t *y, int n)
{
    for (int i = 0; i < n; i++)
        if (x[i] != y[i])
            return x[i] < y[i] ? -1 : 1;
    return 0;
}

/* A float as a key whose unsigned order is the float order (-0 = +0 as for
 * float ==; NaNs sort somewhere, callers that test equality compare floats). */
static inline uint32_t mesh_float_key(float f)
{
    if (f == 0.0f)
        f = 0.0f;
    uint32_t b;
    memcpy(&b, &f, sizeof b);
    return (b & 0x80000000u) ? ~b : b | 0x80000000u;
}

#endif
