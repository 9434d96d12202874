/* SPDX-License-Identifier: MIT */
/* The scalar and batch APIs from 8 threads at once (issue 13, Build item 5).
 * The threads are released together by a barrier and each one's first call is
 * the process's first library call, so the lazy CPU detection and ISA
 * selection (bg_isa_best / bg_isa_active, atomics in src/kernels) run
 * concurrently; the threads start with different entry points. Every thread
 * then runs the same work list twice and keeps every output. After the join
 * the main thread, alone, computes the same list once: each thread's outputs
 * must equal it bit for bit (NaN payloads included: same process, same ISA),
 * and every thread must have seen the same best and active ISA as that
 * single-threaded run. scripts/test runs this under ThreadSanitizer, which
 * reports any data race on the shared state. Public API only. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bumpgrad.h"

enum { THREADS = 8, N = 301, NPOINT = 64, ROUNDS = 2 };

/* Output layout of one run of the work list. */
enum { F_OUT = 39 * N + 16 * NPOINT, D_OUT = 4 * N + 4 * NPOINT };

static float px[N], py[N], pz[N], nx[N], ny[N], nz[N], gx[N], gy[N], gz[N], fp[N];
static double dx[N], dy[N], dz[N];

typedef struct result {
    float f[F_OUT];
    double d[D_OUT];
    int statuses_ok;
    bg_isa best, active, first_active;
    int supported_mask;
    bg_status env;
} result;

static void fill(void)
{
    uint64_t s = 0x9E3779B97F4A7C15ull;
    for (int i = 0; i < N; i++) {
        float r[10];
        for (int k = 0; k < 10; k++) {
            s = s * 6364136223846793005ull + 1442695040888963407ull;
            r[k] = (float)((double)(s >> 40) / 16777216.0) * 2 - 1;
        }
        px[i] = 40 * r[0], py[i] = 40 * r[1], pz[i] = 40 * r[2];
        nx[i] = r[3], ny[i] = r[4], nz[i] = r[5] + 0.5f;
        gx[i] = 3 * r[6], gy[i] = 3 * r[7], gz[i] = 3 * r[8];
        fp[i] = 0.05f * (r[9] + 1);
        dx[i] = px[i] * 1.5, dy[i] = py[i], dz[i] = pz[i] - 1e6;
    }
    px[7] = NAN, py[11] = INFINITY, nx[13] = ny[13] = nz[13] = 0; /* the NaN rules too */
}

/* The first library call of a thread: a different entry point per thread. */
static void first_call(int t, result *r)
{
    bg_vec3 g, n = {0, 0, 1}, v = {0.1f, 0.2f, 0.3f};
    static _Thread_local float out[3][N];
    switch (t % 8) {
    case 0: r->first_active = bg_isa_active(); return;
    case 1: (void)bg_isa_best(); break;
    case 2: bg_noise3_batch(px, py, pz, N, out[0]); break;
    case 3: (void)bg_noise3_grad(1.5f, 2.5f, 3.5f, &g); break;
    case 4:
        bg_perturb_batch(BG_PERTURB_SURFGRAD, nx, ny, nz, gx, gy, gz, N, out[0], out[1], out[2]);
        break;
    case 5: (void)bg_perturb(BG_PERTURB_ADDITIVE, n, v); break;
    case 6: (void)bg_isa_supported(BG_ISA_AVX2); break;
    default: {
        bg_height h = bg_height_default();
        bg_perturb_height_batch(&h, BG_PERTURB_SURFGRAD, px, py, pz, nx, ny, nz, N, NULL, out[0],
                                out[1], out[2]);
    }
    }
    r->first_active = bg_isa_active();
}

/* The work list: every batch entry point and the main single-point ones. */
static void work(result *r)
{
    float *o = r->f;
    double *d = r->d;
    int ok = 1;
    bg_fractal turb = bg_fractal_default(BG_FUNC_TURBULENCE);
    bg_fractal fbm = {BG_FUNC_FBM, 5, 2.1f, 0.55f};
    bg_height h = bg_height_default();
    h.frequency = 1.7f, h.amplitude = 0.25f;

    ok &= bg_noise3_batch(px, py, pz, N, o) == BG_OK, o += N;
    ok &= bg_noise3_grad_batch(px, py, pz, N, o, o + N, o + 2 * N, o + 3 * N) == BG_OK, o += 4 * N;
    ok &= bg_fractal3_batch(&turb, px, py, pz, N, o) == BG_OK, o += N;
    ok &= bg_fractal3_grad_batch(&fbm, px, py, pz, N, o, o + N, o + 2 * N, o + 3 * N) == BG_OK;
    o += 4 * N;
    ok &= bg_fractal3_grad_central_batch(&turb, 1e-3f, px, py, pz, N, o, o + N, o + 2 * N,
                                         o + 3 * N) == BG_OK;
    o += 4 * N;
    ok &= bg_fractal3_grad_footprint_batch(&turb, fp, px, py, pz, N, o, o + N, o + 2 * N,
                                           o + 3 * N) == BG_OK;
    o += 4 * N;
    for (int m = 0; m < 3; m++) {
        ok &= bg_perturb_batch((bg_perturb_method)m, nx, ny, nz, gx, gy, gz, N, o, o + N,
                               o + 2 * N) == BG_OK;
        o += 3 * N;
    }
    for (int mode = 0; mode < 2; mode++) {
        h.gradient = mode ? BG_GRADIENT_CENTRAL : BG_GRADIENT_ANALYTIC;
        ok &= bg_perturb_height_batch(&h, BG_PERTURB_SURFGRAD, px, py, pz, nx, ny, nz, N, o,
                                      o + N, o + 2 * N, o + 3 * N) == BG_OK;
        o += 4 * N;
    }
    h.gradient = BG_GRADIENT_ANALYTIC;
    ok &= bg_perturb_height_footprint_batch(&h, BG_PERTURB_ADDITIVE, fp, px, py, pz, nx, ny, nz,
                                            N, o, o + N, o + 2 * N, o + 3 * N) == BG_OK;
    o += 4 * N;
    ok &= bg_fractal3d_grad_batch(&fbm, dx, dy, dz, N, d, d + N, d + 2 * N, d + 3 * N) == BG_OK;
    d += 4 * N;
    /* Single points (the scalar kernel). */
    for (int i = 0; i < NPOINT; i++) {
        bg_vec3 g, n = {nx[i], ny[i], nz[i]}, v = {gx[i], gy[i], gz[i]}, p = {px[i], py[i], pz[i]};
        bg_dvec3 dg;
        *o++ = bg_noise3(px[i], py[i], pz[i]);
        *o++ = bg_noise3_grad(px[i], py[i], pz[i], &g);
        *o++ = g.x, *o++ = g.y, *o++ = g.z;
        *o++ = bg_fractal3_grad(&turb, px[i], py[i], pz[i], &g);
        *o++ = g.x, *o++ = g.y, *o++ = g.z;
        bg_vec3 q = bg_perturb(BG_PERTURB_SURFGRAD, n, v);
        *o++ = q.x, *o++ = q.y, *o++ = q.z;
        *o++ = bg_height_eval(&h, p, &g);
        *o++ = g.x, *o++ = g.y, *o++ = g.z;
        *d++ = bg_noise3d(dx[i], dy[i], dz[i]);
        *d++ = bg_fractal3d_grad(&fbm, dx[i], dy[i], dz[i], &dg);
        *d++ = dg.x, *d++ = bg_angle_deg(n, q);
    }
    if (o - r->f != F_OUT || d - r->d != D_OUT)
        ok = 0; /* layout drifted from F_OUT / D_OUT */
    r->statuses_ok = ok;
    r->best = bg_isa_best();
    r->active = bg_isa_active();
    r->supported_mask = 0;
    for (int i = 0; i < BG_ISA_COUNT; i++)
        r->supported_mask |= bg_isa_supported((bg_isa)i) << i;
    r->env = bg_isa_env_status(NULL, 0);
}

static pthread_barrier_t start;
static result results[THREADS][ROUNDS];
static result reference;

static void *thread_main(void *arg)
{
    int t = (int)(intptr_t)arg;
    pthread_barrier_wait(&start);
    first_call(t, &results[t][0]);
    for (int k = 0; k < ROUNDS; k++) {
        bg_isa fa = results[t][0].first_active;
        work(&results[t][k]);
        results[t][k].first_active = fa;
    }
    return NULL;
}

int main(void)
{
    fill(); /* no library call before the threads */
    pthread_t th[THREADS];
    if (pthread_barrier_init(&start, NULL, THREADS) != 0) {
        printf("FAIL: pthread_barrier_init\n");
        return 1;
    }
    for (int t = 0; t < THREADS; t++)
        if (pthread_create(&th[t], NULL, thread_main, (void *)(intptr_t)t) != 0) {
            printf("FAIL: pthread_create %d\n", t);
            return 1;
        }
    for (int t = 0; t < THREADS; t++)
        pthread_join(th[t], NULL);
    pthread_barrier_destroy(&start);

    work(&reference); /* single thread now */
    int fails = 0;
    if (!reference.statuses_ok) {
        printf("FAIL: single-thread run: a call did not return BG_OK\n");
        fails++;
    }
    for (int t = 0; t < THREADS; t++)
        for (int k = 0; k < ROUNDS; k++) {
            const result *r = &results[t][k];
            int fbad = 0, dbad = 0;
            for (int i = 0; i < F_OUT; i++)
                fbad += memcmp(&r->f[i], &reference.f[i], sizeof(float)) != 0;
            for (int i = 0; i < D_OUT; i++)
                dbad += memcmp(&r->d[i], &reference.d[i], sizeof(double)) != 0;
            int isa_bad = r->best != reference.best || r->active != reference.active ||
                          r->first_active != reference.active ||
                          r->supported_mask != reference.supported_mask ||
                          r->env != reference.env;
            if (fbad || dbad || isa_bad || !r->statuses_ok) {
                fails++;
                printf("FAIL: thread %d round %d: %d float and %d double outputs differ from "
                       "the single-thread run; isa best %s active %s first %s (single: %s %s); "
                       "statuses %s\n", t, k, fbad, dbad, bg_isa_name(r->best),
                       bg_isa_name(r->active), bg_isa_name(r->first_active),
                       bg_isa_name(reference.best), bg_isa_name(reference.active),
                       r->statuses_ok ? "ok" : "NOT ok");
            }
        }
    printf("%d threads x %d rounds (first library call concurrent, ISA %s), %d float + %d "
           "double outputs each, compared bit for bit with one single-thread run: %d "
           "mismatching runs\n", THREADS, ROUNDS, bg_isa_name(reference.active), F_OUT, D_OUT,
           fails);
    return fails ? 1 : 0;
}
