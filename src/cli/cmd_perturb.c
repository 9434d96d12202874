/* SPDX-License-Identifier: MIT */
/* `bumpgrad perturb`: bump the normals of a CSV table of surface points with a
 * solid height function, through the library's fused height -> normal kernel
 * (Mikkelsen 2010, eq. 2 and 4), or with Perlin's additive rule for comparison.
 * The `inward` column makes the failure of the additive rule countable: it marks
 * rows whose bumped normal faces away from the surface normal. */
#include <stdlib.h>
#include <string.h>
#include "args.h"
#include "cli.h"
#include "json.h"
#include "points/points.h"

typedef struct perturb_args {
    cli_table_io io;
    int method, threads, allow_nonfinite, json;
    bgt_height height;
} perturb_args;

static void perturb_defaults(void *p)
{
    perturb_args *a = p;
    memset(a, 0, sizeof *a);
    a->method = BG_PERTURB_SURFGRAD;
    bgt_height_init(&a->height);
}

#define A(m) offsetof(perturb_args, m)
static const cli_opt perturb_opts[] = {
    CLI_OPT_INCLUDE(A(io), cli_table_io_opts, NULL),
    {.name = "method", .kind = CLI_KIND_CHOICE, .offset = A(method), .metavar = "M",
     .help = "surfgrad, additive or additive-perlin", .choices = cli_method_choices,
     .choice_values = cli_method_values},
    CLI_OPT_INCLUDE(A(threads), cli_threads_opts, NULL),
    {.name = "allow-nonfinite", .kind = CLI_KIND_FLAG, .offset = A(allow_nonfinite),
     .help = "accept nan/inf fields (see the NaN rules in surfgrad.h); without it they are an "
             "error"},
    {.name = "json", .kind = CLI_KIND_FLAG, .offset = A(json),
     .help = "print one JSON object of statistics on standard output (rows, inward rows, rows "
             "inside a --height-grid, time, ISA, every parameter); needs --output FILE"},
    CLI_OPT_INCLUDE(A(height), cli_height_opts, cli_height_heading),
    CLI_OPT_END,
};
#undef A

CLI_SPEC(perturb,
    .summary = "bump surface normals from a CSV table (surface gradient or additive)",
    .usage = "[options] --input IN.csv --output OUT.csv",
    .about =
        "Perturb surface normals with a solid height function h, in float:\n"
        "  surfgrad         n' = normalize(n - grad_S h), grad_S h = g - n (n.g)\n"
        "                   (Mikkelsen 2010, eq. 2 and 4; never faces inward while\n"
        "                   |grad h| < ~1e7, where n' becomes tangent and rounding decides)\n"
        "  additive         n' = normalize(n - g)   (Perlin's rule, gradient negated)\n"
        "  additive-perlin  n' = normalize(n + g)   (Perlin 1985 as published)\n"
        "where n is the input normal (normalized first) and g = grad h at (x,y,z).\n"
        "\n"
        "Input:  a header naming x,y,z,nx,ny,nz (found by name as for `eval`: id first,\n"
        "        other columns passed through), then one point and normal per line;\n"
        "        or FILE.npy of shape (N, 6) (output FILE.npy: (N, 11), float32).\n"
        "Output: header \"x,y,z,nx,ny,nz,height,px,py,pz,inward\": the input, h(p),\n"
        "        the perturbed unit normal and inward = 1 where dot(n', n) <= 0.\n"
        "        A zero or non-finite normal gives n' = (0,0,0) and inward = 1.\n"
        "        Numbers are printed with %.9g (they read back to the same float).\n",
    .opts = perturb_opts,
    .more = "Input rules: as for `bumpgrad eval` (strict CSV; errors name FILE:LINE:COLUMN\n"
            "and leave no output). Exit status: 0 success, 1 I/O failure, 2 bad input or\n"
            "usage.\n"
            "\n"
            "Examples:\n"
            "  bumpgrad perturb -i surface.csv -o bumped.csv\n"
            "  bumpgrad perturb --method additive --amplitude 0.5 -i surface.csv -o add.csv\n"
            "  printf 'x,y,z,nx,ny,nz\\n0.3,0.2,0.1,0,0,1\\n' | bumpgrad perturb -i - -o -\n",
);

/* A warning when a --height-grid missed every point; with -v, the points in
 * its active box, the rows, the time, the ISA and the threads (stderr). */
static void print_text(const void *args, const bgt_points_stats *stats, double dt)
{
    const perturb_args *a = args;
    const char *cmd = "perturb";
    const double *gb = stats->grid_box;
    if (stats->grid && stats->rows > 0 && stats->in_grid == 0)
        cli_warn(cmd, "none of the %zu points lies in the active region of %s (active voxel "
                      "centres in [%g,%g,%g]..[%g,%g,%g]): the height is 0 there and every "
                      "normal is unchanged",
                 stats->rows, a->height.grid_path, gb[0], gb[1], gb[2], gb[3], gb[4], gb[5]);
    else if (stats->grid)
        cli_info(cmd, "%zu of %zu points inside the active box of %s", stats->in_grid, stats->rows,
                 a->height.grid_path);
    cli_info(cmd, "%zu rows in %.3f s, %zu inward (%s, %d threads)", stats->rows, dt,
             stats->inward, bg_isa_name(bg_isa_active()), a->threads);
}

/* One JSON object of statistics and every parameter (--json). */
static void print_json(const void *args, const bgt_points_stats *stats, double dt)
{
    const perturb_args *a = args;
    const char *cmd = "perturb";
    const double *gb = stats->grid_box;
    cli_json j;
    cli_json_points_begin(&j, cmd, dt, stats->rows);
    cli_json_int(&j, "inward", (long long)stats->inward);
    cli_json_num(&j, "inward_fraction",
                 stats->rows ? (double)stats->inward / (double)stats->rows : 0.0);
    if (stats->grid) {
        cli_json_int(&j, "in_grid", (long long)stats->in_grid);
        cli_json_nums(&j, "grid_active_box", gb, 6);
    }
    cli_json_object(&j, "parameters");
    cli_json_str(&j, "input", a->io.input);
    cli_json_str(&j, "output", a->io.output);
    cli_json_str(&j, "method", cli_method_name((bg_perturb_method)a->method));
    cli_json_int(&j, "threads", a->threads);
    cli_json_bool(&j, "allow_nonfinite", a->allow_nonfinite);
    cli_json_height(&j, "height", &a->height);
    cli_json_close(&j);
    cli_json_end(&j);
}

/* The tool call (cli_points_run). */
static bg_status call_perturb(const void *args, const bgt_progress *progress,
                              bgt_points_stats *stats, bgt_err *e)
{
    const perturb_args *a = args;
    bgt_perturb_opts opts = {.input = a->io.input, .output = a->io.output, .height = &a->height,
                             .method = (bg_perturb_method)a->method, .threads = a->threads,
                             .allow_nonfinite = a->allow_nonfinite,
                             .rows = a->io.rows, .progress = progress, .stats = stats};
    return bgt_perturb_run(&opts, e);
}

static int run_perturb(void *args, const char *const *pos, int npos)
{
    (void)pos, (void)npos;
    const char *cmd = "perturb";
    perturb_args a = *(perturb_args *)args;
    static const cli_points_cmd c = {call_perturb, print_text, print_json};
    return cli_points_run(cmd, &c, &a.io, a.json, &a.threads, &a);
}
