/* SPDX-License-Identifier: MIT */
/* Checks the reference against things outside itself: the value Perlin's
 * published implementation gives, the permutation being a permutation, the
 * analytic gradient against a derivative-free Richardson estimate, and the
 * lattice zeros and period that follow from the algorithm's definition. */
#include <math.h>
#include <stdio.h>
#include "ref.h"
#include "common/check.h"

int main(void)
{
    double v = ref_noise(3.14, 42, 7);
    printf("ref_noise(3.14, 42, 7) = %.17g (published 0.13691995878400012)\n", v);
    CHECK(v == 0.13691995878400012, "published value mismatch: %.17g", v);

    /* Each of 0..255 exactly once; a mistyped entry breaks this. */
    int seen[256] = {0}, bad = 0;
    for (int i = 0; i < 256; i++) {
        int p = ref_permutation(i);
        if (p < 0 || p > 255 || seen[p]++)
            bad++;
    }
    printf("permutation: %d bad entries (expected 0)\n", bad);
    CHECK(bad == 0, "permutation table is not a permutation");

    double maxz = 0;
    for (int i = -300; i <= 300; i += 7)
        for (int j = -260; j <= 260; j += 13)
            maxz = fmax(maxz, fabs(ref_noise(i, j, i - j)));
    printf("max |noise| at lattice points: %g (expected 0)\n", maxz);
    CHECK(maxz == 0, "nonzero at lattice");

    ref_rng r;
    ref_rng_seed(&r, 1);
    double maxp = 0;
    for (int i = 0; i < 2000; i++) {
        double x = ref_rng_uniform(&r, -300, 300), y = ref_rng_uniform(&r, -300, 300),
               z = ref_rng_uniform(&r, -300, 300);
        maxp = fmax(maxp, fabs(ref_noise(x, y, z) - ref_noise(x + 256, y - 512, z + 1024)));
    }
    printf("max |noise(p) - noise(p + 256k)| over 2000 points: %g (small: the fraction "
           "changes rounding)\n", maxp);
    CHECK(maxp < 1e-12, "period broken: %g", maxp);

    /* Analytic (product-rule) gradient against long double Richardson. */
    double maxe = 0, maxg = 0;
    int n = 0;
    for (int i = 0; i < 5000; i++) {
        double x = ref_rng_uniform(&r, -50, 50), y = ref_rng_uniform(&r, -50, 50),
               z = ref_rng_uniform(&r, -50, 50);
        double ga[3], gr[3];
        ref_noise_grad(x, y, z, ga);
        if (!ref_noise_grad_richardson(x, y, z, 1e-3, gr))
            continue;
        n++;
        for (int a = 0; a < 3; a++) {
            maxe = fmax(maxe, fabs(ga[a] - gr[a]));
            maxg = fmax(maxg, fabs(ga[a]));
        }
    }
    printf("analytic vs Richardson gradient over %d points: max |err| = %.3g (max |grad| %.3g)\n",
           n, maxe, maxg);
    CHECK(n > 4000 && maxe < 1e-9, "gradient disagreement %g", maxe);

    /* And the gradient must be the gradient of the value ref_noise returns:
     * plain double central differences near the 1e-5 step agree to ~1e-9. */
    double maxv = 0;
    for (int i = 0; i < 2000; i++) {
        double x = ref_rng_uniform(&r, -50, 50), y = ref_rng_uniform(&r, -50, 50),
               z = ref_rng_uniform(&r, -50, 50), g[3], h = 1.0 / 65536;
        ref_noise_grad(x, y, z, g);
        double d = (ref_noise(x + h, y, z) - ref_noise(x - h, y, z)) / (2 * h);
        maxv = fmax(maxv, fabs(d - g[0]));
    }
    printf("analytic d/dx vs double central difference (h=2^-16): max |err| = %.3g\n", maxv);
    CHECK(maxv < 1e-7, "value/gradient inconsistent %g", maxv);

    /* Tangency of the reference surface gradient and the Listing 3 result. */
    double maxt = 0;
    for (int i = 0; i < 1000; i++) {
        double nn[3], g[3], sg[3];
        ref_rng_unit_vector(&r, nn);
        for (int a = 0; a < 3; a++)
            g[a] = ref_rng_uniform(&r, -10, 10);
        ref_surface_gradient(nn, g, sg);
        maxt = fmax(maxt, fabs(nn[0] * sg[0] + nn[1] * sg[1] + nn[2] * sg[2]));
    }
    printf("reference |n . grad_S| over 1000 cases (|g| <= 17): %.3g\n", maxt);
    CHECK(maxt < 1e-13, "not tangent");

    return check_summary("ref_selftest");
}
