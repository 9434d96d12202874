/* SPDX-License-Identifier: MIT */
/* `bumpgrad perturb`: bump the normals of a CSV table of surface points with a
 * solid height function, through the library's fused height -> normal kernel
 * (Mikkelsen 2010, eq. 2 and 4), or with Perlin's additive rule for comparison.
 * The `inward` column makes the failure of the additive rule countable: it marks
 * rows whose bumped normal faces away from the surface normal. */
#include "cli.h"
#include "points/points.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>



static void perturb_help(FILE *fp)
{
    fprintf(fp, "Usage: bumpgrad perturb [options] --input IN.csv --output OUT.csv\n"
                "\n"
                "Perturb surface normals with a solid height function h, in float:\n"
                "  surfgrad         n' = normalize(n - grad_S h), grad_S h = g - n (n.g)\n"
                "                   (Mikkelsen 2010, eq. 2 and 4; never faces inward while\n"
                "                   |grad h| < ~1e7, where n' becomes tangent and rounding decides)\n"
                "  additive         n' = normalize(n - g)   (Perlin's rule, gradient negated)\n"
                "  additive-perlin  n' = normalize(n + g)   (Perlin 1985 as published)\n"
                "where n is the input normal (normalized first) and g = grad h at (x,y,z).\n"
                "\n"
                "Input:  header \"x,y,z,nx,ny,nz\", then one surface point and normal per line.\n"
                "Output: header \"x,y,z,nx,ny,nz,height,px,py,pz,inward\": the input, h(p),\n"
                "        the perturbed unit normal and inward = 1 where dot(n', n) <= 0.\n"
                "        A zero or non-finite normal gives n' = (0,0,0) and inward = 1.\n"
                "        Numbers are printed with %%.9g (they read back to the same float).\n"
                "\n"
                "Options:\n"
                "  -i, --input FILE    input table, \"-\" for standard input (required)\n"
                "  -o, --output FILE   output table, \"-\" for standard output (required);\n"
                "                      written to a temporary file and renamed on success\n"
                "  --method M          surfgrad (default), additive or additive-perlin\n"
                "  --threads N         worker threads (default: all cores)\n"
                "  --allow-nonfinite   accept nan/inf fields (see the NaN rules in surfgrad.h);\n"
                "                      without it they are an error\n"
                "  -h, --help          this help\n");
    cli_height_help(fp);
    fprintf(fp, "\n"
                "Input rules: as for `bumpgrad eval` (strict CSV; errors name FILE:LINE:COLUMN\n"
                "and leave no output). Exit status: 0 success, 1 I/O failure, 2 bad input or\n"
                "usage.\n"
                "\n"
                "Examples:\n"
                "  bumpgrad perturb -i surface.csv -o bumped.csv\n"
                "  bumpgrad perturb --method additive --amplitude 0.5 -i surface.csv -o add.csv\n"
                "  printf 'x,y,z,nx,ny,nz\\n0.3,0.2,0.1,0,0,1\\n' | bumpgrad perturb -i - -o -\n");
}

int cmd_perturb(int argc, char **argv)
{
    const char *cmd = "perturb", *in_path = NULL, *out_path = NULL, *v;
    bg_perturb_method method = BG_PERTURB_SURFGRAD;
    int allow_nonfinite = 0, threads = 0, rc;
    long l;
    bgt_height h;
    bgt_height_init(&h);
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i];
        if (strcmp(o, "-h") == 0 || strcmp(o, "--help") == 0) {
            perturb_help(stdout);
            return CLI_OK;
        } else if (strcmp(o, "-i") == 0 || strcmp(o, "--input") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &in_path)))
                return rc;
        } else if (strcmp(o, "-o") == 0 || strcmp(o, "--output") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &out_path)))
                return rc;
        } else if (strcmp(o, "--method") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)))
                return rc;
            if ((rc = cli_parse_method(cmd, o, v, &method)))
                return rc;
        } else if (strcmp(o, "--threads") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)) ||
                (rc = cli_parse_int(cmd, o, v, 0, 1024, &l)))
                return rc;
            threads = (int)l;
        } else if (strcmp(o, "--allow-nonfinite") == 0) {
            allow_nonfinite = 1;
        } else {
            int r = cli_height_option(cmd, &h, argc, argv, &i);
            if (r == CLI_USAGE)
                return r;
            if (r == 0)
                return cli_usage_error(cmd, "unknown option \"%s\" (see bumpgrad perturb --help)",
                                       o);
        }
    }
    if (!in_path)
        return cli_usage_error(cmd, "--input is required (\"-\" for standard input)");
    if (!out_path)
        return cli_usage_error(cmd, "--output is required (\"-\" for standard output)");
    bgt_err herr;
    bg_status hs = bgt_height_open(&h, &herr);
    if (hs != BG_OK)
        return cli_report(cmd, hs, &herr);
    if (threads == 0)
        threads = bgt_threads_default();

    cli_progress prog;
    bgt_progress sink = cli_progress_sink(&prog);
    bgt_perturb_opts opts = {.input = in_path, .output = out_path, .height = &h, .method = method,
                             .threads = threads, .allow_nonfinite = allow_nonfinite,
                             .progress = &sink};
    bgt_err err;
    rc = cli_report(cmd, bgt_perturb_run(&opts, &err), &err);
    bgt_height_close(&h);
    return rc;
}
