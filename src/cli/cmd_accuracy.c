/* SPDX-License-Identifier: MIT */
/* `bumpgrad accuracy`: speed against accuracy of every way to get the perturbed
 * normal n' = normalize(n - grad_S h) (Mikkelsen 2010, eq. 2 and 4). The study
 * is bgt_accuracy_run (src/tools/study); this file parses, calls and prints. */
#include <stdio.h>
#include <string.h>
#include "cli.h"
#include "study/study_tool.h"

static const char *const CMD = "accuracy";

static void usage(FILE *fp)
{
    fprintf(fp,
            "usage: bumpgrad accuracy [--out DIR] [--samples N] [--runs R] [height options]\n"
            "\n"
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
            "and DIR/accuracy.svg (log-log time against mean error, Pareto front marked).\n"
            "\n"
            "  --out DIR       output folder (default accuracy-output)\n"
            "  --samples N     points (default 65536, multiple of 4)\n"
            "  --runs R        timing runs, median taken (default 5)\n"
            "  --no-chart      skip gnuplot\n"
            "Height options (defaults here: turbulence, 6 octaves, amplitude 0.05, frequency 4):\n");
    cli_height_help(fp);
}

/* The table on stdout, printed when the study reports accuracy.csv in place
 * (its rows are final then), ahead of the chart's lines. */
typedef struct acc_print {
    const bgt_accuracy_result *res;
    int table_done;
} acc_print;

static void print_table(const bgt_accuracy_result *r)
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
    if (!p->table_done)
        print_table(p->res), p->table_done = 1;
    printf("wrote %s\n", path);
}

static void on_gnuplot(void *ctx, const char *text)
{
    (void)ctx;
    fprintf(stderr, "gnuplot: %s", text);
}

int cmd_accuracy(int argc, char **argv)
{
    const char *out_dir = "accuracy-output";
    long samples = 65536, runs = 5;
    int chart = 1;
    bgt_height ch;
    bgt_height_init(&ch);
    ch.h.amplitude = 0.05f;
    ch.h.frequency = 4.0f;
    for (int i = 1; i < argc; i++) {
        const char *v;
        int r = cli_height_option(CMD, &ch, argc, argv, &i);
        if (r == 1)
            continue;
        if (r != 0)
            return r;
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            usage(stdout);
            return CLI_OK;
        } else if (!strcmp(argv[i], "--out")) {
            if ((r = cli_need_value(CMD, argc, argv, &i, &v)))
                return r;
            out_dir = v;
        } else if (!strcmp(argv[i], "--samples")) {
            if ((r = cli_need_value(CMD, argc, argv, &i, &v)) ||
                (r = cli_parse_int(CMD, "--samples", v, 4, 1L << 26, &samples)))
                return r;
        } else if (!strcmp(argv[i], "--runs")) {
            if ((r = cli_need_value(CMD, argc, argv, &i, &v)) ||
                (r = cli_parse_int(CMD, "--runs", v, 1, 15, &runs)))
                return r;
        } else if (!strcmp(argv[i], "--no-chart")) {
            chart = 0;
        } else {
            return cli_usage_error(CMD, "unknown option '%s' (see bumpgrad accuracy --help)", argv[i]);
        }
    }
    if (ch.grid_path)
        return cli_usage_error(CMD, "--height-grid is not supported here: the study needs an analytic reference");

    bgt_accuracy_result res;
    acc_print pr = {&res, 0};
    cli_progress prog;
    bgt_progress sink = cli_progress_sink(&prog);
    bgt_study_report rep = {on_wrote, on_gnuplot, &pr};
    bgt_accuracy_opts o = {.out_dir = out_dir, .samples = (size_t)(samples & ~3L), .runs = (int)runs,
                           .chart = chart, .height = ch.h, .progress = &sink, .report = &rep};
    bgt_err err;
    return cli_report(CMD, bgt_accuracy_run(&o, &res, &err), &err);
}
