/* SPDX-License-Identifier: MIT */
/* Vector vocabulary, scalar: one lane, float (or double when BG_SCALAR_DOUBLE is
 * defined: the double entry points use the very same template). The scalar kernel is the template
 * compiled against this header, so it is by construction the same algorithm as
 * every SIMD level (SLEEF-style "helper" headers). Every vocabulary must define
 * each operation with exactly these IEEE semantics so that lanes agree bit for
 * bit: vf_max(a,b) is (a > b ? a : b) (x86 maxps order), vf_floor is IEEE floor,
 * vi_from_vf truncates an in-range value, vf_sel(m,a,b) is m ? a : b, and the
 * lookups vi_perm2 / vf_lut16 / vi_cell256 below are exact table reads. The
 * full list and the per-ISA notes are in docs/KERNELS.md. */
#ifndef BUMPGRAD_VEC_C_H
#define BUMPGRAD_VEC_C_H

#include <math.h>
#include <stdint.h>
#include <string.h>
#include <float.h>
#include "kernels.h"

#ifdef BG_SCALAR_DOUBLE
#define BG_ISA_SUFFIX c64
#define BG_REAL_MAX DBL_MAX
typedef double bg_real;
#define BG_SQRT sqrt
#define BG_FLOOR floor
#define BG_FABS fabs
#else
/* BG_C_SUFFIX: this one-lane vocabulary compiled again with another ISA's
 * flags (meson.build: c_avx2, the single points of the AVX2 and AVX-512
 * tables; VEX encoding and roundss, the same operations and bits). */
#ifdef BG_C_SUFFIX
#define BG_ISA_SUFFIX BG_C_SUFFIX
#else
#define BG_ISA_SUFFIX c
#endif
#define BG_REAL_MAX FLT_MAX
typedef float bg_real;
#define BG_SQRT sqrtf
#define BG_FLOOR floorf
#define BG_FABS fabsf
#endif
#define LANES 1
#define BG_ISA_ENUM BG_ISA_SCALAR
typedef bg_real vf;
typedef int32_t vi;
typedef int vm;

static inline vf vf_set1(bg_real a) { return a; }
static inline vf vf_loadn(const bg_real *p, size_t c) { (void)c; return *p; }
static inline void vf_storen(bg_real *p, vf v, size_t c) { (void)c; *p = v; }
static inline vf vf_add(vf a, vf b) { return a + b; }
static inline vf vf_sub(vf a, vf b) { return a - b; }
static inline vf vf_mul(vf a, vf b) { return a * b; }
static inline vf vf_div(vf a, vf b) { return a / b; }
static inline vf vf_sqrt(vf a) { return BG_SQRT(a); }
static inline vf vf_floor(vf a) { return BG_FLOOR(a); }
static inline vf vf_abs(vf a) { return BG_FABS(a); }
static inline vf vf_neg(vf a) { return -a; }
static inline vf vf_max(vf a, vf b) { return a > b ? a : b; }
static inline vm vf_lt(vf a, vf b) { return a < b; }
static inline vm vf_le(vf a, vf b) { return a <= b; }
static inline vm vf_gt(vf a, vf b) { return a > b; }
static inline vm vm_and(vm a, vm b) { return a & b; }
static inline vm vm_or(vm a, vm b) { return a | b; }
static inline vm vm_not(vm a) { return !a; }
static inline vf vf_sel(vm m, vf a, vf b) { return m ? a : b; }
static inline vi vi_set1(int32_t a) { return a; }
static inline vi vi_from_vf(vf a) { return (int32_t)a; }
static inline vi vi_add(vi a, vi b) { return a + b; }
static inline vi vi_and(vi a, vi b) { return a & b; }
static inline vm vi_lt(vi a, vi b) { return a < b; }
static inline vm vi_eq(vi a, vi b) { return a == b; }
/* r + 1, or 0 where r = pm1 (bump_tmpl.c octave_cell_carry). */
static inline vi vi_wrap1(vi r, int32_t pm1) { return r == pm1 ? 0 : r + 1; }
static inline vm vi_test(vi a, vi bits) { return (a & bits) != 0; }
/* Every lane of m set. */
static inline int vm_all(vm m) { return m != 0; }
/* bg_perm_pair[idx & 255] (p[idx] | p[idx + 1] << 8), idx >= 0. */
static inline vi vi_perm2(vi idx) { return bg_perm_pair[idx & 255]; }
/* Logical shift right by 8 of a non-negative lane. */
static inline vi vi_srl8(vi a) { return (vi)((uint32_t)a >> 8); }

/* tab[idx & 15]: the corner gradient tables. */
static inline vf vf_lut16(const bg_real *tab, vi idx) { return tab[idx & 15]; }

/* Corner gradients (bump_tmpl.c grad_corner): vf_sel_bit(h, b, a, c) is
 * (bit b of h set ? a : c); vf_flip_bit(a, h, b) flips the sign bit of a where
 * bit b of h is set (the reference's -u, an exact negation). vf_canon(a) is a
 * with every NaN replaced by the one canonical quiet NaN (+qNaN, 0x7fc00000),
 * applied to every kernel output so that NaN results are the same bits on
 * every ISA. */
static inline vf vf_sel_bit(vi h, int b, vf a, vf c) { return (h >> b) & 1 ? a : c; }
/* The flip as an integer XOR: a branch on a random hash bit mispredicts. */
static inline vf vf_flip_bit(vf a, vi h, int b)
{
#ifdef BG_SCALAR_DOUBLE
    uint64_t u;
    memcpy(&u, &a, sizeof u);
    u ^= (uint64_t)((uint32_t)h >> b & 1u) << 63;
#else
    uint32_t u;
    memcpy(&u, &a, sizeof u);
    u ^= ((uint32_t)h >> b & 1u) << 31;
#endif
    memcpy(&a, &u, sizeof a);
    return a;
}
/* One lane: the corner's axes and gradient vector by table (three loads beat
 * the branches a scalar compiler makes of the vector selects; bump_tmpl.c). */
#define BG_GRAD_BY_TABLE 1
static inline vf vf_canon(vf a) { return a != a ? (bg_real)NAN : a; }
#ifndef BG_SCALAR_DOUBLE
/* An integer-valued float (a floor) modulo 256 in [0, 256); 0 for NaN/Inf. From
 * 2^31 up every float is a multiple of 256, so the int32 conversion is only
 * needed (and only defined) below that. */
static inline vi vi_cell256(vf fl) { return fabsf(fl) < 2147483648.0f ? ((int32_t)fl & 255) : 0; }
#endif

#endif
