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

/* The verdict (check_summary) as main's exit status; the folder is removed
 * after a passing run. */
static inline int scratch_finish(const char *name)
{
    if (!check_failures)
        scratch_remove();
    return check_summary(name);
}

/* A test program's main: `PROG GROUP SCRATCH_PARENT` runs the group of that
 * name in a fresh scratch folder, which is removed after a passing run; the
 * verdict (check_summary) is the exit status, 2 for a bad call. */
typedef struct scratch_group {
    const char *name;
    void (*run)(void);
} scratch_group;

static inline int scratch_main(int argc, char **argv, const char *prog, const scratch_group *groups,
                        size_t ngroups)
{
    for (size_t i = 0; argc == 3 && i < ngroups; i++) {
        if (strcmp(argv[1], groups[i].name) != 0)
            continue;
        if (!scratch_create(argv[2], prog, argv[1]))
            return 1;
        groups[i].run();
        return scratch_finish(argv[1]);
    }
    fprintf(stderr, "usage: %s GROUP SCRATCH_PARENT; groups:", prog);
    for (size_t i = 0; i < ngroups; i++)
        fprintf(stderr, " %s", groups[i].name);
    fputc('\n', stderr);
    return 2;
}

#endif
