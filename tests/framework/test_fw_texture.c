/* SPDX-License-Identifier: MIT */
/* Height textures and Listing 2 of Mikkelsen 2010: bilinear sampling, the wrap
 * modes, forward (3 taps) and central (4 taps) differencing against the analytic
 * derivative of a ramp (which bilinear filtering reproduces exactly), convergence
 * for a smooth height, and the differences fed through eq. 3 on a plane. */
#include <stdlib.h>
#include "fw_check.h"

static const double PI = 3.14159265358979323846;

/* Ramp in texel-centre coordinates: H = a*u + b*v + c with u = s*W - 0.5. */
static const double RA = 0.75, RB = -0.4, RC = 3;

static float *make_ramp(int w, int h)
{
    float *t = malloc(sizeof(float) * (size_t)w * (size_t)h);
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++)
            t[j * w + i] = (float)(RA * i + RB * j + RC);
    return t;
}

static void test_validate(void)
{
    float one = 1;
    bg_height_texture t = {1, 1, &one, BG_WRAP_REPEAT};
    CHECK(bg_height_texture_validate(&t) == BG_OK, "valid 1x1");
    CHECK(bg_height_texture_validate(NULL) == BG_ERR_NULL_POINTER, "NULL texture");
    t.texels = NULL;
    CHECK(bg_height_texture_validate(&t) == BG_ERR_NULL_POINTER, "NULL texels");
    t.texels = &one, t.width = 0;
    CHECK(bg_height_texture_validate(&t) == BG_ERR_INVALID_ARGUMENT, "zero width");
    t.width = 1, t.wrap = (bg_wrap)7;
    CHECK(bg_height_texture_validate(&t) == BG_ERR_INVALID_ARGUMENT, "bad wrap");
    /* 1x1 is constant everywhere: zero derivatives */
    t.wrap = BG_WRAP_MIRROR;
    bg_vec2 d = bg_height_texture_derivs(&t, BG_DIFF_CENTRAL, v2f(0.3, 0.9), v2f(0.1, 0), v2f(0, 0.1));
    CHECK(d.x == 0 && d.y == 0, "1x1 derivatives");
}

static void test_ramp(void)
{
    const int W = 64, H = 32;
    float *tx = make_ramp(W, H);
    bg_height_texture tex = {W, H, tx, BG_WRAP_CLAMP};
    double worst_s = 0, worst_f = 0, worst_c = 0;
    for (int it = 0; it < 3000; it++) {
        /* Keep every tap between the first and last texel centres, where bilinear
         * reconstruction of a ramp is exact. */
        double dsx = urand(-1.5, 1.5) / W, dtx = urand(-1.5, 1.5) / H;
        double dsy = urand(-1.5, 1.5) / W, dty = urand(-1.5, 1.5) / H;
        double s = urand(0.5 + 2, W - 0.5 - 2) / W, t = urand(0.5 + 2, H - 0.5 - 2) / H;
        bg_vec2 st = v2f(s, t), dx = v2f(dsx, dtx), dy = v2f(dsy, dty);
        double u = (double)st.x * W - 0.5, v = (double)st.y * H - 0.5;
        double ref = RA * u + RB * v + RC;
        worst_s = fmax(worst_s, fabs(bg_height_texture_sample(&tex, st) - ref));
        /* analytic: dH = a W ds + b H dt (using the float-rounded steps the call sees) */
        double ex = RA * W * dx.x + RB * H * dx.y, ey = RA * W * dy.x + RB * H * dy.y;
        bg_vec2 f = bg_height_texture_derivs(&tex, BG_DIFF_FORWARD, st, dx, dy);
        bg_vec2 c = bg_height_texture_derivs(&tex, BG_DIFF_CENTRAL, st, dx, dy);
        worst_f = fmax(worst_f, fmax(fabs(f.x - ex), fabs(f.y - ey)));
        worst_c = fmax(worst_c, fmax(fabs(c.x - ex), fabs(c.y - ey)));
    }
    /* Texel values up to ~50 in float: sample error is float rounding of H(st) and of
     * the st -> texel mapping (st itself is a float). */
    CHECK(worst_s < 2e-5, "ramp sample: %.3g", worst_s);
    CHECK(worst_f < 2e-5, "forward difference of a ramp: %.3g", worst_f);
    CHECK(worst_c < 2e-5, "central difference of a ramp: %.3g", worst_c);

    /* Listing 2 is 3 taps: forward == H(st+dx) - H(st) with the library's own samples
     * up to the single rounding of each (computed here in float). */
    bg_vec2 st = v2f(0.4, 0.6), dx = v2f(0.01, 0.002), dy = v2f(-0.003, 0.02);
    bg_vec2 f = bg_height_texture_derivs(&tex, BG_DIFF_FORWARD, st, dx, dy);
    float h0 = bg_height_texture_sample(&tex, st);
    float hr = bg_height_texture_sample(&tex, v2f((double)st.x + dx.x, (double)st.y + dx.y));
    CHECK(fabsf(f.x - (hr - h0)) < 1e-5f, "forward = right tap - centre tap");
    free(tx);
}

static void test_wrap(void)
{
    const int W = 8, H = 5;
    float tx[W * H];
    for (int i = 0; i < W * H; i++)
        tx[i] = (float)((i * 37) % 11) - 5.0f; /* arbitrary, non-symmetric */
    bg_height_texture tex = {W, H, tx, BG_WRAP_REPEAT};
    for (int it = 0; it < 500; it++) {
        double s = urand(0, 1), t = urand(0, 1);
        float a = bg_height_texture_sample(&tex, v2f(s, t));
        tex.wrap = BG_WRAP_REPEAT;
        float b = bg_height_texture_sample(&tex, v2f(s + 3, t - 2));
        CHECK(fabsf(a - b) < 1e-5f, "repeat period 1: %g vs %g", a, b);
        tex.wrap = BG_WRAP_MIRROR;
        float m0 = bg_height_texture_sample(&tex, v2f(s, t));
        float m1 = bg_height_texture_sample(&tex, v2f(-s, t));
        float m2 = bg_height_texture_sample(&tex, v2f(2 - s, 4 + t));
        /* tolerance: float rounding of 2 - s times slopes of up to 80 per unit st */
        CHECK(fabsf(m0 - m1) < 1e-4f && fabsf(m0 - m2) < 1e-4f, "mirror symmetry: %g %g %g", m0,
              m1, m2);
        tex.wrap = BG_WRAP_CLAMP;
        /* Left of the first texel centre the clamp holds the edge column. */
        float c0 = bg_height_texture_sample(&tex, v2f(-urand(0, 5), t));
        float c1 = bg_height_texture_sample(&tex, v2f(0.5 / W, t));
        CHECK(c0 == c1, "clamp edge: %g vs %g", c0, c1);
        tex.wrap = BG_WRAP_REPEAT;
    }
    /* Between the last and first texel centres, repeat interpolates across the seam. */
    float seam = bg_height_texture_sample(&tex, v2f(0.0, 0.5 / H));
    CHECK(fabsf(seam - 0.5f * (tx[0] + tx[W - 1])) < 1e-6f, "repeat seam: %g", seam);
    /* Texel centres reproduce texels (exactly where (j + 0.5)/5 is exact in float). */
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++)
            CHECK(fabsf(bg_height_texture_sample(&tex, v2f((i + 0.5) / W, (j + 0.5) / H)) -
                        tx[j * W + i]) < 1e-5f,
                  "texel centre %d,%d", i, j);
    CHECK(bg_height_texture_sample(&tex, v2f(3.5 / W, 2.5 / H)) == tx[2 * W + 3], "exact centre");
    /* Huge and non-finite coordinates. */
    float huge = bg_height_texture_sample(&tex, v2f(1e30, -3e29));
    CHECK(isfinite(huge), "huge st must stay finite");
    tex.wrap = BG_WRAP_MIRROR;
    CHECK(isfinite(bg_height_texture_sample(&tex, v2f(-1e30, 1e30))), "huge mirror");
    tex.wrap = BG_WRAP_CLAMP;
    CHECK(bg_height_texture_sample(&tex, v2f(1e30, 0.5)) == bg_height_texture_sample(&tex, v2f(2, 0.5)),
          "huge clamp");
    CHECK(isnan(bg_height_texture_sample(&tex, v2f(NAN, 0.5))), "NaN st gives NaN");
    bg_vec2 d = bg_height_texture_derivs(&tex, BG_DIFF_FORWARD, v2f(0.5, 0.5), v2f(INFINITY, 0),
                                         v2f(0, 0.1));
    CHECK(isnan(d.x), "Inf step gives NaN");
}

/* Smooth periodic height: f(s,t) = sin(2 pi s) cos(2 pi t) + 0.3 sin(4 pi t). */
static double sm(double s, double t) { return sin(2 * PI * s) * cos(2 * PI * t) + 0.3 * sin(4 * PI * t); }
static double sm_s(double s, double t) { return 2 * PI * cos(2 * PI * s) * cos(2 * PI * t); }
static double sm_t(double s, double t)
{
    return -2 * PI * sin(2 * PI * s) * sin(2 * PI * t) + 1.2 * PI * cos(4 * PI * t);
}

static double smooth_error(int n, bg_diff_mode mode)
{
    float *tx = malloc(sizeof(float) * (size_t)n * (size_t)n);
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++)
            tx[j * n + i] = (float)sm((i + 0.5) / n, (j + 0.5) / n);
    bg_height_texture tex = {n, n, tx, BG_WRAP_REPEAT};
    uint64_t saved = fw_rng_state;
    fw_rng_state = 12345; /* same sample points at every resolution */
    double worst = 0;
    for (int it = 0; it < 400; it++) {
        /* A pixel footprint of about one texel, in a random direction. */
        double s = urand(0, 1), t = urand(0, 1), a = urand(0, 2 * PI), len = 1.0 / n;
        bg_vec2 st = v2f(s, t), dx = v2f(len * cos(a), len * sin(a)),
                dy = v2f(-len * sin(a), len * cos(a));
        bg_vec2 d = bg_height_texture_derivs(&tex, mode, st, dx, dy);
        /* the analytic derivative along each step, times the step (height per pixel) */
        double ex = sm_s(st.x, st.y) * dx.x + sm_t(st.x, st.y) * dx.y;
        double ey = sm_s(st.x, st.y) * dy.x + sm_t(st.x, st.y) * dy.y;
        worst = fmax(worst, fmax(fabs(d.x - ex), fabs(d.y - ey)) / len); /* slope error */
    }
    fw_rng_state = saved;
    free(tx);
    return worst;
}

static void test_convergence(void)
{
    for (int mode = 0; mode < 2; mode++) {
        double prev = 0, first = 0, e = 0;
        for (int n = 16; n <= 512; n *= 2) {
            e = smooth_error(n, (bg_diff_mode)mode);
            if (n == 16)
                first = e;
            else
                CHECK(e < 0.8 * prev, "%s: slope error %.3g at %d did not drop from %.3g",
                      mode ? "central" : "forward", e, n, prev);
            prev = e;
        }
        /* first-order at least: 32x finer texture, error at least 16x smaller */
        CHECK(e < first / 16, "%s converges too slowly: %.3g -> %.3g", mode ? "central" : "forward",
              first, e);
    }
}

/* A ramp texture on a plane, differenced per pixel (Listing 2) and fed through
 * eq. 3: must equal the in-plane gradient of the height, computed here from the
 * Gram matrix of the UV axes (no cross products, unlike eq. 3). */
static void test_listing2_through_eq3(void)
{
    const int W = 64, H = 64;
    float *tx = make_ramp(W, H);
    bg_height_texture tex = {W, H, tx, BG_WRAP_CLAMP};
    double worst = 0;
    for (int it = 0; it < 500; it++) {
        rv A = rmul(rand_dir(), urand(0.5, 2)), B = rmul(rand_dir(), urand(0.5, 2)); /* dP/ds, dP/dt */
        if (rlen(rcross(rnorm(A), rnorm(B))) < 0.3)
            continue;
        rv n = rmul(rnorm(rcross(A, B)), (it & 1) ? -1.0 : 1.0);
        /* screen map d(s,t)/d(x,y), about a texel per pixel */
        double j00 = urand(-1, 1) / W, j01 = urand(-1, 1) / W, j10 = urand(-1, 1) / H,
               j11 = urand(-1, 1) / H;
        if (fabs(j00 * j11 - j01 * j10) < 0.1 / (W * H))
            continue;
        bg_vec2 dx = v2f(j00, j10), dy = v2f(j01, j11);
        rv dpdx = radd(rmul(A, dx.x), rmul(B, dx.y)), dpdy = radd(rmul(A, dy.x), rmul(B, dy.y));
        bg_vec2 st = v2f(urand(0.2, 0.8), urand(0.2, 0.8));
        bg_vec2 d = bg_height_texture_derivs(&tex, BG_DIFF_CENTRAL, st, dx, dy);
        bg_vec3 sg = bg_surfgrad_from_screen_derivs(to_f(n), to_f(dpdx), to_f(dpdy), d.x, d.y);
        /* g = c1 A + c2 B with g.A = dH/ds = a W, g.B = dH/dt = b H */
        double gaa = rdot(A, A), gab = rdot(A, B), gbb = rdot(B, B), det = gaa * gbb - gab * gab;
        double r1 = RA * W, r2 = RB * H;
        double c1 = (r1 * gbb - r2 * gab) / det, c2 = (r2 * gaa - r1 * gab) / det;
        rv ref = radd(rmul(A, c1), rmul(B, c2));
        worst = fmax(worst, rdist(from_f(sg), ref) / rlen(ref));
    }
    CHECK(worst < 1e-3, "Listing 2 + eq. 3 vs in-plane gradient: %.3g", worst);
    free(tx);
}

int main(void)
{
    test_validate();
    test_ramp();
    test_wrap();
    test_convergence();
    test_listing2_through_eq3();
    return check_summary("test_fw_texture");
}
