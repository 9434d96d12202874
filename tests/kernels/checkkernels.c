/* SPDX-License-Identifier: MIT */
/* Kernel harness in the spirit of dav1d's checkasm: every kernel of
 * bg_kernel_table on every ISA this build and CPU have, on the same seeded inputs,
 * compared bit for bit against the scalar kernel (bg_kernels_c); the scalar kernel
 * itself compared against a double reference with an absolute epsilon (tests/ref
 * when built, and always the library's double kernels bg_kernels_c64).
 *
 * Tails 0..2*16+1 and a long run, inputs and outputs misaligned by 0..3 floats,
 * canary floats around every output, inputs allocated to their exact length (so
 * ASan sees any read past the end). Special inputs: lattice and near-lattice
 * points, +-0, negative, large (1e4, 1e7, 3e38), NaN, Inf; zero/NaN/huge normals
 * and gradients. Every kernel output NaN is the canonical quiet NaN, so NaNs are
 * compared bitwise like everything else (docs/KERNELS.md).
 *
 *   checkkernels            run the checks (exit 1 on any mismatch)
 *   checkkernels --bench [--only=<substring>]
 *                           print ns/sample and speed-up over scalar (no checks)
 *   checkkernels --run=<table>:<case>:<n>
 *                           one call of benchmark case <case> (0-based) on the
 *                           table named <table> ("c", "avx2", "avx512vbmi", ...),
 *                           for callgrind instruction counts
 */
#define _POSIX_C_SOURCE 200809L
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "kernels/kernels.h"
#ifdef BG_HAVE_REF
#include "ref.h"
#endif

#define MAX_LANES 16
#define MAX_TAIL (2 * MAX_LANES + 1)
#define LONG_N 517
#define GUARD 8
#define MAX_IN 6
#define MAX_OUT 4

static int failures;
static long checks;

/* ---- deterministic inputs ------------------------------------------------ */

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static uint64_t rng_u64(void)
{
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
static double rng_unit(void) { return (double)(rng_u64() >> 11) * (1.0 / 9007199254740992.0); }
static float rng_range(double lo, double hi) { return (float)(lo + (hi - lo) * rng_unit()); }

/* A coordinate: mostly ordinary values, with every special class mixed in. */
static float coord(void)
{
    unsigned k = (unsigned)(rng_u64() % 40);
    float i = (float)((int)(rng_u64() % 1201) - 600);
    switch (k) {
    case 0: return i;                                      /* lattice point */
    case 1: return nextafterf(i, INFINITY);                /* near lattice */
    case 2: return nextafterf(i, -INFINITY);
    case 3: return i + 1e-4f;
    case 4: return 0.0f;
    case 5: return -0.0f;
    case 6: return rng_range(-1e4, 1e4);
    case 7: return rng_range(-1e7, 1e7);
    case 8: return (rng_u64() & 1) ? 3e38f : -3e38f;
    case 9: return (rng_u64() & 1) ? FLT_MAX : -FLT_MAX;
    case 10: return NAN;
    case 11: return (rng_u64() & 1) ? INFINITY : -INFINITY;
    case 12: return 8388607.5f;                            /* 2^23 - 0.5 */
    case 13: return -8388608.0f;
    case 14: return 255.99998f;
    case 15: return -256.0f;
    case 16: return 1e-40f;                                /* subnormal */
    case 17: return -1e-40f;
    case 18: return rng_range(-1, 1);
    default: return rng_range(-300, 300);
    }
}

static float normal_comp(void)
{
    unsigned k = (unsigned)(rng_u64() % 48);
    switch (k) {
    case 0: return 0.0f;
    case 1: return -0.0f;
    case 2: return NAN;
    case 3: return INFINITY;
    case 4: return 1e30f;
    case 5: return 1e-30f;
    case 6: return 1e-40f;
    case 7: return FLT_MAX;
    default: return rng_range(-1, 1);
    }
}

static float grad_comp(void)
{
    unsigned k = (unsigned)(rng_u64() % 40);
    switch (k) {
    case 0: return 0.0f;
    case 1: return -0.0f;
    case 2: return NAN;
    case 3: return -INFINITY;
    case 4: return 1e20f;
    case 5: return -3e38f;
    case 6: return 1099511627776.0f; /* 2^40: the huge-gradient threshold */
    case 7: return 1.1e12f;
    case 8: return 1e-38f;
    default: return rng_range(-10, 10);
    }
}

/* ---- kernels under test --------------------------------------------------- */

enum kid { K_NOISE3, K_NOISE3_GRAD, K_FRACTAL3, K_FRACTAL3_GRAD, K_FRACTAL3_CENTRAL, K_PERTURB,
           K_PERTURB_HEIGHT, K_COUNT };
static const char *const kname[K_COUNT] = {"noise3", "noise3_grad", "fractal3", "fractal3_grad",
                                           "fractal3_grad_central", "perturb", "perturb_height"};
static const int n_in[K_COUNT] = {3, 3, 3, 3, 3, 6, 6};
static const int n_out[K_COUNT] = {1, 4, 1, 4, 4, 3, 4};

typedef struct params {
    bg_fractal f;
    float h;
    bg_perturb_method m;
    bg_height hg;
    int null_first; /* pass NULL for the optional first output (value / height) */
} params;

static void call(const bg_kernel_table *t, enum kid k, const params *p, float *const *in, size_t n,
                 float *const *out)
{
    float *o0 = p->null_first ? NULL : out[0];
    switch (k) {
    case K_NOISE3: t->noise3(in[0], in[1], in[2], n, out[0]); break;
    case K_NOISE3_GRAD: t->noise3_grad(in[0], in[1], in[2], n, o0, out[1], out[2], out[3]); break;
    case K_FRACTAL3: t->fractal3(&p->f, in[0], in[1], in[2], n, out[0]); break;
    case K_FRACTAL3_GRAD:
        t->fractal3_grad(&p->f, in[0], in[1], in[2], n, o0, out[1], out[2], out[3]);
        break;
    case K_FRACTAL3_CENTRAL:
        t->fractal3_grad_central(&p->f, p->h, in[0], in[1], in[2], n, o0, out[1], out[2], out[3]);
        break;
    case K_PERTURB:
        t->perturb(p->m, in[0], in[1], in[2], in[3], in[4], in[5], n, out[0], out[1], out[2]);
        break;
    case K_PERTURB_HEIGHT:
        t->perturb_height(&p->hg, p->m, in[0], in[1], in[2], in[3], in[4], in[5], n, o0, out[1],
                          out[2], out[3]);
        break;
    default: break;
    }
}

/* ---- buffers with canaries ------------------------------------------------ */

static const uint32_t canary_bits = 0x7FA5A5A5u; /* a NaN no kernel produces */

static float canary(void)
{
    float f;
    memcpy(&f, &canary_bits, sizeof f);
    return f;
}
static int is_canary(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u == canary_bits;
}

typedef struct outbuf {
    float *base; /* GUARD + off + n + GUARD floats */
    float *data;
    size_t n, off;
} outbuf;

static void outbuf_init(outbuf *b, size_t n, size_t off)
{
    size_t total = GUARD + off + n + GUARD;
    b->base = malloc(total * sizeof(float));
    if (!b->base) {
        fprintf(stderr, "out of memory\n");
        exit(2);
    }
    for (size_t i = 0; i < total; i++)
        b->base[i] = canary();
    b->data = b->base + GUARD + off;
    b->n = n;
    b->off = off;
}

static int outbuf_guards_ok(const outbuf *b)
{
    for (size_t i = 0; i < GUARD + b->off; i++)
        if (!is_canary(b->base[i]))
            return 0;
    for (size_t i = 0; i < GUARD; i++)
        if (!is_canary(b->data[b->n + i]))
            return 0;
    return 1;
}

static int same_bits(float a, float b)
{
    uint32_t ua, ub;
    memcpy(&ua, &a, sizeof ua);
    memcpy(&ub, &b, sizeof ub);
    return ua == ub;
}

static void fail(const char *what)
{
    failures++;
    if (failures <= 30)
        fprintf(stderr, "FAIL: %s\n", what);
}

/* Inputs for one run: `n` values at offset `off` in arrays of exactly off + n floats. */
typedef struct inset {
    float *base[MAX_IN];
    float *p[MAX_IN];
} inset;

static void make_inputs(inset *s, enum kid k, size_t n, size_t off)
{
    for (int a = 0; a < n_in[k]; a++) {
        s->base[a] = malloc((off + n + 1) * sizeof(float)); /* +1: malloc(0) */
        if (!s->base[a])
            exit(2);
        s->p[a] = s->base[a] + off;
        for (size_t i = 0; i < off; i++)
            s->base[a][i] = canary();
    }
    for (size_t i = 0; i < n; i++) {
        if (k == K_PERTURB) {
            for (int a = 0; a < 3; a++)
                s->p[a][i] = normal_comp();
            for (int a = 3; a < 6; a++)
                s->p[a][i] = grad_comp();
        } else if (k == K_PERTURB_HEIGHT) {
            for (int a = 0; a < 3; a++)
                s->p[a][i] = coord();
            for (int a = 3; a < 6; a++)
                s->p[a][i] = normal_comp();
        } else {
            for (int a = 0; a < 3; a++)
                s->p[a][i] = coord();
        }
        /* Some points entirely on the lattice or at +-0: the noise is exactly +-0
         * there, so the sign of zero (floor(-0) = -0, ...) reaches the output. */
        if (k != K_PERTURB && rng_u64() % 8 == 0)
            for (int a = 0; a < 3; a++) {
                uint64_t r = rng_u64();
                s->p[a][i] = r % 4 == 0 ? -0.0f : r % 4 == 1 ? 0.0f : (float)((int)(r % 9) - 4);
            }
    }
}

static void free_inputs(inset *s, enum kid k)
{
    for (int a = 0; a < n_in[k]; a++)
        free(s->base[a]);
}

/* One kernel, one parameter set, one length and offset: scalar vs every ISA. */
static void check_case(const bg_kernel_table *const *isas, int nisa, enum kid k, const params *p,
                       const char *pdesc, size_t n, size_t off)
{
    inset in;
    make_inputs(&in, k, n, off);
    size_t ooff = (off + 1) & 3; /* outputs misaligned differently from inputs */
    outbuf ref[MAX_OUT];
    float *ro[MAX_OUT];
    for (int o = 0; o < n_out[k]; o++) {
        outbuf_init(&ref[o], n, ooff);
        ro[o] = ref[o].data;
    }
    call(&bg_kernels_c, k, p, in.p, n, ro);
    char msg[512];
    for (int o = 0; o < n_out[k]; o++)
        if (!outbuf_guards_ok(&ref[o])) {
            snprintf(msg, sizeof msg, "%s scalar [%s] n=%zu off=%zu: output %d guard overwritten",
                     kname[k], pdesc, n, off, o);
            fail(msg);
        }
    for (int s = 0; s < nisa; s++) {
        outbuf got[MAX_OUT];
        float *go[MAX_OUT];
        for (int o = 0; o < n_out[k]; o++) {
            outbuf_init(&got[o], n, ooff);
            go[o] = got[o].data;
        }
        call(isas[s], k, p, in.p, n, go);
        checks++;
        for (int o = 0; o < n_out[k]; o++) {
            if (!outbuf_guards_ok(&got[o])) {
                snprintf(msg, sizeof msg, "%s %s [%s] n=%zu off=%zu: output %d guard overwritten",
                         kname[k], isas[s]->name, pdesc, n, off, o);
                fail(msg);
            }
            if (o == 0 && p->null_first)
                continue;
            for (size_t i = 0; i < n; i++)
                if (!same_bits(go[o][i], ro[o][i])) {
                    snprintf(msg, sizeof msg,
                             "%s %s [%s] n=%zu off=%zu: output %d [%zu] = %a, scalar %a "
                             "(inputs %a %a %a %a %a %a)",
                             kname[k], isas[s]->name, pdesc, n, off, o, i,
                             (double)go[o][i], (double)ro[o][i], (double)in.p[0][i],
                             (double)in.p[1][i], (double)in.p[2][i],
                             n_in[k] > 3 ? (double)in.p[3][i] : 0.0,
                             n_in[k] > 3 ? (double)in.p[4][i] : 0.0,
                             n_in[k] > 3 ? (double)in.p[5][i] : 0.0);
                    fail(msg);
                    break;
                }
        }
        for (int o = 0; o < n_out[k]; o++)
            free(got[o].base);
    }
    /* The kernels must not write their inputs either. */
    for (int a = 0; a < n_in[k]; a++)
        for (size_t i = 0; i < off; i++)
            if (!is_canary(in.base[a][i]))
                fail("input padding modified");
    for (int o = 0; o < n_out[k]; o++)
        free(ref[o].base);
    free_inputs(&in, k);
}

/* ---- parameter sets --------------------------------------------------------- */

static const bg_fractal fractals[] = {
    {BG_FUNC_NOISE, 1, 2.0f, 0.5f},        {BG_FUNC_FBM, 1, 2.0f, 0.5f},
    {BG_FUNC_FBM, 3, 2.0f, 0.5f},          {BG_FUNC_FBM, 6, 2.0f, 0.5f},
    {BG_FUNC_TURBULENCE, 6, 2.0f, 0.5f},   {BG_FUNC_TURBULENCE, 8, 1.9f, 0.6f},
    {BG_FUNC_FBM, 32, 2.5f, 0.45f},        {BG_FUNC_TURBULENCE, 4, 0.5f, 2.0f},
    {BG_FUNC_FBM, 5, 1.0f, -0.7f},
};
#define N_FRACTALS (int)(sizeof fractals / sizeof fractals[0])

static void describe(char *buf, size_t sz, const params *p, enum kid k)
{
    if (k == K_PERTURB)
        snprintf(buf, sz, "method %d", (int)p->m);
    else if (k == K_PERTURB_HEIGHT)
        snprintf(buf, sz, "method %d grad %d func %d oct %d lac %g gain %g amp %g freq %g step %g%s",
                 (int)p->m, (int)p->hg.gradient, (int)p->hg.fractal.function,
                 p->hg.fractal.octaves, (double)p->hg.fractal.lacunarity,
                 (double)p->hg.fractal.gain, (double)p->hg.amplitude, (double)p->hg.frequency,
                 (double)p->hg.step, p->null_first ? " height=NULL" : "");
    else
        snprintf(buf, sz, "func %d oct %d lac %g gain %g h %g%s", (int)p->f.function,
                 p->f.octaves, (double)p->f.lacunarity, (double)p->f.gain, (double)p->h,
                 p->null_first ? " value=NULL" : "");
}

static void check_kernel_all_sizes(const bg_kernel_table *const *isas, int nisa, enum kid k,
                                   const params *p, int long_runs)
{
    char d[256];
    describe(d, sizeof d, p, k);
    for (size_t n = 0; n <= MAX_TAIL; n++)
        check_case(isas, nisa, k, p, d, n, n & 3);
    for (int r = 0; r < long_runs; r++)
        for (size_t off = 0; off < 4; off++)
            check_case(isas, nisa, k, p, d, LONG_N, off);
}

static void check_isas(const bg_kernel_table *const *isas, int nisa)
{
    params p;
    memset(&p, 0, sizeof p);
    p.f = fractals[0];
    check_kernel_all_sizes(isas, nisa, K_NOISE3, &p, 8);
    check_kernel_all_sizes(isas, nisa, K_NOISE3_GRAD, &p, 8);
    p.null_first = 1;
    check_kernel_all_sizes(isas, nisa, K_NOISE3_GRAD, &p, 1);
    p.null_first = 0;
    for (int f = 0; f < N_FRACTALS; f++) {
        p.f = fractals[f];
        check_kernel_all_sizes(isas, nisa, K_FRACTAL3, &p, 1);
        check_kernel_all_sizes(isas, nisa, K_FRACTAL3_GRAD, &p, 1);
        p.h = f & 1 ? 1e-2f : BG_DEFAULT_CENTRAL_STEP;
        check_kernel_all_sizes(isas, nisa, K_FRACTAL3_CENTRAL, &p, 1);
    }
    p.f = fractals[3];
    p.null_first = 1;
    check_kernel_all_sizes(isas, nisa, K_FRACTAL3_GRAD, &p, 0);
    check_kernel_all_sizes(isas, nisa, K_FRACTAL3_CENTRAL, &p, 0);
    p.null_first = 0;
    for (int m = 0; m < 3; m++) {
        p.m = (bg_perturb_method)m;
        check_kernel_all_sizes(isas, nisa, K_PERTURB, &p, 8);
    }
    static const int hf[] = {0, 3, 4, 5, 7};
    for (int m = 0; m < 3; m++)
        for (int gmode = 0; gmode < 2; gmode++)
            for (int fi = 0; fi < (int)(sizeof hf / sizeof hf[0]); fi++) {
                p.m = (bg_perturb_method)m;
                p.hg.fractal = fractals[hf[fi]];
                p.hg.gradient = (bg_gradient_mode)gmode;
                p.hg.amplitude = fi & 1 ? 0.1f : -2.5f;
                p.hg.frequency = fi == 2 ? 3.7f : 1.0f;
                p.hg.step = fi == 3 ? 0.01f : 0.0f;
                p.null_first = fi == 4;
                check_kernel_all_sizes(isas, nisa, K_PERTURB_HEIGHT, &p, 1);
            }
    /* Huge amplitude: gradients beyond 2^40 and overflow to Inf reach perturb. */
    p.hg.fractal = fractals[4];
    p.hg.gradient = BG_GRADIENT_ANALYTIC;
    p.hg.amplitude = 3e37f;
    p.hg.frequency = 1.0f;
    p.null_first = 0;
    for (int m = 0; m < 3; m++) {
        p.m = (bg_perturb_method)m;
        check_kernel_all_sizes(isas, nisa, K_PERTURB_HEIGHT, &p, 1);
    }
}

/* ---- the scalar kernel against double references -------------------------- */

static double maxerr_v, maxerr_g, maxulp;

/* Distance of a float result from a double reference in units of the float
 * spacing at the reference, ulp(|want|) = 2^(e - 23) for |want| in [2^e, 2^e+1). */
static double ulps_of(double got, double want)
{
    int e;
    (void)frexp(want, &e);
    return fabs(got - want) / ldexp(1.0, e - 24);
}

/* Beside the absolute epsilon, a ULP bound where a relative measure means
 * something: |reference| >= 1/4. Near the noise's zeros (and for the small
 * gradient components that come from cancelling corner terms) any absolute
 * error is many ULP of a tiny value, and the absolute bound of noise.h is the
 * contract there. Measured maximum on these inputs: 149 ULP (fractal
 * gradients, sums of 6 octaves); the bound leaves a factor 3.4. Central
 * differences have no ULP bound (their error is the value's rounding over the
 * step). */
#define ULP_MIN 0.25
#define ULP_BOUND 512.0
static void check_close_u(const char *what, double got, double want, double eps, double ulp_bound,
                          double *track, const float *pt)
{
    double e = fabs(got - want);
    if (e > *track)
        *track = e;
    double u = ulp_bound > 0 && fabs(want) >= ULP_MIN ? ulps_of(got, want) : 0;
    if (u > maxulp)
        maxulp = u;
    if (!(e <= eps) || !(u <= ulp_bound || ulp_bound == 0)) {
        char msg[300];
        snprintf(msg, sizeof msg,
                 "%s: %.9g vs reference %.17g (eps %g; %.1f ulp, bound %g) at (%.9g, %.9g, %.9g)",
                 what, got, want, eps, u, ulp_bound, (double)pt[0], (double)pt[1], (double)pt[2]);
        fail(msg);
    }
}
#define check_close(what, got, want, eps, track, pt) \
    check_close_u(what, got, want, eps, ULP_BOUND, track, pt)

/* Smallest |octave| of a fractal at a point, from the double kernels: points near
 * a turbulence crease have a sign-dependent gradient, skip them. */
static double min_abs_octave(const bg_fractal *f, double x, double y, double z)
{
    double freq = 1, m = INFINITY;
    int oct = f->function == BG_FUNC_NOISE ? 1 : f->octaves;
    for (int i = 0; i < oct; i++) {
        double px = x * freq, py = y * freq, pz = z * freq, v, g[3];
        bg_kernels_c64.noise3_grad(&px, &py, &pz, 1, &v, &g[0], &g[1], &g[2]);
        if (fabs(v) < m)
            m = fabs(v);
        freq *= f->lacunarity;
    }
    return m;
}

static void check_scalar_vs_double(void)
{
    enum { N = 4000 };
    static float x[N], y[N], z[N], v[N], gx[N], gy[N], gz[N];
    for (int i = 0; i < N; i++) {
        double r = i % 4 == 0 ? 1e4 : 300; /* float spacing keeps fractions exact */
        x[i] = rng_range(-r, r), y[i] = rng_range(-r, r), z[i] = rng_range(-r, r);
    }
    /* noise.h: value error <= 1e-5, gradient <= 5e-5. */
    bg_kernels_c.noise3_grad(x, y, z, N, v, gx, gy, gz);
    maxerr_v = maxerr_g = 0;
    for (int i = 0; i < N; i++) {
        double px = x[i], py = y[i], pz = z[i], dv, dg[3];
        float pt[3] = {x[i], y[i], z[i]};
        bg_kernels_c64.noise3_grad(&px, &py, &pz, 1, &dv, &dg[0], &dg[1], &dg[2]);
        check_close("noise3_grad value vs c64", v[i], dv, 1e-5, &maxerr_v, pt);
        check_close("noise3_grad dx vs c64", gx[i], dg[0], 5e-5, &maxerr_g, pt);
        check_close("noise3_grad dy vs c64", gy[i], dg[1], 5e-5, &maxerr_g, pt);
        check_close("noise3_grad dz vs c64", gz[i], dg[2], 5e-5, &maxerr_g, pt);
#ifdef BG_HAVE_REF
        double rg[3], rv = ref_noise_grad(px, py, pz, rg);
        check_close("noise3_grad value vs ref", v[i], rv, 1e-5, &maxerr_v, pt);
        check_close("noise3_grad dx vs ref", gx[i], rg[0], 5e-5, &maxerr_g, pt);
        check_close("noise3_grad dy vs ref", gy[i], rg[1], 5e-5, &maxerr_g, pt);
        check_close("noise3_grad dz vs ref", gz[i], rg[2], 5e-5, &maxerr_g, pt);
#endif
    }
    printf("scalar noise3_grad vs double: max |value err| %.3g, max |grad err| %.3g\n", maxerr_v,
           maxerr_g);

    /* Fractals: lacunarity 2 keeps the float octave coordinates exact for these
     * ranges, so the error is the per-octave noise error times sum gain^i (value)
     * or sum gain^i lac^i (gradient). */
    static const bg_fractal ff[] = {{BG_FUNC_FBM, 6, 2.0f, 0.5f},
                                    {BG_FUNC_TURBULENCE, 6, 2.0f, 0.5f},
                                    {BG_FUNC_FBM, 3, 2.0f, 0.75f}};
    for (int fi = 0; fi < 3; fi++) {
        const bg_fractal *f = &ff[fi];
        double sa = 0, saf = 0, a = 1, q = 1;
        for (int o = 0; o < f->octaves; o++, a *= f->gain, q *= f->lacunarity)
            sa += a, saf += a * q;
        for (int i = 0; i < N; i++) {
            double r = 100;
            x[i] = rng_range(-r, r), y[i] = rng_range(-r, r), z[i] = rng_range(-r, r);
        }
        bg_kernels_c.fractal3_grad(f, x, y, z, N, v, gx, gy, gz);
        maxerr_v = maxerr_g = 0;
        for (int i = 0; i < N; i++) {
            double px = x[i], py = y[i], pz = z[i], dv, dg[3];
            float pt[3] = {x[i], y[i], z[i]};
            if (f->function == BG_FUNC_TURBULENCE && min_abs_octave(f, px, py, pz) < 1e-4)
                continue;
            bg_kernels_c64.fractal3_grad(f, &px, &py, &pz, 1, &dv, &dg[0], &dg[1], &dg[2]);
            check_close("fractal3_grad value vs c64", v[i], dv, 1e-5 * sa, &maxerr_v, pt);
            for (int c = 0; c < 3; c++)
                check_close("fractal3_grad gradient vs c64", (c == 0 ? gx : c == 1 ? gy : gz)[i],
                            dg[c], 5e-5 * saf, &maxerr_g, pt);
#ifdef BG_HAVE_REF
            ref_fractal rf = {(enum ref_function)f->function, f->octaves, f->lacunarity, f->gain};
            double rg[3], rv = ref_fractal_grad(&rf, px, py, pz, rg, NULL);
            check_close("fractal3_grad value vs ref", v[i], rv, 1e-5 * sa, &maxerr_v, pt);
            for (int c = 0; c < 3; c++)
                check_close("fractal3_grad gradient vs ref", (c == 0 ? gx : c == 1 ? gy : gz)[i],
                            rg[c], 5e-5 * saf, &maxerr_g, pt);
#endif
        }
        printf("scalar fractal3_grad (func %d, %d octaves) vs double: max |value err| %.3g, max "
               "|grad err| %.3g\n",
               (int)f->function, f->octaves, maxerr_v, maxerr_g);
        /* The value-only kernel gives the same bits as the gradient kernel's value. */
        static float v2[N];
        bg_kernels_c.fractal3(f, x, y, z, N, v2);
        for (int i = 0; i < N; i++)
            if (!same_bits(v[i], v2[i])) {
                fail("fractal3 value differs from fractal3_grad value");
                break;
            }
    }

    /* Central differences: the same step in double; the float error is the value
     * rounding divided by the step, about 1e-7 / 4e-3 per unit of amp * freq. */
    {
        bg_fractal f = {BG_FUNC_FBM, 3, 2.0f, 0.5f};
        float h = 2e-3f; /* explicit: the bound below is for this step */
        for (int i = 0; i < N; i++)
            x[i] = rng_range(-20, 20), y[i] = rng_range(-20, 20), z[i] = rng_range(-20, 20);
        bg_kernels_c.fractal3_grad_central(&f, h, x, y, z, N, v, gx, gy, gz);
        maxerr_v = maxerr_g = 0;
        for (int i = 0; i < N; i++) {
            double px = x[i], py = y[i], pz = z[i], dv, dg[3];
            float pt[3] = {x[i], y[i], z[i]};
            bg_kernels_c64.fractal3_grad_central(&f, h, &px, &py, &pz, 1, &dv, &dg[0], &dg[1],
                                                 &dg[2]);
            check_close("fractal3_grad_central value vs c64", v[i], dv, 2e-5, &maxerr_v, pt);
            /* No ULP bound: a difference quotient's error is the value's
             * rounding over the step, not a few ULP of the quotient. */
            for (int c = 0; c < 3; c++)
                check_close_u("fractal3_grad_central gradient vs c64",
                              (c == 0 ? gx : c == 1 ? gy : gz)[i], dg[c], 2e-3, 0, &maxerr_g, pt);
        }
        printf("scalar fractal3_grad_central (fbm 3) vs double: max |value err| %.3g, max |grad "
               "err| %.3g\n",
               maxerr_v, maxerr_g);
    }

    /* Perturbation: unit normals, moderate gradients. */
    static float nx[N], ny[N], nz[N], ox[N], oy[N], oz[N];
    for (int i = 0; i < N; i++) {
        nx[i] = rng_range(-1, 1), ny[i] = rng_range(-1, 1), nz[i] = rng_range(-1, 1);
        if (fabsf(nx[i]) + fabsf(ny[i]) + fabsf(nz[i]) < 0.1f)
            nz[i] = 1;
        gx[i] = rng_range(-5, 5), gy[i] = rng_range(-5, 5), gz[i] = rng_range(-5, 5);
    }
    for (int m = 0; m < 3; m++) {
        bg_kernels_c.perturb((bg_perturb_method)m, nx, ny, nz, gx, gy, gz, N, ox, oy, oz);
        maxerr_v = 0;
        for (int i = 0; i < N; i++) {
            double dn[3] = {nx[i], ny[i], nz[i]}, dg[3] = {gx[i], gy[i], gz[i]}, dout[3];
            float pt[3] = {nx[i], ny[i], nz[i]};
            bg_kernels_c64.perturb((bg_perturb_method)m, &dn[0], &dn[1], &dn[2], &dg[0], &dg[1],
                                   &dg[2], 1, &dout[0], &dout[1], &dout[2]);
            check_close("perturb vs c64", ox[i], dout[0], 2e-6, &maxerr_v, pt);
            check_close("perturb vs c64", oy[i], dout[1], 2e-6, &maxerr_v, pt);
            check_close("perturb vs c64", oz[i], dout[2], 2e-6, &maxerr_v, pt);
#ifdef BG_HAVE_REF
            double rout[3];
            if (m == BG_PERTURB_SURFGRAD) {
                ref_perturb_surfgrad(dn, dg, rout);
            } else {
                double sg[3] = {dg[0], dg[1], dg[2]};
                if (m == BG_PERTURB_ADDITIVE_PERLIN)
                    sg[0] = -sg[0], sg[1] = -sg[1], sg[2] = -sg[2];
                ref_perturb_additive(dn, sg, rout);
            }
            check_close("perturb vs ref", ox[i], rout[0], 2e-6, &maxerr_v, pt);
            check_close("perturb vs ref", oy[i], rout[1], 2e-6, &maxerr_v, pt);
            check_close("perturb vs ref", oz[i], rout[2], 2e-6, &maxerr_v, pt);
#endif
        }
        printf("scalar perturb method %d vs double: max |err| %.3g\n", m, maxerr_v);
    }

    printf("max ULP error of the scalar kernels vs double (|reference| >= %g): %.1f (bound %g)\n",
           ULP_MIN, maxulp, ULP_BOUND);

    /* The fused kernel is exactly fractal3_grad at frequency * p, scaled by
     * amplitude * frequency, then perturb (bit for bit, scalar). */
    static float px[N], py[N], pz[N], hh[N], fx[N], fy[N], fz[N], hv[N];
    for (int i = 0; i < N; i++) {
        px[i] = rng_range(-50, 50), py[i] = rng_range(-50, 50), pz[i] = rng_range(-50, 50);
    }
    for (int m = 0; m < 3; m++) {
        bg_height hg = {{BG_FUNC_TURBULENCE, 6, 2.0f, 0.5f}, 0.1f, 1.7f, BG_GRADIENT_ANALYTIC, 0};
        bg_kernels_c.perturb_height(&hg, (bg_perturb_method)m, px, py, pz, nx, ny, nz, N, hh, ox,
                                    oy, oz);
        for (int i = 0; i < N; i++)
            fx[i] = px[i] * hg.frequency, fy[i] = py[i] * hg.frequency, fz[i] = pz[i] * hg.frequency;
        bg_kernels_c.fractal3_grad(&hg.fractal, fx, fy, fz, N, hv, gx, gy, gz);
        float af = hg.amplitude * hg.frequency;
        for (int i = 0; i < N; i++)
            gx[i] *= af, gy[i] *= af, gz[i] *= af, hv[i] *= hg.amplitude;
        bg_kernels_c.perturb((bg_perturb_method)m, nx, ny, nz, gx, gy, gz, N, fx, fy, fz);
        for (int i = 0; i < N; i++)
            if (!same_bits(hh[i], hv[i]) || !same_bits(ox[i], fx[i]) || !same_bits(oy[i], fy[i]) ||
                !same_bits(oz[i], fz[i])) {
                fail("perturb_height differs from fractal3_grad + perturb");
                break;
            }
    }
}

/* Perlin's Java reference on the integer cube [0,64)^3, bit for bit including
 * the sign of zero: every fraction is 0 there, so the value is a chain of exact
 * +-0 and the sign decides (issue 13: corner hash 11 gives -y - z = -0 at
 * (0, 2, 22), and the old table-dot-product corner gave +0). tests/ref's
 * ref_noise follows the Java code literally (u/v selects, -u negation, the
 * same lerp nesting). The float kernel computes the same exact zeros, so it
 * must give the same bits too. NaN inputs must come out as the canonical NaN. */
static void check_lattice_reference(void)
{
#ifdef BG_HAVE_REF
    long bad_d = 0, bad_f = 0, negzero = 0;
    for (int i = 0; i < 64; i++)
        for (int j = 0; j < 64; j++)
            for (int k = 0; k < 64; k++) {
                double x = i, y = j, z = k, v, g[3];
                bg_kernels_c64.noise3_grad(&x, &y, &z, 1, &v, &g[0], &g[1], &g[2]);
                double r = ref_noise(x, y, z);
                uint64_t uv, ur;
                memcpy(&uv, &v, sizeof uv);
                memcpy(&ur, &r, sizeof ur);
                negzero += r == 0 && signbit(r);
                if (uv != ur && bad_d++ < 5) {
                    char msg[200];
                    snprintf(msg, sizeof msg, "double noise at (%d,%d,%d) = %a, Java reference %a",
                             i, j, k, v, r);
                    fail(msg);
                }
                float fx = (float)i, fy = (float)j, fz = (float)k, fv;
                bg_kernels_c.noise3(&fx, &fy, &fz, 1, &fv);
                if (!same_bits(fv, (float)r) && bad_f++ < 5) {
                    char msg[200];
                    snprintf(msg, sizeof msg, "float noise at (%d,%d,%d) = %a, Java reference %a",
                             i, j, k, (double)fv, r);
                    fail(msg);
                }
            }
    printf("integer cube [0,64)^3 vs the Java reference: %ld double and %ld float sign/bit "
           "mismatches (%ld reference -0)\n",
           bad_d, bad_f, negzero);
    if (negzero == 0)
        fail("no -0 on the integer cube: the reference check tests nothing");
#endif
    /* The canonical NaN, from the scalar float and double kernels. */
    static const uint32_t qnan = 0x7fc00000u;
    float nx = NAN, ny = 0.5f, nz = -INFINITY, nv, g3[3];
    bg_kernels_c.noise3_grad(&nx, &ny, &nz, 1, &nv, &g3[0], &g3[1], &g3[2]);
    uint32_t un;
    memcpy(&un, &nv, sizeof un);
    if (un != qnan)
        fail("scalar NaN result is not the canonical quiet NaN");
    nz = -NAN;
    bg_kernels_c.noise3(&nz, &ny, &ny, 1, &nv);
    memcpy(&un, &nv, sizeof un);
    if (un != qnan)
        fail("scalar noise3(-NaN) is not the canonical quiet NaN");
    double dx = INFINITY, dy = 0.25, dv, dg[3];
    bg_kernels_c64.noise3_grad(&dx, &dy, &dy, 1, &dv, &dg[0], &dg[1], &dg[2]);
    uint64_t ud;
    memcpy(&ud, &dv, sizeof ud);
    if (ud != 0x7ff8000000000000ull)
        fail("double NaN result is not the canonical quiet NaN");
}

/* The per-point functions (noise.h's bg_noise3, bg_fractal3, ...) against the
 * scalar table with n = 1, bit for bit, on the special-laden coordinates. */
static void check_point_functions(void)
{
    static const bg_fractal pf[] = {{BG_FUNC_NOISE, 1, 2.0f, 0.5f},
                                    {BG_FUNC_FBM, 6, 2.0f, 0.5f},
                                    {BG_FUNC_TURBULENCE, 5, 1.9f, 0.6f}};
    long bad = 0;
    for (int i = 0; i < 20000; i++) {
        float x = coord(), y = coord(), z = coord(), v, g[3], pg[3];
        const bg_fractal *f = &pf[i % 3];
        bg_kernels_c.noise3(&x, &y, &z, 1, &v);
        bad += !same_bits(v, bg_noise3_point_c(x, y, z));
        bg_kernels_c.noise3_grad(&x, &y, &z, 1, &v, &g[0], &g[1], &g[2]);
        float pv = bg_noise3_grad_point_c(x, y, z, pg);
        bad += !same_bits(v, pv) || !same_bits(g[0], pg[0]) || !same_bits(g[1], pg[1]) ||
               !same_bits(g[2], pg[2]);
        bg_kernels_c.fractal3(f, &x, &y, &z, 1, &v);
        bad += !same_bits(v, bg_fractal3_point_c(f, x, y, z));
        bg_kernels_c.fractal3_grad(f, &x, &y, &z, 1, &v, &g[0], &g[1], &g[2]);
        pv = bg_fractal3_grad_point_c(f, x, y, z, pg);
        bad += !same_bits(v, pv) || !same_bits(g[0], pg[0]) || !same_bits(g[1], pg[1]) ||
               !same_bits(g[2], pg[2]);
    }
    checks += 4;
    if (bad)
        fail("a per-point function differs from the scalar kernel with n = 1");
}

/* The lookup tables the kernels use, against each other and the reference. */
static void check_tables(void)
{
    for (int i = 0; i < 512; i++) {
        int p = bg_perm512[i];
        if (p != bg_perm512[i & 255] || p != bg_perm256_u8[i & 255])
            fail("bg_perm512 / bg_perm256_u8 disagree");
#ifdef BG_HAVE_REF
        if (p != ref_permutation(i))
            fail("bg_perm512 differs from Perlin's permutation (tests/ref)");
#endif
        if (i < 256 && bg_perm_pair[i] != (p | bg_perm512[i + 1] << 8))
            fail("bg_perm_pair[i] != p[i] | p[i + 1] << 8");
    }
}

/* ---- benchmark ------------------------------------------------------------ */

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The benchmarked cases (also what --run executes). */
static const struct bench_case {
    enum kid k;
    const char *label;
    params p;
} cases[] = {
    {K_NOISE3, "noise3", {.f = {BG_FUNC_NOISE, 1, 2, .5f}}},
    {K_NOISE3_GRAD, "noise3_grad", {.f = {BG_FUNC_NOISE, 1, 2, .5f}}},
    {K_FRACTAL3, "fractal3 turb6", {.f = {BG_FUNC_TURBULENCE, 6, 2, .5f}}},
    {K_FRACTAL3_GRAD, "fractal3_grad turb6", {.f = {BG_FUNC_TURBULENCE, 6, 2, .5f}}},
    {K_FRACTAL3_CENTRAL, "fractal3_grad_central turb6",
     {.f = {BG_FUNC_TURBULENCE, 6, 2, .5f}, .h = 2e-3f}},
    {K_PERTURB, "perturb surfgrad", {.m = BG_PERTURB_SURFGRAD}},
    {K_PERTURB_HEIGHT, "perturb_height turb6 analytic",
     {.m = BG_PERTURB_SURFGRAD,
      .hg = {{BG_FUNC_TURBULENCE, 6, 2, .5f}, 0.1f, 1, BG_GRADIENT_ANALYTIC, 0}}},
};

/* ns per sample of one kernel on one ISA: the batch length is grown until a call
 * takes about 50 us (short calls are rarely preempted on a busy machine), then
 * `reps` calls are timed; *best gets the fastest (the least disturbed, the
 * usual estimate of the unloaded speed), the return value the median. */
static double bench_one(const bg_kernel_table *t, enum kid k, const params *p, float *const *in,
                        size_t nmax, float *const *out, int reps, double *best)
{
    double ts[128];
    size_t n = 16;
    for (;;) {
        double t0 = now_s();
        call(t, k, p, in, n, out);
        if (now_s() - t0 > 50e-6 || n * 2 > nmax)
            break;
        n *= 2;
    }
    for (int r = 0; r < reps; r++) {
        double t0 = now_s();
        call(t, k, p, in, n, out);
        ts[r] = (now_s() - t0) * 1e9 / (double)n;
    }
    qsort(ts, (size_t)reps, sizeof ts[0], cmp_double);
    *best = ts[0];
    return ts[reps / 2];
}

enum { BN = 8192 };

/* Points in [-100, 100], unit-ish normals: the inputs of --bench and --run. */
static void bench_inputs(float **in, float **out)
{
    static float buf[MAX_IN + MAX_OUT][BN];
    for (int a = 0; a < MAX_IN; a++)
        in[a] = buf[a];
    for (int o = 0; o < MAX_OUT; o++)
        out[o] = buf[MAX_IN + o];
    for (size_t i = 0; i < BN; i++) {
        for (int a = 0; a < 3; a++)
            in[a][i] = rng_range(-100, 100);
        double l;
        do {
            in[3][i] = rng_range(-1, 1), in[4][i] = rng_range(-1, 1), in[5][i] = rng_range(-1, 1);
            l = sqrt((double)in[3][i] * in[3][i] + (double)in[4][i] * in[4][i] +
                     (double)in[5][i] * in[5][i]);
        } while (l < 0.1);
    }
}

/* kin[] for case c: perturb takes the normals first. */
static void case_inputs(enum kid k, float *const *in, float **kin)
{
    if (k == K_PERTURB) {
        kin[0] = in[3], kin[1] = in[4], kin[2] = in[5];
        kin[3] = in[0], kin[4] = in[1], kin[5] = in[2];
    } else {
        for (int a = 0; a < MAX_IN; a++)
            kin[a] = in[a];
    }
}

/* --run=<isa>:<case>:<n>: one call, nothing else, for instruction counts
 * (valgrind --tool=callgrind; subtract the n=0 run). */
static int run_once(const char *spec)
{
    char name[32];
    int ci, n;
    if (sscanf(spec, "%31[^:]:%d:%d", name, &ci, &n) != 3 || ci < 0 ||
        ci >= (int)(sizeof cases / sizeof cases[0]) || n < 0 || n > BN)
        return 2;
    const bg_kernel_table *t = NULL, *all[8];
    if (strcmp(name, "c") == 0 || strcmp(name, "scalar") == 0)
        t = &bg_kernels_c;
    for (int i = 1; i < BG_ISA_COUNT && !t; i++) {
        int m = bg_kernels_variants((bg_isa)i, all, 8);
        for (int j = 0; j < m; j++)
            if (strcmp(all[j]->name, name) == 0)
                t = all[j];
    }
    if (!t)
        return 2;
    float *in[MAX_IN], *out[MAX_OUT], *kin[MAX_IN];
    bench_inputs(in, out);
    case_inputs(cases[ci].k, in, kin);
    call(t, cases[ci].k, &cases[ci].p, kin, (size_t)n, out);
    return 0;
}

static int bench(const bg_kernel_table *const *isas, int nisa, const char *only)
{
    float *in[MAX_IN], *out[MAX_OUT];
    bench_inputs(in, out);
    printf("%-30s %-11s %9s %9s %9s %9s\n", "kernel", "isa", "ns best", "ns median", "M/s best",
           "x scalar");
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        if (only && !strstr(cases[c].label, only))
            continue;
        enum kid k = cases[c].k;
        float *kin[MAX_IN];
        case_inputs(k, in, kin);
        double base, base_med = bench_one(&bg_kernels_c, k, &cases[c].p, kin, BN, out, 41, &base);
        printf("%-30s %-11s %9.3f %9.3f %9.1f %9.2f\n", cases[c].label, "scalar", base, base_med,
               1e3 / base, 1.0);
        for (int s = 0; s < nisa; s++) {
            double ns, med = bench_one(isas[s], k, &cases[c].p, kin, BN, out, 101, &ns);
            printf("%-30s %-11s %9.3f %9.3f %9.1f %9.2f\n", cases[c].label, isas[s]->name, ns, med,
                   1e3 / ns, base / ns);
        }
    }
    return 0;
}

int main(int argc, char **argv)
{
    const bg_kernel_table *isas[BG_ISA_COUNT + 4];
    int nisa = 0;
    /* Every ISA and every variant of it (AVX-512 with and without VBMI). */
    for (int i = BG_ISA_SCALAR + 1; i < BG_ISA_COUNT; i++)
        nisa += bg_kernels_variants((bg_isa)i, isas + nisa, BG_ISA_COUNT + 4 - nisa);
    int do_bench = 0;
    const char *only = NULL;
    for (int a = 1; a < argc; a++) {
        if (strcmp(argv[a], "--bench") == 0)
            do_bench = 1;
        else if (strncmp(argv[a], "--only=", 7) == 0)
            only = argv[a] + 7;
        else if (strncmp(argv[a], "--run=", 6) == 0)
            return run_once(argv[a] + 6);
    }
    printf("ISAs under test:");
    for (int s = 0; s < nisa; s++)
        printf(" %s", isas[s]->name);
    printf(" (best %s)\n", bg_isa_name(bg_isa_best()));
    if (do_bench)
        return bench(isas, nisa, only);

#ifdef BG_HAVE_REF
    printf("double references: tests/ref (ref_*) and bg_kernels_c64\n");
#else
    printf("double reference: bg_kernels_c64 only (tests/ref not configured)\n");
#endif
    check_tables();
    check_lattice_reference();
    check_point_functions();
    check_scalar_vs_double();
    check_isas(isas, nisa);
    printf("%ld ISA-vs-scalar comparisons, %d failures\n", checks, failures);
    return failures ? 1 : 0;
}
