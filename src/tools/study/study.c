/* SPDX-License-Identifier: MIT */
#define _POSIX_C_SOURCE 200809L
#include "study_internal.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include "common/safe_file.h"

static uint64_t splitmix(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

double study_random01(uint64_t *state)
{
    return (double)(splitmix(state) >> 11) * (1.0 / 9007199254740992.0);
}

void study_random_unit(uint64_t *state, double v[3])
{
    /* Archimedes: z uniform in [-1, 1] and a uniform angle give a uniform sphere. */
    double z = 2 * study_random01(state) - 1, a = 2 * 3.14159265358979323846 * study_random01(state);
    double r = sqrt(fmax(0.0, 1 - z * z));
    v[0] = r * cos(a), v[1] = r * sin(a), v[2] = z;
}

void study_tangent_basis(const double n[3], double t1[3], double t2[3])
{
    /* Cross with the axis least aligned with n, so the tangent never degenerates. */
    double a[3] = {0, 0, 0};
    double ax = fabs(n[0]), ay = fabs(n[1]), az = fabs(n[2]);
    a[ax <= ay && ax <= az ? 0 : ay <= az ? 1 : 2] = 1;
    t1[0] = n[1] * a[2] - n[2] * a[1], t1[1] = n[2] * a[0] - n[0] * a[2],
    t1[2] = n[0] * a[1] - n[1] * a[0];
    double l = sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
    t1[0] /= l, t1[1] /= l, t1[2] /= l;
    t2[0] = n[1] * t1[2] - n[2] * t1[1], t2[1] = n[2] * t1[0] - n[0] * t1[2],
    t2[2] = n[0] * t1[1] - n[1] * t1[0];
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

void study_percentiles(double *v, size_t n, double q, double *quantile, double *max)
{
    qsort(v, n, sizeof *v, cmp_double);
    size_t k = (size_t)ceil(q * (double)n);
    k = k == 0 ? 0 : k - 1;
    *quantile = n ? v[k < n ? k : n - 1] : NAN;
    *max = n ? v[n - 1] : NAN;
}

double study_median(double *v, size_t n)
{
    qsort(v, n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double study_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

bg_status study_mkdir(const char *dir, bgt_err *e)
{
    if (mkdir(dir, 0777) == 0 || errno == EEXIST) {
        struct stat st;
        if (stat(dir, &st) == 0 && S_ISDIR(st.st_mode))
            return BG_OK;
        return bgt_fail(e, BG_ERR_IO, "%s exists and is not a folder", dir);
    }
    return bgt_fail(e, BG_ERR_IO, "cannot create folder %s: %s", dir, strerror(errno));
}

char *study_join(const char *dir, const char *name)
{
    size_t n = strlen(dir) + strlen(name) + 2;
    char *p = malloc(n);
    if (p)
        snprintf(p, n, "%s/%s", dir, name);
    return p;
}

bg_status study_gnuplot(const char *script_path, const char *const *outputs_tmp,
                        const char *const *outputs, int count, const bgt_study_report *rep,
                        bgt_err *e)
{
    size_t n = strlen(script_path) + 64;
    char *line = malloc(n);
    if (!line)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    snprintf(line, n, "gnuplot '%s' 2>&1", script_path);
    FILE *p = popen(line, "r");
    free(line);
    if (!p)
        return bgt_fail(e, BG_ERR_IO, "cannot run gnuplot: %s", strerror(errno));
    char buf[512];
    int passed = 0;
    while (fgets(buf, sizeof buf, p)) {
        /* gnuplot warns about points it cannot draw on log axes; pass messages on. */
        if (passed++ < 20 && rep && rep->gnuplot_output)
            rep->gnuplot_output(rep->ctx, buf);
    }
    int st = pclose(p);
    if (st == -1 || !WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        for (int k = 0; k < count; k++)
            remove(outputs_tmp[k]);
        if (st != -1 && WIFEXITED(st) && WEXITSTATUS(st) == 127)
            return bgt_fail(e, BG_ERR_IO, "gnuplot not found (install gnuplot-nox; scripts/setup does)");
        return bgt_fail(e, BG_ERR_IO, "gnuplot failed on %s", script_path);
    }
    for (int k = 0; k < count; k++) {
        bg_status s = bgt_safe_commit_path(outputs_tmp[k], outputs[k], e);
        if (s != BG_OK) {
            for (int j = k + 1; j < count; j++)
                remove(outputs_tmp[j]);
            return s;
        }
        study_wrote(rep, outputs[k]);
    }
    return BG_OK;
}
