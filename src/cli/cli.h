/* SPDX-License-Identifier: MIT */
/* Internal interface of the `bumpgrad` command: the subcommand table and the
 * helpers every subcommand shares (errors, argument parsing, progress,
 * height-function options). Implemented in util.c and heightopt.c; the work
 * itself is done by the tools library (src/tools). */
#ifndef BUMPGRAD_CLI_H
#define BUMPGRAD_CLI_H

#include <stddef.h>
#include <stdio.h>
#include "bumpgrad.h"
#include "common/parallel.h"
#include "common/safe_file.h"
#include "common/tool.h"
#include "height_source.h"
#include "points/points.h"

/* Exit codes: 0 success, 1 runtime failure (I/O error, out of memory),
 * 2 bad input or usage (the message names the argument, file, line, column). */
enum { CLI_OK = 0, CLI_FAIL = 1, CLI_USAGE = 2 };

struct cli_spec;
typedef struct cli_command {
    const char *name;
    /* The option table (args.h), with the summary and the run; main.c calls
     * cli_run_command. */
    const struct cli_spec *spec;
    /* Options main.c must leave to the command although they look global
     * (bench --isa). NULL-terminated or NULL. */
    const char *const *own;
} cli_command;

/* Subcommands (one file each: cmd_<name>.c), listed in main.c: the specs of
 * the commands on the table parser (args.h). */
extern const struct cli_spec cli_spec_bench, cli_spec_eval, cli_spec_perturb, cli_spec_accuracy,
    cli_spec_stability, cli_spec_volume, cli_spec_heightmap, cli_spec_render, cli_spec_mesh;

/* ---- messages ---- */
/* "bumpgrad <cmd>: error: ..." on stderr ("bumpgrad: error: ..." when cmd is
 * NULL or empty). Returns `code` for chaining: cli_usage_error returns
 * CLI_USAGE, cli_fail CLI_FAIL. */
int cli_error(int code, const char *cmd, const char *fmt, ...);
#define cli_usage_error(...) cli_error(CLI_USAGE, __VA_ARGS__)
#define cli_fail(...) cli_error(CLI_FAIL, __VA_ARGS__)

/* ---- argument parsing: each returns 0 on success, else prints an error naming
 * the option and the bad text and returns CLI_USAGE ---- */
int cli_parse_float(const char *cmd, const char *opt, const char *text, float *out);
int cli_parse_double(const char *cmd, const char *opt, const char *text, double *out);
int cli_parse_int(const char *cmd, const char *opt, const char *text, long lo, long hi, long *out);
/* An image size "WxH" (or "N" for N x N when `square` is set), each side in
 * lo..16384 `unit` (the word in the message: "pixels", "texels"). */
int cli_parse_size(const char *cmd, const char *opt, const char *text, long lo, int square,
                   const char *unit, int *w, int *h);
/* Names of functions ("noise", "fbm", "turbulence") and perturbation methods
 * ("surfgrad", "additive", "additive-perlin"); parsed by the option tables. */
const char *cli_function_name(bg_function f);
const char *cli_method_name(bg_perturb_method m);
/* Option value: argv[*i + 1], advancing *i; error if missing. */
int cli_need_value(const char *cmd, int argc, char **argv, int *i, const char **out);

/* ---- tools results: print the message of a failed tools call as
 * "bumpgrad <cmd>: error: ..." and map its status to the exit code
 * (BG_ERR_INVALID_ARGUMENT, BG_ERR_FORMAT, BG_ERR_NULL_POINTER,
 * BG_ERR_UNSUPPORTED_ISA: bad input, 2; BG_ERR_IO, BG_ERR_OUT_OF_MEMORY: 1). ---- */
int cli_exit_code(bg_status s);
int cli_report(const char *cmd, bg_status s, const bgt_err *e);

/* ---- global options (main.c strips them from anywhere on the command line):
 * --quiet/-q: errors only (no progress, no summary lines); --progress: the
 * progress line even when stderr is not a terminal; -v/--verbose: detail
 * (final rate and timing, parameters) on stderr. ---- */
typedef struct cli_globals {
    int quiet, verbose, progress;
} cli_globals;
extern cli_globals cli_global;
int cli_quiet(void);
int cli_verbose(void);
/* "bumpgrad <cmd>: warning: ..." on stderr (also with --quiet: a warning says
 * that nothing happened). */
void cli_warn(const char *cmd, const char *fmt, ...);
/* "bumpgrad <cmd>: ..." on stderr, only with -v. */
void cli_info(const char *cmd, const char *fmt, ...);
/* The studies' (accuracy, stability) gnuplot messages: "gnuplot: TEXT" on
 * stderr (a bgt_study_report callback). */
void cli_study_gnuplot(void *ctx, const char *text);
/* Monotonic seconds. */
double cli_now(void);

/* ---- progress on stderr: on a terminal by default (a redrawn line with rate,
 * unit and ETA), one line per second with --progress elsewhere; a final line
 * with --progress off a terminal or with -v. ---- */
typedef struct cli_progress {
    const char *label, *unit;
    size_t total, last_shown, done, items;
    const size_t *rows; /* set after cli_progress_sink: rows done, read at each update */
    int enabled, tty, verbose;
    double t0, last_t;
} cli_progress;
void cli_progress_begin(cli_progress *p, const char *label, size_t total);
void cli_progress_update(cli_progress *p, size_t done);
void cli_progress_end(cli_progress *p);
/* A tools progress callback that drives `p` (begin/update/end). */
bgt_progress cli_progress_sink(cli_progress *p);
/* The progress of the table commands (eval, perturb): the line counts rows
 * from the tool's statistics. Initialize in place (sink points to prog). */
typedef struct cli_points_progress {
    cli_progress prog;
    bgt_progress sink;
    bgt_points_stats stats;
} cli_points_progress;
void cli_points_progress_init(cli_points_progress *p);
/* The table commands' one driver (eval, perturb): --json needs --output FILE,
 * 0 threads means all cores (*threads is set), the progress line counts rows,
 * the tool call is timed, a failure reported, then print_text, and print_json
 * with --json. Each hook gets the command's own `args`. Returns the exit code. */
typedef struct cli_points_cmd {
    /* The tool (bgt_eval_run, bgt_perturb_run) with the progress sink and the statistics. */
    bg_status (*call)(const void *args, const bgt_progress *progress, bgt_points_stats *stats,
                      bgt_err *e);
    void (*print_text)(const void *args, const bgt_points_stats *stats, double dt);
    void (*print_json)(const void *args, const bgt_points_stats *stats, double dt);
} cli_points_cmd;
struct cli_table_io;
int cli_points_run(const char *cmd, const cli_points_cmd *c, const struct cli_table_io *io,
                   int json, int *threads, const void *args);

/* ---- height-function options shared by perturb, render, mesh, volume,
 * heightmap: the table fragment cli_height_opts (args.h, heightopt.c). ---- */
#endif
