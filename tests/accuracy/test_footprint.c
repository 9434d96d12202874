/* SPDX-License-Identifier: MIT */
/* Footprint-aware octaves (noise.h): the weight rule, continuity (no popping),
 * skipped octaves, and bit equality with the unfiltered kernels at footprint 0. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <bumpgrad.h>
#include "common/check.h"

static float frand(unsigned *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (float)(*s >> 8) * (1.0f / 16777216.0f);
}

int main(void)
{
    check_verbose = 1;
    /* The rule: c_i = clamp(2 - 4 w L^i, 0, 1). */
    CHECK(bg_octave_weight(0.0f, 2.0f, 5) == 1.0f, "footprint 0 keeps octave 5");
    CHECK(bg_octave_weight(0.25f, 2.0f, 0) == 1.0f, "r = 1/4: full weight");
    CHECK(bg_octave_weight(0.375f, 2.0f, 0) == 0.5f, "r = 3/8: half weight");
    CHECK(bg_octave_weight(0.5f, 2.0f, 0) == 0.0f, "r = 1/2 (Nyquist): dropped");
    CHECK(bg_octave_weight(1.0f / 16, 2.0f, 2) == 1.0f && bg_octave_weight(1.0f / 16, 2.0f, 3) == 0.0f &&
              bg_octave_weight(1.0f / 16, 2.0f, 4) == 0.0f,
          "footprint 1/16: octaves 0..2 full, 3 at r = 1/2 dropped");
    CHECK(bg_octaves_for_footprint(1e-9f, 6) == 6.0f, "tiny footprint: 6 octaves");
    CHECK(bg_octaves_for_footprint(0.5f, 6) == 0.0f, "footprint 1/2: nothing representable");
    float e = bg_octaves_for_footprint(3.0f / 64, 6);
    CHECK(fabsf(e - 3.5f) < 1e-6f, "footprint 3/64: 3.5 effective octaves (got %g)", (double)e);
    CHECK(bg_octave_weight(NAN, 2.0f, 3) == 1.0f, "NaN footprint: no filtering");

    /* Continuity: the effective count never jumps as the footprint shrinks. */
    float prev = bg_octaves_for_footprint(1.0f, 6), maxjump = 0;
    for (int k = 1; k <= 4000; k++) {
        float w = powf(2.0f, -12.0f * (float)k / 4000.0f);
        float c = bg_octaves_for_footprint(w, 6);
        maxjump = fmaxf(maxjump, fabsf(c - prev));
        prev = c;
    }
    CHECK(maxjump < 0.01f, "no popping: largest step of the octave count over a fine sweep %g", (double)maxjump);

    enum { N = 1003 };
    float *buf = calloc(20 * N, sizeof(float));
    float *px = buf, *py = px + N, *pz = py + N, *nx = pz + N, *ny = nx + N, *nz = ny + N, *fp = nz + N;
    float *h1 = fp + N, *o1x = h1 + N, *o1y = o1x + N, *o1z = o1y + N;
    float *h2 = o1z + N, *o2x = h2 + N, *o2y = o2x + N, *o2z = o2y + N;
    float *v = o2z + N, *gx = v + N, *gy = gx + N, *gz = gy + N;
    unsigned s = 7;
    for (int i = 0; i < N; i++) {
        px[i] = 20 * frand(&s) - 10, py[i] = 20 * frand(&s) - 10, pz[i] = 20 * frand(&s) - 10;
        float a = frand(&s) * 6.2831853f, zz = 2 * frand(&s) - 1, r = sqrtf(1 - zz * zz);
        nx[i] = r * cosf(a), ny[i] = r * sinf(a), nz[i] = zz;
    }
    bg_function fns[3] = {BG_FUNC_NOISE, BG_FUNC_FBM, BG_FUNC_TURBULENCE};
    const char *names[3] = {"noise", "fbm", "turbulence"};
    for (int f = 0; f < 3; f++) {
        bg_height h = bg_height_default();
        h.fractal = bg_fractal_default(fns[f]);
        h.amplitude = 0.3f, h.frequency = 1.7f;
        memset(fp, 0, N * sizeof(float));
        bg_perturb_height_batch(&h, BG_PERTURB_SURFGRAD, px, py, pz, nx, ny, nz, N, h1, o1x, o1y, o1z);
        bg_perturb_height_footprint_batch(&h, BG_PERTURB_SURFGRAD, fp, px, py, pz, nx, ny, nz, N, h2, o2x,
                                          o2y, o2z);
        CHECK(!memcmp(h1, h2, N * sizeof(float)) && !memcmp(o1x, o2x, N * sizeof(float)) &&
                  !memcmp(o1y, o2y, N * sizeof(float)) && !memcmp(o1z, o2z, N * sizeof(float)),
              "%s: footprint 0 == unfiltered fused kernel, bit for bit (%d points)", names[f], N);

        /* Octaves dropped exactly: footprint with ratio >= 1/2 at octave 3 equals
         * the 3-octave sum (weights of octaves 0..2 are 1 when w*4 <= 1/4). */
        if (fns[f] != BG_FUNC_NOISE) {
            for (int i = 0; i < N; i++)
                fp[i] = 1.0f / 16;
            bg_fractal3_grad_footprint_batch(&h.fractal, fp, px, py, pz, N, v, gx, gy, gz);
            bg_fractal f3 = h.fractal;
            f3.octaves = 3;
            double maxd = 0;
            for (int i = 0; i < N; i++) {
                bg_vec3 g;
                float r = bg_fractal3_grad(&f3, px[i], py[i], pz[i], &g);
                maxd = fmax(maxd, fabs((double)r - v[i]));
                maxd = fmax(maxd, fabs((double)g.x - gx[i]) + fabs((double)g.y - gy[i]) + fabs((double)g.z - gz[i]));
            }
            CHECK(maxd == 0, "%s: footprint 1/16 == the 3-octave sum exactly (max diff %g)", names[f], maxd);
        }
    }
    /* Unit normals, no NaN, for random footprints including NaN and negative. */
    for (int i = 0; i < N; i++)
        fp[i] = i % 97 == 0 ? NAN : i % 89 == 0 ? -1.0f : 0.2f * frand(&s);
    bg_height h = bg_height_default();
    bg_perturb_height_footprint_batch(&h, BG_PERTURB_SURFGRAD, fp, px, py, pz, nx, ny, nz, N, h2, o2x, o2y,
                                      o2z);
    double worst = 0;
    for (int i = 0; i < N; i++)
        worst = fmax(worst, fabs(sqrt((double)o2x[i] * o2x[i] + (double)o2y[i] * o2y[i] + (double)o2z[i] * o2z[i]) - 1));
    CHECK(worst < 1e-6, "random footprints: unit normals (max |len - 1| = %g)", worst);
    /* Every ISA level this CPU has gives the scalar kernel's bits (random
     * footprints, so lanes of one vector keep different octave counts). */
    {
        bg_fractal ft = bg_fractal_default(BG_FUNC_TURBULENCE);
        float *ref = malloc(4 * N * sizeof(float)), *got = malloc(4 * N * sizeof(float));
        bg_isa best = bg_isa_best();
        for (int isa = BG_ISA_SCALAR; isa < BG_ISA_COUNT; isa++) {
            if (bg_isa_force((bg_isa)isa) != BG_OK)
                continue;
            float *o = isa == BG_ISA_SCALAR ? ref : got;
            /* N - 1 samples: a tail shorter than any vector. */
            bg_fractal3_grad_footprint_batch(&ft, fp, px, py, pz, N - 1, o, o + N, o + 2 * N, o + 3 * N);
            int same = 1;
            for (int k = 0; k < 4; k++)
                same &= !memcmp(ref + k * N, o + k * N, (N - 1) * sizeof(float));
            float *ph = isa == BG_ISA_SCALAR ? h1 : h2, *pxo = isa == BG_ISA_SCALAR ? o1x : o2x,
                  *pyo = isa == BG_ISA_SCALAR ? o1y : o2y, *pzo = isa == BG_ISA_SCALAR ? o1z : o2z;
            bg_perturb_height_footprint_batch(&h, BG_PERTURB_ADDITIVE, fp, px, py, pz, nx, ny, nz, N - 1,
                                              ph, pxo, pyo, pzo);
            if (isa != BG_ISA_SCALAR)
                same &= !memcmp(h1, h2, (N - 1) * sizeof(float)) && !memcmp(o1x, o2x, (N - 1) * sizeof(float)) &&
                        !memcmp(o1y, o2y, (N - 1) * sizeof(float)) && !memcmp(o1z, o2z, (N - 1) * sizeof(float));
            if (isa != BG_ISA_SCALAR)
                CHECK(same, "footprint kernels on %s == scalar, bit for bit", bg_isa_name((bg_isa)isa));
        }
        bg_isa_force(best);
        free(ref), free(got);
    }
    free(buf);
    return check_summary("test_footprint");
}
