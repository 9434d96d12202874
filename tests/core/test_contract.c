/* SPDX-License-Identifier: MIT */
/* The API contract of noise.h and surfgrad.h (issue 13, items 7 and 8):
 *  - every batch call returns a bg_status; n = 0 reads nothing (NULL
 *    descriptors and arrays are BG_OK); a NULL required array, an invalid
 *    descriptor, enum or step is refused before any output is written (the
 *    outputs keep their guard values);
 *  - the single-point calls give NaN for an unknown method or an out-of-range
 *    height descriptor;
 *  - bg_fractal_validate / bg_height_validate refuse octave scaling that
 *    overflows float (BG_ERR_OVERFLOW), and what they accept stays finite;
 *  - bg_fractal_max_coordinate is the exact coordinate threshold of the
 *    kernels: finite results at the bound, NaN one float above it.
 * Public API only. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "bumpgrad.h"
#include "check.h"

enum { N = 37 }; /* odd: every ISA runs a tail */

static const float GUARD = -12345.5f;

static float in_x[N], in_y[N], in_z[N], in_n[3][N], in_g[3][N], in_fp[N];
static float out[4][N];
static double din[3][N], dout[4][N];

static void fill_inputs(void)
{
    for (int i = 0; i < N; i++) {
        in_x[i] = -3.7f + 0.61f * (float)i, in_y[i] = 1.3f - 0.27f * (float)i;
        in_z[i] = 0.11f * (float)(i * i) - 5.0f;
        in_n[0][i] = 0.1f * (float)(i % 5) - 0.2f, in_n[1][i] = 0.3f, in_n[2][i] = 1.0f;
        in_g[0][i] = 0.5f - 0.03f * (float)i, in_g[1][i] = 0.2f, in_g[2][i] = -0.4f;
        in_fp[i] = 0.01f * (float)i;
        din[0][i] = in_x[i], din[1][i] = in_y[i], din[2][i] = in_z[i];
    }
}

static void guard_outputs(void)
{
    for (int k = 0; k < 4; k++)
        for (int i = 0; i < N; i++)
            out[k][i] = GUARD, dout[k][i] = GUARD;
}

static int outputs_untouched(void)
{
    for (int k = 0; k < 4; k++)
        for (int i = 0; i < N; i++)
            if (memcmp(&out[k][i], &GUARD, sizeof GUARD) || dout[k][i] != (double)GUARD)
                return 0;
    return 1;
}

/* Every batch entry point with one descriptor set; `drop` names a required
 * array to pass as NULL (-1: none). Returns the call's status. */
enum { B_NOISE, B_NOISE_GRAD, B_FRACTAL, B_FRACTAL_GRAD, B_CENTRAL, B_FOOTPRINT, B_DOUBLE,
       B_PERTURB, B_HEIGHT, B_HEIGHT_FP, B_COUNT };
static const char *const batch_names[B_COUNT] = {
    "bg_noise3_batch", "bg_noise3_grad_batch", "bg_fractal3_batch", "bg_fractal3_grad_batch",
    "bg_fractal3_grad_central_batch", "bg_fractal3_grad_footprint_batch",
    "bg_fractal3d_grad_batch", "bg_perturb_batch", "bg_perturb_height_batch",
    "bg_perturb_height_footprint_batch"};
/* Required array arguments per call (inputs first, then outputs). */
static const int n_required[B_COUNT] = {4, 6, 4, 6, 6, 7, 6, 9, 9, 10};

typedef struct call_args {
    const bg_fractal *f;
    const bg_height *h;
    bg_perturb_method m;
    float step;
} call_args;

static bg_status call_batch(int which, const call_args *a, size_t n, int drop, int all_null)
{
    /* The required arrays of this call, in order; `drop` is set to NULL. */
    const void *p[10];
    for (int k = 0; k < 10; k++)
        p[k] = NULL;
    int np = 0;
    const float *x = in_x, *y = in_y, *z = in_z;
    switch (which) {
    case B_PERTURB:
        p[np++] = in_n[0], p[np++] = in_n[1], p[np++] = in_n[2];
        p[np++] = in_g[0], p[np++] = in_g[1], p[np++] = in_g[2];
        break;
    case B_DOUBLE:
        p[np++] = din[0], p[np++] = din[1], p[np++] = din[2];
        break;
    case B_HEIGHT_FP:
    case B_FOOTPRINT:
        p[np++] = in_fp;
        /* fall through */
    default:
        p[np++] = x, p[np++] = y, p[np++] = z;
        if (which == B_HEIGHT || which == B_HEIGHT_FP)
            p[np++] = in_n[0], p[np++] = in_n[1], p[np++] = in_n[2];
    }
    if (which == B_DOUBLE)
        p[np++] = dout[1], p[np++] = dout[2], p[np++] = dout[3];
    else if (which == B_NOISE || which == B_FRACTAL)
        p[np++] = out[0];
    else
        p[np++] = out[1], p[np++] = out[2], p[np++] = out[3];
    if (np != n_required[which])
        return (bg_status)-1; /* table error: reported as a wrong status */
    if (drop >= 0)
        p[drop] = NULL;
    if (all_null)
        for (int k = 0; k < np; k++)
            p[k] = NULL;
    const bg_fractal *f = all_null ? NULL : a->f;
    const bg_height *h = all_null ? NULL : a->h;
    float *value = all_null ? NULL : out[0];
    double *dvalue = all_null ? NULL : dout[0];
#define F(k) ((const float *)p[k])
#define O(k) ((float *)p[k])
    switch (which) {
    case B_NOISE: return bg_noise3_batch(F(0), F(1), F(2), n, O(3));
    case B_NOISE_GRAD: return bg_noise3_grad_batch(F(0), F(1), F(2), n, value, O(3), O(4), O(5));
    case B_FRACTAL: return bg_fractal3_batch(f, F(0), F(1), F(2), n, O(3));
    case B_FRACTAL_GRAD:
        return bg_fractal3_grad_batch(f, F(0), F(1), F(2), n, value, O(3), O(4), O(5));
    case B_CENTRAL:
        return bg_fractal3_grad_central_batch(f, a->step, F(0), F(1), F(2), n, value, O(3), O(4),
                                              O(5));
    case B_FOOTPRINT:
        return bg_fractal3_grad_footprint_batch(f, F(0), F(1), F(2), F(3), n, value, O(4), O(5),
                                                O(6));
    case B_DOUBLE:
        return bg_fractal3d_grad_batch(f, (const double *)p[0], (const double *)p[1],
                                       (const double *)p[2], n, dvalue, (double *)p[3],
                                       (double *)p[4], (double *)p[5]);
    case B_PERTURB:
        return bg_perturb_batch(a->m, F(0), F(1), F(2), F(3), F(4), F(5), n, O(6), O(7), O(8));
    case B_HEIGHT:
        return bg_perturb_height_batch(h, a->m, F(0), F(1), F(2), F(3), F(4), F(5), n, value,
                                       O(6), O(7), O(8));
    case B_HEIGHT_FP:
        return bg_perturb_height_footprint_batch(h, a->m, F(0), F(1), F(2), F(3), F(4), F(5),
                                                 F(6), n, value, O(7), O(8), O(9));
    }
#undef F
#undef O
    return (bg_status)-1;
}

static void test_batch_misuse(void)
{
    bg_fractal turb = bg_fractal_default(BG_FUNC_TURBULENCE);
    bg_height hd = bg_height_default();
    call_args good = {&turb, &hd, BG_PERTURB_SURFGRAD, 1e-3f};
    int bad = 0, cases = 0;

    /* n = 0: nothing is read, BG_OK even with every pointer NULL (the fused
     * calls used to read h->frequency before their loop). */
    for (int b = 0; b < B_COUNT; b++) {
        guard_outputs();
        bg_status s = call_batch(b, &good, 0, -1, 1);
        cases++;
        if (s != BG_OK || !outputs_untouched()) {
            bad++;
            CHECK(0, "%s with n = 0 and NULL pointers: %s", batch_names[b], bg_status_string(s));
        }
    }

    /* Valid calls are BG_OK and write their outputs. */
    for (int b = 0; b < B_COUNT; b++) {
        guard_outputs();
        bg_status s = call_batch(b, &good, N, -1, 0);
        cases++;
        if (s != BG_OK || outputs_untouched()) {
            bad++;
            CHECK(0, "%s valid call: %s, outputs %s", batch_names[b], bg_status_string(s),
                  outputs_untouched() ? "untouched" : "written");
        }
    }

    /* One required array NULL at a time: BG_ERR_NULL_POINTER, nothing written. */
    for (int b = 0; b < B_COUNT; b++)
        for (int d = 0; d < n_required[b]; d++) {
            guard_outputs();
            bg_status s = call_batch(b, &good, N, d, 0);
            cases++;
            if (s != BG_ERR_NULL_POINTER || !outputs_untouched()) {
                bad++;
                CHECK(0, "%s with required array %d NULL: %s", batch_names[b], d,
                      bg_status_string(s));
            }
        }

    /* Bad descriptors, enums and steps: the documented status, nothing written. */
    struct {
        const char *what;
        bg_fractal f;
        bg_status want;
    } fr[] = {
        {"function 7", {(bg_function)7, 6, 2.0f, 0.5f}, BG_ERR_INVALID_ARGUMENT},
        {"function -1", {(bg_function)-1, 6, 2.0f, 0.5f}, BG_ERR_INVALID_ARGUMENT},
        {"octaves 1000", {BG_FUNC_FBM, 1000, 2.0f, 0.5f}, BG_ERR_INVALID_ARGUMENT},
        {"octaves 0", {BG_FUNC_TURBULENCE, 0, 2.0f, 0.5f}, BG_ERR_INVALID_ARGUMENT},
        {"lacunarity NaN", {BG_FUNC_FBM, 6, NAN, 0.5f}, BG_ERR_INVALID_ARGUMENT},
        {"gain Inf", {BG_FUNC_FBM, 6, 2.0f, INFINITY}, BG_ERR_INVALID_ARGUMENT},
        {"gain 3e38, 32 octaves", {BG_FUNC_FBM, 32, 2.0f, 3e38f}, BG_ERR_OVERFLOW},
        {"lacunarity 3e38, 2 octaves", {BG_FUNC_TURBULENCE, 2, 3e38f, 0.5f}, BG_ERR_OVERFLOW},
    };
    int fractal_calls[] = {B_FRACTAL, B_FRACTAL_GRAD, B_CENTRAL, B_FOOTPRINT, B_DOUBLE,
                           B_HEIGHT, B_HEIGHT_FP};
    for (size_t k = 0; k < sizeof fr / sizeof fr[0]; k++) {
        bg_height h = hd;
        h.fractal = fr[k].f;
        call_args a = {&fr[k].f, &h, BG_PERTURB_SURFGRAD, 1e-3f};
        for (size_t c = 0; c < sizeof fractal_calls / sizeof fractal_calls[0]; c++) {
            guard_outputs();
            bg_status s = call_batch(fractal_calls[c], &a, N, -1, 0);
            cases++;
            if (s != fr[k].want || !outputs_untouched()) {
                bad++;
                CHECK(0, "%s with %s: %s (want %s)%s", batch_names[fractal_calls[c]], fr[k].what,
                      bg_status_string(s), bg_status_string(fr[k].want),
                      outputs_untouched() ? "" : ", outputs written");
            }
        }
    }
    struct {
        const char *what;
        call_args a;
        int which[3];
        bg_status want;
    } other[] = {
        {"method 9", {&turb, &hd, (bg_perturb_method)9, 1e-3f}, {B_PERTURB, B_HEIGHT, B_HEIGHT_FP},
         BG_ERR_INVALID_ARGUMENT},
        {"method -1", {&turb, &hd, (bg_perturb_method)-1, 1e-3f},
         {B_PERTURB, B_HEIGHT, B_HEIGHT_FP}, BG_ERR_INVALID_ARGUMENT},
        {"step 0", {&turb, &hd, BG_PERTURB_SURFGRAD, 0.0f}, {B_CENTRAL, B_CENTRAL, B_CENTRAL},
         BG_ERR_INVALID_ARGUMENT},
        {"step -1e-3", {&turb, &hd, BG_PERTURB_SURFGRAD, -1e-3f}, {B_CENTRAL, B_CENTRAL, B_CENTRAL},
         BG_ERR_INVALID_ARGUMENT},
        {"step NaN", {&turb, &hd, BG_PERTURB_SURFGRAD, NAN}, {B_CENTRAL, B_CENTRAL, B_CENTRAL},
         BG_ERR_INVALID_ARGUMENT},
        {"step Inf", {&turb, &hd, BG_PERTURB_SURFGRAD, INFINITY}, {B_CENTRAL, B_CENTRAL, B_CENTRAL},
         BG_ERR_INVALID_ARGUMENT},
        {"NULL descriptor", {NULL, NULL, BG_PERTURB_SURFGRAD, 1e-3f},
         {B_FRACTAL, B_CENTRAL, B_HEIGHT_FP}, BG_ERR_NULL_POINTER},
        {"NULL descriptor", {NULL, NULL, BG_PERTURB_SURFGRAD, 1e-3f},
         {B_FRACTAL_GRAD, B_DOUBLE, B_HEIGHT}, BG_ERR_NULL_POINTER},
        {"NULL descriptor", {NULL, NULL, BG_PERTURB_SURFGRAD, 1e-3f},
         {B_FOOTPRINT, B_FOOTPRINT, B_FOOTPRINT}, BG_ERR_NULL_POINTER},
    };
    bg_height hbad[3] = {hd, hd, hd};
    hbad[0].gradient = (bg_gradient_mode)5;
    hbad[1].frequency = 3e38f; /* issue 13: perturb --frequency 3e38 */
    hbad[2].amplitude = NAN;
    bg_status hwant[3] = {BG_ERR_INVALID_ARGUMENT, BG_ERR_OVERFLOW, BG_ERR_INVALID_ARGUMENT};
    for (size_t k = 0; k < sizeof other / sizeof other[0]; k++)
        for (int c = 0; c < 3; c++) {
            guard_outputs();
            bg_status s = call_batch(other[k].which[c], &other[k].a, N, -1, 0);
            cases++;
            if (s != other[k].want || !outputs_untouched()) {
                bad++;
                CHECK(0, "%s with %s: %s", batch_names[other[k].which[c]], other[k].what,
                      bg_status_string(s));
            }
        }
    for (int k = 0; k < 3; k++)
        for (int b = B_HEIGHT; b <= B_HEIGHT_FP; b++) {
            call_args a = {&turb, &hbad[k], BG_PERTURB_SURFGRAD, 1e-3f};
            guard_outputs();
            bg_status s = call_batch(b, &a, N, -1, 0);
            cases++;
            if (s != hwant[k] || !outputs_untouched()) {
                bad++;
                CHECK(0, "%s with bad height %d: %s", batch_names[b], k, bg_status_string(s));
            }
        }
    printf("batch contract: %d cases (n = 0 with NULL, valid, each required array NULL, bad "
           "descriptors/enums/steps), %d wrong\n", cases, bad);
}

static int all_nan3(float a, float b, float c)
{
    return isnan(a) && isnan(b) && isnan(c);
}

static void test_point_misuse(void)
{
    int bad = 0;
    bg_vec3 n = {0, 0, 1}, g = {0.3f, -0.2f, 0.1f};
    bg_dvec3 nd = {0, 0, 1}, gd = {0.3, -0.2, 0.1};
    int methods[] = {3, 9, -1, 1000};
    for (int k = 0; k < 4; k++) {
        bg_vec3 r = bg_perturb((bg_perturb_method)methods[k], n, g);
        bg_dvec3 rd = bg_perturbd((bg_perturb_method)methods[k], nd, gd);
        if (!all_nan3(r.x, r.y, r.z) || !(isnan(rd.x) && isnan(rd.y) && isnan(rd.z))) {
            bad++;
            CHECK(0, "bg_perturb(d) with method %d gave (%g %g %g) / (%g %g %g), not NaN",
                  methods[k], (double)r.x, (double)r.y, (double)r.z, rd.x, rd.y, rd.z);
        }
    }
    /* The valid methods still give unit vectors. */
    for (int m = 0; m < 3; m++) {
        bg_vec3 r = bg_perturb((bg_perturb_method)m, n, g);
        double l = sqrt((double)r.x * r.x + (double)r.y * r.y + (double)r.z * r.z);
        CHECK(fabs(l - 1) < 1e-6, "method %d: length %g", m, l);
    }

    bg_height hd = bg_height_default();
    bg_height hb[5] = {hd, hd, hd, hd, hd};
    hb[0].gradient = (bg_gradient_mode)5;
    hb[1].fractal.function = (bg_function)7;
    hb[2].fractal.octaves = 1000;
    hb[3].frequency = INFINITY;
    hb[4].step = -1;
    bg_vec3 p = {0.3f, 1.7f, -2.2f};
    for (int k = -1; k < 5; k++) {
        bg_vec3 gr = {1, 2, 3};
        float v = bg_height_eval(k < 0 ? NULL : &hb[k], p, &gr);
        if (!isnan(v) || !all_nan3(gr.x, gr.y, gr.z)) {
            bad++;
            CHECK(0, "bg_height_eval with bad height %d: %g (%g %g %g), not NaN", k, (double)v,
                  (double)gr.x, (double)gr.y, (double)gr.z);
        }
    }
    bg_vec3 gr;
    float v1 = bg_height_eval(&hd, p, &gr), v2 = bg_height_eval(&hd, p, NULL);
    CHECK(memcmp(&v1, &v2, sizeof v1) == 0 && isfinite(v1), "bg_height_eval with grad NULL");

    /* Footprint helpers: octave outside 0..31 or bad lacunarity is NaN (an
     * octave of 1e9 used to loop 1e9 times). */
    float w[] = {bg_octave_weight(0.01f, 2.0f, 40), bg_octave_weight(0.01f, 2.0f, -1),
                 bg_octave_weight(0.01f, 0.0f, 1), bg_octave_weight(0.01f, NAN, 1),
                 bg_octave_weight(0.01f, INFINITY, 1), bg_octaves_for_footprint(0.0f, 33),
                 bg_octaves_for_footprint(0.0f, -1)};
    for (size_t k = 0; k < sizeof w / sizeof w[0]; k++)
        if (!isnan(w[k])) {
            bad++;
            CHECK(0, "footprint helper case %zu gave %g, not NaN", k, (double)w[k]);
        }
    CHECK(bg_octave_weight(0.0f, 2.0f, BG_MAX_OCTAVES - 1) == 1.0f, "octave 31 weight");
    CHECK(bg_octaves_for_footprint(0.0f, BG_MAX_OCTAVES) == (float)BG_MAX_OCTAVES,
          "32 octaves at footprint 0");
    CHECK(bg_octaves_for_footprint(0.0f, 0) == 0.0f, "0 octaves");

    /* Single-point fractal calls: a NULL or out-of-range descriptor, or a bad
     * central step, gives NaN value and gradient (noise.h), never a guess. */
    bg_fractal bads[4] = {bg_fractal_default(BG_FUNC_FBM), bg_fractal_default(BG_FUNC_FBM),
                          bg_fractal_default(BG_FUNC_FBM), bg_fractal_default(BG_FUNC_FBM)};
    bads[0].function = (bg_function)7;
    bads[1].octaves = 1000;
    bads[2].lacunarity = 0;
    bads[3].gain = NAN;
    for (int k = 0; k <= 4; k++) {
        const bg_fractal *f = k < 4 ? &bads[k] : NULL;
        bg_vec3 g;
        bg_dvec3 gd;
        float a = bg_fractal3(f, 0.3f, 0.2f, 0.1f), b = bg_fractal3_grad(f, 0.3f, 0.2f, 0.1f, &g);
        double c = bg_fractal3d(f, 0.3, 0.2, 0.1), d = bg_fractal3d_grad(f, 0.3, 0.2, 0.1, &gd);
        CHECK(isnan(a) && isnan(b) && isnan(g.x) && isnan(g.z) && isnan(c) && isnan(d) &&
                  isnan(gd.y),
              "single-point fractal with bad descriptor %d: %g %g %g %g", k, (double)a,
              (double)b, c, d);
        float e = bg_fractal3_grad_central(f, 1e-3f, 0.3f, 0.2f, 0.1f, &g);
        double h = bg_fractal3d_grad_central(f, 1e-3, 0.3, 0.2, 0.1, &gd);
        CHECK(isnan(e) && isnan(g.y) && isnan(h) && isnan(gd.x),
              "central single point with bad descriptor %d", k);
    }
    bg_fractal ok = bg_fractal_default(BG_FUNC_FBM);
    const float hs[] = {0.0f, -1.0f, NAN, INFINITY};
    for (int k = 0; k < 4; k++) {
        bg_vec3 g;
        bg_dvec3 gd;
        float e = bg_fractal3_grad_central(&ok, hs[k], 0.3f, 0.2f, 0.1f, &g);
        double h = bg_fractal3d_grad_central(&ok, (double)hs[k], 0.3, 0.2, 0.1, &gd);
        CHECK(isnan(e) && isnan(g.x) && isnan(h) && isnan(gd.z), "central step %g gives NaN",
              (double)hs[k]);
    }
    bg_vec3 g0;
    CHECK(isfinite(bg_fractal3_grad(&ok, 0.3f, 0.2f, 0.1f, &g0)) && isfinite(g0.x),
          "a valid descriptor still gives finite results");
    printf("single-point misuse: unknown methods, bad heights, footprint helpers: %d wrong\n",
           bad);
}

/* The value and gradient bounds behind the overflow check (2.1, 9), measured. */
static void test_noise_bounds(void)
{
    ref_rng r;
    ref_rng_seed(&r, 2024);
    double mv = 0, mg = 0;
    for (int i = 0; i < 200000; i++) {
        bg_vec3 g;
        float v = bg_noise3_grad((float)ref_rng_uniform(&r, -256, 256),
                                 (float)ref_rng_uniform(&r, -256, 256),
                                 (float)ref_rng_uniform(&r, -256, 256), &g);
        mv = fmax(mv, fabs(v));
        mg = fmax(mg, fmax(fabs(g.x), fmax(fabs(g.y), fabs(g.z))));
    }
    printf("noise bounds on 2e5 samples: max |n| = %.4f (bound 2.1), max |dn/dx| = %.4f (bound "
           "9)\n", mv, mg);
    CHECK(mv <= 2.1 && mg <= 9.0, "noise exceeds the bounds the overflow check assumes");
}

static int finite3(const float *v, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* Largest gain (bisection on the float line) that bg_fractal_validate accepts. */
static float largest_gain(bg_function fn, int octaves, float lac)
{
    float lo = 1, hi = FLT_MAX;
    bg_fractal f = {fn, octaves, lac, lo};
    if (bg_fractal_validate(&f) != BG_OK)
        return NAN;
    f.gain = hi;
    if (bg_fractal_validate(&f) == BG_OK)
        return hi;
    while (nextafterf(lo, INFINITY) < hi) {
        float mid = (float)sqrt((double)lo * hi);
        if (mid <= lo || mid >= hi)
            mid = nextafterf(lo, INFINITY);
        f.gain = mid;
        if (bg_fractal_validate(&f) == BG_OK)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

static void test_parameter_overflow(void)
{
    int bad = 0;
    bg_fractal f = {BG_FUNC_FBM, 32, 2.0f, 3e38f};
    bad += bg_fractal_validate(&f) != BG_ERR_OVERFLOW;
    f.octaves = 2;
    bad += bg_fractal_validate(&f) != BG_ERR_OVERFLOW;
    f.octaves = 1; /* gain^0 only: gain is never used */
    bad += bg_fractal_validate(&f) != BG_OK;
    bg_fractal l = {BG_FUNC_TURBULENCE, 2, 3e38f, 0.5f};
    bad += bg_fractal_validate(&l) != BG_ERR_OVERFLOW;
    l.lacunarity = 1e10f, l.octaves = 4;
    bad += bg_fractal_validate(&l) != BG_OK;
    bg_height h = bg_height_default();
    h.frequency = 3e38f;
    bad += bg_height_validate(&h) != BG_ERR_OVERFLOW;
    h = bg_height_default(), h.amplitude = 3e38f;
    bad += bg_height_validate(&h) != BG_ERR_OVERFLOW;
    h = bg_height_default(), h.amplitude = -1e30f, h.frequency = -1e6f;
    bad += bg_height_validate(&h) != BG_OK;
    h.frequency = 1e15f; /* amplitude * frequency * sum of octave gradients overflows */
    bad += bg_height_validate(&h) != BG_ERR_OVERFLOW;
    CHECK(bad == 0, "%d overflow parameter cases wrong", bad);
    CHECK(strstr(bg_status_string(BG_ERR_OVERFLOW), "overflow") != NULL, "status text: %s",
          bg_status_string(BG_ERR_OVERFLOW));

    /* At the edge of acceptance the sums stay finite: the largest accepted gain
     * for 32 octaves, over many points (the gradient weights grow with 2^i). */
    int nonfinite = 0;
    for (int fn = BG_FUNC_FBM; fn <= BG_FUNC_TURBULENCE; fn++)
        for (int oct = 2; oct <= 32; oct += 10) {
            bg_fractal e = {(bg_function)fn, oct, 2.0f, largest_gain((bg_function)fn, oct, 2.0f)};
            float xs[N], ys[N], zs[N];
            for (int i = 0; i < N; i++) /* small coordinates: octave 31 is at 2^31 x */
                xs[i] = in_x[i] * 1e-3f, ys[i] = in_y[i] * 1e-3f, zs[i] = in_z[i] * 1e-3f;
            bg_status s = bg_fractal3_grad_batch(&e, xs, ys, zs, N, out[0], out[1], out[2],
                                                 out[3]);
            if (s != BG_OK || !finite3(out[0], N) || !finite3(out[1], N) ||
                !finite3(out[2], N) || !finite3(out[3], N))
                nonfinite++;
            e.gain = nextafterf(e.gain, INFINITY);
            if (bg_fractal_validate(&e) != BG_ERR_OVERFLOW)
                nonfinite++;
        }
    CHECK(nonfinite == 0, "%d edge-of-acceptance cases not finite or not refused", nonfinite);
    printf("parameter overflow: issue 13 settings refused with BG_ERR_OVERFLOW, edge of "
           "acceptance finite: %s\n", bad == 0 && nonfinite == 0 ? "yes" : "NO");
}

/* Evaluate every float path at x = c on one axis (the others small); 1 if all
 * results are finite, 0 if the value is NaN everywhere it must be, -1 if mixed. */
static int eval_at(const bg_fractal *f, int axis, float c)
{
    float p[3][N];
    for (int i = 0; i < N; i++)
        p[0][i] = in_x[i] * 0.1f, p[1][i] = in_y[i] * 0.1f, p[2][i] = in_z[i] * 0.1f;
    for (int i = 0; i < N; i++)
        p[axis][i] = i % 2 ? c : -c;
    int finite = 1, nan = 1;
    float zero[N];
    memset(zero, 0, sizeof zero);
    for (int path = 0; path < 4; path++) {
        bg_status s;
        if (path == 0)
            s = bg_fractal3_batch(f, p[0], p[1], p[2], N, out[0]);
        else if (path == 1)
            s = bg_fractal3_grad_batch(f, p[0], p[1], p[2], N, out[0], out[1], out[2], out[3]);
        else if (path == 2)
            s = bg_fractal3_grad_central_batch(f, BG_DEFAULT_CENTRAL_STEP, p[0], p[1], p[2], N,
                                               out[0], out[1], out[2], out[3]);
        else
            s = bg_fractal3_grad_footprint_batch(f, zero, p[0], p[1], p[2], N, out[0], out[1],
                                                 out[2], out[3]);
        if (s != BG_OK)
            return -2;
        for (int i = 0; i < N; i++) {
            finite &= isfinite(out[0][i]) != 0;
            nan &= isnan(out[0][i]) != 0;
            if (path > 0)
                for (int k = 1; k < 4; k++)
                    finite &= isfinite(out[k][i]) != 0;
        }
    }
    return finite ? 1 : nan ? 0 : -1;
}

static void test_coordinate_overflow(void)
{
    bg_fractal turb = bg_fractal_default(BG_FUNC_TURBULENCE);
    float m = bg_fractal_max_coordinate(&turb, 1.0f);
    printf("default turbulence: bg_fractal_max_coordinate = %.9g (FLT_MAX / 32 = %.9g)\n",
           (double)m, (double)(FLT_MAX / 32));
    /* 6 octaves of lacunarity 2: the finest octave multiplies by 32 exactly, so
     * the bound is FLT_MAX / 32, a float (a power-of-two division). */
    CHECK(m == FLT_MAX / 32, "default turbulence bound");
    /* issue 13: turbulence at 1e38 is above the bound (NaN), 1e37 below. */
    CHECK(eval_at(&turb, 0, 1e38f) == 0 && m < 1e38f, "x = 1e38 not NaN");
    CHECK(eval_at(&turb, 0, 1e37f) == 1 && m > 1e37f, "x = 1e37 not finite");

    struct {
        bg_fractal f;
    } cases[] = {
        {{BG_FUNC_TURBULENCE, 6, 2.0f, 0.5f}}, {{BG_FUNC_FBM, 5, 2.1f, 0.55f}},
        {{BG_FUNC_FBM, 4, 1e10f, 0.5f}},       {{BG_FUNC_TURBULENCE, 32, 3.0f, 0.3f}},
        {{BG_FUNC_FBM, 7, 1.9999999f, 0.5f}},  {{BG_FUNC_TURBULENCE, 8, 0.5f, 1.5f}},
        {{BG_FUNC_NOISE, 1, 2.0f, 0.5f}},
    };
    int bad = 0, n = 0;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const bg_fractal *f = &cases[k].f;
        float c = bg_fractal_max_coordinate(f, 1.0f);
        for (int axis = 0; axis < 3; axis++) {
            n++;
            int below = eval_at(f, axis, c);
            int above = c < FLT_MAX ? eval_at(f, axis, nextafterf(c, INFINITY)) : 0;
            if (below != 1 || above != 0) {
                bad++;
                CHECK(0, "fractal %zu axis %d: bound %.9g gives %d at the bound, %d above", k,
                      axis, (double)c, below, above);
            }
        }
        /* The bound is FLT_MAX only when no octave scales up. */
        int scales_up = f->function != BG_FUNC_NOISE && f->lacunarity > 1;
        CHECK((c == FLT_MAX) == !scales_up, "fractal %zu: bound %g", k, (double)c);

        /* Double: same, in double. */
        double d = bg_fractal_max_coordinated(f, 1.0);
        double dd[2] = {d, nextafter(d, INFINITY)};
        for (int a = 0; a < (d < DBL_MAX ? 2 : 1); a++) {
            for (int i = 0; i < N; i++)
                din[0][i] = i % 2 ? dd[a] : -dd[a], din[1][i] = 0.3, din[2][i] = -0.7;
            bg_status s = bg_fractal3d_grad_batch(f, din[0], din[1], din[2], N, dout[0], dout[1],
                                                  dout[2], dout[3]);
            int ok = s == BG_OK;
            for (int i = 0; i < N; i++)
                ok &= a == 0 ? isfinite(dout[0][i]) && isfinite(dout[1][i]) : isnan(dout[0][i]);
            if (!ok) {
                bad++;
                CHECK(0, "fractal %zu double bound %.17g: %s", k, dd[0],
                      a ? "not NaN above" : "not finite at");
            }
        }

        /* Fused height with a frequency: the bound on positions. */
        float freqs[] = {1.0f, 2.5f, 1e-3f, -7.0f, 3e20f};
        for (size_t q = 0; q < sizeof freqs / sizeof freqs[0]; q++) {
            bg_height h = bg_height_default();
            h.fractal = *f, h.frequency = freqs[q];
            if (bg_height_validate(&h) != BG_OK)
                continue;
            float pc = bg_fractal_max_coordinate(f, freqs[q]);
            CHECK(pc >= 1.0f, "accepted height with bound %g < 1", (double)pc);
            float at[2] = {pc, nextafterf(pc, INFINITY)};
            for (int a = 0; a < (pc < FLT_MAX ? 2 : 1); a++) {
                float px[N], py[N], pz[N];
                for (int i = 0; i < N; i++)
                    px[i] = in_x[i] * 0.1f, py[i] = i % 2 ? at[a] : -at[a], pz[i] = in_z[i] * 0.1f;
                bg_status s = bg_perturb_height_batch(&h, BG_PERTURB_SURFGRAD, px, py, pz,
                                                      in_n[0], in_n[1], in_n[2], N, out[0],
                                                      out[1], out[2], out[3]);
                int ok = s == BG_OK;
                for (int i = 0; i < N; i++) {
                    /* Above: NaN height, and the normal of a NaN gradient (the unit n). */
                    bg_vec3 nn = {in_n[0][i], in_n[1][i], in_n[2][i]}, gn = {NAN, NAN, NAN};
                    bg_vec3 u = bg_perturb(BG_PERTURB_SURFGRAD, nn, gn);
                    ok &= a == 0 ? isfinite(out[0][i]) && isfinite(out[1][i]) &&
                                       isfinite(out[2][i]) && isfinite(out[3][i])
                                 : isnan(out[0][i]) && u.x == out[1][i] && u.y == out[2][i] &&
                                       u.z == out[3][i];
                }
                n++;
                if (!ok) {
                    bad++;
                    CHECK(0, "fractal %zu frequency %g: position bound %.9g %s", k,
                          (double)freqs[q], (double)pc, a ? "not NaN above" : "not finite at");
                }
            }
        }
    }
    /* Argument rules. */
    bg_fractal bf = {(bg_function)7, 6, 2, 0.5f};
    CHECK(isnan(bg_fractal_max_coordinate(NULL, 1)) && isnan(bg_fractal_max_coordinate(&bf, 1)) &&
              isnan(bg_fractal_max_coordinate(&turb, INFINITY)) &&
              isnan(bg_fractal_max_coordinate(&turb, NAN)) &&
              isnan(bg_fractal_max_coordinated(NULL, 1)),
          "invalid arguments to bg_fractal_max_coordinate are not NaN");
    CHECK(bg_fractal_max_coordinate(&turb, 0) == FLT_MAX &&
              bg_fractal_max_coordinated(&turb, 0) == DBL_MAX,
          "frequency 0 bound");
    printf("coordinate overflow: %d bound checks (at the bound finite, one float above NaN; "
           "float, double, fused with frequencies), %d wrong\n", n, bad);
}

int main(void)
{
    fill_inputs();
    test_batch_misuse();
    test_point_misuse();
    test_noise_bounds();
    test_parameter_overflow();
    test_coordinate_overflow();
    return check_summary("test_contract");
}
