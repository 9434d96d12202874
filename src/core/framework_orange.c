/* SPDX-License-Identifier: MIT */
/* The Orange Book's procedural bumps (OpenGL Shading Language, section 11.4,
 * Listings 11.7-11.8): a tangent-space normal source and the listing's shading. */
#include "bumpgrad/framework.h"
#include <math.h>

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
    bg_vec3 c = {fminf(surface_color.x * diff + spec, 1.0f),
                 fminf(surface_color.y * diff + spec, 1.0f),
                 fminf(surface_color.z * diff + spec, 1.0f)};
    return c;
}
