/* SPDX-License-Identifier: MIT */
/* The perturbation family of the kernel harness (checkkernels.h): the scalar
 * perturb against double (eq. 2 / 4 and the additive rules), the fused
 * perturb_height against fractal3_grad + perturb bit for bit, then perturb and
 * perturb_height on every ISA. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "checkkernels.h"

void check_perturb(const bg_kernel_table *const *isas, int nisa)
{
    rng_seed(0x9E57B1ull);
    enum { N = 4000 };
    static float gx[N], gy[N], gz[N];
    /* Perturbation: unit normals, moderate gradients. */
    static float nx[N], ny[N], nz[N], ox[N], oy[N], oz[N];
    for (int i = 0; i < N; i++) {
        nx[i] = rng_range(-1, 1), ny[i] = rng_range(-1, 1), nz[i] = rng_range(-1, 1);
        if (fabsf(nx[i]) + fabsf(ny[i]) + fabsf(nz[i]) < 0.1f)
            nz[i] = 1;
        gx[i] = rng_range(-5, 5), gy[i] = rng_range(-5, 5), gz[i] = rng_range(-5, 5);
    }
    for (int m = 0; m < 3; m++) {
        bg_kernels_c.perturb((bg_perturb_method)m, nx, ny, nz, gx, gy, gz, N, ox, oy, oz);
        maxerr_v = 0;
        for (int i = 0; i < N; i++) {
            double dn[3] = {nx[i], ny[i], nz[i]}, dg[3] = {gx[i], gy[i], gz[i]}, dout[3];
            float pt[3] = {nx[i], ny[i], nz[i]};
            bg_kernels_c64.perturb((bg_perturb_method)m, &dn[0], &dn[1], &dn[2], &dg[0], &dg[1],
                                   &dg[2], 1, &dout[0], &dout[1], &dout[2]);
            check_close("perturb vs c64", ox[i], dout[0], 2e-6, &maxerr_v, pt);
            check_close("perturb vs c64", oy[i], dout[1], 2e-6, &maxerr_v, pt);
            check_close("perturb vs c64", oz[i], dout[2], 2e-6, &maxerr_v, pt);
#ifdef BG_HAVE_REF
            double rout[3];
            if (m == BG_PERTURB_SURFGRAD) {
                ref_perturb_surfgrad(dn, dg, rout);
            } else {
                double sg[3] = {dg[0], dg[1], dg[2]};
                if (m == BG_PERTURB_ADDITIVE_PERLIN)
                    sg[0] = -sg[0], sg[1] = -sg[1], sg[2] = -sg[2];
                ref_perturb_additive(dn, sg, rout);
            }
            check_close("perturb vs ref", ox[i], rout[0], 2e-6, &maxerr_v, pt);
            check_close("perturb vs ref", oy[i], rout[1], 2e-6, &maxerr_v, pt);
            check_close("perturb vs ref", oz[i], rout[2], 2e-6, &maxerr_v, pt);
#endif
        }
        printf("scalar perturb method %d vs double: max |err| %.3g\n", m, maxerr_v);
    }


    /* The fused kernel is exactly fractal3_grad at frequency * p, scaled by
     * amplitude * frequency, then perturb (bit for bit, scalar). */
    static float px[N], py[N], pz[N], hh[N], fx[N], fy[N], fz[N], hv[N];
    for (int i = 0; i < N; i++) {
        px[i] = rng_range(-50, 50), py[i] = rng_range(-50, 50), pz[i] = rng_range(-50, 50);
    }
    for (int m = 0; m < 3; m++) {
        bg_height hg = {{BG_FUNC_TURBULENCE, 6, 2.0f, 0.5f}, 0.1f, 1.7f, BG_GRADIENT_ANALYTIC, 0, {{0, 0, 0}, 0}};
        bg_kernels_c.perturb_height(&hg, (bg_perturb_method)m, px, py, pz, nx, ny, nz, N, hh, ox,
                                    oy, oz);
        for (int i = 0; i < N; i++)
            fx[i] = px[i] * hg.frequency, fy[i] = py[i] * hg.frequency, fz[i] = pz[i] * hg.frequency;
        bg_kernels_c.fractal3_grad(&hg.fractal, fx, fy, fz, N, hv, gx, gy, gz);
        float af = hg.amplitude * hg.frequency;
        for (int i = 0; i < N; i++)
            gx[i] *= af, gy[i] *= af, gz[i] *= af, hv[i] *= hg.amplitude;
        bg_kernels_c.perturb((bg_perturb_method)m, nx, ny, nz, gx, gy, gz, N, fx, fy, fz);
        for (int i = 0; i < N; i++)
            if (!same_bits(hh[i], hv[i]) || !same_bits(ox[i], fx[i]) || !same_bits(oy[i], fy[i]) ||
                !same_bits(oz[i], fz[i])) {
                fail("perturb_height differs from fractal3_grad + perturb");
                break;
            }
    }

    params p;
    memset(&p, 0, sizeof p);
    for (int m = 0; m < 3; m++) {
        p.m = (bg_perturb_method)m;
        check_kernel(isas, nisa, K_PERTURB, &p, 8);
    }
    static const int hf[] = {0, 3, 4, 5, 7};
    for (int m = 0; m < 3; m++)
        for (int gmode = 0; gmode < 2; gmode++)
            for (int fi = 0; fi < (int)(sizeof hf / sizeof hf[0]); fi++) {
                p.m = (bg_perturb_method)m;
                p.hg.fractal = fractals[hf[fi]];
                p.hg.gradient = (bg_gradient_mode)gmode;
                p.hg.amplitude = fi & 1 ? 0.1f : -2.5f;
                p.hg.frequency = fi == 2 ? 3.7f : 1.0f;
                p.hg.step = fi == 3 ? 0.01f : 0.0f;
                p.null_first = fi == 4;
                check_kernel(isas, nisa, K_PERTURB_HEIGHT, &p, 1);
            }
    /* Huge amplitude: gradients beyond 2^40 and overflow to Inf reach perturb. */
    p.hg.fractal = fractals[4];
    p.hg.gradient = BG_GRADIENT_ANALYTIC;
    p.hg.amplitude = 3e37f;
    p.hg.frequency = 1.0f;
    p.null_first = 0;
    for (int m = 0; m < 3; m++) {
        p.m = (bg_perturb_method)m;
        check_kernel(isas, nisa, K_PERTURB_HEIGHT, &p, 1);
    }
}
