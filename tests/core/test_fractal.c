/* SPDX-License-Identifier: MIT */
/* fBm and turbulence (values and analytic gradients) against the independent
 * double reference, and the central-difference gradient: its division by the
 * step actually taken, and its accuracy at a fixed step. */
#include <math.h>
#include <stdio.h>
#include "bumpgrad.h"
#include "ref.h"
#include "check.h"

#define FLOAT_VALUE_TOL 1e-5
#define FLOAT_GRAD_TOL 5e-5
#define DOUBLE_TOL 1e-12
/* Points where any octave's |noise| is below this are skipped for turbulence:
 * float rounding may flip the sign of an octave there, and the gradient jumps. */
#define CREASE_MARGIN 1e-4

static ref_fractal to_ref(const bg_fractal *f)
{
    ref_fractal r = {(enum ref_function)f->function, f->octaves, f->lacunarity, f->gain};
    return r;
}

static double point_coord(ref_rng *r, int cls, double large)
{
    switch (cls) {
    case 0: return ref_rng_uniform(r, -100, 100);
    case 1: return floor(ref_rng_uniform(r, -100, 100)) + (ref_rng_uniform(r, 0, 1) < 0.5 ? 1e-6 : -1e-6);
    case 2: return -ref_rng_uniform(r, 0, 1e4);
    default: {
        double m = exp(ref_rng_uniform(r, 0, log(large)));
        return ref_rng_uniform(r, 0, 1) < 0.5 ? -m : m;
    }
    }
}
static const char *const cls_name[4] = {"random [-100,100]", "x near-lattice",
                                        "negative [-1e4,0)", "large"};

static void test_float(bg_function fn, const char *name)
{
    bg_fractal f = bg_fractal_default(fn);
    ref_fractal rf = to_ref(&f);
    ref_rng r;
    ref_rng_seed(&r, 21 + (unsigned)fn);
    printf("float %s (%d octaves) vs reference, tolerances value %.0e, gradient %.0e:\n", name,
           f.octaves, FLOAT_VALUE_TOL, FLOAT_GRAD_TOL);
    for (int cls = 0; cls < 4; cls++) {
        double maxv = 0, maxg = 0;
        int n = 0, skipped = 0;
        for (int i = 0; i < 2000; i++) {
            /* near-lattice in x only: with all three near the lattice every
             * octave of turbulence sits on a crease and nothing would be checked */
            int cy = cls == 1 ? 0 : cls;
            float x = cls == 1 ? check_near_lattice_f(&r) : check_to_float(point_coord(&r, cls, 1e4)),
                  y = check_to_float(point_coord(&r, cy, 1e4)),
                  z = check_to_float(point_coord(&r, cy, 1e4));
            double rg[3], minabs;
            double rv = ref_fractal_grad(&rf, x, y, z, rg, &minabs);
            bg_vec3 g;
            float v = bg_fractal3_grad(&f, x, y, z, &g);
            float v1 = bg_fractal3(&f, x, y, z);
            CHECK(v1 == v, "%s value-only %a != value with gradient %a", name, v1, v);
            double ev = fabs(v - rv);
            CHECK(ev <= FLOAT_VALUE_TOL, "%s value at (%.9g,%.9g,%.9g): err %.3g", name, x, y, z, ev);
            maxv = fmax(maxv, ev);
            if (fn == BG_FUNC_TURBULENCE && minabs < CREASE_MARGIN) {
                skipped++;
                continue;
            }
            double eg = fmax(fmax(fabs(g.x - rg[0]), fabs(g.y - rg[1])), fabs(g.z - rg[2]));
            CHECK(eg <= FLOAT_GRAD_TOL, "%s gradient at (%.9g,%.9g,%.9g): err %.3g", name, x, y,
                  z, eg);
            maxg = fmax(maxg, eg);
            n++;
        }
        printf("  %-20s max |value err| %.3g, max |grad err| %.3g over %d points (%d near a "
               "crease skipped)\n", cls_name[cls], maxv, maxg, n, skipped);
    }
}

static void test_double(bg_fractal f, const char *name)
{
    ref_fractal rf = to_ref(&f);
    ref_rng r;
    ref_rng_seed(&r, 31 + (unsigned)f.function);
    double maxv = 0, maxg = 0;
    int n = 0, skipped = 0;
    for (int cls = 0; cls < 4; cls++)
        for (int i = 0; i < 1000; i++) {
            double large = 4503599627370496.0; /* 2^52 */
            double x = point_coord(&r, cls, large), y = point_coord(&r, cls, large),
                   z = point_coord(&r, cls, large);
            double rg[3], minabs;
            double rv = ref_fractal_grad(&rf, x, y, z, rg, &minabs);
            bg_dvec3 g;
            double v = bg_fractal3d_grad(&f, x, y, z, &g);
            double v1 = bg_fractal3d(&f, x, y, z);
            CHECK(v1 == v, "double value-only differs");
            double ev = fabs(v - rv);
            CHECK(ev <= DOUBLE_TOL, "double %s value err %.3g", name, ev);
            maxv = fmax(maxv, ev);
            if (f.function == BG_FUNC_TURBULENCE && minabs < 1e-9) {
                skipped++;
                continue;
            }
            double eg = fmax(fmax(fabs(g.x - rg[0]), fabs(g.y - rg[1])), fabs(g.z - rg[2]));
            CHECK(eg <= DOUBLE_TOL, "double %s gradient at (%.17g,%.17g,%.17g): err %.3g", name,
                  x, y, z, eg);
            maxg = fmax(maxg, eg);
            n++;
        }
    printf("double %s (%d octaves, lacunarity %g, gain %g), all classes up to |x| = 2^52: max "
           "|value err| %.3g, max |grad err| %.3g over %d points (%d skipped), tolerance %.0e\n",
           name, f.octaves, (double)f.lacunarity, (double)f.gain, maxv, maxg, n, skipped,
           DOUBLE_TOL);
}

/* The documented formula: (F(x+h) - F(x-h)) / ((x+h) - (x-h)). At x = 3000 the
 * float spacing is 2^-12, so x +- 1e-3 rounds and the step taken is not 2h;
 * dividing by 2h instead would be off by that ratio. */
static void test_central_step_taken(void)
{
    bg_fractal f = bg_fractal_default(BG_FUNC_FBM);
    ref_fractal rf = to_ref(&f);
    ref_rng r;
    ref_rng_seed(&r, 41);
    const float h = 1e-3f;
    int n = 0, bits_equal = 0, closer = 0;
    double max_ratio_dev = 0, err_taken = 0, err_nominal = 0;
    for (int i = 0; i < 500; i++) {
        float x = check_to_float(ref_rng_uniform(&r, 3000, 3100)),
              y = check_to_float(ref_rng_uniform(&r, -3, 3)), z = check_to_float(ref_rng_uniform(&r, -3, 3));
        float xp = x + h, xm = x - h;
        float taken = xp - xm;
        if (taken == 2 * h)
            continue;
        n++;
        max_ratio_dev = fmax(max_ratio_dev, fabs(taken / (2 * h) - 1));
        bg_vec3 g;
        bg_fractal3_grad_central(&f, h, x, y, z, &g);
        /* The same quotient formed from the library's own values: an identity. */
        float expect = (bg_fractal3(&f, xp, y, z) - bg_fractal3(&f, xm, y, z)) / taken;
        if (g.x == expect)
            bits_equal++;
        double rg[3];
        ref_fractal_grad(&rf, x, y, z, rg, NULL);
        double nominal = (double)g.x * taken / (2 * h);
        double et = fabs(g.x - rg[0]), en = fabs(nominal - rg[0]);
        err_taken += et, err_nominal += en;
        if (et < en)
            closer++;
    }
    printf("central difference at x in [3000, 3100], h = 1e-3 (float): %d points with (x+h)-(x-h) "
           "!= 2h (up to %.1f%% off); gx == (F(x+h)-F(x-h))/((x+h)-(x-h)) bitwise at %d; mean "
           "|err| vs reference %.3g dividing by the step taken, %.3g if divided by 2h (closer "
           "at %d)\n", n, 100 * max_ratio_dev, bits_equal, err_taken / n, err_nominal / n, closer);
    CHECK(n >= 400, "too few points with a rounded step (%d)", n);
    CHECK(bits_equal == n, "central gradient is not divided by the step taken (%d of %d)",
          bits_equal, n);
    CHECK(err_taken < 0.2 * err_nominal, "dividing by the taken step should be much closer");

    /* Double: at x ~ 2^40 the spacing is 2^-12 as well. */
    int nd = 0, eqd = 0;
    for (int i = 0; i < 200; i++) {
        double x = 1099511627776.0 + ref_rng_uniform(&r, 0, 100), y = ref_rng_uniform(&r, -3, 3),
               z = ref_rng_uniform(&r, -3, 3), hd = 1e-3;
        double xp = x + hd, xm = x - hd, taken = xp - xm;
        if (taken == 2 * hd)
            continue;
        nd++;
        bg_dvec3 g;
        bg_fractal3d_grad_central(&f, hd, x, y, z, &g);
        double expect = (bg_fractal3d(&f, xp, y, z) - bg_fractal3d(&f, xm, y, z)) / taken;
        if (g.x == expect)
            eqd++;
    }
    printf("double central difference at x ~ 2^40, h = 1e-3: %d points with a rounded step, "
           "divided by the step taken at %d\n", nd, eqd);
    CHECK(nd >= 150 && eqd == nd, "double central step");
}

/* Central differences are a truncation/rounding trade-off, so their accuracy is
 * checked at fixed steps against bounds measured with accuracy_table (about 3x
 * above the measured maxima, see docs/ACCURACY.md). */
static void test_central_accuracy(void)
{
    struct {
        bg_function fn;
        float h;
        double tol;
    } cases[] = {{BG_FUNC_NOISE, 2e-3f, 1e-3}, {BG_FUNC_FBM, 2e-4f, 1.2e-2},
                 {BG_FUNC_TURBULENCE, 2e-4f, 1.2e-2}};
    for (int c = 0; c < 3; c++) {
        bg_fractal f = bg_fractal_default(cases[c].fn);
        ref_fractal rf = to_ref(&f);
        ref_rng r;
        ref_rng_seed(&r, 51 + (unsigned)c);
        double maxg = 0, h = cases[c].h;
        int n = 0;
        for (int i = 0; i < 2000; i++) {
            float x = check_to_float(ref_rng_uniform(&r, -100, 100)),
                  y = check_to_float(ref_rng_uniform(&r, -100, 100)),
                  z = check_to_float(ref_rng_uniform(&r, -100, 100));
            double rg[3], minabs;
            ref_fractal_grad(&rf, x, y, z, rg, &minabs);
            if (cases[c].fn == BG_FUNC_TURBULENCE) {
                /* skip stencils that straddle a crease */
                unsigned long m = ref_fractal_sign_mask(&rf, x, y, z);
                int clean = minabs >= CREASE_MARGIN;
                for (int a = 0; a < 3 && clean; a++)
                    for (int s = -1; s <= 1; s += 2) {
                        double q[3] = {x, y, z};
                        q[a] += s * h;
                        clean &= ref_fractal_sign_mask(&rf, q[0], q[1], q[2]) == m;
                    }
                if (!clean)
                    continue;
            }
            bg_vec3 g;
            bg_fractal3_grad_central(&f, cases[c].h, x, y, z, &g);
            double eg = fmax(fmax(fabs(g.x - rg[0]), fabs(g.y - rg[1])), fabs(g.z - rg[2]));
            CHECK(eg <= cases[c].tol, "central err %.3g at (%.9g,%.9g,%.9g)", eg, x, y, z);
            maxg = fmax(maxg, eg);
            n++;
        }
        printf("float central gradient, %s, h = %g: max |err| %.3g over %d points (bound %.3g)\n",
               c == 0 ? "noise" : c == 1 ? "fBm" : "turbulence", h, maxg, n, cases[c].tol);
        CHECK(n > 1000, "too few points");
    }
}

int main(void)
{
    test_float(BG_FUNC_FBM, "fBm");
    test_float(BG_FUNC_TURBULENCE, "turbulence");
    bg_fractal f = bg_fractal_default(BG_FUNC_FBM);
    test_double(f, "fBm");
    f.function = BG_FUNC_TURBULENCE;
    test_double(f, "turbulence");
    f.octaves = 9, f.lacunarity = 1.9f, f.gain = 0.6f;
    test_double(f, "turbulence");
    f.function = BG_FUNC_FBM;
    test_double(f, "fBm");
    test_central_step_taken();
    test_central_accuracy();
    return check_summary("test_fractal");
}
