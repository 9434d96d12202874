/* SPDX-License-Identifier: MIT */
/* Helpers shared by the measurement commands (`accuracy`, `stability`):
 * deterministic sampling, statistics, timing, output folders, gnuplot charts. */
#ifndef BUMPGRAD_STUDY_H
#define BUMPGRAD_STUDY_H

#include <stddef.h>
#include <stdint.h>

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
/* mkdir -p for one level; error message names the folder. 0 or CLI_FAIL. */
int study_mkdir(const char *cmd, const char *dir);
/* dir + "/" + name, malloc'd. */
char *study_join(const char *dir, const char *name);
/* Runs gnuplot on `script_path` (which writes to temporary names listed in
 * `outputs_tmp`) and renames each into `outputs`. If gnuplot is missing, says so
 * and returns CLI_FAIL. */
int study_gnuplot(const char *cmd, const char *script_path, const char *const *outputs_tmp,
                  const char *const *outputs, int count);
/* Writes DIR/accuracy.gp from DIR/accuracy.csv and renders PNG and SVG. */
int study_chart_accuracy(const char *cmd, const char *dir);

#endif
