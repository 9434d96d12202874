/* SPDX-License-Identifier: MIT */
/* The framework's one-implementation pieces and its parity with Mikkelsen's
 * reference framework (surfgrad_framework.h): Listing 1 in GPU float against a
 * double reference, the tangent-normal clamp, and each behaviour adopted from the
 * reference (triplanar order, the object-space FLT_EPSILON clamp, FixNormal, the
 * w = 0 bitangent sign, height derivatives at a mip level with the bicubic path,
 * the scale-dependent gradient's chain rule, the parallax helpers), each checked
 * against the reference's formula written out here in double from its published
 * math, plus the places where we keep our own rule (tiny charts). */
#include "fw_check.h"
#include <float.h>
#include <stdlib.h>
#include <string.h>

static double ang(rv a, rv b) /* degrees, accurate near 0 */
{
    return atan2(rlen(rcross(a, b)), rdot(a, b)) * (180.0 / 3.14159265358979323846);
}
static int same_f(bg_vec3 a, bg_vec3 b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

/* ---- Listing 1 in float ------------------------------------------------------- */

/* Listing 1 in double on the float inputs, with this library's det = 0 rule. */
static rv listing1_ref(rv n, rv ss, rv st, double dbs, double dbt)
{
    rv r1 = rcross(st, n), r2 = rcross(n, ss);
    double det = rdot(ss, r1);
    if (det == 0)
        return n;
    double sg = det > 0 ? 1 : -1;
    return rnorm(rsub(rmul(n, fabs(det)), rmul(radd(rmul(r1, dbs), rmul(r2, dbt)), sg)));
}

static void test_listing1_float(void)
{
    double worst = 0, worst_vs_d = 0;
    for (int it = 0; it < 20000; it++) {
        rv n = rand_dir();
        /* a screen chart of a pixel footprint: two independent tangent-ish steps */
        double px = urand(1e-3, 1e-1);
        rv ss = rmul(radd(rperp(n), rmul(rand_dir(), 0.3)), px);
        rv st = rmul(radd(rnorm(rcross(n, rperp(n))), rmul(rand_dir(), 0.3)), px * urand(0.5, 2));
        bg_vec3 nf = to_f(n), sf = to_f(ss), tf = to_f(st);
        float dbs = (float)(urand(-2, 2) * px), dbt = (float)(urand(-2, 2) * px);
        rv ref = listing1_ref(from_f(nf), from_f(sf), from_f(tf), dbs, dbt);
        bg_vec3 r = bg_listing1_normal(nf, sf, tf, dbs, dbt);
        worst = fmax(worst, ang(from_f(r), ref));
        CHECK(fabs(rlen(from_f(r)) - 1) < 1e-6, "listing1 not unit");
        /* the robust double form agrees on well-conditioned charts */
        worst_vs_d = fmax(worst_vs_d,
                          ang(from_f(r), from_f(bg_perturb_normal_screen(nf, sf, tf, dbs, dbt))));
    }
    CHECK(worst < 3e-5, "float Listing 1 vs double reference: %.3g deg", worst);
    CHECK(worst_vs_d < 3e-5, "float Listing 1 vs bg_perturb_normal_screen: %.3g deg", worst_vs_d);

    /* The det = 0 rule: n unchanged, bit for bit, even when not unit. */
    bg_vec3 n = {0.3f, -2.0f, 0.7f}, a = {1, 0, 0}, b = {2, 0, 0};
    CHECK(same_f(bg_listing1_normal(n, a, b, 0.5f, -0.25f), n), "det = 0 keeps n");
    bg_vec3 nan3 = {NAN, 0, 0};
    CHECK(same_f(bg_listing1_normal(n, nan3, b, 0.5f, 0.1f), n), "NaN det keeps n");
    bg_vec3 sx = {1, 0, 0}, sy = {0, 1, 0};
    CHECK(same_f(bg_listing1_normal(n, sx, sy, INFINITY, 0), n), "Inf result keeps n");
    /* n is used as given: a flat height returns normalize(n) for a right-handed
     * chart and for a mirrored one alike (|det| n). */
    bg_vec3 r = bg_listing1_normal(n, sx, sy, 0, 0), rm = bg_listing1_normal(n, sy, sx, 0, 0);
    rv nu = rnorm(from_f(n));
    CHECK(rdist(from_f(r), nu) < 1e-7 && rdist(from_f(rm), nu) < 1e-7, "flat height gives n");
    /* A float chart whose det underflows keeps n (documented), where the double
     * form rescales and still measures the slope. */
    bg_vec3 up = {0, 0, 1}, tx = {1e-23f, 0, 0}, ty = {0, 1e-23f, 0};
    CHECK(same_f(bg_listing1_normal(up, tx, ty, 1e-23f, 0), up), "underflowing det keeps n");
    bg_vec3 rd = bg_perturb_normal_screen(up, tx, ty, 1e-23f, 0);
    CHECK(fabs(ang(from_f(rd), rnorm(R(-1, 0, 1)))) < 1e-5, "robust form on a tiny chart");
}

/* ---- the tangent-normal clamp ---------------------------------------------------- */

static void test_tangent_normal_to_derivs(void)
{
    bg_vec3 m = {0.5f, 0, -0.5f};
    bg_vec2 d = bg_tangent_normal_to_derivs(m);
    CHECK(d.x == -1 && d.y == 0, "m=(0.5,0,-0.5): (%g %g), want (-1, 0)", d.x, d.y);
    bg_vec3 tang = {1, 0, 0};
    d = bg_tangent_normal_to_derivs(tang);
    CHECK(d.x == -128 && d.y == 0, "tangent m: (%g %g)", d.x, d.y);
    bg_vec3 m2 = {0.6f, -0.8f, 0};
    d = bg_tangent_normal_to_derivs(m2);
    /* common floor: z = 0.8/128, so (-0.6, 0.8) * 160: direction kept, max 128 */
    CHECK(fabs(d.x + 96) < 1e-4 && fabs(d.y - 128) < 1e-4, "direction kept: (%g %g)", d.x, d.y);
    bg_vec3 zero = {0, 0, 0}, nanm = {NAN, 0, 1};
    d = bg_tangent_normal_to_derivs(zero);
    CHECK(d.x == 0 && d.y == 0, "m = 0");
    d = bg_tangent_normal_to_derivs(nanm);
    CHECK(d.x == 0 && d.y == 0, "NaN m");
    double worst = 0;
    for (int it = 0; it < 5000; it++) {
        rv mm = rand_dir();
        bg_vec3 mf = to_f(rmul(mm, urand(0.01, 100)));
        rv md = from_f(mf);
        /* the reference's rule written out: abs, floor at max(|x|,|y|)/128 */
        double z = fmax(fabs(md.z), fmax(fabs(md.x), fabs(md.y)) / 128);
        double ex = -md.x / z, ey = -md.y / z;
        bg_vec2 r = bg_tangent_normal_to_derivs(mf);
        worst =
            fmax(worst, fmax(fabs(r.x - ex), fabs(r.y - ey)) / fmax(1, fmax(fabs(ex), fabs(ey))));
        bg_dvec2 rd = bg_tangent_normal_to_derivsd(to_d(md));
        CHECK(fabs(rd.x - ex) <= 1e-15 * fmax(1, fabs(ex)) &&
                  fabs(rd.y - ey) <= 1e-15 * fmax(1, fabs(ey)),
              "double derivs");
        /* one implementation: the surface gradient is the frame times these */
        rv t = rand_dir(), b = rand_dir();
        bg_dvec3 g1 = bg_surfgrad_from_tangent_normald(to_d(t), to_d(b), to_d(md));
        bg_dvec3 g2 = bg_surfgrad_from_tbnd(rd, to_d(t), to_d(b));
        CHECK(memcmp(&g1, &g2, sizeof g1) == 0, "surfgrad_from_tangent_normald != tbn(derivs)");
    }
    CHECK(worst < 1.2e-7, "float derivs vs formula: %.3g", worst);
    bg_vec2 nd = {NAN, 0};
    CHECK(is_zero_f(bg_surfgrad_from_tbn(nd, tang, tang)), "tbn NaN deriv");
}

/* ---- triplanar: the reference's x-plane order -------------------------------------- */

static void test_triplanar_reference_order(void)
{
    double worst = 0;
    for (int it = 0; it < 2000; it++) {
        rv n = rand_dir();
        bg_dvec3 w = bg_triplanar_weightsd(to_d(n), 3);
        /* the reference's weights: max(0, |n| - 0.2)^3 normalized */
        double a[3] = {pow(fmax(fabs(n.x) - 0.2, 0), 3), pow(fmax(fabs(n.y) - 0.2, 0), 3),
                       pow(fmax(fabs(n.z) - 0.2, 0), 3)};
        double s = a[0] + a[1] + a[2];
        worst = fmax(worst, fabs(w.x - a[0] / s) + fabs(w.y - a[1] / s) + fabs(w.z - a[2] / s));
        /* reference planes: x sampled at (z, y), deriv_x = (dh/dz, dh/dy) */
        double dx[2] = {urand(-1, 1), urand(-1, 1)}, dy[2] = {urand(-1, 1), urand(-1, 1)},
               dz[2] = {urand(-1, 1), urand(-1, 1)};
        rv grad = R(a[2] / s * dz[0] + a[1] / s * dy[0], a[2] / s * dz[1] + a[0] / s * dx[1],
                    a[0] / s * dx[0] + a[1] / s * dy[1]);
        rv ref = rproj(n, grad);
        /* ours takes d_yz = (dh/dy, dh/dz): the swapped pair */
        bg_dvec3 r = bg_surfgrad_triplanard(to_d(n), 3, v2d(dx[1], dx[0]), v2d(dy[0], dy[1]),
                                            v2d(dz[0], dz[1]));
        worst = fmax(worst, rdist(from_d(r), ref));
    }
    CHECK(worst < 1e-14, "triplanar vs the reference's formula: %.3g", worst);
}

/* ---- object-space normal clamp ----------------------------------------------------- */

static void test_perturbed_reference_clamp(void)
{
    double worst = 0;
    for (int it = 0; it < 5000; it++) {
        rv n = rand_dir(), v = rand_dir();
        double k = rdot(n, v);
        rv ref = rmul(rsub(rmul(n, k), v), 1.0 / fmax(FLT_EPSILON, fabs(k)));
        bg_dvec3 g = bg_surfgrad_from_perturbed_normal_clampd(to_d(n), to_d(v), BG_CLAMP_REFERENCE);
        worst = fmax(worst, rdist(from_d(g), ref) / fmax(1, rlen(ref)));
    }
    CHECK(worst < 1e-12, "reference clamp vs formula: %.3g", worst);
    /* 0.1 degree above the plane: the slope mode clamps at 128 (89.55 deg), the
     * reference mode reproduces m. */
    double th = 0.1 * 3.14159265358979323846 / 180;
    rv n = R(0, 0, 1), m = R(cos(th), 0, sin(th));
    rv rs = rnorm(rsub(n, from_d(bg_surfgrad_from_perturbed_normald(to_d(n), to_d(m)))));
    rv rr = rnorm(rsub(
        n, from_d(bg_surfgrad_from_perturbed_normal_clampd(to_d(n), to_d(m), BG_CLAMP_REFERENCE))));
    CHECK(fabs(ang(rs, m) - 0.347) < 0.01, "slope mode: %.4g deg off", ang(rs, m));
    CHECK(ang(rr, m) < 1e-10, "reference mode: %.3g deg off", ang(rr, m));
    /* an inward m is mirrored in both modes */
    rv in = R(0.6, 0, -0.8);
    bg_dvec3 gi = bg_surfgrad_from_perturbed_normal_clampd(to_d(n), to_d(in), BG_CLAMP_REFERENCE);
    CHECK(fabs(gi.x + 0.75) < 1e-15 && gi.y == 0 && gi.z == 0, "inward m, reference mode");
    /* exactly tangent: slope 1/FLT_EPSILON */
    bg_dvec3 gt =
        bg_surfgrad_from_perturbed_normal_clampd(to_d(n), to_d(R(1, 0, 0)), BG_CLAMP_REFERENCE);
    CHECK(fabs(gt.x + 1 / FLT_EPSILON) < 1, "tangent m: %g", gt.x);
    bg_vec3 gf = bg_surfgrad_from_perturbed_normal_clamp(to_f(n), to_f(m), BG_CLAMP_REFERENCE);
    bg_dvec3 gd = bg_surfgrad_from_perturbed_normal_clampd(
        to_d(from_f(to_f(n))), to_d(from_f(to_f(m))), BG_CLAMP_REFERENCE);
    CHECK(rdist(from_f(gf), from_d(gd)) < 1e-6 * rlen(from_d(gd)), "float reference clamp");
}

/* ---- back faces ------------------------------------------------------------------------ */

static void test_fix_normal(void)
{
    double worst = 0;
    for (int it = 0; it < 5000; it++) {
        rv N = rmul(rand_dir(), urand(0.5, 2)), V = rand_dir();
        double d = rdot(N, V);
        rv ref = d >= 0 ? N : rsub(N, rmul(V, 2 * d));
        bg_dvec3 r = bg_face_forward_reflectd(to_d(N), to_d(rmul(V, urand(0.1, 10))));
        worst = fmax(worst, rdist(from_d(r), ref));
        CHECK(rdot(from_d(r), V) >= -1e-15, "reflected normal faces away");
        CHECK(fabs(rlen(from_d(r)) - rlen(N)) < 1e-14, "length changed");
        bg_vec3 nf = to_f(N), vf = to_f(V);
        bg_vec3 rf = bg_face_forward_reflect(nf, vf);
        if (d >= 0.01)
            CHECK(same_f(rf, nf), "front-facing n must be returned as is");
    }
    CHECK(worst < 1e-14, "FixNormal vs formula: %.3g", worst);
    bg_vec3 n = {0, 0, 1}, v = {0, 0.6f, -0.8f}, z = {0, 0, 0}, nanv = {NAN, 0, 0};
    bg_vec3 r = bg_face_forward_reflect(n, v);
    /* n - 2 (n.v) v = (0, 0, 1) + 1.6 (0, 0.6, -0.8) = (0, 0.96, -0.28): the view
     * component flips, the screen component (along y) stays */
    CHECK(fabsf(r.y - 0.96f) < 1e-6f && fabsf(r.z + 0.28f) < 1e-6f, "reflect: (%g %g %g)", r.x, r.y,
          r.z);
    bg_vec3 neg = bg_face_forward(n, v);
    CHECK(neg.z == -1, "negation stays available");
    CHECK(same_f(bg_face_forward_reflect(n, z), n), "zero viewer");
    CHECK(same_f(bg_face_forward_reflect(n, nanv), n), "NaN viewer");
}

/* ---- mikkTSpace bitangent sign ------------------------------------------------------------ */

static void test_bitangent_sign(void)
{
    bg_dvec3 t = {1, 0.2, 0}, n = {0, 0, 2};
    /* b = sign (n/|n| x t): (0,0,1) x (1,0.2,0) = (-0.2, 1, 0) */
    double w[6] = {1, 0.5, 0, -0.0, -1, -1e-30};
    double want[6] = {1, 1, -1, -1, -1, -1};
    for (int i = 0; i < 6; i++) {
        bg_dtangent_frame f = bg_mikktspace_renormalized(t, w[i], n);
        CHECK(f.b.x == -0.2 * want[i] && f.b.y == want[i] && f.b.z == 0, "w = %g: b.y = %g", w[i],
              f.b.y);
    }
    bg_dtangent_frame f = bg_mikktspace_renormalized(t, NAN, n);
    CHECK(is_zero_d(f.b) && is_zero_d(f.t), "NaN sign: zero frame");
}

/* ---- height map derivatives at a mip level ------------------------------------------------ */

/* The reference's 4x4 high-quality filter as it writes it (a Gather-ordered matrix
 * H with rows = scanlines j-1..j+2 and the weight vectors X, Y, dX, dY), in double. */
static bg_dvec2 bicubic_ref(const float *tx, int W, int Hh, double s, double t)
{
    double cx = s * W - 0.5, cy = t * Hh - 0.5;
    double fx = floor(cx), fy = floor(cy);
    double tx_ = cx - fx, ty_ = cy - fy;
    int i = (int)fx, j = (int)fy;
    double H[4][4];
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) {
            int x = i - 1 + c, y = j - 1 + r;
            x = ((x % W) + W) % W, y = ((y % Hh) + Hh) % Hh; /* repeat */
            H[r][c] = tx[y * W + x];
        }
    double A[2] = {1 - tx_, tx_}, B[2] = {1 - ty_, ty_};
    double X[4] = {0.25 * A[0], 0.25 * (2 * A[0] + A[1]), 0.25 * (A[0] + 2 * A[1]), 0.25 * A[1]};
    double Y[4] = {0.25 * B[0], 0.25 * (2 * B[0] + B[1]), 0.25 * (B[0] + 2 * B[1]), 0.25 * B[1]};
    double dX[4] = {-0.5 * A[0], -0.5 * A[1], 0.5 * A[0], 0.5 * A[1]};
    double dY[4] = {-0.5 * B[0], -0.5 * B[1], 0.5 * B[0], 0.5 * B[1]};
    bg_dvec2 d = {0, 0};
    for (int r = 0; r < 4; r++) {
        double hdx = 0, hx = 0;
        for (int c = 0; c < 4; c++)
            hdx += H[r][c] * dX[c], hx += H[r][c] * X[c];
        d.x += Y[r] * hdx, d.y += dY[r] * hx;
    }
    return d;
}

static void test_mip_derivs(void)
{
    const int W = 32, Hh = 16;
    float *l0 = malloc(sizeof(float) * W * Hh), *l1 = malloc(sizeof(float) * 16 * 8),
          *l2 = malloc(sizeof(float) * 8 * 4);
    const double a = 0.75, b = -0.4;
    for (int j = 0; j < Hh; j++)
        for (int i = 0; i < W; i++)
            l0[j * W + i] = (float)(a * i + b * j + 3);
    bg_height_texture lv[3] = {
        {W, Hh, l0, BG_WRAP_CLAMP}, {16, 8, l1, BG_WRAP_CLAMP}, {8, 4, l2, BG_WRAP_CLAMP}};
    CHECK(bg_height_mip_size(W) == 16 && bg_height_mip_size(1) == 1 && bg_height_mip_size(5) == 2,
          "mip sizes");
    CHECK(bg_height_texture_downsample(&lv[0], l1) == BG_OK, "downsample 0");
    CHECK(bg_height_texture_downsample(&lv[1], l2) == BG_OK, "downsample 1");
    CHECK(fabs(l1[0] - (0.75 * 0.5 - 0.4 * 0.5 + 3)) < 1e-6, "box filter: %g", l1[0]);
    CHECK(bg_height_texture_downsample(&lv[0], NULL) == BG_ERR_NULL_POINTER, "NULL dst");
    bg_height_mips mips = {lv, 3};
    CHECK(bg_height_mips_validate(&mips) == BG_OK, "valid chain");
    bg_height_mips bad = {lv, 0};
    CHECK(bg_height_mips_validate(&bad) == BG_ERR_INVALID_ARGUMENT, "empty chain");
    CHECK(bg_height_mips_validate(NULL) == BG_ERR_NULL_POINTER, "NULL chain");

    /* A ramp is a ramp in st at every level (box means of a ramp), so every level
     * and every blend between levels gives (a, b) per level-0 texel in the
     * interior, with and without the bicubic path. */
    double worst = 0;
    for (int it = 0; it < 2000; it++) {
        double lod = urand(0, 2);
        bg_vec2 st = v2f(urand(0.35, 0.6), urand(0.35, 0.6));
        bg_vec2 d = bg_height_mips_derivs_level(&mips, st, (float)lod, it & 1);
        worst = fmax(worst, fmax(fabs(d.x - a), fabs(d.y - b)));
    }
    CHECK(worst < 3e-6, "ramp derivative at mip levels: %.3g", worst);
    bg_vec2 bc = bg_height_texture_derivs_bicubic(&lv[0], v2f(0.41, 0.52));
    CHECK(fabs(bc.x - a) < 1e-6 && fabs(bc.y - b) < 1e-6, "bicubic on a ramp: (%g %g)", bc.x, bc.y);
    /* the footprint's own level: 4 texels per pixel along x is lod 2 */
    float lod = bg_height_texture_lod(&lv[0], v2f(4.0 / W, 0), v2f(0, 1.0 / Hh));
    CHECK(lod == 2, "lod of a 4-texel footprint: %g", lod);
    lod = bg_height_texture_lod(&lv[0], v2f(0, 0), v2f(0, 0));
    CHECK(isinf(lod) && lod < 0, "lod of no footprint");
    CHECK(fabsf(bg_height_mips_sample_level(&mips, v2f(0.5, 0.5), 7) -
                bg_height_mips_sample_level(&mips, v2f(0.5, 0.5), 2)) == 0,
          "lod clamped to the chain");
    CHECK(isnan(bg_height_mips_sample_level(&mips, v2f(0.5, 0.5), NAN)), "NaN lod sample");

    /* A smooth periodic height on a repeat texture: the bicubic path against the
     * reference's matrix form, the fade between the paths, and the footprint call. */
    const int N = 16;
    float *tx = malloc(sizeof(float) * N * N), *m1 = malloc(sizeof(float) * 8 * 8);
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++)
            tx[j * N + i] =
                (float)(sin(2 * 3.14159265358979 * i / N) * cos(4 * 3.14159265358979 * j / N) +
                        urand(-0.1, 0.1));
    bg_height_texture pl[2] = {{N, N, tx, BG_WRAP_REPEAT}, {8, 8, m1, BG_WRAP_REPEAT}};
    CHECK(bg_height_texture_downsample(&pl[0], m1) == BG_OK, "downsample periodic");
    bg_height_mips pm = {pl, 2};
    double wb = 0, wfade = 0, wfoot = 0;
    for (int it = 0; it < 3000; it++) {
        bg_vec2 st = v2f(urand(-2, 3), urand(-2, 3));
        bg_dvec2 ref = bicubic_ref(tx, N, N, st.x, st.y);
        bg_vec2 bq = bg_height_texture_derivs_bicubic(&pl[0], st);
        wb = fmax(wb, fmax(fabs(bq.x - ref.x), fabs(bq.y - ref.y)));
        double l = urand(0, 1);
        bg_vec2 plain = bg_height_mips_derivs_level(&pm, st, (float)l, 0);
        bg_vec2 hq = bg_height_mips_derivs_level(&pm, st, (float)l, 1);
        double mix = fmin(fmax(((float)l - 0.5) / (0.05 - 0.5), 0), 1);
        double ex = plain.x + mix * (ref.x - plain.x), ey = plain.y + mix * (ref.y - plain.y);
        wfade = fmax(wfade, fmax(fabs(hq.x - ex), fabs(hq.y - ey)));
        /* DerivFromHeightMap = ...Level at the clamped footprint LOD */
        bg_vec2 dx = v2f(urand(0.2, 3) / N, 0), dy = v2f(0, urand(0.2, 3) / N);
        double fl = fmin(fmax(log2(fmax((double)dx.x, (double)dy.y) * N), 0), 1);
        bg_vec2 f = bg_height_mips_derivs(&pm, st, dx, dy, 1);
        bg_vec2 g = bg_height_mips_derivs_level(&pm, st, (float)fl, 1);
        wfoot = fmax(wfoot, fmax(fabs(f.x - g.x), fabs(f.y - g.y)));
    }
    CHECK(wb < 1e-6, "bicubic vs the reference's matrix form: %.3g", wb);
    CHECK(wfade < 1e-6, "high-quality fade: %.3g", wfade);
    CHECK(wfoot < 1e-5, "footprint LOD call: %.3g", wfoot);
    bg_vec2 nd = bg_height_mips_derivs_level(&pm, v2f(NAN, 0), 0, 1);
    CHECK(isnan(nd.x), "NaN st");
    free(tx), free(m1), free(l0), free(l1), free(l2);
}

/* ---- the scale-dependent gradient and parallax on a plane ---------------------------------- */

/* The plane z = 0 (n = +z) parametrized by P(s, t) = s U + t V with texture
 * coordinates changing per pixel by dst_dx, dst_dy: dP/dx = U ds/dx + V dt/dx. */
typedef struct {
    rv U, V;
    double sx, tx, sy, ty;
} chart;

static chart rand_chart(double scale)
{
    chart c;
    c.U = rmul(R(urand(0.5, 2), urand(-0.5, 0.5), 0), scale);
    c.V = rmul(R(urand(-0.5, 0.5), urand(0.5, 2) * ((urand(0, 1) < 0.5) ? -1 : 1), 0), scale);
    c.sx = urand(0.5, 2), c.tx = urand(-0.5, 0.5), c.sy = urand(-0.5, 0.5), c.ty = urand(0.5, 2);
    return c;
}

static void test_scale_dependent_and_parallax(void)
{
    rv n = R(0, 0, 1);
    double worst_g = 0, worst_tiny = 0, ref_tiny_err = 0, worst_p = 0, worst_rt = 0;
    for (int it = 0; it < 2000; it++) {
        int tiny = it & 1;
        double sc = tiny ? 1e-9 : 1;
        chart c = rand_chart(sc);
        rv dpdx = radd(rmul(c.U, c.sx), rmul(c.V, c.tx)),
           dpdy = radd(rmul(c.U, c.sy), rmul(c.V, c.ty));
        /* h(s, t) = alpha s + beta t, with a texture of dim texels: per texel
         * deriv = (alpha / W, beta / H); its surface gradient is the in-plane
         * gradient of h: G with G.U = alpha, G.V = beta. */
        double W = 256, Hh = 128, alpha = urand(-2, 2) * sc, beta = urand(-2, 2) * sc;
        double det = c.U.x * c.V.y - c.U.y * c.V.x;
        rv G = R((alpha * c.V.y - beta * c.U.y) / det, (beta * c.U.x - alpha * c.V.x) / det, 0);
        bg_dvec3 g =
            bg_surfgrad_scale_dependentd(to_d(n), to_d(dpdx), to_d(dpdy), v2d(alpha / W, beta / Hh),
                                         v2d(W, Hh), v2d(c.sx, c.tx), v2d(c.sy, c.ty));
        double e = rdist(from_d(g), G) / rlen(G);
        if (tiny) {
            worst_tiny = fmax(worst_tiny, e);
            /* The reference's floor max(1.19e-15, |det|) on this chart (|det| ~1e-18) */
            rv r1 = rcross(dpdy, n), r2 = rcross(n, dpdx);
            double dt = rdot(dpdx, r1), hx = alpha * c.sx + beta * c.tx,
                   hy = alpha * c.sy + beta * c.ty;
            rv gr = rmul(radd(rmul(r1, hx), rmul(r2, hy)),
                         (dt < 0 ? -1 : 1) / fmax(1.192093e-15, fabs(dt)));
            ref_tiny_err = fmax(ref_tiny_err, rdist(gr, G) / rlen(G));
        } else {
            worst_g = fmax(worst_g, e);
        }
        /* Parallax: dir with tangential part dir_t = x U + y V (texture offset
         * (x, y), large on the tiny chart) and normal part z: offset bump (x, y) / |z|. */
        double x = urand(-1, 1) / sc, y = urand(-1, 1) / sc, z = urand(0.1, 1) * (it & 2 ? -1 : 1);
        rv dir = radd(radd(rmul(c.U, x), rmul(c.V, y)), R(0, 0, z));
        double bump = urand(0.01, 0.1);
        bg_dvec2 o = bg_project_vec_to_textured(to_d(n), to_d(dpdx), to_d(dpdy), v2d(c.sx, c.tx),
                                                v2d(c.sy, c.ty), to_d(dir), bump, 0);
        worst_p =
            fmax(worst_p, fmax(fabs(o.x - bump * x / fabs(z)), fabs(o.y - bump * y / fabs(z))) /
                              (bump / sc));
        bg_dvec2 os = bg_project_vec_to_textured(to_d(n), to_d(dpdx), to_d(dpdy), v2d(c.sx, c.tx),
                                                 v2d(c.sy, c.ty), to_d(dir), 1, 1);
        worst_p = fmax(worst_p, fmax(fabs(os.x - x), fabs(os.y - y)) / (1 / sc));
        /* ... and back: the offset lands on dir_t */
        bg_dvec3 back = bg_texture_offset_to_surfaced(to_d(n), to_d(dpdx), to_d(dpdy),
                                                      v2d(c.sx, c.tx), v2d(c.sy, c.ty), os);
        rv dt = R(dir.x, dir.y, 0);
        worst_rt = fmax(worst_rt, rdist(from_d(back), dt) / rlen(dt));
    }
    CHECK(worst_g < 1e-14, "scale-dependent gradient vs plane: %.3g", worst_g);
    CHECK(worst_tiny < 1e-14, "scale-dependent on 1e-9 charts: %.3g", worst_tiny);
    CHECK(ref_tiny_err > 0.5, "the reference's 1.19e-15 floor should fail there: %.3g",
          ref_tiny_err);
    CHECK(worst_p < 1e-13, "project to texture: %.3g", worst_p);
    CHECK(worst_rt < 1e-14, "texture offset back to the surface: %.3g", worst_rt);
    /* degenerate charts */
    bg_vec3 u = {1, 0, 0}, up = {0, 0, 1};
    bg_vec2 o = bg_project_vec_to_texture(up, u, u, v2f(1, 0), v2f(0, 1), u, 1, 0);
    CHECK(o.x == 0 && o.y == 0, "parallel chart: no offset");
    CHECK(is_zero_f(bg_texture_offset_to_surface(up, u, u, v2f(1, 0), v2f(2, 0), v2f(1, 1))),
          "singular texture map");
    CHECK(is_zero_f(
              bg_surfgrad_scale_dependent(up, u, u, v2f(1, 1), v2f(8, 8), v2f(1, 0), v2f(0, 1))),
          "scale-dependent on a parallel chart");
    /* float twins round the double once */
    bg_vec3 px = {0.01f, 0.002f, 0}, py = {-0.001f, 0.012f, 0}, dir = {0.3f, -0.2f, 0.9f};
    bg_vec2 of = bg_project_vec_to_texture(up, px, py, v2f(0.002, 0), v2f(0, 0.003), dir, 0.05f, 0);
    bg_dvec2 od = bg_project_vec_to_textured(to_d(from_f(up)), to_d(from_f(px)), to_d(from_f(py)),
                                             v2d((float)0.002, 0), v2d(0, (float)0.003),
                                             to_d(from_f(dir)), 0.05f, 0);
    CHECK(of.x == (float)od.x && of.y == (float)od.y, "float parallax rounds once");
}

int main(void)
{
    test_listing1_float();
    test_tangent_normal_to_derivs();
    test_triplanar_reference_order();
    test_perturbed_reference_clamp();
    test_fix_normal();
    test_bitangent_sign();
    test_mip_derivs();
    test_scale_dependent_and_parallax();
    return check_summary("test_fw_parity");
}
