/* SPDX-License-Identifier: MIT */
/* tests/core's helpers on top of the common checks (common/check.h): float
 * rounding that the optimiser cannot fold, and near-lattice test points. */
#ifndef BUMPGRAD_TESTS_CHECK_H
#define BUMPGRAD_TESTS_CHECK_H

#include <math.h>
#include <stdio.h>
#include "common/check.h"
#include "ref.h"

/* double -> float through a volatile: gcc 12 at -O2/-O3 was seen folding
 * (double)(float)u back to u at one use of a converted value and not at
 * another, which hands the reference a different point than the library
 * (test_surfgrad). Every test input that both sides see is rounded here. */
static inline float check_to_float(double v)
{
    volatile float f = (float)v;
    return f;
}

/* Near-lattice in float: 1e-6 is below the float spacing beyond |k| = 8, so
 * k +- 1e-6 would round back onto the lattice; step 1..3 ulps off k instead
 * (and keep some exact lattice points and some k +- 1e-6 for small k). */
static inline float check_near_lattice_f(ref_rng *r)
{
    float k = (float)floor(ref_rng_uniform(r, -300, 300));
    int mode = (int)(ref_rng_u64(r) % 4);
    if (mode == 0)
        return k;
    if (mode == 1)
        return check_to_float(fmod(k, 8) + (ref_rng_uniform(r, 0, 1) < 0.5 ? 1e-6 : -1e-6));
    float dir = ref_rng_uniform(r, 0, 1) < 0.5 ? -INFINITY : INFINITY;
    for (int i = 0; i < mode - 1; i++)
        k = nextafterf(k, dir);
    return nextafterf(k, dir);
}

#endif
