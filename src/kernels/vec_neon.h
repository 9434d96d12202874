/* SPDX-License-Identifier: MIT */
/* Vector vocabulary, AArch64 Advanced SIMD (NEON): four float lanes. Same IEEE
 * semantics as vec_c.h in every lane. NEON's fmax propagates NaN (and orders
 * -0 < +0), unlike (a > b ? a : b), so vf_max is a compare and bit select. */
#ifndef BUMPGRAD_VEC_NEON_H
#define BUMPGRAD_VEC_NEON_H

#include <arm_neon.h>
#include <math.h>
#include <stdint.h>
#include <string.h>
#include <float.h>
#include "kernels.h"

#define BG_ISA_SUFFIX neon
#define BG_ISA_ENUM BG_ISA_NEON
#define BG_REAL_MAX FLT_MAX
#define LANES 4
typedef float bg_real;
typedef float32x4_t vf;
typedef int32x4_t vi;
typedef uint32x4_t vm;

static inline vf vf_set1(float a) { return vdupq_n_f32(a); }
/* Partial tails go through a zeroed stack copy: never touch p[c..LANES). */
static inline vf vf_loadn(const float *p, size_t c)
{
    if (c == LANES)
        return vld1q_f32(p);
    float t[LANES] = {0};
    memcpy(t, p, c * sizeof(float));
    return vld1q_f32(t);
}
static inline void vf_storen(float *p, vf v, size_t c)
{
    if (c == LANES) {
        vst1q_f32(p, v);
        return;
    }
    float t[LANES];
    vst1q_f32(t, v);
    memcpy(p, t, c * sizeof(float));
}
static inline vf vf_add(vf a, vf b) { return vaddq_f32(a, b); }
static inline vf vf_sub(vf a, vf b) { return vsubq_f32(a, b); }
static inline vf vf_mul(vf a, vf b) { return vmulq_f32(a, b); }
static inline vf vf_div(vf a, vf b) { return vdivq_f32(a, b); }
static inline vf vf_sqrt(vf a) { return vsqrtq_f32(a); }
/* frintm is IEEE floor (keeps -0, passes NaN). */
static inline vf vf_floor(vf a) { return vrndmq_f32(a); }
static inline vf vf_abs(vf a) { return vabsq_f32(a); }
static inline vf vf_neg(vf a) { return vnegq_f32(a); }
static inline vm vf_lt(vf a, vf b) { return vcltq_f32(a, b); }
static inline vm vf_le(vf a, vf b) { return vcleq_f32(a, b); }
static inline vm vf_gt(vf a, vf b) { return vcgtq_f32(a, b); }
static inline vf vf_max(vf a, vf b) { return vbslq_f32(vcgtq_f32(a, b), a, b); }
static inline vm vm_and(vm a, vm b) { return vandq_u32(a, b); }
static inline vm vm_or(vm a, vm b) { return vorrq_u32(a, b); }
static inline vm vm_not(vm a) { return vmvnq_u32(a); }
static inline vf vf_sel(vm m, vf a, vf b) { return vbslq_f32(m, a, b); }

static inline vi vi_set1(int32_t a) { return vdupq_n_s32(a); }
/* fcvtzs truncates toward zero like the C cast (saturating, but only in-range
 * values reach it). */
static inline vi vi_from_vf(vf a) { return vcvtq_s32_f32(a); }
static inline vi vi_add(vi a, vi b) { return vaddq_s32(a, b); }
static inline vi vi_and(vi a, vi b) { return vandq_s32(a, b); }
static inline vm vi_lt(vi a, vi b) { return vcltq_s32(a, b); }
static inline vm vi_eq(vi a, vi b) { return vceqq_s32(a, b); }
static inline vm vi_test(vi a, vi bits) { return vtstq_s32(a, bits); }
/* Every lane of m set. */
static inline int vm_all(vm m) { return vminvq_u32(m) != 0; }
/* r + 1, or 0 where r = pm1 (bump_tmpl.c octave_cell_carry). */
static inline vi vi_wrap1(vi r, int32_t pm1)
{
    return vbicq_s32(vaddq_s32(r, vdupq_n_s32(1)), vreinterpretq_s32_u32(vceqq_s32(r, vdupq_n_s32(pm1))));
}
/* bg_perm_pair[idx & 255]: no gather on NEON, four lane loads. */
static inline vi vi_perm2(vi idx)
{
    int32x4_t i = vandq_s32(idx, vdupq_n_s32(255));
    int32x4_t r = vdupq_n_s32(bg_perm_pair[vgetq_lane_s32(i, 0)]);
    r = vsetq_lane_s32(bg_perm_pair[vgetq_lane_s32(i, 1)], r, 1);
    r = vsetq_lane_s32(bg_perm_pair[vgetq_lane_s32(i, 2)], r, 2);
    return vsetq_lane_s32(bg_perm_pair[vgetq_lane_s32(i, 3)], r, 3);
}
static inline vi vi_srl8(vi a) { return vreinterpretq_s32_u32(vshrq_n_u32(vreinterpretq_u32_s32(a), 8)); }

/* Corner gradients (bump_tmpl.c grad_corner): vf_sel_bit(h, b, a, c) is
 * (bit b of h set ? a : c); vf_flip_bit(a, h, b) flips the sign bit of a where
 * bit b of h is set (the reference's -u, an exact negation). vf_canon(a) is a
 * with every NaN replaced by the one canonical quiet NaN (+qNaN, 0x7fc00000),
 * applied to every kernel output so that NaN results are the same bits on
 * every ISA. */
static inline vf vf_sel_bit(vi h, int b, vf a, vf c)
{
    return vbslq_f32(vtstq_s32(h, vdupq_n_s32(1 << b)), a, c);
}
static inline vf vf_flip_bit(vf a, vi h, int b)
{
    uint32x4_t s = vandq_u32(vshlq_u32(vreinterpretq_u32_s32(h), vdupq_n_s32(31 - b)),
                             vdupq_n_u32(0x80000000u));
    return vreinterpretq_f32_u32(veorq_u32(vreinterpretq_u32_f32(a), s));
}
static inline vf vf_canon(vf a) { return vbslq_f32(vceqq_f32(a, a), a, vdupq_n_f32(NAN)); }
/* tab[idx & 15]: one tbl over the 64 table bytes, byte index 4 (idx & 15) + k
 * for byte k of each lane (the index bytes never exceed 63). */
static inline vf vf_lut16(const float *tab, vi idx)
{
    uint8x16x4_t t = vld1q_u8_x4((const uint8_t *)tab);
    uint32x4_t i = vandq_u32(vreinterpretq_u32_s32(idx), vdupq_n_u32(15));
    uint32x4_t bi = vaddq_u32(vmulq_n_u32(i, 0x04040404u), vdupq_n_u32(0x03020100u));
    return vreinterpretq_f32_u8(vqtbl4q_u8(t, vreinterpretq_u8_u32(bi)));
}

/* Perlin's permutation applied to each of the 16 bytes: tbl over the first 64
 * table bytes, then tbx (which leaves out-of-range lanes alone) over the next
 * three 64-byte quarters with the index moved down by 64 each time. */
static inline uint8x16_t bg_perm_bytes(uint8x16_t idx)
{
    uint8x16_t r = vqtbl4q_u8(vld1q_u8_x4(bg_perm256_u8), idx);
    r = vqtbx4q_u8(r, vld1q_u8_x4(bg_perm256_u8 + 64), vsubq_u8(idx, vdupq_n_u8(64)));
    r = vqtbx4q_u8(r, vld1q_u8_x4(bg_perm256_u8 + 128), vsubq_u8(idx, vdupq_n_u8(128)));
    return vqtbx4q_u8(r, vld1q_u8_x4(bg_perm256_u8 + 192), vsubq_u8(idx, vdupq_n_u8(192)));
}

/* The hash chain in bytes, 4 indices per lane, as the AVX-512 VBMI variant
 * (vec_avx512.h explains the layout): every index is used modulo 256, so byte
 * arithmetic wraps exactly as the doubled table would. 4 table lookups of 7
 * instructions replace 7 x 4 lane loads. */
#define BG_HAVE_HASH8 1
static inline void vi_hash8(vi X, vi Y, vi Z, vi h[8])
{
    static const uint8_t s01[16] = {0, 0, 1, 1, 4, 4, 5, 5, 8, 8, 9, 9, 12, 12, 13, 13};
    static const uint8_t s23[16] = {2, 2, 3, 3, 6, 6, 7, 7, 10, 10, 11, 11, 14, 14, 15, 15};
    const uint8x16_t b01 = vld1q_u8(s01), b23 = vld1q_u8(s23);
    const uint8x16_t plus0101 = vreinterpretq_u8_u32(vdupq_n_u32(0x01000100u));
    /* X, Y, Z < 256: multiplying by 0x01010101 copies the low byte to all four. */
    uint8x16_t xb = vreinterpretq_u8_u32(vmulq_n_u32(vreinterpretq_u32_s32(X), 0x01010101u));
    uint8x16_t yb = vreinterpretq_u8_u32(vmulq_n_u32(vreinterpretq_u32_s32(Y), 0x01010101u));
    uint8x16_t zb = vreinterpretq_u8_u32(vmulq_n_u32(vreinterpretq_u32_s32(Z), 0x01010101u));
    uint8x16_t ab = vaddq_u8(bg_perm_bytes(vaddq_u8(xb, plus0101)), yb);
    uint8x16_t hz = vaddq_u8(bg_perm_bytes(vaddq_u8(vqtbl1q_u8(ab, b01), plus0101)), zb);
    uint32x4_t la = vreinterpretq_u32_u8(bg_perm_bytes(vaddq_u8(vqtbl1q_u8(hz, b01), plus0101)));
    uint32x4_t lb = vreinterpretq_u32_u8(bg_perm_bytes(vaddq_u8(vqtbl1q_u8(hz, b23), plus0101)));
    h[0] = vreinterpretq_s32_u32(la);                  /* p[AA]   */
    h[4] = vreinterpretq_s32_u32(vshrq_n_u32(la, 8));  /* p[AA+1] */
    h[2] = vreinterpretq_s32_u32(vshrq_n_u32(la, 16)); /* p[AB]   */
    h[6] = vreinterpretq_s32_u32(vshrq_n_u32(la, 24)); /* p[AB+1] */
    h[1] = vreinterpretq_s32_u32(lb);                  /* p[BA]   */
    h[5] = vreinterpretq_s32_u32(vshrq_n_u32(lb, 8));  /* p[BA+1] */
    h[3] = vreinterpretq_s32_u32(vshrq_n_u32(lb, 16)); /* p[BB]   */
    h[7] = vreinterpretq_s32_u32(vshrq_n_u32(lb, 24)); /* p[BB+1] */
}
/* floor value mod 256, 0 for NaN/Inf: fcvtzs saturates (2^31 -> 0x7fffffff,
 * low byte 255), so lanes with |fl| >= 2^31 (multiples of 256) and NaN (where
 * the compare is false) are set to 0 explicitly. */
static inline vi vi_cell256(vf fl)
{
    uint32x4_t small = vcaltq_f32(fl, vdupq_n_f32(2147483648.0f));
    int32x4_t c = vandq_s32(vcvtq_s32_f32(fl), vdupq_n_s32(255));
    return vreinterpretq_s32_u32(vandq_u32(vreinterpretq_u32_s32(c), small));
}

#endif
