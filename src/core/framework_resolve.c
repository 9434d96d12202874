/* SPDX-License-Identifier: MIT */
/* The normal resolve and the naive blend (overview, "normal resolve" and
 * "Combining multiple bump influences"; each resolve term is Mikkelsen 2010 eq. 4). */
#include "framework_internal.h"

/* One implementation for the float and double arrays (exactly one pair is used). */
static bg_dvec3 resolve_core(bg_dvec3 n, const bg_vec3 *fg, const float *fw, const bg_dvec3 *dg,
                             const double *dw, size_t count)
{
    bg_dvec3 u = bg_dv3_unit(n);
    if (bg_dv3_is_zero(u))
        return u;
    if (!fg && !dg)
        return u;
    /* Pass 1: bounds of the valid terms, so that pass 2 can scale everything into
     * [-1, 1] when the products would otherwise overflow a double (w 1e200, g 1e200):
     * normalize(n - S) == normalize(n/M - S/M). */
    double mw = 0, mg = 0;
    for (size_t i = 0; i < count; i++) {
        double w = fw ? fw[i] : (dw ? dw[i] : 1.0);
        bg_dvec3 g = fg ? bg_dv3_from_f(fg[i]) : dg[i];
        if (!isfinite(w) || !bg_dv3_finite(g))
            continue; /* an undefined slope is no slope: skip, as surfgrad.h does */
        mw = fmax(mw, fabs(w));
        mg = fmax(mg, bg_dv3_maxabs(g));
    }
    int scaled = mw * mg > 1.0;
    bg_dvec3 acc = u;
    if (scaled)
        acc = bg_dv3_div(bg_dv3_div(u, mw), mg);
    for (size_t i = 0; i < count; i++) {
        double w = fw ? fw[i] : (dw ? dw[i] : 1.0);
        bg_dvec3 g = fg ? bg_dv3_from_f(fg[i]) : dg[i];
        if (!isfinite(w) || !bg_dv3_finite(g))
            continue;
        acc =
            bg_dv3_sub(acc, scaled ? bg_dv3_scale(bg_dv3_div(g, mg), w / mw) : bg_dv3_scale(g, w));
    }
    bg_dvec3 r = bg_dv3_unit(acc);
    return bg_dv3_is_zero(r) ? u : r;
}

bg_dvec3 bg_resolve_normald(bg_dvec3 n, const bg_dvec3 *surfgrads, const double *weights,
                            size_t count)
{
    return resolve_core(n, NULL, NULL, surfgrads, weights, count);
}

bg_vec3 bg_resolve_normal(bg_vec3 n, const bg_vec3 *surfgrads, const float *weights, size_t count)
{
    return bg_f3_from_dv(resolve_core(bg_dv3_from_f(n), surfgrads, weights, NULL, NULL, count));
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
        bg_vec3 r =
            bg_f3_from_dv(resolve_core(bg_dv3(nx[i], ny[i], nz[i]), &s, NULL, NULL, NULL, 1));
        ox[i] = r.x, oy[i] = r.y, oz[i] = r.z; /* after reading: outputs may alias */
    }
}

static bg_dvec3 naive_core(const bg_vec3 *fn, const float *fw, const bg_dvec3 *dn, const double *dw,
                           size_t count)
{
    if (!fn && !dn)
        return bg_dv3_zero();
    /* Scale the weights by their largest magnitude so the sum cannot overflow. */
    double mw = 0;
    for (size_t i = 0; i < count; i++) {
        double w = fw ? fw[i] : (dw ? dw[i] : 1.0);
        if (isfinite(w))
            mw = fmax(mw, fabs(w));
    }
    if (!(mw > 0))
        return bg_dv3_zero();
    bg_dvec3 acc = bg_dv3_zero();
    for (size_t i = 0; i < count; i++) {
        double w = fw ? fw[i] : (dw ? dw[i] : 1.0);
        bg_dvec3 u = bg_dv3_unit(fn ? bg_dv3_from_f(fn[i]) : dn[i]);
        if (!isfinite(w) || bg_dv3_is_zero(u))
            continue;
        acc = bg_dv3_add(acc, bg_dv3_scale(u, w / mw));
    }
    return bg_dv3_unit(acc);
}

bg_vec3 bg_blend_normals_naive(const bg_vec3 *normals, const float *weights, size_t count)
{
    return bg_f3_from_dv(naive_core(normals, weights, NULL, NULL, count));
}

bg_dvec3 bg_blend_normals_naived(const bg_dvec3 *normals, const double *weights, size_t count)
{
    return naive_core(NULL, NULL, normals, weights, count);
}
