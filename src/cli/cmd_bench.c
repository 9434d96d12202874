/* SPDX-License-Identifier: MIT */
/* `bumpgrad bench`: throughput of every batch kernel on every ISA this machine
 * has, with one thread and with N threads, next to peer noise libraries measured
 * in the same run (docs/PERFORMANCE.md explains the method and keeps the
 * numbers). A benchmark only: it checks nothing and its exit status says only
 * whether it could run. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "bench_peers.h"
#include "cli.h"
#include "kernels/kernels.h"

#define BENCH_CMD "bench"
#define BENCH_DEFAULT_SAMPLES ((size_t)1 << 22)
#define BENCH_QUICK_SAMPLES ((size_t)1 << 18)
/* Median of an odd count, and at least 5 runs by default, so that one
 * preempted run on a shared machine moves neither the median nor the verdict. */
#define BENCH_DEFAULT_RUNS 7
#define BENCH_QUICK_RUNS 5
#define BENCH_MAX_RUNS 1000
/* Points are random in [-BOX, BOX]^3, not on a grid: consecutive samples share no
 * lattice cell, so no kernel profits from a coherence the test alone would have,
 * and negative and positive cells both go through the floor/wrap path. */
#define BENCH_BOX 64.0f
#define BENCH_SEED UINT64_C(0x62756d7067726164) /* "bumpgrad" */
#define BENCH_MAX_PEERS 16
/* Thread slices start on multiples of this many points: a 64-byte line of every
 * array, and a whole number of vectors for every ISA, so threads neither share
 * output cache lines nor split a vector into a scalar tail in the middle. */
#define BENCH_SLICE_ALIGN 64

/* ---- what is measured ------------------------------------------------------ */

enum {
    K_NOISE3,
    K_NOISE3_GRAD,
    K_FBM3_GRAD,
    K_TURB3_GRAD,
    K_TURB3_GRAD_CENTRAL,
    K_PERTURB_SURFGRAD,
    K_PERTURB_ADDITIVE,
    K_PERTURB_HEIGHT,
    K_COUNT
};

typedef struct kernel_info {
    const char *name;
    int peer_op; /* cli_peer_op of the comparable peer operation, -1 if none */
    const char *what;
} kernel_info;

/* Comparable peer operation: the peers have no analytic gradient, so our value +
 * gradient kernels are set against their value + 7-evaluation gradient; our
 * fractal kernels, which also return a gradient, against their fBm value alone
 * (so that ratio understates ours). */
static const kernel_info kernels[K_COUNT] = {
    {"noise3", CLI_PEER_VALUE, "improved noise value"},
    {"noise3_grad", CLI_PEER_GRAD_CENTRAL, "value + analytic gradient"},
    {"fbm3_grad", CLI_PEER_FBM, "6-octave fBm + analytic gradient"},
    {"turbulence3_grad", CLI_PEER_FBM, "6-octave turbulence + analytic gradient"},
    {"turbulence3_grad_central", -1, "6-octave turbulence + central gradient (7 evaluations)"},
    {"perturb_surfgrad", -1, "normalize(n - (g - n(n.g))), Listing 3, SoA"},
    {"perturb_additive", -1, "normalize(n - g), SoA"},
    {"perturb_height", -1, "fused 6-octave turbulence gradient -> surfgrad normal"},
};

static const char *const peer_op_names[] = {"value", "fbm", "grad_central"};

/* The input and output arrays, SoA, allocated once for the largest batch. */
typedef struct bench_data {
    size_t n;
    float *px, *py, *pz; /* positions */
    float *nx, *ny, *nz; /* unit normals */
    float *gx, *gy, *gz; /* volume gradients fed to the perturb kernels */
    float *v, *ox, *oy, *oz;
    float *arrays[13];
} bench_data;

/* One measured row: our kernel on one ISA table, or one peer. */
typedef struct bench_job {
    const bench_data *d;
    const bg_kernel_table *t; /* NULL for a peer */
    int kernel;
    const cli_peer *peer;
    bg_fractal fbm, turb;
    bg_height height;
    float step;
} bench_job;

static void job_run(const bench_job *j, size_t b, size_t e)
{
    const bench_data *d = j->d;
    size_t n = e - b;
    if (n == 0)
        return;
    if (j->peer) {
        j->peer->run(d->px + b, d->py + b, d->pz + b, n, d->v + b, d->ox + b, d->oy + b, d->oz + b);
        return;
    }
    const bg_kernel_table *t = j->t;
    switch (j->kernel) {
    case K_NOISE3: t->noise3(d->px + b, d->py + b, d->pz + b, n, d->v + b); break;
    case K_NOISE3_GRAD:
        t->noise3_grad(d->px + b, d->py + b, d->pz + b, n, d->v + b, d->ox + b, d->oy + b,
                       d->oz + b);
        break;
    case K_FBM3_GRAD:
    case K_TURB3_GRAD:
        t->fractal3_grad(j->kernel == K_FBM3_GRAD ? &j->fbm : &j->turb, d->px + b, d->py + b,
                         d->pz + b, n, d->v + b, d->ox + b, d->oy + b, d->oz + b);
        break;
    case K_TURB3_GRAD_CENTRAL:
        t->fractal3_grad_central(&j->turb, j->step, d->px + b, d->py + b, d->pz + b, n, d->v + b,
                                 d->ox + b, d->oy + b, d->oz + b);
        break;
    case K_PERTURB_SURFGRAD:
    case K_PERTURB_ADDITIVE:
        t->perturb(j->kernel == K_PERTURB_SURFGRAD ? BG_PERTURB_SURFGRAD : BG_PERTURB_ADDITIVE,
                   d->nx + b, d->ny + b, d->nz + b, d->gx + b, d->gy + b, d->gz + b, n, d->ox + b,
                   d->oy + b, d->oz + b);
        break;
    case K_PERTURB_HEIGHT:
        t->perturb_height(&j->height, BG_PERTURB_SURFGRAD, d->px + b, d->py + b, d->pz + b,
                          d->nx + b, d->ny + b, d->nz + b, n, d->v + b, d->ox + b, d->oy + b,
                          d->oz + b);
        break;
    default: break;
    }
}

/* ---- threads ------------------------------------------------------------------
 * A team that lives for the whole command, so that a timed run pays two barrier
 * crossings and no thread creation; the caller is worker 0. The library batch
 * calls are single-threaded and reentrant, so each worker calls the kernel on its
 * own contiguous slice. (bgt_parallel_for would create threads per call and
 * chooses its own chunking; here the timed region must be just the work.) */
typedef struct bench_team {
    int threads;
    pthread_t *tid;
    pthread_barrier_t start, done;
    const bench_job *job; /* published before `start`, read after it */
    size_t n;
    int quit;
} bench_team;

typedef struct bench_worker {
    bench_team *team;
    int index;
} bench_worker;

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
    job_run(t->job, b, e);
}

static void *team_main(void *arg)
{
    bench_worker *w = arg;
    bench_team *t = w->team;
    for (;;) {
        pthread_barrier_wait(&t->start);
        if (t->quit)
            break;
        team_slice(t, w->index);
        pthread_barrier_wait(&t->done);
    }
    return NULL;
}

static bench_worker *team_workers;

static int team_start(bench_team *t, int threads)
{
    memset(t, 0, sizeof *t);
    t->threads = threads;
    if (threads <= 1)
        return 0;
    t->tid = calloc((size_t)threads, sizeof *t->tid);
    team_workers = calloc((size_t)threads, sizeof *team_workers);
    if (!t->tid || !team_workers)
        return -1;
    if (pthread_barrier_init(&t->start, NULL, (unsigned)threads) ||
        pthread_barrier_init(&t->done, NULL, (unsigned)threads))
        return -1;
    for (int k = 1; k < threads; k++) {
        team_workers[k].team = t;
        team_workers[k].index = k;
        /* Fatal: the workers already started wait on a barrier sized for all
         * of them; the command exits with an error and takes them along. */
        if (pthread_create(&t->tid[k], NULL, team_main, &team_workers[k]) != 0)
            return -1;
    }
    return 0;
}

static void team_stop(bench_team *t)
{
    if (t->threads > 1) {
        t->quit = 1;
        pthread_barrier_wait(&t->start);
        for (int k = 1; k < t->threads; k++)
            pthread_join(t->tid[k], NULL);
        pthread_barrier_destroy(&t->start);
        pthread_barrier_destroy(&t->done);
    }
    free(t->tid);
    free(team_workers);
    team_workers = NULL;
}

static double clock_seconds(clockid_t id)
{
    struct timespec ts;
    if (clock_gettime(id, &ts) != 0)
        return 0.0;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double now_seconds(void)
{
    return clock_seconds(CLOCK_MONOTONIC);
}

/* Seconds for one run of `job` over [0, n) split across the team (threads == 1
 * runs inline). The barriers make the interval end when the slowest slice does. */
static double team_time(bench_team *t, int threads, const bench_job *job, size_t n)
{
    double t0 = now_seconds();
    if (threads <= 1) {
        job_run(job, 0, n);
    } else {
        t->job = job;
        t->n = n;
        pthread_barrier_wait(&t->start);
        team_slice(t, 0);
        pthread_barrier_wait(&t->done);
    }
    return now_seconds() - t0;
}

/* ---- results ----------------------------------------------------------------- */

typedef struct bench_row {
    char name[64];
    const char *isa; /* ISA name, or "baseline" for peers (built with the default target) */
    int kernel;      /* K_*, or -1 for a peer */
    int peer_op;     /* for a peer */
    int threads;
    double median, min, max; /* M samples/s over the runs */
    /* CPU time the process got over wall time x threads, summed over the runs:
     * about 1 on a quiet machine, 0.5 when another job took half the cores. The
     * workers of an idle team sleep in the barrier and use none. */
    double cpu_share;
} bench_row;

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void measure(bench_team *team, int threads, const bench_job *job, size_t n, int runs,
                    double *rate, bench_row *row)
{
    /* Warm-up on a part of the batch: faults in code, tables and the frequency
     * ramp without paying a full slow run of the scalar kernels. */
    size_t warm = n / 8 > 4096 ? n / 8 : n;
    (void)team_time(team, threads, job, warm);
    double wall = 0.0, cpu0 = clock_seconds(CLOCK_PROCESS_CPUTIME_ID);
    for (int r = 0; r < runs; r++) {
        double s = team_time(team, threads, job, n);
        wall += s;
        /* A timer granularity floor keeps a tiny --samples from dividing by 0. */
        rate[r] = (double)n / (s > 1e-9 ? s : 1e-9) / 1e6;
    }
    qsort(rate, (size_t)runs, sizeof *rate, cmp_double);
    row->min = rate[0];
    row->max = rate[runs - 1];
    row->median = runs % 2 ? rate[runs / 2] : 0.5 * (rate[runs / 2 - 1] + rate[runs / 2]);
    row->threads = threads;
    double cpu = clock_seconds(CLOCK_PROCESS_CPUTIME_ID) - cpu0;
    row->cpu_share = wall > 0 && cpu > 0 ? cpu / (wall * threads) : 0.0;
}

/* ---- inputs ---------------------------------------------------------------------- */

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

static void data_free(bench_data *d)
{
    for (size_t k = 0; k < sizeof d->arrays / sizeof d->arrays[0]; k++)
        free(d->arrays[k]);
    memset(d, 0, sizeof *d);
}

static int data_init(bench_data *d, size_t n)
{
    float **slots[13] = {&d->px, &d->py, &d->pz, &d->nx, &d->ny, &d->nz, &d->gx,
                         &d->gy, &d->gz, &d->v,  &d->ox, &d->oy, &d->oz};
    memset(d, 0, sizeof *d);
    d->n = n;
    for (size_t k = 0; k < 13; k++) {
        /* 64-byte alignment so that the slices of every thread start on a line. */
        void *p = NULL;
        if (posix_memalign(&p, 64, n * sizeof(float)) != 0) {
            data_free(d);
            return -1;
        }
        /* Touch every page now: page faults must not land in the first timed run. */
        memset(p, 0, n * sizeof(float));
        d->arrays[k] = p;
        *slots[k] = p;
    }
    uint64_t s = BENCH_SEED;
    for (size_t i = 0; i < n; i++) {
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
    return 0;
}

/* ---- selection: --kernels ------------------------------------------------------ */

typedef struct bench_sel {
    int ours[K_COUNT];
    int peers[BENCH_MAX_PEERS];
} bench_sel;

static int select_token(const char *tok, bench_sel *sel, const cli_peer *peers, size_t npeers)
{
    int hit = 0;
    if (strcmp(tok, "all") == 0 || strcmp(tok, "ours") == 0)
        for (int k = 0; k < K_COUNT; k++)
            sel->ours[k] = hit = 1;
    for (int k = 0; k < K_COUNT; k++)
        if (strcmp(tok, kernels[k].name) == 0)
            sel->ours[k] = hit = 1;
    /* "peers", "peer:<library>" or "peer:<library>:<op>". */
    int all_peers = strcmp(tok, "all") == 0 || strcmp(tok, "peers") == 0;
    if (all_peers)
        hit = 1;
    for (size_t p = 0; p < npeers; p++) {
        char full[64];
        snprintf(full, sizeof full, "peer:%s:%s", peers[p].library, peer_op_names[peers[p].op]);
        size_t len = strlen(full) - strlen(peer_op_names[peers[p].op]) - 1;
        if (all_peers || strcmp(tok, full) == 0 ||
            (strncmp(tok, full, len) == 0 && tok[len] == '\0'))
            sel->peers[p] = hit = 1;
    }
    /* A known peer library that is not built in is not a usage error (the note
     * at the end says why it is missing); a misspelt library or operation is. */
    static const char *const known[] = {"stb_perlin", "libnoise", "glm"};
    for (size_t k = 0; !hit && k < sizeof known / sizeof known[0]; k++) {
        size_t len = strlen(known[k]);
        if (strncmp(tok, "peer:", 5) != 0 || strncmp(tok + 5, known[k], len) != 0)
            continue;
        const char *rest = tok + 5 + len;
        hit = rest[0] == '\0';
        for (size_t op = 0; !hit && rest[0] == ':' && op < 3; op++)
            hit = strcmp(rest + 1, peer_op_names[op]) == 0;
    }
    return hit ? 0 : -1;
}

static int parse_kernels(const char *list, bench_sel *sel, const cli_peer *peers, size_t npeers)
{
    memset(sel, 0, sizeof *sel);
    char *copy = malloc(strlen(list) + 1);
    if (!copy)
        return cli_fail(BENCH_CMD, "out of memory");
    strcpy(copy, list);
    int rc = 0, tokens = 0;
    char *save = NULL;
    for (char *tok = strtok_r(copy, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        tokens++;
        if (select_token(tok, sel, peers, npeers) != 0) {
            rc = cli_usage_error(BENCH_CMD,
                                 "--kernels: unknown kernel '%s' (see bumpgrad bench --help)", tok);
            break;
        }
    }
    /* "" or "," would run nothing and still exit 0, like a passing benchmark. */
    if (rc == 0 && tokens == 0)
        rc = cli_usage_error(BENCH_CMD, "--kernels: empty list \"%s\" (see bumpgrad bench --help)",
                             list);
    free(copy);
    return rc;
}

/* ---- output -------------------------------------------------------------------- */

static const bench_row *find_row(const bench_row *rows, size_t nrows, const char *name,
                                 const char *isa, int threads)
{
    for (size_t i = 0; i < nrows; i++)
        if (strcmp(rows[i].name, name) == 0 && strcmp(rows[i].isa, isa) == 0 &&
            rows[i].threads == threads)
            return &rows[i];
    return NULL;
}

static const bench_row *best_peer(const bench_row *rows, size_t nrows, int op)
{
    const bench_row *best = NULL;
    for (size_t i = 0; i < nrows; i++)
        if (rows[i].kernel < 0 && rows[i].peer_op == op && (!best || rows[i].median > best->median))
            best = &rows[i];
    return best;
}

typedef struct row_extra {
    double speedup;   /* over scalar, same kernel and threads; 0 if unknown */
    double scaling;   /* over the same kernel and ISA on one thread; 0 if n/a */
    double vs_peer;   /* over the best comparable peer; 0 if none */
    const char *peer; /* that peer's library */
} row_extra;

static row_extra extra_of(const bench_row *rows, size_t nrows, const bench_row *r)
{
    row_extra x = {0, 0, 0, NULL};
    if (r->kernel < 0)
        return x;
    const bench_row *s = find_row(rows, nrows, r->name, "scalar", r->threads);
    if (s && s->median > 0)
        x.speedup = r->median / s->median;
    if (r->threads > 1) {
        const bench_row *one = find_row(rows, nrows, r->name, r->isa, 1);
        if (one && one->median > 0)
            x.scaling = r->median / one->median;
    }
    int op = kernels[r->kernel].peer_op;
    /* Peers run on one thread, so only one-thread rows are set against them. */
    const bench_row *p = op >= 0 && r->threads == 1 ? best_peer(rows, nrows, op) : NULL;
    if (p && p->median > 0) {
        x.vs_peer = r->median / p->median;
        x.peer = p->name;
    }
    return x;
}

static void json_number(FILE *fp, const char *key, double v)
{
    if (v > 0)
        fprintf(fp, ", \"%s\": %.6g", key, v);
    else
        fprintf(fp, ", \"%s\": null", key);
}

/* One JSON array, one record per line (names contain no characters to escape). */
static void print_json(FILE *fp, const bench_row *rows, size_t nrows, size_t samples, int runs)
{
    fputs("[\n", fp);
    for (size_t i = 0; i < nrows; i++) {
        const bench_row *r = &rows[i];
        row_extra x = extra_of(rows, nrows, r);
        fprintf(fp,
                "  {\"kernel\": \"%s\", \"isa\": \"%s\", \"threads\": %d, \"samples\": %zu, "
                "\"runs\": %d, \"msamples_per_s\": %.6g, \"ns_per_sample\": %.6g, "
                "\"min\": %.6g, \"max\": %.6g",
                r->name, r->isa, r->threads, samples, runs, r->median,
                r->median > 0 ? 1e3 / r->median : 0.0, r->min, r->max);
        json_number(fp, "cpu_share", r->cpu_share);
        json_number(fp, "speedup_vs_scalar", x.speedup);
        json_number(fp, "thread_scaling", x.scaling);
        json_number(fp, "vs_best_peer", x.vs_peer);
        if (x.peer)
            fprintf(fp, ", \"best_peer\": \"%s\"", x.peer);
        else
            fputs(", \"best_peer\": null", fp);
        fprintf(fp, "}%s\n", i + 1 < nrows ? "," : "");
    }
    fputs("]\n", fp);
}

static void print_table(FILE *fp, const bench_row *rows, size_t nrows)
{
    fprintf(fp, "%-30s %-8s %3s %9s %9s %9s  %4s %8s %7s %6s  %s\n", "kernel", "isa", "thr",
            "median", "min", "max", "cpu%", "ns/smp", "x scal", "x thr", "vs best peer");
    int noisy = 0;
    for (size_t i = 0; i < nrows; i++) {
        const bench_row *r = &rows[i];
        row_extra x = extra_of(rows, nrows, r);
        char sp[16] = "-", sc[16] = "-", vp[96] = "";
        if (x.speedup > 0)
            snprintf(sp, sizeof sp, "%.2f", x.speedup);
        if (x.scaling > 0)
            snprintf(sc, sizeof sc, "%.2f", x.scaling);
        if (x.vs_peer > 0)
            snprintf(vp, sizeof vp, "%.2fx %s", x.vs_peer, x.peer);
        /* A spread above 10% of the median flags a row disturbed by other load. */
        int flag = r->median > 0 && (r->max - r->min) > 0.10 * r->median;
        noisy |= flag;
        /* cpu% is capped at 100 for display: thread start-up can tip it a hair over. */
        double share = r->cpu_share > 1.0 ? 1.0 : r->cpu_share;
        fprintf(fp, "%-30s %-8s %3d %9.2f %9.2f %9.2f%c %4.0f %8.2f %7s %6s  %s\n", r->name, r->isa,
                r->threads, r->median, r->min, r->max, flag ? '~' : ' ', 100.0 * share,
                r->median > 0 ? 1e3 / r->median : 0.0, sp, sc, vp);
    }
    fputs(
        "\nM samples/s: median, min and max over the runs; ns/smp = 1000 / median (wall time,\n"
        "all threads); x scal = median / scalar median (same kernel, threads); x thr = median /\n"
        "one-thread median (same kernel, ISA); vs best peer: one-thread median over the fastest\n"
        "peer of the comparable operation (noise3: value; noise3_grad: grad_central;\n"
        "fbm3_grad and turbulence3_grad: fbm value, without a gradient). cpu% = CPU time the\n"
        "process got / (wall time x threads): well below 100 means other jobs shared the cores.\n",
        fp);
    if (noisy)
        fputs(
            "~ : max - min above 10% of the median: the machine was busy, rerun on a quiet one.\n",
            fp);
}

/* The 1-minute load average, or -1 where /proc/loadavg does not exist: printed
 * with the table because a median taken on a busy machine is not the machine's
 * speed, and the reader should see that without guessing. */
static double load_average(void)
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

/* ---- command ------------------------------------------------------------------ */

static void usage(FILE *fp)
{
    fputs("usage: bumpgrad bench [--json] [--threads N] [--isa ISA] [--samples N] [--runs R]\n"
          "                      [--kernels LIST] [--quick]\n"
          "\n"
          "Throughput (M samples/s) of every batch kernel on every ISA this machine has,\n"
          "with one thread and with N threads splitting the batch, and of peer noise\n"
          "libraries (one thread) measured in the same run. Inputs: N random points\n"
          "uniform in [-64,64]^3 with a fixed seed, random unit normals and gradients.\n"
          "Each row is timed R times after a warm-up; the median, min and max are shown.\n"
          "A benchmark: it never fails on slow numbers. See docs/PERFORMANCE.md.\n"
          "\n"
          "  --json          one JSON array on stdout, one record per line, with the keys\n"
          "                  kernel, isa, threads, samples, runs, msamples_per_s (median),\n"
          "                  ns_per_sample, min, max (M samples/s), cpu_share, speedup_vs_scalar,\n"
          "                  thread_scaling, vs_best_peer, best_peer (null when n/a);\n"
          "                  peers have isa \"baseline\" (the build's default target)\n"
          "  --threads N     also measure with N threads (default: all cores; 1: one thread only)\n"
          "  --isa ISA       only this ISA: scalar, sse2, avx2, avx512, neon (default: all\n"
          "                  present, up to the cap of bumpgrad --isa or BUMPGRAD_ISA)\n"
          "  --samples N     points per run (default 4194304 = 2^22)\n"
          "  --runs R        timed runs per row (default 7; --quick 5)\n"
          "  --kernels LIST  comma-separated subset (default all): noise3, noise3_grad,\n"
          "                  fbm3_grad, turbulence3_grad, turbulence3_grad_central,\n"
          "                  perturb_surfgrad, perturb_additive, perturb_height, ours, peers,\n"
          "                  peer:<library>, peer:<library>:<value|fbm|grad_central>\n"
          "                  (libraries: stb_perlin, libnoise, glm)\n"
          "  --quick         2^18 points and 5 runs (the meson benchmark); a full run with the\n"
          "                  defaults takes minutes, mostly in the scalar rows\n"
          "  -h, --help      this text\n",
          fp);
}

static size_t collect_peers(cli_peer *peers, const char **missing)
{
    size_t n = 0;
    *missing = NULL;
#if CLI_HAVE_PEER_STB
    n += cli_bench_peers_stb(peers + n, BENCH_MAX_PEERS - n);
#endif
#if CLI_HAVE_PEER_CXX
    n += cli_bench_peers_cxx(peers + n, BENCH_MAX_PEERS - n);
#endif
    int have_stb = 0, have_ln = 0, have_glm = 0;
    for (size_t i = 0; i < n; i++) {
        have_stb |= strcmp(peers[i].library, "stb_perlin") == 0;
        have_ln |= strcmp(peers[i].library, "libnoise") == 0;
        have_glm |= strcmp(peers[i].library, "glm") == 0;
    }
    static char note[160];
    note[0] = '\0';
    if (!have_stb)
        strcat(note, " stb_perlin (libstb-dev)");
    if (!have_ln)
        strcat(note, " libnoise (libnoise-dev, C++)");
    if (!have_glm)
        strcat(note, " glm (libglm-dev, C++)");
    if (note[0])
        *missing = note;
    return n;
}

int cmd_bench(int argc, char **argv)
{
    int json = 0, quick = 0;
    long threads = -1, samples = -1, runs = -1;
    const char *isa_text = NULL, *kernels_text = "all";
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *val = NULL;
        int rc = 0;
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            usage(stdout);
            return CLI_OK;
        } else if (strcmp(a, "--json") == 0) {
            json = 1;
        } else if (strcmp(a, "--quick") == 0) {
            quick = 1;
        } else if (strcmp(a, "--threads") == 0) {
            if (!(rc = cli_need_value(BENCH_CMD, argc, argv, &i, &val)))
                rc = cli_parse_int(BENCH_CMD, a, val, 1, 1024, &threads);
        } else if (strcmp(a, "--samples") == 0) {
            if (!(rc = cli_need_value(BENCH_CMD, argc, argv, &i, &val)))
                rc = cli_parse_int(BENCH_CMD, a, val, 1, 1L << 28, &samples);
        } else if (strcmp(a, "--runs") == 0) {
            if (!(rc = cli_need_value(BENCH_CMD, argc, argv, &i, &val)))
                rc = cli_parse_int(BENCH_CMD, a, val, 1, BENCH_MAX_RUNS, &runs);
        } else if (strcmp(a, "--isa") == 0) {
            rc = cli_need_value(BENCH_CMD, argc, argv, &i, &isa_text);
        } else if (strcmp(a, "--kernels") == 0) {
            rc = cli_need_value(BENCH_CMD, argc, argv, &i, &kernels_text);
        } else {
            return cli_usage_error(BENCH_CMD, "unknown argument '%s' (see bumpgrad bench --help)",
                                   a);
        }
        if (rc)
            return rc;
    }
    size_t n = samples > 0 ? (size_t)samples : quick ? BENCH_QUICK_SAMPLES : BENCH_DEFAULT_SAMPLES;
    int nruns = runs > 0 ? (int)runs : quick ? BENCH_QUICK_RUNS : BENCH_DEFAULT_RUNS;
    int nthreads = threads > 0 ? (int)threads : bgt_threads_default();
    if (nthreads < 1)
        nthreads = 1;

    /* ISAs: all that this build and CPU have, or the one asked for. */
    int isa_on[BG_ISA_COUNT] = {0};
    if (isa_text) {
        bg_isa want;
        if (bg_isa_parse(isa_text, &want) != BG_OK)
            return cli_usage_error(
                BENCH_CMD, "--isa: unknown ISA '%s' (scalar, sse2, avx2, avx512, neon)", isa_text);
        if (!bg_kernels_for(want))
            return cli_usage_error(BENCH_CMD,
                                   "--isa %s: not available in this build on this CPU (best: %s)",
                                   isa_text, bg_isa_name(bg_isa_best()));
        isa_on[want] = 1;
    } else {
        /* Every ISA present, up to the cap of `bumpgrad --isa` / BUMPGRAD_ISA (which
         * set the active level), so that a capped run never measures above it. */
        bg_isa cap = bg_isa_active();
        for (int k = 0; k < BG_ISA_COUNT; k++) {
            int below = k == BG_ISA_SCALAR || k == (int)cap ||
                        (k != BG_ISA_NEON && cap != BG_ISA_NEON && k < (int)cap);
            isa_on[k] = below && bg_kernels_for((bg_isa)k) != NULL;
        }
    }

    cli_peer peers[BENCH_MAX_PEERS];
    const char *missing;
    size_t npeers = collect_peers(peers, &missing);
    bench_sel sel;
    int rc = parse_kernels(kernels_text, &sel, peers, npeers);
    if (rc)
        return rc;

    size_t nrows_max = (size_t)K_COUNT * BG_ISA_COUNT * 2 + npeers;
    bench_row *rows = calloc(nrows_max, sizeof *rows);
    double *rate = calloc((size_t)nruns, sizeof *rate);
    bench_data d;
    if (!rows || !rate || data_init(&d, n) != 0) {
        free(rows);
        free(rate);
        return cli_fail(BENCH_CMD, "out of memory for %zu samples", n);
    }
    bench_team team;
    if (team_start(&team, nthreads) == -1) {
        data_free(&d);
        free(rows);
        free(rate);
        return cli_fail(BENCH_CMD, "cannot start %d threads", nthreads);
    }
    nthreads = team.threads;

    bench_job job;
    memset(&job, 0, sizeof job);
    job.d = &d;
    job.fbm = bg_fractal_default(BG_FUNC_FBM);
    job.turb = bg_fractal_default(BG_FUNC_TURBULENCE);
    job.height = bg_height_default();
    job.height.step = BG_DEFAULT_CENTRAL_STEP;
    job.step = BG_DEFAULT_CENTRAL_STEP;

    /* Progress goes to stderr, so it never mixes into the table or the JSON. */
    int show = isatty(fileno(stderr));
    double load_before = load_average();
    size_t nrows = 0;
    for (size_t p = 0; p < npeers; p++) {
        if (!sel.peers[p])
            continue;
        bench_row *r = &rows[nrows++];
        snprintf(r->name, sizeof r->name, "peer:%s:%s", peers[p].library,
                 peer_op_names[peers[p].op]);
        r->isa = "baseline";
        r->kernel = -1;
        r->peer_op = (int)peers[p].op;
        if (show)
            fprintf(stderr, "\rmeasuring %-40s", r->name);
        job.t = NULL;
        job.peer = &peers[p];
        measure(&team, 1, &job, n, nruns, rate, r);
    }
    job.peer = NULL;
    for (int k = 0; k < K_COUNT; k++) {
        if (!sel.ours[k])
            continue;
        for (int isa = 0; isa < BG_ISA_COUNT; isa++) {
            if (!isa_on[isa])
                continue;
            job.t = bg_kernels_for((bg_isa)isa);
            job.kernel = k;
            for (int pass = 0; pass < (nthreads > 1 ? 2 : 1); pass++) {
                bench_row *r = &rows[nrows++];
                snprintf(r->name, sizeof r->name, "%s", kernels[k].name);
                r->isa = bg_isa_name((bg_isa)isa);
                r->kernel = k;
                r->peer_op = -1;
                if (show)
                    fprintf(stderr, "\rmeasuring %-24s %-8s %3d thr", r->name, r->isa,
                            pass ? nthreads : 1);
                measure(&team, pass ? nthreads : 1, &job, n, nruns, rate, r);
            }
        }
    }
    if (show)
        fprintf(stderr, "\r%70s\r", "");
    team_stop(&team);

    if (json) {
        print_json(stdout, rows, nrows, n, nruns);
        if (missing)
            fprintf(stderr, "bumpgrad " BENCH_CMD ": note: peers not built in:%s\n", missing);
    } else {
        char isas[64] = "";
        for (int k = 0; k < BG_ISA_COUNT; k++)
            if (bg_kernels_for((bg_isa)k)) {
                strcat(isas, " ");
                strcat(isas, bg_isa_name((bg_isa)k));
            }
        printf("bumpgrad %s bench: %zu points in [-64,64]^3 (fixed seed), %d runs per row,\n"
               "threads 1 and %d, ISAs on this machine:%s; central step %g; cores online %ld\n",
               bg_version_string(), n, nruns, nthreads, isas, (double)BG_DEFAULT_CENTRAL_STEP,
               sysconf(_SC_NPROCESSORS_ONLN));
        if (load_before >= 0)
            printf("load average (1 min) %.2f before, %.2f after the run\n", load_before,
                   load_average());
        putchar('\n');
        print_table(stdout, rows, nrows);
        if (missing)
            printf("note: peers not built in (library or C++ compiler absent at configure "
                   "time):%s\n",
                   missing);
    }
    data_free(&d);
    free(rows);
    free(rate);
    if (fflush(stdout) != 0 || ferror(stdout))
        return cli_fail(BENCH_CMD, "cannot write the results: %s", strerror(errno));
    return CLI_OK;
}
