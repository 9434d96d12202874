/* SPDX-License-Identifier: MIT */
/* The kernel harness (after dav1d's checkasm, tests/checkasm/checkasm.h): what
 * the per-family files (check_noise.c, check_fractal.c, check_perturb.c) share.
 * A kernel under test is declared by its id and parameters (enum kid, params);
 * call_ref runs the reference (the scalar kernel, bg_kernels_c), call_new one
 * ISA's table (every ISA and variant the build and CPU have, as the dispatch
 * forces them); check_kernel compares them bit for bit over every tail length,
 * misalignment and guard. Against the double references (tests/ref when built,
 * bg_kernels_c64 always), check_close bounds the absolute error and, where
 * |reference| >= ULP_MIN, the error in ULP, and reports both on failure. */
#ifndef BUMPGRAD_TESTS_CHECKKERNELS_H
#define BUMPGRAD_TESTS_CHECKKERNELS_H

#include <stddef.h>
#include <stdint.h>

#include "kernels/kernels.h"
#ifdef BG_HAVE_REF
#include "ref.h"
#endif

#define MAX_LANES 16
#define MAX_TAIL (2 * MAX_LANES + 1)
#define LONG_N 517
#define GUARD 8
#define MAX_IN 6
#define MAX_OUT 4

extern int failures; /* checks failed so far (main's exit status) */
extern long checks;  /* ISA-vs-scalar comparisons made */
void fail(const char *what);
int same_bits(float a, float b);

/* ---- deterministic inputs (each family seeds its own sequence) ---- */
void rng_seed(uint64_t seed);
uint64_t rng_u64(void);
double rng_unit(void);
float rng_range(double lo, double hi);
/* A coordinate, a normal component, a gradient component: mostly ordinary
 * values, with every special class (lattice, +-0, huge, NaN, Inf, ...) mixed in. */
float coord(void);
float normal_comp(void);
float grad_comp(void);

/* ---- declaring a kernel under test ---- */
enum kid { K_NOISE3, K_NOISE3_GRAD, K_FRACTAL3, K_FRACTAL3_GRAD, K_FRACTAL3_CENTRAL, K_PERTURB,
           K_PERTURB_HEIGHT, K_COUNT };
extern const char *const kname[K_COUNT];
extern const int n_in[K_COUNT], n_out[K_COUNT];

typedef struct params {
    bg_fractal f;
    float h;
    bg_perturb_method m;
    bg_height hg;
    int null_first; /* pass NULL for the optional first output (value / height) */
} params;

/* Kernel k of table t on in[0..n_in[k]) -> out[0..n_out[k]). */
void call_new(const bg_kernel_table *t, enum kid k, const params *p, float *const *in, size_t n,
              float *const *out);
/* The same call on the reference, the scalar kernel. */
void call_ref(enum kid k, const params *p, float *const *in, size_t n, float *const *out);

/* Every ISA in isas[0..nisa) against call_ref, bit for bit: lengths 0..MAX_TAIL
 * (and long_runs x 4 misalignments of LONG_N), canaries around every output,
 * inputs of exactly their length. */
void check_kernel(const bg_kernel_table *const *isas, int nisa, enum kid k, const params *p,
                  int long_runs);

/* Parameter sets: plain noise, fBm and turbulence of 1..32 octaves, odd
 * lacunarities and gains. */
extern const bg_fractal fractals[];
extern const int n_fractals;

/* ---- against a double reference ---- */
extern double maxerr_v, maxerr_g, maxulp;
/* The ULP bound applies where a relative measure means something,
 * |reference| >= ULP_MIN (checkkernels.c explains the numbers). */
#define ULP_MIN 0.25
#define ULP_BOUND 512.0
/* |got - want| <= eps and (ulp_bound > 0) ULP distance <= ulp_bound, else a
 * failure naming both distances and the point; *track keeps the largest error. */
void check_close_u(const char *what, double got, double want, double eps, double ulp_bound,
                   double *track, const float *pt);
#define check_close(what, got, want, eps, track, pt) \
    check_close_u(what, got, want, eps, ULP_BOUND, track, pt)

/* ---- the families: scalar vs double, then every ISA vs scalar ---- */
void check_noise(const bg_kernel_table *const *isas, int nisa);
void check_fractal(const bg_kernel_table *const *isas, int nisa);
void check_perturb(const bg_kernel_table *const *isas, int nisa);

#endif
