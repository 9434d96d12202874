/* SPDX-License-Identifier: MIT */
/* Improved noise and its analytic gradient against the independent double
 * reference (tests/ref), plus identities that need no reference: the published
 * value, zeros on the lattice, period 256, NaN propagation. */
#include <math.h>
#include <stdio.h>
#include "bumpgrad.h"
#include "ref.h"
#include "check.h"

#define FLOAT_VALUE_TOL 1e-5
#define FLOAT_GRAD_TOL 5e-5
#define DOUBLE_GRAD_TOL 1e-12

enum { CLASS_RANDOM, CLASS_NEAR_LATTICE, CLASS_NEGATIVE, CLASS_LARGE, CLASS_COUNT };
static const char *const class_name[CLASS_COUNT] = {"random [-300,300]", "near-lattice",
                                                    "negative [-1e4,0)", "large"};

/* One coordinate of a test point of class `c`; `max_large` bounds the large class. */
static double coord(ref_rng *r, int c, double max_large)
{
    switch (c) {
    case CLASS_RANDOM: return ref_rng_uniform(r, -300, 300);
    case CLASS_NEAR_LATTICE: {
        double k = floor(ref_rng_uniform(r, -300, 300));
        double d = ref_rng_uniform(r, 0, 1) < 0.5 ? 1e-6 : -1e-6;
        return ref_rng_uniform(r, 0, 1) < 0.25 ? k : k + d;
    }
    case CLASS_NEGATIVE: return -ref_rng_uniform(r, 1e-3, 1e4);
    default: {
        /* log-uniform magnitude so every binade up to max_large is visited */
        double m = exp(ref_rng_uniform(r, log(1.0), log(max_large)));
        return ref_rng_uniform(r, 0, 1) < 0.5 ? -m : m;
    }
    }
}

static void test_published_value(void)
{
    double v = bg_noise3d(3.14, 42, 7);
    printf("bg_noise3d(3.14, 42, 7) = %.17g, published 0.13691995878400012\n", v);
    CHECK(v == 0.13691995878400012, "published value: got %.17g", v);
    bg_dvec3 g;
    double v2 = bg_noise3d_grad(3.14, 42, 7, &g);
    CHECK(v2 == v, "bg_noise3d_grad value %.17g differs from bg_noise3d", v2);
}

static void test_float_against_ref(void)
{
    printf("float noise and analytic gradient vs double reference "
           "(tolerances value %.0e, gradient %.0e):\n", FLOAT_VALUE_TOL, FLOAT_GRAD_TOL);
    ref_rng r;
    ref_rng_seed(&r, 11);
    for (int c = 0; c < CLASS_COUNT; c++) {
        double maxv = 0, maxg = 0;
        int n = 4000;
        for (int i = 0; i < n; i++) {
            float x, y, z;
            if (c == CLASS_NEAR_LATTICE)
                x = check_near_lattice_f(&r), y = check_near_lattice_f(&r), z = check_near_lattice_f(&r);
            else
                x = check_to_float(coord(&r, c, 1e4)), y = check_to_float(coord(&r, c, 1e4)),
                z = check_to_float(coord(&r, c, 1e4));
            bg_vec3 g;
            float v = bg_noise3_grad(x, y, z, &g);
            float v1 = bg_noise3(x, y, z);
            double rg[3];
            double rv = ref_noise_grad(x, y, z, rg);
            CHECK(v == v1, "bg_noise3 %a != bg_noise3_grad value %a at (%a,%a,%a)", v1, v, x, y, z);
            double ev = fabs(v - rv);
            double eg = fmax(fmax(fabs(g.x - rg[0]), fabs(g.y - rg[1])), fabs(g.z - rg[2]));
            if (!(ev <= FLOAT_VALUE_TOL) || !(eg <= FLOAT_GRAD_TOL))
                CHECK(0, "(%.9g, %.9g, %.9g): value err %.3g grad err %.3g", x, y, z, ev, eg);
            maxv = fmax(maxv, ev), maxg = fmax(maxg, eg);
        }
        printf("  %-22s %5d points: max |value err| %.3g, max |grad err| %.3g\n",
               class_name[c], n, maxv, maxg);
    }
}

static void test_double_against_ref(void)
{
    printf("double noise (must equal the reference exactly) and gradient (tol %.0e):\n",
           DOUBLE_GRAD_TOL);
    ref_rng r;
    ref_rng_seed(&r, 12);
    for (int c = 0; c < CLASS_COUNT; c++) {
        double maxg = 0;
        int n = 4000, unequal = 0;
        for (int i = 0; i < n; i++) {
            double max_large = 4503599627370496.0; /* 2^52 */
            double x = coord(&r, c, max_large), y = coord(&r, c, max_large),
                   z = coord(&r, c, max_large);
            bg_dvec3 g;
            double v = bg_noise3d_grad(x, y, z, &g);
            double rg[3];
            double rv = ref_noise_grad(x, y, z, rg);
            if (v != rv) {
                unequal++;
                CHECK(0, "double value (%.17g,%.17g,%.17g): %.17g != ref %.17g", x, y, z, v, rv);
            }
            double eg = fmax(fmax(fabs(g.x - rg[0]), fabs(g.y - rg[1])), fabs(g.z - rg[2]));
            CHECK(eg <= DOUBLE_GRAD_TOL, "double grad (%.17g,%.17g,%.17g): err %.3g", x, y, z, eg);
            maxg = fmax(maxg, eg);
        }
        printf("  %-22s %5d points: %d values differ from ref, max |grad err| %.3g%s\n",
               class_name[c], n, unequal, maxg, c == CLASS_LARGE ? " (|x| up to 2^52)" : "");
    }
}

static void test_lattice_zero(void)
{
    int nf = 0, nd = 0, badf = 0, badd = 0;
    const double big[] = {65536.0, 16777216.0, -16777216.0, 4503599627370496.0, -1e15};
    for (int i = -260; i <= 260; i += 3)
        for (int j = -260; j <= 260; j += 5)
            for (int k = -9; k <= 9; k++) {
                int kk = k * 29;
                float v = bg_noise3((float)i, (float)j, (float)kk);
                bg_vec3 g;
                float vg = bg_noise3_grad((float)i, (float)j, (float)kk, &g);
                nf++;
                if (v != 0 || vg != 0)
                    badf++;
                double vd = bg_noise3d(i, j, kk);
                nd++;
                if (vd != 0)
                    badd++;
            }
    /* Large lattice points: every representable integer is a lattice point. */
    for (int a = 0; a < 5; a++)
        for (int b = 0; b < 5; b++) {
            double vd = bg_noise3d(big[a], big[b], -big[(a + b) % 5]);
            nd++;
            if (vd != 0)
                badd++;
            if (fabs(big[a]) <= 16777216.0 && fabs(big[b]) <= 16777216.0) {
                float v = bg_noise3((float)big[a], (float)big[b], 7.0f);
                nf++;
                if (v != 0)
                    badf++;
            }
        }
    printf("noise at lattice points: float %d points, %d nonzero; double %d points, %d nonzero\n",
           nf, badf, nd, badd);
    CHECK(badf == 0 && badd == 0, "noise must be exactly 0 at every lattice point");
}

static void test_period(void)
{
    /* Dyadic coordinates (k/1024 with |k/1024| < 1000) stay exact after +-256 in
     * float, so the fraction is identical and the noise must be bit-identical. */
    ref_rng r;
    ref_rng_seed(&r, 13);
    int n = 0, badf = 0, badd = 0;
    for (int i = 0; i < 3000; i++) {
        float p[3];
        for (int a = 0; a < 3; a++)
            p[a] = (float)(floor(ref_rng_uniform(&r, -700, 700) * 1024) / 1024);
        float v = bg_noise3(p[0], p[1], p[2]);
        double vd = bg_noise3d(p[0], p[1], p[2]);
        for (int axis = 0; axis < 3; axis++)
            for (int s = -1; s <= 1; s += 2) {
                float q[3] = {p[0], p[1], p[2]};
                q[axis] += (float)(256 * s);
                n++;
                if (bg_noise3(q[0], q[1], q[2]) != v)
                    badf++;
                double qd[3] = {p[0], p[1], p[2]};
                qd[axis] += 256.0 * s * 1024 * 1024; /* also a multiple of 256 */
                if (bg_noise3d(qd[0], qd[1], qd[2]) != vd)
                    badd++;
            }
    }
    printf("period 256 per axis: %d shifted points, float mismatches %d, double (shift 2^28) "
           "mismatches %d\n", n, badf, badd);
    CHECK(badf == 0 && badd == 0, "period 256 broken");
}

static void test_nonfinite(void)
{
    const float bad[] = {NAN, INFINITY, -INFINITY};
    int n = 0, fails = 0;
    for (int b = 0; b < 3; b++)
        for (int axis = 0; axis < 3; axis++) {
            float p[3] = {1.25f, -3.5f, 7.75f};
            p[axis] = bad[b];
            bg_vec3 g;
            float v = bg_noise3(p[0], p[1], p[2]);
            float vg = bg_noise3_grad(p[0], p[1], p[2], &g);
            bg_dvec3 gd;
            double vd = bg_noise3d(p[0], p[1], p[2]);
            double vdg = bg_noise3d_grad(p[0], p[1], p[2], &gd);
            float vb, gbx, gby, gbz;
            bg_noise3_grad_batch(&p[0], &p[1], &p[2], 1, &vb, &gbx, &gby, &gbz);
            bg_fractal fb = bg_fractal_default(BG_FUNC_FBM);
            bg_fractal ft = bg_fractal_default(BG_FUNC_TURBULENCE);
            bg_vec3 gf;
            float vf = bg_fractal3_grad(&ft, p[0], p[1], p[2], &gf);
            float vf2 = bg_fractal3(&fb, p[0], p[1], p[2]);
            n++;
            int ok = isnan(v) && isnan(vg) && isnan(g.x) && isnan(g.y) && isnan(g.z) &&
                     isnan(vd) && isnan(vdg) && isnan(gd.x) && isnan(gd.y) && isnan(gd.z) &&
                     isnan(vb) && isnan(gbx) && isnan(gby) && isnan(gbz) && isnan(vf) &&
                     isnan(gf.x) && isnan(gf.y) && isnan(gf.z) && isnan(vf2);
            if (!ok) {
                fails++;
                CHECK(0, "non-finite coordinate %g on axis %d did not give NaN everywhere "
                         "(float %g, double %g, batch %g, turbulence %g)", (double)bad[b], axis,
                      (double)v, vd, (double)vb, (double)vf);
            }
        }
    printf("NaN/Inf coordinates: %d cases (float, double, batch, fractal), %d without NaN\n", n,
           fails);
}

static void test_validate(void)
{
    bg_fractal f = bg_fractal_default(BG_FUNC_FBM);
    int ok = bg_fractal_validate(&f) == BG_OK;
    f.octaves = 0;
    ok &= bg_fractal_validate(&f) == BG_ERR_INVALID_ARGUMENT;
    f.octaves = BG_MAX_OCTAVES;
    ok &= bg_fractal_validate(&f) == BG_OK;
    f.octaves = BG_MAX_OCTAVES + 1;
    ok &= bg_fractal_validate(&f) == BG_ERR_INVALID_ARGUMENT;
    f.octaves = 6;
    f.lacunarity = 0;
    ok &= bg_fractal_validate(&f) == BG_ERR_INVALID_ARGUMENT;
    f.lacunarity = -2;
    ok &= bg_fractal_validate(&f) == BG_ERR_INVALID_ARGUMENT;
    f.lacunarity = NAN;
    ok &= bg_fractal_validate(&f) == BG_ERR_INVALID_ARGUMENT;
    f.lacunarity = INFINITY;
    ok &= bg_fractal_validate(&f) == BG_ERR_INVALID_ARGUMENT;
    f.lacunarity = 1.5f;
    f.gain = INFINITY;
    ok &= bg_fractal_validate(&f) == BG_ERR_INVALID_ARGUMENT;
    f.gain = NAN;
    ok &= bg_fractal_validate(&f) == BG_ERR_INVALID_ARGUMENT;
    f.gain = -0.5f; /* any finite gain is allowed */
    ok &= bg_fractal_validate(&f) == BG_OK;
    f.function = (bg_function)7;
    ok &= bg_fractal_validate(&f) == BG_ERR_INVALID_ARGUMENT;
    ok &= bg_fractal_validate(NULL) == BG_ERR_NULL_POINTER;
    bg_fractal nz = bg_fractal_default(BG_FUNC_NOISE);
    nz.octaves = 0; /* ignored for plain noise */
    ok &= bg_fractal_validate(&nz) == BG_OK;

    bg_height h = bg_height_default();
    ok &= bg_height_validate(&h) == BG_OK;
    ok &= bg_height_validate(NULL) == BG_ERR_NULL_POINTER;
    bg_height t = h;
    t.amplitude = NAN;
    ok &= bg_height_validate(&t) == BG_ERR_INVALID_ARGUMENT;
    t = h, t.frequency = INFINITY;
    ok &= bg_height_validate(&t) == BG_ERR_INVALID_ARGUMENT;
    t = h, t.step = -1e-3f;
    ok &= bg_height_validate(&t) == BG_ERR_INVALID_ARGUMENT;
    t = h, t.step = NAN;
    ok &= bg_height_validate(&t) == BG_ERR_INVALID_ARGUMENT;
    t = h, t.step = 0; /* 0 means the default step */
    ok &= bg_height_validate(&t) == BG_OK;
    t = h, t.gradient = (bg_gradient_mode)5;
    ok &= bg_height_validate(&t) == BG_ERR_INVALID_ARGUMENT;
    t = h, t.fractal.octaves = 99;
    ok &= bg_height_validate(&t) == BG_ERR_INVALID_ARGUMENT;
    printf("bg_fractal_validate / bg_height_validate accept and reject the documented ranges: %s\n",
           ok ? "yes" : "NO");
    CHECK(ok, "validate ranges");
}

int main(void)
{
    test_published_value();
    test_float_against_ref();
    test_double_against_ref();
    test_lattice_zero();
    test_period();
    test_nonfinite();
    test_validate();
    return check_summary("test_noise");
}
