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
        if (ch == '"' || ch == '\\') {
            out[o++] = '\\';
            out[o++] = (char)ch;
        } else if (ch < 0x20 || ch == 0x7f)
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

/* Powers of ten of one digit-accumulator step (10^0..10^8). */
static const uint64_t pow10_u64[9] = {1, 10, 100, 1000, 10000, 100000, 1000000, 10000000,
                                      100000000};

/* Bytes that must be readable past the end of any text the fast path scans
 * (the eight-byte loads below). The scanned text must end with a byte that
 * cannot continue a number (NUL, ',', a blank): the scanner then never looks
 * at the bytes of another field, and needs no end pointer in its loops. */
#define SCAN_PAD 8

/* The decimal digits at p appended to *w (w = 10 w + digit each); returns the
 * number of digits. Eight bytes at a time (little-endian SWAR, after Lemire's
 * fast_float parse_eight_digits_unrolled): subtracting '0' from every byte
 * leaves 0..9 exactly in the digit bytes, and the first byte that is not a
 * digit ends the run; a borrow or carry out of it only reaches the bytes after
 * it, which are dropped. *w wraps for more than 19 digits: the caller rejects
 * those. */
static inline __attribute__((always_inline)) int scan_digits(const char **pp, uint64_t *wp)
{
    const char *p = *pp, *p0 = p;
    uint64_t w = *wp;
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    for (;;) {
        uint64_t v;
        memcpy(&v, p, 8);
        v -= UINT64_C(0x3030303030303030);
        uint64_t bad = (v | (v + UINT64_C(0x0606060606060606))) & UINT64_C(0xF0F0F0F0F0F0F0F0);
        int k = bad ? __builtin_ctzll(bad) >> 3 : 8;
        if (k == 0)
            break;
        if (k < 8)
            v <<= 8 * (8 - k); /* the k digits on top, zeros (leading zeros) below */
        /* First byte = most significant digit: pairs, then quads, then the eight. */
        v = v * 10 + (v >> 8);
        v = (((v & UINT64_C(0x000000FF000000FF)) * (100 + (UINT64_C(1000000) << 32))) +
             (((v >> 16) & UINT64_C(0x000000FF000000FF)) * (1 + (UINT64_C(10000) << 32)))) >>
            32;
        w = w * pow10_u64[k] + v;
        p += k;
        if (k < 8)
            break;
    }
#else
    unsigned dig;
    while ((dig = (unsigned)(*p - '0')) < 10)
        w = w * 10 + dig, p++;
#endif
    *pp = p, *wp = w;
    return (int)(p - p0);
}

/* Scan a decimal at p (see SCAN_PAD for what must follow it): the end of its
 * text and, in *out, its value if the fast path applies and is exact; NULL to
 * fall back. */
static inline __attribute__((always_inline)) const char *scan_decimal(const char *p, double *out)
{
    int neg = *p == '-';
    p += neg | (*p == '+'); /* no branch on the sign (random in a point table) */
    uint64_t w = 0;
    int exp10 = 0;
    unsigned dig;
    /* The integer part is short in a point table ("-13.4567891"): byte by byte. */
    const char *d0 = p;
    while ((dig = (unsigned)(*p - '0')) < 10)
        w = w * 10 + dig, p++;
    int digits = (int)(p - d0);
    if (*p == '.') {
        p++;
        exp10 = -scan_digits(&p, &w);
        digits -= exp10;
    }
    /* 19 digits always fit in 64 bits (leading zeros included: a rare case
     * with more digits simply takes strtod). */
    if (digits == 0 || digits > 19)
        return NULL;
    if ((*p | 0x20) == 'e') {
        p++;
        int eneg = 0, ev = 0;
        if (*p == '-' || *p == '+')
            eneg = *p == '-', p++;
        const char *e0 = p;
        while ((dig = (unsigned)(*p - '0')) < 10 && ev < 100000)
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
 * applies and is exact, 0 to fall back. s[0..n) need not be terminated: it is
 * scanned from a padded copy (a longer field is no plain decimal anyway). */
static int fast_decimal(const char *s, size_t n, double *out)
{
    char t[64 + SCAN_PAD] = {0};
    if (n >= 64)
        return 0;
    memcpy(t, s, n);
    return scan_decimal(t, out) == t + n;
}

/* d is the double of a decimal; 1 with *out if (float)d is the correctly
 * rounded float of that decimal. */
static inline int exact_float(double d, float *out)
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
    double d = 0;
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
    /* +1: the NUL after a line; SCAN_PAD: the fast path's eight-byte loads.
     * Zeroed, so that those loads never see undefined bytes. */
    c->buf = calloc(BUF_CAP + 1 + SCAN_PAD, 1);
    if (!c->buf) {
        bgt_csv_close(c);
        return bgt_fail(c->err, BG_ERR_OUT_OF_MEMORY, "out of memory");
    }
    return 0;
}

void bgt_csv_close(bgt_csv *c)
{
    free(c->arena);
    free(c->offs);
    c->arena = NULL;
    c->offs = NULL;
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

/* The header line of both header readers: the wanted names joined by ',' into
 * want (for messages), the line in *s, *n and in *pos its first byte after a
 * UTF-8 byte-order mark; an empty input is an error naming the header. */
static bg_status header_line(bgt_csv *c, const char *const *names, int count, char want[128],
                             char **s, size_t *n, size_t *pos)
{
    want[0] = '\0';
    for (int k = 0; k < count; k++) {
        strncat(want, names[k], 128 - strlen(want) - 2);
        if (k + 1 < count)
            strcat(want, ",");
    }
    int r = next_line(c, s, n);
    if (r < 0)
        return (bg_status)-r;
    if (r == 0) {
        c->line = 1;
        return row_error(c, 1, "empty input, expected the header \"%s\"", want);
    }
    /* A byte-order mark is what spreadsheet exports put first; it is not data. */
    *pos = *n >= 3 && memcmp(*s, "\xEF\xBB\xBF", 3) == 0 ? 3 : 0;
    return BG_OK;
}

bg_status bgt_csv_header(bgt_csv *c, const char *const *names, int count)
{
    char *s, want[128], got[64];
    size_t n, pos;
    bg_status st = header_line(c, names, count, want, &s, &n, &pos);
    if (st)
        return st;
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

static size_t field_end(const char *s, size_t n, size_t b);

/* One header name: blanks and one pair of double quotes around it removed. */
static void header_name(const char *s, size_t b, size_t e, size_t *nb, size_t *ne)
{
    while (b < e && is_blank_char(s[b]))
        b++;
    while (e > b && is_blank_char(s[e - 1]))
        e--;
    if (e - b >= 2 && s[b] == '"' && s[e - 1] == '"')
        b++, e--;
    *nb = b, *ne = e;
}

static int same_name(const char *s, size_t n, const char *name)
{
    if (strlen(name) != n)
        return 0;
    for (size_t i = 0; i < n; i++)
        if (tolower((unsigned char)s[i]) != tolower((unsigned char)name[i]))
            return 0;
    return 1;
}

bg_status bgt_csv_header_map(bgt_csv *c, const char *const *names, int count)
{
    int have[BGT_CSV_MAX_COLS] = {0}, found = 0, identity = 1;
    char *s, want[128], got[64];
    size_t n, pos;
    bg_status st = header_line(c, names, count, want, &s, &n, &pos);
    if (st != BG_OK)
        return st;
    c->ncols = 0;
    c->id_header[0] = c->extra_header[0] = '\0';
    for (;;) {
        size_t e = field_end(s, n, pos), nb, ne;
        if (c->ncols == BGT_CSV_MAX_COLS)
            return bgt_fail(c->err, BG_ERR_FORMAT, "%s:1:%zu: more than %d columns", c->name,
                            pos + 1, BGT_CSV_MAX_COLS);
        header_name(s, pos, e, &nb, &ne);
        int role = -1;
        for (int k = 0; k < count; k++)
            if (same_name(s + nb, ne - nb, names[k])) {
                if (have[k]) {
                    char msg[160];
                    snprintf(msg, sizeof msg, "column \"%s\" appears twice in the header",
                             names[k]);
                    return bgt_fail(c->err, BG_ERR_FORMAT, "%s:1:%zu: %s", c->name, nb + 1, msg);
                }
                have[k] = 1, role = k, found++;
            }
        if (role < 0 && same_name(s + nb, ne - nb, "id") && !c->id_header[0])
            role = -2;
        /* The exact old header ("x,y,z") keeps the fast path and the old output. */
        if (role != c->ncols || ne - nb != strlen(names[role]) ||
            memcmp(s + nb, names[role], ne - nb) != 0)
            identity = 0;
        char *dst = role == -2 ? c->id_header : c->extra_header;
        size_t cap = role == -2 ? sizeof c->id_header : sizeof c->extra_header;
        if (role < 0) {
            size_t l = strlen(dst);
            if (l + (e - pos) + 2 > cap)
                return bgt_fail(c->err, BG_ERR_FORMAT, "%s:1:%zu: header too long", c->name,
                                pos + 1);
            if (role == -1 && l)
                dst[l++] = ',';
            memcpy(dst + l, s + pos, e - pos);
            dst[l + (e - pos)] = '\0';
        }
        c->role[c->ncols++] = (signed char)role;
        if (e >= n)
            break;
        pos = e + 1;
    }
    if (found < count) {
        if (found == 0) {
            char msg[256];
            snprintf(msg, sizeof msg, "expected the header \"%s\" (any order, any case, extra "
                                      "columns allowed), got \"%s\"",
                     want, quote(s, n, got, sizeof got));
            return bgt_fail(c->err, BG_ERR_FORMAT, "%s:1:1: %s", c->name, msg);
        }
        for (int k = 0; k < count; k++)
            if (!have[k]) {
                char msg[256];
                snprintf(msg, sizeof msg, "the header has no column \"%s\" (needs %s), got \"%s\"",
                         names[k], want, quote(s, n, got, sizeof got));
                return bgt_fail(c->err, BG_ERR_FORMAT, "%s:1:%zu: %s", c->name, n + 1, msg);
            }
    }
    c->mapped = !(identity && c->ncols == count);
    return 0;
}

/* Split and parse one row; `dbl` picks strtod into dcols, else strtof into fcols. */
static bg_status parse_row(bgt_csv *c, char *s, size_t n, size_t pos0, int count, int dbl,
                           float *const *fcols, double *const *dcols, size_t row)
{
    char tmp[64];
    size_t pos = pos0;
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

/* The `count` fields of a row of plain decimals at p (a NUL-terminated line,
 * SCAN_PAD readable bytes after it), stored in row `row` of dcols (double) or
 * fcols (float): the end of the row's text (after the last field and its
 * blanks), or NULL if a field needs the careful path. A row given up halfway
 * may have stored some fields: the careful path then stores the same row
 * again (or fails). */
static inline __attribute__((always_inline)) const char *
fast_fields(const char *p, int count, int dbl, float *const *fcols, double *const *dcols,
            size_t row)
{
    for (int k = 0; k < count; k++) {
        double dv;
        while (is_blank_char(*p))
            p++;
        p = scan_decimal(p, &dv);
        if (!p)
            return NULL;
        if (dbl)
            dcols[k][row] = dv;
        else if (!exact_float(dv, &fcols[k][row]))
            return NULL;
        while (is_blank_char(*p))
            p++;
        if (k + 1 < count) {
            if (*p != ',')
                return NULL;
            p++;
        }
    }
    return p;
}

/* A whole line of plain decimals through the fast path: 1 if every field was
 * taken (values stored), 0 to parse the row again the careful way (which also
 * words the errors). */
static int fast_row(const char *s, size_t n, int count, int dbl, float *const *fcols,
                    double *const *dcols, size_t row)
{
    return fast_fields(s, count, dbl, fcols, dcols, row) == s + n;
}

/* The next row straight from the read buffer, without looking for its line
 * end first: 1 if a complete line of plain decimals ("\n" or "\r\n" after it,
 * within the line length limit) was taken and consumed, 0 to take the next
 * line the general way (next_line), for instance at the end of the buffer. */
static int fast_buffered_row(bgt_csv *c, int count, int dbl, float *const *fcols,
                             double *const *dcols, size_t row)
{
    char *p = c->buf + c->start, *end = c->buf + c->end;
    const char *q;
    *end = '\0'; /* the scan stops here at the latest (buf has the spare bytes) */
    /* Constant arguments for the common tables (eval: 3 columns, perturb: 6)
     * let the compiler unroll the fields and drop the precision tests. */
    if (count == 3)
        q = dbl ? fast_fields(p, 3, 1, fcols, dcols, row) : fast_fields(p, 3, 0, fcols, dcols, row);
    else if (count == 6)
        q = dbl ? fast_fields(p, 6, 1, fcols, dcols, row) : fast_fields(p, 6, 0, fcols, dcols, row);
    else
        q = fast_fields(p, count, dbl, fcols, dcols, row);
    if (!q || q >= end)
        return 0;
    size_t n = (size_t)(q - p); /* the line without its "\n" or "\r\n", as next_line */
    if (*q == '\r')
        q++;
    if (q >= end || *q != '\n' || n > BGT_CSV_MAX_LINE)
        return 0;
    c->start = (size_t)(q + 1 - c->buf);
    c->line++;
    return 1;
}

/* End of the field starting at s[b] (a ',' or n); a field starting with '"'
 * runs to its closing quote ("" is a quote inside). */
static size_t field_end(const char *s, size_t n, size_t b)
{
    size_t e = b;
    while (e < n && is_blank_char(s[e]))
        e++;
    if (e < n && s[e] == '"') {
        for (e++; e < n; e++)
            if (s[e] == '"') {
                if (e + 1 < n && s[e + 1] == '"')
                    e++;
                else {
                    e++;
                    break;
                }
            }
    }
    while (e < n && s[e] != ',')
        e++;
    return e;
}

static int arena_add(bgt_csv *c, const char *s, size_t n, size_t *start)
{
    if (c->arena_len + n + 1 > c->arena_cap) {
        size_t cap = c->arena_cap ? c->arena_cap : 1 << 16;
        while (cap < c->arena_len + n + 1)
            cap *= 2;
        char *a = realloc(c->arena, cap);
        if (!a)
            return 0;
        c->arena = a;
        c->arena_cap = cap;
    }
    *start = c->arena_len;
    memcpy(c->arena + c->arena_len, s, n);
    c->arena_len += n;
    return 1;
}

/* A row of a mapped header: split into ncols fields, parse the wanted ones
 * (same rules and messages as parse_row), keep the id and extra text. */
static bg_status parse_mapped(bgt_csv *c, char *s, size_t n, int dbl, float *const *fcols,
                              double *const *dcols, size_t row)
{
    size_t b = 0, *o = c->offs + 4 * row;
    o[0] = o[1] = o[2] = o[3] = 0;
    int extras = 0;
    for (int k = 0; k < c->ncols; k++) {
        if (k > 0 && b > n) {
            char msg[96];
            snprintf(msg, sizeof msg, "expected %d fields, got %d", c->ncols, k);
            return bgt_fail(c->err, BG_ERR_FORMAT, "%s:%lu:%zu: %s", c->name, c->line, n + 1, msg);
        }
        size_t e = field_end(s, n, b);
        if (k + 1 == c->ncols && e < n) {
            int extra = 1;
            for (size_t i = e + 1; i < n; i++)
                extra += s[i] == ',';
            char msg[96];
            snprintf(msg, sizeof msg, "expected %d fields, got %d", c->ncols, c->ncols + extra);
            return bgt_fail(c->err, BG_ERR_FORMAT, "%s:%lu:%zu: %s", c->name, c->line, e + 2, msg);
        }
        if (k + 1 < c->ncols && e == n) {
            char msg[96];
            snprintf(msg, sizeof msg, "expected %d fields, got %d", c->ncols, k + 1);
            return bgt_fail(c->err, BG_ERR_FORMAT, "%s:%lu:%zu: %s", c->name, c->line, n + 1, msg);
        }
        int r = c->role[k];
        size_t vb = b, ve = e;
        while (vb < ve && is_blank_char(s[vb]))
            vb++;
        while (ve > vb && is_blank_char(s[ve - 1]))
            ve--;
        double dv = 0;
        float fv;
        if (r >= 0 && bgt_csv_fast_path && scan_decimal(s + vb, &dv) == s + ve &&
            (dbl || exact_float(dv, &fv))) {
            if (dbl)
                dcols[r][row] = dv;
            else
                fcols[r][row] = fv;
        } else if (r >= 0) {
            char saved = s[e];
            s[e] = '\0';
            bg_status st = parse_row(c, s, e, b, 1, dbl, fcols ? fcols + r : NULL,
                                     dcols ? dcols + r : NULL, row);
            s[e] = saved;
            if (st)
                return st;
        } else {
            size_t start;
            if (r == -2) {
                if (!arena_add(c, s + b, e - b, &start))
                    return bgt_fail(c->err, BG_ERR_OUT_OF_MEMORY, "out of memory");
                o[0] = start, o[1] = e - b;
            } else {
                if (!arena_add(c, ",", extras ? 1 : 0, &start) ||
                    !arena_add(c, s + b, e - b, &start))
                    return bgt_fail(c->err, BG_ERR_OUT_OF_MEMORY, "out of memory");
                if (!extras)
                    o[2] = start;
                o[3] += e - b + (extras ? 1 : 0);
                extras++;
            }
        }
        b = e + 1;
    }
    return 0;
}

void bgt_csv_row_text(const bgt_csv *c, size_t row, const char **id, size_t *idlen,
                      const char **extra, size_t *extralen)
{
    static const char empty[] = "";
    if (!c->mapped || !c->arena) {
        *id = *extra = empty;
        *idlen = *extralen = 0;
        return;
    }
    const size_t *o = c->offs + 4 * row;
    *id = c->arena + o[0], *idlen = o[1];
    *extra = c->arena + o[2], *extralen = o[3];
}

static bg_status read_rows(bgt_csv *c, int count, int dbl, float *const *fcols, double *const *dcols,
                     size_t max, size_t *rows)
{
    size_t got = 0;
    c->arena_len = 0;
    if (c->mapped && c->offs_cap < max) {
        size_t *o = realloc(c->offs, 4 * max * sizeof *o);
        if (!o)
            return bgt_fail(c->err, BG_ERR_OUT_OF_MEMORY, "out of memory");
        c->offs = o;
        c->offs_cap = max;
    }
    const int fast = bgt_csv_fast_path && !c->mapped;
    while (got < max) {
        if (fast && !c->blank && fast_buffered_row(c, count, dbl, fcols, dcols, got)) {
            got++;
            continue;
        }
        char *s;
        size_t n;
        int r = next_line(c, &s, &n);
        if (r < 0)
            return (bg_status)-r;
        if (r == 0)
            break;
        if (fast && !c->blank && fast_row(s, n, count, dbl, fcols, dcols, got)) {
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
        bg_status e = c->mapped ? parse_mapped(c, s, n, dbl, fcols, dcols, got)
                                : parse_row(c, s, n, 0, count, dbl, fcols, dcols, got);
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

/* ---- writing the pass-through columns (eval, perturb) ---- */

/* [id,]COLUMNS[,extra columns]: the id first, the other columns of the input
 * after ours, as they were. */
void bgt_csv_write_header(FILE *fp, const bgt_csv *in, const char *ours)
{
    if (in->id_header[0])
        fprintf(fp, "%s,", in->id_header);
    fputs(ours, fp);
    if (in->extra_header[0])
        fprintf(fp, ",%s", in->extra_header);
    fputc('\n', fp);
}

void bgt_csv_write_row_prefix(FILE *fp, const bgt_csv *in, size_t r, const char **extra, size_t *elen)
{
    const char *id;
    size_t idlen;
    bgt_csv_row_text(in, r, &id, &idlen, extra, elen);
    if (in->id_header[0]) {
        fwrite(id, 1, idlen, fp);
        fputc(',', fp);
    }
}

void bgt_csv_write_row_suffix(FILE *fp, const bgt_csv *in, const char *extra, size_t elen)
{
    if (in->extra_header[0]) {
        fputc(',', fp);
        fwrite(extra, 1, elen, fp);
    }
    fputc('\n', fp);
}
