/* SPDX-License-Identifier: MIT */
/* The fractal family of the kernel harness (checkkernels.h): the scalar
 * fractal3 / fractal3_grad / fractal3_grad_central against double, then the three
 * kernels on every ISA for every parameter set. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "checkkernels.h"

/* Smallest |octave| of a fractal at a point, from the double kernels: points near
 * a turbulence crease have a sign-dependent gradient, skip them. */
static double min_abs_octave(const bg_fractal *f, double x, double y, double z)
{
    double freq = 1, m = INFINITY;
    int oct = f->function == BG_FUNC_NOISE ? 1 : f->octaves;
    for (int i = 0; i < oct; i++) {
        double px = x * freq, py = y * freq, pz = z * freq, v, g[3];
        bg_kernels_c64.noise3_grad(&px, &py, &pz, 1, &v, &g[0], &g[1], &g[2]);
        if (fabs(v) < m)
            m = fabs(v);
        freq *= f->lacunarity;
    }
    return m;
}

void check_fractal(const bg_kernel_table *const *isas, int nisa)
{
    rng_seed(0xF4AC7A1ull);
    enum { N = 4000 };
    static float x[N], y[N], z[N], v[N], gx[N], gy[N], gz[N];
    /* Fractals: lacunarity 2 keeps the float octave coordinates exact for these
     * ranges, so the error is the per-octave noise error times sum gain^i (value)
     * or sum gain^i lac^i (gradient). */
    static const bg_fractal ff[] = {{BG_FUNC_FBM, 6, 2.0f, 0.5f},
                                    {BG_FUNC_TURBULENCE, 6, 2.0f, 0.5f},
                                    {BG_FUNC_FBM, 3, 2.0f, 0.75f}};
    for (int fi = 0; fi < 3; fi++) {
        const bg_fractal *f = &ff[fi];
        double sa = 0, saf = 0, a = 1, q = 1;
        for (int o = 0; o < f->octaves; o++, a *= f->gain, q *= f->lacunarity)
            sa += a, saf += a * q;
        for (int i = 0; i < N; i++) {
            double r = 100;
            x[i] = rng_range(-r, r), y[i] = rng_range(-r, r), z[i] = rng_range(-r, r);
        }
        bg_kernels_c.fractal3_grad(f, x, y, z, N, v, gx, gy, gz);
        maxerr_v = maxerr_g = 0;
        for (int i = 0; i < N; i++) {
            double px = x[i], py = y[i], pz = z[i], dv, dg[3];
            float pt[3] = {x[i], y[i], z[i]};
            if (f->function == BG_FUNC_TURBULENCE && min_abs_octave(f, px, py, pz) < 1e-4)
                continue;
            bg_kernels_c64.fractal3_grad(f, &px, &py, &pz, 1, &dv, &dg[0], &dg[1], &dg[2]);
            check_close("fractal3_grad value vs c64", v[i], dv, 1e-5 * sa, &maxerr_v, pt);
            for (int c = 0; c < 3; c++)
                check_close("fractal3_grad gradient vs c64", (c == 0 ? gx : c == 1 ? gy : gz)[i],
                            dg[c], 5e-5 * saf, &maxerr_g, pt);
#ifdef BG_HAVE_REF
            ref_fractal rf = {(enum ref_function)f->function, f->octaves, f->lacunarity, f->gain};
            double rg[3], rv = ref_fractal_grad(&rf, px, py, pz, rg, NULL);
            check_close("fractal3_grad value vs ref", v[i], rv, 1e-5 * sa, &maxerr_v, pt);
            for (int c = 0; c < 3; c++)
                check_close("fractal3_grad gradient vs ref", (c == 0 ? gx : c == 1 ? gy : gz)[i],
                            rg[c], 5e-5 * saf, &maxerr_g, pt);
#endif
        }
        printf("scalar fractal3_grad (func %d, %d octaves) vs double: max |value err| %.3g, max "
               "|grad err| %.3g\n",
               (int)f->function, f->octaves, maxerr_v, maxerr_g);
        /* The value-only kernel gives the same bits as the gradient kernel's value. */
        static float v2[N];
        bg_kernels_c.fractal3(f, x, y, z, N, v2);
        for (int i = 0; i < N; i++)
            if (!same_bits(v[i], v2[i])) {
                fail("fractal3 value differs from fractal3_grad value");
                break;
            }
    }

    /* Central differences: the same step in double; the float error is the value
     * rounding divided by the step, about 1e-7 / 4e-3 per unit of amp * freq. */
    {
        bg_fractal f = {BG_FUNC_FBM, 3, 2.0f, 0.5f};
        float h = 2e-3f; /* explicit: the bound below is for this step */
        for (int i = 0; i < N; i++)
            x[i] = rng_range(-20, 20), y[i] = rng_range(-20, 20), z[i] = rng_range(-20, 20);
        bg_kernels_c.fractal3_grad_central(&f, h, x, y, z, N, v, gx, gy, gz);
        maxerr_v = maxerr_g = 0;
        for (int i = 0; i < N; i++) {
            double px = x[i], py = y[i], pz = z[i], dv, dg[3];
            float pt[3] = {x[i], y[i], z[i]};
            bg_kernels_c64.fractal3_grad_central(&f, h, &px, &py, &pz, 1, &dv, &dg[0], &dg[1],
                                                 &dg[2]);
            check_close("fractal3_grad_central value vs c64", v[i], dv, 2e-5, &maxerr_v, pt);
            /* No ULP bound: a difference quotient's error is the value's
             * rounding over the step, not a few ULP of the quotient. */
            for (int c = 0; c < 3; c++)
                check_close_u("fractal3_grad_central gradient vs c64",
                              (c == 0 ? gx : c == 1 ? gy : gz)[i], dg[c], 2e-3, 0, &maxerr_g, pt);
        }
        printf("scalar fractal3_grad_central (fbm 3) vs double: max |value err| %.3g, max |grad "
               "err| %.3g\n",
               maxerr_v, maxerr_g);
    }


    params p;
    memset(&p, 0, sizeof p);
    for (int f = 0; f < n_fractals; f++) {
        p.f = fractals[f];
        check_kernel(isas, nisa, K_FRACTAL3, &p, 1);
        check_kernel(isas, nisa, K_FRACTAL3_GRAD, &p, 1);
        p.h = f & 1 ? 1e-2f : BG_DEFAULT_CENTRAL_STEP;
        check_kernel(isas, nisa, K_FRACTAL3_CENTRAL, &p, 1);
    }
    p.f = fractals[3];
    p.null_first = 1;
    check_kernel(isas, nisa, K_FRACTAL3_GRAD, &p, 0);
    check_kernel(isas, nisa, K_FRACTAL3_CENTRAL, &p, 0);
    p.null_first = 0;
}
