/* SPDX-License-Identifier: MIT */
/* The studies of `bumpgrad accuracy` and `bumpgrad stability` as tools calls:
 * each samples the library on deterministic points, measures, and writes its
 * tables (CSV, markdown, JSON) and gnuplot charts into a folder, every file
 * through the safe writer (common/safe_file.h). libc, libm and the library
 * only: they work in a build without the I/O tools. Charts need the gnuplot
 * program at run time (a missing gnuplot is BG_ERR_IO). */
#ifndef BUMPGRAD_TOOLS_STUDY_H
#define BUMPGRAD_TOOLS_STUDY_H

#include <stddef.h>
#include "bumpgrad.h"
#include "common/tool.h"

/* What a study tells its caller besides progress; any member may be NULL and
 * so may the whole pointer. */
typedef struct bgt_study_report {
    /* A result file was put in place: accuracy.csv and then each chart image
     * (accuracy); each chart image (stability). Called from the calling thread. */
    void (*wrote)(void *ctx, const char *path);
    /* Text gnuplot printed (warnings about points it cannot draw on log axes),
     * as read, usually one line with its newline; at most 20 per chart. */
    void (*gnuplot_output)(void *ctx, const char *text);
    void *ctx;
} bgt_study_report;

/* ---- accuracy: speed against accuracy of every way to get the perturbed
 * normal (Mikkelsen 2010, eq. 2 and 4) ---- */

/* 43 fixed rows plus one "truncated" row per octave below the count. */
enum { BGT_ACCURACY_MAX_ROWS = 43 + BG_MAX_OCTAVES };

typedef struct bgt_accuracy_row {
    char method[32];       /* analytic, central, forward, truncated, fixed-octaves, footprint, listing1 */
    char param[32];        /* step, octaves or pixel density; "" for analytic */
    const char *precision; /* "float32" or "float64" (static string) */
    double ns;             /* median time per sample, one thread (a timing: varies run to run) */
    double mean, p99, max; /* angle error in degrees */
} bgt_accuracy_row;

typedef struct bgt_accuracy_opts {
    const char *out_dir; /* created if missing (one level) */
    size_t samples;      /* points, a multiple of 4, >= 4 */
    int runs;            /* timing runs (median taken), 1..15 */
    int chart;           /* write accuracy.gp and render it with gnuplot */
    bg_height height;    /* the fractal height; its gradient mode is ignored (analytic reference) */
    const bgt_progress *progress;
    const bgt_study_report *report;
} bgt_accuracy_opts;

typedef struct bgt_accuracy_result {
    bgt_accuracy_row rows[BGT_ACCURACY_MAX_ROWS];
    int nrows;
} bgt_accuracy_result;

/* Measures every method and writes OUT/accuracy.csv (method,param,precision,
 * ns_per_sample,err_mean_deg,err_p99_deg,err_max_deg) and, with o->chart,
 * OUT/accuracy.gp, OUT/accuracy.png and OUT/accuracy.svg. r->rows are final
 * when report->wrote is first called (for accuracy.csv), so a caller can show
 * the table there, ahead of the chart. BG_ERR_INVALID_ARGUMENT (samples, runs,
 * height parameters: "invalid height parameters"), BG_ERR_IO (folder, file,
 * gnuplot), BG_ERR_OUT_OF_MEMORY. */
bg_status bgt_accuracy_run(const bgt_accuracy_opts *o, bgt_accuracy_result *r, bgt_err *e);

/* ---- stability: sweeps where bump-mapping methods fail ---- */

typedef struct bgt_stability_opts {
    const char *out_dir; /* created if missing (one level) */
    size_t samples;      /* points per sweep, >= 1 */
    int chart;           /* one gnuplot chart per sweep */
    const bgt_progress *progress;
    const bgt_study_report *report;
} bgt_stability_opts;

/* Writes OUT/STABILITY.md (the report), OUT/summary.json (the numbers the
 * tests read), one CSV per sweep and, with o->chart, one .gp and .png each.
 * The report and the summary are put in place only when every sweep
 * succeeded. BG_ERR_INVALID_ARGUMENT, BG_ERR_IO, BG_ERR_OUT_OF_MEMORY. */
bg_status bgt_stability_run(const bgt_stability_opts *o, bgt_err *e);

#endif
