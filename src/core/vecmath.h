/* SPDX-License-Identifier: MIT */
/* Private 3-vector helpers shared by src/core and the tools (renderer, mesh
 * frames), so that there is one copy of each. Everything is static inline: no
 * symbol is exported and an unused helper costs nothing. Not installed.
 *
 * Two families:
 *  - bg_dv3_*: double value type bg_dvec3 (common.h). The plain operations do
 *    exactly the textbook arithmetic in the textbook order (x, y, z; a.y*b.z -
 *    a.z*b.y for the cross product), so code switching to them keeps its bits.
 *    bg_dv3_unit and bg_dv3_length are the overflow-safe forms the framework
 *    uses; bg_dv3_length_naive is sqrt(dot(a, a)) for callers that want it.
 *  - bg_f3_*: float arrays float[3], the renderer's arithmetic (float products
 *    and sums, sqrtf, division by the length), bit for bit.
 * The project builds with -ffp-contract=off, so no product is fused into a sum
 * and every caller sees the same rounding. */
#ifndef BUMPGRAD_CORE_VECMATH_H
#define BUMPGRAD_CORE_VECMATH_H

#include "bumpgrad/common.h"
#include <math.h>

/* ---- double value type --------------------------------------------------- */

static inline bg_dvec3 bg_dv3(double x, double y, double z)
{
    bg_dvec3 r = {x, y, z};
    return r;
}
static inline bg_dvec3 bg_dv3_zero(void)
{
    return bg_dv3(0, 0, 0);
}
static inline bg_dvec3 bg_dv3_add(bg_dvec3 a, bg_dvec3 b)
{
    return bg_dv3(a.x + b.x, a.y + b.y, a.z + b.z);
}
static inline bg_dvec3 bg_dv3_sub(bg_dvec3 a, bg_dvec3 b)
{
    return bg_dv3(a.x - b.x, a.y - b.y, a.z - b.z);
}
static inline bg_dvec3 bg_dv3_scale(bg_dvec3 a, double s)
{
    return bg_dv3(a.x * s, a.y * s, a.z * s);
}
/** Division by s per component (not multiplication by 1/s: the reciprocal of a
 *  subnormal overflows). */
static inline bg_dvec3 bg_dv3_div(bg_dvec3 a, double s)
{
    return bg_dv3(a.x / s, a.y / s, a.z / s);
}
static inline bg_dvec3 bg_dv3_neg(bg_dvec3 a)
{
    return bg_dv3(-a.x, -a.y, -a.z);
}
static inline double bg_dv3_dot(bg_dvec3 a, bg_dvec3 b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
static inline bg_dvec3 bg_dv3_cross(bg_dvec3 a, bg_dvec3 b)
{
    return bg_dv3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double bg_dv3_maxabs(bg_dvec3 a)
{
    return fmax(fmax(fabs(a.x), fabs(a.y)), fabs(a.z));
}
static inline int bg_dv3_finite(bg_dvec3 a)
{
    return isfinite(a.x) && isfinite(a.y) && isfinite(a.z);
}
static inline int bg_dv3_is_zero(bg_dvec3 a)
{
    return a.x == 0 && a.y == 0 && a.z == 0;
}

/** Unit vector or (0,0,0) (zero, NaN or Inf input). Scaling by the largest
 *  component first keeps the squared length in [1, 3], so neither huge (1e300)
 *  nor tiny (1e-300) input over/underflows. */
static inline bg_dvec3 bg_dv3_unit(bg_dvec3 a)
{
    double m = bg_dv3_maxabs(a);
    if (!(m > 0) || !bg_dv3_finite(a))
        return bg_dv3_zero();
    a = bg_dv3_div(a, m);
    return bg_dv3_scale(a, 1.0 / sqrt(bg_dv3_dot(a, a)));
}

/** Length without overflow or underflow, with the scaling of bg_dv3_unit. 0 for
 *  the zero vector; NaN input gives 0 or NaN, Inf gives Inf or NaN: test the input
 *  with bg_dv3_finite when it matters. */
static inline double bg_dv3_length(bg_dvec3 a)
{
    double m = bg_dv3_maxabs(a);
    if (!(m > 0))
        return 0;
    bg_dvec3 b = bg_dv3_div(a, m);
    return m * sqrt(bg_dv3_dot(b, b));
}

/** sqrt(dot(a, a)): the plain length (overflows beyond 1e154, as written). */
static inline double bg_dv3_length_naive(bg_dvec3 a)
{
    return sqrt(bg_dv3_dot(a, a));
}

/** Float <-> double (widening is exact; narrowing rounds once per component). */
static inline bg_dvec3 bg_dv3_from_f(bg_vec3 a)
{
    return bg_dv3(a.x, a.y, a.z);
}
static inline bg_vec3 bg_f3_from_dv(bg_dvec3 a)
{
    bg_vec3 r = {(float)a.x, (float)a.y, (float)a.z};
    return r;
}

/* ---- float arrays ------------------------------------------------------------ */

static inline float bg_f3_dot(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/** o = a x b; o may alias a or b (all three components are formed first). */
static inline void bg_f3_cross(const float a[3], const float b[3], float o[3])
{
    float x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2],
          z = a[0] * b[1] - a[1] * b[0];
    o[0] = x, o[1] = y, o[2] = z;
}

/** v /= sqrtf(dot(v, v)) in place and returns 1; when the length is zero, NaN or
 *  Inf, leaves v untouched and returns 0. */
static inline int bg_f3_normalize(float v[3])
{
    float l = sqrtf(bg_f3_dot(v, v));
    if (!(l > 0) || !isfinite(l))
        return 0;
    v[0] /= l, v[1] /= l, v[2] /= l;
    return 1;
}

#endif /* BUMPGRAD_CORE_VECMATH_H */
