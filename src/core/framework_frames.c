/* SPDX-License-Identifier: MIT */
/* Tangent frames: the frame from screen derivatives of position and UV (overview,
 * compute_tbn; the reference's GenBasisTB), the mikkTSpace-compliant
 * renormalization (overview, "A note on mikkTSpace usage") and the back-face
 * rules (Mikkelsen 2010 section 2: n represents the visible side). */
#include "framework_internal.h"

bg_dtangent_frame bg_tangent_frame_from_derivsd(bg_dvec3 n, bg_dvec3 dpdx, bg_dvec3 dpdy,
                                                bg_dvec2 duvdx, bg_dvec2 duvdy)
{
    bg_dtangent_frame f = fw_zero_frame();
    bg_dvec3 u = bg_dv3_unit(n);
    if (bg_dv3_is_zero(u) || !bg_dv3_finite(dpdx) || !bg_dv3_finite(dpdy) || !fw_fin2(duvdx) ||
        !fw_fin2(duvdy))
        return f;
    f.n = u;
    /* Only directions and signs survive the normalization below, so scale the
     * position derivatives by one common factor and the UV derivatives by another:
     * tiny or huge pixel footprints then cannot under/overflow the products. */
    double sp = fmax(bg_dv3_maxabs(dpdx), bg_dv3_maxabs(dpdy));
    double su = fmax(fmax(fabs(duvdx.x), fabs(duvdx.y)), fmax(fabs(duvdy.x), fabs(duvdy.y)));
    if (!(sp > 0) || !(su > 0))
        return f;
    dpdx = bg_dv3_div(dpdx, sp), dpdy = bg_dv3_div(dpdy, sp);
    duvdx.x /= su, duvdx.y /= su, duvdy.x /= su, duvdy.y /= su;
    bg_dvec3 px = bg_dv3_sub(dpdx, bg_dv3_scale(u, bg_dv3_dot(dpdx, u)));
    bg_dvec3 py = bg_dv3_sub(dpdy, bg_dv3_scale(u, bg_dv3_dot(dpdy, u)));
    /* J = d(u,v)/d(x,y); dP/du = (dv/dy dP/dx - dv/dx dP/dy) / det J. (The overview's
     * prose writes the inverse Jacobian transposed; its compute_tbn code, followed
     * here, is right.) Only the sign of det J is kept: t is normalized anyway. */
    double det = duvdx.x * duvdy.y - duvdx.y * duvdy.x;
    double hand = fw_sgn(bg_dv3_dot(u, bg_dv3_cross(dpdx, dpdy)));
    if (det == 0 || hand == 0)
        return f;
    bg_dvec3 t = bg_dv3_sub(bg_dv3_scale(px, duvdy.y), bg_dv3_scale(py, duvdx.y));
    t = bg_dv3_unit(bg_dv3_scale(t, fw_sgn(det)));
    if (bg_dv3_is_zero(t))
        return f;
    f.t = t;
    /* b completes a frame with the handedness of (dP/du, dP/dv): the sign of
     * n.(dP/du x dP/dv) is sign(det J) * sign(n.(dP/dx x dP/dy)). */
    f.b = bg_dv3_scale(bg_dv3_cross(u, t), fw_sgn(det) * hand);
    return f;
}

bg_tangent_frame bg_tangent_frame_from_derivs(bg_vec3 n, bg_vec3 dpdx, bg_vec3 dpdy, bg_vec2 duvdx,
                                              bg_vec2 duvdy)
{
    return fw_fframe(bg_tangent_frame_from_derivsd(
        bg_dv3_from_f(n), bg_dv3_from_f(dpdx), bg_dv3_from_f(dpdy), fw_d2(duvdx), fw_d2(duvdy)));
}

bg_dtangent_frame bg_mikktspace_renormalized(bg_dvec3 t, double sign, bg_dvec3 n)
{
    bg_dtangent_frame f = fw_zero_frame();
    if (!bg_dv3_finite(t) || !bg_dv3_finite(n) || isnan(sign))
        return f;
    double len = bg_dv3_length(n);
    if (!(len > 0) || !isfinite(len))
        return f;
    /* The reference pixel shader's rule: w > 0 is +1, anything else (0 too) -1. */
    double s = sign > 0 ? 1.0 : -1.0;
    /* b = sign (n x t) / |n| == sign ((n/|n|) x t): divide first to avoid overflow.
     * One common positive factor 1/|n| keeps the unnormalized decode's ratios. */
    bg_dvec3 nn = bg_dv3_div(n, len);
    f.n = nn;
    f.t = bg_dv3_div(t, len);
    f.b = bg_dv3_scale(bg_dv3_cross(nn, t), s);
    if (!bg_dv3_finite(f.t) || !bg_dv3_finite(f.b) || !bg_dv3_finite(f.n))
        return fw_zero_frame();
    return f;
}

bg_tangent_frame bg_mikktspace_renormalize(bg_vec3 t, float sign, bg_vec3 n)
{
    return fw_fframe(bg_mikktspace_renormalized(bg_dv3_from_f(t), sign, bg_dv3_from_f(n)));
}

/* ---- back faces --------------------------------------------------------------------- */

bg_dvec3 bg_face_forward_refd(bg_dvec3 n, bg_dvec3 n_ref, bg_dvec3 to_viewer)
{
    /* Compare the sign through unit vectors so huge inputs cannot overflow the dot. */
    return bg_dv3_dot(bg_dv3_unit(n_ref), bg_dv3_unit(to_viewer)) < 0 ? bg_dv3_neg(n) : n;
}

bg_dvec3 bg_face_forwardd(bg_dvec3 n, bg_dvec3 to_viewer)
{
    return bg_face_forward_refd(n, n, to_viewer);
}

bg_vec3 bg_face_forward_ref(bg_vec3 n, bg_vec3 n_ref, bg_vec3 to_viewer)
{
    if (bg_dv3_dot(bg_dv3_unit(bg_dv3_from_f(n_ref)), bg_dv3_unit(bg_dv3_from_f(to_viewer))) < 0) {
        bg_vec3 r = {-n.x, -n.y, -n.z}; /* negation is exact: no detour through double */
        return r;
    }
    return n;
}

bg_vec3 bg_face_forward(bg_vec3 n, bg_vec3 to_viewer)
{
    return bg_face_forward_ref(n, n, to_viewer);
}

bg_dvec3 bg_face_forward_reflectd(bg_dvec3 n, bg_dvec3 to_viewer)
{
    bg_dvec3 v = bg_dv3_unit(to_viewer);
    if (!bg_dv3_finite(n))
        return n;
    /* FixNormal: n - 2 (n.v) v, the mirror image of n in the plane normal to v.
     * Only the component along v changes (its sign), so n keeps its length and
     * the part of it that a viewer sees on screen. */
    double d = bg_dv3_dot(n, v);
    if (!(d < 0))
        return n;
    bg_dvec3 r = bg_dv3_sub(n, bg_dv3_scale(v, 2.0 * d));
    return bg_dv3_finite(r) ? r : n;
}

bg_vec3 bg_face_forward_reflect(bg_vec3 n, bg_vec3 to_viewer)
{
    bg_dvec3 d = bg_dv3_from_f(n);
    bg_dvec3 r = bg_face_forward_reflectd(d, bg_dv3_from_f(to_viewer));
    if (r.x == d.x && r.y == d.y && r.z == d.z)
        return n; /* unchanged: exactly the input (also -0.0 and NaN) */
    return bg_f3_from_dv(r);
}
