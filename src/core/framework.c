/* SPDX-License-Identifier: MIT */
/* The surface-gradient framework (Mikkelsen 2020 as retold in the overview seed;
 * Mikkelsen 2010 eq. 2-4, Listings 1-2; Orange Book 11.4). Per-sample math, not a
 * hot kernel: every entry point computes in double, and the float API widens its
 * inputs exactly and rounds once, so float and double share one implementation of
 * the degenerate-input rules, and a float result is the double result rounded once.
 * Scalings divide rather than multiply by a reciprocal: the reciprocal of a
 * subnormal overflows. */
#include <math.h>
#include <stdint.h>
#include "bumpgrad/framework.h"

typedef bg_dvec3 v3;

static v3 mk(double x, double y, double z)
{
    v3 r = {x, y, z};
    return r;
}
static v3 zero3(void) { return mk(0, 0, 0); }
static v3 add(v3 a, v3 b) { return mk(a.x + b.x, a.y + b.y, a.z + b.z); }
static v3 sub(v3 a, v3 b) { return mk(a.x - b.x, a.y - b.y, a.z - b.z); }
static v3 scl(v3 a, double s) { return mk(a.x * s, a.y * s, a.z * s); }
static v3 dvd(v3 a, double s) { return mk(a.x / s, a.y / s, a.z / s); }
static double dot(v3 a, v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static v3 cross(v3 a, v3 b)
{
    return mk(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static double maxabs(v3 a) { return fmax(fmax(fabs(a.x), fabs(a.y)), fabs(a.z)); }
static int fin3(v3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
static int is_zero(v3 a) { return a.x == 0 && a.y == 0 && a.z == 0; }
static double sgn(double x) { return x > 0 ? 1.0 : (x < 0 ? -1.0 : 0.0); }

/* Unit vector or (0,0,0). Scaling by the largest component first keeps the squared
 * length in [1, 3], so neither huge (1e300) nor tiny (1e-300) input over/underflows. */
static v3 unit(v3 a)
{
    double m = maxabs(a);
    if (!(m > 0) || !fin3(a))
        return zero3();
    a = dvd(a, m);
    return scl(a, 1.0 / sqrt(dot(a, a)));
}

/* Length without overflow, same scaling as unit(). */
static double length(v3 a)
{
    double m = maxabs(a);
    if (!(m > 0))
        return 0;
    v3 b = dvd(a, m);
    return m * sqrt(dot(b, b));
}

static v3 d3(bg_vec3 a) { return mk(a.x, a.y, a.z); }
static bg_vec3 f3(v3 a)
{
    bg_vec3 r = {(float)a.x, (float)a.y, (float)a.z};
    return r;
}
static bg_dvec2 d2(bg_vec2 a)
{
    bg_dvec2 r = {a.x, a.y};
    return r;
}
static bg_tangent_frame fframe(bg_dtangent_frame f)
{
    bg_tangent_frame r = {f3(f.t), f3(f.b), f3(f.n)};
    return r;
}
static bg_dtangent_frame zero_frame(void)
{
    bg_dtangent_frame f = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    return f;
}

/* ---- resolve ---------------------------------------------------------------- */

/* One implementation for the float and double arrays (exactly one pair is used). */
static v3 resolve_core(v3 n, const bg_vec3 *fg, const float *fw, const bg_dvec3 *dg,
                       const double *dw, size_t count)
{
    v3 u = unit(n);
    if (is_zero(u))
        return u;
    if (!fg && !dg)
        return u;
    /* Pass 1: bounds of the valid terms, so that pass 2 can scale everything into
     * [-1, 1] when the products would otherwise overflow a double (w 1e200, g 1e200):
     * normalize(n - S) == normalize(n/M - S/M). */
    double mw = 0, mg = 0;
    for (size_t i = 0; i < count; i++) {
        double w = fw ? fw[i] : (dw ? dw[i] : 1.0);
        v3 g = fg ? d3(fg[i]) : dg[i];
        if (!isfinite(w) || !fin3(g))
            continue; /* an undefined slope is no slope: skip, as surfgrad.h does */
        mw = fmax(mw, fabs(w));
        mg = fmax(mg, maxabs(g));
    }
    int scaled = mw * mg > 1.0;
    v3 acc = u;
    if (scaled)
        acc = dvd(dvd(u, mw), mg);
    for (size_t i = 0; i < count; i++) {
        double w = fw ? fw[i] : (dw ? dw[i] : 1.0);
        v3 g = fg ? d3(fg[i]) : dg[i];
        if (!isfinite(w) || !fin3(g))
            continue;
        acc = sub(acc, scaled ? scl(dvd(g, mg), w / mw) : scl(g, w));
    }
    v3 r = unit(acc);
    return is_zero(r) ? u : r;
}

bg_dvec3 bg_resolve_normald(bg_dvec3 n, const bg_dvec3 *surfgrads, const double *weights,
                            size_t count)
{
    return resolve_core(n, NULL, NULL, surfgrads, weights, count);
}

bg_vec3 bg_resolve_normal(bg_vec3 n, const bg_vec3 *surfgrads, const float *weights, size_t count)
{
    return f3(resolve_core(d3(n), surfgrads, weights, NULL, NULL, count));
}

void bg_surfgrad_accumulate_batch(float weight, const float *gx, const float *gy, const float *gz,
                                  size_t count, float *ax, float *ay, float *az)
{
    for (size_t i = 0; i < count; i++) {
        ax[i] = ax[i] + weight * gx[i];
        ay[i] = ay[i] + weight * gy[i];
        az[i] = az[i] + weight * gz[i];
    }
}

void bg_resolve_normal_batch(const float *nx, const float *ny, const float *nz, const float *sx,
                             const float *sy, const float *sz, size_t count, float *ox, float *oy,
                             float *oz)
{
    for (size_t i = 0; i < count; i++) {
        bg_vec3 s = {sx[i], sy[i], sz[i]};
        bg_vec3 r = f3(resolve_core(mk(nx[i], ny[i], nz[i]), &s, NULL, NULL, NULL, 1));
        ox[i] = r.x, oy[i] = r.y, oz[i] = r.z; /* after reading: outputs may alias */
    }
}

static v3 naive_core(const bg_vec3 *fn, const float *fw, const bg_dvec3 *dn, const double *dw,
                     size_t count)
{
    if (!fn && !dn)
        return zero3();
    /* Scale the weights by their largest magnitude so the sum cannot overflow. */
    double mw = 0;
    for (size_t i = 0; i < count; i++) {
        double w = fw ? fw[i] : (dw ? dw[i] : 1.0);
        if (isfinite(w))
            mw = fmax(mw, fabs(w));
    }
    if (!(mw > 0))
        return zero3();
    v3 acc = zero3();
    for (size_t i = 0; i < count; i++) {
        double w = fw ? fw[i] : (dw ? dw[i] : 1.0);
        v3 u = unit(fn ? d3(fn[i]) : dn[i]);
        if (!isfinite(w) || is_zero(u))
            continue;
        acc = add(acc, scl(u, w / mw));
    }
    return unit(acc);
}

bg_vec3 bg_blend_normals_naive(const bg_vec3 *normals, const float *weights, size_t count)
{
    return f3(naive_core(normals, weights, NULL, NULL, count));
}

bg_dvec3 bg_blend_normals_naived(const bg_dvec3 *normals, const double *weights, size_t count)
{
    return naive_core(NULL, NULL, normals, weights, count);
}

/* ---- surface gradients from normals ------------------------------------------ */

bg_dvec3 bg_surfgrad_from_tangent_normald(bg_dvec3 t, bg_dvec3 b, bg_dvec3 m)
{
    if (!fin3(t) || !fin3(b) || !fin3(m))
        return zero3();
    double s = maxabs(m);
    if (!(s > 0))
        return zero3();
    m = dvd(m, s); /* the slopes are ratios: scale freely */
    /* |m.z| keeps the perturbed normal on the visible side; the common floor
     * max(|m.x|,|m.y|)/128 bounds both slopes by 128 without turning the slope's
     * direction, which clamping each ratio separately would do. */
    double z = fmax(fabs(m.z), fmax(fabs(m.x), fabs(m.y)) / BG_MAX_NORMAL_SLOPE);
    v3 r = add(scl(t, -m.x / z), scl(b, -m.y / z));
    return fin3(r) ? r : zero3();
}

bg_vec3 bg_surfgrad_from_tangent_normal(bg_vec3 t, bg_vec3 b, bg_vec3 m)
{
    return f3(bg_surfgrad_from_tangent_normald(d3(t), d3(b), d3(m)));
}

bg_dvec3 bg_surfgrad_from_perturbed_normald(bg_dvec3 n, bg_dvec3 m)
{
    v3 u = unit(n), mu = unit(m);
    if (is_zero(u) || is_zero(mu))
        return zero3();
    double k = dot(mu, u);
    v3 mt = sub(mu, scl(u, k));
    /* |k|: an inward m is mirrored to the visible side (the tangent-space path's
     * |m.z|); the floor |m_t|/128 is the same slope bound in the tangent plane. */
    double z = fmax(fabs(k), length(mt) / BG_MAX_NORMAL_SLOPE);
    if (!(z > 0))
        return zero3();
    return scl(mt, -1.0 / z);
}

bg_vec3 bg_surfgrad_from_perturbed_normal(bg_vec3 n, bg_vec3 m)
{
    return f3(bg_surfgrad_from_perturbed_normald(d3(n), d3(m)));
}

/* ---- surface gradients from height derivatives ---------------------------------- */

/* Rescale the chart so each position derivative has largest component 1 (the
 * height derivative scales with it: a reparametrization s' = s*k leaves eq. 3
 * unchanged). Keeps the triple product away from under/overflow. 0 if unusable. */
static int rescale_chart(v3 *ss, v3 *st, double *bs, double *bt)
{
    double as = maxabs(*ss), at = maxabs(*st);
    if (!(as > 0) || !(at > 0))
        return 0;
    *ss = dvd(*ss, as), *bs /= as;
    *st = dvd(*st, at), *bt /= at;
    return fin3(*ss) && fin3(*st) && isfinite(*bs) && isfinite(*bt);
}

bg_dvec3 bg_surfgrad_from_param_derivsd(bg_dvec3 n, bg_dvec3 sigma_s, bg_dvec3 sigma_t,
                                        double beta_s, double beta_t)
{
    v3 u = unit(n);
    if (is_zero(u) || !fin3(sigma_s) || !fin3(sigma_t) || !isfinite(beta_s) ||
        !isfinite(beta_t))
        return zero3();
    if (!rescale_chart(&sigma_s, &sigma_t, &beta_s, &beta_t))
        return zero3();
    v3 r1 = cross(sigma_t, u), r2 = cross(u, sigma_s);
    double det = dot(sigma_s, r1); /* = n . (sigma_s x sigma_t), signed: eq. 3 */
    if (det == 0)
        return zero3();
    v3 g = dvd(add(scl(r1, beta_s), scl(r2, beta_t)), det);
    return fin3(g) ? g : zero3();
}

bg_vec3 bg_surfgrad_from_param_derivs(bg_vec3 n, bg_vec3 sigma_s, bg_vec3 sigma_t, float beta_s,
                                      float beta_t)
{
    return f3(bg_surfgrad_from_param_derivsd(d3(n), d3(sigma_s), d3(sigma_t), beta_s, beta_t));
}

bg_dvec3 bg_surfgrad_from_screen_derivsd(bg_dvec3 n, bg_dvec3 dpdx, bg_dvec3 dpdy, double dhdx,
                                         double dhdy)
{
    return bg_surfgrad_from_param_derivsd(n, dpdx, dpdy, dhdx, dhdy);
}

bg_vec3 bg_surfgrad_from_screen_derivs(bg_vec3 n, bg_vec3 dpdx, bg_vec3 dpdy, float dhdx, float dhdy)
{
    return f3(bg_surfgrad_from_param_derivsd(d3(n), d3(dpdx), d3(dpdy), dhdx, dhdy));
}

bg_dvec3 bg_perturb_normal_screend(bg_dvec3 n, bg_dvec3 dpdx, bg_dvec3 dpdy, double dhdx,
                                   double dhdy)
{
    v3 u = unit(n);
    if (is_zero(u))
        return u;
    if (!fin3(dpdx) || !fin3(dpdy) || !isfinite(dhdx) || !isfinite(dhdy) ||
        !rescale_chart(&dpdx, &dpdy, &dhdx, &dhdy))
        return u;
    v3 r1 = cross(dpdy, u), r2 = cross(u, dpdx);
    double det = dot(dpdx, r1);
    if (det == 0)
        return u;
    /* Listing 1: multiplying n - grad_S h by |det| removes the division, so the
     * normal tends to the tangent direction instead of overflowing as det -> 0. */
    v3 sg = scl(add(scl(r1, dhdx), scl(r2, dhdy)), sgn(det));
    v3 r = unit(sub(scl(u, fabs(det)), sg));
    return is_zero(r) ? u : r;
}

bg_vec3 bg_perturb_normal_screen(bg_vec3 n, bg_vec3 dpdx, bg_vec3 dpdy, float dhdx, float dhdy)
{
    return f3(bg_perturb_normal_screend(d3(n), d3(dpdx), d3(dpdy), dhdx, dhdy));
}

bg_dvec3 bg_triplanar_weightsd(bg_dvec3 n, double k)
{
    v3 u = unit(n);
    if (is_zero(u) || !isfinite(k) || !(k >= 0))
        return zero3();
    double m = maxabs(u);
    /* Relative to the largest component, that one's weight is exactly 1, so the
     * sum is >= 1 however large k is. pow(0, 0) == 1 gives k = 0 equal thirds. */
    v3 w = mk(pow(fabs(u.x) / m, k), pow(fabs(u.y) / m, k), pow(fabs(u.z) / m, k));
    return scl(w, 1.0 / (w.x + w.y + w.z));
}

bg_vec3 bg_triplanar_weights(bg_vec3 n, float k)
{
    return f3(bg_triplanar_weightsd(d3(n), k));
}

static int fin2(bg_dvec2 a) { return isfinite(a.x) && isfinite(a.y); }

bg_dvec3 bg_surfgrad_triplanard(bg_dvec3 n, double k, bg_dvec2 d_yz, bg_dvec2 d_xz, bg_dvec2 d_xy)
{
    v3 w = bg_triplanar_weightsd(n, k);
    if (is_zero(w))
        return w;
    v3 u = unit(n), g = zero3();
    /* Each plane's 2D gradient lifted to 3D along the two axes it varies in. */
    if (w.x > 0) {
        if (!fin2(d_yz))
            return zero3();
        g = add(g, scl(mk(0, d_yz.x, d_yz.y), w.x));
    }
    if (w.y > 0) {
        if (!fin2(d_xz))
            return zero3();
        g = add(g, scl(mk(d_xz.x, 0, d_xz.y), w.y));
    }
    if (w.z > 0) {
        if (!fin2(d_xy))
            return zero3();
        g = add(g, scl(mk(d_xy.x, d_xy.y, 0), w.z));
    }
    v3 r = sub(g, scl(u, dot(u, g))); /* eq. 2 */
    return fin3(r) ? r : zero3();
}

bg_vec3 bg_surfgrad_triplanar(bg_vec3 n, float k, bg_vec2 d_yz, bg_vec2 d_xz, bg_vec2 d_xy)
{
    return f3(bg_surfgrad_triplanard(d3(n), k, d2(d_yz), d2(d_xz), d2(d_xy)));
}

/* ---- frames ------------------------------------------------------------------------ */

bg_dtangent_frame bg_tangent_frame_from_derivsd(bg_dvec3 n, bg_dvec3 dpdx, bg_dvec3 dpdy,
                                                bg_dvec2 duvdx, bg_dvec2 duvdy)
{
    bg_dtangent_frame f = zero_frame();
    v3 u = unit(n);
    if (is_zero(u) || !fin3(dpdx) || !fin3(dpdy) || !fin2(duvdx) || !fin2(duvdy))
        return f;
    f.n = u;
    /* Only directions and signs survive the normalization below, so scale the
     * position derivatives by one common factor and the UV derivatives by another:
     * tiny or huge pixel footprints then cannot under/overflow the products. */
    double sp = fmax(maxabs(dpdx), maxabs(dpdy));
    double su = fmax(fmax(fabs(duvdx.x), fabs(duvdx.y)), fmax(fabs(duvdy.x), fabs(duvdy.y)));
    if (!(sp > 0) || !(su > 0))
        return f;
    dpdx = dvd(dpdx, sp), dpdy = dvd(dpdy, sp);
    duvdx.x /= su, duvdx.y /= su, duvdy.x /= su, duvdy.y /= su;
    v3 px = sub(dpdx, scl(u, dot(dpdx, u)));
    v3 py = sub(dpdy, scl(u, dot(dpdy, u)));
    /* J = d(u,v)/d(x,y); dP/du = (dv/dy dP/dx - dv/dx dP/dy) / det J. (The overview's
     * prose writes the inverse Jacobian transposed; its compute_tbn code, followed
     * here, is right.) Only the sign of det J is kept: t is normalized anyway. */
    double det = duvdx.x * duvdy.y - duvdx.y * duvdy.x;
    double hand = sgn(dot(u, cross(dpdx, dpdy)));
    if (det == 0 || hand == 0)
        return f;
    v3 t = sub(scl(px, duvdy.y), scl(py, duvdx.y));
    t = unit(scl(t, sgn(det)));
    if (is_zero(t))
        return f;
    f.t = t;
    /* b completes a frame with the handedness of (dP/du, dP/dv): the sign of
     * n.(dP/du x dP/dv) is sign(det J) * sign(n.(dP/dx x dP/dy)). */
    f.b = scl(cross(u, t), sgn(det) * hand);
    return f;
}

bg_tangent_frame bg_tangent_frame_from_derivs(bg_vec3 n, bg_vec3 dpdx, bg_vec3 dpdy, bg_vec2 duvdx,
                                              bg_vec2 duvdy)
{
    return fframe(bg_tangent_frame_from_derivsd(d3(n), d3(dpdx), d3(dpdy), d2(duvdx), d2(duvdy)));
}

bg_dtangent_frame bg_mikktspace_renormalized(bg_dvec3 t, double sign, bg_dvec3 n)
{
    bg_dtangent_frame f = zero_frame();
    if (!fin3(t) || !fin3(n) || isnan(sign))
        return f;
    double len = length(n);
    if (!(len > 0) || !isfinite(len))
        return f;
    double s = sign < 0 ? -1.0 : 1.0;
    /* b = sign (n x t) / |n| == sign ((n/|n|) x t): divide first to avoid overflow.
     * One common positive factor 1/|n| keeps the unnormalized decode's ratios. */
    v3 nn = dvd(n, len);
    f.n = nn;
    f.t = dvd(t, len);
    f.b = scl(cross(nn, t), s);
    if (!fin3(f.t) || !fin3(f.b) || !fin3(f.n))
        return zero_frame();
    return f;
}

bg_tangent_frame bg_mikktspace_renormalize(bg_vec3 t, float sign, bg_vec3 n)
{
    return fframe(bg_mikktspace_renormalized(d3(t), sign, d3(n)));
}

bg_dvec3 bg_face_forward_refd(bg_dvec3 n, bg_dvec3 n_ref, bg_dvec3 to_viewer)
{
    /* Compare the sign through unit vectors so huge inputs cannot overflow the dot. */
    return dot(unit(n_ref), unit(to_viewer)) < 0 ? scl(n, -1.0) : n;
}

bg_dvec3 bg_face_forwardd(bg_dvec3 n, bg_dvec3 to_viewer)
{
    return bg_face_forward_refd(n, n, to_viewer);
}

bg_vec3 bg_face_forward_ref(bg_vec3 n, bg_vec3 n_ref, bg_vec3 to_viewer)
{
    if (dot(unit(d3(n_ref)), unit(d3(to_viewer))) < 0) {
        bg_vec3 r = {-n.x, -n.y, -n.z}; /* negation is exact: no detour through double */
        return r;
    }
    return n;
}

bg_vec3 bg_face_forward(bg_vec3 n, bg_vec3 to_viewer) { return bg_face_forward_ref(n, n, to_viewer); }

/* ---- ray differentials --------------------------------------------------------------- */

/* Hit X(x) = O(x) + s(x) D(x) on the plane n.(X - p) = 0. Differentiating with the
 * plane fixed: dX = w - D (n.w)/(n.D), w = dO + s dD, s = n.(p - O)/(n.D), i.e. the
 * ray's change projected along D onto the plane. Invariant to D's length and to
 * where on the ray O sits. */
static int ray_core(v3 p, v3 n, v3 o, v3 d, v3 dox, v3 doy, v3 ddx, v3 ddy, v3 *dpx, v3 *dpy)
{
    v3 u = unit(n);
    if (is_zero(u) || !fin3(p) || !fin3(o) || !fin3(d) || !fin3(dox) || !fin3(doy) ||
        !fin3(ddx) || !fin3(ddy))
        return 0;
    double nd = dot(u, d);
    if (nd == 0)
        return 0;
    double s = dot(u, sub(p, o)) / nd;
    v3 wx = add(dox, scl(ddx, s)), wy = add(doy, scl(ddy, s));
    *dpx = sub(wx, scl(d, dot(u, wx) / nd));
    *dpy = sub(wy, scl(d, dot(u, wy) / nd));
    return fin3(*dpx) && fin3(*dpy);
}

void bg_ray_differentialsd(bg_dvec3 p, bg_dvec3 n, bg_dvec3 camera, bg_dvec3 dir,
                           bg_dvec3 ddir_dx, bg_dvec3 ddir_dy, bg_dvec3 *dpdx, bg_dvec3 *dpdy)
{
    v3 a, b;
    if (!ray_core(p, n, camera, dir, zero3(), zero3(), ddir_dx, ddir_dy, &a, &b))
        a = b = zero3();
    *dpdx = a, *dpdy = b;
}

void bg_ray_differentials(bg_vec3 p, bg_vec3 n, bg_vec3 camera, bg_vec3 dir, bg_vec3 ddir_dx,
                          bg_vec3 ddir_dy, bg_vec3 *dpdx, bg_vec3 *dpdy)
{
    v3 a, b;
    bg_ray_differentialsd(d3(p), d3(n), d3(camera), d3(dir), d3(ddir_dx), d3(ddir_dy), &a, &b);
    *dpdx = f3(a), *dpdy = f3(b);
}

/* Unprojection X = (M c).xyz / (M c).w of NDC point c = (x, y, z, 1), and its
 * derivatives along NDC x and y: d/dx (h.xyz / h.w) = (col0.xyz - X col0.w) / h.w. */
static int unproject(const double *m, double x, double y, double z, v3 *X, v3 *dX, v3 *dY)
{
    double h[4];
    for (int r = 0; r < 4; r++)
        h[r] = m[4 * r] * x + m[4 * r + 1] * y + m[4 * r + 2] * z + m[4 * r + 3];
    if (h[3] == 0 || !isfinite(h[3]))
        return 0;
    *X = dvd(mk(h[0], h[1], h[2]), h[3]);
    v3 c0 = mk(m[0], m[4], m[8]), c1 = mk(m[1], m[5], m[9]);
    *dX = dvd(sub(c0, scl(*X, m[12])), h[3]);
    *dY = dvd(sub(c1, scl(*X, m[13])), h[3]);
    return fin3(*X);
}

void bg_ray_differentials_inv_viewprojd(const double inv_view_proj[16], bg_dvec2 pixel,
                                        bg_dvec2 viewport, bg_dvec3 p, bg_dvec3 n,
                                        bg_dvec3 *dpdx, bg_dvec3 *dpdy)
{
    v3 a = zero3(), b = zero3();
    *dpdx = a, *dpdy = b;
    if (!inv_view_proj || !(viewport.x != 0) || !(viewport.y != 0) || !fin2(viewport) ||
        !fin2(pixel))
        return;
    for (int i = 0; i < 16; i++)
        if (!isfinite(inv_view_proj[i]))
            return;
    double sx = 2.0 / viewport.x, sy = -2.0 / viewport.y; /* NDC per pixel; y flips */
    double x = pixel.x * sx - 1.0, y = 1.0 + pixel.y * sy;
    v3 x0, x0dx, x0dy, x1, x1dx, x1dy;
    if (!unproject(inv_view_proj, x, y, 0.25, &x0, &x0dx, &x0dy) ||
        !unproject(inv_view_proj, x, y, 0.75, &x1, &x1dx, &x1dy))
        return;
    v3 dox = scl(x0dx, sx), doy = scl(x0dy, sy);
    v3 ddx = scl(sub(x1dx, x0dx), sx), ddy = scl(sub(x1dy, x0dy), sy);
    if (!ray_core(p, n, x0, sub(x1, x0), dox, doy, ddx, ddy, &a, &b))
        return;
    *dpdx = a, *dpdy = b;
}

void bg_ray_differentials_inv_viewproj(const float inv_view_proj[16], bg_vec2 pixel,
                                       bg_vec2 viewport, bg_vec3 p, bg_vec3 n, bg_vec3 *dpdx,
                                       bg_vec3 *dpdy)
{
    double m[16];
    v3 a, b;
    if (!inv_view_proj) {
        bg_vec3 z = {0, 0, 0};
        *dpdx = z, *dpdy = z;
        return;
    }
    for (int i = 0; i < 16; i++)
        m[i] = inv_view_proj[i];
    bg_ray_differentials_inv_viewprojd(m, d2(pixel), d2(viewport), d3(p), d3(n), &a, &b);
    *dpdx = f3(a), *dpdy = f3(b);
}

/* ---- height textures ------------------------------------------------------------------ */

bg_status bg_height_texture_validate(const bg_height_texture *tex)
{
    if (!tex || !tex->texels)
        return BG_ERR_NULL_POINTER;
    if (tex->width < 1 || tex->height < 1 || (size_t)tex->width > SIZE_MAX / (size_t)tex->height)
        return BG_ERR_INVALID_ARGUMENT;
    if (tex->wrap != BG_WRAP_REPEAT && tex->wrap != BG_WRAP_CLAMP && tex->wrap != BG_WRAP_MIRROR)
        return BG_ERR_INVALID_ARGUMENT;
    return BG_OK;
}

/* Reduce a texel-space coordinate (texel centres at integers) into a range whose
 * floor converts to int safely, before any integer conversion. */
static double reduce(double c, int size, bg_wrap wrap)
{
    double period = wrap == BG_WRAP_MIRROR ? 2.0 * size : (double)size;
    if (wrap == BG_WRAP_CLAMP)
        return fmin(fmax(c, -1.0), (double)size);
    c -= period * floor(c / period);
    if (c >= period) /* rounding of the product can land exactly on the period */
        c -= period;
    return c < 0 ? 0 : c;
}

/* Index after the wrap mode; i is within [-1, 2*size] by reduce(). */
static int wrap_index(long i, int size, bg_wrap wrap)
{
    if (wrap == BG_WRAP_CLAMP)
        return i < 0 ? 0 : (i >= size ? size - 1 : (int)i);
    if (wrap == BG_WRAP_REPEAT)
        return (int)(((i % size) + size) % size);
    long p = 2L * size;
    i = ((i % p) + p) % p;
    return (int)(i < size ? i : p - 1 - i); /* mirrored half */
}

static double sample_d(const bg_height_texture *tex, double s, double t)
{
    if (!isfinite(s) || !isfinite(t))
        return NAN;
    double cx = reduce(s * tex->width - 0.5, tex->width, tex->wrap);
    double cy = reduce(t * tex->height - 0.5, tex->height, tex->wrap);
    double fx0 = floor(cx), fy0 = floor(cy);
    double fx = cx - fx0, fy = cy - fy0;
    long x0 = (long)fx0, y0 = (long)fy0;
    int i0 = wrap_index(x0, tex->width, tex->wrap), i1 = wrap_index(x0 + 1, tex->width, tex->wrap);
    int j0 = wrap_index(y0, tex->height, tex->wrap), j1 = wrap_index(y0 + 1, tex->height, tex->wrap);
    const float *row0 = tex->texels + (size_t)j0 * (size_t)tex->width;
    const float *row1 = tex->texels + (size_t)j1 * (size_t)tex->width;
    double a = row0[i0] + fx * ((double)row0[i1] - row0[i0]);
    double b = row1[i0] + fx * ((double)row1[i1] - row1[i0]);
    return a + fy * (b - a);
}

float bg_height_texture_sample(const bg_height_texture *tex, bg_vec2 st)
{
    return (float)sample_d(tex, st.x, st.y);
}

bg_vec2 bg_height_texture_derivs(const bg_height_texture *tex, bg_diff_mode mode, bg_vec2 st,
                                 bg_vec2 dst_dx, bg_vec2 dst_dy)
{
    double s = st.x, t = st.y;
    double hr = sample_d(tex, s + dst_dx.x, t + dst_dx.y);
    double hu = sample_d(tex, s + dst_dy.x, t + dst_dy.y);
    double ds, dt;
    if (mode == BG_DIFF_CENTRAL) {
        double hl = sample_d(tex, s - dst_dx.x, t - dst_dx.y);
        double hd = sample_d(tex, s - dst_dy.x, t - dst_dy.y);
        ds = 0.5 * (hr - hl), dt = 0.5 * (hu - hd);
    } else {
        double h0 = sample_d(tex, s, t); /* Listing 2: one shared tap */
        ds = hr - h0, dt = hu - h0;
    }
    bg_vec2 r = {(float)ds, (float)dt};
    return r;
}

/* ---- Orange Book 11.4 -------------------------------------------------------------------- */

bg_vec3 bg_orange_bump_normal(bg_vec2 st, float bump_density, float bump_size)
{
    bg_vec3 flat = {0, 0, 1};
    double cx = (double)bump_density * st.x, cy = (double)bump_density * st.y;
    if (!isfinite(cx) || !isfinite(cy))
        return flat;
    double px = cx - floor(cx) - 0.5, py = cy - floor(cy) - 0.5; /* fract(c) - 0.5 */
    double d = px * px + py * py;
    if (!(d < bump_size)) /* the listing's d >= BumpSize: flat */
        return flat;
    double f = 1.0 / sqrt(d + 1.0);
    bg_vec3 r = {(float)(px * f), (float)(py * f), (float)f};
    return r;
}

bg_vec3 bg_orange_bump_shade(bg_vec3 normal, bg_vec3 light_dir, bg_vec3 eye_dir,
                             bg_vec3 surface_color, float specular_factor)
{
    float nl = normal.x * light_dir.x + normal.y * light_dir.y + normal.z * light_dir.z;
    float diff = fmaxf(nl, 0.0f);
    bg_vec3 r = {light_dir.x - 2.0f * nl * normal.x, light_dir.y - 2.0f * nl * normal.y,
                 light_dir.z - 2.0f * nl * normal.z}; /* GLSL reflect(L, N) */
    float spec = fmaxf(eye_dir.x * r.x + eye_dir.y * r.y + eye_dir.z * r.z, 0.0f);
    spec = powf(spec, 6.0f) * specular_factor;
    bg_vec3 c = {fminf(surface_color.x * diff + spec, 1.0f), fminf(surface_color.y * diff + spec, 1.0f),
                 fminf(surface_color.z * diff + spec, 1.0f)};
    return c;
}
