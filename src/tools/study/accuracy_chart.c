/* SPDX-License-Identifier: MIT */
/* The chart of `bumpgrad accuracy`: accuracy.gp (time per sample against mean
 * error, log-log, with the Pareto front) rendered to PNG and SVG by gnuplot. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "common/safe_file.h"
#include "study_internal.h"

typedef struct pt {
    double t, e;
    char label[32]; /* the row's parameter (step, density, octaves), "" for none */
} pt;

/* Fixed plot geometry, so the script can place the labels in screen pixels:
 * the canvas, the plot area's edges (fractions of the canvas) and the 7-point
 * label font's cell as pngcairo draws it (measured on the rendered PNG). */
enum { CHART_W = 1100, CHART_H = 700 };
static const double PLOT_L = 0.09, PLOT_R = 0.62, PLOT_B = 0.09, PLOT_T = 0.93;
static const double CHAR_W = 6.0, LABEL_H = 10.0, MARK_R = 6.0;

typedef struct box {
    double x0, y0, x1, y1; /* pixels, y up */
} box;

static int box_hit(const box *a, const box *b)
{
    return a->x0 < b->x1 && b->x0 < a->x1 && a->y0 < b->y1 && b->y0 < a->y1;
}

/* Decades that hold [lo, hi]. */
static void decades(double lo, double hi, double *a, double *b)
{
    *a = pow(10.0, floor(log10(lo)));
    *b = pow(10.0, ceil(log10(hi)));
    if (!(*b > *a))
        *b = *a * 10.0;
}

/* Point labels without overlaps (issue 15: the ones near 90 ns collided):
 * greedy, in order of time then error, each label tries its default place
 * (right of the point, a little above), then steps up and down one label
 * height at a time, then the same on the left of the point; a place is taken
 * when the label's box meets no label placed before, no marker and stays in
 * the plot. A label moved off its default place gets a thin leader line to
 * its point. Writes `set label` / `set arrow` commands. */
static void place_labels(FILE *f, const pt *pts, int np, double x0, double x1, double y0,
                         double y1)
{
    box placed[128], marks[128];
    int nplaced = 0;
    const double L = PLOT_L * CHART_W, R = PLOT_R * CHART_W, B = PLOT_B * CHART_H,
                 T = PLOT_T * CHART_H;
    double sx[128], sy[128];
    for (int k = 0; k < np; k++) {
        sx[k] = L + (log10(pts[k].t) - log10(x0)) / (log10(x1) - log10(x0)) * (R - L);
        sy[k] = B + (log10(pts[k].e) - log10(y0)) / (log10(y1) - log10(y0)) * (T - B);
        marks[k] = (box){sx[k] - MARK_R, sy[k] - MARK_R, sx[k] + MARK_R, sy[k] + MARK_R};
    }
    int tag = 1;
    for (int k = 0; k < np; k++) {
        if (!pts[k].label[0])
            continue;
        const double w = CHAR_W * (double)strlen(pts[k].label) + 2.0;
        box got = {0, 0, 0, 0};
        int found = 0, moved = 0;
        for (int side = 0; side < 2 && !found; side++)
            for (int step = 0; step <= 24 && !found; step++) {
                /* 0, +1, -1, +2, -2, ... label heights from the default place */
                int dy = (step + 1) / 2 * (step % 2 ? 1 : -1);
                double bx = side ? sx[k] - MARK_R - 2 - w : sx[k] + MARK_R - 1;
                double by = sy[k] + 2 + dy * LABEL_H;
                box c = {bx, by, bx + w, by + LABEL_H};
                if (c.x0 < L || c.x1 > R || c.y0 < B || c.y1 > T)
                    continue;
                int clash = 0;
                for (int i = 0; i < nplaced && !clash; i++)
                    clash = box_hit(&c, &placed[i]);
                for (int i = 0; i < np && !clash; i++) /* its own marker it may touch */
                    clash = i != k && box_hit(&c, &marks[i]);
                if (!clash) {
                    got = c, found = 1, moved = side || dy != 0;
                }
            }
        if (!found) /* nowhere free: the default place, overlapping */
            got = (box){sx[k] + MARK_R - 1, sy[k] + 2, sx[k] + MARK_R - 1 + w, sy[k] + 2 + LABEL_H};
        placed[nplaced++] = got;
        fprintf(f, "set label %d '%s' at screen %.5f,%.5f left font ',7' front\n", tag++,
                pts[k].label, (got.x0 + 1) / CHART_W, (got.y0 + 0.5 * LABEL_H) / CHART_H);
        if (moved) {
            /* to the label's nearer vertical edge, at its middle */
            double ex = got.x0 > sx[k] ? got.x0 : got.x1, ey = 0.5 * (got.y0 + got.y1);
            fprintf(f, "set arrow from first %g,%g to screen %.5f,%.5f nohead lw 0.6 lc rgb '#999999' back\n",
                    pts[k].t, pts[k].e, ex / CHART_W, ey / CHART_H);
        }
    }
}

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
            snprintf(pts[np].label, sizeof pts[np].label, "%s", par);
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
               "set lmargin at screen %g\nset rmargin at screen %g\n"
               "set bmargin at screen %g\nset tmargin at screen %g\n",
               PLOT_L, PLOT_R, PLOT_B, PLOT_T);
    if (np > 0) {
        double t0 = INFINITY, t1 = 0, e0 = INFINITY, e1 = 0;
        for (int k = 0; k < np; k++) {
            t0 = fmin(t0, pts[k].t), t1 = fmax(t1, pts[k].t);
            e0 = fmin(e0, pts[k].e), e1 = fmax(e1, pts[k].e);
        }
        if (t0 > 0) {
            decades(t0, t1, &t0, &t1);
            decades(e0, e1, &e0, &e1);
            fprintf(f, "set xrange [%g:%g]\nset yrange [%g:%g]\n", t0, t1, e0, e1);
            place_labels(f, pts, np, t0, t1, e0, e1);
        }
    }
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
        "  $pareto using 1:2 with steps lw 2 dt 2 lc rgb '#444444' title 'Pareto front'\n";
    fprintf(f, "set terminal pngcairo size %d,%d noenhanced\nset output '%s'\n", CHART_W, CHART_H, png_t);
    fprintf(f, body, csv, csv, csv, csv, csv, csv, csv, csv, csv);
    fprintf(f, "set terminal svg size %d,%d noenhanced\nset output '%s'\n", CHART_W, CHART_H, svg_t);
    fprintf(f, body, csv, csv, csv, csv, csv, csv, csv, csv, csv);
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
