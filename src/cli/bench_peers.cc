// SPDX-License-Identifier: MIT
// Peers for `bumpgrad bench` that are C++ libraries: libnoise (libnoise-dev) and
// glm::perlin (libglm-dev). The only C++ of the command; it is compiled only when
// a C++ compiler and at least one of the two libraries were found, and each
// library separately only when meson defines CLI_HAVE_PEER_LIBNOISE / _GLM.
// Nothing here throws across the extern "C" boundary: none of the calls used
// can throw (libnoise throws only on invalid module settings, which are fixed).
#include "bench_peers.h"
#include "bumpgrad/noise.h"

#include <cstddef>

#if CLI_HAVE_PEER_LIBNOISE
#include <libnoise/noise.h>
#endif
#if CLI_HAVE_PEER_GLM
#include <glm/gtc/noise.hpp>
#include <glm/vec3.hpp>
#endif

namespace
{

// The step of bumpgrad's own central differences, so that both sides of the
// grad_central comparison do the same 7 evaluations at the same points.
const float central_step = BG_DEFAULT_CENTRAL_STEP;

// Value + central-difference gradient from any scalar noise: the 7 evaluations a
// caller without an analytic gradient pays. Divides by the step actually taken.
template <typename F>
inline void central7(F f, float px, float py, float pz, float *v, float *gx, float *gy, float *gz)
{
    const float h = central_step;
    float xp = px + h, xm = px - h, yp = py + h, ym = py - h, zp = pz + h, zm = pz - h;
    *v = f(px, py, pz);
    *gx = (f(xp, py, pz) - f(xm, py, pz)) / (xp - xm);
    *gy = (f(px, yp, pz) - f(px, ym, pz)) / (yp - ym);
    *gz = (f(px, py, zp) - f(px, py, zm)) / (zp - zm);
}

#if CLI_HAVE_PEER_LIBNOISE
// QUALITY_BEST selects the quintic fade of improved noise, the same interpolant
// as ours and stb_perlin's (libnoise's default QUALITY_STD is the cubic one).
inline float ln_value(float x, float y, float z)
{
    return static_cast<float>(noise::GradientCoherentNoise3D(x, y, z, 0, noise::QUALITY_BEST));
}

void ln_value_batch(const float *x, const float *y, const float *z, std::size_t n, float *v,
                    float *, float *, float *)
{
    for (std::size_t i = 0; i < n; i++)
        v[i] = ln_value(x[i], y[i], z[i]);
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

void ln_grad_central_batch(const float *x, const float *y, const float *z, std::size_t n, float *v,
                           float *gx, float *gy, float *gz)
{
    for (std::size_t i = 0; i < n; i++)
        central7(ln_value, x[i], y[i], z[i], v + i, gx + i, gy + i, gz + i);
}
#endif

#if CLI_HAVE_PEER_GLM
inline float glm_value(float x, float y, float z)
{
    return glm::perlin(glm::vec3(x, y, z));
}

void glm_value_batch(const float *x, const float *y, const float *z, std::size_t n, float *v,
                     float *, float *, float *)
{
    for (std::size_t i = 0; i < n; i++)
        v[i] = glm_value(x[i], y[i], z[i]);
}

// glm has no fractal sum; this is the loop a glm user writes, with the same
// parameters as the other fbm rows.
void glm_fbm_batch(const float *x, const float *y, const float *z, std::size_t n, float *v, float *,
                   float *, float *)
{
    for (std::size_t i = 0; i < n; i++) {
        float sum = 0.0f, amp = 1.0f, freq = 1.0f;
        for (int o = 0; o < 6; o++) {
            sum += amp * glm_value(freq * x[i], freq * y[i], freq * z[i]);
            amp *= 0.5f;
            freq *= 2.0f;
        }
        v[i] = sum;
    }
}

void glm_grad_central_batch(const float *x, const float *y, const float *z, std::size_t n, float *v,
                            float *gx, float *gy, float *gz)
{
    for (std::size_t i = 0; i < n; i++)
        central7(glm_value, x[i], y[i], z[i], v + i, gx + i, gy + i, gz + i);
}
#endif

} // namespace

extern "C" size_t cli_bench_peers_cxx(cli_peer *out, size_t cap)
{
    const cli_peer all[] = {
#if CLI_HAVE_PEER_LIBNOISE
        {"libnoise", CLI_PEER_VALUE, ln_value_batch},
        {"libnoise", CLI_PEER_FBM, ln_fbm_batch},
        {"libnoise", CLI_PEER_GRAD_CENTRAL, ln_grad_central_batch},
#endif
#if CLI_HAVE_PEER_GLM
        {"glm", CLI_PEER_VALUE, glm_value_batch},
        {"glm", CLI_PEER_FBM, glm_fbm_batch},
        {"glm", CLI_PEER_GRAD_CENTRAL, glm_grad_central_batch},
#endif
        {nullptr, CLI_PEER_VALUE, nullptr},
    };
    std::size_t k = 0;
    for (; all[k].run != nullptr && k < cap; k++)
        out[k] = all[k];
    return k;
}
