/* SPDX-License-Identifier: MIT */
/* Screen derivatives of position without ddx/ddy (Mikkelsen 2010 section 5, the
 * post-process case): ray differentials intersected with the hit's tangent plane,
 * from a pinhole ray or from an inverse view-projection matrix. */
#include "framework_internal.h"

/* Hit X(x) = O(x) + s(x) D(x) on the plane n.(X - p) = 0. Differentiating with the
 * plane fixed: dX = w - D (n.w)/(n.D), w = dO + s dD, s = n.(p - O)/(n.D), i.e. the
 * ray's change projected along D onto the plane. Invariant to D's length and to
 * where on the ray O sits. */
static int ray_core(bg_dvec3 p, bg_dvec3 n, bg_dvec3 o, bg_dvec3 d, bg_dvec3 dox, bg_dvec3 doy,
                    bg_dvec3 ddx, bg_dvec3 ddy, bg_dvec3 *dpx, bg_dvec3 *dpy)
{
    bg_dvec3 u = bg_dv3_unit(n);
    if (bg_dv3_is_zero(u) || !bg_dv3_finite(p) || !bg_dv3_finite(o) || !bg_dv3_finite(d) ||
        !bg_dv3_finite(dox) || !bg_dv3_finite(doy) || !bg_dv3_finite(ddx) || !bg_dv3_finite(ddy))
        return 0;
    double nd = bg_dv3_dot(u, d);
    if (nd == 0)
        return 0;
    double s = bg_dv3_dot(u, bg_dv3_sub(p, o)) / nd;
    bg_dvec3 wx = bg_dv3_add(dox, bg_dv3_scale(ddx, s)), wy = bg_dv3_add(doy, bg_dv3_scale(ddy, s));
    *dpx = bg_dv3_sub(wx, bg_dv3_scale(d, bg_dv3_dot(u, wx) / nd));
    *dpy = bg_dv3_sub(wy, bg_dv3_scale(d, bg_dv3_dot(u, wy) / nd));
    return bg_dv3_finite(*dpx) && bg_dv3_finite(*dpy);
}

void bg_ray_differentialsd(bg_dvec3 p, bg_dvec3 n, bg_dvec3 camera, bg_dvec3 dir, bg_dvec3 ddir_dx,
                           bg_dvec3 ddir_dy, bg_dvec3 *dpdx, bg_dvec3 *dpdy)
{
    bg_dvec3 a, b;
    if (!ray_core(p, n, camera, dir, bg_dv3_zero(), bg_dv3_zero(), ddir_dx, ddir_dy, &a, &b))
        a = b = bg_dv3_zero();
    *dpdx = a, *dpdy = b;
}

void bg_ray_differentials(bg_vec3 p, bg_vec3 n, bg_vec3 camera, bg_vec3 dir, bg_vec3 ddir_dx,
                          bg_vec3 ddir_dy, bg_vec3 *dpdx, bg_vec3 *dpdy)
{
    bg_dvec3 a, b;
    bg_ray_differentialsd(bg_dv3_from_f(p), bg_dv3_from_f(n), bg_dv3_from_f(camera),
                          bg_dv3_from_f(dir), bg_dv3_from_f(ddir_dx), bg_dv3_from_f(ddir_dy), &a,
                          &b);
    *dpdx = bg_f3_from_dv(a), *dpdy = bg_f3_from_dv(b);
}

/* Unprojection X = (M c).xyz / (M c).w of NDC point c = (x, y, z, 1), and its
 * derivatives along NDC x and y: d/dx (h.xyz / h.w) = (col0.xyz - X col0.w) / h.w. */
static int unproject(const double *m, double x, double y, double z, bg_dvec3 *X, bg_dvec3 *dX,
                     bg_dvec3 *dY)
{
    double h[4];
    for (int r = 0; r < 4; r++)
        h[r] = m[4 * r] * x + m[4 * r + 1] * y + m[4 * r + 2] * z + m[4 * r + 3];
    if (h[3] == 0 || !isfinite(h[3]))
        return 0;
    *X = bg_dv3_div(bg_dv3(h[0], h[1], h[2]), h[3]);
    bg_dvec3 c0 = bg_dv3(m[0], m[4], m[8]), c1 = bg_dv3(m[1], m[5], m[9]);
    *dX = bg_dv3_div(bg_dv3_sub(c0, bg_dv3_scale(*X, m[12])), h[3]);
    *dY = bg_dv3_div(bg_dv3_sub(c1, bg_dv3_scale(*X, m[13])), h[3]);
    return bg_dv3_finite(*X);
}

void bg_ray_differentials_inv_viewprojd(const double inv_view_proj[16], bg_dvec2 pixel,
                                        bg_dvec2 viewport, bg_dvec3 p, bg_dvec3 n, bg_dvec3 *dpdx,
                                        bg_dvec3 *dpdy)
{
    bg_dvec3 a = bg_dv3_zero(), b = bg_dv3_zero();
    *dpdx = a, *dpdy = b;
    if (!inv_view_proj || !(viewport.x != 0) || !(viewport.y != 0) || !fw_fin2(viewport) ||
        !fw_fin2(pixel))
        return;
    for (int i = 0; i < 16; i++)
        if (!isfinite(inv_view_proj[i]))
            return;
    double sx = 2.0 / viewport.x, sy = -2.0 / viewport.y; /* NDC per pixel; y flips */
    double x = pixel.x * sx - 1.0, y = 1.0 + pixel.y * sy;
    bg_dvec3 x0, x0dx, x0dy, x1, x1dx, x1dy;
    if (!unproject(inv_view_proj, x, y, 0.25, &x0, &x0dx, &x0dy) ||
        !unproject(inv_view_proj, x, y, 0.75, &x1, &x1dx, &x1dy))
        return;
    bg_dvec3 dox = bg_dv3_scale(x0dx, sx), doy = bg_dv3_scale(x0dy, sy);
    bg_dvec3 ddx = bg_dv3_scale(bg_dv3_sub(x1dx, x0dx), sx),
             ddy = bg_dv3_scale(bg_dv3_sub(x1dy, x0dy), sy);
    if (!ray_core(p, n, x0, bg_dv3_sub(x1, x0), dox, doy, ddx, ddy, &a, &b))
        return;
    *dpdx = a, *dpdy = b;
}

void bg_ray_differentials_inv_viewproj(const float inv_view_proj[16], bg_vec2 pixel,
                                       bg_vec2 viewport, bg_vec3 p, bg_vec3 n, bg_vec3 *dpdx,
                                       bg_vec3 *dpdy)
{
    double m[16];
    bg_dvec3 a, b;
    if (!inv_view_proj) {
        bg_vec3 z = {0, 0, 0};
        *dpdx = z, *dpdy = z;
        return;
    }
    for (int i = 0; i < 16; i++)
        m[i] = inv_view_proj[i];
    bg_ray_differentials_inv_viewprojd(m, fw_d2(pixel), fw_d2(viewport), bg_dv3_from_f(p),
                                       bg_dv3_from_f(n), &a, &b);
    *dpdx = bg_f3_from_dv(a), *dpdy = bg_f3_from_dv(b);
}
