/* SPDX-License-Identifier: MIT */
/* TEMPORARY, during the move of the tools out of src/cli: the old cli_* names
 * of what now lives in src/tools, so that sources not yet converted still
 * compile. Deleted when the last user is converted. */
#ifndef BUMPGRAD_CLI_COMPAT_H
#define BUMPGRAD_CLI_COMPAT_H

#include <stdlib.h>
#include "common/parallel.h"
#include "common/safe_file.h"
#include "height_source.h"

typedef bgt_height cli_height;
#define cli_height_init bgt_height_init
#define cli_height_close bgt_height_close
#define cli_height_gradient bgt_height_gradient
#define cli_height_perturb bgt_height_perturb
#define cli_parallel_for bgt_parallel_for
#define cli_threads_default bgt_threads_default
typedef bgt_safe_file cli_outfile;

int cli_report(const char *cmd, bg_status s, const bgt_err *e);

static inline int cli_height_open(const char *cmd, cli_height *h)
{
    bgt_err e;
    return cli_report(cmd, bgt_height_open(h, &e), &e);
}
static inline int cli_outfile_open(const char *cmd, const char *path, cli_outfile *out)
{
    bgt_err e;
    return cli_report(cmd, bgt_safe_open(out, path, &e), &e);
}
static inline int cli_outfile_commit(const char *cmd, cli_outfile *out)
{
    bgt_err e;
    return cli_report(cmd, bgt_safe_commit(out, &e), &e);
}
static inline void cli_outfile_abort(cli_outfile *out) { bgt_safe_abort(out); }
static inline char *cli_temp_path_like(const char *path)
{
    bgt_err e;
    return bgt_safe_temp_path(path, &e);
}
static inline int cli_rename_into_place(const char *cmd, const char *tmp, const char *path)
{
    bgt_err e;
    return cli_report(cmd, bgt_safe_commit_path(tmp, path, &e), &e);
}

#endif
