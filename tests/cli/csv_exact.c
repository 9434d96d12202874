/* SPDX-License-Identifier: MIT */
/* The CSV reader's decimal fast path (src/tools/common/csv.c) against
 * strtof/strtod: wherever the fast path accepts a field, its value must have
 * the bits strtof (float) or strtod (double) give, on millions of random
 * decimals and on the hard cases: float midpoints printed to 15..17 digits,
 * powers of ten at the edge of the exact range, 2^53 +- 1, the float limits,
 * subnormals, signed zeros. Also checks that the fast path takes the common
 * case (so the test cannot pass by always declining). */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "common/csv.h"

static unsigned long long state = 0x9E3779B97F4A7C15ull;
static uint64_t rnd(void)
{
    state ^= state << 13, state ^= state >> 7, state ^= state << 17;
    return state;
}

static long fails, fast_f, fast_d, total;

static void check(const char *s)
{
    size_t n = strlen(s);
    float f = 0, rf;
    double d = 0, rd;
    total++;
    if (bgt_csv_parse_number(s, n, 0, NULL, &f) == BG_OK) {
        fast_f++;
        rf = strtof(s, NULL);
        if (memcmp(&f, &rf, sizeof f) != 0 && fails++ < 20)
            fprintf(stderr, "FAIL float \"%s\": fast %a, strtof %a\n", s, (double)f, (double)rf);
    }
    if (bgt_csv_parse_number(s, n, 1, &d, NULL) == BG_OK) {
        fast_d++;
        rd = strtod(s, NULL);
        if (memcmp(&d, &rd, sizeof d) != 0 && fails++ < 20)
            fprintf(stderr, "FAIL double \"%s\": fast %a, strtod %a\n", s, d, rd);
    }
}

static void random_decimal(char *buf)
{
    int nd = 1 + (int)(rnd() % 20), point = (int)(rnd() % (unsigned)(nd + 2)) - 1;
    char *p = buf;
    unsigned sign = (unsigned)(rnd() % 3);
    if (sign == 1)
        *p++ = '-';
    else if (sign == 2 && rnd() % 8 == 0)
        *p++ = '+';
    for (int k = 0; k < nd; k++) {
        if (k == point)
            *p++ = '.';
        *p++ = (char)('0' + rnd() % 10);
    }
    if (rnd() % 3 == 0)
        p += sprintf(p, "%c%d", rnd() % 2 ? 'e' : 'E', (int)(rnd() % 80) - 40);
    *p = '\0';
}

int main(int argc, char **argv)
{
    long n = argc > 1 ? atol(argv[1]) : 2000000;
    char buf[128];
    static const char *edge[] = {
        "0", "-0", "+0", "0.0", "-0.0", "0e5", "-0e-5", "1", "-1", "0.1", "0.2", "0.3",
        "1e22", "1e23", "1e-22", "1e-23", "9007199254740992", "9007199254740993",
        "9007199254740991", "18014398509481984", "9999999999999999999", "99999999999999999999",
        "3.4028234663852886e38", "3.4028235e38", "3.4028236e38", "1.17549435e-38",
        "1.1754942e-38", "1e-45", "1.4e-45", "7e-46", "1e-39", "16777216", "16777217",
        "16777218", "16777219", "33554433", "0.000000000000000000000000001", "1.", ".5",
        "-.5", "5.e3", "1e", "1e+", "e5", ".", "-", "+", "1.5x", "0x10", "inf", "nan",
        "1e308", "1.7976931348623157e308", "2.2250738585072014e-308", "4.9e-324",
        "123456789012345678", "1234567890123456789", "0.00000000000000000000001234"};
    for (size_t k = 0; k < sizeof edge / sizeof edge[0]; k++)
        check(edge[k]);
    /* Near float midpoints: the double rounding trap. */
    for (long k = 0; k < n / 4; k++) {
        uint32_t bits = (uint32_t)rnd() & 0x7fffffffu;
        float f;
        memcpy(&f, &bits, sizeof f);
        if (!isfinite(f))
            continue;
        float g = nextafterf(f, INFINITY);
        double mid = ((double)f + (double)g) * 0.5;
        for (int digits = 15; digits <= 19; digits++) {
            snprintf(buf, sizeof buf, "%.*g", digits, mid);
            check(buf);
        }
        snprintf(buf, sizeof buf, "%.9g", (double)f);
        check(buf);
    }
    for (long k = 0; k < n; k++) {
        random_decimal(buf);
        check(buf);
    }
    /* %.9g of uniform floats: the common case must take the fast path. */
    long before = fast_f;
    for (long k = 0; k < 100000; k++) {
        float f = (float)((double)(rnd() % 4000000) / 100000.0 - 20.0);
        snprintf(buf, sizeof buf, "%.9g", (double)f);
        check(buf);
    }
    printf("%ld strings; fast path took %ld (float) and %ld (double); %ld mismatches\n", total,
           fast_f, fast_d, fails);
    if (fast_f - before < 99000) {
        fprintf(stderr, "FAIL: the fast path declined %ld of 100000 %%.9g floats\n",
                100000 - (fast_f - before));
        return 1;
    }
    return fails ? 1 : 0;
}
