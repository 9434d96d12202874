/* SPDX-License-Identifier: MIT */
/* Run this test program again as a child with a given BUMPGRAD_ISA (the
 * variable is read once per process, so each value needs its own), and read
 * the line it prints. Used by kernels/isa_env.c and core/test_isa_status.c. */
#ifndef BUMPGRAD_TESTS_ISA_CHILD_H
#define BUMPGRAD_TESTS_ISA_CHILD_H

#include <stdio.h>
#include <stdlib.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

/* `self --child` with BUMPGRAD_ISA = value (NULL: unset); its standard output
 * in line[0..sz). 0 if it exited with status 0, else -1. If exec fails (qemu-user
 * without binfmt_misc, the cross test), the forked copy runs child() itself: the
 * parent has made no library call, so the copy reads BUMPGRAD_ISA afresh. */
static int run_child(const char *self, const char *value, char *line, size_t sz,
                     int (*child)(void))
{
    int fd[2];
    if (pipe(fd) != 0)
        return -1;
    fflush(stdout); /* or the child would inherit and re-emit buffered output */
    pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        close(fd[0]);
        dup2(fd[1], 1);
        if (value)
            setenv("BUMPGRAD_ISA", value, 1);
        else
            unsetenv("BUMPGRAD_ISA");
        execl(self, self, "--child", (char *)NULL);
        int rc = child();
        fflush(stdout);
        _exit(rc);
    }
    close(fd[1]);
    size_t got = 0;
    ssize_t r;
    while (got + 1 < sz && (r = read(fd[0], line + got, sz - 1 - got)) > 0)
        got += (size_t)r;
    line[got] = 0;
    close(fd[0]);
    int st;
    waitpid(pid, &st, 0);
    return WIFEXITED(st) && WEXITSTATUS(st) == 0 ? 0 : -1;
}

#endif
