/* SPDX-License-Identifier: MIT */
/* The --json writer (json.h). */
#include "json.h"
#include <math.h>

void cli_json_write_string(FILE *fp, const char *s)
{
    /* RFC 8259: the two that must be escaped and the short forms of three
     * control characters; every other control character as \u00XX. */
    static const char *const short_escape[128] = {
        ['"'] = "\\\"", ['\\'] = "\\\\", ['\n'] = "\\n", ['\r'] = "\\r", ['\t'] = "\\t"};
    fputc('"', fp);
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        if (*p < 128 && short_escape[*p])
            fputs(short_escape[*p], fp);
        else if (*p < 0x20 || *p == 0x7f)
            fprintf(fp, "\\u%04x", *p);
        else
            fputc(*p, fp);
    }
    fputc('"', fp);
}

static void key(cli_json *j, const char *k)
{
    if (!j->first[j->depth])
        fputc(',', j->fp);
    j->first[j->depth] = 0;
    fprintf(j->fp, "\n%*s", 2 * j->depth, "");
    cli_json_write_string(j->fp, k);
    fputs(": ", j->fp);
}

void cli_json_begin(cli_json *j, FILE *fp)
{
    j->fp = fp;
    j->depth = 1;
    j->first[1] = 1;
    fputc('{', fp);
}

void cli_json_end(cli_json *j)
{
    fputs("\n}\n", j->fp);
}

void cli_json_object(cli_json *j, const char *k)
{
    key(j, k);
    fputc('{', j->fp);
    if (j->depth < 7)
        j->depth++;
    j->first[j->depth] = 1;
}

void cli_json_close(cli_json *j)
{
    j->depth--;
    fprintf(j->fp, "\n%*s}", 2 * j->depth, "");
}

void cli_json_str(cli_json *j, const char *k, const char *v)
{
    key(j, k);
    if (v)
        cli_json_write_string(j->fp, v);
    else
        fputs("null", j->fp);
}

/* %.17g (double) or %.9g (float) reads back to the same bits; NaN/Inf: null. */
static void num_digits(FILE *fp, double v, int digits)
{
    if (isfinite(v))
        fprintf(fp, "%.*g", digits, v);
    else
        fputs("null", fp);
}

static void num(FILE *fp, double v)
{
    num_digits(fp, v, 17);
}

void cli_json_num(cli_json *j, const char *k, double v)
{
    key(j, k);
    num(j->fp, v);
}

void cli_json_float(cli_json *j, const char *k, float v)
{
    key(j, k);
    num_digits(j->fp, (double)v, 9);
}

void cli_json_int(cli_json *j, const char *k, long long v)
{
    key(j, k);
    fprintf(j->fp, "%lld", v);
}

void cli_json_bool(cli_json *j, const char *k, int v)
{
    key(j, k);
    fputs(v ? "true" : "false", j->fp);
}

void cli_json_ints(cli_json *j, const char *k, const int *v, int n)
{
    key(j, k);
    fputc('[', j->fp);
    for (int i = 0; i < n; i++)
        fprintf(j->fp, "%s%d", i ? ", " : "", v[i]);
    fputc(']', j->fp);
}

void cli_json_nums(cli_json *j, const char *k, const double *v, int n)
{
    key(j, k);
    fputc('[', j->fp);
    for (int i = 0; i < n; i++) {
        if (i)
            fputs(", ", j->fp);
        num(j->fp, v[i]);
    }
    fputc(']', j->fp);
}
