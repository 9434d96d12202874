/* SPDX-License-Identifier: MIT */
/* The per-point fractal functions (octaves across lanes) and the grid entry
 * points (noise.h) against the batch kernels, bit for bit, on every ISA and
 * variant this machine runs; the grid calls' argument checks. Issue 10. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "kernels/kernels.h"
#define CHECK_RNG_SEED 0x9e3779b97f4a7c15ull
#include "check_standalone.h"

/* Lattice, near-lattice, +-0, large, huge, NaN/Inf, subnormal and plain points. */
static float plain_coord(unsigned k)
{
    switch (k) {
    case 9: return 1e-40f;
    case 10: return 255.99998f;
    case 11: return rng_range(-1, 1);
    default: return rng_range(-300, 300);
    }
}
static float coord(void) { return mixed_coord(24, plain_coord); }

/* Octave counts around every lane count (1, 4, 8, 16: chunks of 1, tails),
 * both sums, lacunarities and gains that are not powers of two. */
static const bg_fractal fractals[] = {
    {BG_FUNC_NOISE, 1, 2.0f, 0.5f},       {BG_FUNC_FBM, 1, 2.0f, 0.5f},
    {BG_FUNC_FBM, 2, 2.0f, 0.5f},         {BG_FUNC_FBM, 3, 1.7f, 0.6f},
    {BG_FUNC_FBM, 6, 2.0f, 0.5f},         {BG_FUNC_FBM, 8, 2.5f, -0.7f},
    {BG_FUNC_FBM, 9, 1.9f, 0.55f},        {BG_FUNC_FBM, 17, 0.5f, 2.0f},
    {BG_FUNC_FBM, 32, 1.1f, 0.9f},        {BG_FUNC_TURBULENCE, 4, 2.0f, 0.5f},
    {BG_FUNC_TURBULENCE, 6, 2.0f, 0.5f},  {BG_FUNC_TURBULENCE, 5, 1.9f, 0.6f},
    {BG_FUNC_TURBULENCE, 13, 2.1f, 0.45f},
};
#define NFRACTALS (sizeof fractals / sizeof fractals[0])

/* Every table's noise3_point / noise3_grad_point (on AVX2 and AVX-512 the
 * one-lane kernel compiled with the AVX2 flags) and fractal3_point /
 * fractal3_grad_point against the scalar point functions (which checkkernels ties to the batch with n = 1), and the public
 * bg_fractal3(_grad) against bg_kernels_c.fractal3(_grad) with n = 1. */
static void check_points(const bg_kernel_table *t)
{
    long bad = 0, badpub = 0;
    for (int r = 0; r < 6000; r++) {
        const bg_fractal *f = &fractals[r % NFRACTALS];
        float x = coord(), y = coord(), z = coord(), g[3], pg[3], v, pv;
        bad += !same_bits(t->noise3_point(x, y, z), bg_noise3_point_c(x, y, z));
        v = bg_noise3_grad_point_c(x, y, z, g);
        pv = t->noise3_grad_point(x, y, z, pg);
        bad += !same_bits(v, pv) || !same_bits(g[0], pg[0]) || !same_bits(g[1], pg[1]) ||
               !same_bits(g[2], pg[2]);
        bad += !same_bits(t->fractal3_point(f, x, y, z), bg_fractal3_point_c(f, x, y, z));
        v = bg_fractal3_grad_point_c(f, x, y, z, g);
        pv = t->fractal3_grad_point(f, x, y, z, pg);
        bad += !same_bits(v, pv) || !same_bits(g[0], pg[0]) || !same_bits(g[1], pg[1]) ||
               !same_bits(g[2], pg[2]);
        if (t == bg_kernels()) {
            bg_vec3 q;
            bg_kernels_c.fractal3(f, &x, &y, &z, 1, &v);
            badpub += !same_bits(v, bg_fractal3(f, x, y, z));
            bg_kernels_c.fractal3_grad(f, &x, &y, &z, 1, &v, &g[0], &g[1], &g[2]);
            pv = bg_fractal3_grad(f, x, y, z, &q);
            badpub += !same_bits(v, pv) || !same_bits(g[0], q.x) || !same_bits(g[1], q.y) ||
                      !same_bits(g[2], q.z);
        }
    }
    checks += 2;
    if (bad)
        fail("noise3_point / fractal3_point (or their _grad) differ from the scalar point function",
             t->name);
    if (badpub)
        fail("bg_fractal3 / bg_fractal3_grad differ from the scalar kernel with n = 1", t->name);
}

#define GUARD 8
static const float canary = -12345.678f;

/* An output of n floats between GUARD canaries on each side. */
static float *out_alloc(size_t n)
{
    float *p = malloc((n + 2 * GUARD) * sizeof *p);
    if (!p) {
        fprintf(stderr, "out of memory\n");
        exit(1);
    }
    for (size_t i = 0; i < n + 2 * GUARD; i++)
        p[i] = canary;
    return p + GUARD;
}
static int guards_ok(const float *p, size_t n)
{
    for (size_t i = 0; i < GUARD; i++)
        if (!same_bits(p[-1 - (long)i], canary) || !same_bits(p[n + i], canary))
            return 0;
    return 1;
}
static int untouched(const float *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!same_bits(p[i], canary))
            return 0;
    return guards_ok(p, n);
}

/* Odd counts (tails of every length on every ISA), rows shorter than a vector,
 * one row longer than the 512-point chunk, negative / zero / tiny steps, large
 * origins, a step that crosses the float spacing. */
static const bg_grid3 grids[] = {
    {{0.5, -1.25, 3.0}, {0.37, 0.21, 0.9}, {1, 1, 1}},
    {{-3.1, 2.2, 0.0}, {0.1, -0.3, 0.05}, {7, 3, 2}},
    {{10.0, 0.0, -4.0}, {-0.77, 0.0, 0.5}, {17, 1, 5}},
    {{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, {1, 33, 1}},
    {{-64.0, 5.5, 9.0}, {0.25, 0.125, 1.5}, {513, 2, 1}},
    {{1e6, -2e5, 3.3}, {0.03, 7.0, 0.011}, {3, 5, 37}},
    {{255.5, -0.0, 0.0}, {1e-7, 1e-3, 0.0}, {9, 9, 3}},
    {{-0.5, 0.5, 1e7}, {0.5, 0.5, 0.5}, {31, 4, 4}},
};
#define NGRIDS (sizeof grids / sizeof grids[0])

static size_t grid_n(const bg_grid3 *g)
{
    return g->count[0] * g->count[1] * g->count[2];
}

/* noise.h's coordinates, written out independently of noise.c. */
static void grid_points(const bg_grid3 *g, float *x, float *y, float *z)
{
    size_t o = 0;
    for (size_t k = 0; k < g->count[2]; k++)
        for (size_t j = 0; j < g->count[1]; j++)
            for (size_t i = 0; i < g->count[0]; i++, o++) {
                x[o] = (float)(g->origin[0] + (double)i * g->step[0]);
                y[o] = (float)(g->origin[1] + (double)j * g->step[1]);
                z[o] = (float)(g->origin[2] + (double)k * g->step[2]);
            }
}

static int same_array(const float *a, const float *b, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!same_bits(a[i], b[i]))
            return 0;
    return 1;
}

/* The grid calls against the batch calls on the same points, with the active
 * ISA (the caller forces each level). */
static void check_grids(const char *isa)
{
    for (size_t gi = 0; gi < NGRIDS; gi++) {
        const bg_grid3 *g = &grids[gi];
        size_t n = grid_n(g);
        float *x = out_alloc(n), *y = out_alloc(n), *z = out_alloc(n);
        float *bv = out_alloc(n), *bx = out_alloc(n), *by = out_alloc(n), *bz = out_alloc(n);
        float *v = out_alloc(n), *gx = out_alloc(n), *gy = out_alloc(n), *gz = out_alloc(n);
        grid_points(g, x, y, z);
        checks++;
        if (bg_noise3_batch(x, y, z, n, bv) != BG_OK || bg_noise3_grid(g, v) != BG_OK ||
            !same_array(bv, v, n) || !guards_ok(v, n))
            fail("bg_noise3_grid differs from bg_noise3_batch", isa);
        for (size_t fi = 0; fi < NFRACTALS; fi += 2) {
            const bg_fractal *f = &fractals[fi];
            checks += 2;
            if (bg_fractal3_batch(f, x, y, z, n, bv) != BG_OK ||
                bg_fractal3_grid(f, g, v) != BG_OK || !same_array(bv, v, n) || !guards_ok(v, n))
                fail("bg_fractal3_grid differs from bg_fractal3_batch", isa);
            if (bg_fractal3_grad_batch(f, x, y, z, n, bv, bx, by, bz) != BG_OK ||
                bg_fractal3_grad_grid(f, g, v, gx, gy, gz) != BG_OK || !same_array(bv, v, n) ||
                !same_array(bx, gx, n) || !same_array(by, gy, n) || !same_array(bz, gz, n) ||
                !guards_ok(v, n) || !guards_ok(gx, n) || !guards_ok(gy, n) || !guards_ok(gz, n))
                fail("bg_fractal3_grad_grid differs from bg_fractal3_grad_batch", isa);
            /* value is optional */
            if (bg_fractal3_grad_grid(f, g, NULL, gx, gy, gz) != BG_OK || !same_array(bx, gx, n))
                fail("bg_fractal3_grad_grid with value NULL", isa);
        }
        float *all[] = {x, y, z, bv, bx, by, bz, v, gx, gy, gz};
        for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
            free(all[i] - GUARD);
    }
}

static void expect(bg_status got, bg_status want, const char *what)
{
    checks++;
    if (got != want) {
        char msg[160];
        snprintf(msg, sizeof msg, "%s: status %d, expected %d", what, (int)got, (int)want);
        fail(msg, "checks");
    }
}

/* noise.h's check order; nothing is written on any error. */
static void check_arguments(void)
{
    const bg_fractal fbm = bg_fractal_default(BG_FUNC_FBM);
    const bg_fractal bad_oct = {BG_FUNC_FBM, 0, 2.0f, 0.5f};
    const bg_fractal bad_fn = {(bg_function)7, 6, 2.0f, 0.5f};
    const bg_fractal ovf = {BG_FUNC_FBM, 32, 2.0f, 3e38f};
    bg_grid3 g = {{0, 0, 0}, {0.5, 0.5, 0.5}, {4, 3, 2}};
    float *v = out_alloc(24), *gx = out_alloc(24), *gy = out_alloc(24), *gz = out_alloc(24);

    expect(bg_noise3_grid(NULL, v), BG_ERR_NULL_POINTER, "noise grid NULL");
    expect(bg_fractal3_grid(&fbm, NULL, v), BG_ERR_NULL_POINTER, "fractal grid NULL");
    expect(bg_fractal3_grad_grid(&fbm, NULL, v, gx, gy, gz), BG_ERR_NULL_POINTER,
           "grad grid NULL");
    expect(bg_noise3_grid(&g, NULL), BG_ERR_NULL_POINTER, "noise grid, NULL value");
    expect(bg_fractal3_grid(NULL, &g, v), BG_ERR_NULL_POINTER, "fractal grid, NULL f");
    expect(bg_fractal3_grid(&fbm, &g, NULL), BG_ERR_NULL_POINTER, "fractal grid, NULL value");
    expect(bg_fractal3_grad_grid(&fbm, &g, v, gx, NULL, gz), BG_ERR_NULL_POINTER,
           "grad grid, NULL gy");
    expect(bg_fractal3_grad_grid(NULL, &g, v, gx, gy, gz), BG_ERR_NULL_POINTER,
           "grad grid, NULL f");
    expect(bg_fractal3_grid(&bad_oct, &g, v), BG_ERR_INVALID_ARGUMENT, "0 octaves");
    expect(bg_fractal3_grad_grid(&bad_fn, &g, v, gx, gy, gz), BG_ERR_INVALID_ARGUMENT,
           "unknown function");
    expect(bg_fractal3_grid(&ovf, &g, v), BG_ERR_OVERFLOW, "overflowing fractal");

    bg_grid3 e = g;
    e.count[1] = 0; /* no sample: nothing else is read */
    expect(bg_noise3_grid(&e, NULL), BG_OK, "empty noise grid, NULL value");
    expect(bg_fractal3_grid(NULL, &e, NULL), BG_OK, "empty fractal grid, NULL f");
    expect(bg_fractal3_grad_grid(&bad_oct, &e, NULL, NULL, NULL, NULL), BG_OK,
           "empty grad grid, bad f");
    e.origin[0] = NAN;
    expect(bg_noise3_grid(&e, v), BG_OK, "empty grid, NaN origin");

    bg_grid3 o = g;
    o.count[0] = SIZE_MAX / 2, o.count[1] = 3;
    expect(bg_noise3_grid(&o, v), BG_ERR_OVERFLOW, "count product overflows size_t");
    o.count[0] = SIZE_MAX / sizeof(float) / 3 + 1, o.count[1] = 3, o.count[2] = 1;
    expect(bg_fractal3_grid(&fbm, &o, v), BG_ERR_OVERFLOW, "output bytes overflow size_t");
    o.count[0] = SIZE_MAX, o.count[1] = 1, o.count[2] = 0;
    expect(bg_noise3_grid(&o, NULL), BG_OK, "huge count times 0");

    bg_grid3 nf = g;
    nf.origin[2] = NAN;
    expect(bg_noise3_grid(&nf, v), BG_ERR_INVALID_ARGUMENT, "NaN origin");
    nf = g, nf.step[0] = INFINITY;
    expect(bg_fractal3_grid(&fbm, &nf, v), BG_ERR_INVALID_ARGUMENT, "Inf step");
    nf = g, nf.step[1] = -INFINITY;
    expect(bg_fractal3_grad_grid(&fbm, &nf, v, gx, gy, gz), BG_ERR_INVALID_ARGUMENT,
           "-Inf step");
    /* the descriptor is checked before the grid's values */
    expect(bg_fractal3_grid(&ovf, &nf, v), BG_ERR_OVERFLOW, "overflowing f and bad step");
    checks++;
    if (!untouched(v, 24) || !untouched(gx, 24) || !untouched(gy, 24) || !untouched(gz, 24))
        fail("a failed grid call wrote an output", "checks");
    free(v - GUARD), free(gx - GUARD), free(gy - GUARD), free(gz - GUARD);
}

int main(void)
{
    const bg_kernel_table *tabs[BG_ISA_COUNT + 4];
    int nt = bg_kernels_variants(BG_ISA_SCALAR, tabs, BG_ISA_COUNT + 4);
    for (int i = BG_ISA_SCALAR + 1; i < BG_ISA_COUNT; i++)
        nt += bg_kernels_variants((bg_isa)i, tabs + nt, BG_ISA_COUNT + 4 - nt);
    for (int i = 0; i < nt; i++)
        check_points(tabs[i]);
    for (int i = 0; i < BG_ISA_COUNT; i++) {
        if (!bg_isa_supported((bg_isa)i))
            continue;
        if (bg_isa_force((bg_isa)i) != BG_OK || bg_isa_active() != (bg_isa)i) {
            fail("could not force the level", bg_isa_name((bg_isa)i));
            continue;
        }
        check_points(bg_kernels());
        check_grids(bg_isa_name((bg_isa)i));
    }
    check_arguments();
    printf("check_grid: %d tables, %ld checks, %ld failures\n", nt, checks, failures);
    return failures ? 1 : 0;
}
