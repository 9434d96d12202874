/* SPDX-License-Identifier: MIT */
/* Benchmark of the CSV reader: parse a table of 1M rows "x,y,z" (%.9g floats,
 * written here to a temporary file) with the decimal fast path and with
 * strtof only (the reader before the fast path): the median of 7 interleaved
 * runs each, in process CPU time (the machine may be shared; wall time would
 * measure the load). Instruction counts, which do not depend on the load:
 *   valgrind --tool=callgrind --toggle-collect=run ./csv_bench 1000000 fast
 *   valgrind --tool=callgrind --toggle-collect=run ./csv_bench 1000000 strtof
 * Run: meson test -C BUILD --benchmark csv-parse-1m -v   (or ./csv_bench [ROWS]) */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "common/csv.h"
#include "../common/timing.h"

static double now(void) { return timing_clock_s(CLOCK_PROCESS_CPUTIME_ID); }

static double run(const char *path, size_t *rows_out)
{
    static float a[3][8192];
    float *cols[3] = {a[0], a[1], a[2]};
    static const char *const names[] = {"x", "y", "z"};
    bgt_err e;
    bgt_csv c;
    double t0 = now();
    if (bgt_csv_open(&c, &e, path, 0) || bgt_csv_header(&c, names, 3)) {
        fprintf(stderr, "csv_bench: %s\n", e.msg);
        exit(1);
    }
    size_t total = 0, rows;
    while (bgt_csv_read_float(&c, 3, cols, 8192, &rows) == BG_OK && rows)
        total += rows;
    bgt_csv_close(&c);
    *rows_out = total;
    return now() - t0;
}

int main(int argc, char **argv)
{
    long n = argc > 1 ? atol(argv[1]) : 1000000;
    /* "strtof" or "fast": one parse of that path only (for callgrind
     * --toggle-collect=run, which counts the instructions of run() alone). */
    const char *only = argc > 2 ? argv[2] : NULL;
    if (n < 1 || (only && strcmp(only, "fast") != 0 && strcmp(only, "strtof") != 0)) {
        fprintf(stderr, "usage: csv_bench [ROWS [fast|strtof]]\n");
        return 2;
    }
    char path[] = "/tmp/bumpgrad-csv-bench-XXXXXX";
    int fd = mkstemp(path);
    FILE *fp = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!fp)
        return 1;
    fputs("x,y,z\n", fp);
    unsigned long long s = 88172645463325252ull;
    for (long i = 0; i < n; i++) {
        float v[3];
        for (int k = 0; k < 3; k++) {
            s ^= s << 13, s ^= s >> 7, s ^= s << 17;
            v[k] = (float)((double)(s >> 11) * 0x1p-53 * 40.0 - 20.0);
        }
        fprintf(fp, "%.9g,%.9g,%.9g\n", (double)v[0], (double)v[1], (double)v[2]);
    }
    fclose(fp);
    size_t rows = 0;
    if (only) {
        bgt_csv_fast_path = strcmp(only, "fast") == 0;
        double t = run(path, &rows);
        unlink(path);
        printf("csv parse, %zu rows x 3 floats, %s: %.3f s (%.0f ns/row)\n", rows, only, t,
               1e9 * t / (double)rows);
        return 0;
    }
    /* Interleaved runs, median of each path (the machine may be loaded: the
     * runs alternate so that a burst of load hits both alike). */
    enum { REPS = 7 };
    double ts[2][REPS];
    for (int rep = 0; rep < REPS; rep++)
        for (int fast = 0; fast < 2; fast++) {
            bgt_csv_fast_path = fast;
            ts[fast][rep] = run(path, &rows);
        }
    unlink(path);
    double med[2];
    for (int fast = 0; fast < 2; fast++) {
        qsort(ts[fast], REPS, sizeof ts[fast][0], timing_cmp_double);
        med[fast] = ts[fast][REPS / 2];
    }
    printf("csv parse, %zu rows x 3 floats, median of %d interleaved runs (CPU time): strtof "
           "%.3f s (%.0f ns/row), fast path %.3f s (%.0f ns/row), speed-up %.1fx\n",
           rows, REPS, med[0], 1e9 * med[0] / (double)rows, med[1], 1e9 * med[1] / (double)rows,
           med[0] / med[1]);
    return 0;
}
