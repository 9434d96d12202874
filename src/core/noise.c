/* SPDX-License-Identifier: MIT */
/* Public noise entry points. Single points run the scalar kernel (the template
 * with one lane), so they give the same bits as every batch ISA; batches go
 * through the dispatch table. Double points run the same template in double. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include "bumpgrad/noise.h"
#include "kernels/kernels.h"
#include "params.h"

bg_fractal bg_fractal_default(bg_function function)
{
    bg_fractal f = {function, function == BG_FUNC_NOISE ? 1 : BG_DEFAULT_OCTAVES, 2.0f, 0.5f};
    return f;
}

bg_status bg_fractal_validate(const bg_fractal *f)
{
    if (!f)
        return BG_ERR_NULL_POINTER;
    if (!bg_fractal_in_range(f))
        return BG_ERR_INVALID_ARGUMENT;
    double sv, sg;
    float fmax;
    return bg_fractal_octave_sums(f, &sv, &sg, &fmax) ? BG_OK : BG_ERR_OVERFLOW;
}

/* For a fractal in range: the octave factors freq_i = L^i and amp_i = G^i built
 * in float by repeated multiplication, exactly as the kernels build them
 * (src/kernels/bump_tmpl.c, fractal_fp_vec). Returns 0 if one of freq_i,
 * amp_i, amp_i * freq_i is not finite, or if the sum over the octaves could
 * overflow: BG_NOISE_VALUE_BOUND * sum |amp_i| or BG_NOISE_GRAD_BOUND * sum
 * |amp_i freq_i| above FLT_MAX. Else 1, with those sums and the largest freq_i.
 * The loop does no test: an Inf amp_i or freq_i makes a float sum Inf, or NaN
 * where it meets a factor that underflowed to 0, and both fail the final
 * comparison; freq_i is monotonic (rounding is), so the largest is the last one
 * for L >= 1 and freq_0 = 1 otherwise. A few flops per octave (one check per
 * batch call, bench figures in the commit message). */
int bg_fractal_octave_sums(const bg_fractal *f, double *sum_amp, double *sum_amp_freq,
                           float *max_freq)
{
    int octaves = f->function == BG_FUNC_NOISE ? 1 : f->octaves;
    float amp = 1, freq = 1, last = 1, sv = 0, sg = 0;
    const float gain = f->gain, lac = f->lacunarity;
    for (int i = 0; i < octaves; i++) {
        sv += fabsf(amp);
        sg += fabsf(amp * freq);
        last = freq;
        amp *= gain;
        freq *= lac;
    }
    float top = lac >= 1 ? last : 1;
    if (!(BG_NOISE_VALUE_BOUND * sv <= FLT_MAX) || !(BG_NOISE_GRAD_BOUND * sg <= FLT_MAX) ||
        !(top <= FLT_MAX))
        return 0;
    *sum_amp = sv, *sum_amp_freq = sg, *max_freq = top;
    return 1;
}

/* Largest float q >= 0 with q * fmax finite in float (round to nearest). */
static float max_unscaled(float fmax)
{
    float q = FLT_MAX / fmax; /* fmax >= 1: no overflow, within an ulp or two */
    while (q > 0 && !isfinite(q * fmax))
        q = nextafterf(q, 0);
    while (q < FLT_MAX && isfinite(nextafterf(q, INFINITY) * fmax))
        q = nextafterf(q, INFINITY);
    return q;
}

/* Largest p >= 0 with p * fr, rounded in the type T, <= q (q, fr > 0): start
 * from q / fr (FLT_MAX/DBL_MAX if that overflows), then step by ulps. One loop
 * for the float and the double bounds. */
#define BG_LARGEST_SCALED_BELOW(name, T, NEXTAFTER, T_MAX)                  \
    static T name(T q, T fr)                                               \
    {                                                                      \
        T p = q / fr;                                                      \
        if (!isfinite(p))                                                  \
            p = T_MAX;                                                     \
        while (p > 0 && !(p * fr <= q))                                    \
            p = NEXTAFTER(p, 0);                                           \
        while (p < T_MAX && NEXTAFTER(p, INFINITY) * fr <= q)              \
            p = NEXTAFTER(p, INFINITY);                                    \
        return p;                                                          \
    }
BG_LARGEST_SCALED_BELOW(largest_scaled_below_f, float, nextafterf, FLT_MAX)
BG_LARGEST_SCALED_BELOW(largest_scaled_below_d, double, nextafter, DBL_MAX)

float bg_fractal_max_coordinate(const bg_fractal *f, float frequency)
{
    double sv, sg;
    float top = 1;
    if (bg_fractal_validate(f) != BG_OK || !isfinite(frequency) ||
        !bg_fractal_octave_sums(f, &sv, &sg, &top))
        return NAN;
    float q = max_unscaled(top), fr = fabsf(frequency);
    if (fr == 0 || FLT_MAX * fr <= q)
        return FLT_MAX;
    return largest_scaled_below_f(q, fr);
}

double bg_fractal_max_coordinated(const bg_fractal *f, double frequency)
{
    if (bg_fractal_validate(f) != BG_OK || !isfinite(frequency))
        return NAN;
    /* The double kernel builds freq_i in double from the widened lacunarity. */
    int octaves = f->function == BG_FUNC_NOISE ? 1 : f->octaves;
    double freq = 1, fmax = 1;
    for (int i = 0; i < octaves; i++, freq *= f->lacunarity)
        fmax = freq > fmax ? freq : fmax;
    /* Largest q with q * fmax finite, i.e. q * fmax <= DBL_MAX (fmax >= 1). */
    double q = largest_scaled_below_d(DBL_MAX, fmax);
    double fr = fabs(frequency);
    if (fr == 0 || DBL_MAX * fr <= q)
        return DBL_MAX;
    return largest_scaled_below_d(q, fr);
}

/* Per-point noise goes to the dispatched table's one-lane point function
 * (kernels.h noise3_point: the scalar kernel, compiled with the AVX2 flags in
 * the AVX2 and AVX-512 tables): the same bits as the n = 1 batch, without its
 * loop (issue 10). Per-point fractals take the table's point function, which
 * runs the octaves of the one point across the vector lanes, with the same
 * bits. */
float bg_noise3(float x, float y, float z)
{
    return bg_kernels_inline()->noise3_point(x, y, z);
}

float bg_noise3_grad(float x, float y, float z, bg_vec3 *grad)
{
    float g[3], v = bg_kernels_inline()->noise3_grad_point(x, y, z, g);
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

/* Single points cannot return a status: a NULL or out-of-range descriptor (or
 * step) gives NaN value and gradient (noise.h), one check per call. */
float bg_fractal3(const bg_fractal *f, float x, float y, float z)
{
    if (!bg_fractal_in_range(f))
        return NAN;
    return bg_kernels_inline()->fractal3_point(f, x, y, z);
}

float bg_fractal3_grad(const bg_fractal *f, float x, float y, float z, bg_vec3 *grad)
{
    if (!bg_fractal_in_range(f)) {
        grad->x = grad->y = grad->z = NAN;
        return NAN;
    }
    float g[3], v = bg_kernels_inline()->fractal3_grad_point(f, x, y, z, g);
    grad->x = g[0], grad->y = g[1], grad->z = g[2];
    return v;
}

double bg_fractal3d(const bg_fractal *f, double x, double y, double z)
{
    bg_dvec3 g;
    return bg_fractal3d_grad(f, x, y, z, &g);
}

double bg_fractal3d_grad(const bg_fractal *f, double x, double y, double z, bg_dvec3 *grad)
{
    if (!bg_fractal_in_range(f)) {
        grad->x = grad->y = grad->z = NAN;
        return NAN;
    }
    double v;
    bg_kernels_c64.fractal3_grad(f, &x, &y, &z, 1, &v, &grad->x, &grad->y, &grad->z);
    return v;
}

/* The central-difference point, once for float and double: the n = 1 call of
 * that precision's scalar kernel, or NaN value and gradient for a bad `f` or
 * step (noise.h). */
#define CENTRAL_POINT(name, real, vec3, table)                                               \
    real name(const bg_fractal *f, real h, real x, real y, real z, vec3 *grad)              \
    {                                                                                      \
        real v = NAN;                                                                      \
        if (bg_fractal_in_range(f) && bg_central_step_ok(h))                               \
            table.fractal3_grad_central(f, h, &x, &y, &z, 1, &v, &grad->x, &grad->y,       \
                                        &grad->z);                                         \
        else                                                                               \
            grad->x = grad->y = grad->z = NAN;                                             \
        return v;                                                                          \
    }
CENTRAL_POINT(bg_fractal3_grad_central, float, bg_vec3, bg_kernels_c)
CENTRAL_POINT(bg_fractal3d_grad_central, double, bg_dvec3, bg_kernels_c64)

/* Batches (noise.h): n = 0 reads nothing and is BG_OK; otherwise every
 * required pointer and the parameters are checked once, before any output is
 * written, so a failed call leaves the outputs untouched. batch_ready is that
 * one check for every batch here: 1 if the kernel may run, else 0 with the
 * status to return in *st. `f` is required and validated when `fractal` is
 * set; a call with fewer than three required outputs passes one of them twice. */
static int batch_ready(size_t n, int fractal, const bg_fractal *f, const void *x, const void *y,
                       const void *z, const void *o1, const void *o2, const void *o3,
                       bg_status *st)
{
    *st = BG_OK;
    if (n == 0)
        return 0;
    if (!x || !y || !z || !o1 || !o2 || !o3 || (fractal && !f))
        *st = BG_ERR_NULL_POINTER;
    else if (fractal)
        *st = bg_fractal_validate(f);
    return *st == BG_OK;
}

/* A batch of one point takes the single-point path: the same bits (the point
 * functions equal the batch kernels, tests/kernels/check_grid.c), without the
 * vector kernel's masked-tail set-up, which costs more than the point itself
 * (issue 10: a batch call with n = 1 within 1.3x of the single-point call). */
bg_status bg_noise3_batch(const float *x, const float *y, const float *z, size_t n, float *value)
{
    bg_status s;
    if (!batch_ready(n, 0, NULL, x, y, z, value, value, value, &s))
        return s;
    if (n == 1)
        value[0] = bg_kernels_inline()->noise3_point(x[0], y[0], z[0]);
    else
        bg_kernels()->noise3(x, y, z, n, value);
    return BG_OK;
}

bg_status bg_noise3_grad_batch(const float *x, const float *y, const float *z, size_t n,
                               float *value, float *gx, float *gy, float *gz)
{
    bg_status s;
    if (!batch_ready(n, 0, NULL, x, y, z, gx, gy, gz, &s))
        return s;
    if (n == 1) {
        float g[3], v = bg_kernels_inline()->noise3_grad_point(x[0], y[0], z[0], g);
        if (value)
            value[0] = v;
        gx[0] = g[0], gy[0] = g[1], gz[0] = g[2];
    } else {
        bg_kernels()->noise3_grad(x, y, z, n, value, gx, gy, gz);
    }
    return BG_OK;
}

bg_status bg_fractal3_batch(const bg_fractal *f, const float *x, const float *y, const float *z,
                            size_t n, float *value)
{
    bg_status s;
    if (!batch_ready(n, 1, f, x, y, z, value, value, value, &s))
        return s;
    const bg_kernel_table *k = bg_kernels();
    if (n == 1)
        value[0] = k->fractal3_point(f, x[0], y[0], z[0]);
    else
        k->fractal3(f, x, y, z, n, value);
    return BG_OK;
}

bg_status bg_fractal3_grad_batch(const bg_fractal *f, const float *x, const float *y,
                                 const float *z, size_t n, float *value, float *gx, float *gy,
                                 float *gz)
{
    bg_status s;
    if (!batch_ready(n, 1, f, x, y, z, gx, gy, gz, &s))
        return s;
    const bg_kernel_table *k = bg_kernels();
    if (n == 1) {
        float g[3], v = k->fractal3_grad_point(f, x[0], y[0], z[0], g);
        if (value)
            value[0] = v;
        gx[0] = g[0], gy[0] = g[1], gz[0] = g[2];
    } else {
        k->fractal3_grad(f, x, y, z, n, value, gx, gy, gz);
    }
    return BG_OK;
}

bg_status bg_fractal3_grad_central_batch(const bg_fractal *f, float h, const float *x,
                                         const float *y, const float *z, size_t n, float *value,
                                         float *gx, float *gy, float *gz)
{
    bg_status s;
    if (!batch_ready(n, 1, f, x, y, z, gx, gy, gz, &s))
        return s;
    if (!bg_central_step_ok(h))
        return BG_ERR_INVALID_ARGUMENT;
    bg_kernels()->fractal3_grad_central(f, h, x, y, z, n, value, gx, gy, gz);
    return BG_OK;
}

bg_status bg_fractal3d_grad_batch(const bg_fractal *f, const double *x, const double *y,
                                  const double *z, size_t n, double *value, double *gx,
                                  double *gy, double *gz)
{
    bg_status s;
    if (batch_ready(n, 1, f, x, y, z, gx, gy, gz, &s))
        bg_kernels_c64.fractal3_grad(f, x, y, z, n, value, gx, gy, gz);
    return s;
}

/* ---- Regular grids (noise.h) ------------------------------------------------
 * The grid's points are generated into stack buffers of GRID_CHUNK points and
 * each buffer goes through the dispatched batch kernel: the bits of the batch
 * call on the same coordinates by construction. Hoisting the row-invariant y/z work
 * (lattice, fade) or reusing cell hashes along a row was measured instead of
 * assumed: docs/KERNELS.md, "Regular grids". */
#define GRID_CHUNK 512

typedef enum grid_kind { GRID_NOISE, GRID_FRACTAL, GRID_FRACTAL_GRAD } grid_kind;

/* The sample count of `g`, or BG_ERR_OVERFLOW when its output cannot exist. */
static bg_status grid_total(const bg_grid3 *g, size_t *total)
{
    size_t t = 1;
    *total = 0;
    if (!g->count[0] || !g->count[1] || !g->count[2])
        return BG_OK;
    for (int a = 0; a < 3; a++) {
        size_t c = g->count[a];
        if (t > SIZE_MAX / sizeof(float) / c)
            return BG_ERR_OVERFLOW;
        t *= c;
    }
    *total = t;
    return BG_OK;
}

static int grid_finite(const bg_grid3 *g)
{
    for (int a = 0; a < 3; a++)
        if (!isfinite(g->origin[a]) || !isfinite(g->step[a]))
            return 0;
    return 1;
}

/* The coordinate of sample index `i` along axis `a` (noise.h's formula). */
static inline float grid_coord(const bg_grid3 *g, int a, size_t i)
{
    return (float)(g->origin[a] + (double)i * g->step[a]);
}

/* One batch-kernel call on `c` points whose outputs start at index `o`. */
static void grid_kernel(const bg_kernel_table *k, grid_kind kind, const bg_fractal *f,
                        const float *xs, const float *ys, const float *zs, size_t c, size_t o,
                        float *v, float *gx, float *gy, float *gz)
{
    if (kind == GRID_NOISE)
        k->noise3(xs, ys, zs, c, v + o);
    else if (kind == GRID_FRACTAL)
        k->fractal3(f, xs, ys, zs, c, v + o);
    else
        k->fractal3_grad(f, xs, ys, zs, c, v ? v + o : NULL, gx + o, gy + o, gz + o);
}

/* Rows of at least GRID_ROW_MIN points run row by row: the x coordinates are
 * computed once per call (per segment for rows longer than a chunk), y and z
 * are filled once per row, so the grid adds about 1 instruction per sample to
 * the batch kernel instead of 16 (docs/KERNELS.md). Shorter rows are packed
 * across row ends into whole chunks, so a column still fills the vectors. */
#define GRID_ROW_MIN 16

static void grid_run(grid_kind kind, const bg_fractal *f, const bg_grid3 *g, size_t total,
                     float *v, float *gx, float *gy, float *gz)
{
    const bg_kernel_table *k = bg_kernels();
    float xs[GRID_CHUNK], ys[GRID_CHUNK], zs[GRID_CHUNK];
    const size_t nx = g->count[0], ny = g->count[1];
    if (nx >= GRID_ROW_MIN) {
        const size_t seg = nx < GRID_CHUNK ? nx : GRID_CHUNK;
        for (size_t i = 0; i < seg; i++)
            xs[i] = grid_coord(g, 0, i);
        for (size_t row = 0, o = 0; o < total; row++) {
            float y = grid_coord(g, 1, row % ny), z = grid_coord(g, 2, row / ny);
            for (size_t i = 0; i < seg; i++)
                ys[i] = y, zs[i] = z;
            for (size_t s = 0; s < nx; s += seg) {
                size_t c = nx - s < seg ? nx - s : seg;
                if (nx > GRID_CHUNK)
                    for (size_t i = 0; i < c; i++)
                        xs[i] = grid_coord(g, 0, s + i);
                grid_kernel(k, kind, f, xs, ys, zs, c, o, v, gx, gy, gz);
                o += c;
            }
        }
        return;
    }
    size_t i = 0, j = 0, l = 0;
    float y = grid_coord(g, 1, 0), z = grid_coord(g, 2, 0);
    for (size_t o = 0; o < total;) {
        size_t c = total - o < GRID_CHUNK ? total - o : GRID_CHUNK;
        for (size_t m = 0; m < c; m++) {
            xs[m] = grid_coord(g, 0, i), ys[m] = y, zs[m] = z;
            if (++i == nx) {
                i = 0;
                if (++j == ny)
                    j = 0, z = grid_coord(g, 2, ++l);
                y = grid_coord(g, 1, j);
            }
        }
        grid_kernel(k, kind, f, xs, ys, zs, c, o, v, gx, gy, gz);
        o += c;
    }
}

/* noise.h's check order for the grid calls, then the run. */
static bg_status grid_call(grid_kind kind, const bg_fractal *f, const bg_grid3 *g, float *v,
                           float *gx, float *gy, float *gz)
{
    size_t total;
    if (!g)
        return BG_ERR_NULL_POINTER;
    bg_status s = grid_total(g, &total);
    if (s != BG_OK || total == 0)
        return s;
    const float *o1 = kind == GRID_FRACTAL_GRAD ? gx : v;
    if (!batch_ready(total, kind != GRID_NOISE, f, g, g, g, o1, kind == GRID_FRACTAL_GRAD ? gy : o1,
                     kind == GRID_FRACTAL_GRAD ? gz : o1, &s))
        return s;
    if (!grid_finite(g))
        return BG_ERR_INVALID_ARGUMENT;
    grid_run(kind, f, g, total, v, gx, gy, gz);
    return BG_OK;
}

bg_status bg_noise3_grid(const bg_grid3 *g, float *value)
{
    return grid_call(GRID_NOISE, NULL, g, value, NULL, NULL, NULL);
}

bg_status bg_fractal3_grid(const bg_fractal *f, const bg_grid3 *g, float *value)
{
    return grid_call(GRID_FRACTAL, f, g, value, NULL, NULL, NULL);
}

bg_status bg_fractal3_grad_grid(const bg_fractal *f, const bg_grid3 *g, float *value, float *gx,
                                float *gy, float *gz)
{
    return grid_call(GRID_FRACTAL_GRAD, f, g, value, gx, gy, gz);
}

/* ---- Domains: tileable noise and seeded octaves (noise.h bg_domain) ---------
 * A set domain runs the domain kernels (the dispatched table's dfractal3*);
 * the default (all zero) takes the plain calls, so its bits are theirs. Single
 * points run the scalar kernel's n = 1 batch: the same bits as every ISA. */
bg_status bg_domain_validate(const bg_fractal *f, const bg_domain *d)
{
    if (!f || !d)
        return BG_ERR_NULL_POINTER;
    bg_status s = bg_fractal_validate(f);
    if (s != BG_OK)
        return s;
    return bg_domain_in_range(f, d) ? BG_OK : BG_ERR_INVALID_ARGUMENT;
}

float bg_domain_offset(unsigned int seed, int octave, int axis)
{
    return bg_seed_offset(seed, octave, axis);
}

static const bg_fractal pnoise_fractal = {BG_FUNC_NOISE, 1, 2.0f, 0.5f};

/* The domain of periodic noise, or 0 for a NULL or out-of-range period. */
static int pnoise_domain(const int period[3], bg_domain *d)
{
    if (!period)
        return 0;
    *d = (bg_domain){{period[0], period[1], period[2]}, 0};
    return bg_domain_in_range(&pnoise_fractal, d);
}

/* One point over a domain, float or double, value and gradient: NaN for a bad
 * descriptor; the plain point call for an unset domain. */
static float domain_point(const bg_fractal *f, const bg_domain *d, float x, float y, float z,
                          float g[3])
{
    if (!bg_fractal_in_range(f) || !bg_domain_in_range(f, d)) {
        g[0] = g[1] = g[2] = NAN;
        return NAN;
    }
    float v;
    if (bg_domain_is_set(d))
        bg_kernels_c.dfractal3_grad(f, d, &x, &y, &z, 1, &v, &g[0], &g[1], &g[2]);
    else
        bg_kernels_c.fractal3_grad(f, &x, &y, &z, 1, &v, &g[0], &g[1], &g[2]);
    return v;
}

static double domain_pointd(const bg_fractal *f, const bg_domain *d, double x, double y, double z,
                            bg_dvec3 *g)
{
    if (!bg_fractal_in_range(f) || !bg_domain_in_range(f, d)) {
        g->x = g->y = g->z = NAN;
        return NAN;
    }
    double v;
    if (bg_domain_is_set(d))
        bg_kernels_c64.dfractal3_grad(f, d, &x, &y, &z, 1, &v, &g->x, &g->y, &g->z);
    else
        bg_kernels_c64.fractal3_grad(f, &x, &y, &z, 1, &v, &g->x, &g->y, &g->z);
    return v;
}

float bg_fractal3_domain(const bg_fractal *f, const bg_domain *d, float x, float y, float z)
{
    float g[3];
    return domain_point(f, d, x, y, z, g);
}

float bg_fractal3_domain_grad(const bg_fractal *f, const bg_domain *d, float x, float y, float z,
                              bg_vec3 *grad)
{
    float g[3], v = domain_point(f, d, x, y, z, g);
    grad->x = g[0], grad->y = g[1], grad->z = g[2];
    return v;
}

double bg_fractal3d_domain(const bg_fractal *f, const bg_domain *d, double x, double y, double z)
{
    bg_dvec3 g;
    return domain_pointd(f, d, x, y, z, &g);
}

double bg_fractal3d_domain_grad(const bg_fractal *f, const bg_domain *d, double x, double y,
                                double z, bg_dvec3 *grad)
{
    return domain_pointd(f, d, x, y, z, grad);
}

float bg_pnoise3(float x, float y, float z, const int period[3])
{
    bg_domain d;
    float g[3];
    return pnoise_domain(period, &d) ? domain_point(&pnoise_fractal, &d, x, y, z, g) : NAN;
}

float bg_pnoise3_grad(float x, float y, float z, const int period[3], bg_vec3 *grad)
{
    bg_domain d;
    float g[3] = {NAN, NAN, NAN}, v = NAN;
    if (pnoise_domain(period, &d))
        v = domain_point(&pnoise_fractal, &d, x, y, z, g);
    grad->x = g[0], grad->y = g[1], grad->z = g[2];
    return v;
}

double bg_pnoise3d(double x, double y, double z, const int period[3])
{
    bg_dvec3 g;
    return bg_pnoise3d_grad(x, y, z, period, &g);
}

double bg_pnoise3d_grad(double x, double y, double z, const int period[3], bg_dvec3 *grad)
{
    bg_domain d;
    if (!pnoise_domain(period, &d)) {
        grad->x = grad->y = grad->z = NAN;
        return NAN;
    }
    return domain_pointd(&pnoise_fractal, &d, x, y, z, grad);
}

/* The batch check of a domain call: batch_ready, then bg_domain_validate. */
static int domain_ready(size_t n, const bg_fractal *f, const bg_domain *d, const void *x,
                        const void *y, const void *z, const void *o1, const void *o2,
                        const void *o3, bg_status *st)
{
    if (n && !d) {
        *st = BG_ERR_NULL_POINTER;
        return 0;
    }
    if (!batch_ready(n, 1, f, x, y, z, o1, o2, o3, st))
        return 0;
    *st = bg_domain_validate(f, d);
    return *st == BG_OK;
}

bg_status bg_fractal3_domain_batch(const bg_fractal *f, const bg_domain *d, const float *x,
                                   const float *y, const float *z, size_t n, float *value)
{
    bg_status s;
    if (!domain_ready(n, f, d, x, y, z, value, value, value, &s))
        return s;
    if (bg_domain_is_set(d))
        bg_kernels()->dfractal3(f, d, x, y, z, n, value);
    else
        bg_kernels()->fractal3(f, x, y, z, n, value);
    return BG_OK;
}

bg_status bg_fractal3_domain_grad_batch(const bg_fractal *f, const bg_domain *d, const float *x,
                                        const float *y, const float *z, size_t n, float *value,
                                        float *gx, float *gy, float *gz)
{
    bg_status s;
    if (!domain_ready(n, f, d, x, y, z, gx, gy, gz, &s))
        return s;
    if (bg_domain_is_set(d))
        bg_kernels()->dfractal3_grad(f, d, x, y, z, n, value, gx, gy, gz);
    else
        bg_kernels()->fractal3_grad(f, x, y, z, n, value, gx, gy, gz);
    return BG_OK;
}

bg_status bg_fractal3_domain_grad_central_batch(const bg_fractal *f, const bg_domain *d, float h,
                                                const float *x, const float *y, const float *z,
                                                size_t n, float *value, float *gx, float *gy,
                                                float *gz)
{
    bg_status s;
    if (!domain_ready(n, f, d, x, y, z, gx, gy, gz, &s))
        return s;
    if (!bg_central_step_ok(h))
        return BG_ERR_INVALID_ARGUMENT;
    if (bg_domain_is_set(d))
        bg_kernels()->dfractal3_grad_central(f, d, h, x, y, z, n, value, gx, gy, gz);
    else
        bg_kernels()->fractal3_grad_central(f, h, x, y, z, n, value, gx, gy, gz);
    return BG_OK;
}

bg_status bg_fractal3d_domain_grad_batch(const bg_fractal *f, const bg_domain *d,
                                         const double *x, const double *y, const double *z,
                                         size_t n, double *value, double *gx, double *gy,
                                         double *gz)
{
    bg_status s;
    if (!domain_ready(n, f, d, x, y, z, gx, gy, gz, &s))
        return s;
    if (bg_domain_is_set(d))
        bg_kernels_c64.dfractal3_grad(f, d, x, y, z, n, value, gx, gy, gz);
    else
        bg_kernels_c64.fractal3_grad(f, x, y, z, n, value, gx, gy, gz);
    return BG_OK;
}

bg_status bg_pnoise3_batch(const int period[3], const float *x, const float *y, const float *z,
                           size_t n, float *value)
{
    if (n && !period)
        return BG_ERR_NULL_POINTER;
    bg_domain d = {{0, 0, 0}, 0};
    if (n)
        d = (bg_domain){{period[0], period[1], period[2]}, 0};
    return bg_fractal3_domain_batch(&pnoise_fractal, &d, x, y, z, n, value);
}

bg_status bg_pnoise3_grad_batch(const int period[3], const float *x, const float *y,
                                const float *z, size_t n, float *value, float *gx, float *gy,
                                float *gz)
{
    if (n && !period)
        return BG_ERR_NULL_POINTER;
    bg_domain d = {{0, 0, 0}, 0};
    if (n)
        d = (bg_domain){{period[0], period[1], period[2]}, 0};
    return bg_fractal3_domain_grad_batch(&pnoise_fractal, &d, x, y, z, n, value, gx, gy, gz);
}
