/* SPDX-License-Identifier: MIT */
/* Vector vocabulary, AVX2: eight float lanes. Same IEEE semantics as vec_c.h in
 * every lane. meson also passes -mfma for this level, but -ffp-contract=off keeps
 * the compiler from fusing a*b+c, and no FMA intrinsic is used: fusing would
 * change the rounding and so the bits against the scalar kernel. */
#ifndef BUMPGRAD_VEC_AVX2_H
#define BUMPGRAD_VEC_AVX2_H

#include <immintrin.h>
#include <stdint.h>
#include <string.h>
#include <float.h>
#include "kernels.h"

#define BG_ISA_SUFFIX avx2
#define BG_ISA_ENUM BG_ISA_AVX2
#define BG_REAL_MAX FLT_MAX
#define LANES 8
typedef float bg_real;
typedef __m256 vf;
typedef __m256i vi;
typedef __m256 vm; /* all-ones / all-zeros lanes */

static inline vf vf_set1(float a) { return _mm256_set1_ps(a); }
/* Partial tails go through a zeroed stack copy: never touch p[c..LANES). (A
 * vmaskmovps load would also not fault, but the copy is as fast for one tail per
 * call and has no AMD/Intel masked-store penalty to think about.) */
static inline vf vf_loadn(const float *p, size_t c)
{
    if (c == LANES)
        return _mm256_loadu_ps(p);
    float t[LANES] = {0};
    memcpy(t, p, c * sizeof(float));
    return _mm256_loadu_ps(t);
}
static inline void vf_storen(float *p, vf v, size_t c)
{
    if (c == LANES) {
        _mm256_storeu_ps(p, v);
        return;
    }
    float t[LANES];
    _mm256_storeu_ps(t, v);
    memcpy(p, t, c * sizeof(float));
}
static inline vf vf_add(vf a, vf b) { return _mm256_add_ps(a, b); }
static inline vf vf_sub(vf a, vf b) { return _mm256_sub_ps(a, b); }
static inline vf vf_mul(vf a, vf b) { return _mm256_mul_ps(a, b); }
static inline vf vf_div(vf a, vf b) { return _mm256_div_ps(a, b); }
static inline vf vf_sqrt(vf a) { return _mm256_sqrt_ps(a); }
/* roundps toward -inf is IEEE floor: keeps -0, passes NaN and |a| >= 2^23. */
static inline vf vf_floor(vf a) { return _mm256_round_ps(a, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC); }
static inline vf vf_sign_mask(void) { return _mm256_castsi256_ps(_mm256_set1_epi32(INT32_MIN)); }
static inline vf vf_abs(vf a) { return _mm256_andnot_ps(vf_sign_mask(), a); }
static inline vf vf_neg(vf a) { return _mm256_xor_ps(a, vf_sign_mask()); }
/* vmaxps returns the second operand unless a > b: exactly (a > b ? a : b). */
static inline vf vf_max(vf a, vf b) { return _mm256_max_ps(a, b); }
/* Ordered, quiet predicates: false on NaN like C's <, <=, >. */
static inline vm vf_lt(vf a, vf b) { return _mm256_cmp_ps(a, b, _CMP_LT_OQ); }
static inline vm vf_le(vf a, vf b) { return _mm256_cmp_ps(a, b, _CMP_LE_OQ); }
static inline vm vf_gt(vf a, vf b) { return _mm256_cmp_ps(a, b, _CMP_GT_OQ); }
static inline vm vm_and(vm a, vm b) { return _mm256_and_ps(a, b); }
static inline vm vm_or(vm a, vm b) { return _mm256_or_ps(a, b); }
static inline vm vm_not(vm a) { return _mm256_xor_ps(a, _mm256_castsi256_ps(_mm256_set1_epi32(-1))); }
static inline vf vf_sel(vm m, vf a, vf b) { return _mm256_blendv_ps(b, a, m); }

static inline vi vi_set1(int32_t a) { return _mm256_set1_epi32(a); }
static inline vi vi_from_vf(vf a) { return _mm256_cvttps_epi32(a); }
static inline vi vi_add(vi a, vi b) { return _mm256_add_epi32(a, b); }
static inline vi vi_and(vi a, vi b) { return _mm256_and_si256(a, b); }
static inline vm vi_lt(vi a, vi b) { return _mm256_castsi256_ps(_mm256_cmpgt_epi32(b, a)); }
static inline vm vi_eq(vi a, vi b) { return _mm256_castsi256_ps(_mm256_cmpeq_epi32(a, b)); }
static inline vm vi_test(vi a, vi bits)
{
    return vm_not(_mm256_castsi256_ps(
        _mm256_cmpeq_epi32(_mm256_and_si256(a, bits), _mm256_setzero_si256())));
}
/* bg_perm_pair[idx & 255]: vpgatherdd. -DBG_VEC_NO_GATHER builds the
 * scalar-load alternative measured against it in docs/KERNELS.md. */
static inline vi vi_perm2(vi idx)
{
    vi i = _mm256_and_si256(idx, _mm256_set1_epi32(255));
#ifdef BG_VEC_NO_GATHER
    int32_t k[8];
    _mm256_storeu_si256((__m256i *)(void *)k, i);
    return _mm256_setr_epi32(bg_perm_pair[k[0]], bg_perm_pair[k[1]], bg_perm_pair[k[2]],
                             bg_perm_pair[k[3]], bg_perm_pair[k[4]], bg_perm_pair[k[5]],
                             bg_perm_pair[k[6]], bg_perm_pair[k[7]]);
#else
    return _mm256_i32gather_epi32(bg_perm_pair, i, 4);
#endif
}
static inline vi vi_srl8(vi a) { return _mm256_srli_epi32(a, 8); }
/* tab[idx & 15]: vpermps uses index bits 0-2; bit 3 (moved to the sign)
 * picks the upper half. */
static inline vf vf_lut16(const float *tab, vi idx)
{
    vf lo = _mm256_permutevar8x32_ps(_mm256_loadu_ps(tab), idx);
    vf hi = _mm256_permutevar8x32_ps(_mm256_loadu_ps(tab + 8), idx);
    return _mm256_blendv_ps(lo, hi, _mm256_castsi256_ps(_mm256_slli_epi32(idx, 28)));
}
/* floor value mod 256: cvttps2dq gives 0x80000000 (low byte 0) for NaN, Inf and
 * |fl| >= 2^31, where every float is a multiple of 256 anyway. */
static inline vi vi_cell256(vf fl) { return _mm256_and_si256(_mm256_cvttps_epi32(fl), _mm256_set1_epi32(255)); }

#endif
