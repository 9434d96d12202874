/* SPDX-License-Identifier: MIT */
/* Vector vocabulary, AVX2: eight float lanes. Same IEEE semantics as vec_c.h in
 * every lane. meson also passes -mfma for this level, but -ffp-contract=off keeps
 * the compiler from fusing a*b+c: fusing would change the rounding and so the
 * bits against the scalar kernel. The one FMA intrinsic, vf_fma_exact, is used
 * only where the product is exact, so its one rounding is the sum's. */
#ifndef BUMPGRAD_VEC_AVX2_H
#define BUMPGRAD_VEC_AVX2_H

#include <immintrin.h>
#include <math.h>
#include <stdint.h>
#include <string.h>
#include <float.h>
#include "kernels.h"

/* gcc declines to inline the hash chain (large): a call would spill every
 * live vector register around it (all are caller-saved). */
#define BG_VEC_INLINE static inline __attribute__((always_inline))

#define BG_ISA_SUFFIX avx2
#define BG_ISA_ENUM BG_ISA_AVX2
#define BG_REAL_MAX FLT_MAX
#define LANES 8
typedef float bg_real;
typedef __m256 vf;
typedef __m256i vi;
typedef __m256 vm; /* all-ones / all-zeros lanes */

static inline vf vf_set1(float a) { return _mm256_set1_ps(a); }
/* Partial tails by vmaskmovps: masked-off lanes are neither read nor written
 * (no fault past the end of an array), and loaded as +0. A call of a few
 * points then costs no stack copy and no memcpy call (issue 10 item 4). */
static inline __m256i bg_tail_mask(size_t c)
{
    return _mm256_cmpgt_epi32(_mm256_set1_epi32((int)c), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
}
static inline vf vf_loadn(const float *p, size_t c)
{
    if (c == LANES)
        return _mm256_loadu_ps(p);
#ifdef BG_TAIL_COPY
    float t[LANES] = {0};
    memcpy(t, p, c * sizeof(float));
    return _mm256_loadu_ps(t);
#else
    return _mm256_maskload_ps(p, bg_tail_mask(c));
#endif
}
static inline void vf_storen(float *p, vf v, size_t c)
{
    if (c == LANES) {
        _mm256_storeu_ps(p, v);
        return;
    }
#ifdef BG_TAIL_COPY
    float t[LANES];
    _mm256_storeu_ps(t, v);
    memcpy(p, t, c * sizeof(float));
#else
    _mm256_maskstore_ps(p, bg_tail_mask(c), v);
#endif
}
static inline vf vf_add(vf a, vf b) { return _mm256_add_ps(a, b); }
static inline vf vf_sub(vf a, vf b) { return _mm256_sub_ps(a, b); }
static inline vf vf_mul(vf a, vf b) { return _mm256_mul_ps(a, b); }
static inline vf vf_div(vf a, vf b) { return _mm256_div_ps(a, b); }
/* c + a b for an exact product only (bump_tmpl.c vf_fma_exact). */
#define BG_HAVE_FMA_EXACT 1
static inline vf vf_fma_exact(vf a, vf b, vf c) { return _mm256_fmadd_ps(a, b, c); }
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
/* Every lane of m set. */
static inline int vm_all(vm m) { return _mm256_movemask_ps(m) == 255; }
/* r + 1, or 0 where r = pm1 (bump_tmpl.c octave_cell_carry). */
static inline vi vi_wrap1(vi r, int32_t pm1)
{
    return _mm256_andnot_si256(_mm256_cmpeq_epi32(r, _mm256_set1_epi32(pm1)), _mm256_add_epi32(r, _mm256_set1_epi32(1)));
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

/* In-register hash chain (issue 10): Perlin's permutation applied to each of
 * 32 bytes with vpshufb. vpshufb looks up 16 bytes (per 128-bit lane) with the
 * low nibble; the 16 slices p[16k .. 16k+15] are each looked up and a blend
 * tree on index bits 4, 5, 6, 7 (vpblendvb reads bit 7 of each byte, so each
 * bit is shifted there; 16-bit shifts keep the bytes apart for that bit) picks
 * the slice: 16 vpshufb + 15 vpblendvb for 32 lookups, where the gather chain
 * pays 7 vpgatherdd (about 9.5 cycles each on Zen 3) for 8 points. */
/* -DBG_VEC_GATHER builds the 7-gather chain instead (the generic vi_hash8 of
 * bump_tmpl.c), -DBG_VEC_PSHUFB_FIRST the first step by bg_perm_bytes too:
 * the alternatives measured in docs/KERNELS.md. */
#ifndef BG_VEC_GATHER
/* vpblendvb (b where bit 7 of m's byte is set, else a). gcc 12 folds the
 * intrinsic into a select on m < 0 and, where one m feeds several blends,
 * materializes that compare as an extra vpcmpgtb per mask (6 per vector of
 * the chain): the instruction is written out for gcc. */
BG_VEC_INLINE __m256i bg_blendv8(__m256i a, __m256i b, __m256i m)
{
#if defined(__GNUC__) && !defined(__clang__) && !defined(BG_VEC_BLEND_INTRIN)
    __m256i r;
    __asm__("vpblendvb %3, %2, %1, %0" : "=x"(r) : "x"(a), "xm"(b), "x"(m));
    return r;
#else
    return _mm256_blendv_epi8(a, b, m);
#endif
}
/* Slices 2k and 2k + 1 of the table looked up and blended on index bit 4,
 * then the tree depth first (each pair blended as soon as it is formed), so
 * that no more than one partial result per level is live: all 16 lookups
 * first spilled 7 of them to the stack. */
BG_VEC_INLINE __m256i bg_perm_slice2(const __m128i *t, int k, __m256i lo, __m256i s4)
{
    __m256i a = _mm256_shuffle_epi8(_mm256_broadcastsi128_si256(_mm_loadu_si128(t + 2 * k)), lo);
    __m256i b = _mm256_shuffle_epi8(_mm256_broadcastsi128_si256(_mm_loadu_si128(t + 2 * k + 1)), lo);
    return bg_blendv8(a, b, s4);
}
/* The selectors of a byte lookup by vpshufb slices: the low nibble of each
 * index byte, and its bits 6, 5 and 4 moved to bit 7, where vpblendvb reads
 * them (bit 7 is idx itself). */
typedef struct bg_bytesel {
    __m256i lo, s6, s5, s4;
} bg_bytesel;
BG_VEC_INLINE bg_bytesel bg_bytesel_of(__m256i idx)
{
    bg_bytesel b;
    b.lo = _mm256_and_si256(idx, _mm256_set1_epi8(15));
    b.s6 = _mm256_add_epi8(idx, idx); /* bit 6 -> bit 7 */
    b.s5 = _mm256_add_epi8(b.s6, b.s6); /* bit 5 */
    b.s4 = _mm256_add_epi8(b.s5, b.s5); /* bit 4 */
    return b;
}
BG_VEC_INLINE __m256i bg_perm_bytes_of(const uint8_t *tab, __m256i idx)
{
    const __m128i *t = (const __m128i *)(const void *)tab;
    const bg_bytesel b = bg_bytesel_of(idx);
    __m256i q[2];
    for (int h = 0; h < 2; h++) {
        __m256i p0 = bg_blendv8(bg_perm_slice2(t, 4 * h, b.lo, b.s4),
                                bg_perm_slice2(t, 4 * h + 1, b.lo, b.s4), b.s5);
        __m256i p1 = bg_blendv8(bg_perm_slice2(t, 4 * h + 2, b.lo, b.s4),
                                bg_perm_slice2(t, 4 * h + 3, b.lo, b.s4), b.s5);
        q[h] = bg_blendv8(p0, p1, b.s6);
    }
    return bg_blendv8(q[0], q[1], idx); /* bit 7 */
}
static inline __m256i bg_perm_bytes(__m256i idx) { return bg_perm_bytes_of(bg_perm256_u8, idx); }
/* bg_corner_code(p[i]) << 4 for every byte i of idx (low nibbles 0), from the
 * 8 slices of bg_perm_code_hi (two codes per byte): 8 vpshufb and 8
 * vpblendvb where a 16-slice lookup takes 16 and 15. Slice i >> 5 is picked
 * by bits 5, 6, 7, then the nibble by bit 4. */
BG_VEC_INLINE __m256i bg_perm_code_hi_of(const uint8_t *tab, __m256i idx)
{
    const __m128i *t = (const __m128i *)(const void *)tab;
    const bg_bytesel b = bg_bytesel_of(idx);
    __m256i q[2];
    for (int h = 0; h < 2; h++) {
        __m256i a[4];
        for (int k = 0; k < 4; k++)
            a[k] = _mm256_shuffle_epi8(_mm256_broadcastsi128_si256(_mm_loadu_si128(t + 4 * h + k)), b.lo);
        q[h] = bg_blendv8(bg_blendv8(a[0], a[1], b.s5), bg_blendv8(a[2], a[3], b.s5), b.s6);
    }
    __m256i r = bg_blendv8(q[0], q[1], idx); /* bit 7 */
    /* bit 4 set: the code is the low nibble, moved up (16-bit shift: the bits
     * it carries into the next byte are below that byte's high nibble). */
    r = bg_blendv8(r, _mm256_slli_epi16(r, 4), b.s4);
    return _mm256_and_si256(r, _mm256_set1_epi8((char)0xf0));
}

/* The byte-lane chain of the AVX-512 VBMI variant (vec_avx512.h explains the
 * layout): four indices per dword, every index modulo 256 (vpaddb wraps as the
 * doubled table would). bg_hash_hz gives AA, AB, BA, BB as the bytes of each
 * point's dword. */
BG_VEC_INLINE __m256i bg_hash_hz(vi X, vi Y, vi Z)
{
    const __m256i b0 = _mm256_broadcastsi128_si256(_mm_setr_epi8(0, 0, 0, 0, 4, 4, 4, 4, 8, 8, 8, 8, 12, 12, 12, 12));
    const __m256i b01 = _mm256_broadcastsi128_si256(_mm_setr_epi8(0, 0, 1, 1, 4, 4, 5, 5, 8, 8, 9, 9, 12, 12, 13, 13));
    const __m256i plus0101 = _mm256_set1_epi32(0x01000100);
    __m256i yb = _mm256_shuffle_epi8(Y, b0), zb = _mm256_shuffle_epi8(Z, b0);
#ifndef BG_VEC_PSHUFB_FIRST
    /* First step by one vpgatherdd of the pair table, (p[X], p[X+1]) + Y: it
     * needs 8 lookups, where bg_perm_bytes would do 32 (docs/KERNELS.md has
     * the measurements of both). */
    __m256i q = _mm256_i32gather_epi32(bg_perm_pair, X, 4);
    __m256i ab = _mm256_add_epi8(_mm256_shuffle_epi8(q, _mm256_broadcastsi128_si256(_mm_setr_epi8(0, 1, 0, 1, 4, 5, 4, 5, 8, 9, 8, 9, 12, 13, 12, 13))), yb);
#else
    __m256i ab = _mm256_add_epi8(bg_perm_bytes(_mm256_add_epi8(_mm256_shuffle_epi8(X, b0), plus0101)), yb);
#endif
#ifdef BG_VEC_GATHER2
    /* The second step by two more gathers of the pair table: 31 instead of 38
     * instructions per sample, and slower (docs/PERFORMANCE.md). */
    (void)ab, (void)b01, (void)plus0101;
    __m256i m8 = _mm256_set1_epi32(255);
    __m256i A = _mm256_and_si256(_mm256_add_epi32(q, Y), m8);
    __m256i B = _mm256_and_si256(_mm256_add_epi32(_mm256_srli_epi32(q, 8), Y), m8);
    __m256i qa = _mm256_i32gather_epi32(bg_perm_pair, A, 4), qb = _mm256_i32gather_epi32(bg_perm_pair, B, 4);
    __m256i pq = _mm256_or_si256(_mm256_and_si256(qa, _mm256_set1_epi32(0xffff)), _mm256_slli_epi32(qb, 16));
    return _mm256_add_epi8(pq, zb);
#else
    __m256i i2 = _mm256_add_epi8(_mm256_shuffle_epi8(ab, b01), plus0101);
    return _mm256_add_epi8(bg_perm_bytes(i2), zb); /* AA, AB, BA, BB */
#endif
}

/* The last step needs only the low 4 bits of each corner hash, and those
 * only as the corner's two axes and two signs: one lookup of bg_perm_code2
 * per index gives the corner codes (kernels.h bg_corner_code) of p[i] and
 * p[i + 1], so the 8 corners of 8 points are one bg_perm_bytes call, and each
 * corner decodes with two single-bit selects (bump_tmpl.c
 * BG_HAVE_CODED_HASH), where the reference's h < 4 and h == 12 || h == 14
 * took a third select and two masks. The packed hashes are one register
 * (bump_tmpl.c's vhash): corner k's code is bits 4j .. 4j+3 of each dword,
 * bits above are other corners' (the corner code reads bits 0-3 only). */
#define BG_HAVE_HASHP 1
#define BG_HAVE_CODED_HASH 1
typedef __m256i vhash;
BG_VEC_INLINE vhash vi_hashp(vi X, vi Y, vi Z) { return bg_perm_bytes_of(bg_perm_code2, bg_hash_hz(X, Y, Z)); }
/* Corner k (bit 0: x + 1, bit 1: y + 1, bit 2: z + 1): nibble 0 p[AA], 1 p[AA+1],
 * 2 p[AB], 3 p[AB+1], 4 p[BA], 5 p[BA+1], 6 p[BB], 7 p[BB+1]. */
static const int bg_corner_nib[8] = {0, 4, 2, 6, 1, 5, 3, 7};
static inline vi vh_corner(const vhash *l, int k) { return _mm256_srli_epi32(*l, 4 * bg_corner_nib[k]); }
/* The periodic chain (bump_tmpl.c octave_cell; vec_avx512.h explains the
 * byte patterns): the x step by the pair gather, (p[X], p[X+1]) spread to
 * (p[X], p[X], p[X+1], p[X+1]), whose p[X+1] is p[X1] except where X1 = 0
 * (there p[0] is put in); the second step adds (Y, Y1, Y, Y1); the last gives
 * the z corners' codes (and the z + 1 corners' off the seam) by bg_perm_code2
 * and, where a lane is on the z seam, the z + 1 corners' codes again by a
 * lookup of bg_perm_code_hi (8 slices: about 30 instructions, where the
 * 16-slice lookup of bg_perm_code2 it replaced took about 50 with its
 * packing), packed as vi_hashp does. zseam as in vec_avx512.h, but the
 * separate lookup is always behind the test: with 8 lanes it is needed less
 * often. x0: the lanes where X1 = 0 (all ones); zb, zb1: Z and Z1 in every
 * byte; seam: some lane on the seam. */
BG_VEC_INLINE vhash bg_hashp_bytes(vi Xc, vi x0, __m256i yy, __m256i zb, __m256i zb1, int zseam,
                                   int seam)
{
    const __m256i p0011 = _mm256_broadcastsi128_si256(_mm_setr_epi8(0, 0, 1, 1, 4, 4, 5, 5, 8, 8, 9, 9, 12, 12, 13, 13));
    __m256i q = _mm256_shuffle_epi8(_mm256_i32gather_epi32(bg_perm_pair, Xc, 4), p0011);
    q = _mm256_blendv_epi8(q, _mm256_set1_epi32((int)((uint32_t)bg_perm256_u8[0] * 0x01010000u)),
                           _mm256_and_si256(x0, _mm256_set1_epi32((int)0xffff0000u)));
    __m256i pa = bg_perm_bytes(_mm256_add_epi8(q, yy));
    __m256i h = bg_perm_bytes_of(bg_perm_code2, _mm256_add_epi8(pa, zb));
    if (zseam && seam) {
        const __m256i lo4 = _mm256_set1_epi8(15);
        h = _mm256_or_si256(_mm256_and_si256(h, lo4),
                            bg_perm_code_hi_of(bg_perm_code_hi, _mm256_add_epi8(pa, zb1)));
    }
    return h;
}
/* From cells given wrapped (X1 = X + 1, or 0 at the seam; lattice_per). X
 * (the gather's index) and Y (bytes 0 and 1 of Y | Y1 << 8) must lie in
 * [0, 255]; of Z, X1, Y1 and Z1 only the low byte counts (X1 = 256, X = 255:
 * bg_perm_pair[255] has p[0] already). BG_HASHP_PER_XY255: callers with
 * cells beyond 255 (bump_tmpl.c octave_cell_carry) mask X and Y. */
#define BG_HASHP_PER_XY255 1
BG_VEC_INLINE vhash vi_hashp_per(vi X, vi Y, vi Z, vi X1, vi Y1, vi Z1, int zseam)
{
    const __m256i b0 = _mm256_broadcastsi128_si256(_mm_setr_epi8(0, 0, 0, 0, 4, 4, 4, 4, 8, 8, 8, 8, 12, 12, 12, 12));
    const __m256i p0101 = _mm256_broadcastsi128_si256(_mm_setr_epi8(0, 1, 0, 1, 4, 5, 4, 5, 8, 9, 8, 9, 12, 13, 12, 13));
    __m256i yy = _mm256_shuffle_epi8(_mm256_or_si256(Y, _mm256_slli_epi32(Y1, 8)), p0101);
    __m256i zb = _mm256_shuffle_epi8(Z, b0), zb1 = _mm256_shuffle_epi8(Z1, b0);
    int seam = zseam && _mm256_movemask_epi8(_mm256_cmpeq_epi8(zb1, _mm256_add_epi8(zb, _mm256_set1_epi8(1)))) != -1;
    return bg_hashp_bytes(X, _mm256_cmpeq_epi32(X1, _mm256_setzero_si256()), yy, zb, zb1, zseam, seam);
}
/* From unreduced cells and masks P - 1 (bump_tmpl.c vi_hashp_pow2). */
#define BG_HAVE_HASHP_POW2 1
BG_VEC_INLINE vhash vi_hashp_pow2(vi cx, vi cy, vi cz, vi mx, vi my, vi mz, int zseam)
{
    const __m256i b0 = _mm256_broadcastsi128_si256(_mm_setr_epi8(0, 0, 0, 0, 4, 4, 4, 4, 8, 8, 8, 8, 12, 12, 12, 12));
    __m256i myb = _mm256_shuffle_epi8(my, b0), mzb = _mm256_shuffle_epi8(mz, b0);
    __m256i X = _mm256_and_si256(cx, mx);
    __m256i yy = _mm256_and_si256(_mm256_add_epi8(_mm256_shuffle_epi8(cy, b0), _mm256_set1_epi32(0x01000100)), myb);
    __m256i zr = _mm256_shuffle_epi8(cz, b0);
    __m256i zb = _mm256_and_si256(zr, mzb);
    __m256i zb1 = _mm256_and_si256(_mm256_add_epi8(zr, _mm256_set1_epi8(1)), mzb);
    int seam = zseam && _mm256_movemask_epi8(_mm256_cmpeq_epi8(zb, mzb)) != 0;
    return bg_hashp_bytes(X, _mm256_cmpeq_epi32(X, mx), yy, zb, zb1, zseam, seam);
}
/* Every cell in [-2^22, 2^22) (bump_tmpl.c lattice_pow2). */
static inline int vi_small22(vi cx, vi cy, vi cz)
{
    const __m256i k = _mm256_set1_epi32(1 << 22);
    __m256i t = _mm256_or_si256(_mm256_or_si256(_mm256_add_epi32(cx, k), _mm256_add_epi32(cy, k)), _mm256_add_epi32(cz, k));
    return _mm256_testz_si256(t, _mm256_set1_epi32((int)0xff800000u));
}
#endif

/* Corner gradients (bump_tmpl.c grad_corner): vf_sel_bit(h, b, a, c) is
 * (bit b of h set ? a : c); vf_flip_bit(a, h, b) flips the sign bit of a where
 * bit b of h is set (the reference's -u, an exact negation). vf_canon(a) is a
 * with every NaN replaced by the one canonical quiet NaN (+qNaN, 0x7fc00000),
 * applied to every kernel output so that NaN results are the same bits on
 * every ISA. */
/* vblendvps reads only the sign bit of the selector: bit b shifted there. */
static inline vf vf_sel_bit(vi h, int b, vf a, vf c)
{
    return _mm256_blendv_ps(c, a, _mm256_castsi256_ps(_mm256_slli_epi32(h, 31 - b)));
}
/* The flip as a product with +-1 from an 8-entry vpermps table indexed by
 * hash bits 0-2 (2 instructions where shift, mask and xor are 3): a * -1 is
 * the exact negation, zeros and infinities included, and NaN stays NaN (every
 * output is canonicalized). */
/* vf_flip_sign(h, b): the +-1 factor itself (bump_tmpl.c folds a product
 * with it into a vf_fma_exact). */
#define BG_HAVE_FLIP_SIGN 1
static inline vf vf_flip_sign(vi h, int b)
{
    static const float sgn[2][8] = {{1, -1, 1, -1, 1, -1, 1, -1}, {1, 1, -1, -1, 1, 1, -1, -1}};
    return _mm256_permutevar8x32_ps(_mm256_loadu_ps(sgn[b]), h);
}
static inline vf vf_flip_bit(vf a, vi h, int b) { return _mm256_mul_ps(a, vf_flip_sign(h, b)); }
static inline vf vf_canon(vf a)
{
    return _mm256_blendv_ps(a, _mm256_set1_ps(NAN), _mm256_cmp_ps(a, a, _CMP_UNORD_Q));
}
/* Whether a lane of a, b, c or d is NaN (unordered compares take two operands). */
#define BG_HAVE_ANY_NAN4 1
static inline int vf_any_nan4(vf a, vf b, vf c, vf d)
{
    return _mm256_movemask_ps(_mm256_or_ps(_mm256_cmp_ps(a, b, _CMP_UNORD_Q),
                                           _mm256_cmp_ps(c, d, _CMP_UNORD_Q))) != 0;
}
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
