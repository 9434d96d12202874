/* SPDX-License-Identifier: MIT */
/**
 * @file framework.h
 * @brief The surface-gradient bump mapping framework (Mikkelsen 2020, as retold in
 *        the seed "surface-gradient-framework-overview.md") on the CPU: every bump
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
 *    eq. 3 and Listing 1), with height-texture differencing (Listing 2);
 *  - a volume gradient (eq. 2 is bg_surface_gradient in surfgrad.h) and its
 *    triplanar variant;
 * and supplies the frames they need: a tangent frame from UV and position derivatives
 * (the overview's compute_tbn), analytic dP/dx, dP/dy from ray differentials for
 * renderers without ddx/ddy, mikkTSpace renormalization, and face-forwarding.
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
 *    points (suffix d) do the same arithmetic without the rounding.
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
 * Surface gradient of a tangent-space normal m in the frame (t, b):
 * grad_S h = -(m.x/m.z) t - (m.y/m.z) b (overview, "Surface gradient from a
 * tangent-space normal vector with a tangent basis"). Then
 * normalize(n - grad_S h) == normalize(m.x t + m.y b + m.z n) for any frame with
 * unit n and m.z > 0.
 *
 * Clamping, as the framework does: m.z is replaced by
 * max(|m.z|, max(|m.x|, |m.y|) / 128), so m.z is kept positive (an m below the
 * horizon is mirrored to the visible side) and both slopes are bounded by
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
 * Listing 1 of Mikkelsen 2010 without division: with R1 = dpdy x n, R2 = n x dpdx,
 * det = dpdx . R1, returns normalize(|det| n - sign(det) (dhdx R1 + dhdy R2)), which
 * equals bg_resolve_normal(n, {bg_surfgrad_from_screen_derivs(...)}, NULL, 1) but
 * stays defined as det -> 0 (it tends to the tangent direction).
 * @return unit normal; det == 0 returns the unit n (no slope can be measured); n
 *         invalid or non-finite input: (0,0,0) for n, unit n for the rest.
 */
BG_API bg_vec3 bg_perturb_normal_screen(bg_vec3 n, bg_vec3 dpdx, bg_vec3 dpdy, float dhdx,
                                        float dhdy);
/** Double-precision bg_perturb_normal_screen. */
BG_API bg_dvec3 bg_perturb_normal_screend(bg_dvec3 n, bg_dvec3 dpdx, bg_dvec3 dpdy, double dhdx,
                                          double dhdy);

/**
 * Triplanar blend weights: w_i = |n_i|^k / (|n_x|^k + |n_y|^k + |n_z|^k) (computed
 * as (|n_i|/max|n|)^k so large k never underflows all three). Sum is 1.
 * @param k sharpness >= 0 (0: equal thirds; large: the dominant axis only).
 * @return weights; n invalid, or k negative or non-finite: (0,0,0).
 */
BG_API bg_vec3 bg_triplanar_weights(bg_vec3 n, float k);
/** Double-precision bg_triplanar_weights. */
BG_API bg_dvec3 bg_triplanar_weightsd(bg_dvec3 n, double k);

/**
 * Triplanar surface gradient. Three planar height maps are sampled by the caller at
 * the point's (y,z), (x,z) and (x,y) coordinates and give their derivatives along
 * the world axes of that plane:
 *   d_yz = (dh/dy, dh/dz), d_xz = (dh/dx, dh/dz), d_xy = (dh/dx, dh/dy).
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
 * @param sign bitangent sign (the w of a mikkTSpace tangent); negative means -1,
 *             anything else +1.
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
