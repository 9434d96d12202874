/* SPDX-License-Identifier: MIT */
/* What the C benchmark programs (kernels/checkkernels.c --bench,
 * cli/csv_bench.c) share: a clock in seconds and the comparison that sorts
 * the runs for their median. Define _POSIX_C_SOURCE 200809L before the first
 * include (clock_gettime). */
#ifndef BUMPGRAD_TESTS_COMMON_TIMING_H
#define BUMPGRAD_TESTS_COMMON_TIMING_H

#include <time.h>

/* Clock C (CLOCK_MONOTONIC, CLOCK_PROCESS_CPUTIME_ID, ...) in seconds. */
static inline double timing_clock_s(clockid_t c)
{
    struct timespec ts;
    clock_gettime(c, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* qsort's ascending order of doubles. */
static inline int timing_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

#endif
