/* SPDX-License-Identifier: MIT */
/* UV islands of a mesh (mesh_uv.h): triangles connected through edges whose
 * two end points have the same UVs (float ==) are one island, whatever the
 * vertex indices: an unwelded mesh (`--join never`) has the islands of its
 * welded version. */
#include "mesh/mesh_uv.h"

#include <stdlib.h>
#include <string.h>

typedef struct uvkey {
    float u, v;
    uint32_t corner;
} uvkey;

static int cmp_uv(const void *a, const void *b)
{
    const uvkey *x = a, *y = b;
    if (x->u != y->u)
        return x->u < y->u ? -1 : 1;
    if (x->v != y->v)
        return x->v < y->v ? -1 : 1;
    return (x->corner > y->corner) - (x->corner < y->corner);
}

typedef struct uvedge {
    uint32_t lo, hi, tri;
} uvedge;

static int cmp_edge(const void *a, const void *b)
{
    const uvedge *x = a, *y = b;
    if (x->lo != y->lo)
        return x->lo < y->lo ? -1 : 1;
    if (x->hi != y->hi)
        return x->hi < y->hi ? -1 : 1;
    return (x->tri > y->tri) - (x->tri < y->tri);
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
    uvkey *k = malloc(C * sizeof *k);
    uint32_t *id = malloc(C * sizeof *id);
    uvedge *e = malloc(C * sizeof *e);
    size_t n = (size_t)-1;
    if (!k || !id || !e)
        goto done;
    for (size_t c = 0; c < C; c++)
        k[c] = (uvkey){u[indices[c]], v[indices[c]], (uint32_t)c};
    qsort(k, C, sizeof *k, cmp_uv);
    uint32_t next = 0;
    for (size_t i = 0; i < C; i++) {
        /* NaN UVs equal nothing, so such corners stay apart */
        if (i > 0 && k[i].u == k[i - 1].u && k[i].v == k[i - 1].v)
            id[k[i].corner] = id[k[i - 1].corner];
        else
            id[k[i].corner] = next++;
    }
    for (size_t t = 0; t < triangle_count; t++) {
        island[t] = (uint32_t)t;
        for (int j = 0; j < 3; j++) {
            uint32_t a = id[3 * t + (size_t)j], b = id[3 * t + (size_t)((j + 1) % 3)];
            e[3 * t + (size_t)j] = (uvedge){a < b ? a : b, a < b ? b : a, (uint32_t)t};
        }
    }
    qsort(e, C, sizeof *e, cmp_edge);
    for (size_t i = 1; i < C; i++) {
        if (e[i].lo == e[i - 1].lo && e[i].hi == e[i - 1].hi && e[i].lo != e[i].hi) {
            uint32_t a = find(island, e[i].tri), b = find(island, e[i - 1].tri);
            if (a != b)
                island[a > b ? a : b] = a < b ? a : b;
        }
    }
    /* dense labels 0..n-1 in order of first triangle (roots first, as the
     * labels overwrite the forest) */
    for (size_t t = 0; t < triangle_count; t++)
        e[t].lo = find(island, (uint32_t)t);
    for (size_t t = 0; t < triangle_count; t++)
        id[t] = UINT32_MAX;
    n = 0;
    for (size_t t = 0; t < triangle_count; t++) {
        uint32_t r = e[t].lo;
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
