/* SPDX-License-Identifier: MIT */
/* Internal: the streaming reader of numeric CSV tables used by `eval` and
 * `perturb`. It reads a fixed-size buffer at a time (constant memory for any
 * number of rows) and reports every problem as FILE:LINE:COLUMN. */
#ifndef BUMPGRAD_CLI_CSV_H
#define BUMPGRAD_CLI_CSV_H

#include <stddef.h>
#include <stdio.h>

/* Longest accepted line, in bytes (a row of numbers is far shorter; the cap
 * keeps a binary file or a missing newline from growing memory). */
#define CLI_CSV_MAX_LINE (1u << 16)

typedef struct cli_csv {
    const char *cmd;  /* subcommand name for messages */
    const char *name; /* file name in messages ("<stdin>" for "-") */
    FILE *fp;
    char *buf;         /* CLI_CSV_MAX_LINE + 1 bytes */
    size_t start, end; /* unread bytes are buf[start, end) */
    int eof;
    unsigned long line;  /* number of the line last returned (1-based) */
    unsigned long blank; /* first blank line not yet followed by data, 0 if none */
    size_t consumed;     /* bytes read from the file so far (for progress) */
    size_t size;         /* file size if known (regular file), else 0 */
    int allow_nonfinite; /* accept nan/inf fields */
} cli_csv;

/* Open `path` ("-" = stdin). 0, or CLI_USAGE after a message naming the file. */
int cli_csv_open(cli_csv *c, const char *cmd, const char *path, int allow_nonfinite);
void cli_csv_close(cli_csv *c);

/* Read the header line and require exactly the `count` column names (spaces
 * around names and a UTF-8 byte-order mark are tolerated). 0 or CLI_USAGE/CLI_FAIL. */
int cli_csv_header(cli_csv *c, const char *const *names, int count);

/* Read up to `max` rows of `count` numbers into the column arrays cols[0..count-1],
 * parsed with strtof (float) or strtod (double) so each value is the correctly
 * rounded value of its text in that precision. *rows = 0 at end of input.
 * Returns 0, CLI_USAGE (bad row, message printed) or CLI_FAIL (read error). */
int cli_csv_read_float(cli_csv *c, int count, float *const *cols, size_t max, size_t *rows);
int cli_csv_read_double(cli_csv *c, int count, double *const *cols, size_t max, size_t *rows);

#endif
