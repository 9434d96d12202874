/* SPDX-License-Identifier: MIT */
/* The height-function options shared by every command that bumps a surface,
 * parsed into a bg_height so each command evaluates exactly what the library's
 * fused kernel evaluates: h(p) = A F(f p), grad h = (A f) F'(f p). */
#include "cli.h"
#include <ctype.h>
#include <stdlib.h>
#include <string.h>

static int parse_gradient(const char *cmd, const char *text, bg_gradient_mode *out)
{
    if (strcmp(text, "analytic") == 0)
        *out = BG_GRADIENT_ANALYTIC;
    else if (strcmp(text, "central") == 0)
        *out = BG_GRADIENT_CENTRAL;
    else
        return cli_usage_error(cmd, "--gradient: expected analytic or central, got \"%s\"", text);
    return 0;
}

/* "FILE.vdb:GRID" names a grid inside the file; the split is taken only after a
 * ".vdb" so that a path which itself contains ':' still works without a grid name.
 * The argument string is split in place (argv strings are writable and outlive
 * the options), so nothing needs freeing. */
static void split_grid(char *text, const char **path, const char **name)
{
    *path = text;
    *name = NULL;
    char *colon = strrchr(text, ':');
    if (!colon || colon - text < 4)
        return;
    const char *ext = colon - 4;
    if (ext[0] == '.' && tolower((unsigned char)ext[1]) == 'v' &&
        tolower((unsigned char)ext[2]) == 'd' && tolower((unsigned char)ext[3]) == 'b') {
        *colon = '\0';
        *name = colon[1] ? colon + 1 : NULL;
    }
}

int cli_height_option(const char *cmd, bgt_height *h, int argc, char **argv, int *i)
{
    const char *o = argv[*i], *v;
    float f;
    long l;
    int rc;
#define VALUE()                                                                                    \
    do {                                                                                           \
        if ((rc = cli_need_value(cmd, argc, argv, i, &v)))                                         \
            return rc;                                                                             \
    } while (0)
    if (strcmp(o, "--function") == 0) {
        VALUE();
        /* Only the kind changes: --octaves given earlier must survive. */
        return cli_parse_function(cmd, "--function", v, &h->h.fractal.function) ? CLI_USAGE : 1;
    }
    if (strcmp(o, "--octaves") == 0) {
        VALUE();
        if (cli_parse_int(cmd, o, v, 1, BG_MAX_OCTAVES, &l))
            return CLI_USAGE;
        h->h.fractal.octaves = (int)l;
        return 1;
    }
    if (strcmp(o, "--lacunarity") == 0) {
        VALUE();
        if (cli_parse_float(cmd, o, v, &f))
            return CLI_USAGE;
        if (!(f > 0))
            return cli_usage_error(cmd, "%s: must be > 0, got \"%s\"", o, v);
        h->h.fractal.lacunarity = f;
        return 1;
    }
    if (strcmp(o, "--gain") == 0) {
        VALUE();
        if (cli_parse_float(cmd, o, v, &h->h.fractal.gain))
            return CLI_USAGE;
        return 1;
    }
    if (strcmp(o, "--amplitude") == 0) {
        VALUE();
        if (cli_parse_float(cmd, o, v, &h->h.amplitude))
            return CLI_USAGE;
        return 1;
    }
    if (strcmp(o, "--frequency") == 0) {
        VALUE();
        if (cli_parse_float(cmd, o, v, &f))
            return CLI_USAGE;
        if (!(f > 0))
            return cli_usage_error(cmd, "%s: must be > 0, got \"%s\"", o, v);
        h->h.frequency = f;
        return 1;
    }
    if (strcmp(o, "--gradient") == 0) {
        VALUE();
        return parse_gradient(cmd, v, &h->h.gradient) ? CLI_USAGE : 1;
    }
    if (strcmp(o, "--step") == 0) {
        VALUE();
        if (cli_parse_float(cmd, o, v, &f))
            return CLI_USAGE;
        if (!(f >= 0))
            return cli_usage_error(cmd, "%s: must be >= 0 (0 = default %g), got \"%s\"", o,
                                   (double)BG_DEFAULT_CENTRAL_STEP, v);
        h->h.step = f;
        return 1;
    }
    if (strcmp(o, "--height-grid") == 0) {
        VALUE();
        if (!*v)
            return cli_usage_error(cmd, "--height-grid: empty file name");
        split_grid(argv[*i], &h->grid_path, &h->grid_name);
        return 1;
    }
#undef VALUE
    return 0;
}

void cli_height_help(FILE *fp)
{
    fprintf(fp,
            "Height function h(p) = A * F(f * p):\n"
            "  --function NAME     noise, fbm or turbulence (default turbulence)\n"
            "  --octaves N         octaves of fbm/turbulence, 1..%d (default %d)\n"
            "  --lacunarity L      frequency ratio between octaves, > 0 (default 2)\n"
            "  --gain G            amplitude ratio between octaves (default 0.5)\n"
            "  --amplitude A       height scale A (default 0.1; negative flips bumps)\n"
            "  --frequency F       spatial frequency f, > 0 (default 1)\n"
            "  --gradient MODE     analytic (default) or central differences\n"
            "  --step H            central-difference step in noise space (0 = %g)\n"
            "  --height-grid FILE.vdb[:GRID]\n"
            "                      use a VDB FloatGrid as the height (tools build only)\n",
            BG_MAX_OCTAVES, BG_DEFAULT_OCTAVES, (double)BG_DEFAULT_CENTRAL_STEP);
}

