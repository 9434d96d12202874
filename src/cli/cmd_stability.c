/* SPDX-License-Identifier: MIT */
/* `bumpgrad stability`: sweeps that show where each way of bumping a normal
 * fails (markdown report, CSV tables, gnuplot charts, JSON summary). The
 * study is bgt_stability_run (src/tools/study); this file parses, calls and
 * prints. */
#include <stdio.h>
#include <string.h>
#include "args.h"
#include "cli.h"
#include "study/study.h"

static const char *const CMD = "stability";

typedef struct stability_args {
    const char *out_dir;
    int samples, no_chart;
} stability_args;

static void stability_defaults(void *p)
{
    stability_args *a = p;
    a->out_dir = "stability-output";
    a->samples = 20000;
    a->no_chart = 0;
}

#define A(m) offsetof(stability_args, m)
static const cli_opt stability_opts[] = {
    {.name = "out", .kind = CLI_KIND_STRING, .offset = A(out_dir), .metavar = "DIR",
     .help = "output folder", .flags = CLI_DIR},
    {.name = "samples", .kind = CLI_KIND_INT, .offset = A(samples), .metavar = "N",
     .help = "points per sweep", .lo = 100, .hi = 10000000},
    {.name = "no-chart", .kind = CLI_KIND_FLAG, .offset = A(no_chart), .help = "skip gnuplot"},
    CLI_OPT_END,
};
#undef A

CLI_SPEC(stability,
    .summary = "sweeps where bump methods fail: markdown report, CSVs, charts",
    .usage = "[--out DIR] [--samples N] [--no-chart]",
    .about =
        "Sweeps where bump-mapping methods fail and writes DIR/STABILITY.md (the report),\n"
        "one CSV and one PNG chart per sweep (gnuplot), and DIR/summary.json:\n"
        "  1. inward normals of additive vs surface gradient as the amplitude grows 0.1..10\n"
        "  2. the float32 central-difference step U-curve and its optimum\n"
        "  3. large coordinates 1e3..1e8: float vs double entry points\n"
        "  4. turbulence creases: analytic vs central near octave zero crossings\n"
        "  5. Listing 1 at grazing angles, as det -> 0, across silhouettes\n"
        "  6. degenerate inputs (zero, NaN, Inf, non-unit normals, huge gradients)\n",
    .opts = stability_opts,
);

static void on_wrote(void *ctx, const char *path)
{
    (void)ctx;
    if (!cli_quiet())
        printf("wrote %s\n", path);
}

/* After the charts' lines: where the report and the summary are. */
static void print_text(const char *out_dir)
{
    printf("wrote %s/STABILITY.md and %s/summary.json\n", out_dir, out_dir);
}

static int run_stability(void *args, const char *const *pos, int npos)
{
    (void)pos, (void)npos;
    stability_args a = *(stability_args *)args;
    cli_progress prog;
    bgt_progress sink = cli_progress_sink(&prog);
    bgt_study_report rep = {on_wrote, cli_study_gnuplot, NULL};
    bgt_stability_opts o = {.out_dir = a.out_dir, .samples = (size_t)a.samples,
                            .chart = !a.no_chart, .progress = &sink, .report = &rep};
    bgt_err err;
    bg_status s = bgt_stability_run(&o, &err);
    if (s == BG_OK && !cli_quiet())
        print_text(a.out_dir);
    return cli_report(CMD, s, &err);
}
