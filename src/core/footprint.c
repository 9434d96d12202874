/* SPDX-License-Identifier: MIT */
/* Footprint-aware fBm/turbulence: evaluate no octave finer than the sample's
 * footprint can show (noise.h explains the weight rule). Each octave is one call
 * of the dispatched noise kernel on the samples that still need it (compacted),
 * so the SIMD levels are used and skipped octaves cost nothing. The sums are
 * accumulated in exactly the order of the template's fractal loop, so weight 1
 * everywhere reproduces the unfiltered kernels bit for bit (tested). */
#include <math.h>
#include "bumpgrad/noise.h"
#include "bumpgrad/surfgrad.h"
#include "kernels/kernels.h"

enum { CHUNK = 256 };

/* Weight from the resolution ratio r = footprint * lacunarity^i. */
static float weight_of_ratio(float r)
{
    if (isnan(r))
        return 1.0f;
    float c = 2.0f - 4.0f * r;
    return c > 1.0f ? 1.0f : c < 0.0f ? 0.0f : c;
}

float bg_octave_weight(float footprint, float lacunarity, int octave)
{
    float freq = 1.0f;
    for (int i = 0; i < octave; i++)
        freq *= lacunarity;
    return weight_of_ratio(footprint * freq);
}

float bg_octaves_for_footprint(float footprint, int max_octaves)
{
    float sum = 0.0f, freq = 1.0f;
    for (int i = 0; i < max_octaves; i++, freq *= 2.0f)
        sum += weight_of_ratio(footprint * freq);
    return sum;
}

/* One chunk (m <= CHUNK samples). */
static void fractal_fp_chunk(const bg_kernel_table *k, const bg_fractal *f, const float *fp,
                             const float *x, const float *y, const float *z, size_t m,
                             float *value, float *gx, float *gy, float *gz)
{
    float qx[CHUNK], qy[CHUNK], qz[CHUNK], w[CHUNK], nv[CHUNK], ngx[CHUNK], ngy[CHUNK], ngz[CHUNK];
    unsigned short idx[CHUNK];
    const int noise_only = f->function == BG_FUNC_NOISE;
    const int turb = f->function == BG_FUNC_TURBULENCE;
    const int octaves = noise_only ? 1 : f->octaves;
    for (size_t s = 0; s < m; s++)
        value[s] = gx[s] = gy[s] = gz[s] = 0.0f;
    float amp = 1.0f, freq = 1.0f;
    for (int i = 0; i < octaves; i++) {
        size_t cnt = 0;
        for (size_t s = 0; s < m; s++) {
            float c = weight_of_ratio(fp[s] > 0 ? fp[s] * freq : 0.0f);
            if (c > 0.0f) {
                idx[cnt] = (unsigned short)s, w[cnt] = c;
                qx[cnt] = x[s] * freq, qy[cnt] = y[s] * freq, qz[cnt] = z[s] * freq;
                cnt++;
            }
        }
        /* Ratios grow with the octave when lacunarity >= 1: nothing left to do. */
        if (cnt == 0 && f->lacunarity >= 1.0f)
            break;
        k->noise3_grad(qx, qy, qz, cnt, nv, ngx, ngy, ngz);
        const float af0 = amp * freq;
        for (size_t j = 0; j < cnt; j++) {
            size_t s = idx[j];
            if (noise_only) {
                /* Not a sum: weight 1 must return the noise itself (even -0). */
                value[s] = w[j] * nv[j];
                gx[s] = w[j] * ngx[j], gy[s] = w[j] * ngy[j], gz[s] = w[j] * ngz[j];
                continue;
            }
            float a = amp * w[j], af = af0 * w[j];
            if (turb) {
                value[s] = value[s] + a * fabsf(nv[j]);
                af = nv[j] < 0 ? -af : af; /* sign(0) = +1, as the kernels */
            } else {
                value[s] = value[s] + a * nv[j];
            }
            gx[s] = gx[s] + af * ngx[j];
            gy[s] = gy[s] + af * ngy[j];
            gz[s] = gz[s] + af * ngz[j];
        }
        amp *= f->gain;
        freq *= f->lacunarity;
    }
}

void bg_fractal3_grad_footprint_batch(const bg_fractal *f, const float *footprint, const float *x,
                                      const float *y, const float *z, size_t n, float *value,
                                      float *gx, float *gy, float *gz)
{
    const bg_kernel_table *k = bg_kernels();
    float vtmp[CHUNK];
    for (size_t i = 0; i < n; i += CHUNK) {
        size_t m = n - i < CHUNK ? n - i : CHUNK;
        fractal_fp_chunk(k, f, footprint + i, x + i, y + i, z + i, m, value ? value + i : vtmp,
                         gx + i, gy + i, gz + i);
    }
}

void bg_perturb_height_footprint_batch(const bg_height *h, bg_perturb_method method,
                                       const float *footprint, const float *px, const float *py,
                                       const float *pz, const float *nx, const float *ny,
                                       const float *nz, size_t n, float *height, float *ox,
                                       float *oy, float *oz)
{
    const bg_kernel_table *k = bg_kernels();
    float qx[CHUNK], qy[CHUNK], qz[CHUNK], fq[CHUNK], v[CHUNK], gx[CHUNK], gy[CHUNK], gz[CHUNK];
    const float freq = h->frequency, amp = h->amplitude, af = h->amplitude * h->frequency;
    for (size_t i = 0; i < n; i += CHUNK) {
        size_t m = n - i < CHUNK ? n - i : CHUNK;
        /* The same products as the fused kernel: q = f p, grad h = (A f) F'. */
        for (size_t s = 0; s < m; s++) {
            qx[s] = px[i + s] * freq, qy[s] = py[i + s] * freq, qz[s] = pz[i + s] * freq;
            fq[s] = footprint[i + s] * freq;
        }
        fractal_fp_chunk(k, &h->fractal, fq, qx, qy, qz, m, v, gx, gy, gz);
        for (size_t s = 0; s < m; s++) {
            gx[s] = af * gx[s], gy[s] = af * gy[s], gz[s] = af * gz[s];
            if (height)
                height[i + s] = amp * v[s];
        }
        k->perturb(method, nx + i, ny + i, nz + i, gx, gy, gz, m, ox + i, oy + i, oz + i);
    }
}
