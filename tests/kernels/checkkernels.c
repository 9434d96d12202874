/* SPDX-License-Identifier: MIT */
/* Kernel harness in the spirit of dav1d's checkasm: every kernel of
 * bg_kernel_table on every ISA this build and CPU have, on the same seeded inputs,
 * compared bit for bit against the scalar kernel (bg_kernels_c); the scalar kernel
 * itself compared against a double reference with an absolute epsilon (tests/ref
 * when built, and always the library's double kernels bg_kernels_c64).
 *
 * This file is the harness (checkkernels.h); the kernel families are in
 * check_noise.c, check_fractal.c and check_perturb.c.
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

#include "checkkernels.h"
#include "../common/timing.h"

int failures;
long checks;

/* ---- deterministic inputs ------------------------------------------------ */

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
void rng_seed(uint64_t seed) { rng_state = seed; }
uint64_t rng_u64(void)
{
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
double rng_unit(void) { return (double)(rng_u64() >> 11) * (1.0 / 9007199254740992.0); }
float rng_range(double lo, double hi) { return (float)(lo + (hi - lo) * rng_unit()); }

/* A coordinate: mostly ordinary values, with every special class mixed in. */
float coord(void)
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

float normal_comp(void)
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

float grad_comp(void)
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

const char *const kname[K_COUNT] = {"noise3", "noise3_grad", "fractal3", "fractal3_grad",
                                    "fractal3_grad_central", "perturb", "perturb_height"};
const int n_in[K_COUNT] = {3, 3, 3, 3, 3, 6, 6};
const int n_out[K_COUNT] = {1, 4, 1, 4, 4, 3, 4};

void call_new(const bg_kernel_table *t, enum kid k, const params *p, float *const *in, size_t n,
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

void call_ref(enum kid k, const params *p, float *const *in, size_t n, float *const *out)
{
    call_new(&bg_kernels_c, k, p, in, n, out);
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

int same_bits(float a, float b)
{
    uint32_t ua, ub;
    memcpy(&ua, &a, sizeof ua);
    memcpy(&ub, &b, sizeof ub);
    return ua == ub;
}

void fail(const char *what)
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
    call_ref(k, p, in.p, n, ro);
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
        call_new(isas[s], k, p, in.p, n, go);
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

const bg_fractal fractals[] = {
    {BG_FUNC_NOISE, 1, 2.0f, 0.5f},        {BG_FUNC_FBM, 1, 2.0f, 0.5f},
    {BG_FUNC_FBM, 3, 2.0f, 0.5f},          {BG_FUNC_FBM, 6, 2.0f, 0.5f},
    {BG_FUNC_TURBULENCE, 6, 2.0f, 0.5f},   {BG_FUNC_TURBULENCE, 8, 1.9f, 0.6f},
    {BG_FUNC_FBM, 32, 2.5f, 0.45f},        {BG_FUNC_TURBULENCE, 4, 0.5f, 2.0f},
    {BG_FUNC_FBM, 5, 1.0f, -0.7f},
};
const int n_fractals = (int)(sizeof fractals / sizeof fractals[0]);

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

void check_kernel(const bg_kernel_table *const *isas, int nisa, enum kid k, const params *p,
                  int long_runs)
{
    char d[256];
    describe(d, sizeof d, p, k);
    for (size_t n = 0; n <= MAX_TAIL; n++)
        check_case(isas, nisa, k, p, d, n, n & 3);
    for (int r = 0; r < long_runs; r++)
        for (size_t off = 0; off < 4; off++)
            check_case(isas, nisa, k, p, d, LONG_N, off);
}

/* ---- the scalar kernel against double references -------------------------- */

double maxerr_v, maxerr_g, maxulp;

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
void check_close_u(const char *what, double got, double want, double eps, double ulp_bound,
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

/* ---- benchmark ------------------------------------------------------------ */

static double now_s(void) { return timing_clock_s(CLOCK_MONOTONIC); }

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
      .hg = {{BG_FUNC_TURBULENCE, 6, 2, .5f}, 0.1f, 1, BG_GRADIENT_ANALYTIC, 0, {{0, 0, 0}, 0}}}},
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
        call_new(t, k, p, in, n, out);
        if (now_s() - t0 > 50e-6 || n * 2 > nmax)
            break;
        n *= 2;
    }
    for (int r = 0; r < reps; r++) {
        double t0 = now_s();
        call_new(t, k, p, in, n, out);
        ts[r] = (now_s() - t0) * 1e9 / (double)n;
    }
    qsort(ts, (size_t)reps, sizeof ts[0], timing_cmp_double);
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
    call_new(t, cases[ci].k, &cases[ci].p, kin, (size_t)n, out);
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
    check_noise(isas, nisa);
    check_fractal(isas, nisa);
    check_perturb(isas, nisa);
    printf("max ULP error of the scalar kernels vs double (|reference| >= %g): %.1f (bound %g)\n",
           ULP_MIN, maxulp, ULP_BOUND);

    printf("%ld ISA-vs-scalar comparisons, %d failures\n", checks, failures);
    return failures ? 1 : 0;
}
