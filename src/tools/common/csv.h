/* SPDX-License-Identifier: MIT */
/* Internal: the streaming reader of numeric CSV tables used by `eval` and
 * `perturb`. It reads a fixed-size buffer at a time (constant memory for any
 * number of rows) and reports every problem as FILE:LINE:COLUMN. */
#ifndef BUMPGRAD_TOOLS_CSV_H
#define BUMPGRAD_TOOLS_CSV_H

#include <stddef.h>
#include <stdio.h>
#include "tool.h"

/* Longest accepted line, in bytes (a row of numbers is far shorter; the cap
 * keeps a binary file or a missing newline from growing memory). */
#define BGT_CSV_MAX_LINE (1u << 16)
/* Most columns a mapped header may have. */
#define BGT_CSV_MAX_COLS 64

typedef struct bgt_csv {
    bgt_err *err;     /* where problems are reported */
    const char *name; /* file name in messages ("<stdin>" for "-") */
    FILE *fp;
    char *buf;         /* BGT_CSV_MAX_LINE + 1 bytes */
    size_t start, end; /* unread bytes are buf[start, end) */
    int eof;
    unsigned long line;  /* number of the line last returned (1-based) */
    unsigned long blank; /* first blank line not yet followed by data, 0 if none */
    size_t consumed;     /* bytes read from the file so far (for progress) */
    size_t size;         /* file size if known (regular file), else 0 */
    int allow_nonfinite; /* accept nan/inf fields */
    /* Set by bgt_csv_header_map: */
    int ncols;                        /* fields per row of the file */
    int mapped;                       /* the columns are not exactly names[0..count) */
    signed char role[BGT_CSV_MAX_COLS]; /* k >= 0: names[k]; -1: extra; -2: the id column */
    char id_header[256];              /* the id column's header text as in the file, or "" */
    char extra_header[1024];          /* the other columns' header text, comma-joined, or "" */
    char *arena;                      /* this block's id and extra text (see bgt_csv_row_text) */
    size_t arena_len, arena_cap, offs_cap;
    size_t *offs;                     /* per row: id start, id len, extra start, extra len */
} bgt_csv;

/* Open `path` ("-" = stdin). Every later problem is reported in *err as
 * FILE:LINE:COLUMN: BG_ERR_FORMAT for bad text, BG_ERR_INVALID_ARGUMENT for an
 * input that cannot be opened, BG_ERR_IO for a read error. */
bg_status bgt_csv_open(bgt_csv *c, bgt_err *err, const char *path, int allow_nonfinite);
void bgt_csv_close(bgt_csv *c);

/* Read the header line and require exactly the `count` column names (spaces
 * around names and a UTF-8 byte-order mark are tolerated). */
bg_status bgt_csv_header(bgt_csv *c, const char *const *names, int count);

/* Read the header line and find the `count` columns by name: any order, names
 * compared case-insensitively, blanks around and double quotes around a name
 * ignored. A column named "id" and any other columns are kept as text
 * (bgt_csv_row_text) for the output. Every row must have as many fields as the
 * header. Errors name FILE:1:COLUMN (BG_ERR_FORMAT). */
bg_status bgt_csv_header_map(bgt_csv *c, const char *const *names, int count);
/* Text of row `row` of the last block read: the id field (or empty) and the
 * other extra fields joined by ',' as they were in the file (or empty). */
void bgt_csv_row_text(const bgt_csv *c, size_t row, const char **id, size_t *idlen,
                      const char **extra, size_t *extralen);

/* Read up to `max` rows of `count` numbers into the column arrays cols[0..count-1],
 * parsed with strtof (float) or strtod (double) so each value is the correctly
 * rounded value of its text in that precision. *rows = 0 at end of input.
 * Returns BG_OK, BG_ERR_FORMAT (bad row) or BG_ERR_IO (read error). */
bg_status bgt_csv_read_float(bgt_csv *c, int count, float *const *cols, size_t max, size_t *rows);
bg_status bgt_csv_read_double(bgt_csv *c, int count, double *const *cols, size_t max, size_t *rows);

/* Nonzero (the default): fields that are plain decimals take the exact fast
 * path (csv.c); 0: every field goes through strtof/strtod (for benchmarks). */
extern int bgt_csv_fast_path;
/* The fast path alone, for tests: BG_OK with the value (*dv for dbl, else *fv)
 * if it handles s[0..n), BG_ERR_FORMAT if it leaves the field to strtod/strtof. */
bg_status bgt_csv_parse_number(const char *s, size_t n, int dbl, double *dv, float *fv);

/* Output tables that keep the input's id and extra columns: the header
 * [id,]OURS[,extra...], and around each row of ours the id before and the
 * extra columns after, as they were read (row r of the last block read). */
void bgt_csv_write_header(FILE *fp, const bgt_csv *in, const char *ours);
void bgt_csv_write_row_prefix(FILE *fp, const bgt_csv *in, size_t r, const char **extra,
                              size_t *elen);
void bgt_csv_write_row_suffix(FILE *fp, const bgt_csv *in, const char *extra, size_t elen);

#endif
