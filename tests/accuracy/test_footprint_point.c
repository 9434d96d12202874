/* SPDX-License-Identifier: MIT */
/* bg_footprint_from_differentials (noise.h): max(|dpdx|, |dpdy|) against a
 * double reference, its edge cases, and the footprint of a pinhole camera
 * looking at a plane through bg_ray_differentials (distance times pixel angle,
 * stretched by 1/cos of the view angle along the tilt). */
#include <math.h>
#include <stdio.h>
#include <bumpgrad.h>

static int failures;
#define CHECK(c, ...)                                  \
    do {                                               \
        printf("%s ", (c) ? "ok  " : "FAIL");          \
        printf(__VA_ARGS__);                           \
        printf("\n");                                  \
        if (!(c))                                      \
            failures++;                                \
    } while (0)

static float frand(unsigned *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (float)(*s >> 8) * (1.0f / 16777216.0f) * 2.0f - 1.0f;
}

static double len_d(bg_vec3 v)
{
    return sqrt((double)v.x * v.x + (double)v.y * v.y + (double)v.z * v.z);
}

int main(void)
{
    bg_vec3 a = {3.0f, 4.0f, 0.0f}, b = {0.0f, 0.0f, 2.0f}, z = {0.0f, 0.0f, 0.0f};
    CHECK(bg_footprint_from_differentials(a, b) == 5.0f, "max(|(3,4,0)|, |(0,0,2)|) = 5");
    CHECK(bg_footprint_from_differentials(b, a) == 5.0f, "symmetric in its arguments");
    CHECK(bg_footprint_from_differentials(z, z) == 0.0f, "zero differentials (grazing ray): 0");
    bg_vec3 n = {NAN, 0.0f, 0.0f};
    CHECK(isnan(bg_footprint_from_differentials(n, a)) && isnan(bg_footprint_from_differentials(a, n)),
          "a NaN component in either vector: NaN");
    bg_vec3 big = {3e38f, 3e38f, 0.0f};
    CHECK(isinf(bg_footprint_from_differentials(big, a)), "an overflowing length: +inf");

    /* Against double over random vectors of many magnitudes. */
    unsigned s = 12345u;
    double worst = 0;
    for (int i = 0; i < 100000; i++) {
        float sc = ldexpf(1.0f, (int)(frand(&s) * 40.0f));
        bg_vec3 u = {frand(&s) * sc, frand(&s) * sc, frand(&s) * sc};
        bg_vec3 v = {frand(&s) * sc, frand(&s) * sc, frand(&s) * sc};
        double ref = fmax(len_d(u), len_d(v));
        double got = bg_footprint_from_differentials(u, v);
        double rel = ref > 0 ? fabs(got - ref) / ref : fabs(got);
        worst = rel > worst ? rel : worst;
    }
    CHECK(worst < 4e-7, "100000 random pairs: worst relative error %.3g against double", worst);

    /* A pinhole camera at distance d from the plane z = 0, pixel step s in the
     * unnormalized direction (0, 0, -1) + x s: |dP/dx| = d s facing the plane;
     * tilted by theta about y, the hit is farther and the step stretched by
     * 1/cos^2 along the tilt, 1/cos across it. */
    const float d = 10.0f, step = 1.0f / 512;
    bg_vec3 cam = {0.0f, 0.0f, d}, nrm = {0.0f, 0.0f, 1.0f}, p = {0.0f, 0.0f, 0.0f};
    bg_vec3 dir = {0.0f, 0.0f, -1.0f}, ddx = {step, 0.0f, 0.0f}, ddy = {0.0f, step, 0.0f};
    bg_vec3 dpdx, dpdy;
    bg_ray_differentials(p, nrm, cam, dir, ddx, ddy, &dpdx, &dpdy);
    float w = bg_footprint_from_differentials(dpdx, dpdy);
    CHECK(fabsf(w - d * step) <= 1e-6f * d * step, "facing the plane: footprint %.9g = d * step %.9g",
          (double)w, (double)(d * step));
    const float th = 1.0f; /* radians */
    bg_vec3 dirt = {sinf(th), 0.0f, -cosf(th)};
    bg_vec3 pt = {d * tanf(th), 0.0f, 0.0f};
    bg_vec3 ddxt = {step * cosf(th), 0.0f, step * sinf(th)};
    bg_ray_differentials(pt, nrm, cam, dirt, ddxt, ddy, &dpdx, &dpdy);
    w = bg_footprint_from_differentials(dpdx, dpdy);
    const double want = (double)d / cos(th) * step / cos(th);
    CHECK(fabs(w - want) <= 1e-5 * want, "tilted by 1 rad: footprint %.9g, expected d step / cos^2 = %.9g",
          (double)w, want);
    CHECK(w == (float)len_d(dpdx) || fabs(w - len_d(dpdx)) < 1e-6 * w,
          "tilted: the longer differential is the one along the tilt");

    printf("%s\n", failures ? "FAILED" : "footprint_point: all checks passed");
    return failures ? 1 : 0;
}
