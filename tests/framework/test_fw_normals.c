/* SPDX-License-Identifier: MIT */
/* Normal-side half of the framework: the resolve and the naive blend, surface
 * gradients from tangent-space and object-space normals, the mikkTSpace
 * renormalization, face-forwarding and the Orange Book bumps. References are
 * written out in double here (fw_check.h), never by calling the library. */
#include <stdlib.h>
#include "fw_check.h"

static double ang(rv a, rv b) /* degrees, accurate near 0 */
{
    return atan2(rlen(rcross(a, b)), rdot(a, b)) * (180.0 / 3.14159265358979323846);
}

/* An orthonormal frame (t, b, n) of either handedness. */
static void rand_frame(rv *t, rv *b, rv *n, int left)
{
    *n = rand_dir();
    *t = rperp(*n);
    *b = rcross(*n, *t);
    if (left)
        *b = rmul(*b, -1);
}

static void test_resolve_reference(void)
{
    double worst_f = 0, worst_d = 0;
    for (int it = 0; it < 2000; it++) {
        rv n = rmul(rand_dir(), urand(0.1, 10)); /* any length: normalized first */
        rv nu = rnorm(n);
        int count = 1 + it % 4;
        bg_vec3 gf[4];
        bg_dvec3 gd[4];
        float wf[4];
        double wd[4];
        rv sum = R(0, 0, 0);
        for (int i = 0; i < count; i++) {
            rv g = rmul(rproj(nu, rand_dir()), urand(0, 3));
            gf[i] = to_f(g), gd[i] = to_d(from_f(gf[i]));
            wf[i] = (float)urand(-1, 2), wd[i] = wf[i];
            sum = radd(sum, rmul(from_f(gf[i]), wf[i]));
        }
        bg_vec3 nf = to_f(n);
        rv nfu = rnorm(from_f(nf));
        rv ref = rnorm(rsub(nfu, sum));
        rv rf = from_f(bg_resolve_normal(nf, gf, wf, (size_t)count));
        rv rd = from_d(bg_resolve_normald(to_d(from_f(nf)), gd, wd, (size_t)count));
        worst_f = fmax(worst_f, rdist(rf, ref));
        worst_d = fmax(worst_d, rdist(rd, ref));
        /* Tangent gradients never turn the normal inward (eq. 4). */
        CHECK(rdot(rf, nfu) > 0, "resolve faces away from n at it=%d", it);
    }
    CHECK(worst_f < 2e-7, "float resolve vs reference: %.3g", worst_f);
    CHECK(worst_d < 1e-14, "double resolve vs reference: %.3g", worst_d);
}

/* The overview's counterexample: a flat influence must not flatten the result. */
static void test_flat_influence(void)
{
    bg_vec3 n = {0, 0, 1};
    bg_vec3 g[2] = {{0.6f, -0.3f, 0}, {0, 0, 0}}; /* A bumpy, B flat */
    float w_a_only[1] = {1}, w_both[2] = {1, 0.5f};
    bg_vec3 ra = bg_resolve_normal(n, g, w_a_only, 1);
    bg_vec3 rab = bg_resolve_normal(n, g, w_both, 2);
    CHECK(ra.x == rab.x && ra.y == rab.y && ra.z == rab.z,
          "flat influence changed the resolve: (%g %g %g) vs (%g %g %g)", ra.x, ra.y, ra.z, rab.x,
          rab.y, rab.z);

    /* Naive blend of the two influences' normals, weights summing to 1. */
    bg_vec3 na = ra, nb = n; /* B's normal is the base normal */
    bg_vec3 normals[2] = {na, nb};
    float w[2] = {2.0f / 3.0f, 1.0f / 3.0f};
    rv naive = from_f(bg_blend_normals_naive(normals, w, 2));
    rv rn = R(0, 0, 1);
    double slope_a = tan(ang(from_f(na), rn) * 3.14159265358979323846 / 180);
    /* The naive reference, written out. */
    rv nref = rnorm(radd(rmul(rnorm(from_f(na)), w[0]), rmul(rn, w[1])));
    CHECK(rdist(naive, nref) < 1e-6, "naive blend vs reference: %.3g", rdist(naive, nref));
    CHECK(ang(naive, rn) < ang(from_f(na), rn) - 1.0, "naive blend did not flatten");
    /* The resolve with the same weights scales the slope by exactly w_A: a flat
     * influence adds nothing, the weight alone attenuates. */
    rv rw = from_f(bg_resolve_normal(n, g, w, 2));
    double slope_w = tan(ang(rw, rn) * 3.14159265358979323846 / 180);
    CHECK(fabs(slope_w - w[0] * slope_a) < 1e-6, "resolve slope %.9g, want %.9g", slope_w,
          w[0] * slope_a);
    double slope_naive = tan(ang(naive, rn) * 3.14159265358979323846 / 180);
    CHECK(fabs(slope_naive - w[0] * slope_a) > 0.01, "naive blend unexpectedly proportional");
}

static void test_resolve_degenerate(void)
{
    bg_vec3 zero = {0, 0, 0}, n = {0, 0, 2};
    bg_vec3 g[3] = {{0.5f, 0, 0}, {NAN, 0, 0}, {0, INFINITY, 0}};
    bg_vec3 r = bg_resolve_normal(zero, g, NULL, 1);
    CHECK(is_zero_f(r), "zero n must give the sentinel");
    bg_vec3 nn = {NAN, 0, 1};
    CHECK(is_zero_f(bg_resolve_normal(nn, g, NULL, 1)), "NaN n must give the sentinel");
    r = bg_resolve_normal(n, NULL, NULL, 0);
    CHECK(r.x == 0 && r.y == 0 && r.z == 1, "count 0 must give the unit n");
    bg_vec3 r1 = bg_resolve_normal(n, g, NULL, 1), r3 = bg_resolve_normal(n, g, NULL, 3);
    CHECK(r1.x == r3.x && r1.y == r3.y && r1.z == r3.z, "non-finite influences must be skipped");
    float w[2] = {1, NAN};
    bg_vec3 g2[2] = {{0.5f, 0, 0}, {0.25f, 0, 0}};
    r3 = bg_resolve_normal(n, g2, w, 2);
    CHECK(r1.x == r3.x && r1.y == r3.y && r1.z == r3.z, "NaN weight must be skipped");
    /* weights NULL == all ones */
    float ones[2] = {1, 1};
    bg_vec3 ra = bg_resolve_normal(n, g2, NULL, 2), rb = bg_resolve_normal(n, g2, ones, 2);
    CHECK(ra.x == rb.x && ra.y == rb.y && ra.z == rb.z, "NULL weights != ones");
    /* Huge float gradient: finite, unit, nearly tangent along -g. */
    bg_vec3 big = {3e38f, 0, 0};
    r = bg_resolve_normal(n, &big, NULL, 1);
    CHECK(isfinite(r.x) && fabs(r.x + 1) < 1e-6 && fabs(r.z) < 1e-6, "huge g: (%g %g %g)", r.x, r.y,
          r.z);
    /* Double: products that overflow a double still resolve. */
    bg_dvec3 nd = {0, 0, 1e-300}, gd = {1e300, -1e300, 0};
    double wd = 1e300;
    bg_dvec3 rd = bg_resolve_normald(nd, &gd, &wd, 1);
    CHECK(fabs(rd.x + sqrt(0.5)) < 1e-12 && fabs(rd.y - sqrt(0.5)) < 1e-12 && fabs(rd.z) < 1e-12,
          "double overflow case: (%g %g %g)", rd.x, rd.y, rd.z);
    /* Subnormal inputs are still directions. */
    bg_dvec3 nsub = {0, 0, 1e-310}, gsub = {1e300, 0, 0};
    double wsub = 1e-305;
    rd = bg_resolve_normald(nsub, NULL, NULL, 0);
    CHECK(rd.z == 1, "subnormal n: %g", rd.z);
    rd = bg_resolve_normald(nsub, &gsub, &wsub, 1); /* slope 1e-5 */
    CHECK(fabs(rd.x + 1e-5) < 1e-15 && rd.z > 0.999, "subnormal weight: (%g %g)", rd.x, rd.z);
    /* Naive blend of opposite normals: sentinel. */
    bg_vec3 opp[2] = {{0, 0, 1}, {0, 0, -1}};
    CHECK(is_zero_f(bg_blend_normals_naive(opp, NULL, 2)), "opposite normals must cancel");
    bg_dvec3 oppd[2] = {{0, 0, 1}, {0, 1e-300, 0}};
    bg_dvec3 bd = bg_blend_normals_naived(oppd, NULL, 2);
    CHECK(fabs(bd.y - sqrt(0.5)) < 1e-15, "naive normalizes each normal first: %g", bd.y);
}

static void test_resolve_batch(void)
{
    enum { N = 37 };
    float nx[N], ny[N], nz[N], ax[N], ay[N], az[N], gx[2][N], gy[2][N], gz[2][N];
    float ox[N], oy[N], oz[N];
    const float w[2] = {0.75f, -0.4f};
    for (int i = 0; i < N; i++) {
        rv n = rand_dir();
        nx[i] = (float)n.x, ny[i] = (float)n.y, nz[i] = (float)n.z;
        ax[i] = ay[i] = az[i] = 0;
        for (int k = 0; k < 2; k++) {
            rv g = rmul(rproj(n, rand_dir()), 2);
            gx[k][i] = (float)g.x, gy[k][i] = (float)g.y, gz[k][i] = (float)g.z;
        }
    }
    for (int k = 0; k < 2; k++)
        bg_surfgrad_accumulate_batch(w[k], gx[k], gy[k], gz[k], N, ax, ay, az);
    bg_resolve_normal_batch(nx, ny, nz, ax, ay, az, N, ox, oy, oz);
    double worst = 0;
    for (int i = 0; i < N; i++) {
        /* The accumulator holds float sums: per-element resolve of it is bit-exact. */
        bg_vec3 nn = {nx[i], ny[i], nz[i]}, s = {ax[i], ay[i], az[i]};
        bg_vec3 r = bg_resolve_normal(nn, &s, NULL, 1);
        CHECK(r.x == ox[i] && r.y == oy[i] && r.z == oz[i], "batch != single at %d", i);
        bg_vec3 gg[2] = {{gx[0][i], gy[0][i], gz[0][i]}, {gx[1][i], gy[1][i], gz[1][i]}};
        worst = fmax(worst, rdist(from_f(r), from_f(bg_resolve_normal(nn, gg, w, 2))));
    }
    CHECK(worst < 1e-6, "accumulated batch vs weighted resolve: %.3g", worst);
    /* Outputs aliasing the normal inputs. */
    bg_resolve_normal_batch(nx, ny, nz, ax, ay, az, N, nx, ny, nz);
    for (int i = 0; i < N; i++)
        CHECK(nx[i] == ox[i] && ny[i] == oy[i] && nz[i] == oz[i], "aliased batch differs at %d", i);
}

static void test_tangent_normal(void)
{
    double worst = 0, worst_sg = 0, worst_any = 0;
    for (int it = 0; it < 3000; it++) {
        rv t, b, n;
        rand_frame(&t, &b, &n, it & 1);
        rv m = R(urand(-1, 1), urand(-1, 1), urand(0.05, 1));
        bg_vec3 mf = to_f(m);
        m = from_f(mf);
        bg_vec3 sg = bg_surfgrad_from_tangent_normal(to_f(t), to_f(b), mf);
        rv tf = from_f(to_f(t)), bf = from_f(to_f(b)), nf = from_f(to_f(n));
        rv sgref = rsub(rmul(tf, -m.x / m.z), rmul(bf, m.y / m.z));
        worst_sg = fmax(worst_sg, rdist(from_f(sg), sgref) / fmax(1, rlen(sgref)));
        /* normalize(n - sg) == normalize(m.x t + m.y b + m.z n) */
        rv dec = rnorm(radd(radd(rmul(tf, m.x), rmul(bf, m.y)), rmul(nf, m.z)));
        rv res = from_f(bg_resolve_normal(to_f(n), &sg, NULL, 1));
        worst = fmax(worst, rdist(res, dec));
        /* Identity for any frame (t, b not unit or orthogonal), double API. */
        rv ta = rmul(rand_dir(), urand(0.2, 3)), ba = rmul(rand_dir(), urand(0.2, 3));
        bg_dvec3 sgd = bg_surfgrad_from_tangent_normald(to_d(ta), to_d(ba), to_d(m));
        rv decd = rnorm(radd(radd(rmul(ta, m.x), rmul(ba, m.y)), rmul(n, m.z)));
        worst_any = fmax(worst_any, rdist(from_d(bg_resolve_normald(to_d(n), &sgd, NULL, 1)), decd));
        /* m.z < 0 is mirrored: same gradient as |m.z|. */
        bg_vec3 mneg = {mf.x, mf.y, -mf.z};
        bg_vec3 sgn = bg_surfgrad_from_tangent_normal(to_f(t), to_f(b), mneg);
        CHECK(sgn.x == sg.x && sgn.y == sg.y && sgn.z == sg.z, "m.z sign must not matter");
    }
    CHECK(worst_sg < 1e-6, "tangent-normal gradient vs reference: %.3g", worst_sg);
    CHECK(worst < 1e-6, "resolve vs tangent-space decode: %.3g", worst);
    CHECK(worst_any < 1e-13, "double identity for arbitrary frames: %.3g", worst_any);

    /* Clamp at 128 keeps the slope direction. */
    bg_dvec3 t = {1, 0, 0}, b = {0, 1, 0};
    bg_dvec3 m0 = {1, 0.5, 0};
    bg_dvec3 s = bg_surfgrad_from_tangent_normald(t, b, m0);
    CHECK(s.x == -128 && s.y == -64 && s.z == 0, "horizon clamp: (%g %g %g)", s.x, s.y, s.z);
    bg_dvec3 m1 = {-2, 1, 1e-6};
    s = bg_surfgrad_from_tangent_normald(t, b, m1);
    CHECK(s.x == 128 && s.y == -64, "steep clamp: (%g %g)", s.x, s.y);
    bg_dvec3 m2 = {100, -3, 1}; /* inside the bound: untouched */
    s = bg_surfgrad_from_tangent_normald(t, b, m2);
    CHECK(s.x == -100 && s.y == 3, "no clamp below 128: (%g %g)", s.x, s.y);
    bg_dvec3 mz = {0, 0, 0}, mn = {NAN, 0, 1};
    CHECK(is_zero_d(bg_surfgrad_from_tangent_normald(t, b, mz)), "m = 0 must give 0");
    CHECK(is_zero_d(bg_surfgrad_from_tangent_normald(t, b, mn)), "NaN m must give 0");
}

static void test_perturbed_normal(void)
{
    double worst = 0, worst_in = 0;
    for (int it = 0; it < 3000; it++) {
        rv n = rand_dir(), m = rand_dir();
        double k = rdot(m, n);
        if (fabs(k) < 0.02)
            continue; /* slopes near the clamp are tested below */
        rv nl = rmul(n, urand(0.5, 2)), ml = rmul(m, urand(0.5, 2));
        bg_dvec3 sg = bg_surfgrad_from_perturbed_normald(to_d(nl), to_d(ml));
        CHECK(fabs(rdot(from_d(sg), n)) < 1e-14, "gradient not tangent");
        rv res = from_d(bg_resolve_normald(to_d(n), &sg, NULL, 1));
        if (k > 0) {
            worst = fmax(worst, rdist(res, m));
        } else {
            /* Inward m: the resolve gives m mirrored through the tangent plane. */
            rv mir = rsub(m, rmul(n, 2 * k));
            worst_in = fmax(worst_in, rdist(res, mir));
        }
        bg_vec3 sgf = bg_surfgrad_from_perturbed_normal(to_f(nl), to_f(ml));
        CHECK(rdist(from_f(sgf), from_d(sg)) < 1e-5 * fmax(1, rlen(from_d(sg))),
              "float perturbed-normal gradient off");
    }
    CHECK(worst < 1e-13, "resolve of perturbed-normal gradient: %.3g", worst);
    CHECK(worst_in < 1e-13, "inward m mirrored: %.3g", worst_in);
    /* Tangent m: slope clamped to 128 along m, not infinite. */
    bg_dvec3 n = {0, 0, 1}, m = {0.6, 0.8, 0};
    bg_dvec3 sg = bg_surfgrad_from_perturbed_normald(n, m);
    CHECK(fabs(sg.x + 76.8) < 1e-12 && fabs(sg.y + 102.4) < 1e-12 && sg.z == 0,
          "tangent m: (%g %g %g)", sg.x, sg.y, sg.z);
    bg_dvec3 res = bg_resolve_normald(n, &sg, NULL, 1);
    CHECK(fabs(ang(from_d(res), R(0, 0, 1)) - atan(128.0) * 180 / 3.14159265358979323846) < 1e-9,
          "tangent m resolves to the 128 slope");
    bg_dvec3 zero = {0, 0, 0};
    CHECK(is_zero_d(bg_surfgrad_from_perturbed_normald(zero, m)), "zero n");
    CHECK(is_zero_d(bg_surfgrad_from_perturbed_normald(n, zero)), "zero m");
    /* m exactly along -n: mirrored to n, no slope. */
    bg_dvec3 down = {0, 0, -3};
    sg = bg_surfgrad_from_perturbed_normald(n, down);
    CHECK(is_zero_d(sg), "m = -n gives no slope");
}

static void test_mikktspace(void)
{
    double worst = 0, unnorm = 0;
    for (int it = 0; it < 2000; it++) {
        /* Interpolated vertex data: nothing unit, nothing orthogonal. */
        rv vN = rmul(rand_dir(), urand(0.3, 3));
        rv vT = radd(rmul(rperp(rnorm(vN)), urand(0.3, 3)), rmul(rnorm(vN), urand(-0.3, 0.3)));
        float sign = (it & 1) ? -1.0f : 1.0f;
        rv m = R(urand(-1, 1), urand(-1, 1), urand(0.1, 1));
        bg_vec3 vNf = to_f(vN), vTf = to_f(vT), mf = to_f(m);
        vN = from_f(vNf), vT = from_f(vTf), m = from_f(mf);
        /* mikkTSpace's own decode, unnormalized inputs (overview snippet). */
        rv vB = rmul(rcross(vN, vT), sign);
        rv ref = rnorm(radd(radd(rmul(vT, m.x), rmul(vB, m.y)), rmul(vN, m.z)));
        bg_tangent_frame f = bg_mikktspace_renormalize(vTf, sign, vNf);
        CHECK(fabs(rlen(from_f(f.n)) - 1) < 1e-6, "renormalized n not unit");
        bg_vec3 sg = bg_surfgrad_from_tangent_normal(f.t, f.b, mf);
        rv res = from_f(bg_resolve_normal(f.n, &sg, NULL, 1));
        worst = fmax(worst, rdist(res, ref));
        /* Skipping the renormalization (unit n, raw t and b) does not match. */
        bg_vec3 sg2 = bg_surfgrad_from_tangent_normal(vTf, to_f(vB), mf);
        rv res2 = from_f(bg_resolve_normal(vNf, &sg2, NULL, 1));
        if (fabs(rlen(vN) - 1) > 0.5)
            unnorm = fmax(unnorm, rdist(res2, ref));
    }
    CHECK(worst < 2e-6, "renormalized frame vs unnormalized mikkTSpace decode: %.3g", worst);
    CHECK(unnorm > 1e-2, "renormalization should matter: %.3g", unnorm);
    bg_vec3 t = {1, 0, 0}, z = {0, 0, 0};
    bg_tangent_frame f = bg_mikktspace_renormalize(t, 1, z);
    CHECK(is_zero_f(f.t) && is_zero_f(f.b) && is_zero_f(f.n), "zero n gives the zero frame");
    bg_vec3 n = {0, 0, 2};
    f = bg_mikktspace_renormalize(t, -1, n);
    CHECK(f.b.x == 0 && f.b.y == -1.0f && f.b.z == 0 && f.t.x == 0.5f && f.n.z == 1,
          "sign -1 frame: b=(%g %g %g)", f.b.x, f.b.y, f.b.z);
}

static void test_face_forward(void)
{
    bg_vec3 n = {0, 0, 1}, toward = {0.3f, 0, 1}, away = {0.3f, 0, -1}, side = {1, 0, 0};
    bg_vec3 r = bg_face_forward(n, toward);
    CHECK(r.z == 1, "facing normal must stay");
    r = bg_face_forward(n, away);
    CHECK(r.x == 0 && r.y == 0 && r.z == -1, "back-facing normal must flip");
    r = bg_face_forward(n, side);
    CHECK(r.z == 1, "dot == 0 keeps n");
    bg_vec3 nanv = {NAN, 0, 0};
    r = bg_face_forward(n, nanv);
    CHECK(r.z == 1, "NaN view keeps n");
    /* Reference normal decides: an interpolated normal that leans away on a front face. */
    bg_vec3 ni = {0.9f, 0, -0.1f}, ng = {0, 0, 1};
    r = bg_face_forward_ref(ni, ng, toward);
    CHECK(r.x == ni.x && r.z == ni.z, "front face per geometric normal: keep");
    r = bg_face_forward_ref(ni, ng, away);
    CHECK(r.x == -ni.x && r.z == -ni.z, "back face per geometric normal: flip");
    bg_dvec3 nd = {0, 1e300, 0}, vd = {0, -1e300, 1};
    bg_dvec3 rd = bg_face_forwardd(nd, vd);
    CHECK(rd.y == -1e300, "double face-forward without overflow");
    /* The documented rule: with the flipped base normal, a volume gradient's resolve
     * is the front resolve mirrored through the tangent plane (heights displace
     * toward the viewer on both sides). */
    for (int it = 0; it < 200; it++) {
        rv nn = rand_dir(), g = rmul(rand_dir(), 0.7);
        rv v = rmul(nn, -1); /* viewer behind */
        bg_dvec3 nb = bg_face_forwardd(to_d(nn), to_d(v));
        bg_dvec3 sgf = bg_surface_gradientd(to_d(nn), to_d(g));
        bg_dvec3 sgb = bg_surface_gradientd(nb, to_d(g));
        rv front = from_d(bg_resolve_normald(to_d(nn), &sgf, NULL, 1));
        rv back = from_d(bg_resolve_normald(nb, &sgb, NULL, 1));
        rv mir = rsub(front, rmul(nn, 2 * rdot(front, nn)));
        CHECK(rdist(back, mir) < 1e-13, "back resolve is not the mirror");
        CHECK(rdot(back, v) > 0, "back resolve faces away from the viewer");
    }
}

static void test_orange_bump(void)
{
    const float density = 16, size = 0.15f;
    int inside = 0, outside = 0;
    double worst_ref = 0, worst_res = 0;
    for (int j = 0; j < 97; j++) {
        for (int i = 0; i < 97; i++) {
            bg_vec2 st = v2f(i / 96.0 * 0.37 + 0.01, j / 96.0 * 0.41 - 0.2);
            bg_vec3 nb = bg_orange_bump_normal(st, density, size);
            rv nr = from_f(nb);
            CHECK(fabs(rlen(nr) - 1) < 1e-6, "bump normal not unit at %d,%d", i, j);
            /* Reference from the listing, in double. */
            double cx = (double)density * st.x, cy = (double)density * st.y;
            double px = cx - floor(cx) - 0.5, py = cy - floor(cy) - 0.5, d = px * px + py * py;
            rv ref = d >= size ? R(0, 0, 1) : rmul(R(px, py, 1), 1 / sqrt(d + 1));
            if (d >= size) {
                outside++;
                CHECK(nb.x == 0 && nb.y == 0 && nb.z == 1, "not flat outside the bump radius");
            } else {
                inside++;
            }
            worst_ref = fmax(worst_ref, rdist(nr, ref));
            /* As a surface-gradient source: resolve reproduces the decoded normal. */
            rv t, b, n;
            rand_frame(&t, &b, &n, (i + j) & 1);
            bg_vec3 sg = bg_surfgrad_from_tangent_normal(to_f(t), to_f(b), nb);
            if (d >= size)
                CHECK(is_zero_f(sg), "flat bump region must give no gradient");
            rv res = from_f(bg_resolve_normal(to_f(n), &sg, NULL, 1));
            rv tf = from_f(to_f(t)), bf = from_f(to_f(b)), nf = from_f(to_f(n));
            rv dec = rnorm(radd(radd(rmul(tf, nr.x), rmul(bf, nr.y)), rmul(nf, nr.z)));
            worst_res = fmax(worst_res, rdist(res, dec));
        }
    }
    CHECK(inside > 1000 && outside > 1000, "grid should cover both regions (%d, %d)", inside,
          outside);
    CHECK(worst_ref < 1e-7, "bump normal vs listing: %.3g", worst_ref);
    CHECK(worst_res < 1e-6, "bump normal through the resolve: %.3g", worst_res);
    /* Bump centre is flat-topped (p = 0), rim normal leans outward (convex). */
    bg_vec3 c = bg_orange_bump_normal(v2f(0.5 / 16, 0.5 / 16), density, size);
    CHECK(c.x == 0 && c.y == 0 && c.z == 1, "bump centre");
    bg_vec3 e = bg_orange_bump_normal(v2f((0.5 + 0.3) / 16, 0.5 / 16), density, size);
    CHECK(e.x > 0.25f && e.y == 0, "bump leans outward: %g", e.x);
    bg_vec3 q = bg_orange_bump_normal(v2f(NAN, 0), density, size);
    CHECK(q.x == 0 && q.y == 0 && q.z == 1, "NaN st gives the flat normal");

    /* Shading of Listing 11.8 against a double transcription of it. */
    const bg_vec3 color = {0.7f, 0.6f, 0.18f};
    double worst_shade = 0;
    for (int it = 0; it < 500; it++) {
        bg_vec3 nb = bg_orange_bump_normal(v2f(urand(0, 1), urand(0, 1)), density, size);
        rv l = rand_dir(), eye = rand_dir();
        bg_vec3 lit = bg_orange_bump_shade(nb, to_f(l), to_f(eye), color, 0.5f);
        rv nr = from_f(nb), lf = from_f(to_f(l)), ef = from_f(to_f(eye));
        double nl = rdot(nr, lf), diff = fmax(nl, 0);
        rv refl = rsub(lf, rmul(nr, 2 * nl));
        double sp = pow(fmax(rdot(ef, refl), 0), 6) * 0.5;
        rv ref = R(fmin(color.x * diff + sp, 1), fmin(color.y * diff + sp, 1),
                   fmin(color.z * diff + sp, 1));
        worst_shade = fmax(worst_shade, rdist(from_f(lit), ref));
    }
    CHECK(worst_shade < 1e-5, "shading vs listing: %.3g", worst_shade);
    /* Light along the flat normal, eye looking straight down the mirror direction:
     * full diffuse plus full specular, clamped to 1. */
    bg_vec3 flat = {0, 0, 1}, l = {0, 0, 1}, eye = {0, 0, -1}, white = {1, 1, 1};
    bg_vec3 lit = bg_orange_bump_shade(flat, l, eye, color, 0.5f);
    CHECK(fabsf(lit.x - 1.0f) < 1e-6f && fabsf(lit.y - 1.0f) < 1e-6f &&
              fabsf(lit.z - 0.68f) < 1e-6f,
          "head-on shade: (%g %g %g)", lit.x, lit.y, lit.z);
    lit = bg_orange_bump_shade(flat, l, eye, white, 0.5f);
    CHECK(lit.x == 1 && lit.y == 1 && lit.z == 1, "clamp to 1");
}

int main(void)
{
    test_resolve_reference();
    test_flat_influence();
    test_resolve_degenerate();
    test_resolve_batch();
    test_tangent_normal();
    test_perturbed_normal();
    test_mikktspace();
    test_face_forward();
    test_orange_bump();
    return check_summary("test_fw_normals");
}
