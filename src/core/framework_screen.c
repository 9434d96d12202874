/* SPDX-License-Identifier: MIT */
/* Height derivatives along a chart turned into a surface gradient: Mikkelsen 2010
 * eq. 3 with a parametrization or the screen as the chart, Listing 1 (its
 * division-free normal, in double and in GPU-faithful float), the scale-dependent
 * surface gradient with the texel-to-screen chain rule, and the parallax helpers
 * that map between the surface and texture space through the same chart. */
#include "framework_internal.h"
#include <float.h>

/* ---- eq. 3 --------------------------------------------------------------------- */

bg_dvec3 bg_surfgrad_from_param_derivsd(bg_dvec3 n, bg_dvec3 sigma_s, bg_dvec3 sigma_t,
                                        double beta_s, double beta_t)
{
    bg_dvec3 u = bg_dv3_unit(n);
    if (bg_dv3_is_zero(u) || !bg_dv3_finite(sigma_s) || !bg_dv3_finite(sigma_t) ||
        !isfinite(beta_s) || !isfinite(beta_t))
        return bg_dv3_zero();
    if (!fw_rescale_chart(&sigma_s, &sigma_t, &beta_s, &beta_t))
        return bg_dv3_zero();
    bg_dvec3 r1 = bg_dv3_cross(sigma_t, u), r2 = bg_dv3_cross(u, sigma_s);
    double det = bg_dv3_dot(sigma_s, r1); /* = n . (sigma_s x sigma_t), signed: eq. 3 */
    if (det == 0)
        return bg_dv3_zero();
    bg_dvec3 g = bg_dv3_div(bg_dv3_add(bg_dv3_scale(r1, beta_s), bg_dv3_scale(r2, beta_t)), det);
    return bg_dv3_finite(g) ? g : bg_dv3_zero();
}

/* Eq. 3 in float: computed in double, rounded once. Static (inlined into both
 * float entry points): an exported function may be interposed, so one calling
 * the other would cost a call. */
static inline bg_vec3 param_derivs_f(bg_vec3 n, bg_vec3 sigma_s, bg_vec3 sigma_t, float beta_s,
                                     float beta_t)
{
    return bg_f3_from_dv(bg_surfgrad_from_param_derivsd(bg_dv3_from_f(n), bg_dv3_from_f(sigma_s),
                                                        bg_dv3_from_f(sigma_t), beta_s, beta_t));
}

bg_vec3 bg_surfgrad_from_param_derivs(bg_vec3 n, bg_vec3 sigma_s, bg_vec3 sigma_t, float beta_s,
                                      float beta_t)
{
    return param_derivs_f(n, sigma_s, sigma_t, beta_s, beta_t);
}

bg_dvec3 bg_surfgrad_from_screen_derivsd(bg_dvec3 n, bg_dvec3 dpdx, bg_dvec3 dpdy, double dhdx,
                                         double dhdy)
{
    return bg_surfgrad_from_param_derivsd(n, dpdx, dpdy, dhdx, dhdy);
}

bg_vec3 bg_surfgrad_from_screen_derivs(bg_vec3 n, bg_vec3 dpdx, bg_vec3 dpdy, float dhdx,
                                       float dhdy)
{
    return param_derivs_f(n, dpdx, dpdy, dhdx, dhdy); /* the same eq. 3 */
}

/* ---- Listing 1 -------------------------------------------------------------------- */

bg_dvec3 bg_perturb_normal_screend(bg_dvec3 n, bg_dvec3 dpdx, bg_dvec3 dpdy, double dhdx,
                                   double dhdy)
{
    bg_dvec3 u = bg_dv3_unit(n);
    if (bg_dv3_is_zero(u))
        return u;
    if (!bg_dv3_finite(dpdx) || !bg_dv3_finite(dpdy) || !isfinite(dhdx) || !isfinite(dhdy) ||
        !fw_rescale_chart(&dpdx, &dpdy, &dhdx, &dhdy))
        return u;
    bg_dvec3 r1 = bg_dv3_cross(dpdy, u), r2 = bg_dv3_cross(u, dpdx);
    double det = bg_dv3_dot(dpdx, r1);
    if (det == 0)
        return u;
    /* Listing 1: multiplying n - grad_S h by |det| removes the division, so the
     * normal tends to the tangent direction instead of overflowing as det -> 0. */
    bg_dvec3 sg =
        bg_dv3_scale(bg_dv3_add(bg_dv3_scale(r1, dhdx), bg_dv3_scale(r2, dhdy)), fw_sgn(det));
    bg_dvec3 r = bg_dv3_unit(bg_dv3_sub(bg_dv3_scale(u, fabs(det)), sg));
    return bg_dv3_is_zero(r) ? u : r;
}

bg_vec3 bg_perturb_normal_screen(bg_vec3 n, bg_vec3 dpdx, bg_vec3 dpdy, float dhdx, float dhdy)
{
    return bg_f3_from_dv(bg_perturb_normal_screend(bg_dv3_from_f(n), bg_dv3_from_f(dpdx),
                                                   bg_dv3_from_f(dpdy), dhdx, dhdy));
}

bg_vec3 bg_listing1_normal(bg_vec3 n, bg_vec3 sigma_s, bg_vec3 sigma_t, float dbs, float dbt)
{
    /* Float arithmetic in the listing's order, nothing rescaled or widened: the
     * renderer and the studies call this and must keep their bits. */
    float nn[3] = {n.x, n.y, n.z}, sS[3] = {sigma_s.x, sigma_s.y, sigma_s.z};
    float sT[3] = {sigma_t.x, sigma_t.y, sigma_t.z}, R1[3], R2[3], out[3];
    /* vR1 = cross(vSigmaT, vN), vR2 = cross(vN, vSigmaS), fDet = dot(vSigmaS, vR1) */
    bg_f3_cross(sT, nn, R1);
    bg_f3_cross(nn, sS, R2);
    float det = bg_f3_dot(sS, R1);
    if (!(det != 0))
        return n; /* HLSL sign(0) = 0 would give normalize(0); keep the normal */
    float sg = det > 0 ? 1.0f : -1.0f, ad = fabsf(det);
    for (int a = 0; a < 3; a++)
        out[a] = ad * nn[a] - sg * (dbs * R1[a] + dbt * R2[a]);
    if (!bg_f3_normalize(out))
        return n;
    bg_vec3 r = {out[0], out[1], out[2]};
    return r;
}

/* ---- the scale-dependent surface gradient ---------------------------------------- */

bg_dvec3 bg_surfgrad_scale_dependentd(bg_dvec3 n, bg_dvec3 dpdx, bg_dvec3 dpdy, bg_dvec2 deriv,
                                      bg_dvec2 dim, bg_dvec2 dst_dx, bg_dvec2 dst_dy)
{
    /* Chain rule: dH/dx = dH/ds ds/dx + dH/dt dt/dx with dH/d(s,t) = dim * deriv
     * (deriv per texel), then eq. 3 on the screen chart. */
    double hs = dim.x * deriv.x, ht = dim.y * deriv.y;
    double dhdx = hs * dst_dx.x + ht * dst_dx.y;
    double dhdy = hs * dst_dy.x + ht * dst_dy.y;
    return bg_surfgrad_from_param_derivsd(n, dpdx, dpdy, dhdx, dhdy);
}

bg_vec3 bg_surfgrad_scale_dependent(bg_vec3 n, bg_vec3 dpdx, bg_vec3 dpdy, bg_vec2 deriv,
                                    bg_vec2 dim, bg_vec2 dst_dx, bg_vec2 dst_dy)
{
    return bg_f3_from_dv(bg_surfgrad_scale_dependentd(bg_dv3_from_f(n), bg_dv3_from_f(dpdx),
                                                      bg_dv3_from_f(dpdy), fw_d2(deriv), fw_d2(dim),
                                                      fw_d2(dst_dx), fw_d2(dst_dy)));
}

/* ---- parallax helpers ---------------------------------------------------------------- */

bg_dvec2 bg_project_vec_to_textured(bg_dvec3 n, bg_dvec3 dpdx, bg_dvec3 dpdy, bg_dvec2 dst_dx,
                                    bg_dvec2 dst_dy, bg_dvec3 dir, double bump_scale, int skip_proj)
{
    bg_dvec2 z = {0, 0};
    bg_dvec3 u = bg_dv3_unit(n);
    if (bg_dv3_is_zero(u) || !bg_dv3_finite(dpdx) || !bg_dv3_finite(dpdy) || !bg_dv3_finite(dir) ||
        !fw_fin2(dst_dx) || !fw_fin2(dst_dy) || !isfinite(bump_scale))
        return z;
    /* The chart scaled so each position derivative has largest component 1; the
     * screen coordinates scale inversely, so divide the texture steps instead. */
    double as = bg_dv3_maxabs(dpdx), at = bg_dv3_maxabs(dpdy);
    if (!(as > 0) || !(at > 0))
        return z;
    dpdx = bg_dv3_div(dpdx, as), dpdy = bg_dv3_div(dpdy, at);
    bg_dvec3 r1 = bg_dv3_cross(dpdy, u), r2 = bg_dv3_cross(u, dpdx);
    double det = bg_dv3_dot(dpdx, r1);
    if (det == 0)
        return z;
    /* The tangential part of dir in screen steps: dir_t = x dpdx + y dpdy with
     * (x, y) = (R1.dir, R2.dir) / det (the dual basis of eq. 3). */
    double x = bg_dv3_dot(r1, dir) / det / as, y = bg_dv3_dot(r2, dir) / det / at;
    bg_dvec2 t = {dst_dx.x * x + dst_dy.x * y, dst_dx.y * x + dst_dy.y * y};
    double s = bump_scale;
    if (!skip_proj)
        s /= fmax(fabs(bg_dv3_dot(u, dir)), FLT_EPSILON * bg_dv3_length(dir));
    t.x *= s, t.y *= s;
    return fw_fin2(t) ? t : z;
}

bg_vec2 bg_project_vec_to_texture(bg_vec3 n, bg_vec3 dpdx, bg_vec3 dpdy, bg_vec2 dst_dx,
                                  bg_vec2 dst_dy, bg_vec3 dir, float bump_scale, int skip_proj)
{
    return fw_f2(bg_project_vec_to_textured(bg_dv3_from_f(n), bg_dv3_from_f(dpdx),
                                            bg_dv3_from_f(dpdy), fw_d2(dst_dx), fw_d2(dst_dy),
                                            bg_dv3_from_f(dir), bump_scale, skip_proj));
}

bg_dvec3 bg_texture_offset_to_surfaced(bg_dvec3 n, bg_dvec3 dpdx, bg_dvec3 dpdy, bg_dvec2 dst_dx,
                                       bg_dvec2 dst_dy, bg_dvec2 offset)
{
    bg_dvec3 u = bg_dv3_unit(n);
    if (bg_dv3_is_zero(u) || !bg_dv3_finite(dpdx) || !bg_dv3_finite(dpdy) || !fw_fin2(dst_dx) ||
        !fw_fin2(dst_dy) || !fw_fin2(offset))
        return bg_dv3_zero();
    /* (x, y) = [dst_dx | dst_dy]^-1 offset, the matrix scaled by its largest entry
     * first so a tiny or huge texture footprint cannot under/overflow det. */
    double su = fmax(fmax(fabs(dst_dx.x), fabs(dst_dx.y)), fmax(fabs(dst_dy.x), fabs(dst_dy.y)));
    if (!(su > 0))
        return bg_dv3_zero();
    double ax = dst_dx.x / su, ay = dst_dx.y / su, bx = dst_dy.x / su, by = dst_dy.y / su;
    double det = ax * by - ay * bx;
    if (det == 0)
        return bg_dv3_zero();
    double x = (by * offset.x - bx * offset.y) / det / su;
    double y = (ax * offset.y - ay * offset.x) / det / su;
    /* Screen steps to the surface through the chart's tangent-plane part. */
    bg_dvec3 sx = bg_dv3_sub(dpdx, bg_dv3_scale(u, bg_dv3_dot(dpdx, u)));
    bg_dvec3 sy = bg_dv3_sub(dpdy, bg_dv3_scale(u, bg_dv3_dot(dpdy, u)));
    bg_dvec3 r = bg_dv3_add(bg_dv3_scale(sx, x), bg_dv3_scale(sy, y));
    return bg_dv3_finite(r) ? r : bg_dv3_zero();
}

bg_vec3 bg_texture_offset_to_surface(bg_vec3 n, bg_vec3 dpdx, bg_vec3 dpdy, bg_vec2 dst_dx,
                                     bg_vec2 dst_dy, bg_vec2 offset)
{
    return bg_f3_from_dv(bg_texture_offset_to_surfaced(bg_dv3_from_f(n), bg_dv3_from_f(dpdx),
                                                       bg_dv3_from_f(dpdy), fw_d2(dst_dx),
                                                       fw_d2(dst_dy), fw_d2(offset)));
}
