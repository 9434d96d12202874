/* SPDX-License-Identifier: MIT */
/* The surface gradient (eq. 2) and the perturbed normal (eq. 4, Listing 3):
 * tangency, agreement with the double reference, the "never inward" property
 * of Listing 3 against the additive method, and the degenerate-input rules of
 * surfgrad.h in the scalar, double, batch and fused entry points. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include "bumpgrad.h"
#include "ref.h"
#include "check.h"

static double dot3d(double ax, double ay, double az, double bx, double by, double bz)
{
    return ax * bx + ay * by + az * bz;
}

static bg_vec3 random_unit_f(ref_rng *r)
{
    double u[3];
    ref_rng_unit_vector(r, u);
    bg_vec3 v = {check_to_float(u[0]), check_to_float(u[1]), check_to_float(u[2])};
    return v;
}

/* A volume gradient as the library produces it: amplitude times the analytic
 * gradient of 6-octave turbulence at a random point. */
static bg_vec3 noise_gradient(ref_rng *r, float amplitude)
{
    static const bg_fractal *fp;
    static bg_fractal f;
    if (!fp)
        f = bg_fractal_default(BG_FUNC_TURBULENCE), fp = &f;
    bg_vec3 g;
    bg_fractal3_grad(fp, (float)ref_rng_uniform(r, -50, 50), (float)ref_rng_uniform(r, -50, 50),
                     (float)ref_rng_uniform(r, -50, 50), &g);
    g.x *= amplitude, g.y *= amplitude, g.z *= amplitude;
    return g;
}

static void test_tangent(void)
{
    ref_rng r;
    ref_rng_seed(&r, 61);
    double max_ulps = 0, max_ref = 0, max_ulps_d = 0;
    for (int i = 0; i < 20000; i++) {
        bg_vec3 n = random_unit_f(&r);
        float amp = (float)exp(ref_rng_uniform(&r, log(1e-3), log(1e4)));
        bg_vec3 g = noise_gradient(&r, amp);
        bg_vec3 s = bg_surface_gradient(n, g);
        /* n as the library sees it, normalized in double */
        double nl = sqrt(dot3d(n.x, n.y, n.z, n.x, n.y, n.z));
        double nx = n.x / nl, ny = n.y / nl, nz = n.z / nl;
        double gl = sqrt(dot3d(g.x, g.y, g.z, g.x, g.y, g.z));
        if (gl == 0)
            continue;
        /* float result: each component rounded once, so |n.s| <= ~|s| eps/2 * sqrt(3) */
        double ulps = fabs(dot3d(nx, ny, nz, s.x, s.y, s.z)) / (gl * FLT_EPSILON);
        max_ulps = fmax(max_ulps, ulps);
        double nn[3] = {n.x, n.y, n.z}, gg[3] = {g.x, g.y, g.z}, rs[3];
        ref_surface_gradient(nn, gg, rs);
        double e = fmax(fmax(fabs(s.x - rs[0]), fabs(s.y - rs[1])), fabs(s.z - rs[2])) / gl;
        max_ref = fmax(max_ref, e);
        bg_dvec3 ndv = {nx * 3, ny * 3, nz * 3}, gd = {g.x, g.y, g.z};
        bg_dvec3 sd = bg_surface_gradientd(ndv, gd);
        max_ulps_d = fmax(max_ulps_d, fabs(dot3d(nx, ny, nz, sd.x, sd.y, sd.z)) / (gl * DBL_EPSILON));
    }
    printf("surface gradient tangency over 20000 cases, |g| from 1e-3 to 1e4: max |n . grad_S| = "
           "%.2f ulp(|g|) float, %.2f ulp(|g|) double (n of length 3); max relative deviation "
           "from the reference %.3g\n", max_ulps, max_ulps_d, max_ref);
    CHECK(max_ulps <= 4, "float surface gradient not tangent: %.2f ulps", max_ulps);
    CHECK(max_ulps_d <= 4, "double surface gradient not tangent: %.2f ulps", max_ulps_d);
    CHECK(max_ref <= 2 * FLT_EPSILON, "surface gradient differs from reference: %.3g", max_ref);
}

static void test_perturb_against_ref(void)
{
    ref_rng r;
    ref_rng_seed(&r, 62);
    double max_f = 0, max_d = 0, max_af = 0;
    for (int i = 0; i < 20000; i++) {
        bg_vec3 n = random_unit_f(&r);
        float amp = (float)exp(ref_rng_uniform(&r, log(1e-2), log(1e2)));
        bg_vec3 g = noise_gradient(&r, amp);
        double nn[3] = {n.x, n.y, n.z}, gg[3] = {g.x, g.y, g.z}, rp[3], ra[3];
        ref_perturb_surfgrad(nn, gg, rp);
        ref_perturb_additive(nn, gg, ra);
        bg_vec3 p = bg_perturb_normal(n, g);
        bg_vec3 a = bg_perturb_normal_additive(n, g);
        bg_dvec3 nd = {n.x, n.y, n.z}, gd = {g.x, g.y, g.z};
        bg_dvec3 pd = bg_perturb_normald(nd, gd);
        /* float rounding of n - grad_S grows with |g| (the projection subtracts
         * terms of size |g|), so the error is counted in units of eps (1 + |g|) */
        double unit = FLT_EPSILON * (1 + sqrt(gg[0] * gg[0] + gg[1] * gg[1] + gg[2] * gg[2]));
        max_f = fmax(max_f, fmax(fmax(fabs(p.x - rp[0]), fabs(p.y - rp[1])), fabs(p.z - rp[2])) / unit);
        max_af = fmax(max_af, fmax(fmax(fabs(a.x - ra[0]), fabs(a.y - ra[1])), fabs(a.z - ra[2])) / unit);
        max_d = fmax(max_d, fmax(fmax(fabs(pd.x - rp[0]), fabs(pd.y - rp[1])), fabs(pd.z - rp[2])));
    }
    printf("perturbed normal vs reference, |g| up to ~1e3: max component error in units of "
           "FLT_EPSILON (1 + |g|): Listing 3 float %.3g, additive float %.3g (bound 8); Listing 3 "
           "double %.3g absolute (bound 1e-12)\n", max_f, max_af, max_d);
    CHECK(max_f <= 8, "Listing 3 float error %.3g eps (1 + |g|)", max_f);
    CHECK(max_af <= 8, "additive float error %.3g eps (1 + |g|)", max_af);
    CHECK(max_d <= 1e-12, "Listing 3 double error %.3g", max_d);
}

static void test_never_inward(void)
{
    ref_rng r;
    ref_rng_seed(&r, 63);
    printf("Listing 3 vs additive, random unit normals, g = amplitude * grad(turbulence):\n");
    const double amps[] = {0.01, 0.1, 0.3, 1, 3, 10, 100, 1e3, 1e4};
    for (int k = 0; k < 9; k++) {
        int n = 20000, inward_s = 0, inward_a = 0;
        double min_dot = 1;
        for (int i = 0; i < n; i++) {
            bg_vec3 nrm = random_unit_f(&r);
            bg_vec3 g = noise_gradient(&r, (float)amps[k]);
            bg_vec3 p = bg_perturb_normal(nrm, g);
            bg_vec3 a = bg_perturb_normal_additive(nrm, g);
            double ds = dot3d(p.x, p.y, p.z, nrm.x, nrm.y, nrm.z);
            double da = dot3d(a.x, a.y, a.z, nrm.x, nrm.y, nrm.z);
            min_dot = fmin(min_dot, ds);
            if (!(ds > 0))
                inward_s++;
            if (!(da > 0))
                inward_a++;
        }
        printf("  amplitude %-6g: Listing 3 inward %d of %d (min dot(n', n) %.3g); additive "
               "inward %.2f%%\n", amps[k], inward_s, n, min_dot, 100.0 * inward_a / n);
        CHECK(inward_s == 0, "Listing 3 pointed inward at amplitude %g", amps[k]);
        /* Measured (seed 63): 28.9% at amplitude 1, 47.9% at 10 (half of the normals
         * face a gradient that is larger than 1 and points along them). */
        if (amps[k] == 1)
            CHECK(inward_a >= n / 5, "additive inward fraction at amplitude 1 below 20%%");
        if (amps[k] == 10)
            CHECK(inward_a >= n * 2 / 5, "additive inward fraction at amplitude 10 below 40%%");
    }
}

/* --- degenerate inputs ----------------------------------------------------- */

typedef struct res {
    double x, y, z;
} res;

enum { ENTRY_SCALAR, ENTRY_DOUBLE, ENTRY_BATCH, ENTRY_COUNT };
static const char *const entry_name[ENTRY_COUNT] = {"scalar", "double", "batch"};

static res perturb_via(int entry, bg_perturb_method m, double nx, double ny, double nz, double gx,
                       double gy, double gz)
{
    res o;
    if (entry == ENTRY_DOUBLE) {
        bg_dvec3 n = {nx, ny, nz}, g = {gx, gy, gz};
        bg_dvec3 r = m == BG_PERTURB_SURFGRAD ? bg_perturb_normald(n, g)
                     : m == BG_PERTURB_ADDITIVE ? bg_perturb_normal_additived(n, g)
                                                : bg_perturbd(m, n, g);
        o.x = r.x, o.y = r.y, o.z = r.z;
    } else if (entry == ENTRY_SCALAR) {
        bg_vec3 n = {(float)nx, (float)ny, (float)nz}, g = {(float)gx, (float)gy, (float)gz};
        bg_vec3 r = m == BG_PERTURB_SURFGRAD ? bg_perturb_normal(n, g)
                    : m == BG_PERTURB_ADDITIVE ? bg_perturb_normal_additive(n, g)
                                               : bg_perturb(m, n, g);
        o.x = r.x, o.y = r.y, o.z = r.z;
    } else {
        /* 5 copies so a SIMD batch would also run a full vector and a tail */
        float a[6][5], out[3][5];
        for (int i = 0; i < 5; i++) {
            a[0][i] = (float)nx, a[1][i] = (float)ny, a[2][i] = (float)nz;
            a[3][i] = (float)gx, a[4][i] = (float)gy, a[5][i] = (float)gz;
        }
        bg_perturb_batch(m, a[0], a[1], a[2], a[3], a[4], a[5], 5, out[0], out[1], out[2]);
        o.x = out[0][4], o.y = out[1][4], o.z = out[2][4];
    }
    return o;
}

static int is_unit(res r, double tol)
{
    double l = sqrt(r.x * r.x + r.y * r.y + r.z * r.z);
    return isfinite(l) && fabs(l - 1) <= tol;
}
static int is_zero(res r) { return r.x == 0 && r.y == 0 && r.z == 0; }

static void test_degenerate(void)
{
    const bg_perturb_method methods[3] = {BG_PERTURB_SURFGRAD, BG_PERTURB_ADDITIVE,
                                          BG_PERTURB_ADDITIVE_PERLIN};
    int cases = 0;
    for (int e = 0; e < ENTRY_COUNT; e++) {
        double tol = e == ENTRY_DOUBLE ? 1e-14 : 1e-6;
        double huge = e == ENTRY_DOUBLE ? 1e300 : 1e30;
        double maxv = e == ENTRY_DOUBLE ? DBL_MAX : FLT_MAX;
        /* subnormal powers of two: 3 and 4 times them are exact, unlike 0.6 and 0.8 */
        double tiny = e == ENTRY_DOUBLE ? 0x1p-1060 : 0x1p-140;
        for (int mi = 0; mi < 3; mi++) {
            bg_perturb_method m = methods[mi];
            const char *en = entry_name[e];
            res r;
            /* non-unit n is normalized: with g = 0 the result is n / |n| */
            const double scales[] = {5, 1e-3, huge, maxv, tiny};
            for (int s = 0; s < 5; s++) {
                double k = s == 4 ? 5 : 1;
                r = perturb_via(e, m, 0, k * 0.6 * scales[s], k * 0.8 * scales[s], 0, 0, 0);
                cases++;
                CHECK(fabs(r.x) <= tol && fabs(r.y - 0.6) <= tol && fabs(r.z - 0.8) <= tol,
                      "%s m%d: n scaled by %g not normalized: (%g %g %g)", en, mi, scales[s], r.x,
                      r.y, r.z);
            }
            /* zero or non-finite n: the (0,0,0) sentinel, whatever g is */
            const double bad_n[4][3] = {{0, 0, 0}, {NAN, 0, 1}, {0, INFINITY, 1}, {0, 0, -INFINITY}};
            const double gs[3][3] = {{0.3, -0.2, 0.1}, {NAN, 0, 0}, {huge, 0, 0}};
            for (int b = 0; b < 4; b++)
                for (int gi = 0; gi < 3; gi++) {
                    r = perturb_via(e, m, bad_n[b][0], bad_n[b][1], bad_n[b][2], gs[gi][0],
                                    gs[gi][1], gs[gi][2]);
                    cases++;
                    CHECK(is_zero(r), "%s m%d: invalid n %d, g %d: expected (0,0,0), got (%g %g %g)",
                          en, mi, b, gi, r.x, r.y, r.z);
                }
            /* NaN/Inf g: the unit n (no perturbation) */
            const double bad_g[4][3] = {{NAN, 0, 0}, {0, INFINITY, 0}, {0, 0, -INFINITY},
                                        {NAN, NAN, NAN}};
            for (int b = 0; b < 4; b++) {
                r = perturb_via(e, m, 0, 0, 2, bad_g[b][0], bad_g[b][1], bad_g[b][2]);
                cases++;
                CHECK(r.x == 0 && r.y == 0 && r.z == 1, "%s m%d: NaN/Inf g %d: expected unit n, "
                      "got (%g %g %g)", en, mi, b, r.x, r.y, r.z);
            }
            /* huge finite g: finite and unit; for Listing 3 nearly tangent */
            const double hg[4][3] = {{huge, 0, 0}, {-huge, huge, 0}, {maxv, -maxv, maxv},
                                     {huge, 0, huge}};
            for (int b = 0; b < 4; b++) {
                r = perturb_via(e, m, 0, 0, 1, hg[b][0], hg[b][1], hg[b][2]);
                cases++;
                CHECK(is_unit(r, tol), "%s m%d: huge g %d: not a finite unit vector (%g %g %g)",
                      en, mi, b, r.x, r.y, r.z);
                if (m == BG_PERTURB_SURFGRAD && b < 3)
                    CHECK(r.z >= 0 && r.z < 1e-6, "%s: huge tangent g should give a nearly "
                          "tangent normal, z = %g", en, r.z);
            }
            /* additive: n - g == 0 exactly gives the unit n */
            if (m == BG_PERTURB_ADDITIVE) {
                r = perturb_via(e, m, 0, 0, 1, 0, 0, 1);
                cases++;
                CHECK(r.x == 0 && r.y == 0 && r.z == 1, "%s: n - g == 0 should give n", en);
            }
        }
    }
    printf("degenerate-input rules (non-unit n, zero/NaN/Inf n, NaN/Inf g, huge g, n == g): %d "
           "cases over scalar, double and batch, 3 methods\n", cases);
}

/* No NaN from finite input: fuzz with components from every binade, including
 * subnormals and the largest finite values. */
static void test_fuzz_finite(void)
{
    ref_rng r;
    ref_rng_seed(&r, 64);
    int n = 0, bad = 0;
    for (int i = 0; i < 30000; i++) {
        double c[6];
        for (int k = 0; k < 6; k++) {
            int kind = (int)(ref_rng_u64(&r) % 8);
            double mag = kind == 0 ? 0 : kind == 1 ? FLT_MAX : exp2(ref_rng_uniform(&r, -149, 128));
            if (mag > FLT_MAX)
                mag = FLT_MAX;
            c[k] = (ref_rng_u64(&r) & 1) ? -mag : mag;
        }
        int nzero = (float)c[0] == 0 && (float)c[1] == 0 && (float)c[2] == 0;
        for (int e = 0; e < ENTRY_COUNT; e++)
            for (int m = 0; m < 3; m++) {
                res o = perturb_via(e, (bg_perturb_method)m, c[0], c[1], c[2], c[3], c[4], c[5]);
                n++;
                int ok = nzero ? is_zero(o) : is_unit(o, e == ENTRY_DOUBLE ? 1e-14 : 1e-6);
                if (!ok) {
                    bad++;
                    if (bad < 10)
                        CHECK(0, "%s method %d: n (%g %g %g) g (%g %g %g) -> (%g %g %g)",
                              entry_name[e], m, c[0], c[1], c[2], c[3], c[4], c[5], o.x, o.y, o.z);
                }
            }
        bg_vec3 nf = {(float)c[0], (float)c[1], (float)c[2]}, gf = {(float)c[3], (float)c[4], (float)c[5]};
        bg_vec3 s = bg_surface_gradient(nf, gf);
        if (!isfinite(s.x) || !isfinite(s.y) || !isfinite(s.z)) {
            /* the surface gradient itself may exceed float for |g| near FLT_MAX */
            float mg = fmaxf(fmaxf(fabsf(gf.x), fabsf(gf.y)), fabsf(gf.z));
            if (!(mg > 1e38f) || isnan(s.x) || isnan(s.y) || isnan(s.z)) {
                bad++;
                CHECK(0, "surface gradient not finite for finite input");
            }
        }
    }
    printf("fuzz over all binades (incl. subnormal, FLT_MAX): %d perturbations, %d not unit "
           "(or not (0,0,0) for zero n), no NaN allowed\n", n, bad);
}

static void test_surface_gradient_degenerate(void)
{
    bg_vec3 zero = {0, 0, 0}, nanv = {NAN, 0, 1}, n = {0, 0, 4}, g = {1, 2, 3}, gnan = {0, INFINITY, 0};
    bg_vec3 a = bg_surface_gradient(zero, g), b = bg_surface_gradient(nanv, g),
            c = bg_surface_gradient(n, gnan), d = bg_surface_gradient(n, g);
    int ok = a.x == 0 && a.y == 0 && a.z == 0 && b.x == 0 && b.y == 0 && b.z == 0 && c.x == 0 &&
             c.y == 0 && c.z == 0 && d.x == 1 && d.y == 2 && d.z == 0;
    bg_dvec3 dz = {0, 0, 0}, dn = {0, 0, 0.5}, dg = {1, 2, 3}, dgn = {NAN, 0, 0};
    bg_dvec3 e = bg_surface_gradientd(dz, dg), f = bg_surface_gradientd(dn, dgn),
             h = bg_surface_gradientd(dn, dg);
    ok &= e.x == 0 && e.y == 0 && e.z == 0 && f.x == 0 && f.y == 0 && f.z == 0 && h.x == 1 &&
          h.y == 2 && h.z == 0;
    printf("surface gradient: invalid n -> 0, non-finite g -> 0, non-unit n normalized: %s\n",
           ok ? "yes" : "NO");
    CHECK(ok, "bg_surface_gradient degenerate rules");

    bg_vec3 x = {1, 0, 0}, y = {0, 2, 0}, mx = {-3, 0, 0};
    double a90 = bg_angle_deg(x, y), a180 = bg_angle_deg(x, mx), a0 = bg_angle_deg(x, x),
           an = bg_angle_deg(x, zero);
    printf("bg_angle_deg: 90 -> %.17g, 180 -> %.17g, 0 -> %g, zero vector -> %g\n", a90, a180, a0, an);
    CHECK(fabs(a90 - 90) < 1e-12 && fabs(a180 - 180) < 1e-12 && a0 == 0 && isnan(an),
          "bg_angle_deg");
}

/* The fused height -> normal batch follows the same rules: zero/NaN normal ->
 * (0,0,0); NaN position -> NaN gradient -> unit n; huge amplitude -> unit. */
static void test_fused_degenerate(void)
{
    bg_height h = bg_height_default();
    float px[5] = {0.3f, NAN, 1.7f, 2.1f, -0.4f}, py[5] = {0.1f, 0.2f, INFINITY, 0.5f, 0.9f},
          pz[5] = {0.7f, 0.3f, 0.2f, 0.25f, 1.3f};
    float nx[5] = {0, 0, 0, NAN, 0}, ny[5] = {0, 0, 0, 0, 3}, nz[5] = {0, 2, 1, 1, 4};
    float hv[5], ox[5], oy[5], oz[5];
    int ok = 1;
    for (int mode = 0; mode < 2; mode++) {
        h.gradient = mode ? BG_GRADIENT_CENTRAL : BG_GRADIENT_ANALYTIC;
        for (int m = 0; m < 3; m++) {
            bg_perturb_height_batch(&h, (bg_perturb_method)m, px, py, pz, nx, ny, nz, 5, hv, ox,
                                    oy, oz);
            ok &= ox[0] == 0 && oy[0] == 0 && oz[0] == 0;                      /* zero n */
            ok &= ox[1] == 0 && oy[1] == 0 && oz[1] == 1 && isnan(hv[1]);      /* NaN p */
            ok &= ox[2] == 0 && oy[2] == 0 && oz[2] == 1 && isnan(hv[2]);      /* Inf p */
            ok &= ox[3] == 0 && oy[3] == 0 && oz[3] == 0;                      /* NaN n */
            double l = sqrt((double)ox[4] * ox[4] + (double)oy[4] * oy[4] + (double)oz[4] * oz[4]);
            ok &= fabs(l - 1) < 1e-6;                                          /* non-unit n */
        }
    }
    h.gradient = BG_GRADIENT_ANALYTIC;
    h.amplitude = 1e30f;
    bg_perturb_height_batch(&h, BG_PERTURB_SURFGRAD, px, py, pz, nx, ny, nz, 5, NULL, ox, oy, oz);
    double l = sqrt((double)ox[4] * ox[4] + (double)oy[4] * oy[4] + (double)oz[4] * oz[4]);
    ok &= fabs(l - 1) < 1e-6;
    printf("fused bg_perturb_height_batch degenerate rules (zero/NaN n, NaN/Inf p, amplitude "
           "1e30), analytic and central, 3 methods: %s\n", ok ? "yes" : "NO");
    CHECK(ok, "fused degenerate rules");
}

int main(void)
{
    test_tangent();
    test_perturb_against_ref();
    test_never_inward();
    test_degenerate();
    test_fuzz_finite();
    test_surface_gradient_degenerate();
    test_fused_degenerate();
    return check_summary("test_surfgrad");
}
