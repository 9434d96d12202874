// SPDX-License-Identifier: MIT
// Peers for `bumpgrad bench` that are C++ libraries: libnoise (libnoise-dev) and
// glm::perlin (libglm-dev). The only C++ of the bench; it is compiled only when
// a C++ compiler and at least one of the two libraries were found, and each
// library separately only when meson defines BGT_HAVE_PEER_LIBNOISE / _GLM.
// Nothing here throws across the extern "C" boundary: none of the calls used
// can throw (libnoise throws only on invalid module settings, which are fixed).
#include "bench/peers.h"
#include "bumpgrad/noise.h"

#include <cstddef>

#if BGT_HAVE_PEER_LIBNOISE
#include <libnoise/noise.h>
#endif
#if BGT_HAVE_PEER_GLM
#include <glm/gtc/noise.hpp>
#include <glm/vec3.hpp>
#endif

namespace
{

typedef float (*point_fn)(float, float, float);

// One call of F per point: the value and fbm rows of every peer.
template <point_fn F>
void point_batch(const float *x, const float *y, const float *z, std::size_t n, float *v, float *,
                 float *, float *)
{
    for (std::size_t i = 0; i < n; i++)
        v[i] = F(x[i], y[i], z[i]);
}

// Value + 7-evaluation central gradient (peers.h) of any scalar noise.
template <point_fn F>
void central7_batch(const float *x, const float *y, const float *z, std::size_t n, float *v,
                    float *gx, float *gy, float *gz)
{
    bench_central7_batch(F, x, y, z, n, v, gx, gy, gz);
}

#if BGT_HAVE_PEER_LIBNOISE
// QUALITY_BEST selects the quintic fade of improved noise, the same interpolant
// as ours and stb_perlin's (libnoise's default QUALITY_STD is the cubic one).
float ln_value(float x, float y, float z)
{
    return static_cast<float>(noise::GradientCoherentNoise3D(x, y, z, 0, noise::QUALITY_BEST));
}

// module::Perlin is libnoise's fBm; GetValue is const, so one module per call
// keeps the batch reentrant without sharing mutable state between threads.
void ln_fbm_batch(const float *x, const float *y, const float *z, std::size_t n, float *v, float *,
                  float *, float *)
{
    noise::module::Perlin perlin;
    perlin.SetFrequency(1.0);
    perlin.SetLacunarity(2.0);
    perlin.SetPersistence(0.5);
    perlin.SetOctaveCount(6);
    perlin.SetNoiseQuality(noise::QUALITY_BEST);
    for (std::size_t i = 0; i < n; i++)
        v[i] = static_cast<float>(perlin.GetValue(x[i], y[i], z[i]));
}
#endif

#if BGT_HAVE_PEER_GLM
float glm_value(float x, float y, float z)
{
    return glm::perlin(glm::vec3(x, y, z));
}

// glm has no fractal sum; this is the loop a glm user writes, with the same
// parameters as the other fbm rows.
float glm_fbm(float x, float y, float z)
{
    float sum = 0.0f, amp = 1.0f, freq = 1.0f;
    for (int o = 0; o < 6; o++) {
        sum += amp * glm_value(freq * x, freq * y, freq * z);
        amp *= 0.5f;
        freq *= 2.0f;
    }
    return sum;
}
#endif

} // namespace

extern "C" size_t bench_peers_cxx(bgt_bench_peer *out, size_t cap)
{
    const bgt_bench_peer all[] = {
#if BGT_HAVE_PEER_LIBNOISE
        {"libnoise", BGT_PEER_VALUE, point_batch<ln_value>},
        {"libnoise", BGT_PEER_FBM, ln_fbm_batch},
        {"libnoise", BGT_PEER_GRAD_CENTRAL, central7_batch<ln_value>},
#endif
#if BGT_HAVE_PEER_GLM
        {"glm", BGT_PEER_VALUE, point_batch<glm_value>},
        {"glm", BGT_PEER_FBM, point_batch<glm_fbm>},
        {"glm", BGT_PEER_GRAD_CENTRAL, central7_batch<glm_value>},
#endif
        {nullptr, BGT_PEER_VALUE, nullptr},
    };
    std::size_t k = 0;
    for (; all[k].run != nullptr && k < cap; k++)
        out[k] = all[k];
    return k;
}
