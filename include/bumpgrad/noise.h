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
 * So does a finite coordinate whose octave scaling overflows: octave i samples
 * at lacunarity^i * p, which is Inf once |p| > bg_fractal_max_coordinate()
 * (docs/STABILITY.md, "Octave overflow").
 *
 * Parameters: bg_fractal_validate() is the one definition of a usable
 * descriptor. Batch calls run it once per call and return its status, writing
 * nothing on failure. Single-point calls, which cannot return a status, give
 * NaN (value and every gradient component) for a descriptor that is NULL or out
 * of range; a descriptor that is in range but fails only the overflow check
 * (BG_ERR_OVERFLOW) is not caught per point: its results may be Inf or NaN.
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
 *  lacunarity^i * p with weight gain^i; both factors are built in float by
 *  repeated multiplication (the double entry points: in double). */
typedef struct bg_fractal {
    bg_function function;
    int octaves;      /**< 1..BG_MAX_OCTAVES (ignored for BG_FUNC_NOISE) */
    float lacunarity; /**< frequency ratio between octaves, finite and > 0 */
    float gain;       /**< amplitude ratio between octaves, finite */
} bg_fractal;

/** Defaults: 6 octaves, lacunarity 2, gain 0.5. */
BG_API bg_fractal bg_fractal_default(bg_function function);

/** Check a fractal descriptor: the one rule every entry point applies.
 *  @return BG_OK;
 *   BG_ERR_NULL_POINTER if `f` is NULL;
 *   BG_ERR_INVALID_ARGUMENT if `function` is not a bg_function, or (fBm and
 *   turbulence) `octaves` is outside 1..BG_MAX_OCTAVES, `lacunarity` is not
 *   finite and > 0 or `gain` is not finite;
 *   BG_ERR_OVERFLOW if the octave scaling overflows float for some octave
 *   i < octaves: lacunarity^i, gain^i or gain^i * lacunarity^i (as the kernels
 *   compute them in float) is not finite, or a sum could overflow:
 *   2.1 * sum_i |gain^i| or 9 * sum_i |gain^i lacunarity^i| above FLT_MAX (2.1
 *   and 9 bound |noise| and each |d noise / dx| with a margin for rounding).
 *   Accepted descriptors give finite values and gradients for every finite
 *   coordinate up to bg_fractal_max_coordinate(f, 1) (e.g. `gain` 3e38 with 32
 *   octaves, or `lacunarity` 3e38 with 2 octaves, are BG_ERR_OVERFLOW). Plain
 *   noise (BG_FUNC_NOISE) ignores the other fields. Cost: one pass over the
 *   octaves (about 130 instructions for 6 octaves, 540 for 32); the batch
 *   calls run it once per call. */
BG_API bg_status bg_fractal_validate(const bg_fractal *f);

/** Largest |coordinate| for which every octave of `f` sees a finite point, when
 *  the coordinate is first multiplied by `frequency` in float, as the fused
 *  height calls do with bg_height.frequency (pass 1 for the bg_fractal3* calls,
 *  which take noise-space coordinates). Precisely: the largest float c such that
 *  (c * |frequency|) * lacunarity^i, rounded in float at each product, is finite
 *  for every octave i < octaves. Up to c every coordinate gives finite results
 *  (for an accepted `f`); above it some octave samples at Inf, so the value and
 *  gradient are NaN under the NaN rule (the footprint calls: unless the
 *  footprint drops that octave). The bound holds per axis. The central-
 *  difference calls also evaluate at q +- h, which adds h to the noise-space
 *  coordinate q (no change at such magnitudes for a step below the float
 *  spacing, as the default is). E.g. 6-octave turbulence with lacunarity 2:
 *  FLT_MAX / 32 rounded down, about 1.0634e37.
 *  @return that bound (FLT_MAX if every finite coordinate is safe, e.g.
 *   `frequency` 0), or NaN if bg_fractal_validate(f) is not BG_OK or
 *   `frequency` is not finite. */
BG_API float bg_fractal_max_coordinate(const bg_fractal *f, float frequency);

/** The same bound for the double entry points (bg_fractal3d*), whose octave
 *  factors and products are double: the largest double c such that
 *  (c * |frequency|) * lacunarity^i is finite in double for every octave. */
BG_API double bg_fractal_max_coordinated(const bg_fractal *f, double frequency);

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

/** Fractal value (noise, fBm or turbulence) at (x,y,z). `f` should pass
 *  bg_fractal_validate(); NULL or out of range (any check but the overflow one)
 *  gives NaN. */
BG_API float bg_fractal3(const bg_fractal *f, float x, float y, float z);

/** Fractal value and analytic gradient. For turbulence the gradient of octave i
 *  is sign(noise_i) * grad noise_i; at a zero crossing of any octave the sum has a
 *  crease where the gradient is discontinuous (sign(0) is taken as +1).
 *  `grad` must not be NULL. A NULL or out-of-range `f` gives NaN value and
 *  gradient, as for bg_fractal3. */
BG_API float bg_fractal3_grad(const bg_fractal *f, float x, float y, float z, bg_vec3 *grad);

/** Fractal value and central-difference gradient with step `h` (finite, > 0;
 *  otherwise, or for a NULL or out-of-range `f`, NaN value and gradient): each
 *  component is (F(x+h) - F(x-h)) / ((x+h) - (x-h)), dividing by the step
 *  actually taken in floating point, not by the nominal 2h. 7 evaluations.
 *  If h is below the float spacing at x, so that x + h == x - h, that component
 *  is 0 (no slope can be measured), never NaN. */
BG_API float bg_fractal3_grad_central(const bg_fractal *f, float h, float x, float y, float z,
                                      bg_vec3 *grad);

/** Double-precision fractal entry points (float parameters widened exactly);
 *  invalid `f` or `h` as for the float calls: NaN. */
BG_API double bg_fractal3d(const bg_fractal *f, double x, double y, double z);
BG_API double bg_fractal3d_grad(const bg_fractal *f, double x, double y, double z, bg_dvec3 *grad);
BG_API double bg_fractal3d_grad_central(const bg_fractal *f, double h, double x, double y, double z,
                                        bg_dvec3 *grad);

/* ---- batches (SoA) ------------------------------------------------------- */
/* Inputs are `n` points given as three arrays; outputs are written at [0, n).
 * No alignment is required. Output arrays must not overlap inputs, except that
 * an output may be exactly the same array as an input. Single-threaded and
 * reentrant; the ISA chosen by bg_isa_active() is used, and every ISA gives
 * the same bits as the scalar kernel.
 *
 * Every batch call (here and in surfgrad.h) has one contract:
 *  - n = 0: nothing is read (any pointer may be NULL, the descriptor is not
 *    looked at) and the result is BG_OK;
 *  - otherwise, checked once per call before any output is written, in this
 *    order: BG_ERR_NULL_POINTER if the descriptor or a required array is NULL
 *    (only arrays documented as optional may be); then the descriptor's
 *    validate status (bg_fractal_validate, bg_height_validate), then the other
 *    arguments (BG_ERR_INVALID_ARGUMENT: an unknown method, a step that is not
 *    finite and > 0);
 *  - on any status but BG_OK no output element has been written.
 * Point values are never refused: NaN/Inf coordinates give NaN results (the
 * NaN rule above). The checks cost one pass over the octaves per call, not per
 * point. */

/** Noise values. @return BG_OK or BG_ERR_NULL_POINTER. */
BG_API bg_status bg_noise3_batch(const float *x, const float *y, const float *z, size_t n,
                                 float *value);

/** Noise values and analytic gradients; `value` may be NULL when only the
 *  gradient is wanted. @return BG_OK or BG_ERR_NULL_POINTER. */
BG_API bg_status bg_noise3_grad_batch(const float *x, const float *y, const float *z, size_t n,
                                      float *value, float *gx, float *gy, float *gz);

/** Fractal values. @return BG_OK, BG_ERR_NULL_POINTER or the status of
 *  bg_fractal_validate(f) (BG_ERR_INVALID_ARGUMENT, BG_ERR_OVERFLOW). */
BG_API bg_status bg_fractal3_batch(const bg_fractal *f, const float *x, const float *y,
                                   const float *z, size_t n, float *value);

/** Fractal values and analytic gradients; `value` may be NULL. Statuses as
 *  bg_fractal3_batch. */
BG_API bg_status bg_fractal3_grad_batch(const bg_fractal *f, const float *x, const float *y,
                                        const float *z, size_t n, float *value, float *gx,
                                        float *gy, float *gz);

/** Fractal values and central-difference gradients with step `h`; `value` may
 *  be NULL. Statuses as bg_fractal3_batch, and BG_ERR_INVALID_ARGUMENT if `h`
 *  is not finite and > 0. */
BG_API bg_status bg_fractal3_grad_central_batch(const bg_fractal *f, float h, const float *x,
                                                const float *y, const float *z, size_t n,
                                                float *value, float *gx, float *gy, float *gz);

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
 *  space) and lacunarity `lacunarity`. NaN footprint: 1 (no filtering).
 *  `octave` outside 0..BG_MAX_OCTAVES-1 or `lacunarity` not finite and > 0: NaN. */
BG_API float bg_octave_weight(float footprint, float lacunarity, int octave);

/** Effective octave count for lacunarity 2: sum of the weights c_i of octaves
 *  0..max_octaves-1 (fractional when the last kept octave is fading), e.g. 6 for a
 *  tiny footprint, about 2.5 for footprint 1/16, 0 at footprint >= 1/2.
 *  `max_octaves` outside 0..BG_MAX_OCTAVES: NaN. */
BG_API float bg_octaves_for_footprint(float footprint, int max_octaves);

/** Footprint of one ray-traced sample on the surface, from its ray differentials
 *  dP/dx and dP/dy at the hit (bg_ray_differentials in framework.h):
 *  max(|dpdx|, |dpdy|), in the units of P. Multiply by the height field's
 *  frequency for the noise-space footprint the calls here take. NaN if either
 *  vector has a NaN component (NaN footprints filter nothing); +inf if a length
 *  overflows float (every octave is then dropped). */
BG_API float bg_footprint_from_differentials(bg_vec3 dpdx, bg_vec3 dpdy);

/** Fractal value and analytic gradient with per-sample footprints (noise space):
 *  octave i is weighted by c_i as above and skipped where c_i = 0 for every
 *  sample. `value` may be NULL; `footprint` is required. Uses the dispatched
 *  noise kernel per octave. Statuses as bg_fractal3_batch. */
BG_API bg_status bg_fractal3_grad_footprint_batch(const bg_fractal *f, const float *footprint,
                                                  const float *x, const float *y, const float *z,
                                                  size_t n, float *value, float *gx, float *gy,
                                                  float *gz);

/** Double batches (scalar loops over the double entry points). `value` may be
 *  NULL. Statuses as bg_fractal3_batch. */
BG_API bg_status bg_fractal3d_grad_batch(const bg_fractal *f, const double *x, const double *y,
                                         const double *z, size_t n, double *value, double *gx,
                                         double *gy, double *gz);

/* ---- regular grids (voxel and image bakes) --------------------------------- */

/** A regular lattice of sample points. Sample (i, j, k), 0 <= i < count[0],
 *  0 <= j < count[1], 0 <= k < count[2], lies at
 *  x = (float)(origin[0] + (double)i * step[0]), likewise y with j and z with k
 *  (computed in double and rounded once to float), and is stored at index
 *  i + count[0] * (j + count[1] * k): x fastest, then y, then z. A 2D image is
 *  a grid with count[2] = 1. */
typedef struct bg_grid3 {
    double origin[3]; /**< coordinate of sample (0, 0, 0), noise space */
    double step[3];   /**< spacing along each axis, noise space (any finite value) */
    size_t count[3];  /**< samples along each axis */
} bg_grid3;

/* Grid calls give, for every sample, the bits of the batch call with the same
 * float coordinates (the formula above): one entry point per batch, for callers
 * that would otherwise fill three coordinate arrays. Outputs have
 * count[0] * count[1] * count[2] elements. Checked once per call, before any
 * output is written, in this order:
 *  - BG_ERR_NULL_POINTER if `g` is NULL;
 *  - BG_ERR_OVERFLOW if count[0] * count[1] * count[2] * sizeof(float) does not
 *    fit in a size_t (no buffer could hold the output);
 *  - a grid with no sample (a count of 0): nothing else is read, BG_OK;
 *  - BG_ERR_NULL_POINTER for a NULL descriptor or required output; then the
 *    status of bg_fractal_validate(f);
 *  - BG_ERR_INVALID_ARGUMENT if an origin or a step is not finite.
 * Coordinates that overflow float give NaN results (the NaN rule above), as in
 * a batch. Single-threaded and reentrant; no memory is allocated (the
 * coordinates go through a fixed stack buffer of a few KB). */

/** Noise values on a grid. @return as described above. */
BG_API bg_status bg_noise3_grid(const bg_grid3 *g, float *value);

/** Fractal values on a grid (bg_fractal3_batch on the grid's points). */
BG_API bg_status bg_fractal3_grid(const bg_fractal *f, const bg_grid3 *g, float *value);

/** Fractal values and analytic gradients on a grid (bg_fractal3_grad_batch on
 *  the grid's points): gradients as three arrays like the batch; `value` may be
 *  NULL. Plain noise with its gradient: a descriptor with BG_FUNC_NOISE. */
BG_API bg_status bg_fractal3_grad_grid(const bg_fractal *f, const bg_grid3 *g, float *value,
                                       float *gx, float *gy, float *gz);


/* ---- tileable noise and seeded octaves (bg_domain) --------------------------
 * A domain changes where each octave samples Perlin's lattice; every octave is
 * still Perlin's improved noise (the same fade, corners and lerps), so the
 * gradient stays analytic and exact and every ISA gives the same bits.
 *
 * Periods (tileable noise, like OSL's pnoise or glm's perlin(p, rep)): with
 * period[a] = P > 0 the lattice wraps before hashing: the corner at integer
 * coordinate i along axis a is hashed as (i mod P), so the noise repeats with
 * period P along that axis and the corners on both sides of the seam are the
 * same corners (value and gradient continuous across the wrap). Octave i of a
 * fractal has period P * lacunarity^i in its own coordinates, i.e. the same
 * period P in the caller's; the lacunarity must then be an integer. A period of
 * 256 gives Perlin's noise itself (his lattice repeats every 256); period 0
 * leaves that axis untiled (the plain noise's 256 in each octave's own
 * coordinates). Exactness of the repeat: f(p + P e_a) == f(p) bit for bit
 * wherever p + P e_a is exact in float (e.g. coordinates on a 2^-10 grid below
 * 2^13); elsewhere the float rounding of p + P e_a itself moves the point. The
 * cell index floor(q) mod P is exact for |q| < 2^22 (float) and 2^51 (double);
 * beyond, where float has no fraction left, it is a fixed function of q (the
 * same on every ISA) that need not be periodic, and 0 for NaN/Inf.
 *
 * Seed: 0 leaves Perlin's lattice (the same bits as the plain calls). Another
 * seed offsets octave i by o_i(seed), a vector of multiples of 1/256 in
 * [0, 32) per axis: octave i samples noise at lacunarity^i p + o_i. Different
 * seeds give different patterns; the octaves no longer share lattice planes
 * (lacunarity 2 otherwise puts every coarse lattice plane on a finer one).
 * Offsets are multiples of 1/256, so tiling is kept bit for bit.
 *
 * Cost (docs/PERFORMANCE.md, "Tileable and seeded noise"): a domain adds the
 * cell reduction modulo P per axis (an integer mask when P * lacunarity^i is
 * a power of two: prefer power-of-two periods; none at all for an octave whose
 * every period is a power of two >= 256) and, on most ISAs, a second lookup
 * for the wrapped corners. */

/** Largest per-axis period. */
#define BG_MAX_PERIOD 256

/** Where a fractal's octaves sample the lattice. All zero (the default):
 *  Perlin's lattice, the plain calls' bits. */
typedef struct bg_domain {
    int period[3];     /**< per-axis period, 1..BG_MAX_PERIOD, or 0: not tiled */
    unsigned int seed; /**< 0: no offsets; else per-octave offsets o_i(seed) */
} bg_domain;

/** Check a domain for fractal `f` (which must pass bg_fractal_validate).
 *  @return BG_OK; BG_ERR_NULL_POINTER for NULL `f` or `d`; the status of
 *   bg_fractal_validate(f); BG_ERR_INVALID_ARGUMENT if a period is outside
 *   0..BG_MAX_PERIOD, or a period is set and the fractal's lacunarity is not
 *   an integer, or the finest octave's period P * lacunarity^(octaves-1)
 *   exceeds 2^24 (its cells could not be reduced exactly in float). */
BG_API bg_status bg_domain_validate(const bg_fractal *f, const bg_domain *d);

/** The seed offset o_i along axis `axis` (0..2) of octave `octave`: a multiple
 *  of 1/256 in [0, 32); 0 for seed 0. */
BG_API float bg_domain_offset(unsigned int seed, int octave, int axis);

/** Periodic noise at (x,y,z) with periods period[0..2] (each 1..BG_MAX_PERIOD,
 *  or 0 for an untiled axis). A NULL or out-of-range `period` gives NaN. */
BG_API float bg_pnoise3(float x, float y, float z, const int period[3]);
/** Periodic noise and its analytic gradient; `grad` must not be NULL. */
BG_API float bg_pnoise3_grad(float x, float y, float z, const int period[3], bg_vec3 *grad);
/** Periodic noise in double. */
BG_API double bg_pnoise3d(double x, double y, double z, const int period[3]);
BG_API double bg_pnoise3d_grad(double x, double y, double z, const int period[3], bg_dvec3 *grad);

/** Fractal (noise, fBm, turbulence) over a domain, value and analytic gradient,
 *  float and double. An invalid `f` or `d` (bg_domain_validate, any check but
 *  the overflow one) gives NaN value and gradient. */
BG_API float bg_fractal3_domain(const bg_fractal *f, const bg_domain *d, float x, float y, float z);
BG_API float bg_fractal3_domain_grad(const bg_fractal *f, const bg_domain *d, float x, float y,
                                     float z, bg_vec3 *grad);
BG_API double bg_fractal3d_domain(const bg_fractal *f, const bg_domain *d, double x, double y,
                                  double z);
BG_API double bg_fractal3d_domain_grad(const bg_fractal *f, const bg_domain *d, double x, double y,
                                       double z, bg_dvec3 *grad);

/** Batches (the batch contract above; the descriptor check is
 *  bg_domain_validate). Periodic noise: `period` as for bg_pnoise3. */
BG_API bg_status bg_pnoise3_batch(const int period[3], const float *x, const float *y,
                                  const float *z, size_t n, float *value);
BG_API bg_status bg_pnoise3_grad_batch(const int period[3], const float *x, const float *y,
                                       const float *z, size_t n, float *value, float *gx,
                                       float *gy, float *gz);
BG_API bg_status bg_fractal3_domain_batch(const bg_fractal *f, const bg_domain *d, const float *x,
                                          const float *y, const float *z, size_t n, float *value);
/** `value` may be NULL. */
BG_API bg_status bg_fractal3_domain_grad_batch(const bg_fractal *f, const bg_domain *d,
                                               const float *x, const float *y, const float *z,
                                               size_t n, float *value, float *gx, float *gy,
                                               float *gz);
/** Central differences over a domain (as bg_fractal3_grad_central_batch). */
BG_API bg_status bg_fractal3_domain_grad_central_batch(const bg_fractal *f, const bg_domain *d,
                                                       float h, const float *x, const float *y,
                                                       const float *z, size_t n, float *value,
                                                       float *gx, float *gy, float *gz);
/** Double batch; `value` may be NULL. */
BG_API bg_status bg_fractal3d_domain_grad_batch(const bg_fractal *f, const bg_domain *d,
                                                const double *x, const double *y, const double *z,
                                                size_t n, double *value, double *gx, double *gy,
                                                double *gz);

#ifdef __cplusplus
}
#endif

#endif /* BUMPGRAD_NOISE_H */
