/* SPDX-License-Identifier: MIT */
/* `bumpgrad stability`: sweeps that show where each way of bumping a normal
 * fails (markdown report, CSV tables, gnuplot charts, JSON summary). The
 * study is bgt_stability_run (src/tools/study); this file parses, calls and
 * prints. */
#include <stdio.h>
#include <string.h>
#include "cli.h"
#include "study/study_tool.h"

static const char *const CMD = "stability";

static void usage(FILE *fp)
{
    fprintf(fp,
            "usage: bumpgrad stability [--out DIR] [--samples N] [--no-chart]\n"
            "\n"
            "Sweeps where bump-mapping methods fail and writes DIR/STABILITY.md (the report),\n"
            "one CSV and one PNG chart per sweep (gnuplot), and DIR/summary.json:\n"
            "  1. inward normals of additive vs surface gradient as the amplitude grows 0.1..10\n"
            "  2. the float32 central-difference step U-curve and its optimum\n"
            "  3. large coordinates 1e3..1e8: float vs double entry points\n"
            "  4. turbulence creases: analytic vs central near octave zero crossings\n"
            "  5. Listing 1 at grazing angles, as det -> 0, across silhouettes\n"
            "  6. degenerate inputs (zero, NaN, Inf, non-unit normals, huge gradients)\n"
            "\n"
            "  --out DIR     output folder (default stability-output)\n"
            "  --samples N   points per sweep (default 20000)\n"
            "  --no-chart    skip gnuplot\n");
}

static void on_wrote(void *ctx, const char *path)
{
    (void)ctx;
    printf("wrote %s\n", path);
}

static void on_gnuplot(void *ctx, const char *text)
{
    (void)ctx;
    fprintf(stderr, "gnuplot: %s", text);
}

int cmd_stability(int argc, char **argv)
{
    const char *out_dir = "stability-output";
    long samples = 20000;
    int charts = 1;
    for (int i = 1; i < argc; i++) {
        const char *v;
        int r;
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            usage(stdout);
            return CLI_OK;
        } else if (!strcmp(argv[i], "--out")) {
            if ((r = cli_need_value(CMD, argc, argv, &i, &v)))
                return r;
            out_dir = v;
        } else if (!strcmp(argv[i], "--samples")) {
            if ((r = cli_need_value(CMD, argc, argv, &i, &v)) ||
                (r = cli_parse_int(CMD, "--samples", v, 100, 10000000, &samples)))
                return r;
        } else if (!strcmp(argv[i], "--no-chart")) {
            charts = 0;
        } else {
            return cli_usage_error(CMD, "unknown option '%s' (see bumpgrad stability --help)", argv[i]);
        }
    }
    cli_progress prog;
    bgt_progress sink = cli_progress_sink(&prog);
    bgt_study_report rep = {on_wrote, on_gnuplot, NULL};
    bgt_stability_opts o = {.out_dir = out_dir, .samples = (size_t)samples, .chart = charts,
                            .progress = &sink, .report = &rep};
    bgt_err err;
    bg_status s = bgt_stability_run(&o, &err);
    if (s == BG_OK)
        printf("wrote %s/STABILITY.md and %s/summary.json\n", out_dir, out_dir);
    return cli_report(CMD, s, &err);
}
