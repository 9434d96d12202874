/* SPDX-License-Identifier: MIT */
/**
 * @file noise.h
 * @brief Perlin's improved noise (2002) with its analytic gradient, and the
 *        fBm / turbulence sums of Perlin (1985), in float and double.
 *
 * Values follow Perlin's 2002 reference implementation exactly: his permutation
 * table, the quintic fade 6t^5-15t^4+10t^3 and his 12(+4) gradient vectors.
 * The double entry points reproduce the reference bit for bit
 * (bg_noise3d(3.14, 42, 7) == 0.13691995878400012). The noise is 0 at every
 * lattice point and periodic with period 256 in each axis.
 *
 * Large coordinates: the lattice cell is reduced modulo 256 in floating point
 * before any integer conversion, so the double entry points stay exact for
 * |x| up to 2^52. The float entry points inherit float's spacing: above 2^23
 * every float is an integer, so that axis sits on the lattice (its fractional
 * part is 0) and the noise along it is piecewise constant at 1e5 and exactly
 * on lattice planes from 2^23 (about 8.4e6) up. See docs/STABILITY.md.
 *
 * NaN or Inf in any coordinate gives NaN value and NaN gradient (the canonical
 * quiet NaN, +qNaN: the same bits from every ISA and entry point).
 *
 * All functions are reentrant and thread-safe (no state besides constant tables).
 */
#ifndef BUMPGRAD_NOISE_H
#define BUMPGRAD_NOISE_H

#include "common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Which scalar field a fractal descriptor evaluates. */
typedef enum bg_function {
    BG_FUNC_NOISE = 0,      /**< one octave of noise, lacunarity and gain unused */
    BG_FUNC_FBM = 1,        /**< sum_i gain^i * noise(lacunarity^i * p) */
    BG_FUNC_TURBULENCE = 2  /**< sum_i gain^i * |noise(lacunarity^i * p)| (Perlin 1985) */
} bg_function;

/** Largest octave count accepted. */
#define BG_MAX_OCTAVES 32
/** Default octave count (Perlin 1985, Mikkelsen 2010 section 6: six octaves). */
#define BG_DEFAULT_OCTAVES 6
/** Default step of the central-difference gradient, in noise-space units.
 *  Chosen from the measured float32 error curve (docs/ACCURACY.md): for the
 *  default 6-octave fBm/turbulence the mean gradient error is smallest at
 *  h = 2e-4 (4e-4, against 1.7e-2 at 2e-3), for coordinates up to 1e3; the top
 *  octave runs at 32x the frequency, so its truncation error sets the optimum
 *  (single-octave noise alone would prefer 2e-3). The step must exceed half the
 *  float spacing of the coordinate, or x+h == x-h and that gradient component
 *  is reported as 0: with 2e-4 that happens from |coordinate| = 4096 on. */
#define BG_DEFAULT_CENTRAL_STEP 2e-4f

/** Fractal sum parameters. Octave i (0-based) samples noise at
 *  lacunarity^i * p with weight gain^i. */
typedef struct bg_fractal {
    bg_function function;
    int octaves;      /**< 1..BG_MAX_OCTAVES (ignored for BG_FUNC_NOISE) */
    float lacunarity; /**< frequency ratio between octaves, finite and > 0 */
    float gain;       /**< amplitude ratio between octaves, finite */
} bg_fractal;

/** Defaults: 6 octaves, lacunarity 2, gain 0.5. */
BG_API bg_fractal bg_fractal_default(bg_function function);

/** BG_OK if `f` is in range, else BG_ERR_INVALID_ARGUMENT (or BG_ERR_NULL_POINTER). */
BG_API bg_status bg_fractal_validate(const bg_fractal *f);

/* ---- single points ------------------------------------------------------ */

/** Improved noise at (x,y,z), float. Range about [-1, 1]. Same bits as the batch call. */
BG_API float bg_noise3(float x, float y, float z);

/** Noise value and its analytic gradient (dnoise) from the same pass.
 *  @param grad receives d noise / d(x,y,z); must not be NULL.
 *  Float accuracy against the double reference: |value| error <= 1e-5, gradient <= 5e-5. */
BG_API float bg_noise3_grad(float x, float y, float z, bg_vec3 *grad);

/** Improved noise in double; equals Perlin's reference implementation exactly. */
BG_API double bg_noise3d(double x, double y, double z);

/** Double noise value and analytic gradient. */
BG_API double bg_noise3d_grad(double x, double y, double z, bg_dvec3 *grad);

/** Fractal value (noise, fBm or turbulence) at (x,y,z). `f` must be valid. */
BG_API float bg_fractal3(const bg_fractal *f, float x, float y, float z);

/** Fractal value and analytic gradient. For turbulence the gradient of octave i
 *  is sign(noise_i) * grad noise_i; at a zero crossing of any octave the sum has a
 *  crease where the gradient is discontinuous (sign(0) is taken as +1). */
BG_API float bg_fractal3_grad(const bg_fractal *f, float x, float y, float z, bg_vec3 *grad);

/** Fractal value and central-difference gradient with step `h` (> 0): each
 *  component is (F(x+h) - F(x-h)) / ((x+h) - (x-h)), dividing by the step
 *  actually taken in floating point, not by the nominal 2h. 7 evaluations.
 *  If h is below the float spacing at x, so that x + h == x - h, that component
 *  is 0 (no slope can be measured), never NaN. */
BG_API float bg_fractal3_grad_central(const bg_fractal *f, float h, float x, float y, float z,
                                      bg_vec3 *grad);

/** Double-precision fractal entry points (float parameters widened exactly). */
BG_API double bg_fractal3d(const bg_fractal *f, double x, double y, double z);
BG_API double bg_fractal3d_grad(const bg_fractal *f, double x, double y, double z, bg_dvec3 *grad);
BG_API double bg_fractal3d_grad_central(const bg_fractal *f, double h, double x, double y, double z,
                                        bg_dvec3 *grad);

/* ---- batches (SoA) ------------------------------------------------------- */
/* Inputs are `n` points given as three arrays; outputs are written at [0, n).
 * No alignment is required. Output arrays must not overlap inputs, except that
 * an output may be exactly the same array as an input. Single-threaded and
 * reentrant; the ISA chosen by bg_isa_active() is used, and every ISA gives
 * the same bits as the scalar kernel. */

BG_API void bg_noise3_batch(const float *x, const float *y, const float *z, size_t n, float *value);

/** `value` may be NULL when only the gradient is wanted. */
BG_API void bg_noise3_grad_batch(const float *x, const float *y, const float *z, size_t n,
                                 float *value, float *gx, float *gy, float *gz);

BG_API void bg_fractal3_batch(const bg_fractal *f, const float *x, const float *y, const float *z,
                              size_t n, float *value);

/** `value` may be NULL. */
BG_API void bg_fractal3_grad_batch(const bg_fractal *f, const float *x, const float *y,
                                   const float *z, size_t n, float *value, float *gx, float *gy,
                                   float *gz);

/** `value` may be NULL. */
BG_API void bg_fractal3_grad_central_batch(const bg_fractal *f, float h, const float *x,
                                           const float *y, const float *z, size_t n, float *value,
                                           float *gx, float *gy, float *gz);

/* ---- footprint-aware evaluation ("model no more than a scene needs") -------
 * A sample that covers a footprint of width w (in noise-space units: the pixel's
 * footprint on the surface times the frequency) cannot show noise features
 * smaller than 2w (Nyquist: Perlin noise has one lattice cell per unit). Octave i
 * has cells 1/L^i wide, so its resolution ratio is r_i = w L^i. Its weight is
 * c_i = clamp(2 - 4 r_i, 0, 1): 1 while r_i <= 1/4, fading linearly to 0 at the
 * Nyquist limit r_i = 1/2. For lacunarity 2 the fade spans exactly one octave, so
 * the sum changes continuously with w (no popping as the footprint changes), and
 * octaves with c_i = 0 are not evaluated at all. w = 0 keeps every octave and gives
 * the same bits as the unfiltered call. */

/** Weight c_i of octave `octave` (0-based) for footprint `footprint` (>= 0, noise
 *  space) and lacunarity `lacunarity`. NaN footprint: 1 (no filtering). */
BG_API float bg_octave_weight(float footprint, float lacunarity, int octave);

/** Effective octave count for lacunarity 2: sum of the weights c_i of octaves
 *  0..max_octaves-1 (fractional when the last kept octave is fading), e.g. 6 for a
 *  tiny footprint, about 2.5 for footprint 1/16, 0 at footprint >= 1/2. */
BG_API float bg_octaves_for_footprint(float footprint, int max_octaves);

/** Fractal value and analytic gradient with per-sample footprints (noise space):
 *  octave i is weighted by c_i as above and skipped where c_i = 0 for every
 *  sample. `value` may be NULL. Uses the dispatched noise kernel per octave. */
BG_API void bg_fractal3_grad_footprint_batch(const bg_fractal *f, const float *footprint,
                                             const float *x, const float *y, const float *z,
                                             size_t n, float *value, float *gx, float *gy,
                                             float *gz);

/** Double batches (scalar loops over the double entry points). `value` may be NULL. */
BG_API void bg_fractal3d_grad_batch(const bg_fractal *f, const double *x, const double *y,
                                    const double *z, size_t n, double *value, double *gx,
                                    double *gy, double *gz);

#ifdef __cplusplus
}
#endif

#endif /* BUMPGRAD_NOISE_H */
