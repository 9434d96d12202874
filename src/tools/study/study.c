/* SPDX-License-Identifier: MIT */
#define _POSIX_C_SOURCE 200809L
#include "study.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include "cli.h"

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

int study_mkdir(const char *cmd, const char *dir)
{
    if (mkdir(dir, 0777) == 0 || errno == EEXIST) {
        struct stat st;
        if (stat(dir, &st) == 0 && S_ISDIR(st.st_mode))
            return 0;
        return cli_fail(cmd, "%s exists and is not a folder", dir);
    }
    return cli_fail(cmd, "cannot create folder %s: %s", dir, strerror(errno));
}

char *study_join(const char *dir, const char *name)
{
    size_t n = strlen(dir) + strlen(name) + 2;
    char *p = malloc(n);
    if (p)
        snprintf(p, n, "%s/%s", dir, name);
    return p;
}

int study_gnuplot(const char *cmd, const char *script_path, const char *const *outputs_tmp,
                  const char *const *outputs, int count)
{
    size_t n = strlen(script_path) + 64;
    char *line = malloc(n);
    snprintf(line, n, "gnuplot '%s' 2>&1", script_path);
    FILE *p = popen(line, "r");
    free(line);
    if (!p)
        return cli_fail(cmd, "cannot run gnuplot: %s", strerror(errno));
    char buf[512];
    int printed = 0;
    while (fgets(buf, sizeof buf, p)) {
        /* gnuplot warns about points it cannot draw on log axes; pass messages on. */
        if (printed++ < 20)
            fprintf(stderr, "gnuplot: %s", buf);
    }
    int st = pclose(p);
    if (st == -1 || !WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        for (int k = 0; k < count; k++)
            remove(outputs_tmp[k]);
        if (WIFEXITED(st) && WEXITSTATUS(st) == 127)
            return cli_fail(cmd, "gnuplot not found (install gnuplot-nox; scripts/setup does)");
        return cli_fail(cmd, "gnuplot failed on %s", script_path);
    }
    for (int k = 0; k < count; k++)
        if (cli_rename_into_place(cmd, outputs_tmp[k], outputs[k]))
            return CLI_FAIL;
        else
            printf("wrote %s\n", outputs[k]);
    return 0;
}

typedef struct pt {
    double t, e;
} pt;

static int cmp_pt(const void *a, const void *b)
{
    const pt *x = a, *y = b;
    return x->t < y->t ? -1 : x->t > y->t;
}

int study_chart_accuracy(const char *cmd, const char *dir)
{
    char *csv = study_join(dir, "accuracy.csv"), *gp = study_join(dir, "accuracy.gp");
    char *png = study_join(dir, "accuracy.png"), *svg = study_join(dir, "accuracy.svg");
    char *png_t = study_join(dir, ".accuracy.tmp.png"), *svg_t = study_join(dir, ".accuracy.tmp.svg");
    int rc = CLI_FAIL;
    FILE *in = fopen(csv, "r");
    if (!in) {
        cli_fail(cmd, "cannot read %s", csv);
        goto done;
    }
    /* The Pareto front: sorted by time, keep each point more accurate than every
     * faster one (mean error, zero-error points drawn at the floor 1e-7). */
    pt pts[128];
    int np = 0;
    char line[512];
    if (!fgets(line, sizeof line, in))
        line[0] = 0;
    while (np < 128 && fgets(line, sizeof line, in)) {
        char m[32] = "", par[32] = "", pr[16] = "";
        double ns, mean;
        if (sscanf(line, "%31[^,],%31[^,],%15[^,],%lf,%lf", m, par, pr, &ns, &mean) == 5 ||
            (sscanf(line, "%31[^,],,%15[^,],%lf,%lf", m, pr, &ns, &mean) == 4 && (par[0] = 0, 1))) {
            pts[np].t = ns, pts[np].e = mean > 1e-7 ? mean : 1e-7;
            np++;
        }
    }
    fclose(in);
    qsort(pts, (size_t)np, sizeof pts[0], cmp_pt);

    cli_outfile of;
    if (cli_outfile_open(cmd, gp, &of))
        goto done;
    FILE *f = of.fp;
    fprintf(f, "# Made by `bumpgrad accuracy`; rerun it to regenerate. Reads accuracy.csv.\n");
    fprintf(f, "$pareto << EOD\n");
    double best = INFINITY;
    for (int k = 0; k < np; k++)
        if (pts[k].e < best) {
            best = pts[k].e;
            fprintf(f, "%g,%g\n", pts[k].t, pts[k].e);
        }
    fprintf(f, "EOD\n");
    fprintf(f, "set datafile separator ','\n"
               "set logscale xy\nset grid\nset format y '%%.0e'\n"
               "set xlabel 'time per sample (ns, one thread)'\n"
               "set ylabel 'mean angle error of n (degrees; exact drawn at 1e-7)'\n"
               "set title 'bumpgrad: speed against accuracy of the perturbed normal'\n"
               "set key outside right top\n"
               "e(c) = (column(c) > 1e-7 ? column(c) : 1e-7)\n"
               "sel(m, p) = (strcol(1) eq m && strcol(3) eq p)\n"
               "lab = '(strcol(1).\" \".strcol(2))'\n");
    const char *body =
        "plot \\\n"
        "  '%s' every ::1 using (sel('analytic','float32') ? $4 : 1/0):(e(5)) with points pt 7 ps 1.6 lc rgb '#d62728' title 'analytic f32', \\\n"
        "  '%s' every ::1 using (sel('analytic','float64') ? $4 : 1/0):(e(5)) with points pt 5 ps 1.4 lc rgb '#8c564b' title 'analytic f64 (reference)', \\\n"
        "  '%s' every ::1 using (sel('central','float32') ? $4 : 1/0):(e(5)) with linespoints pt 9 lc rgb '#1f77b4' title 'central f32 (h sweep)', \\\n"
        "  '%s' every ::1 using (sel('central','float64') ? $4 : 1/0):(e(5)) with linespoints pt 11 lc rgb '#17becf' title 'central f64 (h sweep)', \\\n"
        "  '%s' every ::1 using (sel('forward','float32') ? $4 : 1/0):(e(5)) with points pt 13 lc rgb '#9467bd' title 'forward f32', \\\n"
        "  '%s' every ::1 using (sel('listing1','float32') ? $4 : 1/0):(e(5)) with linespoints pt 6 lc rgb '#2ca02c' title 'Listing 1 (pixel density)', \\\n"
        "  '%s' every ::1 using (sel('truncated','float32') ? $4 : 1/0):(e(5)) with linespoints pt 4 lc rgb '#ff7f0e' title 'fewer octaves', \\\n"
        "  '%s' every ::1 using (sel('fixed-octaves','float32') ? $4 : 1/0):(e(5)) with linespoints pt 8 lc rgb '#7f7f7f' title 'all 6 octaves vs pixel average', \\\n"
        "  '%s' every ::1 using (sel('footprint','float32') ? $4 : 1/0):(e(5)) with linespoints pt 3 ps 1.4 lc rgb '#e377c2' title 'footprint-aware vs pixel average', \\\n"
        "  '%s' every ::1 using 4:(e(5)):(strcol(2)) with labels offset 0.8,0.5 font ',7' notitle, \\\n"
        "  $pareto using 1:2 with steps lw 2 dt 2 lc rgb '#444444' title 'Pareto front'\n";
    fprintf(f, "set terminal pngcairo size 1100,700 noenhanced\nset output '%s'\n", png_t);
    fprintf(f, body, csv, csv, csv, csv, csv, csv, csv, csv, csv, csv);
    fprintf(f, "set terminal svg size 1100,700 noenhanced\nset output '%s'\n", svg_t);
    fprintf(f, body, csv, csv, csv, csv, csv, csv, csv, csv, csv, csv);
    if (cli_outfile_commit(cmd, &of))
        goto done;
    {
        const char *tmp[2] = {png_t, svg_t}, *fin[2] = {png, svg};
        rc = study_gnuplot(cmd, gp, tmp, fin, 2);
    }
done:
    free(csv), free(gp), free(png), free(svg), free(png_t), free(svg_t);
    return rc;
}
