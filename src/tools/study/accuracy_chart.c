/* SPDX-License-Identifier: MIT */
/* The chart of `bumpgrad accuracy`: accuracy.gp (time per sample against mean
 * error, log-log, with the Pareto front) rendered to PNG and SVG by gnuplot. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "common/safe_file.h"
#include "study.h"

typedef struct pt {
    double t, e;
} pt;

static int cmp_pt(const void *a, const void *b)
{
    const pt *x = a, *y = b;
    return x->t < y->t ? -1 : x->t > y->t;
}

bg_status study_chart_accuracy(const char *dir, const bgt_study_report *rep, bgt_err *e)
{
    char *csv = study_join(dir, "accuracy.csv"), *gp = study_join(dir, "accuracy.gp");
    char *png = study_join(dir, "accuracy.png"), *svg = study_join(dir, "accuracy.svg");
    char *png_t = study_join(dir, ".accuracy.tmp.png"), *svg_t = study_join(dir, ".accuracy.tmp.svg");
    bg_status rc = BG_ERR_OUT_OF_MEMORY;
    if (!csv || !gp || !png || !svg || !png_t || !svg_t) {
        bgt_fail(e, rc, "out of memory");
        goto done;
    }
    FILE *in = fopen(csv, "r");
    if (!in) {
        rc = bgt_fail(e, BG_ERR_IO, "cannot read %s", csv);
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

    bgt_safe_file of;
    if ((rc = bgt_safe_open(&of, gp, e)) != BG_OK)
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
    if ((rc = bgt_safe_commit(&of, e)) != BG_OK)
        goto done;
    {
        const char *tmp[2] = {png_t, svg_t}, *fin[2] = {png, svg};
        rc = study_gnuplot(gp, tmp, fin, 2, rep, e);
    }
done:
    free(csv), free(gp), free(png), free(svg), free(png_t), free(svg_t);
    return rc;
}
