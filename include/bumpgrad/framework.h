/* SPDX-License-Identifier: MIT */
/**
 * @file framework.h
 * @brief The surface-gradient bump mapping framework (Mikkelsen 2020, "Surface
 *        Gradient-Based Bump Mapping Framework", JCGT 9(3); as retold in the article
 *        "Surface Gradient Bump Mapping Framework Overview") on the CPU: every bump
 *        source turned into a surface gradient, and one normal resolve.
 *
 * The idea: a bump influence is not a normal but a surface gradient grad_S h, a
 * vector in the tangent plane. Influences are blended linearly as gradients and the
 * normal is formed once, n' = normalize(n - sum_i w_i grad_S h_i) (the "resolve").
 * This header converts each common source into a surface gradient:
 *  - a tangent-space normal and a tangent frame (overview, "Surface gradient from a
 *    tangent-space normal vector with a tangent basis");
 *  - an object-space perturbed normal;
 *  - height derivatives along a parametrization or along the screen (Mikkelsen 2010,
 *    eq. 3 and Listing 1), with height-texture differencing (Listing 2), mip-level
 *    and bicubic texture derivatives and the texel-to-screen chain rule of the
 *    reference framework;
 *  - a volume gradient (eq. 2 is bg_surface_gradient in surfgrad.h) and its
 *    triplanar variant;
 * and supplies the frames they need: a tangent frame from UV and position derivatives
 * (the overview's compute_tbn), analytic dP/dx, dP/dy from ray differentials for
 * renderers without ddx/ddy, mikkTSpace renormalization, face-forwarding, and the
 * parallax helpers that map between the surface and texture space.
 * The Orange Book's procedural bump pattern (section 11.4) is included as a
 * tangent-space normal source.
 *
 * Conventions shared by every call:
 *  - All vectors are in one space of the caller's choosing (world or object).
 *  - A normal argument `n` is normalized first (scaled by its largest component,
 *    so no finite n overflows). n zero or non-finite yields the "no normal"
 *    sentinel (0,0,0) where a normal is returned, and the zero surface gradient
 *    where a gradient is returned.
 *  - The zero vector is the "no perturbation" surface gradient: every conversion
 *    returns it for input it cannot interpret (documented per call), so a bad
 *    influence degrades to a flat one instead of spreading NaN.
 *  - The float entry points compute in double and round once; the double entry
 *    points (suffix d) do the same arithmetic without the rounding. The exceptions
 *    are GPU-faithful by contract and say so: bg_listing1_normal (Listing 1 in
 *    float, as a shader computes it) and the Orange Book shading.
 *  - Where Mikkelsen's reference framework (surfgrad_framework.h of
 *    mmikk/surfgrad-bump-standalone-demo) differs from a call here, the call's
 *    comment says how; docs/FRAMEWORK.md has the function-by-function parity table.
 *  - Everything is reentrant and thread-safe: no global state.
 */
#ifndef BUMPGRAD_FRAMEWORK_H
#define BUMPGRAD_FRAMEWORK_H

#include "common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A 2-vector of floats: texture coordinates, pixel coordinates, a pair of derivatives. */
typedef struct bg_vec2 {
    float x, y;
} bg_vec2;

/** A 2-vector of doubles. */
typedef struct bg_dvec2 {
    double x, y;
} bg_dvec2;

/** A tangent frame: tangent t, bitangent b, normal n (lengths as each call documents). */
typedef struct bg_tangent_frame {
    bg_vec3 t, b, n;
} bg_tangent_frame;

/** A tangent frame in double. */
typedef struct bg_dtangent_frame {
    bg_dvec3 t, b, n;
} bg_dtangent_frame;

/** Largest slope |m.x/m.z|, |m.y/m.z| (and |m_tangent|/|m.n| for object-space
 *  normals) a normal can express as a surface gradient. The framework's bound: a
 *  normal at or below the horizon maps to a slope of 128 (89.55 degrees) instead of
 *  an infinite or sign-flipped gradient. */
#define BG_MAX_NORMAL_SLOPE 128.0

/* ---- resolve -------------------------------------------------------------- */

/**
 * The normal resolve: n' = normalize(n - sum_i w_i grad_S h_i) (overview, "normal
 * resolve"; each term is eq. 4 of Mikkelsen 2010). Linear in the influences, so a
 * flat influence (zero gradient) contributes nothing whatever its weight.
 *
 * @param n         base normal (any length; normalized first)
 * @param surfgrads `count` surface gradients, in units of height per unit length
 *                  (dimensionless slopes); may be NULL only when count is 0
 * @param weights   `count` weights, or NULL for all 1 (the framework does not
 *                  require them to sum to 1)
 * @return unit normal. n invalid: (0,0,0). An influence whose weight or gradient
 *         has a NaN/Inf contributes nothing (so no NaN leaves for finite n). Huge
 *         finite terms are scaled before summing: the result stays unit and tends
 *         to the tangent direction. If n - sum is exactly zero (only possible with
 *         gradients that are not tangent), the unit n is returned.
 * Tangent gradients always give dot(n', n) > 0. Thread-safe.
 */
BG_API bg_vec3 bg_resolve_normal(bg_vec3 n, const bg_vec3 *surfgrads, const float *weights,
                                 size_t count);
/** Double-precision bg_resolve_normal. */
BG_API bg_dvec3 bg_resolve_normald(bg_dvec3 n, const bg_dvec3 *surfgrads, const double *weights,
                                   size_t count);

/**
 * Batch accumulation of one influence: a += weight * g over SoA arrays of `count`
 * elements. Call it once per influence into zero-initialized accumulators, then
 * bg_resolve_normal_batch. Plain float arithmetic (weight*g rounded, then added).
 * NaN/Inf in g or weight propagates into a and is dropped by the resolve. `a` may
 * be exactly the same arrays as `g`. Thread-safe on disjoint outputs.
 */
BG_API void bg_surfgrad_accumulate_batch(float weight, const float *gx, const float *gy,
                                         const float *gz, size_t count, float *ax, float *ay,
                                         float *az);

/**
 * Batch resolve over SoA arrays: o = normalize(n - s) per element, with the rules of
 * bg_resolve_normal for one influence of weight 1 (s is the already weighted sum,
 * e.g. from bg_surfgrad_accumulate_batch). Outputs may alias inputs exactly.
 */
BG_API void bg_resolve_normal_batch(const float *nx, const float *ny, const float *nz,
                                    const float *sx, const float *sy, const float *sz,
                                    size_t count, float *ox, float *oy, float *oz);

/**
 * "The wrong way" (overview, "Combining multiple bump influences"):
 * normalize(sum_i w_i normalize(n_i)), for comparison with the resolve. A flat
 * influence pulls the blend toward the base normal in proportion to its weight.
 * @param normals `count` normals (each normalized first); weights NULL for all 1.
 * @return unit vector; an invalid normal or weight is skipped; a sum that is zero
 *         (e.g. opposite normals) gives (0,0,0). Thread-safe.
 */
BG_API bg_vec3 bg_blend_normals_naive(const bg_vec3 *normals, const float *weights, size_t count);
/** Double-precision bg_blend_normals_naive. */
BG_API bg_dvec3 bg_blend_normals_naived(const bg_dvec3 *normals, const double *weights,
                                        size_t count);

/* ---- surface gradients from normals ---------------------------------------- */

/**
 * The one tangent-normal clamp: a tangent-space normal m (z along n) as the height
 * derivatives (dh/du, dh/dv) = (-m.x / z, -m.y / z) with
 * z = max(|m.z|, max(|m.x|, |m.y|) / 128), the rule of the reference's
 * TspaceNormalToDerivative. |m.z| mirrors an m below the horizon to the visible
 * side (m = (0.5, 0, -0.5) gives (-1, 0), not a saturated -128); the common floor
 * bounds both derivatives by BG_MAX_NORMAL_SLOPE while keeping their ratio, i.e.
 * the direction of the slope. m need not be unit (it is scaled by its largest
 * component first, so any finite m works). The derivatives are along the frame's
 * t and b: the reference negates the second one (its gFlipVertDeriv, for a
 * v axis that runs down the image); negate .y for that convention.
 * bg_surfgrad_from_tangent_normal is bg_surfgrad_from_tbn of this.
 * @return the derivatives, |each| <= 128; m zero or non-finite: (0, 0).
 *         Float: computed in double, rounded once.
 */
BG_API bg_vec2 bg_tangent_normal_to_derivs(bg_vec3 m);
/** Double-precision bg_tangent_normal_to_derivs. */
BG_API bg_dvec2 bg_tangent_normal_to_derivsd(bg_dvec3 m);

/**
 * Surface gradient of height derivatives along a tangent frame (the reference's
 * SurfgradFromTBN): deriv.x t + deriv.y b, for derivative maps and for
 * bg_tangent_normal_to_derivs. With an unnormalized mikkTSpace frame from
 * bg_mikktspace_renormalize this is the compliant decode.
 * @return the gradient; any input non-finite (or an overflowing result): (0,0,0).
 */
BG_API bg_vec3 bg_surfgrad_from_tbn(bg_vec2 deriv, bg_vec3 t, bg_vec3 b);
/** Double-precision bg_surfgrad_from_tbn. */
BG_API bg_dvec3 bg_surfgrad_from_tbnd(bg_dvec2 deriv, bg_dvec3 t, bg_dvec3 b);

/**
 * Surface gradient of a tangent-space normal m in the frame (t, b):
 * grad_S h = -(m.x/m.z) t - (m.y/m.z) b (overview, "Surface gradient from a
 * tangent-space normal vector with a tangent basis"). Then
 * normalize(n - grad_S h) == normalize(m.x t + m.y b + m.z n) for any frame with
 * unit n and m.z > 0.
 *
 * Clamping: exactly bg_tangent_normal_to_derivs (one implementation), i.e. m.z is
 * replaced by max(|m.z|, max(|m.x|, |m.y|) / 128), so m.z is kept positive (an m
 * below the horizon is mirrored to the visible side) and both slopes are bounded by
 * BG_MAX_NORMAL_SLOPE, while their ratio, i.e. the direction of the slope, is
 * preserved. m need not be unit.
 * @param t tangent (dP/du direction, any length: the length scales the slope)
 * @param b bitangent
 * @param m tangent-space normal, z along n
 * @return gradient in the plane of t, b. m zero or any input non-finite: (0,0,0).
 */
BG_API bg_vec3 bg_surfgrad_from_tangent_normal(bg_vec3 t, bg_vec3 b, bg_vec3 m);
/** Double-precision bg_surfgrad_from_tangent_normal. */
BG_API bg_dvec3 bg_surfgrad_from_tangent_normald(bg_dvec3 t, bg_dvec3 b, bg_dvec3 m);

/**
 * Surface gradient of an object-space (or world-space) perturbed normal m relative
 * to the base normal n: with k = m.n and m_t = m - k n (n unit),
 * grad_S h = -m_t / max(|k|, |m_t| / 128), so that normalize(n - grad_S h) ==
 * normalize(m) whenever m.n > 0 and the slope |m_t|/k is at most 128.
 *
 * Inward-facing m (m.n <= 0) is handled as the tangent-space path handles m.z < 0:
 * the normal component is taken by absolute value, i.e. m is mirrored through the
 * tangent plane to the visible side, and the slope is clamped at BG_MAX_NORMAL_SLOPE
 * (so a tangent m gives a slope of 128 along m_t rather than an infinite gradient).
 * The resolve of the result therefore never faces away from n.
 * @return tangent to n. n invalid, m zero or non-finite: (0,0,0).
 */
BG_API bg_vec3 bg_surfgrad_from_perturbed_normal(bg_vec3 n, bg_vec3 m);
/** Double-precision bg_surfgrad_from_perturbed_normal. */
BG_API bg_dvec3 bg_surfgrad_from_perturbed_normald(bg_dvec3 n, bg_dvec3 m);

/** Clamp of an object-space normal near and below the tangent plane. */
typedef enum bg_normal_clamp {
    /** The default of bg_surfgrad_from_perturbed_normal: slope bounded by 128, as
     *  the tangent-space path (m within 0.45 degrees of the tangent plane lands on
     *  89.55 degrees; the resolve's slope never exceeds 128). */
    BG_CLAMP_SLOPE = 0,
    /** Mikkelsen's SurfgradFromPerturbedNormal: -m_t / max(FLT_EPSILON, |k|) for the
     *  unit m, so slopes up to 1/FLT_EPSILON = 8.4e6: the resolve reproduces m (to
     *  rounding) unless m is within 6.8e-6 degrees of the tangent plane. */
    BG_CLAMP_REFERENCE = 1
} bg_normal_clamp;

/**
 * bg_surfgrad_from_perturbed_normal with a choice of clamp. In both modes m is
 * normalized first, an inward m (m.n < 0) is mirrored to the visible side through
 * |k|, and n invalid or m zero/non-finite gives (0,0,0). The reference divides the
 * unnormalized v, so its FLT_EPSILON floor scales with |v|; here it applies to the
 * unit m, which is the reference for unit v. An unknown `clamp` is BG_CLAMP_SLOPE.
 */
BG_API bg_vec3 bg_surfgrad_from_perturbed_normal_clamp(bg_vec3 n, bg_vec3 m, bg_normal_clamp clamp);
/** Double-precision bg_surfgrad_from_perturbed_normal_clamp. */
BG_API bg_dvec3 bg_surfgrad_from_perturbed_normal_clampd(bg_dvec3 n, bg_dvec3 m,
                                                         bg_normal_clamp clamp);

/* ---- surface gradients from height derivatives ------------------------------ */

/**
 * Surface gradient from parametric height derivatives, Mikkelsen 2010 eq. 3:
 * grad_S h = ((sigma_t x n) beta_s + (n x sigma_s) beta_t) / (n . (sigma_s x sigma_t)).
 * The denominator carries the sign of the determinant, so orientation-reversing
 * parametrizations (mirrored UVs) give the right gradient (the role of Listing 1's
 * sign(fDet)). Exact for any sigma_s, sigma_t spanning the tangent plane of n.
 * @param n       surface normal (visible side; normalized first). The result does not
 *                depend on the sign of n.
 * @param sigma_s dP/ds, position derivative along the first parameter
 * @param sigma_t dP/dt
 * @param beta_s  dh/ds, height derivative along s (height units per parameter unit)
 * @param beta_t  dh/dt
 * @return gradient in height units per length unit. Determinant zero (sigma_s,
 *         sigma_t parallel or in the normal's direction), n invalid or any input
 *         non-finite: (0,0,0). The determinant is formed after scaling sigma_s and
 *         sigma_t by their largest component, so tiny but valid derivatives (1e-30)
 *         still work.
 */
BG_API bg_vec3 bg_surfgrad_from_param_derivs(bg_vec3 n, bg_vec3 sigma_s, bg_vec3 sigma_t,
                                             float beta_s, float beta_t);
/** Double-precision bg_surfgrad_from_param_derivs. */
BG_API bg_dvec3 bg_surfgrad_from_param_derivsd(bg_dvec3 n, bg_dvec3 sigma_s, bg_dvec3 sigma_t,
                                               double beta_s, double beta_t);

/**
 * Eq. 3 with the screen as the local chart (Mikkelsen 2010 section 3-4): sigma_s =
 * dP/dx, sigma_t = dP/dy (per pixel, from ddx/ddy, bg_ray_differentials or
 * bg_ray_differentials_inv_viewproj) and beta = dh/dx, dh/dy (per pixel, e.g. from
 * bg_height_texture_derivs). Same result and rules as bg_surfgrad_from_param_derivs.
 */
BG_API bg_vec3 bg_surfgrad_from_screen_derivs(bg_vec3 n, bg_vec3 dpdx, bg_vec3 dpdy, float dhdx,
                                              float dhdy);
/** Double-precision bg_surfgrad_from_screen_derivs. */
BG_API bg_dvec3 bg_surfgrad_from_screen_derivsd(bg_dvec3 n, bg_dvec3 dpdx, bg_dvec3 dpdy,
                                                double dhdx, double dhdy);

/**
 * Listing 1 of Mikkelsen 2010 without division, the robust (double) form: with
 * R1 = dpdy x n, R2 = n x dpdx, det = dpdx . R1, returns
 * normalize(|det| n - sign(det) (dhdx R1 + dhdy R2)), which equals
 * bg_resolve_normal(n, {bg_surfgrad_from_screen_derivs(...)}, NULL, 1) but stays
 * defined as det -> 0 (it tends to the tangent direction). n is normalized and the
 * chart rescaled first (as eq. 3 here), so tiny (1e-30) or huge charts work.
 * The double call is the implementation; the float call is it rounded once. For
 * the arithmetic a GPU does (float, in the listing's order, n as given), use
 * bg_listing1_normal.
 * @return unit normal; det == 0 returns the unit n (no slope can be measured); n
 *         invalid or non-finite input: (0,0,0) for n, unit n for the rest.
 */
BG_API bg_vec3 bg_perturb_normal_screen(bg_vec3 n, bg_vec3 dpdx, bg_vec3 dpdy, float dhdx,
                                        float dhdy);
/** Double-precision bg_perturb_normal_screen (robust Listing 1). */
BG_API bg_dvec3 bg_perturb_normal_screend(bg_dvec3 n, bg_dvec3 dpdx, bg_dvec3 dpdy, double dhdx,
                                          double dhdy);

/**
 * Listing 1 of Mikkelsen 2010 exactly as a shader computes it, in float: with the
 * screen-space position derivatives sigma_s (vSigmaS = dP/dx), sigma_t (dP/dy) and
 * height derivatives dbs (dBs), dbt (dBt),
 *   R1 = sigma_t x n, R2 = n x sigma_s, det = sigma_s . R1,
 *   out = normalize(|det| n - sign(det) (dbs R1 + dbt R2)),
 * every operation a float operation in this order (cross products as
 * (a.y b.z - a.z b.y, a.z b.x - a.x b.z, a.x b.y - a.y b.x), dot as
 * (x + y) + z, normalize as division by sqrtf of the dot). n is used as given, not
 * normalized. This is the function the renderer (`render --method listing1`) and
 * the accuracy and stability studies use, so they measure and draw one function.
 *
 * The det = 0 rule: when det is 0 or NaN the listing's sign(fDet) = 0 would make
 * the result normalize(0 * n - 0) = normalize(0), undefined; this function returns
 * n unchanged instead (no slope can be measured: keep the normal). Likewise a
 * result of length zero, NaN or Inf returns n. (The studies used sign(0) = 0
 * before and now follow this rule.)
 * Not rescaled: charts whose det underflows float (|sigma| below ~1e-13) return n;
 * bg_perturb_normal_screend is the robust form.
 */
BG_API bg_vec3 bg_listing1_normal(bg_vec3 n, bg_vec3 sigma_s, bg_vec3 sigma_t, float dbs,
                                  float dbt);

/**
 * The scale-dependent surface gradient (the reference's SurfgradScaleDependent):
 * a height derivative `deriv` measured per texel (e.g. from bg_height_mips_derivs,
 * height units per texel along s and t) of a texture of `dim` = (width, height)
 * texels, carried to the screen by the chain rule
 *   dh/dx = dim.x deriv.x ds/dx + dim.y deriv.y dt/dx   (dst_dx = (ds/dx, dt/dx)),
 *   dh/dy = dim.x deriv.x ds/dy + dim.y deriv.y dt/dy,
 * then eq. 3 on the screen chart (bg_surfgrad_from_screen_derivs, whose rules it
 * has). For derivatives already per pixel, call bg_surfgrad_from_screen_derivs
 * (the reference's isDerivScreenSpace). The reference floors |det| at 1.19e-15,
 * which shrinks the gradient of a chart with |dP| below ~3e-8 per pixel; here the
 * chart is rescaled first, so tiny charts give the exact gradient.
 */
BG_API bg_vec3 bg_surfgrad_scale_dependent(bg_vec3 n, bg_vec3 dpdx, bg_vec3 dpdy, bg_vec2 deriv,
                                           bg_vec2 dim, bg_vec2 dst_dx, bg_vec2 dst_dy);
/** Double-precision bg_surfgrad_scale_dependent. */
BG_API bg_dvec3 bg_surfgrad_scale_dependentd(bg_dvec3 n, bg_dvec3 dpdx, bg_dvec3 dpdy,
                                             bg_dvec2 deriv, bg_dvec2 dim, bg_dvec2 dst_dx,
                                             bg_dvec2 dst_dy);

/* ---- parallax ---------------------------------------------------------------- */

/**
 * Parallax: a direction on the surface as a texture-space offset (the reference's
 * ProjectVecToTextureSpace). The tangential part of dir is written in screen steps,
 * dir_t = x dpdx + y dpdy with (x, y) = ((dpdy x n).dir, (n x dpdx).dir) / det
 * (det = n.(dpdx x dpdy), the dual basis of eq. 3), then carried to texture space,
 * o = x dst_dx + y dst_dy, and scaled:
 *   result = bump_scale o / max(|n.dir|, FLT_EPSILON |dir|)   (skip_proj == 0),
 *   result = bump_scale o                                    (skip_proj != 0).
 * With a unit view direction dir (surface to eye) and heights displacing
 * p' = p + bump_scale H n, -result is the texture offset per unit of height along
 * the view ray, what a parallax-occlusion march steps along. The reference takes a
 * unit dir, and the FLT_EPSILON floor is the same for it.
 * @return the offset; det == 0, n invalid or non-finite input: (0, 0).
 *         The chart is rescaled first (no 1.19e-15 floor on |det|).
 */
BG_API bg_vec2 bg_project_vec_to_texture(bg_vec3 n, bg_vec3 dpdx, bg_vec3 dpdy, bg_vec2 dst_dx,
                                         bg_vec2 dst_dy, bg_vec3 dir, float bump_scale,
                                         int skip_proj);
/** Double-precision bg_project_vec_to_texture. */
BG_API bg_dvec2 bg_project_vec_to_textured(bg_dvec3 n, bg_dvec3 dpdx, bg_dvec3 dpdy,
                                           bg_dvec2 dst_dx, bg_dvec2 dst_dy, bg_dvec3 dir,
                                           double bump_scale, int skip_proj);

/**
 * Parallax: a texture-space offset back on the surface (the reference's
 * TexSpaceOffsToSurface): the screen step (x, y) = [dst_dx | dst_dy]^-1 offset,
 * then x sigma_x + y sigma_y with sigma = dpdx, dpdy projected onto the tangent
 * plane of n. The inverse of bg_project_vec_to_texture (skip_proj, bump_scale 1)
 * for tangent directions. The 2x2 matrix is scaled by its largest entry before its
 * determinant is formed (the reference floors |det| at 1.19e-15 instead).
 * @return a tangent vector; singular [dst_dx | dst_dy], n invalid or non-finite
 *         input: (0,0,0).
 */
BG_API bg_vec3 bg_texture_offset_to_surface(bg_vec3 n, bg_vec3 dpdx, bg_vec3 dpdy, bg_vec2 dst_dx,
                                            bg_vec2 dst_dy, bg_vec2 offset);
/** Double-precision bg_texture_offset_to_surface. */
BG_API bg_dvec3 bg_texture_offset_to_surfaced(bg_dvec3 n, bg_dvec3 dpdx, bg_dvec3 dpdy,
                                              bg_dvec2 dst_dx, bg_dvec2 dst_dy, bg_dvec2 offset);

/* ---- triplanar --------------------------------------------------------------- */

/** Triplanar weighting of the three planes by the unit normal's components. */
typedef enum bg_triplanar_weighting {
    /** a_i = max(0, |n_i| - 0.2): Mikkelsen's reference (DetermineTriplanarWeights,
     *  after NVIDIA's Cascades demo), the default. A plane seen within 11.5 degrees
     *  of edge-on (|n_i| <= 0.2) gets weight exactly 0 and is not read (one plane
     *  fewer on 52% of the sphere), and the blend seams are narrower than with
     *  BG_TRIPLANAR_POWER at the same k. */
    BG_TRIPLANAR_OFFSET = 0,
    /** a_i = |n_i|: the plain power blend, bit for bit what bg_triplanar_weights
     *  computed before the reference weighting became the default. */
    BG_TRIPLANAR_POWER = 1
} bg_triplanar_weighting;

/**
 * Triplanar blend weights w_i = a_i^k / (a_x^k + a_y^k + a_z^k) with a_i as
 * `mode` says, computed as (a_i / max a)^k so large k never underflows all three.
 * Sum is 1. With BG_TRIPLANAR_OFFSET a plane in the dead zone (|n_i| <= 0.2) has
 * weight 0 for every k, also k = 0, where the other planes share equally (the
 * reference's pow(0, 0) is undefined in HLSL); BG_TRIPLANAR_POWER at k = 0 gives
 * equal thirds whatever n is (pow(0, 0) == 1), as bg_triplanar_weights did.
 * @param k sharpness >= 0 (the reference's default is 3).
 * @return weights; n invalid, k negative or non-finite, or an unknown mode: (0,0,0).
 */
BG_API bg_vec3 bg_triplanar_weights_ex(bg_vec3 n, float k, bg_triplanar_weighting mode);
/** Double-precision bg_triplanar_weights_ex. */
BG_API bg_dvec3 bg_triplanar_weights_exd(bg_dvec3 n, double k, bg_triplanar_weighting mode);

/** bg_triplanar_weights_ex with the default BG_TRIPLANAR_OFFSET (the reference's
 *  max(0, |n_i| - 0.2)^k). */
BG_API bg_vec3 bg_triplanar_weights(bg_vec3 n, float k);
/** Double-precision bg_triplanar_weights. */
BG_API bg_dvec3 bg_triplanar_weightsd(bg_dvec3 n, double k);

/**
 * Triplanar surface gradient. Three planar height maps are sampled by the caller at
 * the point's (y,z), (x,z) and (x,y) coordinates and give their derivatives along
 * the world axes of that plane:
 *   d_yz = (dh/dy, dh/dz), d_xz = (dh/dx, dh/dz), d_xy = (dh/dx, dh/dy).
 * Order of the x plane: the reference (SurfgradFromTriplanarProjection) samples the
 * x plane at (z, y) and takes deriv_xplane = (dh/dz, dh/dy); here it is (dh/dy,
 * dh/dz), in the order of the plane's name. Swap the two to port reference code.
 * With w = bg_triplanar_weights(n, k) the blended volume gradient is
 *   g = w.x (0, d_yz.x, d_yz.y) + w.y (d_xz.x, 0, d_xz.y) + w.z (d_xy.x, d_xy.y, 0)
 * and the result is its projection, eq. 2: g - n (n.g). As in the framework, the
 * derivatives of the weights are neglected (exact where one weight is 1).
 * A plane whose weight is exactly 0 is not read, so its samples may be anything.
 * Samples must be derivatives along +axis: a caller that mirrors a plane's texture
 * coordinates on the negative side must negate that derivative (chain rule).
 * @return tangent to n. n invalid, k invalid, or a non-finite sample with a nonzero
 *         weight: (0,0,0).
 */
BG_API bg_vec3 bg_surfgrad_triplanar(bg_vec3 n, float k, bg_vec2 d_yz, bg_vec2 d_xz, bg_vec2 d_xy);
/** Double-precision bg_surfgrad_triplanar. */
BG_API bg_dvec3 bg_surfgrad_triplanard(bg_dvec3 n, double k, bg_dvec2 d_yz, bg_dvec2 d_xz,
                                       bg_dvec2 d_xy);

/**
 * bg_surfgrad_triplanar with the caller's weights (e.g. bg_triplanar_weights_ex
 * with BG_TRIPLANAR_POWER, or any blend): eq. 2 of
 * w.x (0, d_yz) + w.y (d_xz.x, 0, d_xz.y) + w.z (d_xy, 0). The weights are used as
 * given (not normalized). A plane whose weight is exactly 0 is not read.
 * @return tangent to n. n invalid, a non-finite weight, or a non-finite sample with
 *         a nonzero weight: (0,0,0).
 */
BG_API bg_vec3 bg_surfgrad_triplanar_weighted(bg_vec3 n, bg_vec3 weights, bg_vec2 d_yz,
                                              bg_vec2 d_xz, bg_vec2 d_xy);
/** Double-precision bg_surfgrad_triplanar_weighted. */
BG_API bg_dvec3 bg_surfgrad_triplanar_weightedd(bg_dvec3 n, bg_dvec3 weights, bg_dvec2 d_yz,
                                                bg_dvec2 d_xz, bg_dvec2 d_xy);

/* ---- frames ----------------------------------------------------------------- */

/**
 * Tangent frame without stored tangents (overview, compute_tbn): from the screen
 * derivatives of position (dpdx, dpdy) and of the texture coordinates (duvdx,
 * duvdy = (du, dv) per pixel step), with the Jacobian J = d(u,v)/d(x,y):
 *   t = normalize(sign(det J) (dv/dy proj(dpdx) - dv/dx proj(dpdy))),
 *   b = sign(det J) sign(n . (dpdx x dpdy)) (n x t),
 * where proj removes the component along n. t points along dP/du projected on the
 * tangent plane; b is unit, perpendicular to t and n, on the side of dP/dv, so the
 * frame has the handedness of (dP/du, dP/dv) and mirrored UVs come out right.
 * Frame n is the unit n.
 * @return t and b unit (to rounding). det J == 0 (degenerate UVs), dpdx and dpdy
 *         parallel (n.(dpdx x dpdy) == 0) or a zero projection: t = b = (0,0,0),
 *         which the tangent-normal conversion turns into "no perturbation".
 *         n invalid or non-finite input: all three zero.
 */
BG_API bg_tangent_frame bg_tangent_frame_from_derivs(bg_vec3 n, bg_vec3 dpdx, bg_vec3 dpdy,
                                                     bg_vec2 duvdx, bg_vec2 duvdy);
/** Double-precision bg_tangent_frame_from_derivs. */
BG_API bg_dtangent_frame bg_tangent_frame_from_derivsd(bg_dvec3 n, bg_dvec3 dpdx, bg_dvec3 dpdy,
                                                       bg_dvec2 duvdx, bg_dvec2 duvdy);

/**
 * mikkTSpace-compliant renormalization (overview, "A note on mikkTSpace usage") of
 * the interpolated, unnormalized vertex tangent t, bitangent sign and normal n:
 * b = sign * (n x t), then t, b and n are all scaled by 1/|n|. The frame keeps the
 * ratios of the unnormalized mikkTSpace decode, so
 * normalize(m.x t + m.y b + m.z n) is unchanged while n becomes unit, as the
 * surface-gradient calls require. Feed t and b to bg_surfgrad_from_tangent_normal
 * and n to the resolve.
 * @param sign bitangent sign (the w of a mikkTSpace tangent): w > 0 means +1,
 *             anything else -1, so w = 0 (and -0) is -1, as in the reference pixel
 *             shader (`sign_w = tangent.w > 0 ? 1 : -1`). mikkTSpace itself only
 *             writes +-1; a 0 comes from lost or zero-filled data, and the reference
 *             rule is the one renderers built on its shader apply.
 *             NaN is rejected (zero frame) where the reference would take -1.
 * @return the frame; n zero or any input non-finite: all zero.
 */
BG_API bg_tangent_frame bg_mikktspace_renormalize(bg_vec3 t, float sign, bg_vec3 n);
/** Double-precision bg_mikktspace_renormalize. */
BG_API bg_dtangent_frame bg_mikktspace_renormalized(bg_dvec3 t, double sign, bg_dvec3 n);

/**
 * Back-facing fix for double-sided shading: returns -n if dot(n, to_viewer) < 0,
 * else n (unchanged, not normalized). to_viewer points from the surface point to the
 * eye (camera - p). Rule: flip the BASE normal before computing any surface gradient
 * or frame; Mikkelsen 2010 section 2 takes n as the visible side, so heights then
 * displace toward the viewer and a bump reads as a bump from both sides. A caller
 * who wants a thin displaced sheet (a bump is a dent from behind) resolves with the
 * front normal and flips the resolved normal instead. dot == 0 or NaN: n unchanged.
 */
BG_API bg_vec3 bg_face_forward(bg_vec3 n, bg_vec3 to_viewer);
/** Double-precision bg_face_forward. */
BG_API bg_dvec3 bg_face_forwardd(bg_dvec3 n, bg_dvec3 to_viewer);

/**
 * bg_face_forward deciding with a reference normal, usually the geometric (face)
 * normal: returns -n if dot(n_ref, to_viewer) < 0, else n. Use it when an
 * interpolated normal can face away on a front face near silhouettes.
 */
BG_API bg_vec3 bg_face_forward_ref(bg_vec3 n, bg_vec3 n_ref, bg_vec3 to_viewer);
/** Double-precision bg_face_forward_ref. */
BG_API bg_dvec3 bg_face_forward_refd(bg_dvec3 n, bg_dvec3 n_ref, bg_dvec3 to_viewer);

/**
 * The reference's back-facing fix (FixNormal): with v = normalize(to_viewer),
 * returns n if dot(n, v) >= 0, else the reflection n - 2 dot(n, v) v of n in the
 * plane perpendicular to v. Unlike bg_face_forward's negation, only the component
 * along the view changes sign: n keeps its length and its projection on the screen,
 * so an interpolated normal that tips away near a silhouette is bent to the nearest
 * visible direction rather than turned around. The reference applies it to the
 * base normal before ray differentials (ScreenDerivOfPosNoDDXY).
 * to_viewer points from the surface to the eye, any length (the reference takes it
 * unit). dot == 0 or NaN, or to_viewer zero: n unchanged (the reference reflects a
 * NaN dot and returns NaN).
 */
BG_API bg_vec3 bg_face_forward_reflect(bg_vec3 n, bg_vec3 to_viewer);
/** Double-precision bg_face_forward_reflect. */
BG_API bg_dvec3 bg_face_forward_reflectd(bg_dvec3 n, bg_dvec3 to_viewer);

/* ---- screen derivatives without ddx/ddy ------------------------------------- */

/**
 * Analytic dP/dx, dP/dy for ray tracers and deferred renderers (ray differentials):
 * the pixel's ray is camera + s dir, its neighbours' directions change by ddir_dx,
 * ddir_dy per pixel; each neighbour ray is intersected with the tangent plane of
 * the hit (n . (X - p) = 0) and differentiated:
 *   dP = s ddir - dir (n . s ddir) / (n . dir),  s = n . (p - camera) / (n . dir).
 * The result is the derivative of the actual hit on any surface (the tangent plane
 * agrees with the surface to first order) and matches what ddx/ddy measure on a
 * flat triangle. dir may have any length, but ddir must be the derivative of that
 * same dir (normalized dir with the derivative of the normalized dir, or the
 * unnormalized pinhole dir with its per-pixel step).
 * @param p hit point, n its normal (either side), camera the ray origin.
 * @param dpdx receives dP per pixel step in x; @param dpdy per step in y.
 * Outputs are (0,0,0) when the ray grazes the plane (n . dir == 0), n is invalid
 * or any input is non-finite; eq. 3 then yields no perturbation.
 */
BG_API void bg_ray_differentials(bg_vec3 p, bg_vec3 n, bg_vec3 camera, bg_vec3 dir,
                                 bg_vec3 ddir_dx, bg_vec3 ddir_dy, bg_vec3 *dpdx, bg_vec3 *dpdy);
/** Double-precision bg_ray_differentials. */
BG_API void bg_ray_differentialsd(bg_dvec3 p, bg_dvec3 n, bg_dvec3 camera, bg_dvec3 dir,
                                  bg_dvec3 ddir_dx, bg_dvec3 ddir_dy, bg_dvec3 *dpdx,
                                  bg_dvec3 *dpdy);

/**
 * Ray differentials from an inverse view-projection matrix, for deferred shading
 * and any camera a 4x4 matrix describes (perspective, orthographic, off-axis; GL,
 * D3D, reversed or infinite depth). The pixel's ray is the line through the
 * unprojections of NDC (x, y, 0.25) and (x, y, 0.75), depths that are finite inside
 * the frustum under every common depth convention; its origin and direction are
 * differentiated in closed form and intersected with the tangent plane as in
 * bg_ray_differentials (so orthographic rays, whose origin moves, work too).
 *
 * Conventions: inv_view_proj is row-major, m[4*row + col], applied to column vectors
 * (world = m * ndc, then divided by w). Pixel (0,0) is the top-left corner of the
 * viewport, x right, y down, and the pixel centre is at +0.5: ndc.x = 2 px / width - 1,
 * ndc.y = 1 - 2 py / height (NDC y up, GL and D3D). For an NDC with y down (Vulkan),
 * negate column 1 of the matrix. dpdx, dpdy are per pixel step in +x and +y (down),
 * the orientation of D3D ddx/ddy.
 * @param viewport (width, height) in pixels, both nonzero.
 * Outputs (0,0,0) on a grazing ray, a singular unprojection (w == 0), invalid n,
 * zero viewport or non-finite input.
 */
BG_API void bg_ray_differentials_inv_viewproj(const float inv_view_proj[16], bg_vec2 pixel,
                                              bg_vec2 viewport, bg_vec3 p, bg_vec3 n,
                                              bg_vec3 *dpdx, bg_vec3 *dpdy);
/** Double-precision bg_ray_differentials_inv_viewproj. */
BG_API void bg_ray_differentials_inv_viewprojd(const double inv_view_proj[16], bg_dvec2 pixel,
                                               bg_dvec2 viewport, bg_dvec3 p, bg_dvec3 n,
                                               bg_dvec3 *dpdx, bg_dvec3 *dpdy);

/* ---- height textures (Listing 2) ----------------------------------------------- */

/** Addressing outside [0,1) texture coordinates. */
typedef enum bg_wrap {
    BG_WRAP_REPEAT = 0, /**< periodic, period 1 */
    BG_WRAP_CLAMP = 1,  /**< edge texels extend outward */
    BG_WRAP_MIRROR = 2  /**< mirrored repeat, period 2 */
} bg_wrap;

/** A single-channel height texture, borrowed (not owned, not copied). Texel (i, j)
 *  is texels[j * width + i] and its centre is at st = ((i + 0.5)/width,
 *  (j + 0.5)/height), as on GPUs. */
typedef struct bg_height_texture {
    int width, height;    /**< >= 1 each */
    const float *texels;  /**< width*height heights */
    bg_wrap wrap;
} bg_height_texture;

/** Finite-difference scheme for bg_height_texture_derivs. */
typedef enum bg_diff_mode {
    BG_DIFF_FORWARD = 0, /**< Listing 2: H(st + d) - H(st), 3 taps */
    BG_DIFF_CENTRAL = 1  /**< (H(st + d) - H(st - d)) / 2, 4 taps */
} bg_diff_mode;

/** BG_OK if `tex` can be sampled: texels non-NULL (else BG_ERR_NULL_POINTER), sizes
 *  >= 1 with width*height representable, wrap a known mode (else
 *  BG_ERR_INVALID_ARGUMENT). */
BG_API bg_status bg_height_texture_validate(const bg_height_texture *tex);

/**
 * Bilinear sample at st (the GPU's linear filter without mipmaps, computed in double
 * and rounded once). `tex` must be valid (bg_height_texture_validate). Coordinates
 * are reduced with the wrap mode in floating point before any integer conversion,
 * so huge st is safe. NaN/Inf st: NaN. Thread-safe.
 */
BG_API float bg_height_texture_sample(const bg_height_texture *tex, bg_vec2 st);

/**
 * Screen-space height derivatives of a height texture, Mikkelsen 2010 Listing 2:
 * given the pixel's texST and its per-pixel changes dST/dx and dST/dy, forward
 * differencing returns (dBs, dBt) = (H(st + dst_dx) - H(st), H(st + dst_dy) - H(st))
 * (3 taps) and central differencing ((H(st + dst_dx) - H(st - dst_dx)) / 2, ...)
 * (4 taps). Units: height per pixel, ready for bg_surfgrad_from_screen_derivs or
 * bg_perturb_normal_screen. Exact for a height that is linear in st (a ramp) as
 * long as the taps stay within the texture's interior. Differences are taken in
 * double and rounded once. A mode other than BG_DIFF_CENTRAL is forward. NaN/Inf
 * st or steps: NaN. `tex` must be valid. Thread-safe.
 */
BG_API bg_vec2 bg_height_texture_derivs(const bg_height_texture *tex, bg_diff_mode mode,
                                        bg_vec2 st, bg_vec2 dst_dx, bg_vec2 dst_dy);

/* ---- mip levels (the reference's DerivFromHeightMap[Level]) --------------------- */

/** A mip chain of height textures, borrowed: levels[0] the finest (its size is the
 *  `dim` of texel units), each further level any size (usually
 *  bg_height_mip_size of the previous, from bg_height_texture_downsample). */
typedef struct bg_height_mips {
    const bg_height_texture *levels; /**< `count` valid textures */
    int count;                       /**< >= 1 */
} bg_height_mips;

/** Size of the next mip level along one axis: max(1, size / 2) (D3D/GL rule). */
BG_API int bg_height_mip_size(int size);

/**
 * The next mip level of `src` into `dst` (bg_height_mip_size(width) *
 * bg_height_mip_size(height) floats, row-major): each texel the mean of the 2x2
 * block below it (a size-1 axis repeats its texel; for an odd size the last row or
 * column is not read, as the floor sizes imply). Summed in double, rounded once.
 * @return BG_OK; BG_ERR_NULL_POINTER for a NULL dst; src's validation status.
 */
BG_API bg_status bg_height_texture_downsample(const bg_height_texture *src, float *dst);

/** BG_OK if `mips` can be sampled: count >= 1 (else BG_ERR_INVALID_ARGUMENT), levels
 *  non-NULL (else BG_ERR_NULL_POINTER) and every level valid. */
BG_API bg_status bg_height_mips_validate(const bg_height_mips *mips);

/**
 * Trilinear sample at st and level `lod` (SampleLevel): bilinear on levels
 * floor(lod) and floor(lod) + 1, linear between them by the fraction; lod clamped to
 * [0, count - 1]. In double, rounded once. NaN lod or st: NaN. `mips` must be valid.
 */
BG_API float bg_height_mips_sample_level(const bg_height_mips *mips, bg_vec2 st, float lod);

/**
 * Level of detail of a footprint (the isotropic rule of the D3D/GL specifications):
 * log2(max(|dst_dx * dim|, |dst_dy * dim|)) with dim = (width, height) of `tex`,
 * unclamped (-Inf for a zero footprint, NaN for NaN).
 */
BG_API float bg_height_texture_lod(const bg_height_texture *tex, bg_vec2 dst_dx, bg_vec2 dst_dy);

/**
 * Height derivative at a mip level, in height per texel of level 0 (the reference's
 * DerivFromHeightMapLevel): with l = max(0, lod) and e = 2^l,
 *   d = (H_l(st + (e / width, 0)) - H_l(st), H_l(st + (0, e / height)) - H_l(st)) / e,
 * forward differences one texel of level l apart (H_l = bg_height_mips_sample_level
 * at l; width, height of level 0). With hq != 0 and l < 0.5 the result is blended
 * toward bg_height_texture_derivs_bicubic on level 0 by
 * mix = clamp((l - 0.5) / (0.05 - 0.5), 0, 1) (fully bicubic at l <= 0.05), the
 * reference's high-quality path for magnified textures. Feed the result to
 * bg_surfgrad_scale_dependent (screen) or bg_surfgrad_from_tbn (tangent frame:
 * multiply by the texture size first for derivatives per unit st).
 * NaN lod is level 0; NaN st (or lod above ~1000, where 2^l overflows): NaN.
 * `mips` must be valid. In double, rounded once.
 */
BG_API bg_vec2 bg_height_mips_derivs_level(const bg_height_mips *mips, bg_vec2 st, float lod,
                                           int hq);

/**
 * bg_height_mips_derivs_level at the footprint's own level (the reference's
 * DerivFromHeightMap): lod = bg_height_texture_lod(level 0, dst_dx, dst_dy) clamped
 * to [0, count - 1], as CalculateLevelOfDetail clamps.
 */
BG_API bg_vec2 bg_height_mips_derivs(const bg_height_mips *mips, bg_vec2 st, bg_vec2 dst_dx,
                                     bg_vec2 dst_dy, int hq);

/**
 * The reference's high-quality derivative of a magnified height texture (the
 * isUpscaleHQ path), in height per texel: at each of the four texels around st the
 * central difference (H[i+1] - H[i-1]) / 2 along the axis, smoothed across it by
 * the binomial [1 2 1] / 4, interpolated bilinearly to st. A 4x4 texel footprint
 * with the texture's wrap mode; exact for a height linear in the texel index
 * (away from clamped edges). NaN/Inf st: NaN. `tex` must be valid.
 */
BG_API bg_vec2 bg_height_texture_derivs_bicubic(const bg_height_texture *tex, bg_vec2 st);

/* ---- the Orange Book's procedural bumps (OpenGL Shading Language, 11.4) ------- */

/**
 * Tangent-space normal of Listing 11.8: c = density * st, p = fract(c) - 0.5,
 * d = p.x^2 + p.y^2, f = 1/sqrt(d + 1); the normal is (p.x, p.y, 1) f inside a bump
 * (d < bump_size; bump_size is compared with the squared distance, as in the
 * listing) and (0, 0, 1) outside. Unit length. The normal leans away from the bump
 * centre, as on a convex nodule; it is discontinuous at the bump's rim, as in the
 * listing. Use bg_surfgrad_from_tangent_normal to blend it with other influences.
 * NaN/Inf st or density: (0,0,1).
 */
BG_API bg_vec3 bg_orange_bump_normal(bg_vec2 st, float bump_density, float bump_size);

/**
 * Tangent-space lighting of Listing 11.8, in float as the shader:
 * diffuse = surface_color * max(dot(N, L), 0); R = reflect(L, N) = L - 2 dot(N, L) N;
 * spec = specular_factor * max(dot(E, R), 0)^6; color = min(diffuse + spec, 1) per
 * channel. L is the surface-to-light direction and E the eye-to-surface direction
 * (the vertex shader's EyeDir is the eye-space position), both in tangent space and,
 * as in the listing, not renormalized here. NaN inputs propagate.
 */
BG_API bg_vec3 bg_orange_bump_shade(bg_vec3 normal, bg_vec3 light_dir, bg_vec3 eye_dir,
                                    bg_vec3 surface_color, float specular_factor);

#ifdef __cplusplus
}
#endif

#endif /* BUMPGRAD_FRAMEWORK_H */
