/* SPDX-License-Identifier: MIT */
/* A minimal parallel-for over pthreads. Workers take chunks from a shared atomic
 * counter instead of fixed slices: fractal cost varies little per point, but the
 * machine may be shared, and a slow worker then just takes fewer chunks. Every
 * point is computed by the same kernel whichever worker runs it, so results do
 * not depend on the thread count. */
#define _POSIX_C_SOURCE 200809L
#include "parallel.h"
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <unistd.h>

int bgt_threads_default(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    if (n < 1)
        return 1;
    return n > 256 ? 256 : (int)n;
}

typedef struct job {
    size_t n, chunk;
    atomic_size_t next;
    void (*fn)(void *ctx, size_t begin, size_t end, int worker);
    void *ctx;
} job;

typedef struct worker_arg {
    job *j;
    int id;
} worker_arg;

static void run_chunks(job *j, int id)
{
    for (;;) {
        size_t b = atomic_fetch_add(&j->next, j->chunk);
        if (b >= j->n)
            return;
        size_t e = j->n - b < j->chunk ? j->n : b + j->chunk;
        j->fn(j->ctx, b, e, id);
    }
}

static void *worker_main(void *p)
{
    worker_arg *a = p;
    run_chunks(a->j, a->id);
    return NULL;
}

void bgt_parallel_for(size_t n, size_t chunk, int threads,
                      void (*fn)(void *ctx, size_t begin, size_t end, int worker), void *ctx)
{
    if (n == 0)
        return;
    if (chunk == 0)
        chunk = 1;
    if (threads <= 0)
        threads = bgt_threads_default();
    size_t nchunks = (n + chunk - 1) / chunk;
    if ((size_t)threads > nchunks)
        threads = (int)nchunks;
    job j = {.n = n, .chunk = chunk, .fn = fn, .ctx = ctx};
    atomic_init(&j.next, 0);
    if (threads <= 1) {
        run_chunks(&j, 0);
        return;
    }
    pthread_t *tid = malloc(sizeof *tid * (size_t)threads);
    worker_arg *args = malloc(sizeof *args * (size_t)threads);
    int started = 0;
    if (tid && args) {
        /* The calling thread is worker 0; the others are 1..threads-1. */
        for (int t = 1; t < threads; t++) {
            args[t].j = &j;
            args[t].id = t;
            if (pthread_create(&tid[t], NULL, worker_main, &args[t]) != 0)
                break; /* fewer workers: the chunks still all get done */
            started = t;
        }
    }
    run_chunks(&j, 0);
    for (int t = 1; t <= started; t++)
        pthread_join(tid[t], NULL);
    free(tid);
    free(args);
}
