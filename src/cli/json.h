/* SPDX-License-Identifier: MIT */
/* A tiny JSON object writer for the --json statistics of the commands
 * (json.c): one object, nested objects, strings escaped per RFC 8259
 * (quote, backslash, control characters as \uXXXX; other bytes as they are,
 * so UTF-8 stays UTF-8), numbers with 17 significant digits, non-finite
 * numbers as null. */
#ifndef BUMPGRAD_CLI_JSON_H
#define BUMPGRAD_CLI_JSON_H

#include <stddef.h>
#include <stdio.h>

typedef struct cli_json {
    FILE *fp;
    int depth;
    int first[8];
} cli_json;

void cli_json_begin(cli_json *j, FILE *fp);          /* { */
void cli_json_end(cli_json *j);                      /* }\n */
void cli_json_object(cli_json *j, const char *key);  /* "key": { */
void cli_json_close(cli_json *j);                    /* } */
void cli_json_str(cli_json *j, const char *key, const char *v); /* NULL: null */
void cli_json_num(cli_json *j, const char *key, double v);
void cli_json_float(cli_json *j, const char *key, float v); /* %.9g: reads back exactly */
void cli_json_int(cli_json *j, const char *key, long long v);
void cli_json_bool(cli_json *j, const char *key, int v);
void cli_json_ints(cli_json *j, const char *key, const int *v, int n);
void cli_json_nums(cli_json *j, const char *key, const double *v, int n);
/* Shared blocks of the commands' statistics: "command", "version", "isa",
 * "isa_best", "seconds" (util.c); the height parameters as an object (heightopt.c). */
void cli_json_common(cli_json *j, const char *cmd, double seconds);
/* The points commands (eval, perturb): begin on stdout, the common block,
 * "rows" and "rows_per_second" (util.c). */
void cli_json_points_begin(cli_json *j, const char *cmd, double seconds, size_t rows);
struct bgt_height;
void cli_json_height(cli_json *j, const char *key, const struct bgt_height *h);
/* "function", "octaves", "lacunarity", "gain" of a fractal (heightopt.c). */
struct bg_fractal;
void cli_json_fractal(cli_json *j, const struct bg_fractal *f);
struct bg_domain;
/* "period": [X, Y, Z], "seed": N of a domain. */
void cli_json_domain(cli_json *j, const struct bg_domain *d);
/* The escaped form of s, for tests of the escaper. */
void cli_json_write_string(FILE *fp, const char *s);

#endif
