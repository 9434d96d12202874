/* SPDX-License-Identifier: MIT */
/* The one source of every bumpgrad kernel: Perlin's improved noise with its
 * analytic gradient, fBm/turbulence, central differences, the surface-gradient
 * perturbation and the fused height -> normal path. It is compiled once per ISA
 * against the vocabulary chosen in vec.h; the scalar kernel (_c) and the double
 * kernel (_c64) are this same file with one lane. Nothing here may depend on the
 * lane count except the loop stride, so every ISA gives the same bits. */
#include "vec.h"

/* gcc declines to inline noise_vec (large) into the batch loops and then passes
 * whole vectors through memory on every call: force it. */
#if defined(__GNUC__) || defined(__clang__)
#define BG_INLINE static inline __attribute__((always_inline))
#else
#define BG_INLINE static inline
#endif

/* ---- Perlin's improved noise (2002 reference) ------------------------------ */

/* fade(t) = 6t^5 - 15t^4 + 10t^3, evaluated in the reference's order. */
BG_INLINE vf fade(vf t)
{
    vf inner = vf_add(vf_mul(t, vf_sub(vf_mul(t, vf_set1(6)), vf_set1(15))), vf_set1(10));
    return vf_mul(vf_mul(vf_mul(t, t), t), inner);
}

/* fade'(t) = 30 t^2 (t - 1)^2, written as 30t^2 (t(t - 2) + 1). */
BG_INLINE vf dfade(vf t)
{
    vf q = vf_add(vf_mul(t, vf_sub(t, vf_set1(2))), vf_set1(1));
    return vf_mul(vf_mul(vf_set1(30), vf_mul(t, t)), q);
}

#if !defined(BG_HAVE_HASH8) && !defined(BG_HAVE_HASHP)
/* The reference's hash chain A = p[X]+Y, AA = p[A]+Z, ... and the 8 corner
 * hashes p[AA], p[AA+1], ... Every index is used modulo 256 (the 512-entry table
 * is two copies), and the chain always needs p[i] together with p[i+1]: one
 * bg_perm_pair lookup gives both, so 7 lookups replace Perlin's 12 (a gather is
 * the expensive step on every ISA). h[k] is the hash of corner k (bit 0: x + 1,
 * bit 1: y + 1, bit 2: z + 1) in its low 8 bits; higher bits are the other
 * corner's (vf_lut16 uses only the low 4). A vocabulary may provide its own
 * vi_hash8 with the same low 4 bits per corner. */
BG_INLINE void vi_hash8(vi X, vi Y, vi Z, vi h[8])
{
    vi m = vi_set1(255);
    vi q = vi_perm2(X);
    vi A = vi_add(vi_and(q, m), Y), B = vi_add(vi_srl8(q), Y);
    vi qa = vi_perm2(A), qb = vi_perm2(B);
    vi AA = vi_add(vi_and(qa, m), Z), AB = vi_add(vi_srl8(qa), Z);
    vi BA = vi_add(vi_and(qb, m), Z), BB = vi_add(vi_srl8(qb), Z);
    vi q00 = vi_perm2(AA), q01 = vi_perm2(AB), q10 = vi_perm2(BA), q11 = vi_perm2(BB);
    h[0] = q00, h[4] = vi_srl8(q00); /* p[AA], p[AA+1] */
    h[2] = q01, h[6] = vi_srl8(q01); /* p[AB], p[AB+1] */
    h[1] = q10, h[5] = vi_srl8(q10); /* p[BA], p[BA+1] */
    h[3] = q11, h[7] = vi_srl8(q11); /* p[BB], p[BB+1] */
}
#endif

#ifndef BG_HAVE_HASHP
/* The hashes of a cell's 8 corners, as the corner code reads them: vh_corner(s,
 * k) has corner k's hash in its low 4 bits. A vocabulary may keep them packed
 * in fewer registers (vec_avx2.h: one), which lets the batch loops carry them
 * from one step to the next (noise_cell). */
typedef struct vhash {
    vi h[8];
} vhash;
BG_INLINE vhash vi_hashp(vi X, vi Y, vi Z)
{
    vhash s;
    vi_hash8(X, Y, Z, s.h);
    return s;
}
BG_INLINE vi vh_corner(const vhash *s, int k) { return s->h[k]; }
#endif
#ifndef BG_HAVE_HASHP
/* The periodic chain (noise.h bg_domain): the lattice has already wrapped, so
 * each corner's coordinate is given (X1 is X + 1, or 0 at the seam) and the
 * reference's chain p[p[p[X] + Y] + Z] runs on it, one lookup per index: the
 * pair trick of vi_hash8 needs X1 = X + 1. 14 lookups instead of 7. With
 * every period 256 (X1 = X + 1 mod 256) these are the reference's hashes. The
 * byte-lane vocabularies (vec_avx2.h, vec_avx512.h VBMI) give the same hashes
 * with their own vi_hashp_per, which use zseam (octave_cell); this one
 * needs no hint. */
BG_INLINE vi vi_perm1(vi i) { return vi_and(vi_perm2(i), vi_set1(255)); }
BG_INLINE vhash vi_hashp_per(vi X, vi Y, vi Z, vi X1, vi Y1, vi Z1, int zseam)
{
    (void)zseam;
    vhash s;
    vi px[2] = {vi_perm1(X), vi_perm1(X1)}, ys[2] = {Y, Y1};
    for (int k = 0; k < 4; k++) {
        vi pxy = vi_perm1(vi_add(px[k & 1], ys[k >> 1]));
        s.h[k] = vi_perm1(vi_add(pxy, Z));
        s.h[k + 4] = vi_perm1(vi_add(pxy, Z1));
    }
    return s;
}
#endif
#if defined(BG_HAVE_HASHP) && !defined(BG_NO_PIPELINE)
#define BG_PIPELINE 1
#endif

/* One corner: the value grad(hash, dx, dy, dz) of the reference and, for the
 * analytic gradient, the corner's gradient vector. The reference (Perlin 2002):
 *     u = h<8 ? x : y;  v = h<4 ? y : (h==12||h==14 ? x : z);
 *     return ((h&1) == 0 ? u : -u) + ((h&2) == 0 ? v : -v);
 * computed here with the same selects and the same single addition, the
 * negations as sign-bit flips from hash bits 0 and 1, so the value is the
 * reference's bit for bit, sign of zero included (at a lattice point of corner
 * hash 11, -y - z = (-0) + (-0) = -0). The two picked axes always differ, so the
 * gradient vector has two components +-1 (the signs of u and v) and one +0. */
typedef struct corner {
    vf v, gx, gy, gz;
} corner;

/* c + a b where the product a b is exact (a factor +-1, +-2 or +-0 against a
 * finite or NaN one): one rounding either way, so a fused multiply-add gives
 * the bits of the separate product and sum, zeros' signs included (an exact
 * zero sum takes addition's sign rule in both). Vocabularies with FMA map it
 * to one instruction (vec_avx2.h, vec_avx512.h), which also moves the sum from
 * the adder ports to the multiplier ports; elsewhere it is the sum itself. */
#ifndef BG_HAVE_FMA_EXACT
BG_INLINE vf vf_fma_exact(vf a, vf b, vf c) { return vf_add(c, vf_mul(a, b)); }
#endif

#ifdef BG_GRAD_BY_TABLE
/* One lane: table lookups by h & 15 beat the branches a scalar compiler makes
 * of the selects. The gradient vector is tabulated from the selects (+-1 and
 * +0). The value is the dot product gx dx + gy dy + gz dz with the unused
 * component's zero signed so that its product is -0: -0 + a == a for every a,
 * zeros included, so the sum is (+-u) + (+-v) exactly, the reference's bits.
 * The fraction d is >= +0 on the corner's low side (x - floor(x), never -0) and
 * < 0 on its high side (x - floor(x) - 1), so the zero is -0 (-0 * d = -0) for
 * a low-side offset and +0 (+0 * d = -0) for a high-side one: `hi` picks. */
static const bg_real grad_tab_x[16] = {1, -1, 1, -1, 1, -1, 1, -1, 0, 0, 0, 0, 1, 0, -1, 0};
static const bg_real grad_tab_y[16] = {1, 1, -1, -1, 0, 0, 0, 0, 1, -1, 1, -1, 1, -1, 1, -1};
static const bg_real grad_tab_z[16] = {0, 0, 0, 0, 1, 1, -1, -1, 1, 1, -1, -1, 0, 1, 0, -1};
#define NZ (-(bg_real)0)
static const bg_real grad_lo_x[16] = {1, -1, 1, -1, 1, -1, 1, -1, NZ, NZ, NZ, NZ, 1, NZ, -1, NZ};
static const bg_real grad_lo_y[16] = {1, 1, -1, -1, NZ, NZ, NZ, NZ, 1, -1, 1, -1, 1, -1, 1, -1};
static const bg_real grad_lo_z[16] = {NZ, NZ, NZ, NZ, 1, 1, -1, -1, 1, 1, -1, -1, NZ, 1, NZ, -1};
#undef NZ

/* Corner ck's value and, when `want_grad` (a constant after inlining), its
 * gradient vector: the value's own components, whose unused one is -0 on the
 * corner's low side where the reference's gradient has +0. Only the signs of
 * zeros differ, which + - * never turn into a different nonzero value or NaN;
 * the reference's gradient outputs are never -0 (grad_zero_signs), so noise_at
 * adds +0 to its three outputs instead of looking up +0 tables (12 vpermps per
 * vector fewer at AVX-512, 3 additions more). */
BG_INLINE corner grad_corner_g(const vhash *hs, int ck, vf dx, vf dy, vf dz, int want_grad)
{
    corner c;
    vi hash = vh_corner(hs, ck);
    vf gx = vf_lut16(ck & 1 ? grad_tab_x : grad_lo_x, hash);
    vf gy = vf_lut16(ck & 2 ? grad_tab_y : grad_lo_y, hash);
    vf gz = vf_lut16(ck & 4 ? grad_tab_z : grad_lo_z, hash);
    /* (gx dx + gy dy) + gz dz: every product exact (g is +-1 or +-0). */
    c.v = vf_fma_exact(gz, dz, vf_fma_exact(gy, dy, vf_mul(gx, dx)));
    c.gx = c.gy = c.gz = vf_set1(0);
    if (want_grad)
        c.gx = gx, c.gy = gy, c.gz = gz;
    return c;
}
/* The reference's gradient (corner components +-1 and +0) is never -0: a
 * first-level lerp a + t (b - a) is a sum with a in {+-1, +0}, and every later
 * step is a sum whose first operand is an earlier result (exact zero sums of
 * two nonzero operands are +0 under round-to-nearest). From the -0 table
 * entries the same sums give the same values with possibly -0 for +0, which
 * x + (+0) turns back into +0 (and leaves every other x, NaN included, as it
 * is): the reference's bits. */
#define BG_GRAD_ZERO_SIGNS 1
BG_INLINE vf grad_zero_sign(vf g) { return vf_add(g, vf_set1(0)); }
#elif defined(BG_HAVE_CODED_HASH)
/* The vocabulary's hashes are corner codes (kernels.h bg_corner_code): the
 * first axis by bit 3 (y, else x), the second by bit 2 (z, else y), their
 * signs by bits 0 and 1. The same value as the reference's selects, bit for
 * bit (commutative addition for h = 12 and 14), and the same gradient vector:
 * +-1 on the two axes, +0 on the third. */
BG_INLINE corner grad_corner_g(const vhash *hs, int ck, vf dx, vf dy, vf dz, int want_grad)
{
    corner c;
    vi hash = vh_corner(hs, ck);
    vf first = vf_sel_bit(hash, 3, dy, dx), second = vf_sel_bit(hash, 2, dz, dy);
#ifdef BG_HAVE_FLIP_SIGN
    /* The flip is a product with +-1 (exact): the second one fused into the sum. */
    vf sf = vf_flip_sign(hash, 0), ss = vf_flip_sign(hash, 1);
    c.v = vf_fma_exact(second, ss, vf_mul(first, sf));
#else
    vf sf = vf_flip_bit(vf_set1(1), hash, 0), ss = vf_flip_bit(vf_set1(1), hash, 1);
    c.v = vf_add(vf_flip_bit(first, hash, 0), vf_flip_bit(second, hash, 1));
#endif
    vf zero = vf_set1(0);
    c.gx = c.gy = c.gz = zero;
    if (!want_grad)
        return c;
    c.gx = vf_sel_bit(hash, 3, zero, sf);
    c.gy = vf_sel_bit(hash, 3, sf, vf_sel_bit(hash, 2, zero, ss));
    c.gz = vf_sel_bit(hash, 2, ss, zero);
    return c;
}
#else
/* The corner masks shared by the value and the gradient: bit 3 (h >= 8: u = y),
 * h & 12 == 0 (h < 4: v = y) and h & 13 == 12 (h is 12 or 14: v = x). */
BG_INLINE vf grad_value(vi hash, vf dx, vf dy, vf dz, vm lt4, vm x1214)
{
    vf u = vf_sel_bit(hash, 3, dy, dx);
    vf v = vf_sel(lt4, dy, vf_sel(x1214, dx, dz));
    return vf_add(vf_flip_bit(u, hash, 0), vf_flip_bit(v, hash, 1));
}

BG_INLINE void corner_masks(const vhash *hs, int ck, vm *lt4, vm *x1214)
{
    vi hash = vh_corner(hs, ck);
    *lt4 = vi_eq(vi_and(hash, vi_set1(12)), vi_set1(0));
    *x1214 = vi_eq(vi_and(hash, vi_set1(13)), vi_set1(12));
}

/* Corner ck's value and, when `want_grad` (a constant after inlining), its
 * gradient vector. */
BG_INLINE corner grad_corner_g(const vhash *hs, int ck, vf dx, vf dy, vf dz, int want_grad)
{
    corner c;
    vi hash = vh_corner(hs, ck);
    vm lt4, x1214;
    corner_masks(hs, ck, &lt4, &x1214);
    c.v = grad_value(hash, dx, dy, dz, lt4, x1214);
    vf zero = vf_set1(0);
    c.gx = c.gy = c.gz = zero;
    if (!want_grad)
        return c;
    /* d/dx etc. of the value: +-1 on the u and v axes, +0 on the third. */
    vf su = vf_flip_bit(vf_set1(1), hash, 0), sv = vf_flip_bit(vf_set1(1), hash, 1);
    c.gx = vf_sel_bit(hash, 3, vf_sel(x1214, sv, zero), su);
    c.gy = vf_sel_bit(hash, 3, su, vf_sel(lt4, sv, zero));
    c.gz = vf_sel(vm_or(lt4, x1214), zero, sv);
    return c;
}
#endif
BG_INLINE corner grad_corner_v(const vhash *hs, int ck, vf dx, vf dy, vf dz)
{
    return grad_corner_g(hs, ck, dx, dy, dz, 0);
}
BG_INLINE corner grad_corner(const vhash *hs, int ck, vf dx, vf dy, vf dz)
{
    return grad_corner_g(hs, ck, dx, dy, dz, 1);
}

/* lerp(t, a, b) = a + t (b - a), the reference's form. */
BG_INLINE vf lerp(vf t, vf a, vf b) { return vf_add(a, vf_mul(t, vf_sub(b, a))); }

/* lerp(t, a, b) where b - a is exact and t (b - a) too: a and b are corner
 * gradient components (+-1 or +0), so b - a is an integer in [-2, 2]. */
BG_INLINE vf lerp_corner(vf t, vf a, vf b) { return vf_fma_exact(t, vf_sub(b, a), a); }

/* The lerp carried with its gradient: t depends on one axis only (0 x, 1 y,
 * 2 z; a constant after inlining), whose component gains dt (b - a). `first`
 * (a constant): a and b are corners (grad_corner), so the gradient lerps take
 * lerp_corner's exact products. */
BG_INLINE corner lerp_axis_g(vf t, vf dt, corner a, corner b, int axis, int first)
{
    corner r;
    vf dv = vf_sub(b.v, a.v);
    r.v = vf_add(a.v, vf_mul(t, dv));
    if (first)
        r.gx = lerp_corner(t, a.gx, b.gx), r.gy = lerp_corner(t, a.gy, b.gy),
        r.gz = lerp_corner(t, a.gz, b.gz);
    else
        r.gx = lerp(t, a.gx, b.gx), r.gy = lerp(t, a.gy, b.gy), r.gz = lerp(t, a.gz, b.gz);
    vf *g = axis == 0 ? &r.gx : axis == 1 ? &r.gy : &r.gz;
    *g = vf_add(*g, vf_mul(dt, dv));
    return r;
}
BG_INLINE corner lerp_axis(vf t, vf dt, corner a, corner b, int axis)
{
    return lerp_axis_g(t, dt, a, b, axis, 0);
}

/* Split a coordinate into its lattice cell modulo 256 and its fraction.
 * Large coordinates neither overflow nor lose the period; NaN/Inf give a NaN
 * fraction (and so a NaN result) and cell 0, so no out-of-range index is formed.
 * Float: vi_cell256 (floor mod 256, 0 for NaN/Inf) is exact for every float,
 * since from 2^31 up every float is a multiple of 256. Double: the cell is
 * reduced in floating point (cell - 256 floor(cell / 256), exact since /256 is a
 * power of two) before the conversion, as doubles above 2^31 need not be. */
BG_INLINE vf lattice(vf x, vi *cell)
{
    vf fl = vf_floor(x);
#ifdef BG_SCALAR_DOUBLE
    vf c = vf_sub(fl, vf_mul(vf_set1(256), vf_floor(vf_mul(fl, vf_set1((bg_real)(1.0 / 256))))));
    vm ok = vm_and(vf_le(vf_set1(0), c), vf_lt(c, vf_set1(256)));
    *cell = vi_from_vf(vf_sel(ok, c, vf_set1(0)));
#else
    *cell = vi_cell256(fl);
#endif
    return vf_sub(x, fl);
}


/* Improved noise in two steps: noise_cell is the lattice cell, its hash
 * chain and the fractions, noise_at the rest (fades, corners, lerps). The
 * batch loops start the next vector's chain (a gather and three dependent
 * table lookups) before this vector's corners, so the out-of-order core
 * overlaps the two; the operations and so the bits are the same as in one
 * step. The fBm octave loop carries the fractions (3 floors and 3
 * subtractions fewer per octave: AVX2 fbm3 233 -> 229 instructions per
 * sample); the noise3 batch computes them again from the loaded coordinates
 * (cell_refrac), which llvm-mca's Zen 3 model puts at 2.5 cycles per vector
 * less than carrying them (docs/KERNELS.md item 7). */
typedef struct vcell {
    vhash h;
    vf fx, fy, fz;
} vcell;
BG_INLINE vcell noise_cell(vf x, vf y, vf z)
{
    vi X, Y, Z;
    vcell c;
    c.fx = lattice(x, &X), c.fy = lattice(y, &Y), c.fz = lattice(z, &Z);
    c.h = vi_hashp(X, Y, Z);
    return c;
}

#ifdef BG_PIPELINE
/* The cell with its fractions computed again from the coordinates (only the
 * pipelined noise3 and noise3_grad batches use it: clang -Werror refuses an
 * unused one). In noise3_grad it replaces the carried fractions, which the
 * VBMI loop kept on the stack (3 stores and 3 loads per vector, 3 floors and 3
 * subtractions fewer): about 1-2% faster at AVX-512. */
BG_INLINE vcell cell_refrac(vcell c, vf x, vf y, vf z)
{
    vi X, Y, Z; /* unused: noise_cell's */
    c.fx = lattice(x, &X), c.fy = lattice(y, &Y), c.fz = lattice(z, &Z);
    return c;
}
#endif

/* ---- Domains: tileable lattices and seeded octaves (noise.h bg_domain) ----
 * The cell floor(x) reduced modulo the period P (an integer-valued bg_real,
 * 1 <= P <= 2^24, 1/P given rounded): r = fl - P floor((fl + 1/2) / P). The
 * quotient (fl + 1/2) / P is never an integer and lies at least 1/(2P) from
 * one, more than the rounding of (fl + 1/2) * (1/P) moves it while |fl| <
 * 2^22 (float; 2^51 in double), so its floor is exact and so is r, with no
 * correction step. Beyond (the fraction is mostly gone there), r is a fixed
 * function of fl, the same on every ISA, that need not lie in [0, P):
 * vi_cell256 takes it modulo 256 (0 for NaN/Inf), so no index leaves the
 * table. *c1 is the next corner's cell, r + 1, or 0 at the seam. Both are
 * used modulo 256 by the hash, as the plain lattice is: with P = 256 the
 * cells are vi_cell256's and the hashes the plain noise's. */
BG_INLINE vf lattice_per(vf x, bg_real P, bg_real invP, vi *c0, vi *c1)
{
    vf vp = vf_set1(P), zero = vf_set1(0);
    vf fl = vf_floor(x);
    vf q = vf_floor(vf_mul(vf_add(fl, vf_set1((bg_real)0.5)), vf_set1(invP)));
    vf r = vf_sub(fl, vf_mul(q, vp));
    vf r1 = vf_add(r, vf_set1(1));
    r1 = vf_sel(vf_le(vp, r1), zero, r1);
#ifdef BG_SCALAR_DOUBLE
    /* No vi_cell256 in double: out-of-range cells (and NaN) become 0. */
    r = vf_sel(vm_and(vf_le(zero, r), vf_lt(r, vp)), r, zero);
    r1 = vf_sel(vm_and(vf_le(zero, r1), vf_lt(r1, vp)), r1, zero);
    *c0 = vi_and(vi_from_vf(r), vi_set1(255));
    *c1 = vi_and(vi_from_vf(r1), vi_set1(255));
#else
    *c0 = vi_cell256(r);
    *c1 = vi_cell256(r1);
#endif
    return vf_sub(x, fl);
}

/* Per octave: the seed offset and the period (P L^i, or 256 for an untiled
 * axis: the plain lattice's own period) with its reciprocal, built once per
 * call in bg_real by the same operations on every ISA, and how octave_cell
 * takes the cell modulo the periods (the same cells every way):
 *  - OCT_PLAIN (float only): every period a power of two >= 256. floor(x)
 *    modulo P is then floor(x) modulo 256 after the hash's own modulo 256,
 *    and the next corner (r + 1, or 0 at the seam) is (floor(x) + 1) modulo
 *    256: the plain cells, for every finite x (lattice_per's r is exact for
 *    a power of two; where floor(x) + 1/2 rounds up, 2^23 <= |x| < 2^24,
 *    r = -1 is 255 modulo 256, as P - 1 is). For NaN and Inf only the next
 *    corner's cell differs, and the result is NaN either way.
 *  - OCT_POW2: every period a power of two: the cell is floor(x) AND (P - 1)
 *    (mask[a] = min(P, 256) - 1), the next one (floor(x) + 1) AND (P - 1),
 *    in integers, for vectors whose every |floor(x)| < 2^22 (lattice_per's
 *    exact range); lattice_per for the others.
 *  - OCT_ANY: lattice_per.
 * zseam[i] tells vi_hashp_per whether lanes can sit on the z seam: 0 never
 * (P_z a power of two >= 256: Z1 = Z + 1 modulo 256), 2 often (P_z <= 64),
 * else 1. */
enum { OCT_PLAIN, OCT_POW2, OCT_ANY };
typedef struct octlat {
    bg_real off[BG_MAX_OCTAVES][3], per[BG_MAX_OCTAVES][3], inv[BG_MAX_OCTAVES][3];
    int32_t mask[BG_MAX_OCTAVES][3], pm1[BG_MAX_OCTAVES][3]; /* pm1: P - 1 */
    signed char kind[BG_MAX_OCTAVES], zseam[BG_MAX_OCTAVES];
    int tiled;  /* some period is set; else (a seed alone) the plain cells */
    int seeded; /* offsets to add (seed != 0); adding +0 would give the same bits */
    int carry;  /* octave_cell_carry may carry the reduced cells (float only) */
    bg_real carry_lim; /* its range: every |x| below (octave 0's coordinates) */
    bg_real cinv[3];   /* its 1/P of octave 0, or 0 (untiled) */
} octlat;
static inline void octlat_init(octlat *L, const bg_fractal *f, const bg_domain *d)
{
    L->tiled = d->period[0] || d->period[1] || d->period[2];
    L->seeded = d->seed != 0;
    int octaves = f->function == BG_FUNC_NOISE ? 1 : f->octaves;
    bg_real freq = 1;
    const bg_real lac = (bg_real)f->lacunarity;
    for (int i = 0; i < octaves; i++) {
        int pow2 = 1, big = 1;
        for (int a = 0; a < 3; a++) {
            bg_real P = d->period[a] ? (bg_real)d->period[a] * freq : (bg_real)256;
            L->off[i][a] = (bg_real)bg_seed_offset(d->seed, i, a);
            L->per[i][a] = P;
            L->inv[i][a] = (bg_real)1 / P;
            /* 1 <= P <= 2^24 (bg_domain_validate), an integer: exact in long. */
            long n = (long)P;
            int p2 = (n & (n - 1)) == 0;
            pow2 &= p2, big &= p2 && n >= 256;
            L->mask[i][a] = (int32_t)((n < 256 ? n : 256) - 1);
            L->pm1[i][a] = (int32_t)(n - 1);
            if (a == 2)
                L->zseam[i] = (signed char)(p2 && n >= 256 ? 0 : n <= 64 ? 2 : 1);
        }
#ifdef BG_SCALAR_DOUBLE
        /* lattice_per's double cells leave out-of-range r (r = -1 where
         * floor(x) + 1/2 rounds up, 2^52 <= |x| < 2^53) at 0, not modulo 256. */
        big = 0;
#endif
        L->kind[i] = (signed char)(big ? OCT_PLAIN : pow2 ? OCT_POW2 : OCT_ANY);
        freq *= lac;
    }
    /* octave_cell_carry: an unseeded fractal with an integer lacunarity L
     * (bg_domain_validate's rule for a tiled domain) where some octave is
     * OCT_ANY (a period that is not a power of two). lim = floor(2^22 /
     * L^(octaves - 1)) - 1: every octave's |q_i| < 2^22. An L that is not a
     * power of two also needs every tiled period P L^i <= 2^22. */
    L->carry = 0, L->carry_lim = 0;
#ifndef BG_SCALAR_DOUBLE
    int any = 0;
    for (int i = 0; i < octaves; i++)
        any |= L->kind[i] == OCT_ANY;
    /* lac <= 2^24 before the conversion (a seed alone admits any lacunarity) */
    int64_t li = L->tiled && lac <= (bg_real)16777216 ? (int64_t)lac : 0, top = 1;
    int ok = !L->seeded && octaves >= 2 && any && li >= 1 && (bg_real)li == lac;
    for (int i = 1; ok && i < octaves; i++)
        ok = (top *= li) <= 2097152; /* L^(octaves - 1) <= 2^21 */
    int lpow2 = (li & (li - 1)) == 0;
    for (int i = 0; ok && !lpow2 && i < octaves; i++)
        for (int a = 0; a < 3; a++)
            ok &= !d->period[a] || L->per[i][a] <= (bg_real)4194304;
    if (ok) {
        for (int a = 0; a < 3; a++)
            L->cinv[a] = d->period[a] ? L->inv[0][a] : 0;
        L->carry = 1;
        L->carry_lim = (bg_real)(4194304 / top) - 1;
    }
#endif
}

/* OCT_POW2's hashes from the unreduced cells c = floor(q) (vi_from_vf): the
 * corners (c AND (P - 1), (c + 1) AND (P - 1)) per axis, m = P - 1. A
 * vocabulary that runs the chain in bytes (vec_avx512.h VBMI, vec_avx2.h) takes
 * the masks there, where one byte AND per axis wraps both corners, and tests
 * the range on the integer cells (vi_small22); the others form the corners
 * here and run vi_hashp_per. */
#ifndef BG_HAVE_HASHP_POW2
BG_INLINE vhash vi_hashp_pow2(vi cx, vi cy, vi cz, vi mx, vi my, vi mz, int zseam)
{
    vi one = vi_set1(1);
    return vi_hashp_per(vi_and(cx, mx), vi_and(cy, my), vi_and(cz, mz), vi_and(vi_add(cx, one), mx),
                        vi_and(vi_add(cy, one), my), vi_and(vi_add(cz, one), mz), zseam);
}
#endif

/* OCT_POW2's cells (octlat): 1 if every |floor(q)| < 2^22 (false for NaN), and
 * then the fractions and the cells of both corners per axis. With
 * BG_HAVE_HASHP_POW2 the test is vi_small22 on the converted cells (every
 * floor(q) in [-2^22, 2^22); vi_from_vf gives INT32_MIN for NaN, Inf and
 * |q| >= 2^31, outside): it admits floor(q) = -2^22 too, where lattice_per is
 * exact for a power-of-two P (fl + 1/2 and its product with 1/P are exact),
 * so the cells are the same either way. */
BG_INLINE int lattice_pow2(const octlat *L, int i, vf qx, vf qy, vf qz, vcell *c, int zseam)
{
    vf flx = vf_floor(qx), fly = vf_floor(qy), flz = vf_floor(qz);
#ifdef BG_HAVE_SMALL22
    if (!vf_small22(flx, fly, flz))
        return 0;
    vi cx = vi_from_vf(flx), cy = vi_from_vf(fly), cz = vi_from_vf(flz);
#elif defined(BG_HAVE_HASHP_POW2)
    vi cx = vi_from_vf(flx), cy = vi_from_vf(fly), cz = vi_from_vf(flz);
    if (!vi_small22(cx, cy, cz))
        return 0;
#else
    vf lim = vf_set1((bg_real)4194304);
    if (!vm_all(vm_and(vm_and(vf_lt(vf_abs(flx), lim), vf_lt(vf_abs(fly), lim)),
                       vf_lt(vf_abs(flz), lim))))
        return 0;
    vi cx = vi_from_vf(flx), cy = vi_from_vf(fly), cz = vi_from_vf(flz);
#endif
    vi mx = vi_set1(L->mask[i][0]), my = vi_set1(L->mask[i][1]), mz = vi_set1(L->mask[i][2]);
    c->fx = vf_sub(qx, flx), c->fy = vf_sub(qy, fly), c->fz = vf_sub(qz, flz);
    c->h = vi_hashp_pow2(cx, cy, cz, mx, my, mz, zseam);
    return 1;
}

#ifdef BG_HAVE_SMALL22
/* OCT_ANY's cells where every |floor(q)| < 2^22 (vf_small22), the range where
 * lattice_per's r is exact and in [0, P): r by the same quotient with the
 * exact product q P fused (the same r), converted once; the next corner r + 1,
 * or 0 where r = P - 1, in integers (vi_wrap1). Both are used modulo 256 by
 * vi_hashp_per, which reads their low bytes only (vec_avx512.h VBMI). */
BG_INLINE int lattice_any_small(const octlat *L, int i, vf qx, vf qy, vf qz, vcell *c, int zseam)
{
    vf fl[3] = {vf_floor(qx), vf_floor(qy), vf_floor(qz)}, q[3] = {qx, qy, qz}, fr[3];
    vi X[3], X1[3];
    if (!vf_small22(fl[0], fl[1], fl[2]))
        return 0;
    for (int a = 0; a < 3; a++) {
        bg_real P = L->per[i][a];
        vf qq = vf_floor(vf_mul(vf_add(fl[a], vf_set1((bg_real)0.5)), vf_set1(L->inv[i][a])));
        X[a] = vi_from_vf(vf_fma_exact(qq, vf_set1(-P), fl[a]));
        X1[a] = vi_wrap1(X[a], (int32_t)P - 1);
        fr[a] = vf_sub(q[a], fl[a]);
    }
    c->fx = fr[0], c->fy = fr[1], c->fz = fr[2];
    c->h = vi_hashp_per(X[0], X[1], X[2], X1[0], X1[1], X1[2], zseam);
    return 1;
}
#endif

/* Octave i's cell at freq * p (+ its offset, wrapped, with a domain L; the
 * plain cell for L = NULL, a constant after inlining). `kind` is L->kind[i]
 * or, where the caller has tested it once for a whole batch (the periodic
 * noise loops, BG_DNOISE_KIND), that kind as a constant (seeded likewise),
 * which leaves the loop without the tests. */
#define OCT_RUNTIME (-1)
BG_INLINE vcell octave_cell_k(const octlat *L, int i, vf x, vf y, vf z, bg_real freq, int kind,
                              int seeded, int zseam)
{
    vf fq = vf_set1(freq);
    vf qx = vf_mul(x, fq), qy = vf_mul(y, fq), qz = vf_mul(z, fq);
    if (!L)
        return noise_cell(qx, qy, qz);
    if (seeded < 0 ? L->seeded : seeded) {
        qx = vf_add(qx, vf_set1(L->off[i][0]));
        qy = vf_add(qy, vf_set1(L->off[i][1]));
        qz = vf_add(qz, vf_set1(L->off[i][2]));
    }
    if (kind == OCT_RUNTIME)
        kind = L->tiled ? L->kind[i] : OCT_PLAIN;
    /* periods 256 (or powers of two above): the plain cells, the same bits at
     * less cost */
    if (kind == OCT_PLAIN)
        return noise_cell(qx, qy, qz);
    vi X, Y, Z, X1, Y1, Z1;
    vcell c;
    if (zseam < 0)
        zseam = L->zseam[i];
    if (kind == OCT_POW2 && lattice_pow2(L, i, qx, qy, qz, &c, zseam))
        return c;
#ifdef BG_HAVE_SMALL22
    if (kind == OCT_ANY && lattice_any_small(L, i, qx, qy, qz, &c, zseam))
        return c;
#endif
    c.fx = lattice_per(qx, L->per[i][0], L->inv[i][0], &X, &X1);
    c.fy = lattice_per(qy, L->per[i][1], L->inv[i][1], &Y, &Y1);
    c.fz = lattice_per(qz, L->per[i][2], L->inv[i][2], &Z, &Z1);
    c.h = vi_hashp_per(X, Y, Z, X1, Y1, Z1, zseam);
    return c;
}
BG_INLINE vcell octave_cell(const octlat *L, int i, vf x, vf y, vf z, bg_real freq)
{
    return octave_cell_k(L, i, x, y, z, freq, OCT_RUNTIME, -1, -1);
}

/* The reduced cells carried from octave to octave (the fractal loops; octlat's
 * carry: no seed, an integer lacunarity L, some OCT_ANY octave). Octave i's
 * point is q_i = L^i q_0 (freq = L^i, exact), rounded, and its period P_i =
 * P L^i. Octave 0 takes n_0 = -P floor((fl + 1/2) / P) by lattice_per's
 * quotient (exact below 2^22), so that q_0 + n_0 lies in [0, P). Then L^i n_0
 * is a multiple of P_i, and every octave's cell is r_i = floor(q_i) + freq n_0,
 * one fused multiply-add with an exact product (n_0 times a power of two, or
 * an integer below 2^23 where P_i <= 2^22) and an exact sum, converted, and
 * the next corner's vi_wrap1 of it: the same r and r + 1 (or 0 at the seam) as
 * lattice_per's where that is exact, |floor(q_i)| < 2^22 in every octave.
 * r_i lies in [0, P_i): L^i q_0 does, and its rounding q_i cannot reach the
 * integer M = P_i - freq n_0 from below, as q_0 < M / L^i is at least half an
 * ulp of q_0 below that integer (a whole one unless q_0 is a power of two,
 * whose product with L^i is exact), which L^i scales to more than half an
 * ulp of L^i q_0 unless L^i is a power of two (then q_i is exact). Octave 0
 * tests the range for the whole vector once (|q_0| < carry_lim, false for
 * NaN); a vector outside takes octave_cell in every octave. An untiled axis
 * (period 256 in every octave) needs no reduction, as the hash reads its
 * cells modulo 256: its n_0 is 0 (cinv 0), r_i = floor(q_i), and vi_wrap1
 * with 255 gives r_i + 1 modulo 256. (Reducing it with P = 256 would not do:
 * its r_i, below 256 L^i, outgrows the float's integers at deep octaves.) */
#ifndef BG_SCALAR_DOUBLE
typedef struct octcarry {
    vf n0[3];
    int on;
} octcarry;
#define OCTCARRY_INIT(K) ((K).on = 0, (K).n0[0] = (K).n0[1] = (K).n0[2] = vf_set1(0))
BG_INLINE vcell octave_cell_carry(const octlat *L, int i, vf x, vf y, vf z, bg_real freq,
                                  octcarry *K)
{
    if (i == 0) {
        vf lim = vf_set1(L->carry_lim);
        K->on = vm_all(vm_and(vm_and(vf_lt(vf_abs(x), lim), vf_lt(vf_abs(y), lim)),
                              vf_lt(vf_abs(z), lim)));
    }
    if (!K->on)
        return octave_cell(L, i, x, y, z, freq);
    vf fq = vf_set1(freq);
    vf q[3] = {vf_mul(x, fq), vf_mul(y, fq), vf_mul(z, fq)}, fr[3];
    vi X[3], X1[3];
    for (int a = 0; a < 3; a++) {
        vf fl = vf_floor(q[a]);
        if (i == 0) {
            vf qq = vf_floor(vf_mul(vf_add(fl, vf_set1((bg_real)0.5)), vf_set1(L->cinv[a])));
            K->n0[a] = vf_mul(qq, vf_set1(-L->per[0][a]));
        }
        X[a] = vi_from_vf(vf_fma_exact(K->n0[a], fq, fl));
        X1[a] = vi_wrap1(X[a], L->pm1[i][a]);
        fr[a] = vf_sub(q[a], fl);
    }
#ifdef BG_HASHP_PER_XY255
    X[0] = vi_and(X[0], vi_set1(255)), X[1] = vi_and(X[1], vi_set1(255));
#endif
    vcell c;
    c.fx = fr[0], c.fy = fr[1], c.fz = fr[2];
    c.h = vi_hashp_per(X[0], X[1], X[2], X1[0], X1[1], X1[2], L->zseam[i]);
    return c;
}
#else
typedef struct octcarry {
    int on;
} octcarry;
#define OCTCARRY_INIT(K) ((K).on = 0)
#endif
/* Octave i's cell in a fractal loop: carry 0 never carried, 1 carried (the
 * caller tested L->carry), -1 as L->carry says. */
BG_INLINE vcell octave_cell_fr(const octlat *L, int i, vf x, vf y, vf z, bg_real freq, int carry,
                               octcarry *K)
{
#ifndef BG_SCALAR_DOUBLE
    if (L && carry && (carry > 0 || L->carry))
        return octave_cell_carry(L, i, x, y, z, freq, K);
#else
    (void)carry, (void)K;
#endif
    return octave_cell(L, i, x, y, z, freq);
}

/* The gradient only when `want_grad` (a constant after inlining, so the
 * value-only kernel does no gradient work). */
BG_INLINE corner noise_at(vcell c, int want_grad)
{
    vhash hs = c.h;
    vf fx = c.fx, fy = c.fy, fz = c.fz;
    vf u = fade(fx), v = fade(fy), w = fade(fz);

    vf x1 = vf_sub(fx, vf_set1(1)), y1 = vf_sub(fy, vf_set1(1)), z1 = vf_sub(fz, vf_set1(1));
    if (!want_grad) {
        /* lerp(w, lerp(v, lerp(u, ..), lerp(u, ..)), lerp(v, ..)) exactly as the
         * reference, each corner pair folded as soon as it is formed (fewer
         * live registers than forming all eight first; the same operations). */
        corner r;
        vf c000 = grad_corner_v(&hs, 0, fx, fy, fz).v, c100 = grad_corner_v(&hs, 1, x1, fy, fz).v;
        vf a0 = lerp(u, c000, c100);
        vf c010 = grad_corner_v(&hs, 2, fx, y1, fz).v, c110 = grad_corner_v(&hs, 3, x1, y1, fz).v;
        vf a1 = lerp(u, c010, c110);
        vf b0 = lerp(v, a0, a1);
        vf c001 = grad_corner_v(&hs, 4, fx, fy, z1).v, c101 = grad_corner_v(&hs, 5, x1, fy, z1).v;
        vf a2 = lerp(u, c001, c101);
        vf c011 = grad_corner_v(&hs, 6, fx, y1, z1).v, c111 = grad_corner_v(&hs, 7, x1, y1, z1).v;
        vf a3 = lerp(u, c011, c111);
        vf b1 = lerp(v, a2, a3);
        r.v = lerp(w, b0, b1);
        r.gx = r.gy = r.gz = vf_set1(0);
        return r;
    }
    /* With the gradient, each corner pair is folded into its lerp as soon as it
     * is formed (the same operations in the same association as lerping after
     * all eight): 8 corners x 4 vectors live at once do not fit the 32 AVX-512
     * registers next to the rest and were spilled to the stack. */
    vf du = dfade(fx), dv = dfade(fy), dw = dfade(fz);
    corner a0 = lerp_axis_g(u, du, grad_corner(&hs, 0, fx, fy, fz), grad_corner(&hs, 1, x1, fy, fz), 0, 1);
    corner a1 = lerp_axis_g(u, du, grad_corner(&hs, 2, fx, y1, fz), grad_corner(&hs, 3, x1, y1, fz), 0, 1);
    corner b0 = lerp_axis(v, dv, a0, a1, 1);
    corner a2 = lerp_axis_g(u, du, grad_corner(&hs, 4, fx, fy, z1), grad_corner(&hs, 5, x1, fy, z1), 0, 1);
    corner a3 = lerp_axis_g(u, du, grad_corner(&hs, 6, fx, y1, z1), grad_corner(&hs, 7, x1, y1, z1), 0, 1);
    corner b1 = lerp_axis(v, dv, a2, a3, 1);
    corner r = lerp_axis(w, dw, b0, b1, 2);
#ifdef BG_GRAD_ZERO_SIGNS
    r.gx = grad_zero_sign(r.gx), r.gy = grad_zero_sign(r.gy), r.gz = grad_zero_sign(r.gz);
#endif
    return r;
}

BG_INLINE corner noise_vec(vf x, vf y, vf z, int want_grad)
{
    return noise_at(noise_cell(x, y, z), want_grad);
}

/* ---- fBm and turbulence (Perlin 1985) -------------------------------------- */

/* Footprint weight of an octave (noise.h): c = clamp(2 - 4 r, 0, 1) for the
 * resolution ratio r = footprint * frequency; 1 up to r = 1/4, 0 from the
 * Nyquist limit r = 1/2. `fp` is already sanitized (NaN and negative -> 0). */
BG_INLINE vf octave_weight(vf fp, bg_real freq)
{
    vf w = vf_sub(vf_set1(2), vf_mul(vf_set1(4), vf_mul(fp, vf_set1(freq))));
    w = vf_sel(vf_gt(w, vf_set1(1)), vf_set1(1), w);
    return vf_sel(vf_lt(w, vf_set1(0)), vf_set1(0), w);
}

/* Octave i samples noise at lacunarity^i p with weight gain^i; both factors are
 * built by repeated multiplication in bg_real, identical on every ISA.
 * With `use_fp` (a constant after inlining) octave i is also weighted by its
 * footprint weight, and the loop stops at the first octave that no lane can
 * show. A weight of exactly 1 multiplies exactly, so footprint 0 reproduces the
 * unfiltered sum bit for bit. */
BG_INLINE corner fractal_fp_vec_k(const bg_fractal *f, vf x, vf y, vf z, int want_grad,
                                  int use_fp, vf fp, const octlat *L, int carry)
{
    int octaves = f->function == BG_FUNC_NOISE ? 1 : f->octaves;
    if (use_fp) {
        fp = vf_sel(vf_gt(fp, vf_set1(0)), fp, vf_set1(0));
        /* Octaves beyond the finest any lane needs are skipped (ratios grow with
         * the octave when lacunarity >= 1): one horizontal minimum per vector. */
        if (f->lacunarity >= 1 || f->function == BG_FUNC_NOISE) {
            bg_real lanes[LANES], mn;
            vf_storen(lanes, fp, LANES);
            mn = lanes[0];
            for (int l = 1; l < LANES; l++)
                mn = lanes[l] < mn ? lanes[l] : mn;
            bg_real fq = 1;
            int need = 0;
            while (need < octaves && mn * fq < (bg_real)0.5)
                need++, fq *= (bg_real)f->lacunarity;
            octaves = need;
        }
    }
    if (f->function == BG_FUNC_NOISE) {
        corner o;
        if (octaves == 0) {
            o.v = o.gx = o.gy = o.gz = vf_set1(0);
            return o;
        }
        o = L ? noise_at(octave_cell(L, 0, x, y, z, 1), want_grad) : noise_vec(x, y, z, want_grad);
        if (use_fp) {
            /* Not a sum: weight 1 must return the noise itself (even -0). */
            vf w = octave_weight(fp, 1);
            o.v = vf_mul(w, o.v), o.gx = vf_mul(w, o.gx), o.gy = vf_mul(w, o.gy),
            o.gz = vf_mul(w, o.gz);
        }
        return o;
    }
    int turb = f->function == BG_FUNC_TURBULENCE;
    bg_real amp = 1, freq = 1;
    const bg_real gain = (bg_real)f->gain, lac = (bg_real)f->lacunarity;
    corner s;
    s.v = s.gx = s.gy = s.gz = vf_set1(0);
    octcarry K; /* octave_cell_carry's, when L->carry */
    OCTCARRY_INIT(K);
#ifdef BG_PIPELINE
    /* Octave i + 1's hash chain is started before octave i's corners (noise_at). */
    vcell cell = octave_cell_fr(L, 0, x, y, z, freq, carry, &K);
#endif
    for (int i = 0; i < octaves; i++) {
#ifdef BG_PIPELINE
        vcell next = cell;
        if (i + 1 < octaves)
            next = octave_cell_fr(L, i + 1, x, y, z, freq * lac, carry, &K);
        corner o = noise_at(cell, want_grad);
        cell = next;
#else
        corner o = noise_at(octave_cell_fr(L, i, x, y, z, freq, carry, &K), want_grad);
#endif
        vf a = vf_set1(amp), af = vf_set1(amp * freq);
        if (use_fp) {
            vf w = octave_weight(fp, freq);
            a = vf_mul(a, w), af = vf_mul(af, w);
        }
        if (turb) {
            /* d|n| = sign(n) dn, with sign(0) = +1 (the crease: docs/STABILITY.md). */
            vm neg = vf_lt(o.v, vf_set1(0));
            s.v = vf_add(s.v, vf_mul(a, vf_abs(o.v)));
            if (want_grad) {
                af = vf_sel(neg, vf_neg(af), af);
                s.gx = vf_add(s.gx, vf_mul(af, o.gx));
                s.gy = vf_add(s.gy, vf_mul(af, o.gy));
                s.gz = vf_add(s.gz, vf_mul(af, o.gz));
            }
        } else {
            s.v = vf_add(s.v, vf_mul(a, o.v));
            if (want_grad) {
                s.gx = vf_add(s.gx, vf_mul(af, o.gx));
                s.gy = vf_add(s.gy, vf_mul(af, o.gy));
                s.gz = vf_add(s.gz, vf_mul(af, o.gz));
            }
        }
        amp *= gain;
        freq *= lac;
    }
    return s;
}

BG_INLINE corner fractal_fp_vec(const bg_fractal *f, vf x, vf y, vf z, int want_grad, int use_fp,
                                vf fp, const octlat *L)
{
    return fractal_fp_vec_k(f, x, y, z, want_grad, use_fp, fp, L, -1);
}
BG_INLINE corner fractal_vec_l(const bg_fractal *f, vf x, vf y, vf z, int want_grad,
                               const octlat *L)
{
    return fractal_fp_vec(f, x, y, z, want_grad, 0, vf_set1(0), L);
}
/* fractal_vec_l with octave_cell_fr's carry given (a constant: the domain
 * fractal batches run one loop per value, so neither has the other's code). */
BG_INLINE corner fractal_vec_lk(const bg_fractal *f, vf x, vf y, vf z, int want_grad,
                                const octlat *L, int carry)
{
    return fractal_fp_vec_k(f, x, y, z, want_grad, 0, vf_set1(0), L, carry);
}
BG_INLINE corner fractal_vec(const bg_fractal *f, vf x, vf y, vf z, int want_grad)
{
    return fractal_vec_l(f, x, y, z, want_grad, NULL);
}

/* A step below the spacing of the coordinate's floating-point grid rounds to
 * x +- h == x: the difference quotient is then 0/0. We return 0 for that
 * component (no slope can be measured) so finite input never yields NaN. */
static inline vf central_quotient(vf num, vf den)
{
    vm none = vf_le(vf_abs(den), vf_set1(0));
    return vf_sel(none, vf_set1(0), vf_div(num, vf_sel(none, vf_set1(1), den)));
}

/* Central differences: (F(x+h) - F(x-h)) / ((x+h) - (x-h)), dividing by the step
 * actually taken, which differs from 2h once x is large (rounding of x +- h). */
BG_INLINE corner fractal_central_vec(const bg_fractal *f, vf h, vf x, vf y, vf z, const octlat *L)
{
#define fractal_vec(f, x, y, z, g) fractal_vec_l(f, x, y, z, g, L)
    corner r = fractal_vec(f, x, y, z, 0);
    vf xp = vf_add(x, h), xm = vf_sub(x, h);
    vf yp = vf_add(y, h), ym = vf_sub(y, h);
    vf zp = vf_add(z, h), zm = vf_sub(z, h);
    r.gx = central_quotient(vf_sub(fractal_vec(f, xp, y, z, 0).v, fractal_vec(f, xm, y, z, 0).v),
                            vf_sub(xp, xm));
    r.gy = central_quotient(vf_sub(fractal_vec(f, x, yp, z, 0).v, fractal_vec(f, x, ym, z, 0).v),
                            vf_sub(yp, ym));
    r.gz = central_quotient(vf_sub(fractal_vec(f, x, y, zp, 0).v, fractal_vec(f, x, y, zm, 0).v),
                            vf_sub(zp, zm));
#undef fractal_vec
    return r;
}

/* ---- The surface gradient and the perturbed normal ------------------------- */

typedef struct v3 {
    vf x, y, z;
} v3;

/* n' = normalize(n - grad_S h) with grad_S h = g - n (n.g) (eq. 2 and 4, Listing 3),
 * or the additive forms normalize(n -+ g). The degenerate-input rules are the ones
 * documented in surfgrad.h; they are selects, so every lane follows them alike. */
BG_INLINE v3 perturb_vec(bg_perturb_method method, v3 n, v3 g)
{
    vf zero = vf_set1(0), one = vf_set1(1), big = vf_set1(BG_REAL_MAX);
    /* Normalize n with a pre-scale by its largest component: no finite n overflows. */
    vf ax = vf_abs(n.x), ay = vf_abs(n.y), az = vf_abs(n.z);
    vf m = vf_max(vf_max(ax, ay), az);
    vm nvalid = vm_and(vm_and(vf_gt(m, zero), vf_le(ax, big)), vm_and(vf_le(ay, big), vf_le(az, big)));
    /* A subnormal m would make 1/m overflow (NaN out of a finite n): lift a tiny
     * n by 2^64 first, exactly; larger n keep their bits. */
    vm tiny = vf_lt(m, vf_set1((bg_real)0x1p-64));
    vf lift = vf_sel(tiny, vf_set1((bg_real)0x1p64), one);
    n.x = vf_mul(n.x, lift), n.y = vf_mul(n.y, lift), n.z = vf_mul(n.z, lift);
    m = vf_mul(m, lift);
    vf inv = vf_div(one, vf_sel(nvalid, m, one));
    n.x = vf_mul(n.x, inv), n.y = vf_mul(n.y, inv), n.z = vf_mul(n.z, inv);
    vf il = vf_div(one, vf_sqrt(vf_add(vf_add(vf_mul(n.x, n.x), vf_mul(n.y, n.y)), vf_mul(n.z, n.z))));
    n.x = vf_mul(n.x, il), n.y = vf_mul(n.y, il), n.z = vf_mul(n.z, il);

    /* Huge g: scale n and g by 1/max|g| so no product overflows; normalize()
     * ignores a positive common factor. */
    vf gxa = vf_abs(g.x), gya = vf_abs(g.y), gza = vf_abs(g.z);
    vm gvalid = vm_and(vm_and(vf_le(gxa, big), vf_le(gya, big)), vf_le(gza, big));
    vf mg = vf_max(vf_max(gxa, gya), gza);
    vm huge = vm_and(gvalid, vf_gt(mg, vf_set1((bg_real)1099511627776.0))); /* 2^40 */
    vf sc = vf_sel(huge, vf_div(one, mg), one);
    g.x = vf_mul(g.x, sc), g.y = vf_mul(g.y, sc), g.z = vf_mul(g.z, sc);

    v3 s;
    if (method == BG_PERTURB_SURFGRAD) {
        vf d = vf_add(vf_add(vf_mul(n.x, g.x), vf_mul(n.y, g.y)), vf_mul(n.z, g.z));
        /* grad_S = g - n (n.g) (eq. 2); s = n - grad_S (eq. 4). */
        s.x = vf_sub(vf_mul(n.x, sc), vf_sub(g.x, vf_mul(n.x, d)));
        s.y = vf_sub(vf_mul(n.y, sc), vf_sub(g.y, vf_mul(n.y, d)));
        s.z = vf_sub(vf_mul(n.z, sc), vf_sub(g.z, vf_mul(n.z, d)));
    } else if (method == BG_PERTURB_ADDITIVE) {
        s.x = vf_sub(vf_mul(n.x, sc), g.x);
        s.y = vf_sub(vf_mul(n.y, sc), g.y);
        s.z = vf_sub(vf_mul(n.z, sc), g.z);
    } else {
        s.x = vf_add(vf_mul(n.x, sc), g.x);
        s.y = vf_add(vf_mul(n.y, sc), g.y);
        s.z = vf_add(vf_mul(n.z, sc), g.z);
    }
    /* With a huge g (nearly) along n, s is about n/max|g| and s.s underflows, so
     * the length is wrong or 0: rescale a tiny s by its largest component first
     * (a division, which cannot overflow); other s keep their bits. */
    vf ms = vf_max(vf_max(vf_abs(s.x), vf_abs(s.y)), vf_abs(s.z));
    vm stiny = vm_and(vf_gt(ms, zero), vf_lt(ms, vf_set1((bg_real)0x1p-32)));
    vf msd = vf_sel(stiny, ms, one);
    s.x = vf_div(s.x, msd), s.y = vf_div(s.y, msd), s.z = vf_div(s.z, msd);
    vf len = vf_sqrt(vf_add(vf_add(vf_mul(s.x, s.x), vf_mul(s.y, s.y)), vf_mul(s.z, s.z)));
    vm keep = vm_and(gvalid, vf_gt(len, zero));
    vf il2 = vf_div(one, vf_sel(keep, len, one));
    v3 r;
    r.x = vf_sel(keep, vf_mul(s.x, il2), n.x);
    r.y = vf_sel(keep, vf_mul(s.y, il2), n.y);
    r.z = vf_sel(keep, vf_mul(s.z, il2), n.z);
    r.x = vf_sel(nvalid, r.x, zero);
    r.y = vf_sel(nvalid, r.y, zero);
    r.z = vf_sel(nvalid, r.z, zero);
    return r;
}

/* ---- Batch kernels ---------------------------------------------------------
 * One stride loop each; the last partial vector is read and written with
 * vf_loadn/vf_storen (count c < LANES), so tails take the same arithmetic path. */

#define BG_FOR_BATCH_FROM(i, c, i0, n) \
    for (size_t i = (i0), c; i < (n) && ((c = ((n) - i < LANES ? (n) - i : LANES)), 1); i += LANES)
#define BG_FOR_BATCH(i, c, n) BG_FOR_BATCH_FROM(i, c, 0, n)

/* Every output goes through vf_canon: a NaN result is the one canonical quiet
 * NaN on every ISA (x86 arithmetic makes the "default NaN" with the sign bit
 * set, scalar code may keep an input's payload), so outputs compare bit for bit
 * with no NaN caveat. */
BG_INLINE void store_out(bg_real *p, vf v, size_t c) { vf_storen(p, vf_canon(v), c); }

/* A last partial vector of one point costs a whole vector (8 or 16 lanes of
 * work for one result): that point goes to the scalar kernel instead, which
 * gives the same bits by construction (issue 10: a batch of n < LANES must cost
 * no more than 1.3x n single calls). BG_VEC_N(n) is the count the vector loop
 * takes, BG_TAIL1(n) says whether one point is left for bg_kernels_c. */
#if LANES > 1 && !defined(BG_SCALAR_DOUBLE)
#define BG_VEC_N(n) ((n) % LANES == 1 ? (n) - 1 : (n))
#define BG_TAIL1(n) ((n) % LANES == 1)
#define BG_SCALAR_TAIL 1
#else
#define BG_VEC_N(n) (n)
#define BG_TAIL1(n) 0
#endif
/* p + k, or NULL for an optional output that is absent. */
#define BG_OPT(p, k) ((p) ? (p) + (k) : NULL)

/* Full vectors from i while two or more are left, each vector's hash chain
 * started one step ahead (noise_cell): i is left at the first vector the
 * caller's BG_FOR_BATCH loop still has to do. AT(cell, p) is the work at p.
 * Only where the hashes are packed (BG_PIPELINE): with 8 hash registers to
 * carry, or a libm floor computed twice (the scalar kernel), it costs more
 * than it hides (the sse2 and scalar rows of docs/PERFORMANCE.md). */
#ifndef BG_PIPELINE
#define BG_PIPELINED(i, n, AT)
#define BG_PIPELINED_CELL(i, n, AT, CELL)
#else
#define BG_CELL_PLAIN(p) noise_cell(vf_loadn(x + (p), LANES), vf_loadn(y + (p), LANES),        \
                                    vf_loadn(z + (p), LANES))
#define BG_PIPELINED(i, n, AT) BG_PIPELINED_CELL(i, n, AT, BG_CELL_PLAIN)
#define BG_PIPELINED_CELL(i, n, AT, CELL)                                                       \
    if ((n) >= 2 * LANES) {                                                                    \
        vcell c_ = CELL(0);                                                                    \
        for (; i + 2 * LANES <= (n); i += LANES) {                                             \
            size_t j_ = i + LANES;                                                             \
            vcell next_ = CELL(j_);                                                            \
            AT(c_, i);                                                                         \
            c_ = next_;                                                                        \
        }                                                                                      \
        AT(c_, i);                                                                             \
        i += LANES;                                                                            \
    }
#endif

/* The value-and-gradient batch pipelines only where the vocabulary asks
 * (BG_PIPELINE_GRAD): with 32 zmm registers it pays (noise3_grad 2.34 -> 1.84
 * ns/sample at AVX-512), with AVX2's 16 the carried hashes spill (63 -> 68
 * instructions per sample, 3% slower). */
#if defined(BG_PIPELINE) && defined(BG_PIPELINE_GRAD)
#define BG_PIPELINED_GRAD BG_PIPELINED
#define BG_PIPELINED_GRAD_CELL BG_PIPELINED_CELL
#else
#define BG_PIPELINED_GRAD(i, n, AT)
#define BG_PIPELINED_GRAD_CELL(i, n, AT, CELL)
#endif

void KFN(noise3)(const bg_real *x, const bg_real *y, const bg_real *z, size_t n, bg_real *v)
{
    size_t i0 = 0;
#define NOISE3_AT(cell, p)                                                                      \
    store_out(v + (p),                                                                          \
              noise_at(cell_refrac(cell, vf_loadn(x + (p), LANES), vf_loadn(y + (p), LANES),    \
                                   vf_loadn(z + (p), LANES)),                                   \
                       0).v,                                                                    \
              LANES)
    BG_PIPELINED(i0, BG_VEC_N(n), NOISE3_AT)
#undef NOISE3_AT
    BG_FOR_BATCH_FROM(i, c, i0, BG_VEC_N(n))
    {
        corner r = noise_vec(vf_loadn(x + i, c), vf_loadn(y + i, c), vf_loadn(z + i, c), 0);
        store_out(v + i, r.v, c);
    }
#ifdef BG_SCALAR_TAIL
    if (BG_TAIL1(n)) {
        size_t t = n - 1;
        v[t] = PFN(noise3_point)(x[t], y[t], z[t]);
    }
#endif
}

BG_INLINE void store_corner(corner r, size_t i, size_t c, bg_real *v, bg_real *gx,
                                bg_real *gy, bg_real *gz)
{
#ifdef BG_HAVE_ANY_NAN4
    /* No NaN in any of the four (the usual case): vf_canon is the identity, so
     * one test of all four replaces its four tests and selects. */
    if (!vf_any_nan4(r.v, r.gx, r.gy, r.gz)) {
        if (v)
            vf_storen(v + i, r.v, c);
        vf_storen(gx + i, r.gx, c), vf_storen(gy + i, r.gy, c), vf_storen(gz + i, r.gz, c);
        return;
    }
#endif
    if (v)
        store_out(v + i, r.v, c);
    store_out(gx + i, r.gx, c);
    store_out(gy + i, r.gy, c);
    store_out(gz + i, r.gz, c);
}

void KFN(noise3_grad)(const bg_real *x, const bg_real *y, const bg_real *z, size_t n, bg_real *v,
                      bg_real *gx, bg_real *gy, bg_real *gz)
{
    size_t i0 = 0;
#define NOISE3_GRAD_AT(cell, p)                                                                 \
    store_corner(noise_at(cell_refrac(cell, vf_loadn(x + (p), LANES), vf_loadn(y + (p), LANES),    \
                                      vf_loadn(z + (p), LANES)),                                   \
                          1),                                                                      \
                 p, LANES, v, gx, gy, gz)
    BG_PIPELINED_GRAD(i0, BG_VEC_N(n), NOISE3_GRAD_AT)
#undef NOISE3_GRAD_AT
    BG_FOR_BATCH_FROM(i, c, i0, BG_VEC_N(n))
    {
        corner r = noise_vec(vf_loadn(x + i, c), vf_loadn(y + i, c), vf_loadn(z + i, c), 1);
        store_corner(r, i, c, v, gx, gy, gz);
    }
#ifdef BG_SCALAR_TAIL
    if (BG_TAIL1(n)) {
        size_t t = n - 1;
        bg_kernels_c.noise3_grad(x + t, y + t, z + t, 1, BG_OPT(v, t), gx + t, gy + t, gz + t);
    }
#endif
}

void KFN(fractal3)(const bg_fractal *f, const bg_real *x, const bg_real *y, const bg_real *z,
                   size_t n, bg_real *v)
{
    BG_FOR_BATCH(i, c, BG_VEC_N(n))
    {
        corner r = fractal_vec(f, vf_loadn(x + i, c), vf_loadn(y + i, c), vf_loadn(z + i, c), 0);
        store_out(v + i, r.v, c);
    }
#ifdef BG_SCALAR_TAIL
    if (BG_TAIL1(n)) {
        size_t t = n - 1;
        v[t] = PFN(fractal3_point)(f, x[t], y[t], z[t]);
    }
#endif
}

void KFN(fractal3_grad)(const bg_fractal *f, const bg_real *x, const bg_real *y, const bg_real *z,
                        size_t n, bg_real *v, bg_real *gx, bg_real *gy, bg_real *gz)
{
    BG_FOR_BATCH(i, c, BG_VEC_N(n))
    {
        corner r = fractal_vec(f, vf_loadn(x + i, c), vf_loadn(y + i, c), vf_loadn(z + i, c), 1);
        store_corner(r, i, c, v, gx, gy, gz);
    }
#ifdef BG_SCALAR_TAIL
    if (BG_TAIL1(n)) {
        size_t t = n - 1;
        bg_kernels_c.fractal3_grad(f, x + t, y + t, z + t, 1, BG_OPT(v, t), gx + t, gy + t, gz + t);
    }
#endif
}

void KFN(fractal3_grad_central)(const bg_fractal *f, bg_real h, const bg_real *x,
                                const bg_real *y, const bg_real *z, size_t n, bg_real *v,
                                bg_real *gx, bg_real *gy, bg_real *gz)
{
    vf hv = vf_set1(h);
    BG_FOR_BATCH(i, c, BG_VEC_N(n))
    {
        corner r = fractal_central_vec(f, hv, vf_loadn(x + i, c), vf_loadn(y + i, c),
                                       vf_loadn(z + i, c), NULL);
        store_corner(r, i, c, v, gx, gy, gz);
    }
#ifdef BG_SCALAR_TAIL
    if (BG_TAIL1(n)) {
        size_t t = n - 1;
        bg_kernels_c.fractal3_grad_central(f, h, x + t, y + t, z + t, 1, BG_OPT(v, t), gx + t, gy + t, gz + t);
    }
#endif
}

void KFN(perturb)(bg_perturb_method m, const bg_real *nx, const bg_real *ny, const bg_real *nz,
                  const bg_real *gx, const bg_real *gy, const bg_real *gz, size_t n,
                  bg_real *ox, bg_real *oy, bg_real *oz)
{
    BG_FOR_BATCH(i, c, n)
    {
        v3 nn = {vf_loadn(nx + i, c), vf_loadn(ny + i, c), vf_loadn(nz + i, c)};
        v3 gg = {vf_loadn(gx + i, c), vf_loadn(gy + i, c), vf_loadn(gz + i, c)};
        v3 r = perturb_vec(m, nn, gg);
        store_out(ox + i, r.x, c);
        store_out(oy + i, r.y, c);
        store_out(oz + i, r.z, c);
    }
}

/* ---- Fractals over a domain (noise.h bg_domain) ----------------------------
 * The caller validated `d` (bg_domain_validate) and found it set. Periodic
 * noise (BG_FUNC_NOISE) pipelines its hash chains as noise3 does, and where
 * it does not, runs a loop of its own (BG_DNOISE_REST): octave 0's cell and
 * noise_at, the operations of fractal_vec_l for one octave, without the
 * fractal loop in the same body (AVX2 pnoise3_grad 84 -> 79 instructions per
 * sample). */
#define BG_CELL_DOM(p) octave_cell_k(&L, 0, vf_loadn(x + (p), LANES), vf_loadn(y + (p), LANES), \
                                     vf_loadn(z + (p), LANES), 1, kind_, seeded_, zs_)
#define BG_DNOISE_REST(i0, n, want_grad, STORE)                                                 \
    BG_FOR_BATCH_FROM(i, c, i0, n)                                                             \
    {                                                                                          \
        corner r = noise_at(octave_cell_k(&L, 0, vf_loadn(x + i, c), vf_loadn(y + i, c),       \
                                          vf_loadn(z + i, c), 1, kind_, seeded_, zs_),         \
                            want_grad);                                                        \
        STORE;                                                                                 \
    }                                                                                          \
    i0 = n
/* The periodic noise loop LOOP(kind_, seeded_, zs_) once per kind of the
 * octave's lattice and whether it is seeded, and unseeded with zseam 2 (small
 * z periods) apart, so that each loop body has no test of them
 * (octave_cell_k; -1: read from L). */
#define BG_DNOISE_KIND(LOOP)                                                                   \
    do {                                                                                       \
        int k_ = L.tiled ? L.kind[0] : OCT_PLAIN;                                              \
        if (L.seeded) {                                                                        \
            if (k_ == OCT_PLAIN) {                                                             \
                LOOP(OCT_PLAIN, 1, -1);                                                        \
            } else if (k_ == OCT_POW2) {                                                       \
                LOOP(OCT_POW2, 1, -1);                                                         \
            } else {                                                                           \
                LOOP(OCT_ANY, 1, -1);                                                          \
            }                                                                                  \
        } else if (k_ == OCT_PLAIN) {                                                          \
            LOOP(OCT_PLAIN, 0, -1);                                                            \
        } else if (k_ == OCT_POW2 && L.zseam[0] == 2) {                                        \
            LOOP(OCT_POW2, 0, 2);                                                              \
        } else if (k_ == OCT_POW2) {                                                           \
            LOOP(OCT_POW2, 0, -1);                                                             \
        } else if (L.zseam[0] == 2) {                                                          \
            LOOP(OCT_ANY, 0, 2);                                                               \
        } else {                                                                               \
            LOOP(OCT_ANY, 0, -1);                                                              \
        }                                                                                      \
    } while (0)
void KFN(dfractal3_grad)(const bg_fractal *f, const bg_domain *d, const bg_real *x,
                         const bg_real *y, const bg_real *z, size_t n, bg_real *v, bg_real *gx,
                         bg_real *gy, bg_real *gz)
{
    octlat L;
    octlat_init(&L, f, d);
    size_t i0 = 0;
    if (f->function == BG_FUNC_NOISE) {
        /* Pipelined wherever the hashes are packed, AVX2 included, where the
         * plain noise3_grad is not (BG_PIPELINE_GRAD): the periodic chain is
         * longer (the range test, the wraps, the z seam's lookup), and
         * starting it a vector ahead made AVX2 pnoise3_grad about 8% faster
         * (63.3 instructions per sample against 63.8 unpipelined). */
#define DNOISE_GRAD_AT(cell, p) store_corner(noise_at(cell, 1), p, LANES, v, gx, gy, gz)
#define DNOISE_GRAD_LOOP(kind, seeded, zs)                                                     \
    {                                                                                          \
        const int kind_ = kind, seeded_ = seeded, zs_ = zs;                                    \
        BG_PIPELINED_CELL(i0, BG_VEC_N(n), DNOISE_GRAD_AT, BG_CELL_DOM)                        \
        BG_DNOISE_REST(i0, BG_VEC_N(n), 1, store_corner(r, i, c, v, gx, gy, gz));              \
    }
        BG_DNOISE_KIND(DNOISE_GRAD_LOOP);
#undef DNOISE_GRAD_LOOP
#undef DNOISE_GRAD_AT
    }
#define DFRACTAL_GRAD_LOOP(carry)                                                              \
    BG_FOR_BATCH_FROM(i, c, i0, BG_VEC_N(n))                                                   \
    {                                                                                          \
        corner r = fractal_vec_lk(f, vf_loadn(x + i, c), vf_loadn(y + i, c), vf_loadn(z + i, c), \
                                  1, &L, carry);                                               \
        store_corner(r, i, c, v, gx, gy, gz);                                                  \
    }
    if (L.carry) {
        DFRACTAL_GRAD_LOOP(1)
    } else {
        DFRACTAL_GRAD_LOOP(0)
    }
#undef DFRACTAL_GRAD_LOOP
#ifdef BG_SCALAR_TAIL
    if (BG_TAIL1(n)) {
        size_t t = n - 1;
        bg_kernels_c.dfractal3_grad(f, d, x + t, y + t, z + t, 1, BG_OPT(v, t), gx + t, gy + t,
                                    gz + t);
    }
#endif
}

#ifndef BG_SCALAR_DOUBLE
void KFN(dfractal3)(const bg_fractal *f, const bg_domain *d, const bg_real *x, const bg_real *y,
                    const bg_real *z, size_t n, bg_real *v)
{
    octlat L;
    octlat_init(&L, f, d);
    size_t i0 = 0;
    if (f->function == BG_FUNC_NOISE) {
#define DNOISE_AT(cell, p) store_out(v + (p), noise_at(cell, 0).v, LANES)
#define DNOISE_LOOP(kind, seeded, zs)                                                          \
    {                                                                                          \
        const int kind_ = kind, seeded_ = seeded, zs_ = zs;                                    \
        BG_PIPELINED_CELL(i0, BG_VEC_N(n), DNOISE_AT, BG_CELL_DOM)                             \
        BG_DNOISE_REST(i0, BG_VEC_N(n), 0, store_out(v + i, r.v, c));                          \
    }
        BG_DNOISE_KIND(DNOISE_LOOP);
#undef DNOISE_LOOP
#undef DNOISE_AT
    }
#define DFRACTAL_LOOP(carry)                                                                   \
    BG_FOR_BATCH_FROM(i, c, i0, BG_VEC_N(n))                                                   \
    {                                                                                          \
        corner r = fractal_vec_lk(f, vf_loadn(x + i, c), vf_loadn(y + i, c), vf_loadn(z + i, c), \
                                  0, &L, carry);                                               \
        store_out(v + i, r.v, c);                                                              \
    }
    if (L.carry) {
        DFRACTAL_LOOP(1)
    } else {
        DFRACTAL_LOOP(0)
    }
#undef DFRACTAL_LOOP
#ifdef BG_SCALAR_TAIL
    if (BG_TAIL1(n)) {
        size_t t = n - 1;
        bg_kernels_c.dfractal3(f, d, x + t, y + t, z + t, 1, v + t);
    }
#endif
}

void KFN(dfractal3_grad_central)(const bg_fractal *f, const bg_domain *d, bg_real h,
                                 const bg_real *x, const bg_real *y, const bg_real *z, size_t n,
                                 bg_real *v, bg_real *gx, bg_real *gy, bg_real *gz)
{
    octlat L;
    octlat_init(&L, f, d);
    vf hv = vf_set1(h);
    BG_FOR_BATCH(i, c, BG_VEC_N(n))
    {
        corner r = fractal_central_vec(f, hv, vf_loadn(x + i, c), vf_loadn(y + i, c),
                                       vf_loadn(z + i, c), &L);
        store_corner(r, i, c, v, gx, gy, gz);
    }
#ifdef BG_SCALAR_TAIL
    if (BG_TAIL1(n)) {
        size_t t = n - 1;
        bg_kernels_c.dfractal3_grad_central(f, d, h, x + t, y + t, z + t, 1, BG_OPT(v, t), gx + t,
                                            gy + t, gz + t);
    }
#endif
}

/* Fractal value + analytic gradient with per-sample footprints (noise space). */
void KFN(fractal3_grad_fp)(const bg_fractal *f, const bg_real *fp, const bg_real *x,
                           const bg_real *y, const bg_real *z, size_t n, bg_real *v, bg_real *gx,
                           bg_real *gy, bg_real *gz)
{
    BG_FOR_BATCH(i, c, BG_VEC_N(n))
    {
        corner r = fractal_fp_vec(f, vf_loadn(x + i, c), vf_loadn(y + i, c), vf_loadn(z + i, c), 1,
                                  1, vf_loadn(fp + i, c), NULL);
        store_corner(r, i, c, v, gx, gy, gz);
    }
#ifdef BG_SCALAR_TAIL
    if (BG_TAIL1(n)) {
        size_t t = n - 1;
        bg_kernels_c.fractal3_grad_fp(f, fp + t, x + t, y + t, z + t, 1, BG_OPT(v, t), gx + t, gy + t, gz + t);
    }
#endif
}

/* Fused height -> normal: h(p) = A F(f p), grad h = A f F'(f p), then eq. 4.
 * With `fp` (footprints in world units, scaled by the frequency like p) the
 * octaves are footprint-weighted and the gradient is always analytic. */
BG_INLINE void perturb_height_impl(const bg_height *h, bg_perturb_method m, const bg_real *fp,
                                   const bg_real *px, const bg_real *py, const bg_real *pz,
                                   const bg_real *nx, const bg_real *ny, const bg_real *nz,
                                   size_t n, bg_real *height, bg_real *ox, bg_real *oy,
                                   bg_real *oz, const octlat *L)
{
    vf freq = vf_set1(h->frequency), amp = vf_set1(h->amplitude);
    vf af = vf_set1(h->amplitude * h->frequency);
    vf step = vf_set1(h->step > 0 ? h->step : BG_DEFAULT_CENTRAL_STEP);
    int central = !fp && h->gradient == BG_GRADIENT_CENTRAL;
    BG_FOR_BATCH(i, c, BG_VEC_N(n))
    {
        vf qx = vf_mul(vf_loadn(px + i, c), freq);
        vf qy = vf_mul(vf_loadn(py + i, c), freq);
        vf qz = vf_mul(vf_loadn(pz + i, c), freq);
        corner r = fp        ? fractal_fp_vec(&h->fractal, qx, qy, qz, 1, 1,
                                              vf_mul(vf_loadn(fp + i, c), freq), L)
                   : central ? fractal_central_vec(&h->fractal, step, qx, qy, qz, L)
                             : fractal_vec_l(&h->fractal, qx, qy, qz, 1, L);
        v3 nn = {vf_loadn(nx + i, c), vf_loadn(ny + i, c), vf_loadn(nz + i, c)};
        v3 gg = {vf_mul(af, r.gx), vf_mul(af, r.gy), vf_mul(af, r.gz)};
        v3 o = perturb_vec(m, nn, gg);
        if (height)
            store_out(height + i, vf_mul(amp, r.v), c);
        store_out(ox + i, o.x, c);
        store_out(oy + i, o.y, c);
        store_out(oz + i, o.z, c);
    }
#ifdef BG_SCALAR_TAIL
    if (BG_TAIL1(n)) {
        size_t t = n - 1;
        if (fp)
            bg_kernels_c.perturb_height_fp(h, m, fp + t, px + t, py + t, pz + t, nx + t, ny + t,
                                           nz + t, 1, BG_OPT(height, t), ox + t, oy + t, oz + t);
        else
            bg_kernels_c.perturb_height(h, m, px + t, py + t, pz + t, nx + t, ny + t, nz + t, 1,
                                        BG_OPT(height, t), ox + t, oy + t, oz + t);
    }
#endif
}

/* Both entry points below: the domain's lattice set up when the height has
 * one. Inlined into each, so that fp == NULL stays a constant in the plain one. */
BG_INLINE void perturb_height_entry(const bg_height *h, bg_perturb_method m, const bg_real *fp,
                                    const bg_real *px, const bg_real *py, const bg_real *pz,
                                    const bg_real *nx, const bg_real *ny, const bg_real *nz,
                                    size_t n, bg_real *height, bg_real *ox, bg_real *oy,
                                    bg_real *oz)
{
    if (bg_domain_is_set(&h->domain)) {
        octlat L;
        octlat_init(&L, &h->fractal, &h->domain);
        perturb_height_impl(h, m, fp, px, py, pz, nx, ny, nz, n, height, ox, oy, oz, &L);
    } else {
        perturb_height_impl(h, m, fp, px, py, pz, nx, ny, nz, n, height, ox, oy, oz, NULL);
    }
}

void KFN(perturb_height_fp)(const bg_height *h, bg_perturb_method m, const bg_real *fp,
                            const bg_real *px, const bg_real *py, const bg_real *pz,
                            const bg_real *nx, const bg_real *ny, const bg_real *nz, size_t n,
                            bg_real *height, bg_real *ox, bg_real *oy, bg_real *oz)
{
    perturb_height_entry(h, m, fp, px, py, pz, nx, ny, nz, n, height, ox, oy, oz);
}

void KFN(perturb_height)(const bg_height *h, bg_perturb_method m, const bg_real *px,
                         const bg_real *py, const bg_real *pz, const bg_real *nx,
                         const bg_real *ny, const bg_real *nz, size_t n, bg_real *height,
                         bg_real *ox, bg_real *oy, bg_real *oz)
{
    perturb_height_entry(h, m, NULL, px, py, pz, nx, ny, nz, n, height, ox, oy, oz);
}
#endif

/* ---- Single points (scalar float only) ---------------------------------------
 * The per-point entry points of noise.h call these directly: no table load, no
 * batch loop, arguments and result in registers. The same noise_vec /
 * fractal_vec as the batch kernels, so the same bits. */
#if LANES == 1 && !defined(BG_SCALAR_DOUBLE)
float KFN(noise3_point)(float x, float y, float z)
{
    return vf_canon(noise_vec(x, y, z, 0).v);
}

float KFN(noise3_grad_point)(float x, float y, float z, float g[3])
{
    corner r = noise_vec(x, y, z, 1);
    g[0] = vf_canon(r.gx), g[1] = vf_canon(r.gy), g[2] = vf_canon(r.gz);
    return vf_canon(r.v);
}

float KFN(fractal3_point)(const bg_fractal *f, float x, float y, float z)
{
    return vf_canon(fractal_vec(f, x, y, z, 0).v);
}

float KFN(fractal3_grad_point)(const bg_fractal *f, float x, float y, float z, float g[3])
{
    corner r = fractal_vec(f, x, y, z, 1);
    g[0] = vf_canon(r.gx), g[1] = vf_canon(r.gy), g[2] = vf_canon(r.gz);
    return vf_canon(r.v);
}
#endif

/* ---- Single points with the octaves across lanes -----------------------------
 * A per-point fBm/turbulence call has no second point to fill the lanes with,
 * but its octaves are independent noise evaluations: octave i at
 * (lac^i x, lac^i y, lac^i z). So one vector evaluates LANES octaves of the one
 * point (all 6 default octaves in one AVX2 noise_vec instead of 6 scalar ones),
 * and the octave sum is then formed lane by lane in octave order with the
 * scalar kernel's operations (fractal_fp_vec without footprint): the same
 * products x * freq_i, the same noise bits per lane (every ISA equals scalar),
 * the same sequential sum, so the same bits as bg_fractal3_point_c (issue 10;
 * tests/kernels/check_grid.c checks every table against it). A chunk of a
 * single octave runs on the scalar point function (a whole vector for one
 * octave costs more); NaN payloads may differ before the final vf_canon, which
 * makes every NaN the canonical one. */
#if LANES > 1 && !defined(BG_SCALAR_DOUBLE)
BG_INLINE float fractal_point_lanes(const bg_fractal *f, float x, float y, float z, int want_grad,
                                    float g[3])
{
    const int octaves = f->octaves, turb = f->function == BG_FUNC_TURBULENCE;
    const float gain = f->gain, lac = f->lacunarity;
    float amp = 1, freq = 1, sv = 0, sx = 0, sy = 0, sz = 0;
    for (int i0 = 0; i0 < octaves; i0 += LANES) {
        int c = octaves - i0 < LANES ? octaves - i0 : LANES;
        float nv[LANES], nx[LANES], ny[LANES], nz[LANES];
        if (c == 1) {
            if (want_grad) {
                float og[3];
                nv[0] = PFN(noise3_grad_point)(x * freq, y * freq, z * freq, og);
                nx[0] = og[0], ny[0] = og[1], nz[0] = og[2];
            } else {
                nv[0] = PFN(noise3_point)(x * freq, y * freq, z * freq);
            }
        } else {
            float fq[LANES], fr = freq;
            for (int k = 0; k < LANES; k++) {
                fq[k] = k < c ? fr : 0; /* unused lanes sample the origin */
                fr *= lac;
            }
            vf vq = vf_loadn(fq, LANES);
            corner o = noise_vec(vf_mul(vf_set1(x), vq), vf_mul(vf_set1(y), vq),
                                 vf_mul(vf_set1(z), vq), want_grad);
            vf_storen(nv, o.v, LANES);
            if (want_grad) {
                vf_storen(nx, o.gx, LANES);
                vf_storen(ny, o.gy, LANES);
                vf_storen(nz, o.gz, LANES);
            }
        }
        for (int k = 0; k < c; k++) {
            float a = amp, af = amp * freq, n = nv[k];
            if (turb) {
                sv = sv + a * fabsf(n);
                af = n < 0 ? -af : af;
            } else {
                sv = sv + a * n;
            }
            if (want_grad) {
                sx = sx + af * nx[k];
                sy = sy + af * ny[k];
                sz = sz + af * nz[k];
            }
            amp *= gain;
            freq *= lac;
        }
    }
    if (want_grad) {
        g[0] = sx != sx ? NAN : sx, g[1] = sy != sy ? NAN : sy, g[2] = sz != sz ? NAN : sz;
    }
    return sv != sv ? NAN : sv;
}

static float KFN(fractal3_point)(const bg_fractal *f, float x, float y, float z)
{
    if (f->function == BG_FUNC_NOISE || f->octaves < 2)
        return PFN(fractal3_point)(f, x, y, z);
    return fractal_point_lanes(f, x, y, z, 0, NULL);
}

static float KFN(fractal3_grad_point)(const bg_fractal *f, float x, float y, float z, float g[3])
{
    if (f->function == BG_FUNC_NOISE || f->octaves < 2)
        return PFN(fractal3_grad_point)(f, x, y, z, g);
    return fractal_point_lanes(f, x, y, z, 1, g);
}
#endif

/* ---- This ISA's kernel table ---------------------------------------------- */
#define BG_STR2(a) #a
#define BG_STR(a) BG_STR2(a)
#ifdef BG_SCALAR_DOUBLE
const bg_kernel_table_d bg_kernels_c64 = {
    .noise3_grad = bg_noise3_grad_c64,
    .fractal3_grad = bg_fractal3_grad_c64,
    .fractal3_grad_central = bg_fractal3_grad_central_c64,
    .perturb = bg_perturb_c64,
    .dfractal3_grad = bg_dfractal3_grad_c64,
};
#else
const bg_kernel_table KFN(kernels) = {
    .isa = BG_ISA_ENUM,
    .noise3 = KFN(noise3),
    .noise3_grad = KFN(noise3_grad),
    .fractal3 = KFN(fractal3),
    .fractal3_grad = KFN(fractal3_grad),
    .fractal3_grad_central = KFN(fractal3_grad_central),
    .perturb = KFN(perturb),
    .perturb_height = KFN(perturb_height),
    .fractal3_grad_fp = KFN(fractal3_grad_fp),
    .perturb_height_fp = KFN(perturb_height_fp),
    .fractal3_point = KFN(fractal3_point),
    .fractal3_grad_point = KFN(fractal3_grad_point),
#if LANES > 1
    .noise3_point = PFN(noise3_point),
    .noise3_grad_point = PFN(noise3_grad_point),
#else
    .noise3_point = KFN(noise3_point),
    .noise3_grad_point = KFN(noise3_grad_point),
#endif
    .dfractal3 = KFN(dfractal3),
    .dfractal3_grad = KFN(dfractal3_grad),
    .dfractal3_grad_central = KFN(dfractal3_grad_central),
    .name = BG_STR(BG_ISA_SUFFIX),
};
#endif
