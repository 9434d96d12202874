/* SPDX-License-Identifier: MIT */
/* The usage example of docs/FRAMEWORK.md, verbatim between the markers, so the
 * documented code keeps compiling; main() runs it on a flat, lit-from-the-front
 * hit and checks the documented outcome (unit normal, facing the viewer, and the
 * weights' effect). */
#include <math.h>
#include <stdio.h>
#include "common/check.h"

/* ---- begin docs/FRAMEWORK.md example ---- */
#include <bumpgrad.h>

/* hit: position p, interpolated normal nv, mikkTSpace tangent tv (+ sign),
 * uv0 (normal map), uv1 (height map) and their per-pixel derivatives; camera. */
bg_vec3 shade_normal(bg_vec3 p, bg_vec3 nv, bg_vec3 tv, float tsign, bg_vec3 camera,
                     bg_vec3 ray_dir, bg_vec3 ddir_dx, bg_vec3 ddir_dy,
                     bg_vec3 normal_map_sample, bg_vec2 uv1, bg_vec2 duv1dx,
                     bg_vec2 duv1dy, const bg_height_texture *bump_tex,
                     const bg_height *solid)
{
    bg_vec3 to_eye = {camera.x - p.x, camera.y - p.y, camera.z - p.z};
    nv = bg_face_forward(nv, to_eye);          /* double-sided: visible side first */

    /* 1. tangent-space normal map, mikkTSpace-compliant */
    bg_tangent_frame f = bg_mikktspace_renormalize(tv, tsign, nv);
    bg_vec3 g[3];
    g[0] = bg_surfgrad_from_tangent_normal(f.t, f.b, normal_map_sample);

    /* 2. height texture on uv1: no tangents, no ddx/ddy -> ray differentials */
    bg_vec3 dpdx, dpdy;
    bg_ray_differentials(p, f.n, camera, ray_dir, ddir_dx, ddir_dy, &dpdx, &dpdy);
    bg_vec2 dB = bg_height_texture_derivs(bump_tex, BG_DIFF_CENTRAL, uv1, duv1dx, duv1dy);
    g[1] = bg_surfgrad_from_screen_derivs(f.n, dpdx, dpdy, dB.x, dB.y);

    /* 3. solid turbulence: its volume gradient projected (eq. 2) */
    bg_vec3 vg;
    bg_height_eval(solid, p, &vg);
    g[2] = bg_surface_gradient(f.n, vg);

    float w[3] = {1.0f, 0.5f, 1.0f};           /* a weight of 0.5 halves that slope */
    return bg_resolve_normal(f.n, g, w, 3);
}
/* ---- end docs/FRAMEWORK.md example ---- */

int main(void)
{
    float tex[16];
    for (int i = 0; i < 16; i++)
        tex[i] = 0.02f * (float)(i % 4); /* ramp along s */
    bg_height_texture bump = {4, 4, tex, BG_WRAP_CLAMP};
    bg_height solid = bg_height_default();
    solid.amplitude = 0.0f; /* isolate the first two influences */
    bg_vec3 p = {0.1f, 0.2f, 0}, n = {0, 0, 1}, t = {1, 0, 0}, cam = {0.1f, 0.2f, 5};
    bg_vec3 dir = {0, 0, -1}, ddx = {0.001f, 0, 0}, ddy = {0, -0.001f, 0};
    bg_vec3 flat = {0, 0, 1};
    bg_vec2 uv = {0.5f, 0.5f}, duvdx = {0.01f, 0}, duvdy = {0, 0.01f};
    bg_vec3 r = shade_normal(p, n, t, 1.0f, cam, dir, ddx, ddy, flat, uv, duvdx, duvdy, &bump,
                             &solid);
    double len = sqrt((double)r.x * r.x + (double)r.y * r.y + (double)r.z * r.z);
    CHECK(fabs(len - 1) < 1e-6, "result not unit");
    CHECK(r.z > 0.5f, "result faces away from the viewer");
    /* The ramp rises along +s = +x, so the normal tilts toward -x; y untouched. */
    CHECK(r.x < -0.01f && fabsf(r.y) < 1e-6f, "height texture slope missing or wrong");
    /* Seen from behind, the back-side rule flips the base normal. */
    bg_vec3 cam2 = {0.1f, 0.2f, -5}, dir2 = {0, 0, 1};
    bg_vec3 r2 = shade_normal(p, n, t, 1.0f, cam2, dir2, ddx, ddy, flat, uv, duvdx, duvdy, &bump,
                              &solid);
    CHECK(r2.z < -0.5f, "back side must face the viewer");
    return check_summary("test_fw_example");
}
