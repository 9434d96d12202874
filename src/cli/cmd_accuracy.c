/* SPDX-License-Identifier: MIT */
/* `bumpgrad accuracy`: speed against accuracy of every way to get the perturbed
 * normal n' = normalize(n - grad_S h) (Mikkelsen 2010, eq. 2 and 4). The study
 * is bgt_accuracy_run (src/tools/study); this file parses, calls and prints. */
#include <stdio.h>
#include <string.h>
#include "args.h"
#include "cli.h"
#include "study/study.h"

static const char *const CMD = "accuracy";

typedef struct accuracy_args {
    const char *out_dir;
    int samples, runs, no_chart;
    bgt_height height;
} accuracy_args;

/* The study's own defaults: a finer, flatter height than the other commands'. */
static void accuracy_defaults(void *p)
{
    accuracy_args *a = p;
    memset(a, 0, sizeof *a);
    a->out_dir = "accuracy-output";
    a->samples = 65536;
    a->runs = 5;
    bgt_height_init(&a->height);
    a->height.h.amplitude = 0.05f;
    a->height.h.frequency = 4.0f;
}

#define A(m) offsetof(accuracy_args, m)
static const cli_opt accuracy_opts[] = {
    {.name = "out", .kind = CLI_KIND_STRING, .offset = A(out_dir), .metavar = "DIR",
     .help = "output folder", .flags = CLI_DIR},
    {.name = "samples", .kind = CLI_KIND_INT, .offset = A(samples), .metavar = "N",
     .help = "points (rounded down to a multiple of 4)", .lo = 4, .hi = 1L << 26},
    {.name = "runs", .kind = CLI_KIND_INT, .offset = A(runs), .metavar = "R",
     .help = "timing runs, median taken", .lo = 1, .hi = 15},
    {.name = "no-chart", .kind = CLI_KIND_FLAG, .offset = A(no_chart), .help = "skip gnuplot"},
    CLI_OPT_INCLUDE(A(height), cli_height_opts,
                    "Height function h(p) = A * F(f * p) (--height-grid is refused here):"),
    CLI_OPT_END,
};
#undef A

CLI_SPEC(accuracy,
    .summary = "speed against accuracy of every gradient method: CSV and a log-log chart",
    .usage = "[--out DIR] [--samples N] [--runs R] [height options]",
    .about =
        "Speed against accuracy of every way to get the perturbed normal\n"
        "n' = normalize(n - grad_S h) (Mikkelsen 2010, eq. 2 and 4) on N points of the\n"
        "unit sphere (normal = position): analytic gradient in float32 (fused SIMD batch,\n"
        "best ISA) and float64; central differences in float32 and float64 over steps\n"
        "1e-7..1e-1; forward differences in float32; Listing 1 on 2x2 pixel quads at\n"
        "several pixel densities; the height truncated to fewer octaves. Error: angle in\n"
        "degrees to the float64 analytic reference normal (mean, p99, max). Time: median\n"
        "of R runs, one thread, ns per sample.\n"
        "Rows `fixed-octaves` and `footprint` (param: pixels per unit) compare all six\n"
        "octaves with footprint-aware octaves (bg_perturb_height_footprint_batch); their\n"
        "error is measured against what the pixel should show: the exact normal averaged\n"
        "over the pixel (6x6 supersampling in double).\n"
        "\n"
        "Writes DIR/accuracy.csv (method,param,precision,ns_per_sample,err_mean_deg,\n"
        "err_p99_deg,err_max_deg), DIR/accuracy.gp and, with gnuplot, DIR/accuracy.png\n"
        "and DIR/accuracy.svg (log-log time against mean error, Pareto front marked).\n",
    .opts = accuracy_opts,
);

/* The table on stdout, printed when the study reports accuracy.csv in place
 * (its rows are final then), ahead of the chart's lines. */
typedef struct acc_print {
    const bgt_accuracy_result *res;
    int table_done;
} acc_print;

static void print_text(const bgt_accuracy_result *r)
{
    printf("%-10s %-8s %-8s %12s %12s %12s %12s\n", "method", "param", "precision", "ns/sample",
           "mean deg", "p99 deg", "max deg");
    for (int k = 0; k < r->nrows; k++) {
        const bgt_accuracy_row *w = &r->rows[k];
        printf("%-10s %-8s %-8s %12.3f %12.3g %12.3g %12.3g\n", w->method, w->param, w->precision,
               w->ns, w->mean, w->p99, w->max);
    }
}

static void on_wrote(void *ctx, const char *path)
{
    acc_print *p = ctx;
    if (cli_quiet())
        return;
    if (!p->table_done)
        print_text(p->res), p->table_done = 1;
    printf("wrote %s\n", path);
}

static int run_accuracy(void *args, const char *const *pos, int npos)
{
    (void)pos, (void)npos;
    accuracy_args a = *(accuracy_args *)args;
    if (a.height.grid_path)
        return cli_usage_error(CMD, "--height-grid is not supported here: the study needs an analytic reference");

    bgt_accuracy_result res;
    acc_print pr = {&res, 0};
    cli_progress prog;
    bgt_progress sink = cli_progress_sink(&prog);
    bgt_study_report rep = {on_wrote, cli_study_gnuplot, &pr};
    bgt_accuracy_opts o = {.out_dir = a.out_dir, .samples = (size_t)a.samples & ~(size_t)3,
                           .runs = a.runs, .chart = !a.no_chart, .height = a.height.h,
                           .progress = &sink, .report = &rep};
    bgt_err err;
    return cli_report(CMD, bgt_accuracy_run(&o, &res, &err), &err);
}
