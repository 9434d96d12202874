/* SPDX-License-Identifier: MIT */
/* Internal: the kernel table that every ISA fills, and the dispatch entry points.
 * Kernels are written once in *_tmpl.c against the vector vocabulary of vec_*.h
 * and compiled per ISA (docs/DESIGN.md, rule 3); this header is the only contract between
 * src/core and src/kernels. */
#ifndef BUMPGRAD_KERNELS_H
#define BUMPGRAD_KERNELS_H

#include <stdint.h>
#include "bumpgrad/noise.h"
#include "bumpgrad/surfgrad.h"

/* Perlin's reference permutation, doubled so that p[i + 1] never wraps (i < 511). */
extern const int32_t bg_perm512[512];
extern const uint8_t bg_perm256_u8[256];
/* bg_perm_pair[i] = p[i] | p[(i + 1) & 255] << 8, for the 7-lookup hash chain. */
extern const int32_t bg_perm_pair[256];
/* bg_perm_nib2[i] = (p[i] & 15) | (p[(i + 1) & 255] & 15) << 4: two corner
 * hashes (their low 4 bits) in one byte, for the last step of the chain. */
extern const uint8_t bg_perm_nib2[256];
/* The corner code of a hash h (its low 4 bits): Perlin's grad(h, x, y, z) =
 * (+-u) + (+-v) restated as a first and a second axis with their signs, so
 * that a corner needs two selects on single bits where the reference's form
 * needs three, two of them on compares (h < 4, h == 12 || h == 14):
 *   bit 3: the first axis is y (else x);   bit 2: the second axis is z (else y);
 *   bit 0: the first is negated;           bit 1: the second is negated.
 * For h < 12 the first axis is u and the second v, so the code is h with bit 2
 * set for h = 8..11 (v = z there). For h = 12 and 14 the reference adds
 * (+-y) + (+-x), and the code adds (+-x) + (+-y) with the signs swapped
 * (h & 2 for x, h & 1 for y): IEEE addition is commutative, zeros included,
 * so the value is the same bits. 13 and 15 (-y + z, -y - z) are their own
 * codes. check_noise.c compares every code with Perlin's grad. */
static inline int bg_corner_code(int h)
{
    static const uint8_t code[16] = {0, 1, 2, 3, 4, 5, 6, 7, 12, 13, 14, 15, 0, 13, 1, 15};
    return code[h & 15];
}
/* bg_perm_code2[i] = bg_corner_code(p[i]) | bg_corner_code(p[(i + 1) & 255]) << 4:
 * bg_perm_nib2 with each hash replaced by its corner code (vec_avx2.h). */
extern const uint8_t bg_perm_code2[256];
/* bg_perm_code_hi[16 k + j] = bg_corner_code(p[32 k + 16 + j]) |
 * bg_corner_code(p[32 k + j]) << 4: every corner code in 8 slices of 16 bytes
 * (vec_avx2.h bg_perm_code_hi). */
extern const uint8_t bg_perm_code_hi[128];

/* The seed offset of octave i along one axis (noise.h bg_domain): k / 256 with
 * k in [0, 8192) from a 32-bit mix of (seed, octave, axis); 0 for seed 0.
 * Exact in float and double, so every ISA and both precisions add the same
 * value. The one definition (bg_domain_offset returns it). */
static inline uint32_t bg_mix32(uint32_t h)
{
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return h;
}
static inline float bg_seed_offset(uint32_t seed, int octave, int axis)
{
    if (!seed)
        return 0.0f;
    uint32_t k = bg_mix32(bg_mix32(seed) + (uint32_t)(3 * octave + axis) * 0x9e3779b9u) >> 19;
    return (float)k * (1.0f / 256);
}

/* 1 if any field of domain `d` is set (the domain kernels run); the default,
 * all zero, takes the plain kernels and their bits. */
static inline int bg_domain_is_set(const bg_domain *d)
{
    return d->seed != 0 || d->period[0] != 0 || d->period[1] != 0 || d->period[2] != 0;
}

typedef struct bg_kernel_table {
    bg_isa isa;
    void (*noise3)(const float *x, const float *y, const float *z, size_t n, float *v);
    void (*noise3_grad)(const float *x, const float *y, const float *z, size_t n, float *v,
                        float *gx, float *gy, float *gz);
    void (*fractal3)(const bg_fractal *f, const float *x, const float *y, const float *z,
                     size_t n, float *v);
    void (*fractal3_grad)(const bg_fractal *f, const float *x, const float *y, const float *z,
                          size_t n, float *v, float *gx, float *gy, float *gz);
    void (*fractal3_grad_central)(const bg_fractal *f, float h, const float *x, const float *y,
                                  const float *z, size_t n, float *v, float *gx, float *gy,
                                  float *gz);
    void (*perturb)(bg_perturb_method m, const float *nx, const float *ny, const float *nz,
                    const float *gx, const float *gy, const float *gz, size_t n, float *ox,
                    float *oy, float *oz);
    void (*perturb_height)(const bg_height *h, bg_perturb_method m, const float *px,
                           const float *py, const float *pz, const float *nx, const float *ny,
                           const float *nz, size_t n, float *height, float *ox, float *oy,
                           float *oz);
    /* Footprint-aware fractal and fused calls (noise.h, surfgrad.h). */
    void (*fractal3_grad_fp)(const bg_fractal *f, const float *fp, const float *x, const float *y,
                             const float *z, size_t n, float *v, float *gx, float *gy, float *gz);
    void (*perturb_height_fp)(const bg_height *h, bg_perturb_method m, const float *fp,
                              const float *px, const float *py, const float *pz, const float *nx,
                              const float *ny, const float *nz, size_t n, float *height, float *ox,
                              float *oy, float *oz);
    /* One point of fBm/turbulence with its octaves across the lanes (bump_tmpl.c);
     * the same bits as bg_fractal3_point_c / bg_fractal3_grad_point_c, which the
     * scalar table holds. `f` must be in range (bg_fractal_in_range). */
    float (*fractal3_point)(const bg_fractal *f, float x, float y, float z);
    float (*fractal3_grad_point)(const bg_fractal *f, float x, float y, float z, float g[3]);
    /* One point of noise: the one-lane kernel, compiled with this ISA's flags
     * where that gives shorter code (bg_noise3_point_c_avx2: VEX encoding and
     * roundss for floor), the same operations and bits as bg_noise3_point_c. */
    float (*noise3_point)(float x, float y, float z);
    float (*noise3_grad_point)(float x, float y, float z, float g[3]);
    /* A fractal over a domain (noise.h bg_domain; the caller checked it with
     * bg_domain_validate and that it is active). BG_FUNC_NOISE: periodic noise. */
    void (*dfractal3)(const bg_fractal *f, const bg_domain *d, const float *x, const float *y,
                      const float *z, size_t n, float *v);
    void (*dfractal3_grad)(const bg_fractal *f, const bg_domain *d, const float *x,
                           const float *y, const float *z, size_t n, float *v, float *gx,
                           float *gy, float *gz);
    void (*dfractal3_grad_central)(const bg_fractal *f, const bg_domain *d, float h,
                                   const float *x, const float *y, const float *z, size_t n,
                                   float *v, float *gx, float *gy, float *gz);
    /* Name of this table's variant: the BG_ISA_SUFFIX ("c", "sse2", ..., "avx512vbmi"). */
    const char *name;
} bg_kernel_table;

/* Double-precision kernels: the same template with a one-lane double vocabulary. */
typedef struct bg_kernel_table_d {
    void (*noise3_grad)(const double *x, const double *y, const double *z, size_t n, double *v,
                        double *gx, double *gy, double *gz);
    void (*fractal3_grad)(const bg_fractal *f, const double *x, const double *y, const double *z,
                          size_t n, double *v, double *gx, double *gy, double *gz);
    void (*fractal3_grad_central)(const bg_fractal *f, double h, const double *x,
                                  const double *y, const double *z, size_t n, double *v,
                                  double *gx, double *gy, double *gz);
    void (*perturb)(bg_perturb_method m, const double *nx, const double *ny, const double *nz,
                    const double *gx, const double *gy, const double *gz, size_t n, double *ox,
                    double *oy, double *oz);
    void (*dfractal3_grad)(const bg_fractal *f, const bg_domain *d, const double *x,
                           const double *y, const double *z, size_t n, double *v, double *gx,
                           double *gy, double *gz);
} bg_kernel_table_d;

/* The table of the active ISA (bg_isa_active()); never NULL. */
const bg_kernel_table *bg_kernels(void);
/* The same, inline for the per-point entry points (noise.c): one load and one
 * test before the table's call, where a call to bg_kernels() made bg_noise3
 * spill its arguments. bg_active_table is dispatch.c's state (NULL until the
 * first call; bg_kernels() sets it). */
#include <stdatomic.h>
extern _Atomic(const bg_kernel_table *) bg_active_table;
static inline const bg_kernel_table *bg_kernels_inline(void)
{
    const bg_kernel_table *t = atomic_load_explicit(&bg_active_table, memory_order_acquire);
    return t ? t : bg_kernels();
}
/* The table of one ISA, or NULL if this build or CPU lacks it (for the harness). */
const bg_kernel_table *bg_kernels_for(bg_isa isa);
/* Every table built for `isa` that this CPU can run, the one bg_kernels_for()
 * returns first (an ISA level may have variants using an extra feature, e.g.
 * AVX-512 with VBMI; all give the same bits). Stores at most `max`, returns the
 * count (0 if the ISA is unsupported). For the harness. */
int bg_kernels_variants(bg_isa isa, const bg_kernel_table **out, int max);
/* "scalar, sse2, avx2, avx512, neon": the names of the ISA levels, lowest
 * first, comma-separated; with supported_only, only those bg_isa_supported()
 * accepts here. Truncated at a name to fit len. For messages (the CLI). */
void bg_isa_list(char *buf, size_t len, int supported_only);
/* The scalar float table (used by the single-point entry points). */
extern const bg_kernel_table bg_kernels_c;
/* Single points on the scalar float kernel, for the per-point entry points
 * (same bits as bg_kernels_c with n = 1; g = {dx, dy, dz}). */
float bg_noise3_point_c(float x, float y, float z);
float bg_noise3_grad_point_c(float x, float y, float z, float g[3]);
float bg_fractal3_point_c(const bg_fractal *f, float x, float y, float z);
float bg_fractal3_grad_point_c(const bg_fractal *f, float x, float y, float z, float g[3]);
/* The same four, compiled with the AVX2 flags (BG_HAVE_C_AVX2; only called on
 * a CPU with AVX2, through the AVX2 and AVX-512 tables). */
float bg_noise3_point_c_avx2(float x, float y, float z);
float bg_noise3_grad_point_c_avx2(float x, float y, float z, float g[3]);
float bg_fractal3_point_c_avx2(const bg_fractal *f, float x, float y, float z);
float bg_fractal3_grad_point_c_avx2(const bg_fractal *f, float x, float y, float z, float g[3]);
extern const bg_kernel_table_d bg_kernels_c64;

#endif
