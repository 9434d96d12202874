/* SPDX-License-Identifier: MIT */
/* `bumpgrad eval`: noise / fBm / turbulence value and gradient at points read
 * from a CSV table. The table is streamed in blocks, so memory stays constant
 * for any number of rows, and written through a temporary file, so a bad row
 * at line 900000 leaves no partial output. Numbers are printed with enough
 * digits (9 for float, 17 for double) to read back to the same bits. */
#include <stdlib.h>
#include <string.h>
#include "args.h"
#include "cli.h"
#include "json.h"
#include "points/points.h"

typedef struct eval_args {
    cli_table_io io;
    bg_fractal fractal;
    bg_domain domain;
    int central, dbl, threads, allow_nonfinite, json;
    double step;
} eval_args;

static void eval_defaults(void *p)
{
    eval_args *a = p;
    memset(a, 0, sizeof *a);
    a->fractal = bg_fractal_default(BG_FUNC_NOISE);
    a->fractal.octaves = BG_DEFAULT_OCTAVES; /* noise ignores it; kept for --function fbm */
    a->step = (double)BG_DEFAULT_CENTRAL_STEP;
}

static const char *const gradient_choices[] = {"analytic", "central", NULL};
static const char *const precision_choices[] = {"float", "double", NULL};

#define A(m) offsetof(eval_args, m)
static const cli_opt eval_opts[] = {
    CLI_OPT_INCLUDE(A(io), cli_table_io_opts, NULL),
    CLI_OPT_INCLUDE(A(fractal), cli_fractal_opts, NULL),
    CLI_OPT_INCLUDE(A(domain), cli_domain_opts, NULL),
    {.name = "gradient", .kind = CLI_KIND_CHOICE, .offset = A(central), .metavar = "MODE",
     .help = "analytic gradient or central differences", .choices = gradient_choices},
    {.name = "step", .kind = CLI_KIND_DOUBLE, .offset = A(step), .metavar = "H",
     .help = "central-difference step, > 0", .flags = CLI_GT_LO, .lo = 0},
    {.name = "precision", .kind = CLI_KIND_CHOICE, .offset = A(dbl), .metavar = "P",
     .help = "float (SIMD batch kernels) or double (scalar; double noise equals Perlin's "
             "reference)",
     .choices = precision_choices},
    CLI_OPT_INCLUDE(A(threads), cli_threads_opts, NULL),
    {.name = "allow-nonfinite", .kind = CLI_KIND_FLAG, .offset = A(allow_nonfinite),
     .help = "accept nan/inf coordinates (their results are NaN); without it they are an error"},
    {.name = "json", .kind = CLI_KIND_FLAG, .offset = A(json),
     .help = "print one JSON object of statistics on standard output (rows, time, ISA, every "
             "parameter); needs --output FILE"},
    CLI_OPT_END,
};
#undef A

CLI_SPEC(eval,
    .summary = "noise / fBm / turbulence value and gradient at points from a CSV table",
    .usage = "[options] --input IN.csv --output OUT.csv",
    .about = "Evaluate Perlin's improved noise (2002), fBm or turbulence (1985) and its\n"
             "gradient at every point of a CSV table.\n"
             "\n"
             "Input:  a header naming the columns x, y, z (any order, any case, quoted or\n"
             "        not), then one point per line. A column \"id\" is written first in the\n"
             "        output; any other column is passed through, unchanged, at the end.\n"
             "        Or FILE.npy: a float32/float64 array of shape (N, 3).\n"
             "Output: header \"x,y,z,value,dx,dy,dz\"; (dx,dy,dz) is the gradient of value.\n"
             "        Numbers are printed to read back exactly: %.9g in float, %.17g in\n"
             "        double. x,y,z are the input values as parsed in that precision.\n"
             "        Or FILE.npy: shape (N, 7), float32 (or float64 with --precision double).\n",
    .opts = eval_opts,
    .more = "Input rules: fields may have spaces around them; CRLF line ends and a missing\n"
            "final newline are accepted; blank lines are accepted only at the end. Any\n"
            "other problem (wrong header, wrong field count, text that is not a number,\n"
            "NaN/Inf without --allow-nonfinite, a number out of range of the precision)\n"
            "stops with FILE:LINE:COLUMN and the output file is not written (an existing\n"
            "one is left as it was). With -o -, rows before the error may already be on\n"
            "standard output; the exit status tells.\n"
            "\n"
            "Exit status: 0 success, 1 I/O failure (e.g. unwritable output), 2 bad input\n"
            "or usage (including an input file that cannot be opened).\n"
            "\n"
            "Examples:\n"
            "  printf 'x,y,z\\n3.14,42,7\\n' | bumpgrad eval --precision double -i - -o -\n"
            "  bumpgrad eval --function turbulence --octaves 8 -i pts.csv -o out.csv\n"
            "  bumpgrad eval --function fbm --gradient central --step 1e-3 -i pts.csv -o fd.csv\n"
            "  bumpgrad eval --function fbm --period 8,8,0 --seed 3 -i pts.csv -o tiled.csv\n",
);

/* With -v: the rows, the time, the ISA and the threads (stderr). */
static void print_text(const void *args, const bgt_points_stats *stats, double dt)
{
    const eval_args *a = args;
    const char *cmd = "eval";
    cli_info(cmd, "%zu rows in %.3f s (%s, %d threads)", stats->rows, dt,
             bg_isa_name(bg_isa_active()), a->threads);
}

/* One JSON object of statistics and every parameter (--json). */
static void print_json(const void *args, const bgt_points_stats *stats, double dt)
{
    const eval_args *a = args;
    const char *cmd = "eval";
    cli_json j;
    cli_json_points_begin(&j, cmd, dt, stats->rows);
    cli_json_object(&j, "parameters");
    cli_json_str(&j, "input", a->io.input);
    cli_json_str(&j, "output", a->io.output);
    cli_json_fractal(&j, &a->fractal);
    cli_json_domain(&j, &a->domain);
    cli_json_str(&j, "gradient", a->central ? "central" : "analytic");
    cli_json_num(&j, "step", a->step);
    cli_json_str(&j, "precision", a->dbl ? "double" : "float");
    cli_json_int(&j, "threads", a->threads);
    cli_json_bool(&j, "allow_nonfinite", a->allow_nonfinite);
    cli_json_close(&j);
    cli_json_end(&j);
}

/* The tool call (cli_points_run). */
static bg_status call_eval(const void *args, const bgt_progress *progress,
                           bgt_points_stats *stats, bgt_err *e)
{
    const eval_args *a = args;
    bgt_eval_opts opts = {.input = a->io.input, .output = a->io.output, .fractal = a->fractal,
                          .domain = a->domain, .central = a->central, .dbl = a->dbl,
                          .step = a->step, .threads = a->threads,
                          .allow_nonfinite = a->allow_nonfinite,
                          .rows = a->io.rows, .progress = progress, .stats = stats};
    return bgt_eval_run(&opts, e);
}

static int run_eval(void *args, const char *const *pos, int npos)
{
    (void)pos, (void)npos;
    const char *cmd = "eval";
    eval_args a = *(eval_args *)args;
    if (bg_fractal_validate(&a.fractal) != BG_OK)
        return cli_usage_error(cmd, "invalid fractal parameters");
    if (cli_domain_check(cmd, &a.fractal, &a.domain))
        return CLI_USAGE;
    if (a.dbl && a.central && (a.domain.seed || a.domain.period[0] || a.domain.period[1] ||
                               a.domain.period[2]))
        return cli_usage_error(cmd, "--period/--seed with --precision double: only the analytic "
                                    "gradient (no double central differences over a domain)");
    if (!a.dbl && !((float)a.step > 0))
        return cli_usage_error(cmd, "--step %g is zero in float precision", a.step);
    static const cli_points_cmd c = {call_eval, print_text, print_json};
    return cli_points_run(cmd, &c, &a.io, a.json, &a.threads, &a);
}
