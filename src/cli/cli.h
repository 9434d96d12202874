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

/* Exit codes: 0 success, 1 runtime failure (I/O error, out of memory),
 * 2 bad input or usage (the message names the argument, file, line, column). */
enum { CLI_OK = 0, CLI_FAIL = 1, CLI_USAGE = 2 };

typedef struct cli_command {
    const char *name;
    const char *summary;
    int (*run)(int argc, char **argv); /* argv[0] is the subcommand name */
} cli_command;

/* Subcommands (one file each: cmd_<name>.c), listed in main.c. */
int cmd_eval(int argc, char **argv);
int cmd_perturb(int argc, char **argv);
int cmd_render(int argc, char **argv);
int cmd_mesh(int argc, char **argv);
int cmd_accuracy(int argc, char **argv);
int cmd_stability(int argc, char **argv);
int cmd_bench(int argc, char **argv);
int cmd_volume(int argc, char **argv);
int cmd_heightmap(int argc, char **argv);

/* ---- messages ---- */
/* "bumpgrad <cmd>: error: ..." on stderr. Returns CLI_USAGE for chaining. */
int cli_usage_error(const char *cmd, const char *fmt, ...);
/* "bumpgrad <cmd>: error: ..." on stderr. Returns CLI_FAIL. */
int cli_fail(const char *cmd, const char *fmt, ...);

/* ---- argument parsing: each returns 0 on success, else prints an error naming
 * the option and the bad text and returns CLI_USAGE ---- */
int cli_parse_float(const char *cmd, const char *opt, const char *text, float *out);
int cli_parse_double(const char *cmd, const char *opt, const char *text, double *out);
int cli_parse_int(const char *cmd, const char *opt, const char *text, long lo, long hi, long *out);
/* Names of functions ("noise", "fbm", "turbulence") and perturbation methods
 * ("surfgrad", "additive", "additive-perlin"): parse (error names the option) and print. */
int cli_parse_function(const char *cmd, const char *opt, const char *text, bg_function *out);
int cli_parse_method(const char *cmd, const char *opt, const char *text, bg_perturb_method *out);
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

/* ---- progress on stderr, only when stderr is a terminal ---- */
typedef struct cli_progress {
    const char *label;
    size_t total, last_shown;
    int enabled;
    double t0;
} cli_progress;
void cli_progress_begin(cli_progress *p, const char *label, size_t total);
void cli_progress_update(cli_progress *p, size_t done);
void cli_progress_end(cli_progress *p);
/* A tools progress callback that drives `p` (begin/update/end). */
bgt_progress cli_progress_sink(cli_progress *p);

/* ---- height-function options shared by perturb, render, mesh, volume:
 * --function noise|fbm|turbulence --octaves N --lacunarity L --gain G
 * --amplitude A --frequency F --gradient analytic|central --step H
 * (and, with the tools, --height-grid FILE.vdb[:GRID]). ---- */
/* If argv[*i] is a height option, consume it (and its value): returns 1; returns 0
 * if it is not one; CLI_USAGE (after printing) on a bad value. */
int cli_height_option(const char *cmd, bgt_height *h, int argc, char **argv, int *i);
/* The --help lines for these options. */
void cli_height_help(FILE *fp);
#endif
