/* SPDX-License-Identifier: MIT */
/* bgt_mikk_tangents_threads gives the same bytes and stats on any thread
 * count (src/tools/mesh/mikktspace.c works per welded vertex in parallel).
 * The mesh exercises every path: a UV sphere with degenerate triangles at the
 * poles and scattered ones, a mirrored half (fans of both orientations),
 * zero-UV-area triangles (the serial path of their vertices; a column of
 * them between the halves, where the fans of both orientations compete for
 * them), jittered
 * positions, and an unwelded copy (one vertex per corner, in reverse order). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/check.h"
#include "mesh/mikktspace.h"

enum { SIDE = 96 };

static uint32_t hash32(uint32_t x)
{
    x ^= x >> 16, x *= 0x7feb352du, x ^= x >> 15, x *= 0x846ca68bu, x ^= x >> 16;
    return x;
}

typedef struct mesh {
    size_t nv, nt;
    float *a; /* px py pz nx ny nz u v, nv each */
    uint32_t *ix;
} mesh;

static bgt_mikk_mesh view(const mesh *m)
{
    const float *a = m->a;
    size_t n = m->nv;
    return (bgt_mikk_mesh){n,         m->nt,     m->ix,     a,         a + n,    a + 2 * n,
                           a + 3 * n, a + 4 * n, a + 5 * n, a + 6 * n, a + 7 * n};
}

static int make_sphere(mesh *m)
{
    size_t n = (SIDE + 1) * (SIDE + 1);
    m->nv = n, m->nt = 2 * SIDE * SIDE;
    m->a = malloc(8 * n * sizeof *m->a);
    m->ix = malloc(3 * m->nt * sizeof *m->ix);
    if (!m->a || !m->ix)
        return -1;
    for (uint32_t r = 0; r <= SIDE; r++)
        for (uint32_t s = 0; s <= SIDE; s++) {
            uint32_t i = r * (SIDE + 1) + s;
            const double pi = 3.14159265358979323846;
            double th = pi * r / SIDE, ph = 2.0 * pi * s / SIDE;
            double x = sin(th) * cos(ph), y = sin(th) * sin(ph), z = cos(th);
            if (r == 0 || r == SIDE)
                x = y = 0.0;
            double rad = 1.0 + 0.002 * ((hash32(i) & 1023) / 1023.0 - 0.5);
            double u = (double)s / SIDE, v = (double)r / SIDE;
            if (s > SIDE / 2)
                u = 1.0 - u; /* mirrored half */
            if (s == SIDE / 2 + 1)
                u = 0.5; /* a column of zero-UV-area triangles between the halves */
            if ((hash32(7 * i) & 31) == 0)
                v = 0.5; /* some triangles lose their UV area */
            float f[8] = {(float)(x * rad), (float)(y * rad), (float)(z * rad), (float)x,
                          (float)y,         (float)z,         (float)u,         (float)v};
            for (int k = 0; k < 8; k++)
                m->a[k * n + i] = f[k];
        }
    uint32_t *ix = m->ix;
    for (uint32_t r = 0; r < SIDE; r++)
        for (uint32_t s = 0; s < SIDE; s++) {
            uint32_t i0 = r * (SIDE + 1) + s, i1 = i0 + 1, i2 = i0 + SIDE + 1, i3 = i2 + 1;
            int deg = (hash32(i0 * 3 + 1) & 63) == 0;
            uint32_t q[6] = {i0, i2, deg ? i0 : i1, i1, i2, i3};
            memcpy(ix, q, sizeof q);
            ix += 6;
        }
    return 0;
}

/* One vertex per corner, the corners' vertices in reverse order. */
static int unweld(const mesh *m, mesh *o)
{
    size_t n = 3 * m->nt;
    o->nv = n, o->nt = m->nt;
    o->a = malloc(8 * n * sizeof *o->a);
    o->ix = malloc(n * sizeof *o->ix);
    if (!o->a || !o->ix)
        return -1;
    for (size_t c = 0; c < n; c++) {
        size_t d = n - 1 - c;
        for (int k = 0; k < 8; k++)
            o->a[k * n + d] = m->a[k * m->nv + m->ix[c]];
        o->ix[c] = (uint32_t)d;
    }
    return 0;
}

static void check_threads(const char *name, const mesh *m, int want_zero_area)
{
    bgt_mikk_mesh mm = view(m);
    size_t bytes = 12 * m->nt * sizeof(float);
    float *one = malloc(bytes), *many = malloc(bytes);
    CHECK(one && many, "%s: out of memory", name);
    if (!one || !many)
        goto done;
    bgt_mikk_stats s1, sn;
    CHECK(bgt_mikk_tangents_threads(&mm, one, &s1, 1) == BG_OK, "%s: 1 thread", name);
    CHECK(s1.degenerate > 0 && (s1.zero_uv_area > 0) == want_zero_area && s1.fans > 0,
          "%s: the mesh misses a path (degenerate %zu, zero UV area %zu, fans %zu)", name,
          s1.degenerate, s1.zero_uv_area, s1.fans);
    static const int counts[] = {2, 3, 7, 0};
    for (size_t k = 0; k < sizeof counts / sizeof *counts; k++) {
        memset(many, 0xff, bytes);
        CHECK(bgt_mikk_tangents_threads(&mm, many, &sn, counts[k]) == BG_OK, "%s: %d threads",
              name, counts[k]);
        CHECK(memcmp(one, many, bytes) == 0, "%s: %d threads give other bytes than 1", name,
              counts[k]);
        CHECK(memcmp(&s1, &sn, sizeof s1) == 0, "%s: %d threads give other stats", name,
              counts[k]);
    }
    /* bgt_mikk_tangents is the all-cores call */
    CHECK(bgt_mikk_tangents(&mm, many, NULL) == BG_OK && memcmp(one, many, bytes) == 0,
          "%s: bgt_mikk_tangents differs", name);
done:
    free(one);
    free(many);
}

int main(void)
{
    mesh m = {0}, u = {0};
    if (make_sphere(&m) != 0 || unweld(&m, &u) != 0) {
        fprintf(stderr, "test_mikk_threads: out of memory\n");
        return 1;
    }
    check_threads("sphere", &m, 1);
    check_threads("unwelded sphere", &u, 1);
    /* without zero-UV-area triangles every vertex takes the parallel path */
    for (size_t i = 0; i < m.nv; i++) {
        size_t s = i % (SIDE + 1);
        m.a[6 * m.nv + i] = (float)((double)(s > SIDE / 2 ? SIDE - s : s) / SIDE);
        m.a[7 * m.nv + i] = (float)((double)(i / (SIDE + 1)) / SIDE);
    }
    check_threads("sphere, all UV areas nonzero", &m, 0);
    free(m.a), free(m.ix), free(u.a), free(u.ix);
    return check_summary("test_mikk_threads");
}
