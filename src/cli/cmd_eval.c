/* SPDX-License-Identifier: MIT */
/* `bumpgrad eval`: noise / fBm / turbulence value and gradient at points read
 * from a CSV table. The table is streamed in blocks, so memory stays constant
 * for any number of rows, and written through a temporary file, so a bad row
 * at line 900000 leaves no partial output. Numbers are printed with enough
 * digits (9 for float, 17 for double) to read back to the same bits. */
#include "cli.h"
#include "points/points.h"
#include <stdlib.h>
#include <string.h>

/* Rows per block: large enough that per-block costs (thread start, stdio calls)
 * vanish, small enough (~460 KB of columns in double) to stay in L2. */


static void eval_help(FILE *fp)
{
    fprintf(fp,
            "Usage: bumpgrad eval [options] --input IN.csv --output OUT.csv\n"
            "\n"
            "Evaluate Perlin's improved noise (2002), fBm or turbulence (1985) and its\n"
            "gradient at every point of a CSV table.\n"
            "\n"
            "Input:  header \"x,y,z\", then one point per line.\n"
            "Output: header \"x,y,z,value,dx,dy,dz\"; (dx,dy,dz) is the gradient of value.\n"
            "        Numbers are printed to read back exactly: %%.9g in float, %%.17g in\n"
            "        double. x,y,z are the input values as parsed in that precision.\n"
            "\n"
            "Options:\n"
            "  -i, --input FILE        input table, \"-\" for standard input (required)\n"
            "  -o, --output FILE       output table, \"-\" for standard output (required);\n"
            "                          written to a temporary file and renamed on success\n"
            "  --function NAME         noise (default), fbm or turbulence\n"
            "  --octaves N             octaves of fbm/turbulence, 1..%d (default %d)\n"
            "  --lacunarity L          frequency ratio between octaves, > 0 (default 2)\n"
            "  --gain G                amplitude ratio between octaves (default 0.5)\n"
            "  --gradient MODE         analytic (default) or central differences\n"
            "  --step H                central-difference step (default %g)\n"
            "  --precision P           float (default; SIMD batch kernels) or double\n"
            "                          (scalar; double noise equals Perlin's reference)\n"
            "  --threads N             worker threads (default: all cores)\n"
            "  --allow-nonfinite       accept nan/inf coordinates (their results are NaN);\n"
            "                          without it they are an error\n"
            "  -h, --help              this help\n"
            "\n"
            "Input rules: fields may have spaces around them; CRLF line ends and a missing\n"
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
            "  bumpgrad eval --function fbm --gradient central --step 1e-3 -i pts.csv -o fd.csv\n",
            BG_MAX_OCTAVES, BG_DEFAULT_OCTAVES, (double)BG_DEFAULT_CENTRAL_STEP);
}

int cmd_eval(int argc, char **argv)
{
    const char *cmd = "eval", *in_path = NULL, *out_path = NULL, *v;
    bg_fractal f = bg_fractal_default(BG_FUNC_NOISE);
    f.octaves = BG_DEFAULT_OCTAVES; /* noise ignores it; kept for --function fbm */
    int central = 0, dbl = 0, allow_nonfinite = 0, threads = 0, rc;
    double step = 0;
    long l;
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i];
        if (strcmp(o, "-h") == 0 || strcmp(o, "--help") == 0) {
            eval_help(stdout);
            return CLI_OK;
        } else if (strcmp(o, "-i") == 0 || strcmp(o, "--input") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &in_path)))
                return rc;
        } else if (strcmp(o, "-o") == 0 || strcmp(o, "--output") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &out_path)))
                return rc;
        } else if (strcmp(o, "--function") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)))
                return rc;
            if ((rc = cli_parse_function(cmd, o, v, &f.function)))
                return rc;
        } else if (strcmp(o, "--octaves") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)) ||
                (rc = cli_parse_int(cmd, o, v, 1, BG_MAX_OCTAVES, &l)))
                return rc;
            f.octaves = (int)l;
        } else if (strcmp(o, "--lacunarity") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)) ||
                (rc = cli_parse_float(cmd, o, v, &f.lacunarity)))
                return rc;
            if (!(f.lacunarity > 0))
                return cli_usage_error(cmd, "%s: must be > 0, got \"%s\"", o, v);
        } else if (strcmp(o, "--gain") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)) ||
                (rc = cli_parse_float(cmd, o, v, &f.gain)))
                return rc;
        } else if (strcmp(o, "--gradient") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)))
                return rc;
            if (strcmp(v, "analytic") == 0)
                central = 0;
            else if (strcmp(v, "central") == 0)
                central = 1;
            else
                return cli_usage_error(cmd, "--gradient: expected analytic or central, got \"%s\"",
                                       v);
        } else if (strcmp(o, "--step") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)) ||
                (rc = cli_parse_double(cmd, o, v, &step)))
                return rc;
            if (!(step > 0))
                return cli_usage_error(cmd, "%s: must be > 0, got \"%s\"", o, v);
        } else if (strcmp(o, "--precision") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)))
                return rc;
            if (strcmp(v, "float") == 0)
                dbl = 0;
            else if (strcmp(v, "double") == 0)
                dbl = 1;
            else
                return cli_usage_error(cmd, "--precision: expected float or double, got \"%s\"", v);
        } else if (strcmp(o, "--threads") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)) ||
                (rc = cli_parse_int(cmd, o, v, 0, 1024, &l)))
                return rc;
            threads = (int)l;
        } else if (strcmp(o, "--allow-nonfinite") == 0) {
            allow_nonfinite = 1;
        } else {
            return cli_usage_error(cmd, "unknown option \"%s\" (see bumpgrad eval --help)", o);
        }
    }
    if (!in_path)
        return cli_usage_error(cmd, "--input is required (\"-\" for standard input)");
    if (!out_path)
        return cli_usage_error(cmd, "--output is required (\"-\" for standard output)");
    if (bg_fractal_validate(&f) != BG_OK)
        return cli_usage_error(cmd, "invalid fractal parameters");
    if (step == 0)
        step = (double)BG_DEFAULT_CENTRAL_STEP;
    if (!dbl && !((float)step > 0))
        return cli_usage_error(cmd, "--step %g is zero in float precision", step);
    if (threads == 0)
        threads = bgt_threads_default();

    cli_progress prog;
    bgt_progress sink = cli_progress_sink(&prog);
    bgt_eval_opts opts = {.input = in_path, .output = out_path, .fractal = f, .central = central,
                          .dbl = dbl, .step = step, .threads = threads,
                          .allow_nonfinite = allow_nonfinite, .progress = &sink};
    bgt_err err;
    return cli_report(cmd, bgt_eval_run(&opts, &err), &err);
}
