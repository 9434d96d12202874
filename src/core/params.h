/* SPDX-License-Identifier: MIT */
/* Internal: the range checks of the parameter descriptors that every entry
 * point can afford on every call (a few compares, no loop). The single-point
 * functions (bg_fractal3*, bg_height_eval) use them to return NaN for a
 * descriptor that would otherwise be read out of its range (an unknown enum
 * silently running another function, a NULL pointer, an octave count that loops
 * a thousand times); the batch calls run the full bg_fractal_validate /
 * bg_height_validate (these checks plus the octave-overflow check) once per call.
 * noise.h and surfgrad.h document the contract. */
#ifndef BUMPGRAD_CORE_PARAMS_H
#define BUMPGRAD_CORE_PARAMS_H

#include <math.h>
#include "bumpgrad/noise.h"
#include "bumpgrad/surfgrad.h"

/* Bounds on Perlin's improved noise and its gradient components, with a margin
 * for float rounding: the value is a convex combination (fade weights in [0,1])
 * of corner values +-d1 +-d2 with |d| <= 1, so |n| <= 2; each gradient
 * component adds a lerp of corner gradient components (|g| <= 1) and
 * fade'(t) (at most 30/16 = 1.875) times a difference of two corner values
 * (at most 4), so |dn/dx| <= 8.5. noise.h quotes them (bg_fractal_validate);
 * tests/core/test_contract.c checks them on samples. */
#define BG_NOISE_VALUE_BOUND 2.1
#define BG_NOISE_GRAD_BOUND 9.0

/* 1 if `f` passes every check of bg_fractal_validate except the overflow one. */
static inline int bg_fractal_in_range(const bg_fractal *f)
{
    if (!f)
        return 0;
    if (f->function == BG_FUNC_NOISE)
        return 1;
    if (f->function != BG_FUNC_FBM && f->function != BG_FUNC_TURBULENCE)
        return 0;
    return f->octaves >= 1 && f->octaves <= BG_MAX_OCTAVES && f->lacunarity > 0 &&
           isfinite(f->lacunarity) && isfinite(f->gain);
}

/* The octave-overflow check of bg_fractal_validate for a fractal in range
 * (noise.c): 1 and the sums sum|amp_i|, sum|amp_i freq_i| and max freq_i, or 0
 * if the octave scaling overflows float. */
int bg_fractal_octave_sums(const bg_fractal *f, double *sum_amp, double *sum_amp_freq,
                           float *max_freq);

/* 1 if domain `d` suits fractal `f` (in range): bg_domain_validate's checks.
 * The finest octave's period P * L^(octaves-1) is built in float by repeated
 * multiplication, as the kernels build it (bump_tmpl.c octlat_init). */
static inline int bg_domain_in_range(const bg_fractal *f, const bg_domain *d)
{
    if (!d)
        return 0;
    int any = 0;
    for (int a = 0; a < 3; a++) {
        if (d->period[a] < 0 || d->period[a] > BG_MAX_PERIOD)
            return 0;
        any |= d->period[a] != 0;
    }
    if (!any || f->function == BG_FUNC_NOISE)
        return 1;
    float lac = f->lacunarity;
    if (!(lac >= 1 && lac <= 16777216.0f && lac == floorf(lac)))
        return 0;
    for (int a = 0; a < 3; a++) {
        float p = (float)d->period[a];
        for (int i = 1; i < f->octaves && p > 0; i++)
            if ((p *= lac) > 16777216.0f)
                return 0;
    }
    return 1;
}

/* 1 if `h` passes every check of bg_height_validate except the overflow one. */
static inline int bg_height_in_range(const bg_height *h)
{
    return h && bg_fractal_in_range(&h->fractal) && bg_domain_in_range(&h->fractal, &h->domain) &&
           isfinite(h->amplitude) &&
           isfinite(h->frequency) && h->step >= 0 && isfinite(h->step) &&
           (h->gradient == BG_GRADIENT_ANALYTIC || h->gradient == BG_GRADIENT_CENTRAL);
}

/* 1 if `h` is a usable central-difference step: finite and > 0. */
static inline int bg_central_step_ok(double h)
{
    return h > 0 && isfinite(h);
}

/* 1 if `m` is a bg_perturb_method. */
static inline int bg_perturb_method_ok(bg_perturb_method m)
{
    return m == BG_PERTURB_SURFGRAD || m == BG_PERTURB_ADDITIVE || m == BG_PERTURB_ADDITIVE_PERLIN;
}

/* The checks of the fused height batches (surfgrad.c), before n: pointers
 * (`height` is optional), bg_height_validate, the method. */
bg_status bg_perturb_height_check(const bg_height *h, bg_perturb_method method,
                                  const float *px, const float *py, const float *pz,
                                  const float *nx, const float *ny, const float *nz, float *ox,
                                  float *oy, float *oz);

#endif
