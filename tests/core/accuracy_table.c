/* SPDX-License-Identifier: MIT */
/* Prints the accuracy tables of docs/ACCURACY.md (markdown): float and double
 * noise / fBm / turbulence values and gradients (analytic and central) against
 * the independent double reference, and the float central-difference gradient
 * error as a function of the step h (the U-curve the default step is chosen
 * from). A measurement, not a test: it never fails on numbers.
 *
 * Usage: accuracy_table [points] [stream]    (defaults 20000, 1; stream numbers the pseudo-random inputs) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "bumpgrad.h"
#include "ref.h"

/* Turbulence has a crease wherever an octave crosses zero; the gradient is
 * undefined there and a central difference across it measures the jump, not
 * an error. Points closer than this (in |noise_i|) to a crease are skipped, and
 * for central differences also points whose stencil straddles one. */
#define CREASE_MARGIN 1e-4

typedef struct stats {
    double max_v, sum_v, max_g, sum_g;
    long n, skipped, vanished;
} stats;

static void add(stats *s, double ev, double eg)
{
    s->max_v = fmax(s->max_v, ev), s->sum_v += ev;
    s->max_g = fmax(s->max_g, eg), s->sum_g += eg;
    s->n++;
}

static ref_fractal to_ref(const bg_fractal *f)
{
    ref_fractal r = {(enum ref_function)f->function, f->octaves, f->lacunarity, f->gain};
    return r;
}

/* 1 if no octave changes sign over the 7-point stencil of step h at p. */
static int stencil_clean(const ref_fractal *rf, double x, double y, double z, double h)
{
    unsigned long m = ref_fractal_sign_mask(rf, x, y, z);
    double p[3] = {x, y, z};
    for (int a = 0; a < 3; a++)
        for (int s = -1; s <= 1; s += 2) {
            double q[3] = {p[0], p[1], p[2]};
            q[a] += s * h;
            if (ref_fractal_sign_mask(rf, q[0], q[1], q[2]) != m)
                return 0;
        }
    return 1;
}

/* Through a volatile: gcc 12 was seen folding (double)(float)x back to x at
 * some uses (see tests/core/check.h), which would measure a different point. */
static float to_float(double v)
{
    volatile float f = (float)v;
    return f;
}

/* A step below half the float spacing of a coordinate is no step: x+h == x-h,
 * and the library reports 0 for that component (noise.h). Such points are
 * counted apart, so that the table shows where the step stops working instead
 * of mixing those zeros into the error statistics. */
static int step_vanishes(float x, float y, float z, float h)
{
    return (x + h) - (x - h) == 0 || (y + h) - (y - h) == 0 || (z + h) - (z - h) == 0;
}

static double grad_err3(double gx, double gy, double gz, const double r[3])
{
    return fmax(fmax(fabs(gx - r[0]), fabs(gy - r[1])), fabs(gz - r[2]));
}

/* mode 0 analytic, 1 central with step h; prec 0 float, 1 double */
static stats measure(const bg_fractal *f, int mode, int prec, double h, long npts,
                     unsigned long long seed, double range)
{
    stats s = {0, 0, 0, 0, 0, 0, 0};
    ref_rng r;
    ref_rng_seed(&r, seed);
    ref_fractal rf = to_ref(f);
    for (long i = 0; i < npts; i++) {
        double x = ref_rng_uniform(&r, -range, range), y = ref_rng_uniform(&r, -range, range),
               z = ref_rng_uniform(&r, -range, range);
        if (!prec) /* the reference sees exactly the float point the library sees */
            x = to_float(x), y = to_float(y), z = to_float(z);
        double rg[3], minabs;
        double rv = ref_fractal_grad(&rf, x, y, z, rg, &minabs);
        if (f->function == BG_FUNC_TURBULENCE &&
            (minabs < CREASE_MARGIN || (mode == 1 && !stencil_clean(&rf, x, y, z, h)))) {
            s.skipped++;
            continue;
        }
        if (mode == 1 && prec == 0 && step_vanishes((float)x, (float)y, (float)z, (float)h)) {
            s.vanished++;
            continue;
        }
        double v, g[3];
        if (prec == 0) {
            bg_vec3 gf;
            v = mode ? bg_fractal3_grad_central(f, (float)h, (float)x, (float)y, (float)z, &gf)
                     : bg_fractal3_grad(f, (float)x, (float)y, (float)z, &gf);
            g[0] = gf.x, g[1] = gf.y, g[2] = gf.z;
        } else {
            bg_dvec3 gd;
            v = mode ? bg_fractal3d_grad_central(f, h, x, y, z, &gd)
                     : bg_fractal3d_grad(f, x, y, z, &gd);
            g[0] = gd.x, g[1] = gd.y, g[2] = gd.z;
        }
        add(&s, fabs(v - rv), grad_err3(g[0], g[1], g[2], rg));
    }
    return s;
}

int main(int argc, char **argv)
{
    long npts = argc > 1 ? atol(argv[1]) : 20000;
    unsigned long long seed = argc > 2 ? strtoull(argv[2], NULL, 10) : 1;
    if (npts <= 0) {
        fprintf(stderr, "usage: accuracy_table [points > 0] [stream]\n");
        return 2;
    }
    const char *fname[3] = {"noise", "fBm", "turbulence"};
    bg_fractal fr[3] = {bg_fractal_default(BG_FUNC_NOISE), bg_fractal_default(BG_FUNC_FBM),
                        bg_fractal_default(BG_FUNC_TURBULENCE)};
    const double range = 100;

    printf("bumpgrad %s, %ld random points per row in [-%g, %g]^3, random stream %llu; fBm and "
           "turbulence: %d octaves, lacunarity %g, gain %g.\n"
           "Errors are absolute, against tests/ref (double); gradient error is the largest "
           "component error. Turbulence skips points within %g of a crease.\n\n",
           bg_version_string(), npts, range, range, seed, fr[1].octaves,
           (double)fr[1].lacunarity, (double)fr[1].gain, CREASE_MARGIN);

    printf("### Values and gradients\n\n");
    printf("| function | precision | gradient | max value err | mean value err | "
           "max grad err | mean grad err | points (skipped) |\n");
    printf("|---|---|---|---|---|---|---|---|\n");
    for (int fi = 0; fi < 3; fi++)
        for (int prec = 0; prec < 2; prec++)
            for (int mode = 0; mode < 2; mode++) {
                double h = prec ? 1e-5 : BG_DEFAULT_CENTRAL_STEP;
                stats s = measure(&fr[fi], mode, prec, h, npts, seed, range);
                char gname[64];
                if (mode)
                    snprintf(gname, sizeof gname, "central h=%g", h);
                else
                    snprintf(gname, sizeof gname, "analytic");
                printf("| %s | %s | %s | %.3g | %.3g | %.3g | %.3g | %ld (%ld) |\n", fname[fi],
                       prec ? "double" : "float", gname, s.max_v, s.n ? s.sum_v / s.n : 0,
                       s.max_g, s.n ? s.sum_g / s.n : 0, s.n, s.skipped);
            }

    printf("\n### Float central-difference gradient error against the step h\n\n"
           "Each cell: max / mean gradient error over %ld points with coordinates in "
           "[-R, R]^3.\n\n", npts / 4);
    struct col {
        int fi;
        double range;
    } cols[] = {{0, 100}, {1, 1}, {1, 100}, {1, 1000}, {2, 100}};
    enum { NCOL = sizeof cols / sizeof cols[0] };
    double best_h[NCOL], best_mean[NCOL];
    printf("| h |");
    for (int c = 0; c < NCOL; c++) {
        printf(" %s, R=%g |", fname[cols[c].fi], cols[c].range);
        best_h[c] = 0, best_mean[c] = INFINITY;
    }
    printf("\n|---|");
    for (int c = 0; c < NCOL; c++)
        printf("---|");
    printf("\n");
    const double mant[] = {1, 2, 5};
    for (int e = -6; e <= -1; e++)
        for (int m = 0; m < 3; m++) {
            double h = mant[m] * pow(10, e);
            if (h > 0.1 * 1.0000001)
                break;
            h = (double)(float)h;
            printf("| %.0e |", h);
            for (int c = 0; c < NCOL; c++) {
                stats s = measure(&fr[cols[c].fi], 1, 0, h, npts / 4, seed + 7, cols[c].range);
                double mean = s.n ? s.sum_g / s.n : NAN;
                if (s.n)
                    printf(" %.2g / %.2g", s.max_g, mean);
                else /* every stencil straddles a turbulence crease at this h */
                    printf(" - ");
                if (s.vanished)
                    printf(" (%ld zero-step)", s.vanished);
                printf(" |");
                if (s.vanished == 0 && mean < best_mean[c])
                    best_mean[c] = mean, best_h[c] = h;
            }
            printf("\n");
        }
    printf("\nStep with the smallest mean error (no zero-step points):");
    for (int c = 0; c < NCOL; c++)
        printf(" %s R=%g: h=%g (mean %.2g);", fname[cols[c].fi], cols[c].range, best_h[c],
               best_mean[c]);
    printf("\nBG_DEFAULT_CENTRAL_STEP = %g.\n", (double)BG_DEFAULT_CENTRAL_STEP);
    return 0;
}
