/* SPDX-License-Identifier: MIT */
/* The library's ISA rule and its BUMPGRAD_ISA report (issue 9, item 4):
 *  - bg_isa_supported() is 1 exactly for the levels bg_isa_force() accepts,
 *    each of which has a kernel table here, and 0 outside the enum;
 *  - bg_isa_env_status() names a bad BUMPGRAD_ISA and lists the supported
 *    levels, and the lazy initialisation ignores that value (best level);
 *    a good value is BG_OK and is the active level.
 * BUMPGRAD_ISA is read once per process, so each value runs in its own child
 * (this program re-executed with --child; the parent makes no library call
 * before the children). */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bumpgrad.h"
#include "kernels/kernels.h"
#include "check.h"
#include "../kernels/isa_child.h"

/* Child: print "STATUS ACTIVE|MESSAGE" for the environment it was given. */
static int child(void)
{
    char msg[256];
    memset(msg, 'x', sizeof msg);
    bg_status s = bg_isa_env_status(msg, sizeof msg);
    if (!memchr(msg, '\0', sizeof msg))
        return 3;
    printf("%d %s|%s\n", (int)s, bg_isa_name(bg_isa_active()), msg);
    return 0;
}

static const char *const names[] = {"scalar", "sse2", "avx2", "avx512", "neon"};

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "--child") == 0)
        return child();

    /* Children first: the parent has not initialised the dispatch. The
     * expected list and levels come from bg_isa_supported() afterwards, in
     * the parent (the same CPU). */
    struct {
        const char *value;
        char line[512];
        int ok;
    } runs[8 + BG_ISA_COUNT];
    const char *values[] = {NULL, "", "bogus", "AVX2", "c", "avx2 ", "sse4", "neon"};
    int nruns = 0;
    for (size_t k = 0; k < sizeof values / sizeof values[0]; k++)
        runs[nruns++].value = values[k];
    for (int i = 0; i < BG_ISA_COUNT; i++)
        runs[nruns++].value = names[i];
    for (int k = 0; k < nruns; k++)
        runs[k].ok =
            run_child(argv[0], runs[k].value, runs[k].line, sizeof runs[k].line, child) == 0;

    /* The rule: scalar always, nothing outside the enum, and exactly what
     * bg_isa_force() accepts; every supported level has a kernel table. */
    bg_isa best = bg_isa_best(), start = bg_isa_active();
    char have[128] = "";
    int rule_bad = 0;
    CHECK(bg_isa_supported(BG_ISA_SCALAR) == 1, "scalar not supported");
    CHECK(bg_isa_supported(best) == 1, "best level %s not supported", bg_isa_name(best));
    CHECK(bg_isa_supported((bg_isa)-1) == 0 && bg_isa_supported(BG_ISA_COUNT) == 0 &&
              bg_isa_supported((bg_isa)99) == 0,
          "values outside the enum are supported");
    for (int i = 0; i < BG_ISA_COUNT; i++) {
        int sup = bg_isa_supported((bg_isa)i);
        bg_status fs = bg_isa_force((bg_isa)i);
        int chain = i == BG_ISA_SCALAR || i == (int)best ||
                    (i != BG_ISA_NEON && best != BG_ISA_NEON && i <= (int)best);
        if (sup != (fs == BG_OK) || sup != chain || (sup && !bg_kernels_for((bg_isa)i)) ||
            (!sup && fs != BG_ERR_UNSUPPORTED_ISA) || (sup && bg_isa_active() != (bg_isa)i)) {
            rule_bad++;
            CHECK(0, "%s: supported %d, force %s, chain rule %d", names[i], sup,
                  bg_status_string(fs), chain);
        }
        if (sup) {
            if (have[0])
                strcat(have, ", ");
            strcat(have, names[i]);
        }
    }
    bg_isa_force(start);
    printf("bg_isa_supported: best %s, supported {%s}, agrees with bg_isa_force and the chain "
           "rule: %s\n", bg_isa_name(best), have, rule_bad ? "NO" : "yes");

    /* Each child's report. */
    int env_bad = 0;
    for (int k = 0; k < nruns; k++) {
        const char *v = runs[k].value;
        bg_isa want;
        int known = v && bg_isa_parse(v, &want) == BG_OK;
        int good = !v || !*v || (known && bg_isa_supported(want));
        bg_status ws = good ? BG_OK : known ? BG_ERR_UNSUPPORTED_ISA : BG_ERR_INVALID_ARGUMENT;
        char expect[512];
        const char *active = good && v && *v ? bg_isa_name(want) : bg_isa_name(best);
        if (good)
            snprintf(expect, sizeof expect, "%d %s|\n", (int)ws, active);
        else if (known)
            snprintf(expect, sizeof expect,
                     "%d %s|BUMPGRAD_ISA: ISA level \"%s\" is not available here (this CPU has: "
                     "%s)\n", (int)ws, active, v, have);
        else
            snprintf(expect, sizeof expect,
                     "%d %s|BUMPGRAD_ISA: unknown ISA level \"%s\" (this CPU has: %s)\n",
                     (int)ws, active, v, have);
        printf("  BUMPGRAD_ISA=%s%s%s -> %s", v ? "\"" : "(unset)", v ? v : "", v ? "\"" : "",
               runs[k].line);
        if (!runs[k].ok || strcmp(runs[k].line, expect) != 0) {
            env_bad++;
            CHECK(0, "child for %s: got \"%s\", want \"%s\"", v ? v : "(unset)", runs[k].line,
                  expect);
        }
    }
    /* At least one refused value of each kind was exercised. */
    CHECK(strstr(runs[2].line, "unknown ISA level \"bogus\"") != NULL, "bogus not reported");
    int refused_level = 0;
    for (int k = 0; k < nruns; k++)
        refused_level |= strstr(runs[k].line, "is not available here") != NULL;
    CHECK(refused_level, "no unsupported level was refused (neon or avx512 on x86, sse2 on arm)");

    /* Truncation: always NUL-terminated within msglen; NULL buffer allowed. */
    setenv("BUMPGRAD_ISA", "a-rather-long-unknown-isa-name", 1);
    char small[8];
    memset(small, 'x', sizeof small);
    bg_status s = bg_isa_env_status(small, sizeof small);
    CHECK(s == BG_ERR_INVALID_ARGUMENT && small[7] == '\0' && strlen(small) == 7,
          "truncated message: %s", small);
    CHECK(bg_isa_env_status(NULL, 0) == BG_ERR_INVALID_ARGUMENT, "NULL buffer");
    CHECK(bg_isa_active() == start, "env_status changed the active level");
    unsetenv("BUMPGRAD_ISA");
    CHECK(bg_isa_env_status(small, sizeof small) == BG_OK && small[0] == '\0', "unset: BG_OK");
    printf("bg_isa_env_status: %d child processes, %d wrong\n", nruns, env_bad);
    return check_summary("test_isa_status");
}
