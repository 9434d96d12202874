/* SPDX-License-Identifier: MIT */
/**
 * @file ref.h
 * @brief Independent double-precision reference for the bumpgrad tests.
 *
 * Written from the published algorithms (Perlin 2002 "Improving Noise", Perlin
 * 1985 fBm/turbulence, Mikkelsen 2010 eq. 2 / eq. 4 / Listing 3), sharing no code
 * and no headers with src/. Plain C, double throughout, no SIMD, nothing clever:
 * its only job is to be obviously right, so that the library can be compared
 * against it. Used by tests/core, the kernel harness and the accuracy tools:
 * link with `ref_dep` (declared in tests/ref/meson.build).
 *
 * Conventions: vectors are `double[3]`; functions are pure and thread-safe.
 * Coordinates must be finite (the reference does not define NaN/Inf behaviour;
 * the tests check the library's NaN rules directly).
 */
#ifndef BUMPGRAD_TESTS_REF_H
#define BUMPGRAD_TESTS_REF_H

#ifdef __cplusplus
extern "C" {
#endif

/** Perlin's improved noise, evaluated exactly as his reference implementation
 *  (floor, cell reduced mod 256 then `& 255`, fade, lerp, grad(hash, x, y, z)),
 *  so it reproduces ref_noise(3.14, 42, 7) == 0.13691995878400012. Exact for
 *  |coordinate| up to 2^52. */
double ref_noise(double x, double y, double z);

/** Entry `i & 255` of Perlin's permutation (for table checks). */
int ref_permutation(int i);

/** Noise value (same bits as ref_noise) and its analytic gradient, derived
 *  separately from the lerp chain: noise = sum over the 8 corners of
 *  Wx*Wy*Wz*(g_c . (p - c)) with Wx = 1-u or u, and the product rule
 *  d/dx = sum dWx*Wy*Wz*(g_c . d) + Wx*Wy*Wz*g_c.x. `grad` may be NULL. */
double ref_noise_grad(double x, double y, double z, double grad[3]);

/** A second, derivative-free gradient for validating ref_noise_grad itself:
 *  long double central differences of a long double noise with one step of
 *  Richardson extrapolation, (4 D(h/2) - D(h)) / 3, error O(h^4).
 *  Only valid where [x-h, x+h] stays inside one lattice cell along each axis
 *  (the noise's third derivative jumps at cell faces); returns 0 if that is not
 *  the case, 1 on success. */
int ref_noise_grad_richardson(double x, double y, double z, double h, double grad[3]);

/** Which fractal sum. */
enum ref_function { REF_NOISE = 0, REF_FBM = 1, REF_TURBULENCE = 2 };

/** Fractal parameters: octave i samples noise at lacunarity^i * p with weight
 *  gain^i (powers built by repeated multiplication in double). */
typedef struct ref_fractal {
    enum ref_function function;
    int octaves;
    double lacunarity;
    double gain;
} ref_fractal;

/** Fractal value and analytic gradient (grad may be NULL).
 *  fBm = sum gain^i noise_i, turbulence = sum gain^i |noise_i| (Perlin 1985),
 *  whose gradient sum gain^i lac^i sign(noise_i) grad noise_i is undefined where
 *  an octave crosses zero. If `min_abs_octave` is not NULL it receives the
 *  smallest |noise_i| over the octaves, so a caller can stay away from creases. */
double ref_fractal_grad(const ref_fractal *f, double x, double y, double z, double grad[3],
                        double *min_abs_octave);

/** Bit i set when octave i of `f` is negative at (x, y, z). Two points with
 *  different masks have a turbulence crease between them (a central difference
 *  across it does not estimate the gradient). */
unsigned long ref_fractal_sign_mask(const ref_fractal *f, double x, double y, double z);

/** Surface gradient (Mikkelsen 2010, eq. 2): out = g - n (n . g), n normalized
 *  first. n must be nonzero and finite. */
void ref_surface_gradient(const double n[3], const double g[3], double out[3]);

/** Perturbed normal (eq. 4, Listing 3): normalize(n - surface_gradient(n, g)). */
void ref_perturb_surfgrad(const double n[3], const double g[3], double out[3]);

/** Perlin's additive perturbation with the gradient negated: normalize(n - g),
 *  n normalized first. If n - g is exactly zero, out = the unit n. */
void ref_perturb_additive(const double n[3], const double g[3], double out[3]);

/** Deterministic generator for test inputs (splitmix64), so every test run sees
 *  the same points on every platform. */
typedef struct ref_rng {
    unsigned long long state;
} ref_rng;
void ref_rng_seed(ref_rng *r, unsigned long long seed);
unsigned long long ref_rng_u64(ref_rng *r);
/** Uniform double in [lo, hi). */
double ref_rng_uniform(ref_rng *r, double lo, double hi);
/** Uniformly distributed unit vector on the sphere. */
void ref_rng_unit_vector(ref_rng *r, double out[3]);

#ifdef __cplusplus
}
#endif

#endif /* BUMPGRAD_TESTS_REF_H */
