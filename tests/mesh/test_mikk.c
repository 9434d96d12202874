/* SPDX-License-Identifier: MIT */
/* bgt_mikk_tangents (src/tools/mesh/mikktspace.c) against the reference
 * mikktspace.c's tangents for the meshes of mikk_cases.h (mikk_expected.h:
 * numbers from the reference, see its provenance comment), plus properties
 * the algorithm promises: welding makes an unwelded input identical to the
 * welded one, the result does not depend on the order of the triangles or of
 * their corners, degenerate and zero-UV-area triangles follow their rules. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh/mesh_uv.h"
#include "mesh/mikktspace.h"
#include "mikk_cases.h"
#include "mikk_expected.h"
#include "mikk_pole.h"
#include "common/check.h"


static bgt_mikk_mesh view(const mc_mesh *m)
{
    return (bgt_mikk_mesh){m->nv, m->nt, m->ix, m->px, m->py, m->pz, m->nx, m->ny, m->nz, m->u,
                           m->v};
}

/* angle between two tangents in degrees */
static double angle_deg(const float *a, const float *b)
{
    double cx = (double)a[1] * b[2] - (double)a[2] * b[1];
    double cy = (double)a[2] * b[0] - (double)a[0] * b[2];
    double cz = (double)a[0] * b[1] - (double)a[1] * b[0];
    double d = (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2];
    return atan2(sqrt(cx * cx + cy * cy + cz * cz), d) * 180.0 / M_PI;
}

/* Tangents of float-rounded inputs, evaluated in double here and in float by
 * the reference: they agree to a few float ulps (measured: < 2e-5 deg). */
#define TOL_DEG 1e-4

static void test_against_reference(void)
{
    static mc_mesh m;
    static float out[12 * MC_MAXT];
    for (int id = 0; id < MC_COUNT; id++) {
        mc_build(id, &m);
        bgt_mikk_mesh v = view(&m);
        bgt_mikk_stats st;
        CHECK(bgt_mikk_tangents(&v, out, &st) == BG_OK, "%s: status", m.name);
        double worst = 0.0;
        size_t signs = 0;
        for (size_t c = 0; c < 3 * m.nt; c++) {
            const float *e = mikk_expected[id] + 4 * c, *o = out + 4 * c;
            double a = angle_deg(e, o);
            worst = a > worst ? a : worst;
            signs += e[3] != o[3];
        }
        CHECK(worst <= TOL_DEG, "%s: max angle to the reference %.3g deg", m.name, worst);
        CHECK(signs == 0, "%s: %zu sign mismatches", m.name, signs);
        printf("%-12s %3zu triangles: max %.2g deg from the reference, %zu sign mismatches, "
               "%zu fans, %zu degenerate, %zu zero UV area, %zu unreached corners\n",
               m.name, m.nt, worst, signs, st.fans, st.degenerate, st.zero_uv_area,
               st.unreached);
    }
}

/* The rounding-sensitive fan (mikk_pole.h): the 180 degree split decided in
 * the reference's float order. Corners away from the pole have partial fans
 * here; all corners are compared. */
static void test_pole(void)
{
    static float out[12 * MIKK_POLE_NT], a[8][MIKK_POLE_NV];
    for (int i = 0; i < MIKK_POLE_NV; i++)
        for (int k = 0; k < 8; k++)
            a[k][i] = mikk_pole_vert[i][k];
    bgt_mikk_mesh v = {MIKK_POLE_NV, MIKK_POLE_NT, mikk_pole_ix, a[0], a[1], a[2],
                       a[3], a[4], a[5], a[6], a[7]};
    CHECK(bgt_mikk_tangents(&v, out, NULL) == BG_OK, "pole: status");
    double worst = 0.0;
    size_t signs = 0;
    for (size_t c = 0; c < 3 * MIKK_POLE_NT; c++) {
        double a = angle_deg(mikk_pole_expected + 4 * c, out + 4 * c);
        worst = a > worst ? a : worst;
        signs += mikk_pole_expected[4 * c + 3] != out[4 * c + 3];
    }
    CHECK(worst <= TOL_DEG && signs == 0, "pole: max angle to the reference %.3g deg, %zu signs",
          worst, signs);
    printf("%-12s %3d triangles: max %.2g deg from the reference, %zu sign mismatches\n", "pole",
           MIKK_POLE_NT, worst, signs);
}

/* The rules, checked on their own so that a failure says which one drifted. */
static void test_rules(void)
{
    static mc_mesh a, b;
    static float ta[12 * MC_MAXT], tb[12 * MC_MAXT];
    bgt_mikk_stats sa, sb;

    /* welding: the unwelded patch gives the welded patch's tangents, bit for bit */
    mc_build(MC_CURVED, &a);
    mc_build(MC_UNWELDED, &b);
    bgt_mikk_mesh va = view(&a), vb = view(&b);
    bgt_mikk_tangents(&va, ta, &sa);
    bgt_mikk_tangents(&vb, tb, &sb);
    CHECK(a.nt == b.nt && memcmp(ta, tb, 12 * a.nt * sizeof *ta) == 0,
          "unwelded input differs from the welded one");
    CHECK(sa.welded_vertices == a.nv && sb.welded_vertices == a.nv,
          "welded vertex count %zu / %zu, expected %zu", sa.welded_vertices,
          sb.welded_vertices, a.nv);

    /* order independence: reverse the triangle order and rotate each
     * triangle's corners; corner (t, k) moves to (nt-1-t, (k+1) % 3) */
    for (int id = 0; id < MC_COUNT; id++) {
        if (id == MC_ZERO_UV)
            continue; /* zero-UV-area triangles take the first fan: order-dependent */
        mc_build(id, &a);
        b = a;
        for (size_t t = 0; t < a.nt; t++)
            for (int k = 0; k < 3; k++)
                b.ix[3 * (a.nt - 1 - t) + (size_t)(k + 1) % 3] = a.ix[3 * t + (size_t)k];
        va = view(&a), vb = view(&b);
        bgt_mikk_tangents(&va, ta, NULL);
        bgt_mikk_tangents(&vb, tb, NULL);
        double worst = 0.0;
        size_t signs = 0;
        for (size_t t = 0; t < a.nt; t++)
            for (int k = 0; k < 3; k++) {
                const float *p = ta + 4 * (3 * t + (size_t)k);
                const float *q = tb + 4 * (3 * (a.nt - 1 - t) + (size_t)(k + 1) % 3);
                double d = angle_deg(p, q);
                worst = d > worst ? d : worst;
                signs += p[3] != q[3];
            }
        CHECK(worst <= 1e-5 && signs == 0, "%s: reordering changes tangents (%.3g deg, %zu signs)",
              a.name, worst, signs);
    }

    /* split fan: the centre vertex (index 0) has two fans whose tangents are
     * about 90 degrees apart; triangles 0-2 share one, 3-5 the other */
    mc_build(MC_SPLIT_FAN, &a);
    va = view(&a);
    bgt_mikk_tangents(&va, ta, NULL);
    CHECK(angle_deg(ta + 0, ta + 4 * 3) < 1e-6 && angle_deg(ta + 0, ta + 4 * 6) < 1e-6,
          "split fan: the first fan's centre corners differ");
    CHECK(angle_deg(ta + 0, ta + 4 * 9) > 60.0, "split fan: the two fans share a tangent (%.3g deg)",
          angle_deg(ta + 0, ta + 4 * 9));
    /* the strip around vertex c2 (triangles 6..9): each sign is its UV
     * orientation, and where it changes the centre corners are in different
     * fans (not averaged together) */
    for (size_t t = 6; t < 10; t++) {
        const uint32_t *ix = a.ix + 3 * t;
        double area = ((double)a.u[ix[1]] - a.u[ix[0]]) * ((double)a.v[ix[2]] - a.v[ix[0]]) -
                      ((double)a.u[ix[2]] - a.u[ix[0]]) * ((double)a.v[ix[1]] - a.v[ix[0]]);
        CHECK(ta[4 * 3 * t + 3] == (area > 0.0 ? 1.0f : -1.0f), "split fan: sign of triangle %zu",
              t);
        if (t > 6 && ta[4 * 3 * t + 3] != ta[4 * 3 * (t - 1) + 3])
            CHECK(angle_deg(ta + 4 * 3 * t, ta + 4 * 3 * (t - 1)) > 1.0,
                  "split fan: triangles %zu and %zu of opposite orientation share a tangent", t - 1,
                  t);
    }

    /* alternating: every centre corner has its own fan, signs alternate */
    mc_build(MC_ALTERNATING, &a);
    va = view(&a);
    bgt_mikk_tangents(&va, ta, &sa);
    CHECK(sa.fans == 18, "alternating: %zu fans, expected 3 per triangle (18)", sa.fans);
    for (int t = 0; t < 6; t++)
        CHECK(ta[4 * 3 * t + 3] == (t % 2 ? -1.0f : 1.0f), "alternating: sign of triangle %d", t);

    /* zero UV: the island (triangles 18, 19) keeps the default frame (1,0,0), -1;
     * the degenerate triangle 20's corner at grid vertex 5 copies the first
     * non-degenerate corner at vertex 5 */
    mc_build(MC_ZERO_UV, &a);
    va = view(&a);
    bgt_mikk_tangents(&va, ta, &sa);
    CHECK(sa.degenerate == 1 && sa.unreached == 6 + 2 && sa.zero_uv_area == 4, "zero uv: %zu degenerate, %zu unreached",
          sa.degenerate, sa.unreached);
    static const size_t dflt[8] = {7, 12, 54, 55, 56, 57, 58, 59};
    for (size_t i = 0; i < 8; i++) {
        size_t c = dflt[i];
        CHECK(ta[4 * c] == 1.0f && ta[4 * c + 1] == 0.0f && ta[4 * c + 2] == 0.0f &&
                  ta[4 * c + 3] == -1.0f,
              "zero uv: corner %zu is not the default frame", c);
    }
    for (size_t c = 0; c < 3 * 20; c++)
        if (c != 7 && c != 12 && c < 54)
            CHECK(ta[4 * c] != 1.0f || ta[4 * c + 1] != 0.0f, "zero uv: corner %zu unreached", c);
    size_t first = 0;
    while (a.ix[first] != 5)
        first++;
    CHECK(memcmp(ta + 4 * 3 * 20, ta + 4 * first, 4 * sizeof *ta) == 0,
          "zero uv: the degenerate triangle did not inherit corner %zu", first);
}

/* encode is the exact inverse of the renderer's decode, on real frames of
 * the curved and the mirrored patch (signs +1 and -1) */
static void test_encode_decode(void)
{
    static mc_mesh a;
    static float tan[12 * MC_MAXT];
    const int ids[2] = {MC_CURVED, MC_MIRRORED};
    unsigned seed = 12345u;
    double worst = 0.0;
    int fails = 0, negative = 0;
    for (int q = 0; q < 2; q++) {
        mc_build(ids[q], &a);
        bgt_mikk_mesh v = view(&a);
        bgt_mikk_tangents(&v, tan, NULL);
        for (size_t t = 0; t < a.nt; t++) {
            float nv[3][3];
            const float *tc[3], *nc[3];
            for (int k = 0; k < 3; k++) {
                uint32_t i = a.ix[3 * t + (size_t)k];
                nv[k][0] = a.nx[i], nv[k][1] = a.ny[i], nv[k][2] = a.nz[i];
                tc[k] = tan + 4 * (3 * t + (size_t)k);
                nc[k] = nv[k];
            }
            negative += tc[0][3] < 0.0f;
            for (int r = 0; r < 20; r++) {
                double w[3], d[3], mm[3], back[3];
                seed = seed * 1664525u + 1013904223u;
                w[1] = (seed >> 8) / 16777216.0;
                seed = seed * 1664525u + 1013904223u;
                w[2] = (1.0 - w[1]) * ((seed >> 8) / 16777216.0);
                w[0] = 1.0 - w[1] - w[2];
                bgt_mikk_frame f;
                bgt_mikk_frame_at(tc, nc, w, &f);
                for (int k = 0; k < 3; k++) {
                    seed = seed * 1664525u + 1013904223u;
                    d[k] = f.n[k] + 0.8 * ((seed >> 8) / 8388608.0 - 1.0);
                }
                double l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                for (int k = 0; k < 3; k++)
                    d[k] /= l;
                if (bgt_mikk_encode(&f, d, mm) != 0 || bgt_mikk_decode(&f, mm, back) != 0) {
                    fails++;
                    continue;
                }
                float fa[3] = {(float)d[0], (float)d[1], (float)d[2]};
                float fb[3] = {(float)back[0], (float)back[1], (float)back[2]};
                double e = angle_deg(fa, fb);
                worst = e > worst ? e : worst;
            }
        }
    }
    CHECK(fails == 0 && negative > 0, "encode/decode: %d failures, %d mirrored triangles", fails,
          negative);
    CHECK(worst < 1e-4, "encode/decode round trip off by %.3g deg", worst);
    printf("encode/decode round trip: max %.2g deg (float-rounded comparison)\n", worst);
}

/* UV islands: by shared UV edges, not by vertex index */
static void test_islands(void)
{
    static mc_mesh a;
    uint32_t isl[MC_MAXT];
    static const size_t expect[MC_COUNT] = {
        [MC_CURVED] = 1, [MC_UNWELDED] = 1, [MC_MIRRORED] = 1, [MC_ALTERNATING] = 1,
        /* two fans meeting at one vertex only, and the strip */
        [MC_SPLIT_FAN] = 3,
        /* the patch (zero-area triangles included: their edges are proper),
         * the two triangles of the one-point island (no edge of non-zero UV
         * length joins them) and the degenerate triangle with UVs of its own */
        [MC_ZERO_UV] = 4};
    for (int id = 0; id < MC_COUNT; id++) {
        mc_build(id, &a);
        size_t n = mesh_uv_islands(a.nt, a.ix, a.u, a.v, isl);
        CHECK(n == expect[id], "%s: %zu UV islands, expected %zu", a.name, n, expect[id]);
        if (id == MC_SPLIT_FAN)
            CHECK(isl[0] == isl[2] && isl[3] == isl[5] && isl[0] != isl[3] && isl[6] == isl[9],
                  "split fan: island labels");
    }
}

static void test_errors(void)
{
    static mc_mesh a;
    static float t[12 * MC_MAXT];
    mc_build(MC_CURVED, &a);
    bgt_mikk_mesh v = view(&a);
    CHECK(bgt_mikk_tangents(NULL, t, NULL) == BG_ERR_NULL_POINTER, "NULL mesh");
    CHECK(bgt_mikk_tangents(&v, NULL, NULL) == BG_ERR_NULL_POINTER, "NULL output");
    bgt_mikk_mesh w = v;
    w.u = NULL;
    CHECK(bgt_mikk_tangents(&w, t, NULL) == BG_ERR_NULL_POINTER, "NULL UVs");
    a.ix[7] = (uint32_t)a.nv;
    CHECK(bgt_mikk_tangents(&v, t, NULL) == BG_ERR_INVALID_ARGUMENT, "index out of range");
    w.triangle_count = 0;
    CHECK(bgt_mikk_tangents(&w, t, NULL) == BG_OK, "empty mesh");
}

int main(void)
{
    test_against_reference();
    test_pole();
    test_rules();
    test_encode_decode();
    test_islands();
    test_errors();
    return check_summary("test_mikk");
}
