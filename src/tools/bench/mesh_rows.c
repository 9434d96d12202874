/* SPDX-License-Identifier: MIT */
/* The mesh rows of `bumpgrad bench` (bench_internal.h): mikkTSpace tangents
 * of a generated UV sphere (triangles/s) and the whole normal-map bake of a
 * smaller one (texels/s), in memory, no file I/O. Each run is one whole call,
 * threaded inside (the row's thread count). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bench/bench_internal.h"
#include "mesh/mikktspace.h"
#ifdef BG_HAVE_TOOLS
#include "mesh/mesh.h"
#endif

/* A UV sphere of side x side quads, two triangles each (those at the poles
 * are degenerate, as in a sphere from a modelling tool): unit normals equal to
 * the positions, u around, v from pole to pole, the seam split. */
static int make_sphere(bench_mesh *bm, size_t side)
{
    size_t nv = (side + 1) * (side + 1), T = 2 * side * side;
    bm->vertex_count = nv;
    bm->triangle_count = T;
    bm->attr = malloc(8 * nv * sizeof *bm->attr);
    bm->indices = malloc(3 * T * sizeof *bm->indices);
    if (!bm->attr || !bm->indices)
        return -1;
    float *a = bm->attr;
    const double pi = 3.14159265358979323846;
    for (size_t r = 0; r <= side; r++)
        for (size_t s = 0; s <= side; s++) {
            size_t i = r * (side + 1) + s;
            double th = pi * (double)r / (double)side, ph = 2.0 * pi * (double)s / (double)side;
            double x = sin(th) * cos(ph), y = sin(th) * sin(ph), z = cos(th);
            if (s == side)
                x = sin(th), y = 0.0;
            if (r == 0 || r == side)
                x = y = 0.0;
            a[i] = a[3 * nv + i] = (float)x;
            a[nv + i] = a[4 * nv + i] = (float)y;
            a[2 * nv + i] = a[5 * nv + i] = (float)z;
            a[6 * nv + i] = (float)((double)s / (double)side);
            a[7 * nv + i] = (float)(1.0 - (double)r / (double)side);
        }
    uint32_t *ix = bm->indices;
    for (size_t r = 0; r < side; r++)
        for (size_t s = 0; s < side; s++) {
            uint32_t i0 = (uint32_t)(r * (side + 1) + s), i1 = i0 + 1;
            uint32_t i2 = i0 + (uint32_t)side + 1, i3 = i2 + 1;
            uint32_t q[6] = {i0, i2, i1, i1, i2, i3};
            memcpy(ix, q, sizeof q);
            ix += 6;
        }
    return 0;
}

double bench_mesh_bytes(int kernel)
{
    double side = kernel == K_MIKK ? BENCH_MIKK_SIDE : BENCH_BAKE_SIDE;
    double nv = (side + 1) * (side + 1), T = 2 * side * side;
    /* the sphere, the corner tangents, and mikkTSpace's own arrays (about
     * 140 bytes per triangle) */
    double bytes = nv * 32 + T * (12 + 48 + 140);
    if (kernel == K_MESH_BAKE)
        bytes += (double)BENCH_BAKE_TEXELS * BENCH_BAKE_TEXELS * 64;
    return bytes;
}

size_t bench_mesh_samples(int kernel)
{
    return kernel == K_MIKK ? 2 * (size_t)BENCH_MIKK_SIDE * BENCH_MIKK_SIDE
                            : (size_t)BENCH_BAKE_TEXELS * BENCH_BAKE_TEXELS;
}

int bench_mesh_init(bench_mesh *bm, int kernel)
{
    memset(bm, 0, sizeof *bm);
    bm->kernel = kernel;
    if (make_sphere(bm, kernel == K_MIKK ? BENCH_MIKK_SIDE : BENCH_BAKE_SIDE) != 0)
        goto fail;
    bm->tangents = malloc(12 * bm->triangle_count * sizeof *bm->tangents);
    if (!bm->tangents)
        goto fail;
    return 0;
fail:
    bench_mesh_free(bm);
    return -1;
}

void bench_mesh_free(bench_mesh *bm)
{
    free(bm->attr);
    free(bm->indices);
    free(bm->tangents);
    memset(bm, 0, sizeof *bm);
}

/* One run: the whole call on j->threads threads. A failure (out of memory)
 * is kept in bm->status for the caller to report. */
void bench_mesh_run(const bench_job *j)
{
    bench_mesh *bm = j->mesh;
    size_t nv = bm->vertex_count;
    float *a = bm->attr;
    if (bm->status != BG_OK)
        return;
    if (bm->kernel == K_MIKK) {
        bgt_mikk_mesh mm = {nv, bm->triangle_count, bm->indices, a, a + nv, a + 2 * nv,
                            a + 3 * nv, a + 4 * nv, a + 5 * nv, a + 6 * nv, a + 7 * nv};
        bm->status = bgt_mikk_tangents_threads(&mm, bm->tangents, NULL, j->threads);
        return;
    }
#ifdef BG_HAVE_TOOLS
    bg_mesh m;
    memset(&m, 0, sizeof m);
    m.vertex_count = nv;
    m.triangle_count = bm->triangle_count;
    m.px = a, m.py = a + nv, m.pz = a + 2 * nv;
    m.nx = a + 3 * nv, m.ny = a + 4 * nv, m.nz = a + 5 * nv;
    m.u = a + 6 * nv, m.v = a + 7 * nv;
    m.indices = bm->indices;
    bgt_height h;
    bgt_height_init(&h);
    mesh_bake_opts o;
    memset(&o, 0, sizeof o);
    o.width = o.height = BENCH_BAKE_TEXELS;
    o.space = MESH_BAKE_TANGENT;
    o.padding = 16;
    o.method = BG_PERTURB_SURFGRAD;
    o.threads = j->threads;
    o.tangents = MESH_TANGENTS_MIKK;
    o.filter = MESH_FILTER_FOOTPRINT;
    mesh_bake_stats st;
    bgt_err e;
    bm->status = bgt_height_open(&h, &e);
    if (bm->status == BG_OK)
        bm->status = bgt_mesh_bake_dropped(&m, m.nx, m.ny, m.nz, &h, &o, &st, &e);
    bgt_height_close(&h);
#else
    bm->status = BG_ERR_INVALID_ARGUMENT;
#endif
}
