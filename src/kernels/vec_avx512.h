/* SPDX-License-Identifier: MIT */
/* Vector vocabulary, AVX-512 (F, BW, DQ, VL): sixteen float lanes, predicates in
 * opmask registers, masked loads/stores for the tails. Same IEEE semantics as
 * vec_c.h in every lane; -ffp-contract=off keeps -mfma from fusing. */
#ifndef BUMPGRAD_VEC_AVX512_H
#define BUMPGRAD_VEC_AVX512_H

#include <immintrin.h>
#include <math.h>
#include <stdint.h>
#include <float.h>
#include "kernels.h"

#ifdef BG_VEC_VBMI
#define BG_ISA_SUFFIX avx512vbmi
#else
#define BG_ISA_SUFFIX avx512
#endif
#define BG_ISA_ENUM BG_ISA_AVX512
#define BG_REAL_MAX FLT_MAX
#define LANES 16
typedef float bg_real;
typedef __m512 vf;
typedef __m512i vi;
typedef __mmask16 vm;

static inline vf vf_set1(float a) { return _mm512_set1_ps(a); }
/* Masked tails: masked-out elements are neither read nor written (no fault past
 * the end of the caller's arrays), the unused lanes are zero. */
static inline __mmask16 bg_tail_mask(size_t c) { return (__mmask16)((1u << c) - 1u); }
static inline vf vf_loadn(const float *p, size_t c)
{
    if (c == LANES)
        return _mm512_loadu_ps(p);
    return _mm512_maskz_loadu_ps(bg_tail_mask(c), p);
}
static inline void vf_storen(float *p, vf v, size_t c)
{
    if (c == LANES)
        _mm512_storeu_ps(p, v);
    else
        _mm512_mask_storeu_ps(p, bg_tail_mask(c), v);
}
static inline vf vf_add(vf a, vf b) { return _mm512_add_ps(a, b); }
static inline vf vf_sub(vf a, vf b) { return _mm512_sub_ps(a, b); }
static inline vf vf_mul(vf a, vf b) { return _mm512_mul_ps(a, b); }
static inline vf vf_div(vf a, vf b) { return _mm512_div_ps(a, b); }
/* c + a b for an exact product only (bump_tmpl.c vf_fma_exact): then the
 * fused rounding is the rounding of the sum. */
#define BG_HAVE_FMA_EXACT 1
static inline vf vf_fma_exact(vf a, vf b, vf c) { return _mm512_fmadd_ps(a, b, c); }
static inline vf vf_sqrt(vf a) { return _mm512_sqrt_ps(a); }
/* vrndscaleps with scale 0 toward -inf is IEEE floor (keeps -0, passes NaN). */
static inline vf vf_floor(vf a) { return _mm512_roundscale_ps(a, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC); }
static inline vf vf_abs(vf a) { return _mm512_castsi512_ps(_mm512_and_si512(_mm512_castps_si512(a), _mm512_set1_epi32(INT32_MAX))); }
static inline vf vf_neg(vf a) { return _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(a), _mm512_set1_epi32(INT32_MIN))); }
/* vmaxps returns the second operand unless a > b: exactly (a > b ? a : b). */
static inline vf vf_max(vf a, vf b) { return _mm512_max_ps(a, b); }
static inline vm vf_lt(vf a, vf b) { return _mm512_cmp_ps_mask(a, b, _CMP_LT_OQ); }
static inline vm vf_le(vf a, vf b) { return _mm512_cmp_ps_mask(a, b, _CMP_LE_OQ); }
static inline vm vf_gt(vf a, vf b) { return _mm512_cmp_ps_mask(a, b, _CMP_GT_OQ); }
static inline vm vm_and(vm a, vm b) { return (vm)(a & b); }
static inline vm vm_or(vm a, vm b) { return (vm)(a | b); }
static inline vm vm_not(vm a) { return (vm)~a; }
static inline vf vf_sel(vm m, vf a, vf b) { return _mm512_mask_blend_ps(m, b, a); }

static inline vi vi_set1(int32_t a) { return _mm512_set1_epi32(a); }
static inline vi vi_from_vf(vf a) { return _mm512_cvttps_epi32(a); }
static inline vi vi_add(vi a, vi b) { return _mm512_add_epi32(a, b); }
static inline vi vi_and(vi a, vi b) { return _mm512_and_si512(a, b); }
static inline vm vi_lt(vi a, vi b) { return _mm512_cmplt_epi32_mask(a, b); }
static inline vm vi_eq(vi a, vi b) { return _mm512_cmpeq_epi32_mask(a, b); }
static inline vm vi_test(vi a, vi bits) { return _mm512_test_epi32_mask(a, bits); }
/* Every lane of m set. */
static inline int vm_all(vm m) { return m == 0xffff; }
/* r + 1, or 0 where r = pm1 (bump_tmpl.c lattice_any_small, octave_cell_carry). */
static inline vi vi_wrap1(vi r, int32_t pm1)
{
    return _mm512_maskz_add_epi32(_mm512_cmpneq_epi32_mask(r, _mm512_set1_epi32(pm1)), r, _mm512_set1_epi32(1));
}

#ifdef BG_VEC_VBMI
/* Perlin's permutation applied to every byte: p256[b] for each of the 64 bytes,
 * the 256-byte table held in four zmm registers. vpermi2b indexes 128 table
 * bytes with the low 7 bits; bit 7 of each index byte picks the upper half. */
static inline __m512i bg_perm_bytes_of(const uint8_t *tab, __m512i idx)
{
    const __m512i *t = (const __m512i *)(const void *)tab;
    __m512i lo = _mm512_permutex2var_epi8(_mm512_loadu_si512(t), idx, _mm512_loadu_si512(t + 1));
    __m512i hi = _mm512_permutex2var_epi8(_mm512_loadu_si512(t + 2), idx, _mm512_loadu_si512(t + 3));
    return _mm512_mask_mov_epi8(lo, _mm512_movepi8_mask(idx), hi);
}
static inline __m512i bg_perm_bytes(__m512i idx) { return bg_perm_bytes_of(bg_perm256_u8, idx); }
/* The reference's 12-lookup hash chain in 3 byte lookups. Every index in the
 * chain is only ever used modulo 256 (p has period 256: the 512-entry table is
 * two copies), so the chain runs in bytes, where vpaddb wraps for free, with
 * up to four indices per dword lane sharing one vpermi2b pair:
 *   (X, X+1)          -> (A, B) = (p[X]+Y, p[X+1]+Y)
 *   (A, A+1, B, B+1)  -> (AA, AB, BA, BB) (+Z)
 *   (AA, AB, BA, BB)  -> the 8 corner hashes, by bg_perm_nib2: the corner code
 *                        reads only bits 0-3 of a hash, and bg_perm_nib2[i]
 *                        holds p[i] & 15 and p[i+1] & 15 (vec_avx2.h's chain).
 * The packed hashes are one register (bump_tmpl.c's vhash): corner k's hash
 * is bits 4j .. 4j+3 of each dword (j = bg_corner_nib[k]); the bits above are
 * other corners', which vf_lut16 (vpermps) ignores. */
#define BG_HAVE_HASHP 1
#define BG_PIPELINE_GRAD 1 /* bump_tmpl.c: 32 registers hold the carried hashes */
typedef __m512i vhash;
static inline vhash vi_hashp(vi X, vi Y, vi Z)
{
    /* vpshufb patterns, per 128-bit lane: byte 0 of each dword to all four bytes;
     * bytes (0,0,1,1) of each dword. */
    const __m512i b0 = _mm512_broadcast_i32x4(_mm_setr_epi8(0, 0, 0, 0, 4, 4, 4, 4, 8, 8, 8, 8, 12, 12, 12, 12));
    const __m512i b01 = _mm512_broadcast_i32x4(_mm_setr_epi8(0, 0, 1, 1, 4, 4, 5, 5, 8, 8, 9, 9, 12, 12, 13, 13));
    const __m512i plus0101 = _mm512_set1_epi32(0x01000100);
    __m512i yb = _mm512_shuffle_epi8(Y, b0), zb = _mm512_shuffle_epi8(Z, b0);
    __m512i ab = _mm512_add_epi8(bg_perm_bytes(_mm512_add_epi8(_mm512_shuffle_epi8(X, b0), plus0101)), yb);
    __m512i i2 = _mm512_add_epi8(_mm512_shuffle_epi8(ab, b01), plus0101);
    __m512i hz = _mm512_add_epi8(bg_perm_bytes(i2), zb); /* AA, AB, BA, BB */
    return bg_perm_bytes_of(bg_perm_nib2, hz);
}
/* Corner k (bit 0: x + 1, bit 1: y + 1, bit 2: z + 1): nibble 0 p[AA], 1 p[AA+1],
 * 2 p[AB], 3 p[AB+1], 4 p[BA], 5 p[BA+1], 6 p[BB], 7 p[BB+1]. */
static const int bg_corner_nib[8] = {0, 4, 2, 6, 1, 5, 3, 7};
static inline vi vh_corner(const vhash *l, int k) { return _mm512_srli_epi32(*l, (unsigned)(4 * bg_corner_nib[k])); }
/* The periodic chain (bump_tmpl.c octave_cell). Every step looks up
 * independent byte indices, so a wrapped corner costs nothing there: the x
 * step looks up (X, X, X1, X1), which gives (p[X], p[X], p[X1], p[X1]); adding
 * (Y, Y1, Y, Y1) gives the four indices of the second step (AA, AB, BA, BB
 * before + Z, in vi_hashp's order), *pa. Only the last step pairs two corners
 * in one lookup (bg_perm_nib2: p[i] and p[i + 1]), which holds off the z seam
 * (Z1 = Z + 1 modulo 256: every lane of an untiled z); the lanes on the seam
 * look their z + 1 corners up on their own (p[i] alone) and put those low
 * nibbles over the pair's high ones. zseam (bump_tmpl.c octave_cell): 0 no
 * lane is on the z seam, 1 few are (tested per vector), 2 many are (P_z <=
 * 64; P_z = 16: a lane of 16 on the seam in 64% of the vectors): the z + 1
 * lookup without the test, whose branch would mispredict. xb, yy: the byte
 * patterns above; zb: Z in every byte. */
static inline vhash bg_hashp_bytes(__m512i xb, __m512i yy, __m512i zb, __m512i *pa)
{
    *pa = bg_perm_bytes(_mm512_add_epi8(bg_perm_bytes(xb), yy));
    return bg_perm_bytes_of(bg_perm_nib2, _mm512_add_epi8(*pa, zb));
}
/* The pair's high nibbles replaced by hi's low ones in the lanes of k. */
static inline vhash bg_hashp_hi(vhash h, __m512i hi, __mmask16 k)
{
    return _mm512_mask_ternarylogic_epi32(h, k, _mm512_slli_epi16(hi, 4), _mm512_set1_epi8((char)0xf0), 0xd8);
}
/* From cells given wrapped (X1 = X + 1, or 0 at the seam; lattice_per): the
 * byte patterns by two-source byte permutes; the z + 1 corners p[pa + Z1]
 * where Z1 differs from Z + 1 modulo 256. */
static inline vhash vi_hashp_per(vi X, vi Y, vi Z, vi X1, vi Y1, vi Z1, int zseam)
{
    /* dword j: (X, X, X1, X1) and (Y, Y1, Y, Y1) from byte 4j of each source
     * (64 + 4j: the second). */
    const __m512i ixx = _mm512_set_epi32(
        0x7c7c3c3c, 0x78783838, 0x74743434, 0x70703030, 0x6c6c2c2c, 0x68682828, 0x64642424, 0x60602020,
        0x5c5c1c1c, 0x58581818, 0x54541414, 0x50501010, 0x4c4c0c0c, 0x48480808, 0x44440404, 0x40400000);
    const __m512i ixy = _mm512_set_epi32(
        0x7c3c7c3c, 0x78387838, 0x74347434, 0x70307030, 0x6c2c6c2c, 0x68286828, 0x64246424, 0x60206020,
        0x5c1c5c1c, 0x58185818, 0x54145414, 0x50105010, 0x4c0c4c0c, 0x48084808, 0x44044404, 0x40004000);
    const __m512i b0 = _mm512_broadcast_i32x4(_mm_setr_epi8(0, 0, 0, 0, 4, 4, 4, 4, 8, 8, 8, 8, 12, 12, 12, 12));
    __m512i zb = _mm512_shuffle_epi8(Z, b0), zb1 = _mm512_shuffle_epi8(Z1, b0), pa;
    vhash h = bg_hashp_bytes(_mm512_permutex2var_epi8(X, ixx, X1), _mm512_permutex2var_epi8(Y, ixy, Y1), zb, &pa);
    if (!zseam)
        return h;
    __mmask16 k = zseam == 2 ? (__mmask16)0xffff
                             : _mm512_cmpneq_epi32_mask(zb1, _mm512_add_epi8(zb, _mm512_set1_epi8(1)));
    if (zseam == 2 || k)
        h = bg_hashp_hi(h, bg_perm_bytes(_mm512_add_epi8(pa, zb1)), k);
    return h;
}
/* From unreduced cells and masks P - 1 (bump_tmpl.c vi_hashp_pow2): the byte
 * patterns by adding the corners' 0/1 and masking, bytewise. A lane on the z
 * seam (Z = P_z - 1) has Z1 = 0: its z + 1 corners are p[pa]. */
#define BG_HAVE_HASHP_POW2 1
static inline vhash vi_hashp_pow2(vi cx, vi cy, vi cz, vi mx, vi my, vi mz, int zseam)
{
    const __m512i b0 = _mm512_broadcast_i32x4(_mm_setr_epi8(0, 0, 0, 0, 4, 4, 4, 4, 8, 8, 8, 8, 12, 12, 12, 12));
    __m512i mxb = _mm512_shuffle_epi8(mx, b0), myb = _mm512_shuffle_epi8(my, b0), mzb = _mm512_shuffle_epi8(mz, b0);
    __m512i xb = _mm512_and_si512(_mm512_add_epi8(_mm512_shuffle_epi8(cx, b0), _mm512_set1_epi32(0x01010000)), mxb);
    __m512i yy = _mm512_and_si512(_mm512_add_epi8(_mm512_shuffle_epi8(cy, b0), _mm512_set1_epi32(0x01000100)), myb);
    __m512i zb = _mm512_and_si512(_mm512_shuffle_epi8(cz, b0), mzb), pa;
    vhash h = bg_hashp_bytes(xb, yy, zb, &pa);
    if (!zseam)
        return h;
    __mmask16 k = _mm512_cmpeq_epi32_mask(zb, mzb);
    if (zseam == 2 || k)
        h = bg_hashp_hi(h, bg_perm_bytes(pa), k);
    return h;
}
/* Every |fl| < 2^22 (bump_tmpl.c lattice_pow2; false for NaN): vrangeps
 * 0x0b is max(|a|, |b|) (NaN if either is). */
#define BG_HAVE_SMALL22 1
static inline int vf_small22(vf a, vf b, vf c)
{
    vf m = _mm512_range_ps(_mm512_range_ps(a, b, 0x0b), c, 0x0b);
    return _mm512_cmp_ps_mask(m, _mm512_set1_ps(4194304.0f), _CMP_LT_OQ) == 0xffff;
}
#else
#endif
/* bg_perm_pair[idx & 255]: vpgatherdd (the VBMI variant replaces the whole
 * chain with vi_hash8 above). */
static inline vi vi_perm2(vi idx)
{
    vi i = _mm512_and_si512(idx, _mm512_set1_epi32(255));
#ifdef BG_VEC_NO_GATHER
    int32_t k[16], r[16];
    _mm512_storeu_si512(k, i);
    for (int j = 0; j < 16; j++)
        r[j] = bg_perm_pair[k[j]];
    return _mm512_loadu_si512(r);
#else
    return _mm512_i32gather_epi32(i, bg_perm_pair, 4);
#endif
}
static inline vi vi_srl8(vi a) { return _mm512_srli_epi32(a, 8); }

/* Corner gradients (bump_tmpl.c grad_corner): vf_sel_bit(h, b, a, c) is
 * (bit b of h set ? a : c); vf_flip_bit(a, h, b) flips the sign bit of a where
 * bit b of h is set (the reference's -u, an exact negation). vf_canon(a) is a
 * with every NaN replaced by the one canonical quiet NaN (+qNaN, 0x7fc00000),
 * applied to every kernel output so that NaN results are the same bits on
 * every ISA. */
static inline vf vf_sel_bit(vi h, int b, vf a, vf c)
{
    return _mm512_mask_blend_ps(_mm512_test_epi32_mask(h, _mm512_set1_epi32(1 << b)), c, a);
}
static inline vf vf_flip_bit(vf a, vi h, int b)
{
    vi s = _mm512_and_si512(_mm512_slli_epi32(h, (unsigned)(31 - b)), _mm512_set1_epi32(INT32_MIN));
    return _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(a), s));
}
static inline vf vf_canon(vf a)
{
    return _mm512_mask_mov_ps(a, _mm512_cmp_ps_mask(a, a, _CMP_UNORD_Q), _mm512_set1_ps(NAN));
}
/* Whether a lane of a, b, c or d is NaN (unordered compares take two operands). */
#define BG_HAVE_ANY_NAN4 1
static inline int vf_any_nan4(vf a, vf b, vf c, vf d)
{
    return (_mm512_cmp_ps_mask(a, b, _CMP_UNORD_Q) | _mm512_cmp_ps_mask(c, d, _CMP_UNORD_Q)) != 0;
}

/* The corners by table (bump_tmpl.c BG_GRAD_BY_TABLE): three vpermps of
 * 16-entry tables, three products and two sums per corner, where the selects
 * and sign flips cost about 12 instructions; the gradient vector is the three
 * looked-up components themselves. */
#ifndef BG_AVX512_CORNER_SELECTS
#define BG_GRAD_BY_TABLE 1
#endif
/* tab[idx & 15]: vpermps ignores the index bits above 3. */
static inline vf vf_lut16(const float *tab, vi idx) { return _mm512_permutexvar_ps(idx, _mm512_loadu_ps(tab)); }
/* floor value mod 256: vcvttps2dq gives 0x80000000 (low byte 0) for NaN, Inf and
 * |fl| >= 2^31, where every float is a multiple of 256 anyway. */
static inline vi vi_cell256(vf fl) { return _mm512_and_si512(_mm512_cvttps_epi32(fl), _mm512_set1_epi32(255)); }

#endif
