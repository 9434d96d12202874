/* SPDX-License-Identifier: MIT */
/* The height-function options shared by every command that bumps a surface,
 * as one table fragment (cli_height_opts, see args.h), parsed into a
 * bgt_height so each command evaluates exactly what the library's fused
 * kernel evaluates: h(p) = A F(f p), grad h = (A f) F'(f p). Also the
 * other fragments several commands share (--input/--output of the table
 * commands, --threads) and the choice names the commands print. */
#include <ctype.h>
#include <math.h>
#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "args.h"
#include "cli.h"
#include "json.h"

/* Choice fields are stored as int. */
_Static_assert(sizeof(bg_function) == sizeof(int), "bg_function is stored as int");
_Static_assert(sizeof(bg_gradient_mode) == sizeof(int), "bg_gradient_mode is stored as int");
_Static_assert(sizeof(bg_perturb_method) == sizeof(int), "bg_perturb_method is stored as int");

const char *const cli_function_choices[] = {"noise", "fbm", "turbulence", NULL};
const int cli_function_values[] = {BG_FUNC_NOISE, BG_FUNC_FBM, BG_FUNC_TURBULENCE};
const char *const cli_method_choices[] = {"surfgrad", "additive", "additive-perlin", NULL};
const int cli_method_values[] = {BG_PERTURB_SURFGRAD, BG_PERTURB_ADDITIVE,
                                 BG_PERTURB_ADDITIVE_PERLIN};
static const char *const gradient_choices[] = {"analytic", "central", NULL};
static const int gradient_values[] = {BG_GRADIENT_ANALYTIC, BG_GRADIENT_CENTRAL};

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

static int parse_grid(const char *cmd, const char *opt, char *text, void *field)
{
    bgt_height *h = field;
    if (!*text)
        return cli_usage_error(cmd, "%s: empty file name", opt);
    split_grid(text, &h->grid_path, &h->grid_name);
    return 0;
}

static int format_step(const void *field, char *buf, size_t len)
{
    float s = *(const float *)field;
    if (s == 0)
        snprintf(buf, len, "0 = %g", (double)BG_DEFAULT_CENTRAL_STEP);
    else
        snprintf(buf, len, "%g", (double)s);
    return 1;
}

static int parse_step(const char *cmd, const char *opt, char *text, void *field)
{
    float f;
    if (cli_parse_float(cmd, opt, text, &f))
        return CLI_USAGE;
    if (!(f >= 0))
        return cli_usage_error(cmd, "%s: must be >= 0 (0 = default %g), got \"%s\"", opt,
                               (double)BG_DEFAULT_CENTRAL_STEP, text);
    *(float *)field = f;
    return 0;
}

#define CLI_STR_(x) #x
#define CLI_STR(x) CLI_STR_(x)
#define FR(m) offsetof(bg_fractal, m)
const cli_opt cli_fractal_opts[] = {
    {.name = "function", .kind = CLI_KIND_CHOICE, .offset = FR(function), .metavar = "NAME",
     .help = "noise, fbm or turbulence", .choices = cli_function_choices,
     .choice_values = cli_function_values},
    {.name = "octaves", .kind = CLI_KIND_INT, .offset = FR(octaves), .metavar = "N",
     .help = "octaves of fbm/turbulence, 1.." CLI_STR(BG_MAX_OCTAVES), .lo = 1, .hi = BG_MAX_OCTAVES},
    {.name = "lacunarity", .kind = CLI_KIND_FLOAT, .offset = FR(lacunarity), .metavar = "L",
     .help = "frequency ratio between octaves, > 0", .flags = CLI_GT_LO, .lo = 0},
    {.name = "gain", .kind = CLI_KIND_FLOAT, .offset = FR(gain), .metavar = "G",
     .help = "amplitude ratio between octaves"},
    CLI_OPT_END,
};
#undef FR

/* --period X,Y,Z (X,Y: z not tiled; one N: all three axes): the tiling periods of
 * noise.h's bg_domain, each 0 (untiled) or 1..BG_MAX_PERIOD. */
static int parse_period(const char *cmd, const char *opt, char *text, void *field)
{
    int *period = field, n = 0;
    const char *s = text;
    char *end = text;
    while (n < 3) {
        long v = strtol(s, &end, 10);
        if (end == s || v < 0 || v > BG_MAX_PERIOD)
            return cli_usage_error(cmd, "%s: expected X,Y,Z or N, each 0 (not tiled) or 1..%d, "
                                        "got \"%s\"", opt, BG_MAX_PERIOD, text);
        period[n++] = (int)v;
        if (*end == '\0')
            break;
        if (*end != ',')
            return cli_usage_error(cmd, "%s: expected X,Y,Z or N, got \"%s\"", opt, text);
        s = end + 1;
    }
    if (*end != '\0')
        return cli_usage_error(cmd, "%s: expected X,Y,Z or N, got \"%s\"", opt, text);
    if (n == 1)
        period[1] = period[2] = period[0];
    else if (n == 2)
        period[2] = 0;
    return 0;
}

static int format_period(const void *field, char *buf, size_t len)
{
    const int *p = field;
    if (!p[0] && !p[1] && !p[2])
        snprintf(buf, len, "0 = not tiled");
    else
        snprintf(buf, len, "%d,%d,%d", p[0], p[1], p[2]);
    return 1;
}

#define DO(m) offsetof(bg_domain, m)
const cli_opt cli_domain_opts[] = {
    {.name = "period", .kind = CLI_KIND_CUSTOM, .offset = DO(period), .metavar = "X,Y,Z",
     .help = "tile the noise: periods in noise-space units (f * p), each 1.." CLI_STR(BG_MAX_PERIOD)
             " or 0 (that axis not tiled); X,Y leaves z untiled, one N tiles all three; needs an "
             "integer lacunarity",
     .parse = parse_period, .format = format_period},
    {.name = "seed", .kind = CLI_KIND_INT, .offset = DO(seed), .metavar = "N",
     .help = "vary the pattern: octave i is moved by an offset drawn from N (0 = Perlin's "
             "lattice, the same values as without it)", .lo = 0, .hi = 2147483647},
    CLI_OPT_END,
};
#undef DO

#define HO(m) offsetof(bgt_height, m)
const cli_opt cli_height_opts[] = {
    CLI_OPT_INCLUDE(HO(h.fractal), cli_fractal_opts, NULL),
    CLI_OPT_INCLUDE(HO(h.domain), cli_domain_opts, NULL),
    {.name = "amplitude", .kind = CLI_KIND_FLOAT, .offset = HO(h.amplitude), .metavar = "A",
     .help = "height scale A (negative flips bumps)"},
    {.name = "frequency", .kind = CLI_KIND_FLOAT, .offset = HO(h.frequency), .metavar = "F",
     .help = "spatial frequency f, > 0", .flags = CLI_GT_LO, .lo = 0},
    {.name = "gradient", .kind = CLI_KIND_CHOICE, .offset = HO(h.gradient), .metavar = "MODE",
     .help = "analytic gradient or central differences", .choices = gradient_choices,
     .choice_values = gradient_values},
    {.name = "step", .kind = CLI_KIND_CUSTOM, .offset = HO(h.step), .metavar = "H",
     .help = "central-difference step in noise space, >= 0", .parse = parse_step,
     .format = format_step},
    {.name = "height-grid", .kind = CLI_KIND_CUSTOM, .offset = 0, .metavar = "FILE.vdb[:GRID]",
     .help = "use a VDB FloatGrid as the height (tools build only); with a band, points "
             "outside the grid's active region are counted and reported",
     .parse = parse_grid, .flags = CLI_FILE, .complete_ext = "vdb"},
    CLI_OPT_END,
};
#undef HO
const char cli_height_heading[] = "Height function h(p) = A * F(f * p):";

#define IO(m) offsetof(cli_table_io, m)
/* "A:B", "A:" or ":B", non-negative integers, A <= B. */
static int parse_rows(const char *cmd, const char *opt, char *text, void *field)
{
    bgt_row_range *r = field;
    const char *colon = strchr(text, ':');
    unsigned long long v[2] = {0, 0};
    int open_end = 0, bad = !colon;
    for (int k = 0; k < 2 && !bad; k++) {
        const char *s = k ? colon + 1 : text, *stop = k ? text + strlen(text) : colon;
        if (s == stop) {
            open_end = k;
            continue;
        }
        char *end;
        errno = 0;
        v[k] = strtoull(s, &end, 10);
        bad = *s < '0' || *s > '9' || end != stop || errno != 0;
    }
    if (bad || (!open_end && v[0] > v[1]) || v[0] >= SIZE_MAX || v[1] >= SIZE_MAX)
        return cli_usage_error(cmd, "%s: expected A:B (rows A..B-1, 0 <= A <= B; A: or :B), "
                               "got \"%s\"", opt, text);
    r->have = 1;
    r->begin = (size_t)v[0];
    r->end = open_end ? SIZE_MAX : (size_t)v[1];
    return 0;
}

const cli_opt cli_table_io_opts[] = {
    {.name = "input", .short_name = 'i', .kind = CLI_KIND_STRING, .offset = IO(input),
     .metavar = "FILE", .help = "input table, \"-\" for standard input",
     .flags = CLI_REQUIRED | CLI_FILE, .complete_ext = "csv"},
    {.name = "output", .short_name = 'o', .kind = CLI_KIND_STRING, .offset = IO(output),
     .metavar = "FILE", .help = "output table, \"-\" for standard output; written to a temporary "
                                "file and renamed on success",
     .flags = CLI_REQUIRED | CLI_FILE, .complete_ext = "csv"},
    {.name = "rows", .kind = CLI_KIND_CUSTOM, .offset = IO(rows), .metavar = "A:B",
     .help = "only rows A..B-1 of a .npy input (A: or :B for an open end); the output holds "
             "those rows, so jobs over consecutive ranges concatenate to the whole run",
     .parse = parse_rows},
    CLI_OPT_END,
};
#undef IO

const cli_opt cli_threads_opts[] = {
    {.name = "threads", .kind = CLI_KIND_INT, .offset = 0, .metavar = "N",
     .help = "worker threads, 0 = all cores", .lo = 0, .hi = 1024, .flags = CLI_ZERO_NONE},
    CLI_OPT_END,
};

void cli_json_fractal(cli_json *j, const bg_fractal *f)
{
    cli_json_str(j, "function", cli_function_name(f->function));
    cli_json_int(j, "octaves", f->octaves);
    cli_json_float(j, "lacunarity", f->lacunarity);
    cli_json_float(j, "gain", f->gain);
}

void cli_json_height(cli_json *j, const char *key, const bgt_height *h)
{
    cli_json_object(j, key);
    if (h->grid_path) {
        cli_json_str(j, "grid_path", h->grid_path);
        cli_json_str(j, "grid_name", h->grid_name);
    } else {
        cli_json_fractal(j, &h->h.fractal);
        cli_json_float(j, "amplitude", h->h.amplitude);
        cli_json_float(j, "frequency", h->h.frequency);
        cli_json_str(j, "gradient", h->h.gradient == BG_GRADIENT_CENTRAL ? "central" : "analytic");
        cli_json_float(j, "step", h->h.step != 0 ? h->h.step : BG_DEFAULT_CENTRAL_STEP);
        cli_json_domain(j, &h->h.domain);
    }
    cli_json_close(j);
}

void cli_json_domain(cli_json *j, const bg_domain *d)
{
    cli_json_ints(j, "period", d->period, 3);
    cli_json_int(j, "seed", (long long)d->seed);
}

int cli_domain_check(const char *cmd, const bg_fractal *f, const bg_domain *d)
{
    if (bg_domain_validate(f, d) == BG_OK)
        return 0;
    if (d->period[0] || d->period[1] || d->period[2]) {
        if (f->function != BG_FUNC_NOISE && f->lacunarity != floorf(f->lacunarity))
            return cli_usage_error(cmd, "--period needs an integer --lacunarity (got %g): octave i "
                                        "tiles with period P * lacunarity^i",
                                   (double)f->lacunarity);
        return cli_usage_error(cmd, "--period %d,%d,%d: the finest octave's period P * "
                                    "lacunarity^(octaves-1) exceeds 2^24",
                               d->period[0], d->period[1], d->period[2]);
    }
    return cli_usage_error(cmd, "invalid fractal parameters");
}
