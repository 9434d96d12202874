/* SPDX-License-Identifier: MIT */
/* Forcing an ISA with the BUMPGRAD_ISA environment variable changes no output
 * bit of the public batch API. The program re-runs itself once per ISA level the
 * machine supports, with BUMPGRAD_ISA set (the variable is read once, at the first
 * batch call, so each level needs its own process; the parent never makes one),
 * and compares per-call hashes
 * of every output with the scalar run. Every bit is hashed, NaNs included: NaN
 * results are the one canonical quiet NaN on every ISA (docs/KERNELS.md).
 * Public API only. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bumpgrad.h"
#include "isa_child.h"

enum { N = 3001, NAPI = 12 }; /* odd length: every ISA runs a tail */

static uint64_t hash_floats(uint64_t h, const float *p, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        uint32_t u;
        memcpy(&u, &p[i], sizeof u);
        for (int b = 0; b < 4; b++) {
            h ^= (u >> (8 * b)) & 0xFF;
            h *= 0x100000001B3ull; /* FNV-1a */
        }
    }
    return h;
}

static uint64_t rng = 12345;
static float rnd(float lo, float hi)
{
    rng = rng * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * (float)((rng >> 40) * (1.0 / 16777216.0));
}

static int child(void)
{
    static float x[N], y[N], z[N], nx[N], ny[N], nz[N], v[N], a[N], b[N], c[N];
    static const float special[] = {0.0f, -0.0f, 1.0f, -1.0f, 255.5f, -256.0f, 1e4f, 1e7f,
                                    3e38f, NAN, INFINITY, -INFINITY, 1e-40f};
    for (int i = 0; i < N; i++) {
        x[i] = i % 17 == 0 ? special[(i / 17) % 13] : rnd(-200, 200);
        y[i] = i % 19 == 0 ? special[(i / 19) % 13] : rnd(-200, 200);
        z[i] = rnd(-200, 200);
        nx[i] = i % 23 == 0 ? special[(i / 23) % 13] : rnd(-1, 1);
        ny[i] = rnd(-1, 1);
        nz[i] = rnd(-1, 1);
    }
    uint64_t h[NAPI];
    for (int k = 0; k < NAPI; k++)
        h[k] = 0xCBF29CE484222325ull;
    bg_fractal turb = bg_fractal_default(BG_FUNC_TURBULENCE);
    bg_fractal fbm = {BG_FUNC_FBM, 5, 2.1f, 0.55f};

    bg_noise3_batch(x, y, z, N, v);
    h[0] = hash_floats(h[0], v, N);
    bg_noise3_grad_batch(x, y, z, N, v, a, b, c);
    h[1] = hash_floats(hash_floats(hash_floats(hash_floats(h[1], v, N), a, N), b, N), c, N);
    bg_fractal3_batch(&turb, x, y, z, N, v);
    h[2] = hash_floats(h[2], v, N);
    bg_fractal3_grad_batch(&fbm, x, y, z, N, v, a, b, c);
    h[3] = hash_floats(hash_floats(hash_floats(hash_floats(h[3], v, N), a, N), b, N), c, N);
    bg_fractal3_grad_batch(&turb, x, y, z, N, NULL, a, b, c);
    h[4] = hash_floats(hash_floats(hash_floats(h[4], a, N), b, N), c, N);
    bg_fractal3_grad_central_batch(&turb, 2e-3f, x, y, z, N, v, a, b, c);
    h[5] = hash_floats(hash_floats(hash_floats(hash_floats(h[5], v, N), a, N), b, N), c, N);
    for (int m = 0; m < 3; m++) {
        bg_perturb_batch((bg_perturb_method)m, nx, ny, nz, x, y, z, N, a, b, c);
        h[6 + m] = hash_floats(hash_floats(hash_floats(h[6 + m], a, N), b, N), c, N);
    }
    bg_height hg = bg_height_default();
    bg_perturb_height_batch(&hg, BG_PERTURB_SURFGRAD, x, y, z, nx, ny, nz, N, v, a, b, c);
    h[9] = hash_floats(hash_floats(hash_floats(hash_floats(h[9], v, N), a, N), b, N), c, N);
    hg.gradient = BG_GRADIENT_CENTRAL;
    bg_perturb_height_batch(&hg, BG_PERTURB_ADDITIVE, x, y, z, nx, ny, nz, N, v, a, b, c);
    h[10] = hash_floats(hash_floats(hash_floats(hash_floats(h[10], v, N), a, N), b, N), c, N);
    /* In-place: outputs alias the inputs exactly (allowed by the API). */
    memcpy(a, x, sizeof a), memcpy(b, y, sizeof b), memcpy(c, z, sizeof c);
    bg_noise3_grad_batch(a, b, c, N, v, a, b, c);
    h[11] = hash_floats(hash_floats(hash_floats(hash_floats(h[11], v, N), a, N), b, N), c, N);

    printf("%s", bg_isa_name(bg_isa_active()));
    for (int k = 0; k < NAPI; k++)
        printf(" %016llx", (unsigned long long)h[k]);
    printf("\n");
    return 0;
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "--child") == 0)
        return child();
    static const char *const names[] = {"scalar", "sse2", "avx2", "avx512", "neon"};
    bg_isa best = bg_isa_best();
    char ref[1024], got[1024];
    if (run_child(argv[0], "scalar", ref, sizeof ref, child) != 0 ||
        strncmp(ref, "scalar ", 7) != 0) {
        fprintf(stderr, "FAIL: scalar run: %s\n", ref);
        return 1;
    }
    printf("%s", ref);
    int fails = 0, runs = 0;
    for (int i = 1; i < BG_ISA_COUNT; i++) {
        bg_isa isa = (bg_isa)i;
        int supported = best == BG_ISA_NEON ? isa == BG_ISA_NEON
                                            : best != BG_ISA_SCALAR && isa <= best && isa != BG_ISA_NEON;
        if (!supported)
            continue;
        runs++;
        if (run_child(argv[0], names[i], got, sizeof got, child) != 0) {
            fprintf(stderr, "FAIL: child for %s failed\n", names[i]);
            fails++;
            continue;
        }
        printf("%s", got);
        /* The child must really have run the forced level ... */
        size_t ln = strlen(names[i]);
        if (strncmp(got, names[i], ln) != 0 || got[ln] != ' ') {
            fprintf(stderr, "FAIL: BUMPGRAD_ISA=%s not honoured: %s", names[i], got);
            fails++;
            continue;
        }
        /* ... and produced the scalar run's hashes, call by call. */
        if (strcmp(got + ln, ref + 6) != 0) {
            fprintf(stderr, "FAIL: BUMPGRAD_ISA=%s output differs from scalar\n", names[i]);
            fails++;
        }
    }
    printf("%d forced ISA levels compared with scalar, %d failures\n", runs, fails);
    return fails ? 1 : 0;
}
