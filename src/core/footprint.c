/* SPDX-License-Identifier: MIT */
/* Footprint-aware fBm/turbulence: evaluate no octave finer than the sample's
 * footprint can show (noise.h explains the weight rule). The batches run the
 * kernel template (fractal_fp_vec in src/kernels/bump_tmpl.c), which weights each
 * octave per lane and stops at the first octave no lane can show; a weight of 1
 * multiplies exactly, so footprint 0 reproduces the unfiltered kernels bit for
 * bit (tests/accuracy/test_footprint.c). The scalar helpers below use the same
 * formula for callers that plan their own octave loops. */
#include <math.h>
#include "bumpgrad/noise.h"
#include "bumpgrad/surfgrad.h"
#include "kernels/kernels.h"
#include "params.h"

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
    if (octave < 0 || octave >= BG_MAX_OCTAVES || !(lacunarity > 0) || !isfinite(lacunarity))
        return NAN;
    float freq = 1.0f;
    for (int i = 0; i < octave; i++)
        freq *= lacunarity;
    return weight_of_ratio(footprint * freq);
}

float bg_octaves_for_footprint(float footprint, int max_octaves)
{
    if (max_octaves < 0 || max_octaves > BG_MAX_OCTAVES)
        return NAN;
    float sum = 0.0f, freq = 1.0f;
    for (int i = 0; i < max_octaves; i++, freq *= 2.0f)
        sum += weight_of_ratio(footprint * freq);
    return sum;
}

/* The footprint of a ray-traced sample: the longer of its two ray differentials. */
float bg_footprint_from_differentials(bg_vec3 dpdx, bg_vec3 dpdy)
{
    float fx = sqrtf(dpdx.x * dpdx.x + dpdx.y * dpdx.y + dpdx.z * dpdx.z);
    float fy = sqrtf(dpdy.x * dpdy.x + dpdy.y * dpdy.y + dpdy.z * dpdy.z);
    if (isnan(fx) || isnan(fy))
        return NAN;
    return fx > fy ? fx : fy;
}

/* The batch contract of noise.h: n = 0 reads nothing; checks before writes. */
bg_status bg_fractal3_grad_footprint_batch(const bg_fractal *f, const float *footprint,
                                           const float *x, const float *y, const float *z,
                                           size_t n, float *value, float *gx, float *gy, float *gz)
{
    if (n == 0)
        return BG_OK;
    if (!f || !footprint || !x || !y || !z || !gx || !gy || !gz)
        return BG_ERR_NULL_POINTER;
    bg_status s = bg_fractal_validate(f);
    if (s != BG_OK)
        return s;
    bg_kernels()->fractal3_grad_fp(f, footprint, x, y, z, n, value, gx, gy, gz);
    return BG_OK;
}

bg_status bg_perturb_height_footprint_batch(const bg_height *h, bg_perturb_method method,
                                            const float *footprint, const float *px,
                                            const float *py, const float *pz, const float *nx,
                                            const float *ny, const float *nz, size_t n,
                                            float *height, float *ox, float *oy, float *oz)
{
    if (n == 0)
        return BG_OK;
    if (!footprint)
        return BG_ERR_NULL_POINTER;
    bg_status s = bg_perturb_height_check(h, method, px, py, pz, nx, ny, nz, ox, oy, oz);
    if (s != BG_OK)
        return s;
    bg_kernels()->perturb_height_fp(h, method, footprint, px, py, pz, nx, ny, nz, n, height, ox, oy,
                                    oz);
    return BG_OK;
}
