/* SPDX-License-Identifier: MIT */
/* What the stand-alone kernel checks (check_grid.c, check_domain.c) share:
 * the failure count and report (a failure names the ISA or part it was seen
 * in; the first 30 are printed), a xorshift sequence seeded by the includer's
 * CHECK_RNG_SEED, bit-for-bit float comparison, and the special classes of
 * coordinate every check mixes in. (The kernel harness, checkkernels.h, has
 * its own.) */
#ifndef BUMPGRAD_TESTS_CHECK_STANDALONE_H
#define BUMPGRAD_TESTS_CHECK_STANDALONE_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

static long failures, checks;

static inline void fail(const char *what, const char *isa)
{
    failures++;
    if (failures <= 30)
        fprintf(stderr, "FAIL: %s (%s)\n", what, isa);
}

#ifndef CHECK_RNG_SEED
#error "define CHECK_RNG_SEED before including check_standalone.h"
#endif

static uint64_t rng_state = CHECK_RNG_SEED;

static inline uint64_t rng_u64(void)
{
    rng_state ^= rng_state << 13, rng_state ^= rng_state >> 7, rng_state ^= rng_state << 17;
    return rng_state;
}

static inline float rng_range(double a, double b)
{
    return (float)(a + (b - a) * (double)(rng_u64() >> 11) * 0x1p-53);
}

static inline int same_bits(float a, float b)
{
    uint32_t ua, ub;
    memcpy(&ua, &a, sizeof ua);
    memcpy(&ub, &b, sizeof ub);
    return ua == ub;
}

/* Special class K (0..SPECIAL_COORDS-1) near the lattice point I: the point,
 * its float neighbours, +-0, large, huge, NaN and +-Inf. */
#define SPECIAL_COORDS 9
static inline float special_coord(unsigned k, float i)
{
    switch (k) {
    case 0: return i;
    case 1: return nextafterf(i, INFINITY);
    case 2: return nextafterf(i, -INFINITY);
    case 3: return 0.0f;
    case 4: return -0.0f;
    case 5: return rng_range(-1e7, 1e7);
    case 6: return (rng_u64() & 1) ? 3e38f : -3e38f;
    case 7: return NAN;
    default: return (rng_u64() & 1) ? INFINITY : -INFINITY;
    }
}

/* One coordinate of CLASSES classes, drawn uniformly: the first
 * SPECIAL_COORDS the special ones near a lattice point in [-600, 600], the
 * others EXTRA(class). */
static inline float mixed_coord(unsigned classes, float (*extra)(unsigned k))
{
    float i = (float)((int)(rng_u64() % 1201) - 600);
    unsigned k = (unsigned)(rng_u64() % classes);
    return k < SPECIAL_COORDS ? special_coord(k, i) : extra(k);
}

#endif
