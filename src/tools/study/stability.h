/* SPDX-License-Identifier: MIT */
/* Internal interface of the stability study (bgt_stability_run): the output
 * helpers (stability_out.c) and the sweeps (stability_sweeps.c,
 * stability_listing1.c), called by the run (stability.c). Each sweep appends
 * its section to the report, its numbers to the JSON summary, writes its CSV
 * and its chart. */
#ifndef BUMPGRAD_STUDY_STABILITY_H
#define BUMPGRAD_STUDY_STABILITY_H

#include <stddef.h>
#include <stdio.h>
#include "common/safe_file.h"
#include "study_internal.h"

typedef struct st_out {
    const char *dir;
    FILE *md;   /* the report, built in memory order */
    FILE *json; /* summary for tests */
    int chart;
    int json_first;
    const bgt_study_report *report;
    bgt_err *e; /* never NULL */
} st_out;

/* One number of summary.json; NaN and infinities are written as null. */
void st_json_num(st_out *o, const char *key, double v);
/* A section of the study: opens DIR/name (temp + rename on commit), writes the
 * CSV header line, then the section's report text (printf format md_fmt) to
 * o->md; NULL with o->e set on failure. */
FILE *st_csv_begin(st_out *o, const char *name, bgt_safe_file *of, const char *header,
                   const char *md_fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;
/* A gnuplot chart of CSV columns (x column, then y columns), log axes as
 * asked, linked from the report. BG_OK without o->chart. */
bg_status st_chart(st_out *o, const char *name, const char *csv, const char *title,
                   const char *xlabel, const char *ylabel, int logx, int logy, const char *plot);
/* A BG_ERR_OUT_OF_MEMORY failure, for `return st_oom(o);`. */
bg_status st_oom(st_out *o);

/* 1. inward normals against amplitude; 2. the float32 central-difference step;
 * 3. large coordinates; 4. turbulence creases (stability_sweeps.c). */
bg_status st_sweep_inward(st_out *o, size_t n);
bg_status st_sweep_step(st_out *o, size_t n);
bg_status st_sweep_large(st_out *o);
bg_status st_sweep_creases(st_out *o, size_t n);
/* 5. Listing 1 where it fails (stability_listing1.c). */
bg_status st_sweep_listing1(st_out *o, size_t n);

#endif
