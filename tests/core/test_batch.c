/* SPDX-License-Identifier: MIT */
/* Batch calls on the scalar ISA give the same bits as the single-point calls
 * (noise.h and surfgrad.h promise it). Inputs include lattice points, +-0,
 * negative, large and non-finite coordinates; lengths 0..37 exercise every
 * loop shape. Bits are compared with memcmp, so NaN payloads and signed zeros
 * count too. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bumpgrad.h"
#include "ref.h"
#include "check.h"

#define N 1000

static float px[N], py[N], pz[N], nx[N], ny[N], nz[N], gx[N], gy[N], gz[N];

static void fill(void)
{
    ref_rng r;
    ref_rng_seed(&r, 71);
    const float special[] = {0.0f, -0.0f, 1.0f, -1.0f, 255.0f, 256.0f, -256.0f, 1e4f, -1e4f,
                             1e6f, 16777216.0f, NAN, INFINITY, -INFINITY, 1e-6f, 3.0e-39f};
    for (int i = 0; i < N; i++) {
        float *p[3] = {&px[i], &py[i], &pz[i]};
        for (int a = 0; a < 3; a++) {
            int kind = (int)(ref_rng_u64(&r) % 10);
            if (kind == 0)
                *p[a] = special[ref_rng_u64(&r) % 16];
            else if (kind == 1)
                *p[a] = (float)floor(ref_rng_uniform(&r, -300, 300));
            else
                *p[a] = (float)ref_rng_uniform(&r, -300, 300);
        }
        double u[3];
        ref_rng_unit_vector(&r, u);
        double s = ref_rng_uniform(&r, 0, 1) < 0.1 ? 0 : exp(ref_rng_uniform(&r, -5, 5));
        nx[i] = (float)(u[0] * s), ny[i] = (float)(u[1] * s), nz[i] = (float)(u[2] * s);
        gx[i] = (float)ref_rng_uniform(&r, -3, 3), gy[i] = (float)ref_rng_uniform(&r, -3, 3);
        gz[i] = i % 97 == 5 ? NAN : (float)ref_rng_uniform(&r, -3, 3);
    }
}

static int same(const float *a, const float *b, size_t n)
{
    return memcmp(a, b, n * sizeof(float)) == 0;
}

int main(void)
{
    bg_status st = bg_isa_force(BG_ISA_SCALAR);
    printf("bg_isa_force(scalar): %s, active ISA: %s\n", bg_status_string(st),
           bg_isa_name(bg_isa_active()));
    CHECK(st == BG_OK && bg_isa_active() == BG_ISA_SCALAR, "could not force the scalar ISA");
    fill();

    static float v[N], ax[N], ay[N], az[N], sv[N], sx[N], sy[N], sz[N];
    int mismatches = 0, calls = 0;

    /* noise value / gradient */
    bg_noise3_batch(px, py, pz, N, v);
    bg_noise3_grad_batch(px, py, pz, N, sv, ax, ay, az);
    for (int i = 0; i < N; i++) {
        bg_vec3 g;
        float s1 = bg_noise3(px[i], py[i], pz[i]);
        float s2 = bg_noise3_grad(px[i], py[i], pz[i], &g);
        sx[i] = g.x, sy[i] = g.y, sz[i] = g.z;
        if (memcmp(&s1, &v[i], 4) || memcmp(&s2, &sv[i], 4))
            mismatches++;
    }
    mismatches += !same(sx, ax, N) + !same(sy, ay, N) + !same(sz, az, N);
    calls += 2;
    /* gradient without value (NULL) must give the same gradient */
    bg_noise3_grad_batch(px, py, pz, N, NULL, sx, sy, sz);
    mismatches += !same(sx, ax, N) + !same(sy, ay, N) + !same(sz, az, N);
    calls++;

    /* fractals: value, analytic, central */
    for (int fn = 0; fn < 3; fn++) {
        bg_fractal f = bg_fractal_default((bg_function)fn);
        bg_fractal3_batch(&f, px, py, pz, N, v);
        bg_fractal3_grad_batch(&f, px, py, pz, N, sv, ax, ay, az);
        for (int i = 0; i < N; i++) {
            bg_vec3 g;
            float s1 = bg_fractal3(&f, px[i], py[i], pz[i]);
            float s2 = bg_fractal3_grad(&f, px[i], py[i], pz[i], &g);
            if (memcmp(&s1, &v[i], 4) || memcmp(&s2, &sv[i], 4) || memcmp(&g.x, &ax[i], 4) ||
                memcmp(&g.y, &ay[i], 4) || memcmp(&g.z, &az[i], 4))
                mismatches++;
        }
        bg_fractal3_grad_central_batch(&f, 1e-3f, px, py, pz, N, sv, ax, ay, az);
        for (int i = 0; i < N; i++) {
            bg_vec3 g;
            float s2 = bg_fractal3_grad_central(&f, 1e-3f, px[i], py[i], pz[i], &g);
            if (memcmp(&s2, &sv[i], 4) || memcmp(&g.x, &ax[i], 4) || memcmp(&g.y, &ay[i], 4) ||
                memcmp(&g.z, &az[i], 4))
                mismatches++;
        }
        calls += 3;
        /* double batch vs double single points */
        double dx[64], dy[64], dz[64], dv[64], dgx[64], dgy[64], dgz[64];
        for (int i = 0; i < 64; i++)
            dx[i] = px[i] * 1e3, dy[i] = py[i], dz[i] = pz[i] - 1e9;
        bg_fractal3d_grad_batch(&f, dx, dy, dz, 64, dv, dgx, dgy, dgz);
        for (int i = 0; i < 64; i++) {
            bg_dvec3 g;
            double s2 = bg_fractal3d_grad(&f, dx[i], dy[i], dz[i], &g);
            if (memcmp(&s2, &dv[i], 8) || memcmp(&g.x, &dgx[i], 8) || memcmp(&g.y, &dgy[i], 8) ||
                memcmp(&g.z, &dgz[i], 8))
                mismatches++;
        }
        calls++;
    }

    /* perturbation, all methods */
    for (int m = 0; m < 3; m++) {
        bg_perturb_batch((bg_perturb_method)m, nx, ny, nz, gx, gy, gz, N, ax, ay, az);
        for (int i = 0; i < N; i++) {
            bg_vec3 n = {nx[i], ny[i], nz[i]}, g = {gx[i], gy[i], gz[i]};
            bg_vec3 o = bg_perturb((bg_perturb_method)m, n, g);
            if (memcmp(&o.x, &ax[i], 4) || memcmp(&o.y, &ay[i], 4) || memcmp(&o.z, &az[i], 4))
                mismatches++;
        }
        calls++;
    }

    /* fused height -> normal against bg_height_eval + bg_perturb */
    for (int mode = 0; mode < 2; mode++)
        for (int m = 0; m < 3; m++) {
            bg_height h = bg_height_default();
            h.gradient = mode ? BG_GRADIENT_CENTRAL : BG_GRADIENT_ANALYTIC;
            h.frequency = 2.5f, h.amplitude = 0.3f;
            bg_perturb_height_batch(&h, (bg_perturb_method)m, px, py, pz, nx, ny, nz, N, v, ax,
                                    ay, az);
            for (int i = 0; i < N; i++) {
                bg_vec3 p = {px[i], py[i], pz[i]}, n = {nx[i], ny[i], nz[i]}, g;
                float hv = bg_height_eval(&h, p, &g);
                bg_vec3 o = bg_perturb((bg_perturb_method)m, n, g);
                if (memcmp(&hv, &v[i], 4) || memcmp(&o.x, &ax[i], 4) ||
                    memcmp(&o.y, &ay[i], 4) || memcmp(&o.z, &az[i], 4))
                    mismatches++;
            }
            calls++;
        }

    /* every length 0..37 and an exact in-place alias (output == input array) */
    int len_bad = 0;
    for (size_t n = 0; n <= 37; n++) {
        float out[40], guard = 12345.0f;
        for (int i = 0; i < 40; i++)
            out[i] = guard;
        bg_noise3_batch(px + 3, py + 3, pz + 3, n, out);
        for (size_t i = 0; i < 40; i++) {
            float s = i < n ? bg_noise3(px[3 + i], py[3 + i], pz[3 + i]) : guard;
            if (memcmp(&s, &out[i], 4))
                len_bad++;
        }
    }
    {
        float x[N], y[N], z[N];
        memcpy(x, px, sizeof x), memcpy(y, py, sizeof y), memcpy(z, pz, sizeof z);
        bg_fractal f = bg_fractal_default(BG_FUNC_FBM);
        bg_fractal3_grad_batch(&f, x, y, z, N, NULL, x, y, z); /* gradient over the input */
        bg_fractal3_grad_batch(&f, px, py, pz, N, NULL, ax, ay, az);
        len_bad += !same(x, ax, N) + !same(y, ay, N) + !same(z, az, N);
    }
    printf("scalar ISA: %d batch calls over %d points compared bit for bit with single-point "
           "calls: %d mismatches; lengths 0..37 with guard values and in-place aliasing: %d "
           "mismatches\n", calls, N, mismatches, len_bad);
    CHECK(mismatches == 0, "batch differs from single point");
    CHECK(len_bad == 0, "tail/alias handling differs");
    return check_summary("test_batch");
}
