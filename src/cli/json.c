/* SPDX-License-Identifier: MIT */
/* The --json writer (json.h). */
#include "json.h"
#include <math.h>

void cli_json_write_string(FILE *fp, const char *s)
{
    fputc('"', fp);
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        switch (*p) {
        case '"':
            fputs("\\\"", fp);
            break;
        case '\\':
            fputs("\\\\", fp);
            break;
        case '\n':
            fputs("\\n", fp);
            break;
        case '\r':
            fputs("\\r", fp);
            break;
        case '\t':
            fputs("\\t", fp);
            break;
        default:
            if (*p < 0x20 || *p == 0x7f)
                fprintf(fp, "\\u%04x", *p);
            else
                fputc(*p, fp);
        }
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

static void num(FILE *fp, double v)
{
    if (isfinite(v))
        fprintf(fp, "%.17g", v);
    else
        fputs("null", fp);
}

void cli_json_num(cli_json *j, const char *k, double v)
{
    key(j, k);
    num(j->fp, v);
}

void cli_json_float(cli_json *j, const char *k, float v)
{
    key(j, k);
    if (isfinite(v))
        fprintf(j->fp, "%.9g", (double)v);
    else
        fputs("null", j->fp);
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
