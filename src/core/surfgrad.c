/* SPDX-License-Identifier: MIT */
/* Public surface-gradient entry points (Mikkelsen 2010, eq. 2 and 4, Listing 3).
 * The perturbations run the kernel template (one lane here), so single points,
 * batches and every ISA share one implementation of the degenerate-input rules. */
#include <float.h>
#include <math.h>
#include "bumpgrad/surfgrad.h"
#include "kernels/kernels.h"
#include "params.h"

/* An unknown method is a caller's error, not a degenerate input: NaN in every
 * component, which no valid result can be (surfgrad.h). */
bg_vec3 bg_perturb(bg_perturb_method method, bg_vec3 n, bg_vec3 g)
{
    if (!bg_perturb_method_ok(method))
        return (bg_vec3){NAN, NAN, NAN};
    bg_vec3 r;
    bg_kernels_c.perturb(method, &n.x, &n.y, &n.z, &g.x, &g.y, &g.z, 1, &r.x, &r.y, &r.z);
    return r;
}

bg_dvec3 bg_perturbd(bg_perturb_method method, bg_dvec3 n, bg_dvec3 g)
{
    bg_dvec3 r;
    if (!bg_perturb_method_ok(method))
        return (bg_dvec3){NAN, NAN, NAN};
    bg_kernels_c64.perturb(method, &n.x, &n.y, &n.z, &g.x, &g.y, &g.z, 1, &r.x, &r.y, &r.z);
    return r;
}

bg_vec3 bg_perturb_normal(bg_vec3 n, bg_vec3 g) { return bg_perturb(BG_PERTURB_SURFGRAD, n, g); }
bg_dvec3 bg_perturb_normald(bg_dvec3 n, bg_dvec3 g) { return bg_perturbd(BG_PERTURB_SURFGRAD, n, g); }
bg_vec3 bg_perturb_normal_additive(bg_vec3 n, bg_vec3 g) { return bg_perturb(BG_PERTURB_ADDITIVE, n, g); }
bg_dvec3 bg_perturb_normal_additived(bg_dvec3 n, bg_dvec3 g) { return bg_perturbd(BG_PERTURB_ADDITIVE, n, g); }

/* grad_S h = g - n (n.g) (eq. 2), with n normalized through the same scaled
 * normalization as the perturbation. Computed in double then rounded once. */
bg_dvec3 bg_surface_gradientd(bg_dvec3 n, bg_dvec3 g)
{
    bg_dvec3 zero = {0, 0, 0};
    double m = fmax(fmax(fabs(n.x), fabs(n.y)), fabs(n.z));
    if (!(m > 0) || !isfinite(n.x) || !isfinite(n.y) || !isfinite(n.z) || !isfinite(g.x) ||
        !isfinite(g.y) || !isfinite(g.z))
        return zero;
    n.x /= m, n.y /= m, n.z /= m;
    double l = sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
    n.x /= l, n.y /= l, n.z /= l;
    double d = n.x * g.x + n.y * g.y + n.z * g.z;
    bg_dvec3 r = {g.x - n.x * d, g.y - n.y * d, g.z - n.z * d};
    return r;
}

bg_vec3 bg_surface_gradient(bg_vec3 n, bg_vec3 g)
{
    bg_dvec3 nd = {n.x, n.y, n.z}, gd = {g.x, g.y, g.z};
    bg_dvec3 r = bg_surface_gradientd(nd, gd);
    bg_vec3 o = {(float)r.x, (float)r.y, (float)r.z};
    return o;
}

double bg_angle_degd(bg_dvec3 a, bg_dvec3 b)
{
    double cx = a.y * b.z - a.z * b.y, cy = a.z * b.x - a.x * b.z, cz = a.x * b.y - a.y * b.x;
    double s = sqrt(cx * cx + cy * cy + cz * cz), c = a.x * b.x + a.y * b.y + a.z * b.z;
    double la = a.x * a.x + a.y * a.y + a.z * a.z, lb = b.x * b.x + b.y * b.y + b.z * b.z;
    if (!(la > 0) || !(lb > 0) || !isfinite(la) || !isfinite(lb))
        return NAN;
    return atan2(s, c) * (180.0 / 3.14159265358979323846);
}

double bg_angle_deg(bg_vec3 a, bg_vec3 b)
{
    bg_dvec3 ad = {a.x, a.y, a.z}, bd = {b.x, b.y, b.z};
    return bg_angle_degd(ad, bd);
}

bg_status bg_perturb_batch(bg_perturb_method method, const float *nx, const float *ny,
                           const float *nz, const float *gx, const float *gy, const float *gz,
                           size_t n, float *ox, float *oy, float *oz)
{
    if (n == 0)
        return BG_OK;
    if (!nx || !ny || !nz || !gx || !gy || !gz || !ox || !oy || !oz)
        return BG_ERR_NULL_POINTER;
    if (!bg_perturb_method_ok(method))
        return BG_ERR_INVALID_ARGUMENT;
    bg_kernels()->perturb(method, nx, ny, nz, gx, gy, gz, n, ox, oy, oz);
    return BG_OK;
}

bg_height bg_height_default(void)
{
    bg_height h;
    h.fractal = bg_fractal_default(BG_FUNC_TURBULENCE);
    h.amplitude = 0.1f;
    h.frequency = 1.0f;
    h.gradient = BG_GRADIENT_ANALYTIC;
    h.step = 0.0f;
    h.domain = (bg_domain){{0, 0, 0}, 0};
    return h;
}

bg_status bg_height_validate(const bg_height *h)
{
    /* The fractal's own octave sums, then the height's scale on top of them, as
     * the fused kernel applies it: q = f p, h = A F(q), grad = (A f) F'(q). */
    double sv, sg;
    float fmax;
    if (!h)
        return BG_ERR_NULL_POINTER;
    if (!bg_height_in_range(h))
        return BG_ERR_INVALID_ARGUMENT;
    if (!bg_fractal_octave_sums(&h->fractal, &sv, &sg, &fmax))
        return BG_ERR_OVERFLOW;
    float af = h->amplitude * h->frequency, top = fabsf(h->frequency) * fmax;
    if (!isfinite(af) || !isfinite(top) ||
        BG_NOISE_VALUE_BOUND * sv * fabs((double)h->amplitude) > FLT_MAX ||
        BG_NOISE_GRAD_BOUND * sg * fabs((double)af) > FLT_MAX)
        return BG_ERR_OVERFLOW;
    return BG_OK;
}

float bg_height_eval(const bg_height *h, bg_vec3 p, bg_vec3 *grad)
{
    if (!bg_height_in_range(h)) {
        if (grad)
            grad->x = grad->y = grad->z = NAN;
        return NAN;
    }
    /* Same arithmetic, in the same order, as the fused kernel (q = f p, grad = (A f) F'). */
    float q[3] = {p.x * h->frequency, p.y * h->frequency, p.z * h->frequency};
    float v, g[3];
    const float step = h->step > 0 ? h->step : BG_DEFAULT_CENTRAL_STEP;
    if (bg_domain_is_set(&h->domain)) {
        if (h->gradient == BG_GRADIENT_CENTRAL)
            bg_kernels_c.dfractal3_grad_central(&h->fractal, &h->domain, step, &q[0], &q[1], &q[2],
                                                1, &v, &g[0], &g[1], &g[2]);
        else
            bg_kernels_c.dfractal3_grad(&h->fractal, &h->domain, &q[0], &q[1], &q[2], 1, &v, &g[0],
                                        &g[1], &g[2]);
    } else if (h->gradient == BG_GRADIENT_CENTRAL) {
        bg_kernels_c.fractal3_grad_central(&h->fractal, step, &q[0], &q[1], &q[2], 1, &v, &g[0],
                                           &g[1], &g[2]);
    } else {
        bg_kernels_c.fractal3_grad(&h->fractal, &q[0], &q[1], &q[2], 1, &v, &g[0], &g[1], &g[2]);
    }
    float af = h->amplitude * h->frequency;
    if (grad)
        grad->x = af * g[0], grad->y = af * g[1], grad->z = af * g[2];
    return h->amplitude * v;
}

bg_status bg_perturb_height_check(const bg_height *h, bg_perturb_method method,
                                  const float *px, const float *py, const float *pz,
                                  const float *nx, const float *ny, const float *nz, float *ox,
                                  float *oy, float *oz)
{
    if (!h || !px || !py || !pz || !nx || !ny || !nz || !ox || !oy || !oz)
        return BG_ERR_NULL_POINTER;
    bg_status s = bg_height_validate(h);
    if (s != BG_OK)
        return s;
    return bg_perturb_method_ok(method) ? BG_OK : BG_ERR_INVALID_ARGUMENT;
}

bg_status bg_perturb_height_batch(const bg_height *h, bg_perturb_method method, const float *px,
                                  const float *py, const float *pz, const float *nx,
                                  const float *ny, const float *nz, size_t n, float *height,
                                  float *ox, float *oy, float *oz)
{
    if (n == 0)
        return BG_OK;
    bg_status s = bg_perturb_height_check(h, method, px, py, pz, nx, ny, nz, ox, oy, oz);
    if (s != BG_OK)
        return s;
    bg_kernels()->perturb_height(h, method, px, py, pz, nx, ny, nz, n, height, ox, oy, oz);
    return BG_OK;
}
