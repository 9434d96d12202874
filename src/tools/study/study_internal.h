/* SPDX-License-Identifier: MIT */
/* Inside the studies (the face is study.h): the helpers accuracy.c and
 * stability*.c share: deterministic sampling, statistics, timing, output
 * folders, running gnuplot. */
#ifndef BUMPGRAD_TOOLS_STUDY_INTERNAL_H
#define BUMPGRAD_TOOLS_STUDY_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include "common/tool.h"
#include "study/study.h"

/* A uniformly distributed unit vector from a splitmix64 stream (deterministic). */
void study_random_unit(uint64_t *state, double v[3]);
/* Uniform double in [0, 1). */
double study_random01(uint64_t *state);
/* Two unit tangents orthogonal to unit n (a fixed, continuous-enough choice). */
void study_tangent_basis(const double n[3], double t1[3], double t2[3]);
/* Sorts `v` in place; returns its q-quantile (nearest rank) and its maximum. */
void study_percentiles(double *v, size_t n, double q, double *quantile, double *max);
double study_median(double *v, size_t n);
/* Monotonic time in seconds. */
double study_now(void);
/* mkdir for one level; an existing folder is fine. BG_ERR_IO naming the folder. */
bg_status study_mkdir(const char *dir, bgt_err *e);
/* dir + "/" + name, malloc'd (NULL when out of memory). */
char *study_join(const char *dir, const char *name);
/* Runs gnuplot on `script_path` (which writes to the temporary names
 * `outputs_tmp`), passes its output to rep->gnuplot_output, and puts each
 * temporary in place as `outputs` (bgt_safe_commit_path), reporting each
 * through rep->wrote. A missing gnuplot is BG_ERR_IO and says so. */
bg_status study_gnuplot(const char *script_path, const char *const *outputs_tmp,
                        const char *const *outputs, int count, const bgt_study_report *rep,
                        bgt_err *e);
/* Writes DIR/accuracy.gp from DIR/accuracy.csv and renders PNG and SVG
 * (accuracy_chart.c). */
bg_status study_chart_accuracy(const char *dir, const bgt_study_report *rep, bgt_err *e);

static inline void study_wrote(const bgt_study_report *rep, const char *path)
{
    if (rep && rep->wrote)
        rep->wrote(rep->ctx, path);
}

#endif
