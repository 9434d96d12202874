/* SPDX-License-Identifier: MIT */
/* Internal interface of the `bumpgrad` command: the subcommand table and the
 * helpers every subcommand shares (errors, argument parsing, safe output files,
 * progress, threads). */
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

/* Subcommands (one file each: cmd_<name>.c). */
int cmd_eval(int argc, char **argv);
int cmd_perturb(int argc, char **argv);

#endif
