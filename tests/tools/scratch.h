/* SPDX-License-Identifier: MIT */
/* The scratch folder of the tools' unit tests (test_bake.c,
 * test_io.c): one fresh folder per run under the build directory, paths in
 * it, a count of temporaries a failed write left behind. Include once, from
 * the test's main file (it defines the test's static state). */
#ifndef BUMPGRAD_TESTS_TOOLS_SCRATCH_H
#define BUMPGRAD_TESTS_TOOLS_SCRATCH_H

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "common/check.h"

static char dir[4096]; /* the scratch folder */

/* PARENT/PROG_WHAT_XXXXXX, created (mkdtemp); 0 with a message on failure. */
static int scratch_create(const char *parent, const char *prog, const char *what)
{
    snprintf(dir, sizeof dir, "%s/%s_%s_XXXXXX", parent, prog, what);
    if (!mkdtemp(dir)) {
        perror(dir);
        return 0;
    }
    return 1;
}

/* Remove the folder after a passing run (a failure's files stay for inspection). */
static void scratch_remove(void)
{
    char cmd[4200];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        printf("  note: could not remove %s\n", dir);
}

/* The verdict (check_summary) as main's exit status; the folder is removed
 * after a passing run. */
static int scratch_finish(const char *name)
{
    if (!check_failures)
        scratch_remove();
    return check_summary(name);
}

/* dir/name, valid until 8 more calls. */
static const char *path_in(const char *name)
{
    static char buf[8][4200];
    static int slot;
    slot = (slot + 1) % 8;
    snprintf(buf[slot], sizeof buf[slot], "%s/%s", dir, name);
    return buf[slot];
}

/* Entries of the scratch folder whose name contains ".tmp": a failed write
 * must not leave its temporary file behind. */
static int temp_leftovers(void)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (strstr(e->d_name, ".tmp"))
            n++;
    if (d)
        closedir(d);
    return n;
}

#endif
