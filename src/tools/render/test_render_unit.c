/* SPDX-License-Identifier: MIT */
/* Unit tests of the renderer's pieces that the command-line tests cannot see:
 *  - Listing 1 on a 2x2 quad of a plane with a linear height is exact: the
 *    screen-space derivatives of linear functions are exact, so eq. (3) and
 *    Listing 1 must give normalize(n - grad_S h) (eq. 2, 4) for any plane,
 *    orientation, quad lane, fine or coarse derivative. The reference is
 *    computed here in double from the formula, sharing no code.
 *  - The marching-tetrahedra isosurface and its BVH: the BVH's closest hit
 *    equals a brute-force loop over all triangles; rays aimed at the blob's
 *    centre (which is inside) all hit, on the side their vertex normals face;
 *    vertex normals are unit and face normals agree with them.
 *  - One function per equation: render_listing1 gives the same bits as the
 *    library's bg_listing1_normal for the same quad, on random quads and on
 *    degenerate ones (det = 0, inward, zero normals).
 * The renderer's own unit test (src/tools/render/meson.build): it sees the
 * pieces behind render_internal.h, which nothing outside the tool includes. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bumpgrad/framework.h"
#include "render_internal.h"
#include "common/check.h"

static unsigned long long rng = 0x9E3779B97F4A7C15ull;
static double urand(void) /* [-1, 1), xorshift64* */
{
    rng ^= rng >> 12, rng ^= rng << 25, rng ^= rng >> 27;
    return (double)((rng * 2685821657736338717ull) >> 11) / 4503599627370496.0 - 1.0;
}

/* d = the unit direction from o towards t */
static void aim(const float o[3], const float t[3], float d[3])
{
    for (int k = 0; k < 3; k++)
        d[k] = t[k] - o[k];
    float l = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int k = 0; k < 3; k++)
        d[k] /= l;
}

static void test_listing1_plane(void)
{
    double worst = 0;
    for (int trial = 0; trial < 2000; trial++) {
        double a[3], b[3], c[3], o[3];
        for (int k = 0; k < 3; k++)
            a[k] = urand() * 0.01, b[k] = urand() * 0.01, c[k] = urand() * 3, o[k] = urand();
        double nn[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
        double l = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
        /* Badly conditioned quads (nearly parallel sigma_s, sigma_t) lose
         * float digits in any implementation; keep the angle above ~3 degrees. */
        double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        double lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
        if (l < 0.05 * la * lb)
            continue;
        double side = (trial & 1) ? -1.0 : 1.0; /* either orientation of n */
        for (int k = 0; k < 3; k++)
            nn[k] = side * nn[k] / l;
        float pos[4][3], h[4], n[3] = {(float)nn[0], (float)nn[1], (float)nn[2]};
        for (int lane = 0; lane < 4; lane++) {
            double s = lane & 1, t = lane >> 1, hv = 0.25;
            for (int k = 0; k < 3; k++) {
                double p = o[k] + s * a[k] + t * b[k];
                pos[lane][k] = (float)p;
            }
            for (int k = 0; k < 3; k++)
                hv += c[k] * pos[lane][k];
            h[lane] = (float)hv;
        }
        /* Reference: eq. 2 and 4 in double, with n and the gradient c. */
        double d = nn[0] * c[0] + nn[1] * c[1] + nn[2] * c[2], r[3];
        for (int k = 0; k < 3; k++)
            r[k] = nn[k] - (c[k] - nn[k] * d);
        double rl = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        for (int fine = 0; fine < 2; fine++)
            for (int lane = 0; lane < 4; lane++) {
                float out[3];
                render_listing1((const float(*)[3])pos, h, lane, fine, n, out);
                double dot = (out[0] * r[0] + out[1] * r[1] + out[2] * r[2]) / rl;
                double ang = acos(dot > 1 ? 1 : dot) * 57.29577951308232;
                if (ang > worst)
                    worst = ang;
            }
    }
    /* Float positions and heights of a 0.01-sized quad: the differences keep
     * about 5 digits, so a few hundredths of a degree is the honest bound. */
    CHECK(worst < 0.05, "Listing 1 on planes with linear height: worst angle %g deg", worst);
    printf("listing1 on linear planes: worst angle %.2e deg\n", worst);
}

static void test_listing1_degenerate(void)
{
    /* A quad collapsed to a line: det = 0; HLSL's sign(0) would give a zero
     * vector, we keep the normal. */
    float pos[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 0, 0}, {1, 0, 0}}, h[4] = {0, 1, 2, 3};
    float n[3] = {0, 0, 1}, out[3];
    render_listing1((const float(*)[3])pos, h, 0, 1, n, out);
    CHECK(out[0] == 0 && out[1] == 0 && out[2] == 1, "degenerate quad keeps n");
}

/* The one-rule check's own stream (xorshift64, floats in [-1, 1)), so the
 * other checks see the same points with or without it. */
static unsigned long long rule_rng = 0x9e3779b97f4a7c15ull;
static float rule_rand(void)
{
    rule_rng ^= rule_rng << 13, rule_rng ^= rule_rng >> 7, rule_rng ^= rule_rng << 17;
    return (float)((double)(rule_rng >> 11) / 9007199254740992.0 * 2 - 1);
}

static int same3(const float a[3], bg_vec3 b)
{
    return memcmp(&a[0], &b.x, 4) == 0 && memcmp(&a[1], &b.y, 4) == 0 &&
           memcmp(&a[2], &b.z, 4) == 0;
}

/* render_listing1 against bg_listing1_normal, bit for bit: the renderer keeps
 * no copy of the equation (tests/tools/test_one_rule.c checks heightmap's). */
static void test_listing1_one_rule(void)
{
    int bad = 0, det0 = 0;
    for (int k = 0; k < 200000; k++) {
        float pos[4][3], h[4], n[3] = {rule_rand(), rule_rand(), rule_rand()}, out[3];
        for (int q = 0; q < 4; q++)
            for (int a = 0; a < 3; a++)
                pos[q][a] = rule_rand();
        for (int q = 0; q < 4; q++)
            h[q] = 0.1f * rule_rand();
        if (k % 7 == 0) /* collinear quad: det = 0 */
            for (int a = 0; a < 3; a++)
                pos[2][a] = pos[0][a] + 2 * (pos[1][a] - pos[0][a]),
                pos[3][a] = pos[1][a] + 2 * (pos[1][a] - pos[0][a]);
        int lane = k & 3, fine = (k >> 2) & 1;
        render_listing1((const float(*)[3])pos, h, lane, fine, n, out);
        int lx = lane & 1, ly = lane >> 1, r = fine ? 2 * ly : 0, c = fine ? lx : 0;
        bg_vec3 ss = {pos[r + 1][0] - pos[r][0], pos[r + 1][1] - pos[r][1], pos[r + 1][2] - pos[r][2]};
        bg_vec3 st = {pos[c + 2][0] - pos[c][0], pos[c + 2][1] - pos[c][1], pos[c + 2][2] - pos[c][2]};
        bg_vec3 nn = {n[0], n[1], n[2]};
        bg_vec3 ref = bg_listing1_normal(nn, ss, st, h[r + 1] - h[r], h[c + 2] - h[c]);
        det0 += same3(n, ref);
        int same = same3(out, ref);
        bad += !same;
        CHECK(same || bad > 5, "listing1 case %d: render (%g %g %g) vs library (%g %g %g)", k,
              (double)out[0], (double)out[1], (double)out[2], (double)ref.x, (double)ref.y,
              (double)ref.z);
    }
    CHECK(bad == 0, "listing1: %d of 200000 quads differ from bg_listing1_normal", bad);
    CHECK(det0 > 0, "some quads kept the normal (the det = 0 rule was reached)");
    printf("listing1 vs bg_listing1_normal: 200000 quads, %d mismatches, %d kept the normal "
           "(det = 0 rule)\n", bad, det0);
}

static int brute(const render_mesh *m, const float o[3], const float d[3], render_hit *best)
{
    int found = 0;
    float tmax = INFINITY;
    for (size_t t = 0; t < m->ntri; t++) {
        render_mesh one = *m;
        render_bvh_node leaf = {{-INFINITY, -INFINITY, -INFINITY}, {INFINITY, INFINITY, INFINITY}, -1,
                                (int)t, 1};
        one.nodes = &leaf;
        one.nnodes = 1;
        render_hit h;
        if (render_mesh_intersect(&one, o, d, tmax, &h)) {
            *best = h;
            tmax = h.t;
            found = 1;
        }
    }
    return found;
}

static void test_mesh(render_shape shape)
{
    render_mesh m;
    CHECK(render_mesh_build(shape, 20, &m) == 0, "mesh builds");
    if (m.ntri == 0)
        return;
    double worst_unit = 0;
    int bad_face = 0;
    for (size_t t = 0; t < m.ntri; t++)
        for (int v = 0; v < 3; v++) {
            const float *n = m.nrm + t * 9 + v * 3, *f = m.face + t * 3;
            double l = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
            if (fabs(l - 1) > worst_unit)
                worst_unit = fabs(l - 1);
            bad_face += n[0] * f[0] + n[1] * f[1] + n[2] * f[2] <= 0;
        }
    CHECK(worst_unit < 1e-5, "vertex normals unit (worst %g)", worst_unit);
    CHECK(bad_face == 0, "%d vertex normals face away from their triangle", bad_face);
    int mismatch = 0, missed = 0, backside = 0;
    for (int r = 0; r < 300; r++) {
        float o[3], d[3], target[3] = {0, 0, 0};
        double u = urand(), v = urand(), w = urand(), l = sqrt(u * u + v * v + w * w) + 1e-9;
        o[0] = (float)(3 * u / l), o[1] = (float)(3 * v / l), o[2] = (float)(3 * w / l);
        if (shape == RENDER_TORUS) /* aim at random points near the ring */
            for (int k = 0; k < 3; k++)
                target[k] = (float)(0.4 * urand());
        aim(o, target, d);
        render_hit a, b;
        int ha = render_mesh_intersect(&m, o, d, INFINITY, &a), hb = brute(&m, o, d, &b);
        if (ha != hb || (ha && a.t != b.t))
            mismatch++;
        if (shape == RENDER_BLOB && !ha)
            missed++;
        if (ha) {
            const float *f = m.face + (size_t)a.prim * 3;
            backside += f[0] * d[0] + f[1] * d[1] + f[2] * d[2] >= 0;
        }
    }
    CHECK(mismatch == 0, "%s: BVH and brute force disagree on %d of 300 rays",
          render_shape_name(shape), mismatch);
    CHECK(missed == 0, "%s: %d rays at the inside point missed", render_shape_name(shape), missed);
    CHECK(backside == 0, "%s: %d first hits on a back face", render_shape_name(shape), backside);
    printf("%s: %zu triangles, BVH nodes %zu\n", render_shape_name(shape), m.ntri, m.nnodes);
    render_mesh_free(&m);
}

static void test_names(void)
{
    for (int i = 0; i < RENDER_METHOD_COUNT; i++) {
        render_method m;
        CHECK(render_method_parse(render_method_name((render_method)i), &m) == 0 && (int)m == i,
              "method name round trip %d", i);
    }
    render_method m;
    CHECK(render_method_parse("Surfgrad", &m) != 0, "method names are exact");
}

/* Embree and the BVH on the same rays: the same hit or miss, the same
 * triangle, t and barycentrics equal to float rounding. Rays that graze an
 * edge may legitimately pick either neighbour (watertight vs Moeller-Trumbore
 * tests); they must then agree on t. Without Embree: its build must fail
 * cleanly with BG_ERR_INVALID_ARGUMENT. */
static void test_embree(render_shape shape)
{
    render_mesh m;
    CHECK(render_mesh_build(shape, 24, &m) == 0, "mesh builds");
    render_embree *rt = NULL;
    bgt_err err;
    double secs = -1;
    bg_status s = render_embree_build(&m, 2, &rt, &secs, &err);
    if (!render_embree_available()) {
        CHECK(s == BG_ERR_INVALID_ARGUMENT && rt == NULL, "no Embree: a clean error");
        render_mesh_free(&m);
        return;
    }
    CHECK(s == BG_OK && rt && secs >= 0, "embree builds");
    int n = 20000, same_prim = 0, hits = 0, far = 0;
    double worst_p = 0;
    for (int i = 0; i < n; i++) {
        float o[3], d[3], tgt[3];
        for (int k = 0; k < 3; k++)
            o[k] = (float)(urand() * 3.0), tgt[k] = (float)(urand() * 0.8);
        o[2] += (o[2] >= 0 ? 3.0f : -3.0f);
        aim(o, tgt, d);
        render_hit a, b;
        int ha = render_mesh_intersect(&m, o, d, INFINITY, &a), hb = render_embree_intersect(rt, o, d, &b);
        CHECK(ha == hb, "ray %d: bvh hit %d, embree hit %d", i, ha, hb);
        if (!ha || !hb)
            continue;
        hits++;
        same_prim += a.prim == b.prim;
        /* The hit points from each one's barycentrics on its triangle: grazing
         * rays make t and the barycentrics ill-conditioned, the point is not. */
        double dp = 0;
        for (int k = 0; k < 3; k++) {
            const float *A = m.pos + (size_t)a.prim * 9, *B = m.pos + (size_t)b.prim * 9;
            double pa = A[k] + a.b1 * (A[3 + k] - A[k]) + a.b2 * (A[6 + k] - A[k]);
            double pb = B[k] + b.b1 * (B[3 + k] - B[k]) + b.b2 * (B[6 + k] - B[k]);
            dp = fmax(dp, fabs(pa - pb));
        }
        worst_p = dp > worst_p ? dp : worst_p;
        far += dp > 1e-5;
    }
    CHECK(hits > n / 4, "enough rays hit (%d)", hits);
    CHECK(same_prim >= hits - hits / 1000, "same triangle on all but edge rays (%d of %d)", same_prim, hits);
    CHECK(far <= hits / 1000, "hit points within 1e-5 on all but 0.1%% of the rays (%d)", far);
    CHECK(worst_p < 1e-3, "hit points within 1e-3 on every ray (%g)", worst_p);
    printf("embree vs bvh (%s): %d hits, %d same triangle, %d points > 1e-5 apart, max %.2g\n",
           render_shape_name(shape), hits, same_prim, far, worst_p);
    render_embree_free(rt);
    render_mesh_free(&m);
}

int main(void)
{
    test_embree(RENDER_BLOB);
    test_embree(RENDER_TORUS);
    test_listing1_plane();
    test_listing1_degenerate();
    test_listing1_one_rule();
    test_mesh(RENDER_BLOB);
    test_mesh(RENDER_TORUS);
    test_names();
    return check_summary("test_render_unit");
}
