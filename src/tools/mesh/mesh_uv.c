/* SPDX-License-Identifier: MIT */
/* UV islands of a mesh (mesh_uv.h): triangles connected through edges whose
 * two end points have the same UVs (float ==) are one island, whatever the
 * vertex indices: an unwelded mesh (`--join never`) has the islands of its
 * welded version. */
#include "mesh/mesh_uv.h"

#include <stdlib.h>
#include <string.h>
#include "mesh/mesh_sort.h"

/* Both sorts sort three keys: corners by (u key, v key, corner), edges by
 * (lower UV id, higher UV id, triangle). */
typedef struct key3 {
    uint32_t k[3];
} key3;

static int cmp_keys3(const void *a, const void *b)
{
    return mesh_keys_cmp(((const key3 *)a)->k, ((const key3 *)b)->k, 3);
}

static uint32_t find(uint32_t *p, uint32_t i)
{
    while (p[i] != i) {
        p[i] = p[p[i]];
        i = p[i];
    }
    return i;
}

size_t mesh_uv_islands(size_t triangle_count, const uint32_t *indices, const float *u,
                       const float *v, uint32_t *island)
{
    size_t C = 3 * triangle_count;
    if (triangle_count == 0)
        return 0;
    key3 *k = malloc(C * sizeof *k);
    uint32_t *id = malloc(C * sizeof *id);
    key3 *e = malloc(C * sizeof *e);
    size_t n = (size_t)-1;
    if (!k || !id || !e)
        goto done;
    for (size_t c = 0; c < C; c++)
        k[c] = (key3){{mesh_float_key(u[indices[c]]), mesh_float_key(v[indices[c]]), (uint32_t)c}};
    qsort(k, C, sizeof *k, cmp_keys3);
    uint32_t next = 0;
    for (size_t i = 0; i < C; i++) {
        /* NaN UVs equal nothing, so such corners stay apart */
        uint32_t a = indices[k[i].k[2]], b = i > 0 ? indices[k[i - 1].k[2]] : 0;
        if (i > 0 && u[a] == u[b] && v[a] == v[b])
            id[k[i].k[2]] = id[k[i - 1].k[2]];
        else
            id[k[i].k[2]] = next++;
    }
    for (size_t t = 0; t < triangle_count; t++) {
        island[t] = (uint32_t)t;
        for (int j = 0; j < 3; j++) {
            uint32_t a = id[3 * t + (size_t)j], b = id[3 * t + (size_t)((j + 1) % 3)];
            e[3 * t + (size_t)j] = (key3){{a < b ? a : b, a < b ? b : a, (uint32_t)t}};
        }
    }
    qsort(e, C, sizeof *e, cmp_keys3);
    for (size_t i = 1; i < C; i++) {
        if (mesh_keys_cmp(e[i].k, e[i - 1].k, 2) == 0 && e[i].k[0] != e[i].k[1]) {
            uint32_t a = find(island, e[i].k[2]), b = find(island, e[i - 1].k[2]);
            if (a != b)
                island[a > b ? a : b] = a < b ? a : b;
        }
    }
    /* dense labels 0..n-1 in order of first triangle (roots first, as the
     * labels overwrite the forest) */
    for (size_t t = 0; t < triangle_count; t++)
        e[t].k[0] = find(island, (uint32_t)t);
    for (size_t t = 0; t < triangle_count; t++)
        id[t] = UINT32_MAX;
    n = 0;
    for (size_t t = 0; t < triangle_count; t++) {
        uint32_t r = e[t].k[0];
        if (id[r] == UINT32_MAX)
            id[r] = (uint32_t)n++;
        island[t] = id[r];
    }
done:
    free(k);
    free(id);
    free(e);
    return n;
}
