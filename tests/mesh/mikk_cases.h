/* SPDX-License-Identifier: MIT */
/* The small meshes of test_mikk.c, one per rule of the mikkTSpace algorithm
 * (src/tools/mesh/mikktspace.h). Built by code so that the numbers are
 * reproducible anywhere; mikk_expected.h holds the reference's tangents for
 * exactly these meshes (see its provenance comment). */
#ifndef BUMPGRAD_TESTS_MIKK_CASES_H
#define BUMPGRAD_TESTS_MIKK_CASES_H

#include <math.h>
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define MC_MAXV 256
#define MC_MAXT 256

typedef struct mc_mesh {
    const char *name;
    size_t nv, nt;
    float px[MC_MAXV], py[MC_MAXV], pz[MC_MAXV];
    float nx[MC_MAXV], ny[MC_MAXV], nz[MC_MAXV];
    float u[MC_MAXV], v[MC_MAXV];
    uint32_t ix[3 * MC_MAXT];
} mc_mesh;

/* A vertex on the bumpy surface z = 0.3 sin(1.3 x) cos(0.9 y) with its unit
 * normal, and the given UV. */
static uint32_t mc_vert(mc_mesh *m, double x, double y, double u, double v)
{
    double z = 0.3 * sin(1.3 * x) * cos(0.9 * y);
    double zx = 0.39 * cos(1.3 * x) * cos(0.9 * y), zy = -0.27 * sin(1.3 * x) * sin(0.9 * y);
    double l = sqrt(zx * zx + zy * zy + 1.0);
    size_t i = m->nv++;
    m->px[i] = (float)x, m->py[i] = (float)y, m->pz[i] = (float)z;
    m->nx[i] = (float)(-zx / l), m->ny[i] = (float)(-zy / l), m->nz[i] = (float)(1.0 / l);
    m->u[i] = (float)u, m->v[i] = (float)v;
    return (uint32_t)i;
}

static void mc_tri(mc_mesh *m, uint32_t a, uint32_t b, uint32_t c)
{
    m->ix[3 * m->nt] = a, m->ix[3 * m->nt + 1] = b, m->ix[3 * m->nt + 2] = c;
    m->nt++;
}

/* n x n grid of vertices over [0,2]^2 split into counter-clockwise triangles,
 * alternating diagonals; UV = f(x, y) given by mode:
 *  0: rotated by 0.4 rad and scaled, 1: mirrored at x = 1 (u = |x - 1|),
 *  2: like 0 with vertex 6's UV replaced by vertex 2's. */
static void mc_grid(mc_mesh *m, int n, int mode)
{
    uint32_t id[8][8];
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double x = 2.0 * i / (n - 1), y = 2.0 * j / (n - 1);
            double u = 0.3 * (cos(0.4) * x - sin(0.4) * y) + 0.5;
            double v = 0.25 * (sin(0.4) * x + cos(0.4) * y) + 0.1;
            if (mode == 1)
                u = 0.4 * fabs(x - 1.0) + 0.1, v = 0.3 * y + 0.1;
            id[j][i] = mc_vert(m, x, y, u, v);
        }
    for (int j = 0; j + 1 < n; j++)
        for (int i = 0; i + 1 < n; i++) {
            uint32_t a = id[j][i], b = id[j][i + 1], c = id[j + 1][i + 1], d = id[j + 1][i];
            if ((i + j) & 1)
                mc_tri(m, a, b, c), mc_tri(m, a, c, d);
            else
                mc_tri(m, a, b, d), mc_tri(m, b, c, d);
        }
    if (mode == 2) {
        /* in a 4 x 4 grid, give vertex 6 the UV of vertex 2: triangles 2
         * (1, 2, 6) and 4 (2, 3, 6) get exactly zero UV area (in float and in
         * double), so vertex 2, which only they use, has no fan at all, and
         * vertices 1, 3 and 6 have fans that zero-area triangles join */
        m->u[6] = m->u[2];
        m->v[6] = m->v[2];
    }
}

/* Every corner its own vertex (the numbers unchanged). */
static void mc_unweld(mc_mesh *m)
{
    mc_mesh w = *m;
    w.nv = 3 * m->nt;
    for (size_t c = 0; c < 3 * m->nt; c++) {
        uint32_t i = m->ix[c];
        w.px[c] = m->px[i], w.py[c] = m->py[i], w.pz[c] = m->pz[i];
        w.nx[c] = m->nx[i], w.ny[c] = m->ny[i], w.nz[c] = m->nz[i];
        w.u[c] = m->u[i], w.v[c] = m->v[i];
        w.ix[c] = (uint32_t)c;
    }
    *m = w;
}

enum { MC_CURVED, MC_UNWELDED, MC_MIRRORED, MC_ALTERNATING, MC_SPLIT_FAN, MC_ZERO_UV, MC_COUNT };

static void mc_build(int id, mc_mesh *m)
{
    memset(m, 0, sizeof *m);
    switch (id) {
    case MC_CURVED: /* a plain welded patch: fans of 1..6 triangles */
        m->name = "curved";
        mc_grid(m, 4, 0);
        break;
    case MC_UNWELDED: /* the same patch, one vertex per corner: welding must undo it */
        mc_grid(m, 4, 0);
        mc_unweld(m);
        m->name = "unwelded";
        break;
    case MC_MIRRORED: /* u mirrored at x = 1, the seam vertices shared: sign -1 on the left */
        m->name = "mirrored";
        mc_grid(m, 5, 1);
        break;
    case MC_ALTERNATING: {
        /* 6 triangles around a centre whose UV orientation alternates: at the
         * centre and at every rim vertex each triangle is a fan of its own */
        m->name = "alternating";
        uint32_t c = mc_vert(m, 1.0, 1.0, 0.5, 0.5);
        static const double deg[6] = {0, 60, 10, 70, 20, 80};
        uint32_t r[6];
        for (int i = 0; i < 6; i++) {
            double a = i * M_PI / 3.0, b = deg[i] * M_PI / 180.0;
            r[i] = mc_vert(m, 1.0 + cos(a), 1.0 + sin(a), 0.5 + 0.3 * cos(b),
                           0.5 + 0.3 * sin(b));
        }
        for (int i = 0; i < 6; i++)
            mc_tri(m, c, r[i], r[(i + 1) % 6]);
        break;
    }
    case MC_SPLIT_FAN: {
        /* two fans of three triangles sharing only the centre vertex (same
         * position, normal and UV, so one welded vertex) with UV gradients
         * about 90 degrees apart, plus a fan split by a mirrored triangle */
        m->name = "split fan";
        uint32_t c = mc_vert(m, 1.0, 1.0, 0.5, 0.5);
        for (int f = 0; f < 2; f++) {
            uint32_t r[4];
            for (int i = 0; i < 4; i++) {
                double a = (f * 180.0 + 10.0 + i * 50.0) * M_PI / 180.0;
                double x = cos(a), y = sin(a);
                /* fan 0: uv along (x, y); fan 1: rotated by 90 degrees */
                double u = f ? -y : x, v = f ? x : y;
                r[i] = mc_vert(m, 1.0 + x, 1.0 + y, 0.5 + 0.2 * u, 0.5 + 0.2 * v);
            }
            for (int i = 0; i < 3; i++)
                mc_tri(m, c, r[i], r[i + 1]);
        }
        /* a strip of 4 triangles around (3, 1) whose middle pair is mirrored */
        uint32_t c2 = mc_vert(m, 3.0, 1.0, 0.8, 0.5);
        uint32_t q[5];
        static const double qu[5] = {0.9, 0.85, 0.95, 0.87, 0.92};
        for (int i = 0; i < 5; i++) {
            double a = (i * 45.0) * M_PI / 180.0;
            q[i] = mc_vert(m, 3.0 + cos(a), 1.0 + sin(a), qu[i], 0.5 + 0.1 * i);
        }
        for (int i = 0; i < 4; i++)
            mc_tri(m, c2, q[i], q[i + 1]);
        break;
    }
    case MC_ZERO_UV: {
        /* a patch with one zero-UV-area triangle inside (it joins its
         * neighbours' fans), an island whose UVs are all equal (no fan reaches
         * it: default frame) and a degenerate triangle hanging off a patch
         * vertex (it inherits that vertex's frame) */
        m->name = "zero uv";
        mc_grid(m, 4, 2);
        uint32_t a = mc_vert(m, 3.0, 0.0, 0.7, 0.7), b = mc_vert(m, 4.0, 0.0, 0.7, 0.7);
        uint32_t c = mc_vert(m, 4.0, 1.0, 0.7, 0.7), d = mc_vert(m, 3.0, 1.0, 0.7, 0.7);
        mc_tri(m, a, b, c);
        mc_tri(m, a, c, d);
        uint32_t g = 5; /* an inner grid vertex */
        uint32_t e = mc_vert(m, 0.0, 0.0, 0.9, 0.9); /* then moved onto g: other UV */
        m->px[e] = m->px[g], m->py[e] = m->py[g], m->pz[e] = m->pz[g];
        m->nx[e] = m->nx[g], m->ny[e] = m->ny[g], m->nz[e] = m->nz[g];
        uint32_t h = mc_vert(m, m->px[g] + 0.1f, m->py[g], 0.95, 0.9);
        mc_tri(m, g, e, h);
        break;
    }
    default:
        break;
    }
}

#endif
