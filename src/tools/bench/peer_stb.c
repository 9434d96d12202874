/* SPDX-License-Identifier: MIT */
/* Peer for `bumpgrad bench` (bench.h): Sean Barrett's stb_perlin (Debian libstb-dev), used
 * only through its public header. This is the one translation unit of bumpgrad
 * that instantiates it, so STB_PERLIN_IMPLEMENTATION is defined here and nowhere
 * else. stb_perlin is also improved noise (Perlin 2002) in float, the closest
 * peer to our noise3, so its ratios are the ones the targets refer to. */
#define STB_PERLIN_IMPLEMENTATION
#include <stb/stb_perlin.h>

#include "bench/bench.h"
#include "bumpgrad/noise.h"
#include "bench/peers.h"

/* Wrap 0 means "no wrapping" (period 256, as ours). */
static inline float stb_value(float x, float y, float z)
{
    return stb_perlin_noise3(x, y, z, 0, 0, 0);
}

static void stb_value_batch(const float *x, const float *y, const float *z, size_t n, float *v,
                            float *gx, float *gy, float *gz)
{
    (void)gx, (void)gy, (void)gz;
    for (size_t i = 0; i < n; i++)
        v[i] = stb_value(x[i], y[i], z[i]);
}

static void stb_fbm_batch(const float *x, const float *y, const float *z, size_t n, float *v,
                          float *gx, float *gy, float *gz)
{
    (void)gx, (void)gy, (void)gz;
    for (size_t i = 0; i < n; i++)
        v[i] = stb_perlin_fbm_noise3(x[i], y[i], z[i], 2.0f, 0.5f, 6);
}

static void stb_grad_central_batch(const float *x, const float *y, const float *z, size_t n,
                                   float *v, float *gx, float *gy, float *gz)
{
    bench_central7_batch(stb_value, x, y, z, n, v, gx, gy, gz);
}

size_t bench_peers_stb(bgt_bench_peer *out, size_t cap)
{
    const bgt_bench_peer all[] = {
        {"stb_perlin", BGT_PEER_VALUE, stb_value_batch},
        {"stb_perlin", BGT_PEER_FBM, stb_fbm_batch},
        {"stb_perlin", BGT_PEER_GRAD_CENTRAL, stb_grad_central_batch},
    };
    size_t k = 0;
    for (; k < sizeof all / sizeof all[0] && k < cap; k++)
        out[k] = all[k];
    return k;
}
