/* SPDX-License-Identifier: MIT */
/* Tileable noise and seeded octaves (noise.h bg_domain):
 *  - every ISA and variant this machine runs equals the scalar kernel bit for
 *    bit (value, analytic and central gradients, the fused height path), on
 *    hard coordinates and every tail length;
 *  - periods of 256 and seed 0 are Perlin's noise itself, bit for bit;
 *  - a point's result does not depend on the points sharing its vector: the
 *    cells carried from octave to octave equal the quotient's;
 *  - f(p + P e_a) == f(p) bit for bit (value and gradient), float and double,
 *    for noise, fBm and turbulence with integer lacunarity, seeded or not;
 *  - value and gradient are continuous across the seam (both sides of the
 *    plane x = kP agree to the step times a bound on the second derivative);
 *  - a seed changes the pattern, seed 0 is the plain call, bad domains are
 *    refused with the documented status. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "kernels/kernels.h"
#define CHECK_RNG_SEED 0x243f6a8885a308d3ull
#include "check_standalone.h"

#define CHECK(c, what, isa) (checks++, (c) ? (void)0 : fail(what, isa))

/* v0 == v1 and (x0, y0, z0) == (x1, y1, z1) bit for bit over [0, n): a value
 * and its gradient (or a perturbed normal) against another's. */
static int same_vg(size_t n, const float *v0, const float *x0, const float *y0, const float *z0,
                   const float *v1, const float *x1, const float *y1, const float *z1)
{
    int ok = 1;
    for (size_t i = 0; i < n; i++)
        ok &= same_bits(v0[i], v1[i]) && same_bits(x0[i], x1[i]) && same_bits(y0[i], y1[i]) &&
              same_bits(z0[i], z1[i]);
    return ok;
}

/* Lattice, near-lattice, +-0, large, huge, NaN/Inf and plain points. */
static float plain_coord(unsigned k)
{
    return k == 9 ? rng_range(-3e7, 3e7) : rng_range(-300, 300);
}
static float coord(void) { return mixed_coord(20, plain_coord); }

/* A dyadic coordinate k / 1024 in [-64, 64): p + P (P <= 256) stays exact. */
static float dyadic(void) { return (float)((int)(rng_u64() % 131072) - 65536) / 1024.0f; }

static const bg_fractal fractals[] = {
    {BG_FUNC_NOISE, 1, 2.0f, 0.5f},
    {BG_FUNC_FBM, 6, 2.0f, 0.5f},
    {BG_FUNC_TURBULENCE, 6, 2.0f, 0.5f},
    {BG_FUNC_FBM, 4, 3.0f, 0.6f},
    {BG_FUNC_TURBULENCE, 3, 1.0f, 0.7f},
};
#define NF ((int)(sizeof fractals / sizeof fractals[0]))

static bg_domain random_domain(void)
{
    static const int pick[] = {0, 1, 2, 3, 4, 5, 7, 8, 16, 31, 64, 100, 128, 255, 256};
    bg_domain d;
    for (int a = 0; a < 3; a++)
        d.period[a] = pick[rng_u64() % (sizeof pick / sizeof pick[0])];
    d.seed = (rng_u64() & 1) ? (unsigned)(rng_u64() >> 40) : 0;
    if (!bg_domain_is_set(&d))
        d.period[0] = 5;
    return d;
}

#define N 203 /* not a multiple of any lane count: every tail length is hit */

/* Every table against the scalar kernel, bit for bit. */
static void check_isa(const bg_kernel_table *t)
{
    float x[N], y[N], z[N], v0[N], g0[3][N], v1[N], g1[3][N];
    for (int round = 0; round < 40; round++) {
        const bg_fractal *f = &fractals[round % NF];
        bg_domain d = random_domain();
        if (bg_domain_validate(f, &d) != BG_OK)
            continue;
        for (int i = 0; i < N; i++)
            x[i] = coord(), y[i] = coord(), z[i] = coord();
        for (size_t n = 1; n <= N; n += (n < 40 ? 1 : 27)) {
            bg_kernels_c.dfractal3_grad(f, &d, x, y, z, n, v0, g0[0], g0[1], g0[2]);
            t->dfractal3_grad(f, &d, x, y, z, n, v1, g1[0], g1[1], g1[2]);
            int ok = same_vg(n, v0, g0[0], g0[1], g0[2], v1, g1[0], g1[1], g1[2]);
            CHECK(ok, "dfractal3_grad equals the scalar kernel", t->name);
            t->dfractal3(f, &d, x, y, z, n, v1);
            ok = 1;
            for (size_t i = 0; i < n; i++)
                ok &= same_bits(v0[i], v1[i]);
            CHECK(ok, "dfractal3 equals dfractal3_grad's value", t->name);
        }
        bg_kernels_c.dfractal3_grad_central(f, &d, 1e-3f, x, y, z, N, v0, g0[0], g0[1], g0[2]);
        t->dfractal3_grad_central(f, &d, 1e-3f, x, y, z, N, v1, g1[0], g1[1], g1[2]);
        int ok = same_vg(N, v0, g0[0], g0[1], g0[2], v1, g1[0], g1[1], g1[2]);
        CHECK(ok, "dfractal3_grad_central equals the scalar kernel", t->name);

        /* The fused height path with a domain. */
        bg_height h = bg_height_default();
        h.fractal = *f, h.domain = d, h.frequency = 0.75f;
        h.gradient = (round & 1) ? BG_GRADIENT_CENTRAL : BG_GRADIENT_ANALYTIC;
        float nx[N], ny[N], nz[N], o0[3][N], o1[3][N];
        for (int i = 0; i < N; i++)
            nx[i] = 0.3f, ny[i] = -0.2f, nz[i] = 1.0f, x[i] = rng_range(-50, 50);
        bg_kernels_c.perturb_height(&h, BG_PERTURB_SURFGRAD, x, y, z, nx, ny, nz, N, v0, o0[0],
                                    o0[1], o0[2]);
        t->perturb_height(&h, BG_PERTURB_SURFGRAD, x, y, z, nx, ny, nz, N, v1, o1[0], o1[1], o1[2]);
        ok = same_vg(N, v0, o0[0], o0[1], o0[2], v1, o1[0], o1[1], o1[2]);
        CHECK(ok, "perturb_height with a domain equals the scalar kernel", t->name);
    }

    /* Periods 256 and no seed: Perlin's noise itself, through the domain
     * kernel (the period-256 wrap is the plain lattice's). */
    for (int k = 0; k < NF; k++) {
        const bg_fractal *f = &fractals[k];
        bg_domain d = {{256, 256, 256}, 0};
        for (int i = 0; i < N; i++)
            x[i] = coord(), y[i] = coord(), z[i] = coord();
        t->fractal3_grad(f, x, y, z, N, v0, g0[0], g0[1], g0[2]);
        t->dfractal3_grad(f, &d, x, y, z, N, v1, g1[0], g1[1], g1[2]);
        int ok = same_vg(N, v0, g0[0], g0[1], g0[2], v1, g1[0], g1[1], g1[2]);
        CHECK(ok, "period 256 is Perlin's noise", t->name);
    }
}

/* The cells carried from octave to octave (bump_tmpl.c octave_cell_carry)
 * equal the quotient's (lattice_per): a batch of points within the carried
 * range against the same batch with a huge coordinate in every 16th point,
 * which sends each vector holding one through the quotient in every octave.
 * Unseeded fractals with lacunarity 1 to 5 (power-of-two and not), periods
 * that are not powers of two, deep octaves and untiled axes, in the carried
 * range (octaves chosen so that it applies: every period P L^i <= 2^22). The
 * scalar table has one lane, where the two batches are one, so it is left
 * out. */
static void check_carry(const bg_kernel_table *t)
{
    enum { M = 64 };
    static const float lacs[] = {2, 3, 1, 4, 5};
    static const int pers[] = {0, 3, 5, 7, 10, 12, 16, 100, 255};
    float x[M], y[M], z[M], xq[M], v0[M], g0[3][M], v1[M], g1[3][M];
    for (int round = 0; round < 80; round++) {
        bg_fractal f = {(round & 1) ? BG_FUNC_FBM : BG_FUNC_TURBULENCE, 2, lacs[round % 5], 0.5f};
        bg_domain d = {{0, 0, 0}, 0};
        for (int a = 0; a < 3; a++)
            d.period[a] = pers[rng_u64() % (sizeof pers / sizeof pers[0])];
        d.period[0] = 10 + (int)(rng_u64() % 3); /* one period not a power of two */
        if (round < 20) /* an untiled axis at deep octaves (small periods) */
            d.period[1] = 0, d.period[2] = (round & 2) ? 0 : 3;
        /* as many octaves as the domain and the carry allow, up to 20 */
        int pmax = d.period[0] > d.period[1] ? d.period[0] : d.period[1];
        pmax = pmax > d.period[2] ? pmax : d.period[2];
        for (int o = 20; o >= 2; o--) {
            f.octaves = o;
            if (bg_domain_validate(&f, &d) == BG_OK &&
                pmax * pow(f.lacunarity, o - 1) <= 4194304.0)
                break;
        }
        double top = pow(f.lacunarity, f.octaves - 1), lim = floor(4194304.0 / top) - 1;
        if (lim < 1)
            lim = 1;
        for (int i = 0; i < M; i++) {
            double r = (i & 1) ? lim : (lim < 4 ? lim : 4); /* small points too */
            x[i] = rng_range(-r, r), y[i] = rng_range(-r, r), z[i] = rng_range(-r, r);
            if (i % 4 == 2) {
                /* just below a multiple of the period, where a rounding of
                 * x L^i up to the next period's start would show */
                int m = (int)(rng_u64() % 9) - 4, k = 1 + (int)(rng_u64() % 3);
                float e = (float)d.period[0] * (float)m;
                while (k--)
                    e = nextafterf(e, -INFINITY);
                if (fabs(e) < lim)
                    x[i] = e;
            }
            xq[i] = i % 16 == 15 ? 3e7f : x[i];
        }
        t->dfractal3_grad(&f, &d, x, y, z, M, v0, g0[0], g0[1], g0[2]);
        t->dfractal3_grad(&f, &d, xq, y, z, M, v1, g1[0], g1[1], g1[2]);
        int ok = 1;
        for (int i = 0; i < M; i++)
            if (i % 16 != 15)
                ok &= same_vg(1, v0 + i, g0[0] + i, g0[1] + i, g0[2] + i, v1 + i, g1[0] + i,
                              g1[1] + i, g1[2] + i);
        CHECK(ok, "carried cells equal the quotient's (value and gradient)", t->name);
        t->dfractal3(&f, &d, xq, y, z, M, v1);
        t->dfractal3(&f, &d, x, y, z, M, v0);
        ok = 1;
        for (int i = 0; i < M; i++)
            if (i % 16 != 15)
                ok &= same_bits(v0[i], v1[i]);
        CHECK(ok, "carried cells equal the quotient's (value)", t->name);
    }
}

/* f(p + P e_a) == f(p), and the seam's continuity, through the public calls. */
static void check_periodic(void)
{
    enum { M = 256 };
    float x[M], y[M], z[M], xs[M], v0[M], g0[3][M], v1[M], g1[3][M];
    for (int round = 0; round < 60; round++) {
        const bg_fractal *f = &fractals[round % 4]; /* integer lacunarity >= 2 */
        bg_domain d = random_domain();
        for (int a = 0; a < 3; a++)
            if (!d.period[a])
                d.period[a] = 1 + (int)(rng_u64() % 256);
        CHECK(bg_domain_validate(f, &d) == BG_OK, "domain accepted", "api");
        for (int i = 0; i < M; i++)
            x[i] = dyadic(), y[i] = dyadic(), z[i] = dyadic();
        bg_fractal3_domain_grad_batch(f, &d, x, y, z, M, v0, g0[0], g0[1], g0[2]);
        for (int a = 0; a < 3; a++) {
            float *c = a == 0 ? x : a == 1 ? y : z;
            memcpy(xs, c, sizeof xs);
            for (int i = 0; i < M; i++)
                xs[i] = c[i] + (float)(d.period[a] * (1 + (int)(rng_u64() % 2)));
            bg_fractal3_domain_grad_batch(f, &d, a == 0 ? xs : x, a == 1 ? xs : y, a == 2 ? xs : z,
                                          M, v1, g1[0], g1[1], g1[2]);
            int ok = same_vg(M, v0, g0[0], g0[1], g0[2], v1, g1[0], g1[1], g1[2]);
            CHECK(ok, "f(p + P e_a) == f(p) (float)", "api");
        }
        /* double */
        for (int i = 0; i < 16; i++) {
            bg_dvec3 ga, gb;
            double px = x[i], py = y[i], pz = z[i];
            double va = bg_fractal3d_domain_grad(f, &d, px, py, pz, &ga);
            double vb = bg_fractal3d_domain_grad(f, &d, px + 2.0 * d.period[0], py - d.period[1],
                                                 pz + d.period[2], &gb);
            CHECK(va == vb && ga.x == gb.x && ga.y == gb.y && ga.z == gb.z && !isnan(va),
                  "f(p + P) == f(p) (double)", "api");
        }
        /* The seam: x = kP approached from both sides. Noise's second
         * derivatives are below 100 per unit (fade'' <= 5.8 times corner
         * differences <= 4, times the octave factor L^i for octave i). */
        const float eps = 0x1p-16f;
        float lmax = 1;
        for (int i = 1; i < (f->function == BG_FUNC_NOISE ? 1 : f->octaves); i++)
            lmax *= f->lacunarity;
        for (int a = 0; a < 3; a++) {
            float xa[M], xb[M], va[M], vb[M], ga[3][M], gb[3][M];
            float *other[3] = {x, y, z};
            for (int i = 0; i < M; i++) {
                float s = (float)(d.period[a] * ((int)(rng_u64() % 5) - 2));
                xa[i] = s - eps, xb[i] = s + eps;
            }
            float *pa[3] = {other[0], other[1], other[2]}, *pb[3] = {other[0], other[1], other[2]};
            pa[a] = xa, pb[a] = xb;
            bg_fractal3_domain_grad_batch(f, &d, pa[0], pa[1], pa[2], M, va, ga[0], ga[1], ga[2]);
            bg_fractal3_domain_grad_batch(f, &d, pb[0], pb[1], pb[2], M, vb, gb[0], gb[1], gb[2]);
            double worst_v = 0, worst_g = 0;
            for (int i = 0; i < M; i++) {
                worst_v = fmax(worst_v, fabs((double)va[i] - vb[i]));
                for (int c = 0; c < 3; c++)
                    worst_g = fmax(worst_g, fabs((double)ga[c][i] - gb[c][i]));
            }
            /* Turbulence has creases (|n|'s gradient flips sign at n = 0):
             * only its value is continuous. */
            CHECK(worst_v <= 2 * eps * 9 * 2 * lmax, "value continuous across the seam", "api");
            if (f->function != BG_FUNC_TURBULENCE)
                CHECK(worst_g <= 2 * eps * 100 * 2 * lmax * lmax, "gradient continuous across the seam",
                      "api");
        }
    }
    /* The seam matters: without the wrap (period 0) the same points jump. */
    {
        const bg_fractal *f = &fractals[0];
        bg_domain d = {{7, 0, 0}, 0};
        int jumps = 0;
        for (int i = 0; i < 200; i++) {
            float yy = dyadic(), zz = dyadic();
            float a = bg_fractal3_domain(f, &d, 7 - 0x1p-16f, yy, zz);
            float b = bg_fractal3_domain(f, &d, 7 + 0x1p-16f, yy, zz);
            float c = bg_noise3(7 + 0x1p-16f, yy, zz);
            CHECK(fabsf(a - b) < 1e-3f, "pnoise continuous at x = 7", "api");
            jumps += fabsf(a - c) > 1e-2f;
        }
        CHECK(jumps > 100, "the wrap changes the corners at the seam", "api");
    }
}

static void check_api(void)
{
    enum { M = 301 };
    float x[M], y[M], z[M], v0[M], v1[M], g0[3][M], g1[3][M];
    for (int i = 0; i < M; i++)
        x[i] = rng_range(-40, 40), y[i] = rng_range(-40, 40), z[i] = rng_range(-40, 40);
    bg_fractal f = bg_fractal_default(BG_FUNC_TURBULENCE);
    /* The default domain is the plain call, bit for bit. */
    bg_domain d0 = {{0, 0, 0}, 0};
    bg_fractal3_grad_batch(&f, x, y, z, M, v0, g0[0], g0[1], g0[2]);
    bg_fractal3_domain_grad_batch(&f, &d0, x, y, z, M, v1, g1[0], g1[1], g1[2]);
    int ok = 1;
    for (int i = 0; i < M; i++)
        ok &= same_bits(v0[i], v1[i]) && same_bits(g0[0][i], g1[0][i]);
    CHECK(ok, "the default domain is the plain fractal", "api");
    /* A seed changes the pattern; different seeds differ. */
    bg_domain d1 = {{0, 0, 0}, 1}, d2 = {{0, 0, 0}, 2};
    bg_fractal3_domain_batch(&f, &d1, x, y, z, M, v1);
    int differ = 0;
    for (int i = 0; i < M; i++)
        differ += fabsf(v0[i] - v1[i]) > 1e-3f;
    CHECK(differ > M * 9 / 10, "seed 1 changes the pattern", "api");
    bg_fractal3_domain_batch(&f, &d2, x, y, z, M, v0);
    differ = 0;
    for (int i = 0; i < M; i++)
        differ += fabsf(v0[i] - v1[i]) > 1e-3f;
    CHECK(differ > M * 9 / 10, "seeds 1 and 2 differ", "api");
    /* Each octave is still Perlin's noise of a moved point: a one-octave
     * seeded fractal is the noise at p + o_0. */
    bg_fractal one = {BG_FUNC_FBM, 1, 2.0f, 0.5f};
    for (int i = 0; i < 50; i++) {
        float a = bg_fractal3_domain(&one, &d1, x[i], y[i], z[i]);
        float b = bg_noise3(x[i] + bg_domain_offset(1, 0, 0), y[i] + bg_domain_offset(1, 0, 1),
                            z[i] + bg_domain_offset(1, 0, 2));
        CHECK(same_bits(a, b), "seeded octave 0 is noise(p + o_0)", "api");
    }
    /* Offsets: multiples of 1/256 in [0, 32), 0 for seed 0. */
    for (int s = 0; s < 100; s++)
        for (int a = 0; a < 3; a++) {
            float o = bg_domain_offset((unsigned)s * 7919u, s % 32, a);
            CHECK(o >= 0 && o < 32 && o * 256 == floorf(o * 256) && (s || o == 0), "offset range",
                  "api");
        }
    /* Point calls equal the batch; pnoise with periods 256 is bg_noise3; the
     * double pnoise with periods 256 is Perlin's reference. */
    int p256[3] = {256, 256, 256}, p5[3] = {5, 3, 200};
    for (int i = 0; i < 50; i++) {
        bg_vec3 g;
        CHECK(same_bits(bg_pnoise3(x[i], y[i], z[i], p256), bg_noise3(x[i], y[i], z[i])),
              "pnoise 256 == noise", "api");
        CHECK(bg_pnoise3d(x[i], y[i], z[i], p256) == bg_noise3d(x[i], y[i], z[i]),
              "pnoise3d 256 == noise3d", "api");
        float pv = bg_pnoise3_grad(x[i], y[i], z[i], p5, &g), bv, bg[3];
        bg_pnoise3_grad_batch(p5, &x[i], &y[i], &z[i], 1, &bv, &bg[0], &bg[1], &bg[2]);
        CHECK(same_bits(pv, bv) && same_bits(g.x, bg[0]) && same_bits(g.z, bg[2]),
              "pnoise point == batch", "api");
        bg_dvec3 gd;
        double dv = bg_pnoise3d_grad(x[i], y[i], z[i], p5, &gd);
        CHECK(fabs(dv - pv) < 1e-5 && fabs(gd.x - g.x) < 5e-5, "pnoise float vs double", "api");
    }
    /* Refusals: the documented statuses, nothing written. */
    bg_domain bad[] = {{{257, 1, 1}, 0}, {{-1, 0, 0}, 0}, {{0, 0, 300}, 3}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        v0[0] = 42;
        CHECK(bg_fractal3_domain_batch(&f, &bad[k], x, y, z, 4, v0) == BG_ERR_INVALID_ARGUMENT &&
                  v0[0] == 42,
              "bad period refused", "api");
        CHECK(isnan(bg_fractal3_domain(&f, &bad[k], 1, 2, 3)), "bad period point is NaN", "api");
    }
    bg_fractal lac25 = {BG_FUNC_FBM, 4, 2.5f, 0.5f};
    bg_domain dp = {{4, 4, 4}, 0};
    CHECK(bg_domain_validate(&lac25, &dp) == BG_ERR_INVALID_ARGUMENT, "non-integer lacunarity",
          "api");
    CHECK(bg_domain_validate(&lac25, &d1) == BG_OK, "seed only: any lacunarity", "api");
    bg_fractal deep = {BG_FUNC_FBM, 32, 2.0f, 0.5f};
    CHECK(bg_domain_validate(&deep, &dp) == BG_ERR_INVALID_ARGUMENT, "finest period above 2^24",
          "api");
    CHECK(bg_fractal3_domain_batch(&f, NULL, x, y, z, 4, v0) == BG_ERR_NULL_POINTER, "NULL domain",
          "api");
    CHECK(bg_pnoise3_batch(NULL, x, y, z, 4, v0) == BG_ERR_NULL_POINTER, "NULL period", "api");
    CHECK(isnan(bg_pnoise3(1, 2, 3, NULL)), "NULL period point is NaN", "api");
    /* bg_height_eval follows the domain like the fused batch. */
    bg_height h = bg_height_default();
    h.domain = (bg_domain){{8, 8, 0}, 9};
    CHECK(bg_height_validate(&h) == BG_OK, "height with a domain", "api");
    float nx[M], ny[M], nz[M], hh[M], o[3][M];
    for (int i = 0; i < M; i++)
        nx[i] = 0, ny[i] = 0, nz[i] = 1;
    bg_perturb_height_batch(&h, BG_PERTURB_SURFGRAD, x, y, z, nx, ny, nz, M, hh, o[0], o[1], o[2]);
    for (int i = 0; i < 40; i++) {
        bg_vec3 g, p = {x[i], y[i], z[i]};
        CHECK(same_bits(bg_height_eval(&h, p, &g), hh[i]), "bg_height_eval == fused batch", "api");
    }
}

int main(void)
{
    const bg_kernel_table *tabs[BG_ISA_COUNT + 4];
    int nt = bg_kernels_variants(BG_ISA_SCALAR, tabs, BG_ISA_COUNT + 4);
    for (int i = BG_ISA_SCALAR + 1; i < BG_ISA_COUNT; i++)
        nt += bg_kernels_variants((bg_isa)i, tabs + nt, BG_ISA_COUNT + 4 - nt);
    for (int i = 0; i < nt; i++) {
        check_isa(tabs[i]);
        if (tabs[i] != &bg_kernels_c)
            check_carry(tabs[i]);
        printf("%-12s domain kernels checked\n", tabs[i]->name);
    }
    check_periodic();
    check_api();
    printf("%ld checks, %ld failures\n", checks, failures);
    return failures ? 1 : 0;
}
