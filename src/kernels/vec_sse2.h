/* SPDX-License-Identifier: MIT */
/* Vector vocabulary, SSE2: four float lanes. Plain SSE2 only (no SSE4.1), so
 * floor and blend are built from compares and logic; each operation keeps the
 * exact IEEE semantics documented in vec_c.h so every lane matches the scalar
 * kernel bit for bit. */
#ifndef BUMPGRAD_VEC_SSE2_H
#define BUMPGRAD_VEC_SSE2_H

#include <emmintrin.h>
#include <math.h>
#include <stdint.h>
#include <string.h>
#include <float.h>
#include "kernels.h"

#define BG_ISA_SUFFIX sse2
#define BG_ISA_ENUM BG_ISA_SSE2
#define BG_REAL_MAX FLT_MAX
#define LANES 4
typedef float bg_real;
typedef __m128 vf;
typedef __m128i vi;
typedef __m128 vm; /* all-ones / all-zeros lanes */

static inline vf vf_set1(float a) { return _mm_set1_ps(a); }
/* Partial tails go through a zeroed stack copy: never touch p[c..LANES). */
static inline vf vf_loadn(const float *p, size_t c)
{
    if (c == LANES)
        return _mm_loadu_ps(p);
    float t[LANES] = {0};
    memcpy(t, p, c * sizeof(float));
    return _mm_loadu_ps(t);
}
static inline void vf_storen(float *p, vf v, size_t c)
{
    if (c == LANES) {
        _mm_storeu_ps(p, v);
        return;
    }
    float t[LANES];
    _mm_storeu_ps(t, v);
    memcpy(p, t, c * sizeof(float));
}
static inline vf vf_add(vf a, vf b) { return _mm_add_ps(a, b); }
static inline vf vf_sub(vf a, vf b) { return _mm_sub_ps(a, b); }
static inline vf vf_mul(vf a, vf b) { return _mm_mul_ps(a, b); }
static inline vf vf_div(vf a, vf b) { return _mm_div_ps(a, b); }
static inline vf vf_sqrt(vf a) { return _mm_sqrt_ps(a); }
static inline vf vf_sign_mask(void) { return _mm_castsi128_ps(_mm_set1_epi32(INT32_MIN)); }
static inline vf vf_abs(vf a) { return _mm_andnot_ps(vf_sign_mask(), a); }
static inline vf vf_neg(vf a) { return _mm_xor_ps(a, vf_sign_mask()); }
/* maxps returns the second operand unless a > b: exactly (a > b ? a : b). */
static inline vf vf_max(vf a, vf b) { return _mm_max_ps(a, b); }
static inline vm vf_lt(vf a, vf b) { return _mm_cmplt_ps(a, b); }
static inline vm vf_le(vf a, vf b) { return _mm_cmple_ps(a, b); }
static inline vm vf_gt(vf a, vf b) { return _mm_cmpgt_ps(a, b); }
static inline vm vm_and(vm a, vm b) { return _mm_and_ps(a, b); }
static inline vm vm_or(vm a, vm b) { return _mm_or_ps(a, b); }
static inline vm vm_not(vm a) { return _mm_xor_ps(a, _mm_castsi128_ps(_mm_set1_epi32(-1))); }
static inline vf vf_sel(vm m, vf a, vf b) { return _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b)); }

/* IEEE floor without SSE4.1's roundps. Truncation through int32 is exact for
 * |a| < 2^23; from 2^23 up every float is an integer (and NaN must pass
 * through), so those lanes take a itself. A truncation above a is one too big.
 * The sign of a is OR-ed back so that floor(-0) = -0 as in floorf (truncation
 * gives +0; any other negative a already yields a negative result). */
static inline vf vf_floor(vf a)
{
    vf t = _mm_cvtepi32_ps(_mm_cvttps_epi32(a));
    t = _mm_sub_ps(t, _mm_and_ps(_mm_cmpgt_ps(t, a), _mm_set1_ps(1.0f)));
    t = _mm_or_ps(t, _mm_and_ps(a, vf_sign_mask()));
    vm small = _mm_cmplt_ps(vf_abs(a), _mm_set1_ps(8388608.0f)); /* false for NaN */
    return vf_sel(small, t, a);
}

static inline vi vi_set1(int32_t a) { return _mm_set1_epi32(a); }
static inline vi vi_from_vf(vf a) { return _mm_cvttps_epi32(a); }
static inline vi vi_add(vi a, vi b) { return _mm_add_epi32(a, b); }
static inline vi vi_and(vi a, vi b) { return _mm_and_si128(a, b); }
static inline vm vi_lt(vi a, vi b) { return _mm_castsi128_ps(_mm_cmplt_epi32(a, b)); }
static inline vm vi_eq(vi a, vi b) { return _mm_castsi128_ps(_mm_cmpeq_epi32(a, b)); }
static inline vm vi_test(vi a, vi bits)
{
    return vm_not(_mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(a, bits), _mm_setzero_si128())));
}
/* Every lane of m set. */
static inline int vm_all(vm m) { return _mm_movemask_ps(m) == 15; }
/* r + 1, or 0 where r = pm1 (bump_tmpl.c octave_cell_carry). */
static inline vi vi_wrap1(vi r, int32_t pm1)
{
    return _mm_andnot_si128(_mm_cmpeq_epi32(r, _mm_set1_epi32(pm1)), _mm_add_epi32(r, _mm_set1_epi32(1)));
}
/* bg_perm_pair[idx & 255]: SSE2 has no gather, so four scalar loads. */
static inline vi vi_perm2(vi idx)
{
    vi i = _mm_and_si128(idx, _mm_set1_epi32(255));
    return _mm_setr_epi32(bg_perm_pair[_mm_cvtsi128_si32(i)],
                          bg_perm_pair[_mm_cvtsi128_si32(_mm_shuffle_epi32(i, 0x55))],
                          bg_perm_pair[_mm_cvtsi128_si32(_mm_shuffle_epi32(i, 0xAA))],
                          bg_perm_pair[_mm_cvtsi128_si32(_mm_shuffle_epi32(i, 0xFF))]);
}
static inline vi vi_srl8(vi a) { return _mm_srli_epi32(a, 8); }

/* Corner gradients (bump_tmpl.c grad_corner): vf_sel_bit(h, b, a, c) is
 * (bit b of h set ? a : c); vf_flip_bit(a, h, b) flips the sign bit of a where
 * bit b of h is set (the reference's -u, an exact negation). vf_canon(a) is a
 * with every NaN replaced by the one canonical quiet NaN (+qNaN, 0x7fc00000),
 * applied to every kernel output so that NaN results are the same bits on
 * every ISA. */
static inline vf vf_sel_bit(vi h, int b, vf a, vf c)
{
    vm m = _mm_castsi128_ps(_mm_srai_epi32(_mm_slli_epi32(h, 31 - b), 31));
    return vf_sel(m, a, c);
}
static inline vf vf_flip_bit(vf a, vi h, int b)
{
    vi s = _mm_and_si128(_mm_slli_epi32(h, 31 - b), _mm_set1_epi32(INT32_MIN));
    return _mm_xor_ps(a, _mm_castsi128_ps(s));
}
static inline vf vf_canon(vf a) { return vf_sel(_mm_cmpunord_ps(a, a), _mm_set1_ps(NAN), a); }
/* tab[idx & 15]: no variable shuffle in SSE2, so four scalar loads. */
static inline vf vf_lut16(const float *tab, vi idx)
{
    vi i = _mm_and_si128(idx, _mm_set1_epi32(15));
    return _mm_setr_ps(tab[_mm_cvtsi128_si32(i)], tab[_mm_cvtsi128_si32(_mm_shuffle_epi32(i, 0x55))],
                       tab[_mm_cvtsi128_si32(_mm_shuffle_epi32(i, 0xAA))],
                       tab[_mm_cvtsi128_si32(_mm_shuffle_epi32(i, 0xFF))]);
}
/* floor value mod 256: cvttps2dq gives 0x80000000 (low byte 0) for NaN, Inf and
 * |fl| >= 2^31, where every float is a multiple of 256 anyway. */
static inline vi vi_cell256(vf fl) { return _mm_and_si128(_mm_cvttps_epi32(fl), _mm_set1_epi32(255)); }

#endif
