/* SPDX-License-Identifier: MIT */
/* Split [0, n) into chunks over worker threads (parallel.c). */
#ifndef BUMPGRAD_TOOLS_PARALLEL_H
#define BUMPGRAD_TOOLS_PARALLEL_H

#include <stddef.h>

/* The number of online cores, clamped to [1, 256]. */
int bgt_threads_default(void);
/* fn(ctx, begin, end, worker) is called for disjoint ranges covering [0, n),
 * from `threads` workers (0 = all cores; the caller is worker 0). Results must
 * not depend on which worker runs a chunk. */
void bgt_parallel_for(size_t n, size_t chunk, int threads,
                      void (*fn)(void *ctx, size_t begin, size_t end, int worker), void *ctx);

#endif
