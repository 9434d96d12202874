/* SPDX-License-Identifier: MIT */
/* Bump sources given as normals or per-plane derivatives, turned into surface
 * gradients: tangent-space normals with a tangent basis and object-space normals
 * (overview, "Surface gradient from a tangent-space normal vector with a tangent
 * basis"), and the triplanar projection (overview, "Volumetric bump maps": a
 * special case of a volume gradient, projected by Mikkelsen 2010 eq. 2). */
#include "framework_internal.h"
#include <float.h>

/* ---- tangent-space normals ---------------------------------------------------- */

bg_dvec2 bg_tangent_normal_to_derivsd(bg_dvec3 m)
{
    bg_dvec2 r = {0, 0};
    if (!bg_dv3_finite(m))
        return r;
    double s = bg_dv3_maxabs(m);
    if (!(s > 0))
        return r;
    m = bg_dv3_div(m, s); /* the slopes are ratios: scale freely */
    /* |m.z| keeps the perturbed normal on the visible side; the common floor
     * max(|m.x|,|m.y|)/128 bounds both slopes by 128 without turning the slope's
     * direction, which clamping each ratio separately would do. */
    double z = fmax(fabs(m.z), fmax(fabs(m.x), fabs(m.y)) / BG_MAX_NORMAL_SLOPE);
    r.x = -m.x / z, r.y = -m.y / z;
    return r;
}

bg_vec2 bg_tangent_normal_to_derivs(bg_vec3 m)
{
    return fw_f2(bg_tangent_normal_to_derivsd(bg_dv3_from_f(m)));
}

bg_dvec3 bg_surfgrad_from_tbnd(bg_dvec2 deriv, bg_dvec3 t, bg_dvec3 b)
{
    if (!fw_fin2(deriv) || !bg_dv3_finite(t) || !bg_dv3_finite(b))
        return bg_dv3_zero();
    bg_dvec3 r = bg_dv3_add(bg_dv3_scale(t, deriv.x), bg_dv3_scale(b, deriv.y));
    return bg_dv3_finite(r) ? r : bg_dv3_zero();
}

bg_vec3 bg_surfgrad_from_tbn(bg_vec2 deriv, bg_vec3 t, bg_vec3 b)
{
    return bg_f3_from_dv(bg_surfgrad_from_tbnd(fw_d2(deriv), bg_dv3_from_f(t), bg_dv3_from_f(b)));
}

bg_dvec3 bg_surfgrad_from_tangent_normald(bg_dvec3 t, bg_dvec3 b, bg_dvec3 m)
{
    if (!bg_dv3_finite(t) || !bg_dv3_finite(b) || !bg_dv3_finite(m))
        return bg_dv3_zero();
    if (bg_dv3_is_zero(m))
        return bg_dv3_zero();
    /* The one clamp rule (bg_tangent_normal_to_derivs), then the frame. */
    return bg_surfgrad_from_tbnd(bg_tangent_normal_to_derivsd(m), t, b);
}

bg_vec3 bg_surfgrad_from_tangent_normal(bg_vec3 t, bg_vec3 b, bg_vec3 m)
{
    return bg_f3_from_dv(
        bg_surfgrad_from_tangent_normald(bg_dv3_from_f(t), bg_dv3_from_f(b), bg_dv3_from_f(m)));
}

/* ---- object-space normals ------------------------------------------------------- */

bg_dvec3 bg_surfgrad_from_perturbed_normal_clampd(bg_dvec3 n, bg_dvec3 m, bg_normal_clamp clamp)
{
    bg_dvec3 u = bg_dv3_unit(n), mu = bg_dv3_unit(m);
    if (bg_dv3_is_zero(u) || bg_dv3_is_zero(mu))
        return bg_dv3_zero();
    double k = bg_dv3_dot(mu, u);
    bg_dvec3 mt = bg_dv3_sub(mu, bg_dv3_scale(u, k));
    double z;
    if (clamp == BG_CLAMP_REFERENCE)
        z = fmax(fabs(k), (double)FLT_EPSILON); /* SurfgradFromPerturbedNormal, unit m */
    else
        /* |k|: an inward m is mirrored to the visible side (the tangent-space path's
         * |m.z|); the floor |m_t|/128 is the same slope bound in the tangent plane. */
        z = fmax(fabs(k), bg_dv3_length(mt) / BG_MAX_NORMAL_SLOPE);
    if (!(z > 0))
        return bg_dv3_zero();
    return bg_dv3_scale(mt, -1.0 / z);
}

bg_vec3 bg_surfgrad_from_perturbed_normal_clamp(bg_vec3 n, bg_vec3 m, bg_normal_clamp clamp)
{
    return bg_f3_from_dv(
        bg_surfgrad_from_perturbed_normal_clampd(bg_dv3_from_f(n), bg_dv3_from_f(m), clamp));
}

bg_dvec3 bg_surfgrad_from_perturbed_normald(bg_dvec3 n, bg_dvec3 m)
{
    return bg_surfgrad_from_perturbed_normal_clampd(n, m, BG_CLAMP_SLOPE);
}

bg_vec3 bg_surfgrad_from_perturbed_normal(bg_vec3 n, bg_vec3 m)
{
    return bg_f3_from_dv(bg_surfgrad_from_perturbed_normal_clampd(
        bg_dv3_from_f(n), bg_dv3_from_f(m), BG_CLAMP_SLOPE));
}

/* ---- triplanar ------------------------------------------------------------------- */

/* Mikkelsen's reference subtracts 0.2 from |n_i| (after the Cascades demo): a plane
 * seen within 11.5 degrees of edge-on gets exactly weight 0 and is not read. */
#define TRIPLANAR_OFFSET 0.2

bg_dvec3 bg_triplanar_weights_exd(bg_dvec3 n, double k, bg_triplanar_weighting mode)
{
    bg_dvec3 u = bg_dv3_unit(n);
    if (bg_dv3_is_zero(u) || !isfinite(k) || !(k >= 0) ||
        (mode != BG_TRIPLANAR_OFFSET && mode != BG_TRIPLANAR_POWER))
        return bg_dv3_zero();
    double off = mode == BG_TRIPLANAR_OFFSET ? TRIPLANAR_OFFSET : 0.0;
    bg_dvec3 a =
        bg_dv3(fmax(fabs(u.x) - off, 0.0), fmax(fabs(u.y) - off, 0.0), fmax(fabs(u.z) - off, 0.0));
    double m = bg_dv3_maxabs(a); /* >= 1/sqrt(3) - 0.2 > 0 for a unit u */
    /* Relative to the largest term, that one's weight is exactly 1, so the sum is
     * >= 1 however large k is. In the reference weighting a term in the dead zone
     * is 0 for every k, also k = 0 (where the others share equally); the power
     * weighting keeps pow(0, 0) == 1, so k = 0 is equal thirds whatever n is. */
    int dead = mode == BG_TRIPLANAR_OFFSET;
    bg_dvec3 w = bg_dv3(dead && !(a.x > 0) ? 0.0 : pow(a.x / m, k),
                        dead && !(a.y > 0) ? 0.0 : pow(a.y / m, k),
                        dead && !(a.z > 0) ? 0.0 : pow(a.z / m, k));
    return bg_dv3_scale(w, 1.0 / (w.x + w.y + w.z));
}

bg_vec3 bg_triplanar_weights_ex(bg_vec3 n, float k, bg_triplanar_weighting mode)
{
    return bg_f3_from_dv(bg_triplanar_weights_exd(bg_dv3_from_f(n), k, mode));
}

bg_dvec3 bg_triplanar_weightsd(bg_dvec3 n, double k)
{
    return bg_triplanar_weights_exd(n, k, BG_TRIPLANAR_OFFSET);
}

bg_vec3 bg_triplanar_weights(bg_vec3 n, float k)
{
    return bg_f3_from_dv(bg_triplanar_weights_exd(bg_dv3_from_f(n), k, BG_TRIPLANAR_OFFSET));
}

bg_dvec3 bg_surfgrad_triplanar_weightedd(bg_dvec3 n, bg_dvec3 w, bg_dvec2 d_yz, bg_dvec2 d_xz,
                                         bg_dvec2 d_xy)
{
    bg_dvec3 u = bg_dv3_unit(n), g = bg_dv3_zero();
    if (bg_dv3_is_zero(u) || !bg_dv3_finite(w))
        return bg_dv3_zero();
    /* Each plane's 2D gradient lifted to 3D along the two axes it varies in. */
    if (w.x != 0) {
        if (!fw_fin2(d_yz))
            return bg_dv3_zero();
        g = bg_dv3_add(g, bg_dv3_scale(bg_dv3(0, d_yz.x, d_yz.y), w.x));
    }
    if (w.y != 0) {
        if (!fw_fin2(d_xz))
            return bg_dv3_zero();
        g = bg_dv3_add(g, bg_dv3_scale(bg_dv3(d_xz.x, 0, d_xz.y), w.y));
    }
    if (w.z != 0) {
        if (!fw_fin2(d_xy))
            return bg_dv3_zero();
        g = bg_dv3_add(g, bg_dv3_scale(bg_dv3(d_xy.x, d_xy.y, 0), w.z));
    }
    bg_dvec3 r = bg_dv3_sub(g, bg_dv3_scale(u, bg_dv3_dot(u, g))); /* eq. 2 */
    return bg_dv3_finite(r) ? r : bg_dv3_zero();
}

bg_vec3 bg_surfgrad_triplanar_weighted(bg_vec3 n, bg_vec3 weights, bg_vec2 d_yz, bg_vec2 d_xz,
                                       bg_vec2 d_xy)
{
    return bg_f3_from_dv(bg_surfgrad_triplanar_weightedd(bg_dv3_from_f(n), bg_dv3_from_f(weights),
                                                         fw_d2(d_yz), fw_d2(d_xz), fw_d2(d_xy)));
}

bg_dvec3 bg_surfgrad_triplanard(bg_dvec3 n, double k, bg_dvec2 d_yz, bg_dvec2 d_xz, bg_dvec2 d_xy)
{
    bg_dvec3 w = bg_triplanar_weightsd(n, k);
    if (bg_dv3_is_zero(w))
        return w;
    return bg_surfgrad_triplanar_weightedd(n, w, d_yz, d_xz, d_xy);
}

bg_vec3 bg_surfgrad_triplanar(bg_vec3 n, float k, bg_vec2 d_yz, bg_vec2 d_xz, bg_vec2 d_xy)
{
    return bg_f3_from_dv(
        bg_surfgrad_triplanard(bg_dv3_from_f(n), k, fw_d2(d_yz), fw_d2(d_xz), fw_d2(d_xy)));
}
