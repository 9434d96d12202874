/* SPDX-License-Identifier: MIT */
/* How `bumpgrad bench` times a row: fixed random inputs, a thread team that
 * lives for the whole run, a warm-up and R timed runs reduced to their median. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench/bench_internal.h"

/* Points are random in [-BOX, BOX]^3, not on a grid: consecutive samples share no
 * lattice cell, so no kernel profits from a coherence the test alone would have,
 * and negative and positive cells both go through the floor/wrap path. */
#define BENCH_BOX 64.0f
#define BENCH_SEED UINT64_C(0x62756d7067726164) /* "bumpgrad" */
/* Thread slices start on multiples of this many points: a 64-byte line of every
 * array, and a whole number of vectors for every ISA, so threads neither share
 * output cache lines nor split a vector into a scalar tail in the middle. */
#define BENCH_SLICE_ALIGN 64

/* ---- inputs ---- */

/* splitmix64: a fixed seed gives the same points on every machine and run. */
static uint64_t next_u64(uint64_t *s)
{
    uint64_t z = (*s += UINT64_C(0x9e3779b97f4a7c15));
    z = (z ^ (z >> 30)) * UINT64_C(0xbf58476d1ce4e5b9);
    z = (z ^ (z >> 27)) * UINT64_C(0x94d049bb133111eb);
    return z ^ (z >> 31);
}

/* Uniform in [-1, 1), with 24 random bits (exact in float). */
static float next_unit(uint64_t *s)
{
    return (float)(next_u64(s) >> 40) * (2.0f / 16777216.0f) - 1.0f;
}

void bench_data_free(bench_data *d)
{
    for (size_t k = 0; k < BENCH_NARRAYS; k++)
        free(d->arrays[k]);
    memset(d, 0, sizeof *d);
}

static void fill_points(bench_data *d)
{
    uint64_t s = BENCH_SEED;
    for (size_t i = 0; i < d->n; i++) {
        d->px[i] = BENCH_BOX * next_unit(&s);
        d->py[i] = BENCH_BOX * next_unit(&s);
        d->pz[i] = BENCH_BOX * next_unit(&s);
        /* Normals: random directions (not axis-aligned, so no shortcut applies). */
        float x, y, z, q;
        do {
            x = next_unit(&s);
            y = next_unit(&s);
            z = next_unit(&s);
            q = x * x + y * y + z * z;
        } while (q < 1e-4f || q > 1.0f);
        float r = 1.0f / sqrtf(q);
        d->nx[i] = x * r;
        d->ny[i] = y * r;
        d->nz[i] = z * r;
        /* Gradients of the size a bump map produces (|g| up to about 1). */
        d->gx[i] = 0.5f * next_unit(&s);
        d->gy[i] = 0.5f * next_unit(&s);
        d->gz[i] = 0.5f * next_unit(&s);
    }
}

int bench_data_init(bench_data *d, size_t n)
{
    float **slots[BENCH_NARRAYS] = {&d->px, &d->py, &d->pz, &d->nx, &d->ny, &d->nz, &d->gx,
                                    &d->gy, &d->gz, &d->v,  &d->ox, &d->oy, &d->oz};
    memset(d, 0, sizeof *d);
    d->n = n;
    for (size_t k = 0; k < BENCH_NARRAYS; k++) {
        /* 64-byte alignment so that the slices of every thread start on a line. */
        void *p = NULL;
        if (posix_memalign(&p, 64, n * sizeof(float)) != 0) {
            bench_data_free(d);
            return -1;
        }
        /* Touch every page now: page faults must not land in the first timed run. */
        memset(p, 0, n * sizeof(float));
        d->arrays[k] = p;
        *slots[k] = p;
    }
    fill_points(d);
    return 0;
}

/* ---- threads ----
 * A team that lives for the whole run, so that a timed run pays two barrier
 * crossings and no thread creation; the caller is worker 0. The library batch
 * calls are single-threaded and reentrant, so each worker calls the kernel on its
 * own contiguous slice. (bgt_parallel_for would create threads per call and
 * chooses its own chunking; here the timed region must be just the work.) */
typedef struct bench_worker {
    bench_team *team;
    int index;
} bench_worker;

struct bench_team {
    int threads;
    pthread_t *tid;
    bench_worker *workers;
    pthread_barrier_t start, done;
    /* The gate the workers pass before their first barrier: 1 once every
     * worker exists, 2 if one could not be created (then they all leave, and
     * no barrier is ever waited on by a team smaller than its count). */
    pthread_mutex_t lock;
    pthread_cond_t gate;
    int state;
    const bench_job *job; /* published before `start`, read after it */
    size_t n;
    int quit;
};

static void slice_of(size_t n, int threads, int k, size_t *b, size_t *e)
{
    size_t blocks = (n + BENCH_SLICE_ALIGN - 1) / BENCH_SLICE_ALIGN;
    size_t per = blocks / (size_t)threads, extra = blocks % (size_t)threads, kk = (size_t)k;
    size_t first = kk * per + (kk < extra ? kk : extra);
    size_t count = per + (kk < extra ? 1 : 0);
    *b = first * BENCH_SLICE_ALIGN;
    *e = (first + count) * BENCH_SLICE_ALIGN;
    if (*b > n)
        *b = n;
    if (*e > n)
        *e = n;
}

static void team_slice(bench_team *t, int k)
{
    size_t b, e;
    slice_of(t->n, t->threads, k, &b, &e);
    bench_job_run(t->job, b, e);
}

static void *team_main(void *arg)
{
    bench_worker *w = arg;
    bench_team *t = w->team;
    pthread_mutex_lock(&t->lock);
    while (t->state == 0)
        pthread_cond_wait(&t->gate, &t->lock);
    int go = t->state == 1;
    pthread_mutex_unlock(&t->lock);
    while (go) {
        pthread_barrier_wait(&t->start);
        if (t->quit)
            break;
        team_slice(t, w->index);
        pthread_barrier_wait(&t->done);
    }
    return NULL;
}

int bench_team_threads(const bench_team *t) { return t->threads; }

static void open_gate(bench_team *t, int state)
{
    pthread_mutex_lock(&t->lock);
    t->state = state;
    pthread_cond_broadcast(&t->gate);
    pthread_mutex_unlock(&t->lock);
}

static void team_free(bench_team *t)
{
    if (t->threads > 1) {
        pthread_barrier_destroy(&t->start);
        pthread_barrier_destroy(&t->done);
        pthread_mutex_destroy(&t->lock);
        pthread_cond_destroy(&t->gate);
    }
    free(t->tid);
    free(t->workers);
    free(t);
}

bench_team *bench_team_start(int threads)
{
    bench_team *t = calloc(1, sizeof *t);
    if (!t)
        return NULL;
    if (threads <= 1) {
        t->threads = 1;
        return t;
    }
    t->tid = calloc((size_t)threads, sizeof *t->tid);
    t->workers = calloc((size_t)threads, sizeof *t->workers);
    if (!t->tid || !t->workers || pthread_barrier_init(&t->start, NULL, (unsigned)threads)) {
        free(t->tid), free(t->workers), free(t);
        return NULL;
    }
    pthread_barrier_init(&t->done, NULL, (unsigned)threads);
    pthread_mutex_init(&t->lock, NULL);
    pthread_cond_init(&t->gate, NULL);
    t->threads = threads;
    for (int k = 1; k < threads; k++) {
        t->workers[k].team = t;
        t->workers[k].index = k;
        if (pthread_create(&t->tid[k], NULL, team_main, &t->workers[k]) != 0) {
            open_gate(t, 2);
            for (int j = 1; j < k; j++)
                pthread_join(t->tid[j], NULL);
            team_free(t);
            return NULL;
        }
    }
    open_gate(t, 1);
    return t;
}

void bench_team_stop(bench_team *t)
{
    if (!t)
        return;
    if (t->threads > 1) {
        t->quit = 1;
        pthread_barrier_wait(&t->start);
        for (int k = 1; k < t->threads; k++)
            pthread_join(t->tid[k], NULL);
    }
    team_free(t);
}

/* ---- timing ---- */

static double clock_seconds(clockid_t id)
{
    struct timespec ts;
    if (clock_gettime(id, &ts) != 0)
        return 0.0;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Seconds for one run of `job` over [0, n) split across the team (threads == 1
 * runs inline). The barriers make the interval end when the slowest slice does. */
static double team_time(bench_team *t, int threads, const bench_job *job, size_t n)
{
    double t0 = clock_seconds(CLOCK_MONOTONIC);
    if (threads <= 1 || bench_is_mesh(job->kernel)) { /* a mesh row threads inside */
        bench_job_run(job, 0, n);
    } else {
        t->job = job;
        t->n = n;
        pthread_barrier_wait(&t->start);
        team_slice(t, 0);
        pthread_barrier_wait(&t->done);
    }
    return clock_seconds(CLOCK_MONOTONIC) - t0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median of v[0..n-1], sorting v. */
static double median_of(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void bench_measure(bench_team *team, int threads, const bench_job *job, size_t n, int runs,
                   double *rate, bgt_bench_row *row)
{
    /* Warm-up on a part of the batch: faults in code, tables and the frequency
     * ramp without paying a full slow run of the scalar kernels. */
    size_t warm = n / 8 > 4096 ? n / 8 : n;
    (void)team_time(team, threads, job, warm);
    double wall = 0.0, cpu = 0.0;
    /* rate[0..runs-1]: M samples/s of each run; rate[runs..2 runs-1]: its CPU
     * seconds (the caller gives room for 2 x runs). */
    double *cpu_run = rate + runs;
    for (int r = 0; r < runs; r++) {
        double c0 = clock_seconds(CLOCK_PROCESS_CPUTIME_ID);
        double s = team_time(team, threads, job, n);
        cpu_run[r] = clock_seconds(CLOCK_PROCESS_CPUTIME_ID) - c0;
        cpu += cpu_run[r];
        wall += s;
        /* A timer granularity floor keeps a tiny sample count from dividing by 0. */
        rate[r] = (double)n / (s > 1e-9 ? s : 1e-9) / 1e6;
    }
    double cpu_med = median_of(cpu_run, runs);
    row->cpu_ns = cpu_med > 0 ? 1e9 * cpu_med / (double)n : 0.0;
    row->median = median_of(rate, runs);
    row->min = rate[0];
    row->max = rate[runs - 1];
    row->threads = threads;
    row->cpu_share = wall > 0 && cpu > 0 ? cpu / (wall * threads) : 0.0;
}

/* The 1-minute load average, or -1 where /proc/loadavg does not exist: reported
 * with the rows because a median taken on a busy machine is not the machine's
 * speed, and the reader should see that without guessing. */
double bench_load_average(void)
{
    double la = -1.0;
    FILE *fp = fopen("/proc/loadavg", "r");
    if (fp) {
        if (fscanf(fp, "%lf", &la) != 1)
            la = -1.0;
        fclose(fp);
    }
    return la;
}
