/* SPDX-License-Identifier: MIT */
/**
 * @file surfgrad.h
 * @brief The surface gradient (Mikkelsen 2010, eq. 2) and the perturbed normal
 *        (eq. 4, Listing 3), Perlin's additive perturbation for comparison,
 *        and the fused "height gradient -> perturbed normal" batch.
 *
 * Degenerate inputs (the same rule in every entry point, scalar and batch):
 *  - n is normalized first, with a scale by its largest component so that no
 *    finite n overflows or underflows;
 *  - n zero, or with a NaN/Inf component: the result is (0,0,0), the
 *    "no normal" sentinel (test with dot(r,r) == 0);
 *  - g with a NaN/Inf component (and n valid): the result is the unit n,
 *    i.e. no perturbation where the slope is undefined;
 *  - finite but huge g (largest component above 2^40): n and g are scaled by
 *    1/max|g| before the formula, so nothing overflows; the result is finite
 *    and unit, close to tangent to the surface;
 *  - additive only: n - g == 0 exactly gives the unit n.
 * So no NaN leaves these functions for finite inputs, and the result is always
 * either unit length (to float rounding) or exactly (0,0,0).
 *
 * Misuse is not a degenerate input: an unknown bg_perturb_method gives NaN in
 * every component from the single-point calls (bg_perturb, bg_perturbd) and
 * BG_ERR_INVALID_ARGUMENT from the batches. The batches follow the contract of
 * noise.h ("batches"): a bg_status, n = 0 reads nothing, every check before the
 * first write.
 *
 * Thread-safe and reentrant.
 */
#ifndef BUMPGRAD_SURFGRAD_H
#define BUMPGRAD_SURFGRAD_H

#include "common.h"
#include "noise.h"

#ifdef __cplusplus
extern "C" {
#endif

/** How a perturbed normal is formed from the unit normal n and a volume gradient g. */
typedef enum bg_perturb_method {
    BG_PERTURB_SURFGRAD = 0,        /**< normalize(n - (g - n (n.g))): eq. 4, Listing 3 */
    BG_PERTURB_ADDITIVE = 1,        /**< normalize(n - g): Perlin's method with the gradient
                                         negated, as for the paper's Figure 2(a) */
    BG_PERTURB_ADDITIVE_PERLIN = 2  /**< normalize(n + g): Perlin's original sign (Per85) */
} bg_perturb_method;

/** Surface gradient grad_S h = g - n (n.g) (eq. 2): the projection of the volume
 *  gradient onto the tangent plane of the unit normal n (n is normalized first).
 *  Invalid n gives (0,0,0); non-finite g gives (0,0,0). */
BG_API bg_vec3 bg_surface_gradient(bg_vec3 n, bg_vec3 g);
BG_API bg_dvec3 bg_surface_gradientd(bg_dvec3 n, bg_dvec3 g);

/** Perturbed normal normalize(n - grad_S h) (eq. 4, Listing 3). For unit n and
 *  finite g it never points inward: dot(result, n) > 0 (up to float rounding for
 *  |g| beyond about 1e7, where the result is nearly tangent). */
BG_API bg_vec3 bg_perturb_normal(bg_vec3 n, bg_vec3 g);
BG_API bg_dvec3 bg_perturb_normald(bg_dvec3 n, bg_dvec3 g);

/** Perlin's additive perturbation normalize(n - g), the comparison mode of the
 *  paper's Figure 2: without the projection it understates gradients above the
 *  tangent plane and overstates those below it, up to pointing inward. */
BG_API bg_vec3 bg_perturb_normal_additive(bg_vec3 n, bg_vec3 g);
BG_API bg_dvec3 bg_perturb_normal_additived(bg_dvec3 n, bg_dvec3 g);

/** Any method by enum (same results as the functions above). A `method`
 *  outside bg_perturb_method gives (NaN, NaN, NaN). */
BG_API bg_vec3 bg_perturb(bg_perturb_method method, bg_vec3 n, bg_vec3 g);
BG_API bg_dvec3 bg_perturbd(bg_perturb_method method, bg_dvec3 n, bg_dvec3 g);

/** Angle between two vectors in degrees, in [0, 180], computed as
 *  atan2(|a x b|, a.b) in double (accurate near 0 and 180). Either vector zero or
 *  non-finite: NaN. */
BG_API double bg_angle_deg(bg_vec3 a, bg_vec3 b);
BG_API double bg_angle_degd(bg_dvec3 a, bg_dvec3 b);

/** Batch perturbation over SoA normals and gradients; outputs may alias inputs
 *  exactly. Every array is required.
 *  @return BG_OK, BG_ERR_NULL_POINTER, or BG_ERR_INVALID_ARGUMENT for an
 *   unknown `method` (nothing written). */
BG_API bg_status bg_perturb_batch(bg_perturb_method method, const float *nx, const float *ny,
                                  const float *nz, const float *gx, const float *gy,
                                  const float *gz, size_t n, float *ox, float *oy, float *oz);

/** How the fused call differentiates the height field. */
typedef enum bg_gradient_mode {
    BG_GRADIENT_ANALYTIC = 0, /**< analytic gradient from the same pass (dnoise) */
    BG_GRADIENT_CENTRAL = 1   /**< central differences with `step` (noise-space units) */
} bg_gradient_mode;

/** A solid (volume) height field: h(p) = amplitude * F(frequency * p), where F is
 *  the fractal described by `fractal`. Its gradient is amplitude * frequency * F'. */
typedef struct bg_height {
    bg_fractal fractal;
    float amplitude;
    float frequency;
    bg_gradient_mode gradient;
    float step; /**< central-difference step in noise space; 0 means BG_DEFAULT_CENTRAL_STEP */
    bg_domain domain; /**< periods (tileable, in noise space) and seed (noise.h); zero: none */
} bg_height;

/** Defaults: 6-octave turbulence, amplitude 0.1, frequency 1, analytic gradient. */
BG_API bg_height bg_height_default(void);

/** Check a height descriptor.
 *  @return BG_OK;
 *   BG_ERR_NULL_POINTER if `h` is NULL;
 *   BG_ERR_INVALID_ARGUMENT if the fractal is out of range (bg_fractal_validate),
 *   `amplitude` or `frequency` is not finite, `step` is not finite and >= 0, or
 *   `gradient` is not a bg_gradient_mode;
 *   BG_ERR_OVERFLOW if the fractal's octave scaling overflows
 *   (bg_fractal_validate), or the height's scale on top of it does:
 *   |frequency| * lacunarity^(octaves-1) (the finest octave's factor for a
 *   point at |p| = 1), amplitude * frequency, 2.1 |amplitude| sum_i |gain^i| or
 *   9 |amplitude frequency| sum_i |gain^i lacunarity^i| not finite in float
 *   (e.g. `frequency` 3e38). Accepted heights give finite heights and normals
 *   for every position with each |p| up to
 *   bg_fractal_max_coordinate(&h->fractal, h->frequency), which is >= 1. */
BG_API bg_status bg_height_validate(const bg_height *h);

/** Height and its volume gradient at one point (same bits as the batch).
 *  `grad` may be NULL (height only). A NULL `h`, or one that fails
 *  bg_height_validate's range checks (anything but BG_ERR_OVERFLOW, which is
 *  not checked per point), gives NaN height and gradient. */
BG_API float bg_height_eval(const bg_height *h, bg_vec3 p, bg_vec3 *grad);

/** Fused "height gradient -> perturbed normal": evaluates h and its gradient at
 *  each position p and perturbs the normal n there with `method`; no intermediate
 *  arrays. `height` may be NULL. The positions and normals are SoA arrays.
 *  @return BG_OK; BG_ERR_NULL_POINTER (`h` or a required array); the status of
 *   bg_height_validate(h) (BG_ERR_INVALID_ARGUMENT, BG_ERR_OVERFLOW); or
 *   BG_ERR_INVALID_ARGUMENT for an unknown `method`. Nothing is written unless
 *   BG_OK. */
BG_API bg_status bg_perturb_height_batch(const bg_height *h, bg_perturb_method method,
                                         const float *px, const float *py, const float *pz,
                                         const float *nx, const float *ny, const float *nz,
                                         size_t n, float *height, float *ox, float *oy,
                                         float *oz);

/** The fused call with a per-sample footprint (world units, e.g. the pixel's
 *  footprint on the surface from ray differentials): octaves finer than the
 *  footprint can show are faded out and not evaluated (bg_octave_weight, with
 *  footprint * frequency in noise space). Always the analytic gradient. `height`
 *  may be NULL; `footprint` is required. With every footprint 0 the result equals
 *  bg_perturb_height_batch with the analytic gradient, bit for bit. Statuses as
 *  bg_perturb_height_batch (`h->gradient` must still be valid, though unused). */
BG_API bg_status bg_perturb_height_footprint_batch(const bg_height *h, bg_perturb_method method,
                                                   const float *footprint, const float *px,
                                                   const float *py, const float *pz,
                                                   const float *nx, const float *ny,
                                                   const float *nz, size_t n, float *height,
                                                   float *ox, float *oy, float *oz);

#ifdef __cplusplus
}
#endif

#endif /* BUMPGRAD_SURFGRAD_H */
