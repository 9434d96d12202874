/* SPDX-License-Identifier: MIT */
/* The noise family of the kernel harness (checkkernels.h): the lookup tables,
 * Perlin's Java reference on the integer lattice, the per-point functions, the
 * scalar noise3 / noise3_grad against double (noise.h: value error <= 1e-5,
 * gradient <= 5e-5, plus the ULP bound), and noise3 / noise3_grad on every ISA. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "checkkernels.h"

/* The lookup tables the kernels use, against each other and the reference. */
static void check_tables(void)
{
    for (int i = 0; i < 512; i++) {
        int p = bg_perm512[i];
        if (p != bg_perm512[i & 255] || p != bg_perm256_u8[i & 255])
            fail("bg_perm512 / bg_perm256_u8 disagree");
#ifdef BG_HAVE_REF
        if (p != ref_permutation(i))
            fail("bg_perm512 differs from Perlin's permutation (tests/ref)");
#endif
        if (i < 256 && bg_perm_pair[i] != (p | bg_perm512[i + 1] << 8))
            fail("bg_perm_pair[i] != p[i] | p[i + 1] << 8");
        if (i < 256 && bg_perm_nib2[i] != ((p & 15) | (bg_perm512[i + 1] & 15) << 4))
            fail("bg_perm_nib2[i] != (p[i] & 15) | (p[i + 1] & 15) << 4");
        if (i < 256 && bg_perm_code2[i] != (bg_corner_code(p) | bg_corner_code(bg_perm512[i + 1]) << 4))
            fail("bg_perm_code2[i] != code(p[i]) | code(p[i + 1]) << 4");
        if (i < 256) {
            int e = bg_perm_code_hi[(i >> 5) * 16 + (i & 15)];
            if ((i & 16 ? e & 15 : e >> 4) != bg_corner_code(p))
                fail("bg_perm_code_hi: code(p[i]) not in nibble (i & 16 ? low : high) of entry 16 (i >> 5) + (i & 15)");
        }
    }
    /* The corner code against Perlin's grad, bit for bit, on offsets that
     * include both zeros: first/second axis and their signs (kernels.h). */
    const float d[] = {0.0f, -0.0f, 0.375f, -0.625f, 1.0f, -1.0f};
    for (int h = 0; h < 16; h++)
        for (int a = 0; a < 6; a++)
            for (int b = 0; b < 6; b++)
                for (int c = 0; c < 6; c++) {
                    float x = d[a], y = d[b], z = d[c];
                    float u = h < 8 ? x : y, v = h < 4 ? y : (h == 12 || h == 14 ? x : z);
                    float ref = ((h & 1) == 0 ? u : -u) + ((h & 2) == 0 ? v : -v);
                    int k = bg_corner_code(h);
                    float first = k & 8 ? y : x, second = k & 4 ? z : y;
                    float got = (k & 1 ? -first : first) + (k & 2 ? -second : second);
                    if (memcmp(&ref, &got, sizeof ref) != 0)
                        fail("bg_corner_code(h) disagrees with Perlin's grad(h, x, y, z)");
                }
}

/* Perlin's Java reference on the integer cube [0,64)^3, bit for bit including
 * the sign of zero: every fraction is 0 there, so the value is a chain of exact
 * +-0 and the sign decides (issue 13: corner hash 11 gives -y - z = -0 at
 * (0, 2, 22), and the old table-dot-product corner gave +0). tests/ref's
 * ref_noise follows the Java code literally (u/v selects, -u negation, the
 * same lerp nesting). The float kernel computes the same exact zeros, so it
 * must give the same bits too. NaN inputs must come out as the canonical NaN. */
static void check_lattice_reference(void)
{
#ifdef BG_HAVE_REF
    long bad_d = 0, bad_f = 0, negzero = 0;
    for (int i = 0; i < 64; i++)
        for (int j = 0; j < 64; j++)
            for (int k = 0; k < 64; k++) {
                double x = i, y = j, z = k, v, g[3];
                bg_kernels_c64.noise3_grad(&x, &y, &z, 1, &v, &g[0], &g[1], &g[2]);
                double r = ref_noise(x, y, z);
                uint64_t uv, ur;
                memcpy(&uv, &v, sizeof uv);
                memcpy(&ur, &r, sizeof ur);
                negzero += r == 0 && signbit(r);
                if (uv != ur && bad_d++ < 5) {
                    char msg[200];
                    snprintf(msg, sizeof msg, "double noise at (%d,%d,%d) = %a, Java reference %a",
                             i, j, k, v, r);
                    fail(msg);
                }
                float fx = (float)i, fy = (float)j, fz = (float)k, fv;
                bg_kernels_c.noise3(&fx, &fy, &fz, 1, &fv);
                if (!same_bits(fv, (float)r) && bad_f++ < 5) {
                    char msg[200];
                    snprintf(msg, sizeof msg, "float noise at (%d,%d,%d) = %a, Java reference %a",
                             i, j, k, (double)fv, r);
                    fail(msg);
                }
            }
    printf("integer cube [0,64)^3 vs the Java reference: %ld double and %ld float sign/bit "
           "mismatches (%ld reference -0)\n",
           bad_d, bad_f, negzero);
    if (negzero == 0)
        fail("no -0 on the integer cube: the reference check tests nothing");
#endif
    /* The canonical NaN, from the scalar float and double kernels. */
    static const uint32_t qnan = 0x7fc00000u;
    float nx = NAN, ny = 0.5f, nz = -INFINITY, nv, g3[3];
    bg_kernels_c.noise3_grad(&nx, &ny, &nz, 1, &nv, &g3[0], &g3[1], &g3[2]);
    uint32_t un;
    memcpy(&un, &nv, sizeof un);
    if (un != qnan)
        fail("scalar NaN result is not the canonical quiet NaN");
    nz = -NAN;
    bg_kernels_c.noise3(&nz, &ny, &ny, 1, &nv);
    memcpy(&un, &nv, sizeof un);
    if (un != qnan)
        fail("scalar noise3(-NaN) is not the canonical quiet NaN");
    double dx = INFINITY, dy = 0.25, dv, dg[3];
    bg_kernels_c64.noise3_grad(&dx, &dy, &dy, 1, &dv, &dg[0], &dg[1], &dg[2]);
    uint64_t ud;
    memcpy(&ud, &dv, sizeof ud);
    if (ud != 0x7ff8000000000000ull)
        fail("double NaN result is not the canonical quiet NaN");
}

/* The per-point functions (noise.h's bg_noise3, bg_fractal3, ...) against the
 * scalar table with n = 1, bit for bit, on the special-laden coordinates. */
static void check_point_functions(void)
{
    static const bg_fractal pf[] = {{BG_FUNC_NOISE, 1, 2.0f, 0.5f},
                                    {BG_FUNC_FBM, 6, 2.0f, 0.5f},
                                    {BG_FUNC_TURBULENCE, 5, 1.9f, 0.6f}};
    long bad = 0;
    for (int i = 0; i < 20000; i++) {
        float x = coord(), y = coord(), z = coord(), v, g[3], pg[3];
        const bg_fractal *f = &pf[i % 3];
        bg_kernels_c.noise3(&x, &y, &z, 1, &v);
        bad += !same_bits(v, bg_noise3_point_c(x, y, z));
        bg_kernels_c.noise3_grad(&x, &y, &z, 1, &v, &g[0], &g[1], &g[2]);
        float pv = bg_noise3_grad_point_c(x, y, z, pg);
        bad += !same_bits(v, pv) || !same_bits(g[0], pg[0]) || !same_bits(g[1], pg[1]) ||
               !same_bits(g[2], pg[2]);
        bg_kernels_c.fractal3(f, &x, &y, &z, 1, &v);
        bad += !same_bits(v, bg_fractal3_point_c(f, x, y, z));
        bg_kernels_c.fractal3_grad(f, &x, &y, &z, 1, &v, &g[0], &g[1], &g[2]);
        pv = bg_fractal3_grad_point_c(f, x, y, z, pg);
        bad += !same_bits(v, pv) || !same_bits(g[0], pg[0]) || !same_bits(g[1], pg[1]) ||
               !same_bits(g[2], pg[2]);
    }
    checks += 4;
    if (bad)
        fail("a per-point function differs from the scalar kernel with n = 1");
}

void check_noise(const bg_kernel_table *const *isas, int nisa)
{
    rng_seed(0x9E3779B97F4A7C15ull);
    check_tables();
    check_lattice_reference();
    check_point_functions();

    enum { N = 4000 };
    static float x[N], y[N], z[N], v[N], gx[N], gy[N], gz[N];
    for (int i = 0; i < N; i++) {
        double r = i % 4 == 0 ? 1e4 : 300; /* float spacing keeps fractions exact */
        x[i] = rng_range(-r, r), y[i] = rng_range(-r, r), z[i] = rng_range(-r, r);
    }
    /* noise.h: value error <= 1e-5, gradient <= 5e-5. */
    bg_kernels_c.noise3_grad(x, y, z, N, v, gx, gy, gz);
    maxerr_v = maxerr_g = 0;
    for (int i = 0; i < N; i++) {
        double px = x[i], py = y[i], pz = z[i], dv, dg[3];
        float pt[3] = {x[i], y[i], z[i]};
        bg_kernels_c64.noise3_grad(&px, &py, &pz, 1, &dv, &dg[0], &dg[1], &dg[2]);
        check_close("noise3_grad value vs c64", v[i], dv, 1e-5, &maxerr_v, pt);
        check_close("noise3_grad dx vs c64", gx[i], dg[0], 5e-5, &maxerr_g, pt);
        check_close("noise3_grad dy vs c64", gy[i], dg[1], 5e-5, &maxerr_g, pt);
        check_close("noise3_grad dz vs c64", gz[i], dg[2], 5e-5, &maxerr_g, pt);
#ifdef BG_HAVE_REF
        double rg[3], rv = ref_noise_grad(px, py, pz, rg);
        check_close("noise3_grad value vs ref", v[i], rv, 1e-5, &maxerr_v, pt);
        check_close("noise3_grad dx vs ref", gx[i], rg[0], 5e-5, &maxerr_g, pt);
        check_close("noise3_grad dy vs ref", gy[i], rg[1], 5e-5, &maxerr_g, pt);
        check_close("noise3_grad dz vs ref", gz[i], rg[2], 5e-5, &maxerr_g, pt);
#endif
    }
    printf("scalar noise3_grad vs double: max |value err| %.3g, max |grad err| %.3g\n", maxerr_v,
           maxerr_g);

    params p;
    memset(&p, 0, sizeof p);
    p.f = fractals[0];
    check_kernel(isas, nisa, K_NOISE3, &p, 8);
    check_kernel(isas, nisa, K_NOISE3_GRAD, &p, 8);
    p.null_first = 1;
    check_kernel(isas, nisa, K_NOISE3_GRAD, &p, 1);
    p.null_first = 0;
}
