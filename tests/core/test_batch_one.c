/* SPDX-License-Identifier: MIT */
/* A batch of one point takes the single-point path (noise.c); it must give
 * the bits the vector kernel gives that point inside a full batch, on every
 * ISA level this CPU supports, with and without the value output. Bits are
 * compared with memcmp, so NaN payloads and signed zeros count too. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "bumpgrad.h"
#include "ref.h"
#include "check.h"

#define N 777

static float px[N], py[N], pz[N];

static void fill(void)
{
    ref_rng r;
    ref_rng_seed(&r, 1234);
    const float special[] = {0.0f, -0.0f, 2.0f, 22.0f, -256.0f, 1e6f, NAN, INFINITY};
    for (int i = 0; i < N; i++) {
        float *p[3] = {&px[i], &py[i], &pz[i]};
        for (int a = 0; a < 3; a++)
            *p[a] = i % 9 == 0 ? special[(i / 9 + a) % 8] : (float)ref_rng_uniform(&r, -80, 80);
    }
}

static int differ(float a, float b)
{
    return memcmp(&a, &b, sizeof a) != 0;
}

/* Returns the number of points whose n = 1 call differs from the full batch. */
static int check_level(const bg_fractal *f)
{
    static float v[N], gx[N], gy[N], gz[N], fv[N], fx[N], fy[N], fz[N];
    int bad = 0;
    bg_noise3_grad_batch(px, py, pz, N, v, gx, gy, gz);
    bg_noise3_batch(px, py, pz, N, fv);
    bg_fractal3_grad_batch(f, px, py, pz, N, NULL, fx, fy, fz);
    for (int i = 0; i < N; i++) {
        float a, b, c, d, e, s, t, u, w;
        bg_noise3_batch(px + i, py + i, pz + i, 1, &a);
        bg_noise3_grad_batch(px + i, py + i, pz + i, 1, &b, &c, &d, &e);
        bg_noise3_grad_batch(px + i, py + i, pz + i, 1, NULL, &s, &t, &u);
        bad += differ(a, fv[i]) || differ(b, v[i]) || differ(c, gx[i]) || differ(d, gy[i]) ||
               differ(e, gz[i]) || differ(s, gx[i]) || differ(t, gy[i]) || differ(u, gz[i]);
        bg_fractal3_grad_batch(f, px + i, py + i, pz + i, 1, &w, &s, &t, &u);
        bad += differ(s, fx[i]) || differ(t, fy[i]) || differ(u, fz[i]);
        float fw;
        bg_fractal3_batch(f, px + i, py + i, pz + i, 1, &fw);
        bad += differ(fw, w);
    }
    /* the fractal value of the full batch against the n = 1 value */
    bg_fractal3_batch(f, px, py, pz, N, fv);
    for (int i = 0; i < N; i++) {
        float w;
        bg_fractal3_batch(f, px + i, py + i, pz + i, 1, &w);
        bad += differ(w, fv[i]);
    }
    return bad;
}

int main(void)
{
    fill();
    bg_fractal fr[3] = {bg_fractal_default(BG_FUNC_FBM), bg_fractal_default(BG_FUNC_FBM),
                        bg_fractal_default(BG_FUNC_TURBULENCE)};
    fr[1].octaves = 9; /* 8 octaves across the AVX2 lanes, then one scalar */
    int levels = 0;
    for (int isa = 0; isa < BG_ISA_COUNT; isa++) {
        if (!bg_isa_supported((bg_isa)isa))
            continue;
        CHECK(bg_isa_force((bg_isa)isa) == BG_OK, "could not force an ISA");
        for (int k = 0; k < 3; k++) {
            int bad = check_level(&fr[k]);
            printf("%-7s fractal %d: %d of %d points differ\n", bg_isa_name((bg_isa)isa), k, bad,
                   N);
            CHECK(bad == 0, "a batch of one point differs from the full batch");
        }
        levels++;
    }
    CHECK(levels >= 1, "no ISA level was tested");
    printf("n = 1 batches equal the full batch on %d ISA level(s)\n", levels);
    return 0;
}
