/* SPDX-License-Identifier: MIT */
/* Public noise entry points. Single points run the scalar kernel (the template
 * with one lane), so they give the same bits as every batch ISA; batches go
 * through the dispatch table. Double points run the same template in double. */
#include <math.h>
#include "bumpgrad/noise.h"
#include "kernels/kernels.h"

bg_fractal bg_fractal_default(bg_function function)
{
    bg_fractal f = {function, function == BG_FUNC_NOISE ? 1 : BG_DEFAULT_OCTAVES, 2.0f, 0.5f};
    return f;
}

bg_status bg_fractal_validate(const bg_fractal *f)
{
    if (!f)
        return BG_ERR_NULL_POINTER;
    if (f->function != BG_FUNC_NOISE && f->function != BG_FUNC_FBM &&
        f->function != BG_FUNC_TURBULENCE)
        return BG_ERR_INVALID_ARGUMENT;
    if (f->function == BG_FUNC_NOISE)
        return BG_OK;
    if (f->octaves < 1 || f->octaves > BG_MAX_OCTAVES)
        return BG_ERR_INVALID_ARGUMENT;
    if (!(f->lacunarity > 0) || !isfinite(f->lacunarity) || !isfinite(f->gain))
        return BG_ERR_INVALID_ARGUMENT;
    return BG_OK;
}

/* Per-point calls go straight to the scalar point functions (kernels.h): the
 * same bits as the n = 1 batch, without its table load and loop (issue 10). */
float bg_noise3(float x, float y, float z)
{
    return bg_noise3_point_c(x, y, z);
}

float bg_noise3_grad(float x, float y, float z, bg_vec3 *grad)
{
    float g[3], v = bg_noise3_grad_point_c(x, y, z, g);
    grad->x = g[0], grad->y = g[1], grad->z = g[2];
    return v;
}

double bg_noise3d(double x, double y, double z)
{
    bg_dvec3 g;
    return bg_noise3d_grad(x, y, z, &g);
}

double bg_noise3d_grad(double x, double y, double z, bg_dvec3 *grad)
{
    double v;
    bg_kernels_c64.noise3_grad(&x, &y, &z, 1, &v, &grad->x, &grad->y, &grad->z);
    return v;
}

float bg_fractal3(const bg_fractal *f, float x, float y, float z)
{
    return bg_fractal3_point_c(f, x, y, z);
}

float bg_fractal3_grad(const bg_fractal *f, float x, float y, float z, bg_vec3 *grad)
{
    float g[3], v = bg_fractal3_grad_point_c(f, x, y, z, g);
    grad->x = g[0], grad->y = g[1], grad->z = g[2];
    return v;
}

float bg_fractal3_grad_central(const bg_fractal *f, float h, float x, float y, float z,
                               bg_vec3 *grad)
{
    float v;
    bg_kernels_c.fractal3_grad_central(f, h, &x, &y, &z, 1, &v, &grad->x, &grad->y, &grad->z);
    return v;
}

double bg_fractal3d(const bg_fractal *f, double x, double y, double z)
{
    bg_dvec3 g;
    return bg_fractal3d_grad(f, x, y, z, &g);
}

double bg_fractal3d_grad(const bg_fractal *f, double x, double y, double z, bg_dvec3 *grad)
{
    double v;
    bg_kernels_c64.fractal3_grad(f, &x, &y, &z, 1, &v, &grad->x, &grad->y, &grad->z);
    return v;
}

double bg_fractal3d_grad_central(const bg_fractal *f, double h, double x, double y, double z,
                                 bg_dvec3 *grad)
{
    double v;
    bg_kernels_c64.fractal3_grad_central(f, h, &x, &y, &z, 1, &v, &grad->x, &grad->y, &grad->z);
    return v;
}

void bg_noise3_batch(const float *x, const float *y, const float *z, size_t n, float *value)
{
    bg_kernels()->noise3(x, y, z, n, value);
}

void bg_noise3_grad_batch(const float *x, const float *y, const float *z, size_t n, float *value,
                          float *gx, float *gy, float *gz)
{
    bg_kernels()->noise3_grad(x, y, z, n, value, gx, gy, gz);
}

void bg_fractal3_batch(const bg_fractal *f, const float *x, const float *y, const float *z,
                       size_t n, float *value)
{
    bg_kernels()->fractal3(f, x, y, z, n, value);
}

void bg_fractal3_grad_batch(const bg_fractal *f, const float *x, const float *y, const float *z,
                            size_t n, float *value, float *gx, float *gy, float *gz)
{
    bg_kernels()->fractal3_grad(f, x, y, z, n, value, gx, gy, gz);
}

void bg_fractal3_grad_central_batch(const bg_fractal *f, float h, const float *x, const float *y,
                                    const float *z, size_t n, float *value, float *gx, float *gy,
                                    float *gz)
{
    bg_kernels()->fractal3_grad_central(f, h, x, y, z, n, value, gx, gy, gz);
}

void bg_fractal3d_grad_batch(const bg_fractal *f, const double *x, const double *y,
                             const double *z, size_t n, double *value, double *gx, double *gy,
                             double *gz)
{
    bg_kernels_c64.fractal3_grad(f, x, y, z, n, value, gx, gy, gz);
}
