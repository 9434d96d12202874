/* SPDX-License-Identifier: MIT */
/* Internal interface of the `bumpgrad` command: the subcommand table and the
 * helpers every subcommand shares (errors, argument parsing, safe output files,
 * progress, threads, height-function options). Implemented in util.c,
 * outfile.c, parallel.c, heightopt.c. */
#ifndef BUMPGRAD_CLI_H
#define BUMPGRAD_CLI_H

#include <stddef.h>
#include <stdio.h>
#include "bumpgrad.h"

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

/* ---- safe output: write to "<path>.tmp.XXXXXX" in the same folder, rename on
 * commit; abort (or a crash) never leaves a half-written file nor touches an
 * existing one. "-" means stdout (commit just flushes). ---- */
typedef struct cli_outfile {
    FILE *fp;
    char *path;     /* final path */
    char *tmp_path; /* temporary path, NULL for stdout */
} cli_outfile;
/* 0, CLI_FAIL, or CLI_USAGE for an empty path. */
int cli_outfile_open(const char *cmd, const char *path, cli_outfile *out);
int cli_outfile_commit(const char *cmd, cli_outfile *out);                   /* 0 or CLI_FAIL */
void cli_outfile_abort(cli_outfile *out);
/* For writers that need a path (OpenImageIO, OpenVDB, PLY): make a temporary
 * path next to `path` keeping its extension (…/.name.tmp123.png), and rename it
 * into place. Returns malloc'd string or NULL. */
char *cli_temp_path_like(const char *path);
int cli_rename_into_place(const char *cmd, const char *tmp_path, const char *path);

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

/* ---- threads: split [0, n) into chunks over `threads` workers (0 = all cores).
 * fn(ctx, begin, end, worker) is called for disjoint ranges. ---- */
int cli_threads_default(void);
void cli_parallel_for(size_t n, size_t chunk, int threads,
                      void (*fn)(void *ctx, size_t begin, size_t end, int worker), void *ctx);

/* ---- height-function options shared by perturb, render, mesh, volume:
 * --function noise|fbm|turbulence --octaves N --lacunarity L --gain G
 * --amplitude A --frequency F --gradient analytic|central --step H
 * (and, with the tools, --height-grid FILE.vdb[:GRID]). ---- */
typedef struct cli_height {
    bg_height h;
    const char *grid_path; /* non-NULL: a VDB FloatGrid is the height (tools only) */
    const char *grid_name; /* NULL: the first FloatGrid of the file */
    void *grid;            /* opened grid (bg_vdb_height *), set by cli_height_open */
} cli_height;
void cli_height_init(cli_height *h);
/* If argv[*i] is a height option, consume it (and its value): returns 1; returns 0
 * if it is not one; CLI_USAGE (after printing) on a bad value. */
int cli_height_option(const char *cmd, cli_height *h, int argc, char **argv, int *i);
/* The --help lines for these options. */
void cli_height_help(FILE *fp);
/* Validate the options and open the VDB grid if one was given. 0, CLI_USAGE
 * (bad combination, grid given without tools) or CLI_FAIL (unreadable grid). */
int cli_height_open(const char *cmd, cli_height *h);
void cli_height_close(cli_height *h);
/* Height and volume gradient at n points (SoA): the fractal kernels, or the grid
 * (gradient by a stencil on the grid). `height` may be NULL. */
void cli_height_gradient(const cli_height *h, const float *px, const float *py, const float *pz,
                         size_t n, float *height, float *gx, float *gy, float *gz);
/* Height and perturbed normal (fused kernel, or grid gradient + bg_perturb_batch). */
void cli_height_perturb(const cli_height *h, bg_perturb_method m, const float *px,
                        const float *py, const float *pz, const float *nx, const float *ny,
                        const float *nz, size_t n, float *height, float *ox, float *oy, float *oz);

#endif
