/* SPDX-License-Identifier: MIT */
/* Private pieces shared by the framework_*.c files (include/bumpgrad/framework.h):
 * conversions between the float and double API types and the rules they share.
 *
 * The framework is per-sample math, not a hot kernel: every entry point computes
 * in double, and the float API widens its inputs exactly and rounds once, so float
 * and double share one implementation of the degenerate-input rules and a float
 * result is the double result rounded once. The exceptions are the calls that are
 * GPU-faithful by contract (bg_listing1_normal, the Orange Book shading), which
 * compute in float as the shader does. Scalings divide rather than multiply by a
 * reciprocal: the reciprocal of a subnormal overflows. */
#ifndef BUMPGRAD_CORE_FRAMEWORK_INTERNAL_H
#define BUMPGRAD_CORE_FRAMEWORK_INTERNAL_H

#include "bumpgrad/framework.h"
#include "vecmath.h"

static inline double fw_sgn(double x)
{
    return x > 0 ? 1.0 : (x < 0 ? -1.0 : 0.0);
}
static inline int fw_fin2(bg_dvec2 a)
{
    return isfinite(a.x) && isfinite(a.y);
}
static inline bg_dvec2 fw_d2(bg_vec2 a)
{
    bg_dvec2 r = {a.x, a.y};
    return r;
}
static inline bg_vec2 fw_f2(bg_dvec2 a)
{
    bg_vec2 r = {(float)a.x, (float)a.y};
    return r;
}
static inline bg_tangent_frame fw_fframe(bg_dtangent_frame f)
{
    bg_tangent_frame r = {bg_f3_from_dv(f.t), bg_f3_from_dv(f.b), bg_f3_from_dv(f.n)};
    return r;
}
static inline bg_dtangent_frame fw_zero_frame(void)
{
    bg_dtangent_frame f = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    return f;
}

/* Rescale a chart so each position derivative has largest component 1 (the height
 * derivative scales with it: a reparametrization s' = s*k leaves eq. 3 unchanged).
 * Keeps the triple product away from under/overflow. 0 if unusable. Shared by eq. 3,
 * Listing 1 and the parallax helpers (framework_screen.c). */
static inline int fw_rescale_chart(bg_dvec3 *ss, bg_dvec3 *st, double *bs, double *bt)
{
    double as = bg_dv3_maxabs(*ss), at = bg_dv3_maxabs(*st);
    if (!(as > 0) || !(at > 0))
        return 0;
    *ss = bg_dv3_div(*ss, as), *bs /= as;
    *st = bg_dv3_div(*st, at), *bt /= at;
    return bg_dv3_finite(*ss) && bg_dv3_finite(*st) && isfinite(*bs) && isfinite(*bt);
}

#endif /* BUMPGRAD_CORE_FRAMEWORK_INTERNAL_H */
