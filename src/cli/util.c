/* SPDX-License-Identifier: MIT */
/* Messages, option-value parsing and the progress line of the `bumpgrad` command.
 * Option values are parsed over the whole string: "1.5x", " 2", "" and "nan" are
 * errors, because a silently truncated or non-finite parameter gives a plausible
 * but wrong picture rather than a failure. */
#define _POSIX_C_SOURCE 200809L
#include "args.h"
#include "cli.h"
#include "json.h"
#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

/* The one message writer: "bumpgrad <cmd>: <kind>..." on stderr ("bumpgrad:
 * <kind>..." without a command), kind "error: ", "warning: " or "". */
static void vmessage(const char *cmd, const char *kind, const char *fmt, va_list ap)
{
    if (cmd && *cmd)
        fprintf(stderr, "bumpgrad %s: %s", cmd, kind);
    else
        fprintf(stderr, "bumpgrad: %s", kind);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
}

int cli_error(int code, const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vmessage(cmd, "error: ", fmt, ap);
    va_end(ap);
    return code;
}

/* strtod/strtof skip leading blanks; a value with blanks around it most likely
 * came from a quoting mistake, so both ends must be part of the number. */
static int bad_edges(const char *text)
{
    return text[0] == '\0' || isspace((unsigned char)text[0]);
}

/* One reader for both precisions: strtof for float (a double rounded again to
 * float could differ in the last bit), strtod for double. ERANGE with a large
 * result is overflow to inf; with a tiny one it is a harmless underflow to a
 * subnormal or zero. */
static int parse_real(const char *cmd, const char *opt, const char *text, int in_float,
                      double *out)
{
    if (!text || bad_edges(text))
        return cli_usage_error(cmd, "%s: expected a number, got \"%s\"", opt, text ? text : "");
    char *end;
    errno = 0;
    double v = in_float ? (double)strtof(text, &end) : strtod(text, &end);
    if (*end != '\0')
        return cli_usage_error(cmd, "%s: expected a number, got \"%s\"", opt, text);
    if (!isfinite(v) || (errno == ERANGE && fabs(v) > 1.0))
        return cli_usage_error(cmd, "%s: expected a finite number%s, got \"%s\"", opt,
                               in_float ? " in float range" : "", text);
    *out = v;
    return 0;
}

int cli_parse_double(const char *cmd, const char *opt, const char *text, double *out)
{
    return parse_real(cmd, opt, text, 0, out);
}

int cli_parse_float(const char *cmd, const char *opt, const char *text, float *out)
{
    double v = 0;
    int rc = parse_real(cmd, opt, text, 1, &v);
    if (!rc)
        *out = (float)v; /* exact: v came from strtof */
    return rc;
}

int cli_parse_int(const char *cmd, const char *opt, const char *text, long lo, long hi, long *out)
{
    if (!text || bad_edges(text))
        return cli_usage_error(cmd, "%s: expected an integer in [%ld, %ld], got \"%s\"", opt, lo,
                               hi, text ? text : "");
    char *end;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (*end != '\0' || errno == ERANGE || v < lo || v > hi)
        return cli_usage_error(cmd, "%s: expected an integer in [%ld, %ld], got \"%s\"", opt, lo,
                               hi, text);
    *out = v;
    return 0;
}

int cli_parse_size(const char *cmd, const char *opt, const char *text, long lo, int square,
                   const char *unit, int *w, int *h)
{
    enum { MAX_SIDE = 16384 };
    char *end;
    long a = strtol(text, &end, 10), b = square ? a : 0;
    const int have_x = end != text && (*end == 'x' || *end == 'X');
    if (have_x) {
        const char *s = end + 1;
        b = strtol(s, &end, 10);
        if (end == s)
            b = 0;
    }
    if (end == text || *end || (!have_x && !square) || a < lo || b < lo || a > MAX_SIDE ||
        b > MAX_SIDE)
        return cli_usage_error(cmd, "%s: expected %sWxH with %ld..%d %s each, got \"%s\"", opt,
                               square ? "N or " : "", lo, (int)MAX_SIDE, unit, text);
    *w = (int)a, *h = (int)b;
    return 0;
}

int cli_need_value(const char *cmd, int argc, char **argv, int *i, const char **out)
{
    if (*i + 1 >= argc)
        return cli_usage_error(cmd, "%s needs a value", argv[*i]);
    *i += 1;
    *out = argv[*i];
    return 0;
}

/* ---- global options and progress ------------------------------------------ */

cli_globals cli_global = {0};

int cli_quiet(void) { return cli_global.quiet; }
int cli_verbose(void) { return cli_global.verbose && !cli_global.quiet; }

void cli_warn(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vmessage(cmd, "warning: ", fmt, ap);
    va_end(ap);
}

void cli_info(const char *cmd, const char *fmt, ...)
{
    if (!cli_verbose())
        return;
    va_list ap;
    va_start(ap, fmt);
    vmessage(cmd, "", fmt, ap);
    va_end(ap);
}

double cli_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* What the tools count, by the label they report: the unit of the rate. */
static const char *unit_of(const char *label)
{
    static const struct {
        const char *label, *unit;
    } units[] = {{"eval", "bytes"},      {"perturb", "bytes"}, {"render", "tiles"},
                 {"baking rows", "rows"}, {"accuracy", "steps"}, {"stability", "sweeps"},
                 {"bake", "texels"}};
    for (size_t k = 0; k < sizeof units / sizeof units[0]; k++)
        if (label && strcmp(label, units[k].label) == 0)
            return units[k].unit;
    return "items";
}

void cli_progress_begin(cli_progress *p, const char *label, size_t total)
{
    const size_t *rows = p->rows;
    memset(p, 0, sizeof *p);
    p->rows = rows;
    p->label = label;
    p->unit = unit_of(label);
    p->total = total;
    p->last_shown = (size_t)-1;
    p->tty = isatty(STDERR_FILENO);
    /* By default only a terminal gets the line (BUMPGRAD_NO_PROGRESS turns it
     * off there too); --progress forces it anywhere, as one line per second
     * instead of a redrawn one; --quiet silences it. */
    p->enabled = !cli_global.quiet &&
                 (cli_global.progress || (p->tty && getenv("BUMPGRAD_NO_PROGRESS") == NULL));
    p->verbose = cli_verbose();
    p->t0 = cli_now();
    p->last_t = p->t0;
}

static void format_rate(double rate, const char *unit, char *buf, size_t len)
{
    const char *suffix = "";
    if (rate >= 1e9)
        rate /= 1e9, suffix = "G";
    else if (rate >= 1e6)
        rate /= 1e6, suffix = "M";
    else if (rate >= 1e3)
        rate /= 1e3, suffix = "k";
    if (strcmp(unit, "bytes") == 0)
        snprintf(buf, len, "%.1f %sB/s", rate, suffix);
    else
        snprintf(buf, len, "%.1f%s %s/s", rate, suffix, unit);
}

static void format_eta(double s, char *buf, size_t len)
{
    if (!(s >= 0) || s > 1e7)
        snprintf(buf, len, "?");
    else if (s >= 3600)
        snprintf(buf, len, "%dh%02dm", (int)(s / 3600), (int)(s / 60) % 60);
    else if (s >= 60)
        snprintf(buf, len, "%dm%02ds", (int)(s / 60), (int)s % 60);
    else
        snprintf(buf, len, "%.0fs", s);
}

static void progress_line(cli_progress *p, double now, const char *end)
{
    double dt = now - p->t0;
    size_t done = p->done;
    char rate[48], extra[64] = "", eta[24];
    format_rate(dt > 0 ? (double)done / dt : 0.0, p->unit, rate, sizeof rate);
    if (p->items && dt > 0) {
        char r2[48];
        format_rate((double)p->items / dt, "rows", r2, sizeof r2);
        snprintf(extra, sizeof extra, ", %s", r2);
    }
    if (p->total) {
        size_t d = done < p->total ? done : p->total;
        format_eta(d ? dt * (double)(p->total - d) / (double)d : -1.0, eta, sizeof eta);
        fprintf(stderr, "%s%s: %5.1f%%  %s%s  ETA %s%s", p->tty ? "\r" : "", p->label,
                100.0 * (double)d / (double)p->total, rate, extra, eta, end);
    } else {
        fprintf(stderr, "%s%s: %zu %s  %s%s%s", p->tty ? "\r" : "", p->label, done, p->unit, rate,
                extra, end);
    }
    fflush(stderr);
}

void cli_progress_update(cli_progress *p, size_t done)
{
    p->done = done;
    if (p->rows)
        p->items = *p->rows;
    if (!p->enabled)
        return;
    if (p->tty) {
        /* Redraw at most once per 0.1 % (or every 2^16 items when the total is
         * unknown) so that the clock and the terminal are not hit per item. */
        size_t key = p->total ? (size_t)((double)done / (double)p->total * 1000.0) : done >> 16;
        if (key == p->last_shown)
            return;
        p->last_shown = key;
        progress_line(p, cli_now(), "   ");
    } else {
        /* A log or a pipe: one full line a second, no carriage returns. */
        double now = cli_now();
        if (now - p->last_t < 1.0)
            return;
        p->last_t = now;
        progress_line(p, now, "\n");
    }
}

void cli_progress_end(cli_progress *p)
{
    double now = cli_now();
    if (p->rows)
        p->items = *p->rows;
    if (p->enabled && p->tty)
        /* Erase the line so the next message (or the shell prompt) starts clean. */
        fputs("\r\033[K", stderr);
    if ((p->enabled && !p->tty) || p->verbose) {
        double dt = now - p->t0;
        char rate[48], extra[64] = "";
        format_rate(dt > 0 ? (double)p->done / dt : 0.0, p->unit, rate, sizeof rate);
        if (p->items) {
            char r2[48];
            format_rate(dt > 0 ? (double)p->items / dt : 0.0, "rows", r2, sizeof r2);
            snprintf(extra, sizeof extra, "; %zu rows, %s", p->items, r2);
        }
        fprintf(stderr, "%s: done, %zu %s in %.2f s (%s%s)\n", p->label, p->done, p->unit, dt,
                rate, extra);
    }
    fflush(stderr);
    p->enabled = 0;
    p->verbose = 0;
}

/* The names of the option tables' choices (heightopt.c), so that what is
 * printed is what is parsed. */
static const char *choice_name(const char *const *names, const int *values, int v)
{
    for (int k = 0; names[k]; k++)
        if (values[k] == v)
            return names[k];
    return "?";
}

const char *cli_function_name(bg_function f)
{
    return choice_name(cli_function_choices, cli_function_values, (int)f);
}

const char *cli_method_name(bg_perturb_method m)
{
    return choice_name(cli_method_choices, cli_method_values, (int)m);
}

/* ---- tools results ------------------------------------------------------- */

int cli_exit_code(bg_status s)
{
    switch (s) {
    case BG_OK:
        return CLI_OK;
    case BG_ERR_IO:
    case BG_ERR_OUT_OF_MEMORY:
        return CLI_FAIL;
    default:
        return CLI_USAGE;
    }
}

int cli_report(const char *cmd, bg_status s, const bgt_err *e)
{
    if (s == BG_OK)
        return CLI_OK;
    const char *msg = e && e->msg[0] ? e->msg : bg_status_string(s);
    if (cmd && *cmd)
        fprintf(stderr, "bumpgrad %s: error: %s\n", cmd, msg);
    else
        fprintf(stderr, "bumpgrad: error: %s\n", msg);
    return cli_exit_code(s);
}

static void sink_begin(void *ctx, const char *label, size_t total)
{
    cli_progress_begin(ctx, label, total);
}
static void sink_update(void *ctx, size_t done) { cli_progress_update(ctx, done); }
static void sink_end(void *ctx) { cli_progress_end(ctx); }

bgt_progress cli_progress_sink(cli_progress *p)
{
    memset(p, 0, sizeof *p);
    bgt_progress s = {sink_begin, sink_update, sink_end, p};
    return s;
}

void cli_points_progress_init(cli_points_progress *p)
{
    p->sink = cli_progress_sink(&p->prog);
    memset(&p->stats, 0, sizeof p->stats);
    p->prog.rows = &p->stats.rows;
}

int cli_points_run(const char *cmd, const cli_points_cmd *c, const cli_table_io *io, int json,
                   int *threads, const void *args)
{
    if (json && strcmp(io->output, "-") == 0)
        return cli_usage_error(cmd, "--json writes to standard output: give --output a file");
    if (*threads == 0)
        *threads = bgt_threads_default();
    cli_points_progress pp;
    cli_points_progress_init(&pp);
    bgt_err err;
    double t0 = cli_now();
    bg_status st = c->call(args, &pp.sink, &pp.stats, &err);
    double dt = cli_now() - t0;
    if (st != BG_OK)
        return cli_report(cmd, st, &err);
    c->print_text(args, &pp.stats, dt);
    if (json)
        c->print_json(args, &pp.stats, dt);
    return CLI_OK;
}

void cli_json_common(cli_json *j, const char *cmd, double seconds)
{
    cli_json_str(j, "command", cmd);
    cli_json_str(j, "version", bg_version_string());
    cli_json_str(j, "isa", bg_isa_name(bg_isa_active()));
    cli_json_str(j, "isa_best", bg_isa_name(bg_isa_best()));
    cli_json_num(j, "seconds", seconds);
}

void cli_json_points_begin(cli_json *j, const char *cmd, double seconds, size_t rows)
{
    cli_json_begin(j, stdout);
    cli_json_common(j, cmd, seconds);
    cli_json_int(j, "rows", (long long)rows);
    cli_json_num(j, "rows_per_second", seconds > 0 ? (double)rows / seconds : 0.0);
}

void cli_study_gnuplot(void *ctx, const char *text)
{
    (void)ctx;
    fprintf(stderr, "gnuplot: %s", text);
}
