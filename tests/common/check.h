/* SPDX-License-Identifier: MIT */
/* The one check vocabulary of the C tests (the kernel harness, checkkernels.h,
 * has its own, per ISA): CHECK(cond, printf-args) prints what failed with its
 * file and line and counts it; check_summary(name) prints the verdict and is
 * main()'s exit status, so meson marks the test red. With check_verbose set,
 * passing checks print an "ok" line too. Include from tests as
 * "common/check.h" (tests_dep puts tests/ on the include path). */
#ifndef BUMPGRAD_TESTS_COMMON_CHECK_H
#define BUMPGRAD_TESTS_COMMON_CHECK_H

#include <stdio.h>

static int check_failures;
static int check_verbose;

#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        int check_ok_ = !!(cond);                                                                  \
        if (!check_ok_)                                                                            \
            check_failures++;                                                                      \
        if (!check_ok_ || check_verbose) {                                                         \
            if (check_ok_)                                                                         \
                printf("  ok   ");                                                                 \
            else                                                                                   \
                printf("  FAIL %s:%d: ", __FILE__, __LINE__);                                      \
            printf(__VA_ARGS__);                                                                   \
            printf("\n");                                                                          \
        }                                                                                          \
    } while (0)

static inline int check_summary(const char *name)
{
    if (check_failures)
        printf("%s: %d check(s) FAILED\n", name, check_failures);
    else
        printf("%s: all checks passed\n", name);
    fflush(stdout);
    return check_failures ? 1 : 0;
}

#endif
