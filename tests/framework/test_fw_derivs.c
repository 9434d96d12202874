/* SPDX-License-Identifier: MIT */
/* Derivative side of the framework: eq. 3 from parametric and screen derivatives
 * (and Listing 1), the triplanar gradient, the tangent frame from UV derivatives
 * (compute_tbn) and ray differentials. The references are known height fields and
 * known surfaces: the surface gradient must equal the projection (eq. 2) of the
 * field's gradient, frames must equal the parametrization's own tangents, and ray
 * differentials must equal finite differences of actual ray hits. */
#include "fw_check.h"

/* h(P) = a.P + 0.5 P^T Q P, Q symmetric: gradient a + Q P. */
static const double HA[3] = {0.3, -0.7, 0.45};
static const double HQ[3][3] = {{0.8, 0.2, -0.1}, {0.2, -0.5, 0.3}, {-0.1, 0.3, 0.25}};
static rv hgrad(rv p)
{
    double q[3] = {p.x, p.y, p.z}, g[3];
    for (int i = 0; i < 3; i++)
        g[i] = HA[i] + HQ[i][0] * q[0] + HQ[i][1] * q[1] + HQ[i][2] * q[2];
    return R(g[0], g[1], g[2]);
}

static double rel(rv a, rv ref) { return rdist(a, ref) / fmax(1e-300, rlen(ref)); }

static void test_eq3_plane(void)
{
    double worst_d = 0, worst_f = 0, worst_l1 = 0;
    for (int it = 0; it < 2000; it++) {
        rv U = rmul(rand_dir(), urand(0.1, 3)), V = rmul(rand_dir(), urand(0.1, 3));
        if (rlen(rcross(rnorm(U), rnorm(V))) < 0.2)
            continue;
        rv P = radd(radd(R(urand(-2, 2), urand(-2, 2), urand(-2, 2)), rmul(U, urand(-1, 1))),
                    rmul(V, urand(-1, 1)));
        /* odd iterations: n against U x V, an orientation-reversing chart */
        rv n = rmul(rnorm(rcross(U, V)), (it & 1) ? -1.0 : 1.0);
        rv g = hgrad(P);
        double bs = rdot(g, U), bt = rdot(g, V); /* chain rule, exact */
        rv ref = rproj(n, g);
        bg_dvec3 sd = bg_surfgrad_from_param_derivsd(to_d(rmul(n, 2.5)), to_d(U), to_d(V), bs, bt);
        worst_d = fmax(worst_d, rel(from_d(sd), ref));
        bg_vec3 sf = bg_surfgrad_from_param_derivs(to_f(n), to_f(U), to_f(V), (float)bs, (float)bt);
        worst_f = fmax(worst_f, rdist(from_f(sf), ref) / fmax(1, rlen(ref)));
        /* Listing 1 (division-free) == resolve of the eq. 3 gradient. */
        rv l1 = from_d(bg_perturb_normal_screend(to_d(n), to_d(U), to_d(V), bs, bt));
        rv r = from_d(bg_resolve_normald(to_d(n), &sd, NULL, 1));
        worst_l1 = fmax(worst_l1, rdist(l1, r));
        /* Swapping the parameters reverses orientation: same gradient. */
        bg_dvec3 sw = bg_surfgrad_from_param_derivsd(to_d(n), to_d(V), to_d(U), bt, bs);
        CHECK(rel(from_d(sw), ref) < 1e-12, "swapped chart differs");
    }
    CHECK(worst_d < 1e-12, "double eq. 3 vs eq. 2 on planes: %.3g", worst_d);
    CHECK(worst_f < 2e-5, "float eq. 3 vs eq. 2 on planes: %.3g", worst_f);
    CHECK(worst_l1 < 1e-13, "Listing 1 vs resolve: %.3g", worst_l1);
}

static void test_eq3_sphere(void)
{
    double worst = 0;
    for (int it = 0; it < 2000; it++) {
        double r = urand(0.5, 3), th = urand(0.3, 2.8), ph = urand(-3, 3);
        rv c = R(urand(-1, 1), urand(-1, 1), urand(-1, 1));
        rv n = R(sin(th) * cos(ph), sin(th) * sin(ph), cos(th));
        rv P = radd(c, rmul(n, r));
        rv st = rmul(R(cos(th) * cos(ph), cos(th) * sin(ph), -sin(th)), r);
        rv sp = rmul(R(-sin(th) * sin(ph), sin(th) * cos(ph), 0), r);
        rv g = hgrad(P), ref = rproj(n, g);
        double bth = rdot(g, st), bph = rdot(g, sp);
        /* preserving (theta, phi), reversing (phi, theta), mirrored (-theta, phi) */
        bg_dvec3 a = bg_surfgrad_from_param_derivsd(to_d(n), to_d(st), to_d(sp), bth, bph);
        bg_dvec3 b = bg_surfgrad_from_param_derivsd(to_d(n), to_d(sp), to_d(st), bph, bth);
        bg_dvec3 m = bg_surfgrad_from_param_derivsd(to_d(n), to_d(rmul(st, -1)), to_d(sp), -bth, bph);
        worst = fmax(worst, fmax(rel(from_d(a), ref), fmax(rel(from_d(b), ref), rel(from_d(m), ref))));
        /* Screen chart: any invertible 2x2 map of (theta, phi) to pixels. */
        double j00 = urand(-2, 2), j01 = urand(-2, 2), j10 = urand(-2, 2), j11 = urand(-2, 2);
        if (fabs(j00 * j11 - j01 * j10) < 0.1)
            continue;
        /* d(theta,phi)/d(x,y) = [[j00 j01][j10 j11]] */
        rv dpdx = radd(rmul(st, j00), rmul(sp, j10)), dpdy = radd(rmul(st, j01), rmul(sp, j11));
        bg_dvec3 s = bg_surfgrad_from_screen_derivsd(to_d(n), to_d(dpdx), to_d(dpdy),
                                                    rdot(g, dpdx), rdot(g, dpdy));
        worst = fmax(worst, rel(from_d(s), ref));
    }
    CHECK(worst < 1e-11, "eq. 3 vs eq. 2 on sphere patches: %.3g", worst);
}

static void test_eq3_degenerate(void)
{
    bg_dvec3 n = {0, 0, 1}, u = {1, 0, 0}, v = {2, 0, 0}, w = {0, 1, 0};
    CHECK(is_zero_d(bg_surfgrad_from_param_derivsd(n, u, v, 1, 1)), "parallel chart");
    bg_dvec3 r = bg_perturb_normal_screend(n, u, v, 1, 1);
    CHECK(r.x == 0 && r.y == 0 && r.z == 1, "Listing 1 with det 0 gives n");
    bg_dvec3 zero = {0, 0, 0};
    CHECK(is_zero_d(bg_surfgrad_from_param_derivsd(zero, u, w, 1, 1)), "zero n");
    CHECK(is_zero_d(bg_surfgrad_from_param_derivsd(n, u, w, NAN, 1)), "NaN beta");
    /* The sign of n does not matter (eq. 3 numerator and denominator both flip). */
    bg_dvec3 nm = {0, 0, -1};
    bg_dvec3 a = bg_surfgrad_from_param_derivsd(n, u, w, 0.3, -0.2);
    bg_dvec3 b = bg_surfgrad_from_param_derivsd(nm, u, w, 0.3, -0.2);
    CHECK(a.x == b.x && a.y == b.y && a.z == b.z && a.x == 0.3 && a.y == -0.2, "sign of n");
    /* Tiny pixel footprints (1e-30) keep working, in float too. */
    bg_vec3 nf = {0, 0, 1}, uf = {1e-30f, 0, 0}, wf = {0, 2e-30f, 0};
    bg_vec3 sf = bg_surfgrad_from_screen_derivs(nf, uf, wf, 3e-30f, -2e-30f);
    CHECK(fabsf(sf.x - 3) < 1e-5f && fabsf(sf.y + 1) < 1e-5f, "tiny chart: (%g %g)", sf.x, sf.y);
    /* Steep but finite: Listing 1 tends to the tangent direction. */
    bg_dvec3 steep = bg_perturb_normal_screend(n, u, w, 1e200, 0);
    CHECK(fabs(steep.x + 1) < 1e-12 && isfinite(steep.z), "steep Listing 1");
}

/* ---- triplanar ---------------------------------------------------------------- */

static void test_triplanar(void)
{
    /* weights: the default is the reference's max(0, |n_i| - 0.2)^k, the power
     * blend |n_i|^k is BG_TRIPLANAR_POWER; both written out here. */
    rv n = rnorm(R(1, -2, 3));
    bg_dvec3 w = bg_triplanar_weights_exd(to_d(n), 4, BG_TRIPLANAR_POWER);
    double s = pow(fabs(n.x), 4) + pow(fabs(n.y), 4) + pow(fabs(n.z), 4);
    CHECK(fabs(w.x - pow(n.x, 4) / s) < 1e-15 && fabs(w.y - pow(n.y, 4) / s) < 1e-15 &&
              fabs(w.z - pow(n.z, 4) / s) < 1e-15,
          "power weights k=4");
    w = bg_triplanar_weightsd(to_d(n), 4);
    s = pow(fabs(n.x) - 0.2, 4) + pow(fabs(n.y) - 0.2, 4) + pow(fabs(n.z) - 0.2, 4);
    CHECK(fabs(w.x - pow(fabs(n.x) - 0.2, 4) / s) < 1e-15 &&
              fabs(w.y - pow(fabs(n.y) - 0.2, 4) / s) < 1e-15 &&
              fabs(w.z - pow(fabs(n.z) - 0.2, 4) / s) < 1e-15,
          "offset weights k=4");
    for (int mode = 0; mode < 2; mode++) {
        bg_triplanar_weighting m = mode ? BG_TRIPLANAR_POWER : BG_TRIPLANAR_OFFSET;
        w = bg_triplanar_weights_exd(to_d(n), 0, m);
        CHECK(fabs(w.x - 1.0 / 3) < 1e-15 && fabs(w.z - 1.0 / 3) < 1e-15, "k=0 gives thirds");
        w = bg_triplanar_weights_exd(to_d(n), 5000, m);
        CHECK(w.z == 1 && w.x == 0 && w.y == 0, "large k: dominant axis only (%g %g %g)", w.x,
              w.y, w.z);
        CHECK(is_zero_d(bg_triplanar_weights_exd(to_d(n), -1, m)), "negative k");
    }
    CHECK(is_zero_d(bg_triplanar_weights_exd(to_d(n), 1, (bg_triplanar_weighting)7)),
          "unknown weighting");
    /* An axis within the reference's dead zone (|n_x| <= 0.2) has weight 0 at every
     * k, also k = 0, where the other two share equally. */
    rv nd = rnorm(R(0.1, 0.5, 0.86));
    w = bg_triplanar_weightsd(to_d(nd), 0);
    CHECK(w.x == 0 && fabs(w.y - 0.5) < 1e-15 && fabs(w.z - 0.5) < 1e-15,
          "dead zone at k=0: (%g %g %g)", w.x, w.y, w.z);
    w = bg_triplanar_weightsd(to_d(nd), 0.5);
    CHECK(w.x == 0 && w.y > 0, "dead zone at k=0.5");

    /* h = f(x, y) = sin(2x) + x y^2: a function of the xy plane. */
    double worst_exact = 0, worst_ref = 0;
    for (int it = 0; it < 500; it++) {
        rv P = R(urand(-3, 3), urand(-3, 3), urand(-3, 3));
        double fx = 2 * cos(2 * P.x) + P.y * P.y, fy = 2 * P.x * P.y;
        rv g = R(fx, fy, 0);
        bg_dvec2 dxy = v2d(fx, fy), junk = v2d(NAN, 1e30);
        /* n = +z or -z: only the xy plane is read, result is exactly eq. 2. */
        rv nz = R(0, 0, (it & 1) ? -1 : 1);
        bg_dvec3 r = bg_surfgrad_triplanard(to_d(nz), 3, junk, junk, dxy);
        worst_exact = fmax(worst_exact, rdist(from_d(r), rproj(nz, g)));
        /* Same field seen from the yz plane: h = f(y, z) with n = -x. */
        bg_dvec2 dyz = v2d(fx, fy); /* (dh/dy, dh/dz) of h = f(y, z) */
        rv nx = R(-1, 0, 0);
        r = bg_surfgrad_triplanard(to_d(nx), 3, dyz, junk, junk);
        worst_exact = fmax(worst_exact, rdist(from_d(r), rproj(nx, R(0, fx, fy))));
        /* General n against the documented formula, written out here. */
        rv nn = rand_dir();
        double k = urand(0, 8);
        bg_dvec2 a = v2d(urand(-1, 1), urand(-1, 1)), b = v2d(urand(-1, 1), urand(-1, 1));
        double ax = pow(fmax(fabs(nn.x) - 0.2, 0), k), ay = pow(fmax(fabs(nn.y) - 0.2, 0), k),
               az = pow(fmax(fabs(nn.z) - 0.2, 0), k);
        double sum = ax + ay + az;
        rv gg = radd(radd(rmul(R(0, a.x, a.y), ax / sum), rmul(R(b.x, 0, b.y), ay / sum)),
                     rmul(R(fx, fy, 0), az / sum));
        bg_dvec3 rg = bg_surfgrad_triplanard(to_d(nn), k, a, b, dxy);
        worst_ref = fmax(worst_ref, rdist(from_d(rg), rproj(nn, gg)) / fmax(1, rlen(gg)));
        /* The power blend through the caller-weights call. */
        double px = pow(fabs(nn.x), k), py = pow(fabs(nn.y), k), pz = pow(fabs(nn.z), k);
        double ps = px + py + pz;
        rv gp = radd(radd(rmul(R(0, a.x, a.y), px / ps), rmul(R(b.x, 0, b.y), py / ps)),
                     rmul(R(fx, fy, 0), pz / ps));
        bg_dvec3 wp = bg_triplanar_weights_exd(to_d(nn), k, BG_TRIPLANAR_POWER);
        bg_dvec3 rp = bg_surfgrad_triplanar_weightedd(to_d(nn), wp, a, b, dxy);
        worst_ref = fmax(worst_ref, rdist(from_d(rp), rproj(nn, gp)) / fmax(1, rlen(gp)));
        bg_vec3 rf = bg_surfgrad_triplanar(to_f(nn), (float)k, v2f(a.x, a.y), v2f(b.x, b.y),
                                           v2f(fx, fy));
        CHECK(rdist(from_f(rf), from_d(rg)) < 1e-5 * fmax(1, rlen(gg)), "float triplanar");
    }
    CHECK(worst_exact < 1e-15, "triplanar on a one-plane field: %.3g", worst_exact);
    CHECK(worst_ref < 1e-14, "triplanar vs formula: %.3g", worst_ref);
    /* A non-finite sample that is actually used: no perturbation. */
    CHECK(is_zero_d(bg_surfgrad_triplanard(to_d(n), 2, v2d(NAN, 0), v2d(0, 0), v2d(0, 0))),
          "NaN sample with weight");
}

/* ---- tangent frame from UV derivatives --------------------------------------------- */

/* Expected frame for chart tangents (A = dP/du, B = dP/dv) and normal n:
 * t = normalize(proj(A)), b = sign(n.(A x B)) normalize(n x t). */
static void expected_frame(rv n, rv A, rv B, rv *t, rv *b)
{
    *t = rnorm(rproj(n, A));
    double h = rdot(n, rcross(A, B)) > 0 ? 1 : -1;
    *b = rmul(rnorm(rcross(n, *t)), h);
}

static void check_frame(rv n, rv A, rv B, double *worst, int it)
{
    /* A random screen map: d(u,v)/d(x,y) = J (either sign of det). */
    double j00 = urand(-2, 2), j01 = urand(-2, 2), j10 = urand(-2, 2), j11 = urand(-2, 2);
    if (fabs(j00 * j11 - j01 * j10) < 0.05)
        return;
    rv dpdx = radd(rmul(A, j00), rmul(B, j10)), dpdy = radd(rmul(A, j01), rmul(B, j11));
    bg_dtangent_frame f = bg_tangent_frame_from_derivsd(to_d(n), to_d(dpdx), to_d(dpdy),
                                                        v2d(j00, j10), v2d(j01, j11));
    rv t, b;
    expected_frame(rnorm(n), A, B, &t, &b);
    double e = fmax(rdist(from_d(f.t), t), rdist(from_d(f.b), b));
    if (e > 1e-9 && *worst <= 1e-9)
        printf("  frame mismatch at it=%d: t=(%g %g %g) want (%g %g %g)\n", it, f.t.x, f.t.y,
               f.t.z, t.x, t.y, t.z);
    *worst = fmax(*worst, e);
    CHECK(rdist(from_d(f.n), rnorm(n)) < 1e-15, "frame n must be the unit n");
}

static void test_tangent_frame(void)
{
    double worst = 0;
    for (int it = 0; it < 2000; it++) {
        /* Plane, non-orthogonal UV axes, mirrored u on odd iterations, seen from
         * either side (n along or against A x B). */
        rv A = rmul(rand_dir(), urand(0.2, 3)), B = rmul(rand_dir(), urand(0.2, 3));
        if (rlen(rcross(rnorm(A), rnorm(B))) < 0.2)
            continue;
        if (it & 1)
            A = rmul(A, -1); /* u' = -u */
        rv n = rmul(rnorm(rcross(A, B)), (it & 2) ? -1.0 : 1.0);
        check_frame(n, A, B, &worst, it);
        /* An interpolated normal that is not the plane's: the projection matters. */
        rv ni = rnorm(radd(n, rmul(rperp(n), 0.2)));
        check_frame(ni, A, B, &worst, it);
        /* Sphere patch, lat-long (orthogonal tangents): b must be dP/dv's direction. */
        double th = urand(0.3, 2.8), ph = urand(-3, 3), mir = (it & 1) ? -1.0 : 1.0;
        rv sn = R(sin(th) * cos(ph), sin(th) * sin(ph), cos(th));
        rv su = rmul(R(cos(th) * cos(ph), cos(th) * sin(ph), -sin(th)), mir); /* u = mir*theta */
        rv sv = R(-sin(th) * sin(ph), sin(th) * cos(ph), 0);
        check_frame(sn, su, sv, &worst, it);
        rv t, b;
        expected_frame(sn, su, sv, &t, &b);
        CHECK(rdist(b, rnorm(sv)) < 1e-12, "sphere: b is not dP/dv");
    }
    CHECK(worst < 1e-9, "tangent frame vs chart tangents: %.3g", worst);

    /* Float API and the decode through the framework on the same frame. */
    rv A = R(1, 0.3, 0), B = R(-0.2, 1, 0), n = R(0, 0, 1);
    bg_tangent_frame ff = bg_tangent_frame_from_derivs(to_f(n), to_f(A), to_f(B), v2f(-1, 0),
                                                       v2f(0, 1)); /* u mirrored */
    rv t, b;
    expected_frame(n, rmul(A, -1), B, &t, &b);
    CHECK(rdist(from_f(ff.t), t) < 1e-6 && rdist(from_f(ff.b), b) < 1e-6, "float frame");
    /* Degenerate UVs: zero t and b, and the tangent normal then does nothing. */
    bg_tangent_frame fz =
        bg_tangent_frame_from_derivs(to_f(n), to_f(A), to_f(B), v2f(1, 2), v2f(2, 4));
    CHECK(is_zero_f(fz.t) && is_zero_f(fz.b) && fz.n.z == 1, "degenerate UV frame");
    bg_vec3 m = {0.3f, 0.2f, 0.9f};
    bg_vec3 sg = bg_surfgrad_from_tangent_normal(fz.t, fz.b, m);
    CHECK(is_zero_f(sg), "degenerate frame must give no gradient");
}

/* ---- ray differentials -------------------------------------------------------------- */

/* Ray-plane (n.X = n.q) and ray-sphere (centre c, radius r) hits from o along d. */
static rv hit_plane(rv o, rv d, rv pn, rv q) { return radd(o, rmul(d, rdot(pn, rsub(q, o)) / rdot(pn, d))); }
static rv hit_sphere(rv o, rv d, rv c, double r)
{
    rv oc = rsub(o, c);
    double a = rdot(d, d), b = rdot(oc, d), cc = rdot(oc, oc) - r * r;
    double s = (-b - sqrt(b * b - a * cc)) / a;
    return radd(o, rmul(d, s));
}

typedef struct {
    rv c, f, rt, dn; /* camera, forward, right per pixel, down per pixel */
    double cx, cy;
} pinhole;

static rv pin_dir(const pinhole *cam, double x, double y)
{
    return radd(cam->f, radd(rmul(cam->rt, x - cam->cx), rmul(cam->dn, y - cam->cy)));
}

static void test_ray_differentials(void)
{
    double worst = 0, worst_norm = 0, worst_f = 0, worst_sg = 0;
    for (int it = 0; it < 400; it++) {
        pinhole cam;
        cam.c = R(urand(-2, 2), urand(-2, 2), urand(-2, 2));
        cam.f = rand_dir();
        rv right = rperp(cam.f), down = rcross(cam.f, right);
        double px = urand(5e-4, 3e-3);
        cam.rt = rmul(right, px), cam.dn = rmul(down, px);
        cam.cx = 320, cam.cy = 240;
        double x = urand(0, 640), y = urand(0, 480);
        rv d = pin_dir(&cam, x, y);
        const double h = 1e-3;
        rv p, n, fx, fy;
        if (it & 1) { /* sphere in front of the camera */
            rv sc = radd(cam.c, rmul(cam.f, urand(4, 8)));
            double r = 2.5;
            rv oc = rsub(cam.c, sc);
            double b = rdot(oc, d), disc = b * b - rdot(d, d) * (rdot(oc, oc) - r * r);
            if (disc < 0.05)
                continue;
            p = hit_sphere(cam.c, d, sc, r);
            n = rnorm(rsub(p, sc));
            fx = rmul(rsub(hit_sphere(cam.c, pin_dir(&cam, x + h, y), sc, r),
                           hit_sphere(cam.c, pin_dir(&cam, x - h, y), sc, r)), 0.5 / h);
            fy = rmul(rsub(hit_sphere(cam.c, pin_dir(&cam, x, y + h), sc, r),
                           hit_sphere(cam.c, pin_dir(&cam, x, y - h), sc, r)), 0.5 / h);
        } else { /* plane, normal toward or away from the camera */
            rv pn = rand_dir();
            if (fabs(rdot(pn, rnorm(d))) < 0.15)
                continue;
            rv q = radd(cam.c, rmul(cam.f, urand(2, 10)));
            p = hit_plane(cam.c, d, pn, q);
            n = pn;
            fx = rmul(rsub(hit_plane(cam.c, pin_dir(&cam, x + h, y), pn, q),
                           hit_plane(cam.c, pin_dir(&cam, x - h, y), pn, q)), 0.5 / h);
            fy = rmul(rsub(hit_plane(cam.c, pin_dir(&cam, x, y + h), pn, q),
                           hit_plane(cam.c, pin_dir(&cam, x, y - h), pn, q)), 0.5 / h);
        }
        bg_dvec3 ax, ay;
        bg_ray_differentialsd(to_d(p), to_d(n), to_d(cam.c), to_d(d), to_d(cam.rt), to_d(cam.dn),
                              &ax, &ay);
        worst = fmax(worst, fmax(rel(from_d(ax), fx), rel(from_d(ay), fy)));
        /* Normalized direction with the derivative of the normalized direction. */
        double l = rlen(d);
        rv dn = rmul(d, 1 / l);
        rv ddx = rsub(rmul(cam.rt, 1 / l), rmul(d, rdot(d, cam.rt) / (l * l * l)));
        rv ddy = rsub(rmul(cam.dn, 1 / l), rmul(d, rdot(d, cam.dn) / (l * l * l)));
        bg_dvec3 bx, by;
        bg_ray_differentialsd(to_d(p), to_d(rmul(n, -3)), to_d(cam.c), to_d(dn), to_d(ddx),
                              to_d(ddy), &bx, &by);
        worst_norm = fmax(worst_norm, fmax(rel(from_d(bx), fx), rel(from_d(by), fy)));
        bg_vec3 cx, cy;
        bg_ray_differentials(to_f(p), to_f(n), to_f(cam.c), to_f(d), to_f(cam.rt), to_f(cam.dn),
                             &cx, &cy);
        worst_f = fmax(worst_f, fmax(rel(from_f(cx), fx), rel(from_f(cy), fy)));
        /* Into eq. 3: the screen-space surface gradient of a solid field equals eq. 2. */
        rv g = hgrad(p);
        bg_dvec3 sg = bg_surfgrad_from_screen_derivsd(to_d(n), ax, ay, rdot(g, from_d(ax)),
                                                     rdot(g, from_d(ay)));
        worst_sg = fmax(worst_sg, rel(from_d(sg), rproj(n, g)));
    }
    CHECK(worst < 1e-6, "ray differentials vs finite differences of hits: %.3g", worst);
    CHECK(worst_norm < 1e-6, "normalized-direction convention: %.3g", worst_norm);
    CHECK(worst_f < 1e-4, "float ray differentials: %.3g", worst_f);
    CHECK(worst_sg < 1e-9, "screen eq. 3 with ray differentials vs eq. 2: %.3g", worst_sg);
    /* Grazing ray: zeros. */
    bg_dvec3 zx, zy, p = {0, 0, 0}, n = {0, 0, 1}, c = {-1, 0, 0}, d = {1, 0, 0}, dd = {0, 1, 0};
    bg_ray_differentialsd(p, n, c, d, dd, dd, &zx, &zy);
    CHECK(is_zero_d(zx) && is_zero_d(zy), "grazing ray must give zeros");
}

/* 4x4 row-major helpers for the camera matrices (column vectors). */
static void mat_mul(const double *a, const double *b, double *o)
{
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) {
            double s = 0;
            for (int k = 0; k < 4; k++)
                s += a[4 * r + k] * b[4 * k + c];
            o[4 * r + c] = s;
        }
}

static int mat_inv(const double *m, double *inv) /* Gauss-Jordan, partial pivoting */
{
    double a[4][8];
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 8; c++)
            a[r][c] = c < 4 ? m[4 * r + c] : (c - 4 == r);
    for (int c = 0; c < 4; c++) {
        int piv = c;
        for (int r = c + 1; r < 4; r++)
            if (fabs(a[r][c]) > fabs(a[piv][c]))
                piv = r;
        if (a[piv][c] == 0)
            return 0;
        for (int k = 0; k < 8; k++) {
            double t = a[c][k];
            a[c][k] = a[piv][k], a[piv][k] = t;
        }
        double d = a[c][c];
        for (int k = 0; k < 8; k++)
            a[c][k] /= d;
        for (int r = 0; r < 4; r++)
            if (r != c) {
                double f = a[r][c];
                for (int k = 0; k < 8; k++)
                    a[r][k] -= f * a[c][k];
            }
    }
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            inv[4 * r + c] = a[r][c + 4];
    return 1;
}

static void look_at(rv eye, rv target, rv up, double *v)
{
    rv f = rnorm(rsub(target, eye)), s = rnorm(rcross(f, up)), u = rcross(s, f);
    double m[16] = {s.x,  s.y,  s.z,  -rdot(s, eye), u.x, u.y, u.z, -rdot(u, eye),
                    -f.x, -f.y, -f.z, rdot(f, eye),  0,   0,   0,   1};
    for (int i = 0; i < 16; i++)
        v[i] = m[i];
}

/* The test's own pixel ray: unproject NDC depths 0.1 and 0.9. */
static void pixel_ray(const double *inv, double px, double py, double w, double h, rv *o, rv *d)
{
    double x = 2 * px / w - 1, y = 1 - 2 * py / h, z[2] = {0.1, 0.9};
    rv pt[2];
    for (int k = 0; k < 2; k++) {
        double v[4] = {x, y, z[k], 1}, o4[4];
        for (int r = 0; r < 4; r++)
            o4[r] = inv[4 * r] * v[0] + inv[4 * r + 1] * v[1] + inv[4 * r + 2] * v[2] +
                    inv[4 * r + 3] * v[3];
        pt[k] = R(o4[0] / o4[3], o4[1] / o4[3], o4[2] / o4[3]);
    }
    *o = pt[0], *d = rsub(pt[1], pt[0]);
}

static void test_inv_viewproj(void)
{
    const double W = 800, H = 600, aspect = W / H, c = 1 / tan(0.5 * 0.9), nr = 0.1, fr = 100;
    double proj[3][16] = {
        /* GL perspective */
        {c / aspect, 0, 0, 0, 0, c, 0, 0, 0, 0, (fr + nr) / (nr - fr), 2 * fr * nr / (nr - fr), 0, 0,
         -1, 0},
        /* orthographic, 8 x 6 units */
        {2 / 8.0, 0, 0, 0, 0, 2 / 6.0, 0, 0, 0, 0, -2 / (fr - nr), -(fr + nr) / (fr - nr), 0, 0, 0,
         1},
        /* reversed-Z infinite perspective (D3D style depth 1 at near, 0 at infinity) */
        {c / aspect, 0, 0, 0, 0, c, 0, 0, 0, 0, 0, nr, 0, 0, -1, 0},
    };
    double worst[3] = {0, 0, 0}, worst_f = 0;
    for (int it = 0; it < 300; it++) {
        int k = it % 3;
        rv eye = R(urand(-3, 3), urand(-3, 3), urand(5, 9)), target = R(urand(-1, 1), urand(-1, 1), 0);
        double view[16], vp[16], inv[16];
        look_at(eye, target, R(0, 1, 0), view);
        mat_mul(proj[k], view, vp);
        if (!mat_inv(vp, inv))
            continue;
        double px = urand(100, 700), py = urand(100, 500), h = 1e-3;
        rv o, d, p, n, fx, fy, o1, d1, o2, d2;
        pixel_ray(inv, px, py, W, H, &o, &d);
        if ((it / 3) & 1) {
            rv sc = target;
            double r = 2;
            rv oc = rsub(o, sc);
            double b = rdot(oc, d), disc = b * b - rdot(d, d) * (rdot(oc, oc) - r * r);
            if (disc < 0.1 * rdot(d, d))
                continue;
            p = hit_sphere(o, d, sc, r);
            n = rnorm(rsub(p, sc));
            pixel_ray(inv, px + h, py, W, H, &o1, &d1);
            pixel_ray(inv, px - h, py, W, H, &o2, &d2);
            fx = rmul(rsub(hit_sphere(o1, d1, sc, r), hit_sphere(o2, d2, sc, r)), 0.5 / h);
            pixel_ray(inv, px, py + h, W, H, &o1, &d1);
            pixel_ray(inv, px, py - h, W, H, &o2, &d2);
            fy = rmul(rsub(hit_sphere(o1, d1, sc, r), hit_sphere(o2, d2, sc, r)), 0.5 / h);
        } else {
            rv pn = rand_dir(), q = target;
            if (fabs(rdot(pn, rnorm(d))) < 0.2)
                continue;
            p = hit_plane(o, d, pn, q);
            n = pn;
            pixel_ray(inv, px + h, py, W, H, &o1, &d1);
            pixel_ray(inv, px - h, py, W, H, &o2, &d2);
            fx = rmul(rsub(hit_plane(o1, d1, pn, q), hit_plane(o2, d2, pn, q)), 0.5 / h);
            pixel_ray(inv, px, py + h, W, H, &o1, &d1);
            pixel_ray(inv, px, py - h, W, H, &o2, &d2);
            fy = rmul(rsub(hit_plane(o1, d1, pn, q), hit_plane(o2, d2, pn, q)), 0.5 / h);
        }
        bg_dvec3 ax, ay;
        bg_ray_differentials_inv_viewprojd(inv, v2d(px, py), v2d(W, H), to_d(p), to_d(n), &ax, &ay);
        worst[k] = fmax(worst[k], fmax(rel(from_d(ax), fx), rel(from_d(ay), fy)));
        float invf[16];
        for (int i = 0; i < 16; i++)
            invf[i] = (float)inv[i];
        bg_vec3 bx, by;
        bg_ray_differentials_inv_viewproj(invf, v2f(px, py), v2f(W, H), to_f(p), to_f(n), &bx, &by);
        worst_f = fmax(worst_f, fmax(rel(from_f(bx), fx), rel(from_f(by), fy)));
    }
    CHECK(worst[0] < 1e-6, "GL perspective: %.3g", worst[0]);
    CHECK(worst[1] < 1e-6, "orthographic: %.3g", worst[1]);
    CHECK(worst[2] < 1e-6, "reversed-Z infinite perspective: %.3g", worst[2]);
    CHECK(worst_f < 1e-3, "float inverse view-projection: %.3g", worst_f);
    bg_dvec3 zx, zy, p = {0, 0, 0}, n = {0, 0, 1};
    double zero[16] = {0};
    bg_ray_differentials_inv_viewprojd(zero, v2d(1, 1), v2d(2, 2), p, n, &zx, &zy);
    CHECK(is_zero_d(zx) && is_zero_d(zy), "singular matrix must give zeros");
}

int main(void)
{
    test_eq3_plane();
    test_eq3_sphere();
    test_eq3_degenerate();
    test_triplanar();
    test_tangent_frame();
    test_ray_differentials();
    test_inv_viewproj();
    return check_summary("test_fw_derivs");
}
