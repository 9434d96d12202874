/* SPDX-License-Identifier: MIT */
/* Test vocabulary for tests/framework: the common checks, and a small
 * double-precision vector toolkit written here, independently of src/, so the
 * references in these tests share no code with the functions they check. */
#ifndef BUMPGRAD_TESTS_FW_CHECK_H
#define BUMPGRAD_TESTS_FW_CHECK_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include "bumpgrad.h"
#include "common/check.h"

typedef struct {
    double x, y, z;
} rv;

static inline rv R(double x, double y, double z)
{
    rv r = {x, y, z};
    return r;
}
static inline rv radd(rv a, rv b) { return R(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline rv rsub(rv a, rv b) { return R(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline rv rmul(rv a, double s) { return R(a.x * s, a.y * s, a.z * s); }
static inline double rdot(rv a, rv b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline rv rcross(rv a, rv b)
{
    return R(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double rlen(rv a) { return sqrt(rdot(a, a)); }
static inline rv rnorm(rv a) { return rmul(a, 1.0 / rlen(a)); }
static inline double rdist(rv a, rv b) { return rlen(rsub(a, b)); }
/* eq. 2 written out: the part of g perpendicular to the unit n. */
static inline rv rproj(rv n, rv g) { return rsub(g, rmul(n, rdot(n, g))); }

static inline rv from_f(bg_vec3 a) { return R(a.x, a.y, a.z); }
static inline rv from_d(bg_dvec3 a) { return R(a.x, a.y, a.z); }
/* Through a volatile: gcc 12.2's SLP vectorizer folds neighbouring
 * (double)(float)v round trips into no rounding at all (a miscompilation, see
 * docs/ACCURACY.md), and the double references must see the float inputs. */
static inline float fw_to_float(double v)
{
    volatile float f = (float)v;
    return f;
}
static inline bg_vec3 to_f(rv a)
{
    bg_vec3 r = {fw_to_float(a.x), fw_to_float(a.y), fw_to_float(a.z)};
    return r;
}
static inline bg_dvec3 to_d(rv a)
{
    bg_dvec3 r = {a.x, a.y, a.z};
    return r;
}
static inline bg_vec2 v2f(double x, double y)
{
    bg_vec2 r = {(float)x, (float)y};
    return r;
}
static inline bg_dvec2 v2d(double x, double y)
{
    bg_dvec2 r = {x, y};
    return r;
}
static inline int is_zero_f(bg_vec3 a) { return a.x == 0 && a.y == 0 && a.z == 0; }
static inline int is_zero_d(bg_dvec3 a) { return a.x == 0 && a.y == 0 && a.z == 0; }

/* Deterministic generator (xorshift64*), uniform in [lo, hi). */
static uint64_t fw_rng_state = 0x9E3779B97F4A7C15ull;
static inline double urand(double lo, double hi)
{
    fw_rng_state ^= fw_rng_state >> 12;
    fw_rng_state ^= fw_rng_state << 25;
    fw_rng_state ^= fw_rng_state >> 27;
    uint64_t v = fw_rng_state * 2685821657736338717ull;
    return lo + (hi - lo) * ((double)(v >> 11) * (1.0 / 9007199254740992.0));
}
static inline rv rand_dir(void)
{
    for (;;) {
        rv v = R(urand(-1, 1), urand(-1, 1), urand(-1, 1));
        double l = rlen(v);
        if (l > 0.1 && l <= 1)
            return rmul(v, 1.0 / l);
    }
}
/* Unit vector perpendicular to unit n. */
static inline rv rperp(rv n)
{
    rv a = fabs(n.x) < 0.6 ? R(1, 0, 0) : R(0, 1, 0);
    return rnorm(rcross(n, a));
}

#endif
