/* SPDX-License-Identifier: MIT */
/* Height textures: GPU-style bilinear sampling with wrap modes and the screen-space
 * height derivatives of Mikkelsen 2010 Listing 2; the mip-level derivative of the
 * reference framework (DerivFromHeightMapLevel) with its bicubic high-quality path. */
#include "framework_internal.h"
#include <stdint.h>

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

/* Where (s, t) falls between texel centres: the texel (*i, *j) below and left of
 * it after reduce(), and the fractions *fx, *fy towards the next; 0 if s or t is
 * not finite. Bilinear sampling and the bicubic derivatives both start here. */
static inline int texel_cell(const bg_height_texture *tex, double s, double t, long *i, long *j,
                             double *fx, double *fy)
{
    if (!isfinite(s) || !isfinite(t))
        return 0;
    double cx = reduce(s * tex->width - 0.5, tex->width, tex->wrap);
    double cy = reduce(t * tex->height - 0.5, tex->height, tex->wrap);
    double fx0 = floor(cx), fy0 = floor(cy);
    *fx = cx - fx0, *fy = cy - fy0;
    *i = (long)fx0, *j = (long)fy0;
    return 1;
}

static double sample_d(const bg_height_texture *tex, double s, double t)
{
    long x0, y0;
    double fx, fy;
    if (!texel_cell(tex, s, t, &x0, &y0, &fx, &fy))
        return NAN;
    int i0 = wrap_index(x0, tex->width, tex->wrap), i1 = wrap_index(x0 + 1, tex->width, tex->wrap);
    int j0 = wrap_index(y0, tex->height, tex->wrap),
        j1 = wrap_index(y0 + 1, tex->height, tex->wrap);
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

/* ---- mip levels and the reference's level derivative -------------------------------- */

int bg_height_mip_size(int size)
{
    return size > 1 ? size / 2 : 1;
}

bg_status bg_height_texture_downsample(const bg_height_texture *src, float *dst)
{
    bg_status st = bg_height_texture_validate(src);
    if (st != BG_OK)
        return st;
    if (!dst)
        return BG_ERR_NULL_POINTER;
    int w = bg_height_mip_size(src->width), h = bg_height_mip_size(src->height);
    for (int j = 0; j < h; j++) {
        /* 2x2 box; a size-1 axis reads its one texel twice. */
        int j0 = 2 * j < src->height ? 2 * j : src->height - 1;
        int j1 = 2 * j + 1 < src->height ? 2 * j + 1 : src->height - 1;
        const float *r0 = src->texels + (size_t)j0 * (size_t)src->width;
        const float *r1 = src->texels + (size_t)j1 * (size_t)src->width;
        for (int i = 0; i < w; i++) {
            int i0 = 2 * i < src->width ? 2 * i : src->width - 1;
            int i1 = 2 * i + 1 < src->width ? 2 * i + 1 : src->width - 1;
            double s = ((double)r0[i0] + r0[i1]) + ((double)r1[i0] + r1[i1]);
            dst[(size_t)j * (size_t)w + (size_t)i] = (float)(0.25 * s);
        }
    }
    return BG_OK;
}

bg_status bg_height_mips_validate(const bg_height_mips *mips)
{
    if (!mips || !mips->levels)
        return BG_ERR_NULL_POINTER;
    if (mips->count < 1)
        return BG_ERR_INVALID_ARGUMENT;
    for (int i = 0; i < mips->count; i++) {
        bg_status st = bg_height_texture_validate(&mips->levels[i]);
        if (st != BG_OK)
            return st;
    }
    return BG_OK;
}

/* Trilinear: bilinear in the two levels around lod, linear between them; lod is
 * clamped to the chain as SampleLevel clamps to the view's levels. */
static double sample_level_d(const bg_height_mips *mips, double s, double t, double lod)
{
    if (isnan(lod))
        return NAN;
    lod = fmin(fmax(lod, 0.0), (double)(mips->count - 1));
    int l0 = (int)floor(lod);
    double f = lod - l0;
    double a = sample_d(&mips->levels[l0], s, t);
    if (f == 0 || l0 + 1 >= mips->count)
        return a;
    return a + f * (sample_d(&mips->levels[l0 + 1], s, t) - a);
}

float bg_height_mips_sample_level(const bg_height_mips *mips, bg_vec2 st, float lod)
{
    return (float)sample_level_d(mips, st.x, st.y, lod);
}

float bg_height_texture_lod(const bg_height_texture *tex, bg_vec2 dst_dx, bg_vec2 dst_dy)
{
    /* The isotropic LOD of the D3D/GL specifications: log2 of the longer of the two
     * screen steps measured in texels. */
    double lx = hypot((double)dst_dx.x * tex->width, (double)dst_dx.y * tex->height);
    double ly = hypot((double)dst_dy.x * tex->width, (double)dst_dy.y * tex->height);
    return (float)log2(fmax(lx, ly));
}

/* Texel (i, j) after the wrap mode, for any integer i, j the 4x4 footprint reaches. */
static double texel(const bg_height_texture *tex, long i, long j)
{
    int x = wrap_index(i, tex->width, tex->wrap), y = wrap_index(j, tex->height, tex->wrap);
    return tex->texels[(size_t)y * (size_t)tex->width + (size_t)x];
}

static bg_dvec2 bicubic_derivs(const bg_height_texture *tex, double s, double t)
{
    bg_dvec2 r = {NAN, NAN};
    long i, j;
    double fx, fy;
    if (!texel_cell(tex, s, t, &i, &j, &fx, &fy))
        return r;
    /* The derivative along x at texel (a, b) is the central difference
     * (H[a+1] - H[a-1]) / 2, smoothed across by the [1 2 1]/4 binomial; both
     * fields are then interpolated bilinearly between the four texels around the
     * sample, which is the quadratic B-spline-like filter of the reference. */
    double gx[2][2], gy[2][2];
    for (int b = 0; b < 2; b++)
        for (int a = 0; a < 2; a++) {
            long x = i + a, y = j + b;
            double dxm = texel(tex, x + 1, y - 1) - texel(tex, x - 1, y - 1);
            double dx0 = texel(tex, x + 1, y) - texel(tex, x - 1, y);
            double dxp = texel(tex, x + 1, y + 1) - texel(tex, x - 1, y + 1);
            double dym = texel(tex, x - 1, y + 1) - texel(tex, x - 1, y - 1);
            double dy0 = texel(tex, x, y + 1) - texel(tex, x, y - 1);
            double dyp = texel(tex, x + 1, y + 1) - texel(tex, x + 1, y - 1);
            gx[b][a] = 0.125 * (dxm + 2.0 * dx0 + dxp);
            gy[b][a] = 0.125 * (dym + 2.0 * dy0 + dyp);
        }
    double x0 = gx[0][0] + fx * (gx[0][1] - gx[0][0]), x1 = gx[1][0] + fx * (gx[1][1] - gx[1][0]);
    double y0 = gy[0][0] + fx * (gy[0][1] - gy[0][0]), y1 = gy[1][0] + fx * (gy[1][1] - gy[1][0]);
    r.x = x0 + fy * (x1 - x0);
    r.y = y0 + fy * (y1 - y0);
    return r;
}

bg_vec2 bg_height_texture_derivs_bicubic(const bg_height_texture *tex, bg_vec2 st)
{
    return fw_f2(bicubic_derivs(tex, st.x, st.y));
}

/* The reference fades to the bicubic path between LOD 0.5 (none) and 0.05 (all). */
#define HQ_FADE_START 0.5
#define HQ_FADE_END 0.05

bg_vec2 bg_height_mips_derivs_level(const bg_height_mips *mips, bg_vec2 st, float lod, int hq)
{
    const bg_height_texture *top = &mips->levels[0];
    double s = st.x, t = st.y;
    double l = fmax(0.0, (double)lod); /* NaN lod is level 0, as max(0, NaN) on GPUs */
    /* Forward differences one texel of level l apart (2^l top-level texels),
     * divided by that step: height per top-level texel at every level. */
    double e = exp2(l);
    double hc = sample_level_d(mips, s, t, l);
    double hr = sample_level_d(mips, s + e / top->width, t, l);
    double hu = sample_level_d(mips, s, t + e / top->height, l);
    bg_dvec2 d = {(hr - hc) / e, (hu - hc) / e};
    double mix = fmin(fmax((l - HQ_FADE_START) / (HQ_FADE_END - HQ_FADE_START), 0.0), 1.0);
    if (hq && mix > 0) {
        bg_dvec2 b = bicubic_derivs(top, s, t);
        d.x += mix * (b.x - d.x), d.y += mix * (b.y - d.y);
    }
    return fw_f2(d);
}

bg_vec2 bg_height_mips_derivs(const bg_height_mips *mips, bg_vec2 st, bg_vec2 dst_dx,
                              bg_vec2 dst_dy, int hq)
{
    /* CalculateLevelOfDetail: the LOD clamped to the chain. -Inf (no footprint)
     * becomes 0; NaN becomes 0 in bg_height_mips_derivs_level. */
    float lod = bg_height_texture_lod(&mips->levels[0], dst_dx, dst_dy);
    lod = fminf(fmaxf(lod, 0.0f), (float)(mips->count - 1));
    return bg_height_mips_derivs_level(mips, st, lod, hq);
}
