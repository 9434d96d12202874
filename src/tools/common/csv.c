/* SPDX-License-Identifier: MIT */
/* Streaming numeric CSV reader (see csv.h). Strict on purpose: a table of
 * sample points that parses "almost" (a stray blank line, a truncated row, a
 * "1.5x") is far more likely a broken export than an intent, so each such case is
 * an error naming the line and column rather than a silently skipped row. */
#define _POSIX_C_SOURCE 200809L
#include "csv.h"
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* The buffer holds the longest accepted line with its "\r\n". */
#define BUF_CAP (BGT_CSV_MAX_LINE + 2)

static int is_blank_char(char ch)
{
    return ch == ' ' || ch == '\t';
}

/* The offending text, shortened and with control bytes escaped, for messages. */
static const char *quote(const char *s, size_t n, char *out, size_t cap)
{
    size_t o = 0, limit = 40;
    for (size_t i = 0; i < n && o + 8 < cap; i++) {
        if (i == limit) {
            memcpy(out + o, "...", 3);
            o += 3;
            break;
        }
        unsigned char ch = (unsigned char)s[i];
        if (ch < 0x20 || ch == 0x7f || ch == '"' || ch == '\\')
            o += (size_t)snprintf(out + o, cap - o, "\\x%02x", ch);
        else
            out[o++] = (char)ch;
    }
    out[o] = '\0';
    return out;
}

/* ---- the decimal fast path ------------------------------------------------
 * Most fields of a point table are short decimals ("-13.4567891",
 * "1.5e-05"). For those, w * 10^e with w < 2^53 and |e| <= 22 is a product
 * (or quotient) of two doubles that are exact, so one IEEE operation gives the
 * correctly rounded double (Clinger 1990). For float, rounding that double
 * again is wrong only when the double lands exactly on the midpoint between two
 * floats (the true value may lie on either side); that case, and every field
 * the fast path does not understand (more than 19 significant digits, hex,
 * inf/nan, a bad character, a result near the float or double limits), goes
 * to strtof/strtod, which also produces the error messages. tests/tools
 * (csv_exact) compares both paths on millions of random and edge-case strings. */

static const double pow10_exact[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                       1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                       1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/* Scan a decimal at p (before end): the end of its text and, in *out, its
 * value if the fast path applies and is exact; NULL to fall back. */
static const char *scan_decimal(const char *p, const char *end, double *out)
{
    int neg = 0;
    if (p < end && (*p == '-' || *p == '+'))
        neg = *p == '-', p++;
    uint64_t w = 0;
    int exp10 = 0;
    const char *d0 = p;
    unsigned dig;
    while (p < end && (dig = (unsigned)(*p - '0')) < 10)
        w = w * 10 + dig, p++;
    int digits = (int)(p - d0);
    if (p < end && *p == '.') {
        const char *f0 = ++p;
        while (p < end && (dig = (unsigned)(*p - '0')) < 10)
            w = w * 10 + dig, p++;
        exp10 = -(int)(p - f0);
        digits -= exp10;
    }
    /* 19 digits always fit in 64 bits (leading zeros included: a rare case
     * with more digits simply takes strtod). */
    if (digits == 0 || digits > 19)
        return NULL;
    if (p < end && (*p == 'e' || *p == 'E')) {
        p++;
        int eneg = 0, ev = 0;
        if (p < end && (*p == '-' || *p == '+'))
            eneg = *p == '-', p++;
        const char *e0 = p;
        while (p < end && (dig = (unsigned)(*p - '0')) < 10 && ev < 100000)
            ev = ev * 10 + (int)dig, p++;
        if (p == e0 || ev >= 100000)
            return NULL;
        exp10 += eneg ? -ev : ev;
    }
    if (w > (UINT64_C(1) << 53))
        return NULL;
    double d = (double)w;
    if (w == 0) {
        /* strtod gives -0.0 for "-0"; the exponent does not matter */
    } else if (exp10 >= 0 && exp10 <= 22) {
        d *= pow10_exact[exp10];
    } else if (exp10 < 0 && exp10 >= -22) {
        d /= pow10_exact[-exp10];
    } else {
        return NULL;
    }
    if (!(d < 1e300)) /* stay far from overflow, ERANGE is strtod's business */
        return NULL;
    *out = neg ? -d : d;
    return p;
}

/* Parse s[0..n) (no blanks around) as a decimal; 1 with *out if the fast path
 * applies and is exact, 0 to fall back. */
static int fast_decimal(const char *s, size_t n, double *out)
{
    return scan_decimal(s, s + n, out) == s + n;
}

/* d is the double of a decimal; 1 with *out if (float)d is the correctly
 * rounded float of that decimal. */
static int exact_float(double d, float *out)
{
    double a = fabs(d);
    if (a != 0 && (a < 0x1p-126 || a > 0x1p127)) /* subnormal or near FLT_MAX: strtof */
        return 0;
    /* A normal float keeps 24 of the double's 53 significant bits; d is a
     * midpoint between two floats exactly when the 29 bits dropped are 1000...0.
     * Then the true value may lie on either side: strtof decides. */
    uint64_t bits;
    memcpy(&bits, &d, sizeof bits);
    if ((bits & ((UINT64_C(1) << 29) - 1)) == (UINT64_C(1) << 28))
        return 0;
    *out = (float)d;
    return 1;
}

/* The float of the decimal s[0..n): 1 if exact, 0 to fall back to strtof. */
static int fast_float(const char *s, size_t n, float *out)
{
    double d;
    return fast_decimal(s, n, &d) && exact_float(d, out);
}

int bgt_csv_fast_path = 1;

bg_status bgt_csv_parse_number(const char *s, size_t n, int dbl, double *dv, float *fv)
{
    /* For tests: the fast path, or 1 if it declined. */
    if (dbl)
        return fast_decimal(s, n, dv) ? BG_OK : BG_ERR_FORMAT;
    return fast_float(s, n, fv) ? BG_OK : BG_ERR_FORMAT;
}

static bg_status row_error(const bgt_csv *c, size_t col, const char *fmt, const char *arg)
{
    char msg[256];
    snprintf(msg, sizeof msg, fmt, arg);
    return bgt_fail(c->err, BG_ERR_FORMAT, "%s:%lu:%zu: %s", c->name, c->line, col, msg);
}

bg_status bgt_csv_open(bgt_csv *c, bgt_err *err, const char *path, int allow_nonfinite)
{
    memset(c, 0, sizeof *c);
    c->err = err;
    c->allow_nonfinite = allow_nonfinite;
    if (strcmp(path, "-") == 0) {
        c->name = "<stdin>";
        c->fp = stdin;
    } else {
        c->name = path;
        c->fp = fopen(path, "rb");
        if (!c->fp)
            return bgt_fail(err, BG_ERR_INVALID_ARGUMENT, "cannot open input %s: %s", path, strerror(errno));
        struct stat st;
        if (fstat(fileno(c->fp), &st) == 0) {
            if (S_ISDIR(st.st_mode)) {
                fclose(c->fp);
                c->fp = NULL;
                return bgt_fail(err, BG_ERR_INVALID_ARGUMENT, "cannot read input %s: is a directory", path);
            }
            if (S_ISREG(st.st_mode))
                c->size = (size_t)st.st_size;
        }
    }
    c->buf = malloc(BUF_CAP + 1);
    if (!c->buf) {
        bgt_csv_close(c);
        return bgt_fail(c->err, BG_ERR_OUT_OF_MEMORY, "out of memory");
    }
    return 0;
}

void bgt_csv_close(bgt_csv *c)
{
    if (c->fp && c->fp != stdin)
        fclose(c->fp);
    c->fp = NULL;
    free(c->buf);
    c->buf = NULL;
}

/* Next line without its "\n" or "\r\n", NUL-terminated in place. 1: a line,
 * 0: end of input, or a bg_status negated. */
static int next_line(bgt_csv *c, char **line, size_t *len)
{
    for (;;) {
        char *p = c->buf + c->start;
        char *nl = memchr(p, '\n', c->end - c->start);
        if (nl || (c->eof && c->start < c->end)) {
            size_t n = nl ? (size_t)(nl - p) : c->end - c->start;
            c->start += nl ? n + 1 : n;
            c->line++;
            if (n > 0 && p[n - 1] == '\r')
                n--;
            if (n > BGT_CSV_MAX_LINE) {
                bgt_fail(c->err, BG_ERR_FORMAT, "%s:%lu:1: line longer than %u bytes", c->name,
                         c->line, (unsigned)BGT_CSV_MAX_LINE);
                return -(int)BG_ERR_FORMAT;
            }
            p[n] = '\0'; /* buf has one spare byte past BUF_CAP */
            *line = p;
            *len = n;
            return 1;
        }
        if (c->eof)
            return 0;
        if (c->start > 0) {
            memmove(c->buf, c->buf + c->start, c->end - c->start);
            c->end -= c->start;
            c->start = 0;
        }
        if (c->end == BUF_CAP) {
            c->line++;
            bgt_fail(c->err, BG_ERR_FORMAT, "%s:%lu:1: line longer than %u bytes", c->name, c->line,
                            (unsigned)BGT_CSV_MAX_LINE);
            return -(int)BG_ERR_FORMAT;
        }
        size_t r = fread(c->buf + c->end, 1, BUF_CAP - c->end, c->fp);
        c->end += r;
        c->consumed += r;
        if (r == 0) {
            if (ferror(c->fp)) {
                bgt_fail(c->err, BG_ERR_IO, "reading %s failed: %s", c->name, strerror(errno));
                return -(int)BG_ERR_IO;
            }
            c->eof = 1;
        }
    }
}

static int line_is_blank(const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!is_blank_char(s[i]))
            return 0;
    return 1;
}

bg_status bgt_csv_header(bgt_csv *c, const char *const *names, int count)
{
    char *s;
    size_t n;
    char want[128] = "", got[64];
    for (int k = 0; k < count; k++) {
        strncat(want, names[k], sizeof want - strlen(want) - 2);
        if (k + 1 < count)
            strcat(want, ",");
    }
    int r = next_line(c, &s, &n);
    if (r < 0)
        return (bg_status)-r;
    if (r == 0) {
        c->line = 1;
        return row_error(c, 1, "empty input, expected the header \"%s\"", want);
    }
    size_t pos = 0;
    /* A byte-order mark is what spreadsheet exports put first; it is not data. */
    if (n >= 3 && memcmp(s, "\xEF\xBB\xBF", 3) == 0)
        pos = 3;
    for (int k = 0; k < count; k++) {
        while (pos < n && is_blank_char(s[pos]))
            pos++;
        size_t nlen = strlen(names[k]);
        /* The column points at the first byte that differs from the header:
         * the start of a wrong name, or where a ',' or the line end belongs. */
        size_t b = pos;
        int ok = n - pos >= nlen && memcmp(s + pos, names[k], nlen) == 0;
        if (ok) {
            pos += nlen;
            while (pos < n && is_blank_char(s[pos]))
                pos++;
            ok = k + 1 < count ? pos < n && s[pos] == ',' : pos == n;
            b = pos;
        }
        if (!ok) {
            char msg[256];
            snprintf(msg, sizeof msg, "expected the header \"%s\", got \"%s\"", want,
                     quote(s, n, got, sizeof got));
            return bgt_fail(c->err, BG_ERR_FORMAT, "%s:%lu:%zu: %s", c->name, c->line, b + 1, msg);
        }
        pos++; /* the comma */
    }
    return 0;
}

/* Split and parse one row; `dbl` picks strtod into dcols, else strtof into fcols. */
static bg_status parse_row(bgt_csv *c, char *s, size_t n, int count, int dbl, float *const *fcols,
                     double *const *dcols, size_t row)
{
    char tmp[64];
    size_t pos = 0;
    for (int k = 0; k < count; k++) {
        size_t b = pos;
        size_t e = b;
        while (e < n && s[e] != ',')
            e++;
        if (e == n && k + 1 < count) {
            char msg[96];
            snprintf(msg, sizeof msg, "expected %d fields, got %d", count, k + 1);
            return bgt_fail(c->err, BG_ERR_FORMAT, "%s:%lu:%zu: %s", c->name, c->line, n + 1, msg);
        }
        if (k + 1 == count && e < n) {
            int extra = 1;
            for (size_t i = e + 1; i < n; i++)
                extra += s[i] == ',';
            char msg[96];
            snprintf(msg, sizeof msg, "expected %d fields, got %d", count, count + extra);
            return bgt_fail(c->err, BG_ERR_FORMAT, "%s:%lu:%zu: %s", c->name, c->line, e + 2, msg);
        }
        size_t vb = b;
        while (vb < e && is_blank_char(s[vb]))
            vb++;
        /* strtod would skip \v \f \r too; they are no more a number's edge
         * here than after it. */
        if (vb < e && isspace((unsigned char)s[vb]))
            return row_error(c, vb + 1, "expected a number, got \"%s\"",
                             quote(s + vb, e - vb, tmp, sizeof tmp));
        char saved = s[e];
        s[e] = '\0';
        char *end;
        double dv = 0;
        float fv = 0;
        errno = 0;
        if (vb == e) {
            s[e] = saved;
            return row_error(c, b + 1, "expected a number, got \"%s\"", "");
        }
        if (dbl)
            dv = strtod(s + vb, &end);
        else
            fv = strtof(s + vb, &end);
        int range = errno == ERANGE;
        while (is_blank_char(*end))
            end++;
        s[e] = saved;
        if (end == s + vb || end != s + e)
            return row_error(c, vb + 1, "expected a number, got \"%s\"",
                             quote(s + vb, e - vb, tmp, sizeof tmp));
        int finite = dbl ? isfinite(dv) : isfinite(fv);
        double mag = dbl ? fabs(dv) : fabsf(fv);
        /* ERANGE with a big result is an overflowing literal like 1e999: not an
         * explicit inf, so it stays an error even with --allow-nonfinite. */
        if (range && mag > 1.0) {
            int fits_double = !dbl && isfinite(strtod(s + vb, NULL));
            return row_error(
                c, vb + 1,
                fits_double ? "number \"%s\" is out of the range of float (use --precision double?)"
                : dbl       ? "number \"%s\" is out of the range of double"
                            : "number \"%s\" is out of the range of float",
                quote(s + vb, e - vb, tmp, sizeof tmp));
        }
        if (!finite && !c->allow_nonfinite)
            return row_error(c, vb + 1,
                             "non-finite value \"%s\" (--allow-nonfinite accepts NaN and Inf)",
                             quote(s + vb, e - vb, tmp, sizeof tmp));
        if (dbl)
            dcols[k][row] = dv;
        else
            fcols[k][row] = fv;
        pos = e + 1;
    }
    return 0;
}

/* A whole row of plain decimals through the fast path: 1 if every field was
 * taken (values stored), 0 to parse the row again the careful way (which also
 * words the errors). */
static int fast_row(const char *s, size_t n, int count, int dbl, float *const *fcols,
                    double *const *dcols, size_t row)
{
    const char *p = s, *end = s + n;
    double dv[16];
    float fv[16];
    if (count > 16)
        return 0;
    for (int k = 0; k < count; k++) {
        while (p < end && is_blank_char(*p))
            p++;
        p = scan_decimal(p, end, &dv[k]);
        if (!p || (!dbl && !exact_float(dv[k], &fv[k])))
            return 0;
        while (p < end && is_blank_char(*p))
            p++;
        if (k + 1 < count) {
            if (p == end || *p != ',')
                return 0;
            p++;
        } else if (p != end) {
            return 0;
        }
    }
    for (int k = 0; k < count; k++) {
        if (dbl)
            dcols[k][row] = dv[k];
        else
            fcols[k][row] = fv[k];
    }
    return 1;
}

static bg_status read_rows(bgt_csv *c, int count, int dbl, float *const *fcols, double *const *dcols,
                     size_t max, size_t *rows)
{
    size_t got = 0;
    while (got < max) {
        char *s;
        size_t n;
        int r = next_line(c, &s, &n);
        if (r < 0)
            return (bg_status)-r;
        if (r == 0)
            break;
        if (bgt_csv_fast_path && !c->blank &&
            fast_row(s, n, count, dbl, fcols, dcols, got)) {
            got++;
            continue;
        }
        if (line_is_blank(s, n)) {
            if (!c->blank)
                c->blank = c->line;
            continue;
        }
        if (c->blank) {
            /* Blank lines at the very end are harmless; inside the data they mean
             * a damaged or concatenated file. */
            c->line = c->blank;
            return row_error(c, 1, "blank line inside the data%s", "");
        }
        bg_status e = parse_row(c, s, n, count, dbl, fcols, dcols, got);
        if (e)
            return e;
        got++;
    }
    *rows = got;
    return 0;
}

bg_status bgt_csv_read_float(bgt_csv *c, int count, float *const *cols, size_t max, size_t *rows)
{
    return read_rows(c, count, 0, cols, NULL, max, rows);
}

bg_status bgt_csv_read_double(bgt_csv *c, int count, double *const *cols, size_t max, size_t *rows)
{
    return read_rows(c, count, 1, NULL, cols, max, rows);
}
