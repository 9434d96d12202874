/* SPDX-License-Identifier: MIT */
/* Shared pieces of the libFuzzer harnesses (tests/fuzz): a private temporary
 * directory, writing an input into it, the checks every harness makes on a
 * result (a failure always carries a message; nothing is left behind), and a
 * watchdog for the I/O shim's child processes (mesh import, VDB probe).
 *
 * The watchdog: the mesh import child has no timeout (issue 13 item 3) and the
 * VDB probe child has neither a memory cap nor a timeout shorter than 60 s
 * (item 4). libFuzzer only watches its own process, so a hung or ballooning
 * child would hold a core or gigabytes of the shared machine indefinitely.
 * While a harness is inside a call that forks, a thread polls the process's
 * children every 50 ms and SIGKILLs any child older than FUZZ_CHILD_TIMEOUT
 * seconds (default 20) or larger than FUZZ_CHILD_MAX_MB MiB resident (default
 * 2048). The harness then aborts, so libFuzzer saves the input as a crash
 * artifact: a hang or a memory blow-up is a finding, reported like a crash. */
#ifndef BUMPGRAD_FUZZ_UTIL_H
#define BUMPGRAD_FUZZ_UTIL_H

#ifndef _GNU_SOURCE
#error "define _GNU_SOURCE before the first include (fmemopen, mkdtemp, clock_gettime)"
#endif
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <time.h>
#include <unistd.h>

/* The in-process variants (fuzz_mesh_inproc, fuzz_vdb_inproc: the same harness
 * source built with -DFUZZ_NO_FORK). The I/O shim loads in-process when it
 * cannot fork: the mesh import runs import_guarded, the very function the
 * import child runs (same assimp flags and post-processing), in this process;
 * the VDB open skips its probe child and runs open_impl, which the parent runs
 * after every probe anyway. This fork() takes the place of libc's for the
 * module (exports.list exports it) and always fails, so the shim takes that
 * path with no fork, pipe, child or 10 ms polling per input. What is lost:
 * the child's isolation (an abort inside assimp or OpenVDB, which the child
 * would contain, kills the fuzzer and is a finding about that library) and the
 * child's limits (the harness's -rss_limit_mb and -timeout stand in). */
#ifdef FUZZ_NO_FORK
pid_t fork(void);
pid_t fork(void)
{
    errno = EAGAIN;
    return -1;
}
#endif

/* Report a broken invariant and abort: libFuzzer saves the input. */
#define FUZZ_CHECK(cond, ...)                                                                    \
    do {                                                                                         \
        if (!(cond)) {                                                                           \
            fprintf(stderr, "fuzz invariant failed at %s:%d: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                                        \
            fputc('\n', stderr);                                                                 \
            abort();                                                                             \
        }                                                                                        \
    } while (0)

static char fuzz_dir[256];

static inline void fuzz_remove_dir(void)
{
    DIR *d = opendir(fuzz_dir);
    if (d) {
        struct dirent *de;
        char p[512];
        while ((de = readdir(d)))
            if (strcmp(de->d_name, ".") && strcmp(de->d_name, "..")) {
                snprintf(p, sizeof p, "%s/%s", fuzz_dir, de->d_name);
                unlink(p);
            }
        closedir(d);
    }
    rmdir(fuzz_dir);
}

/* Create the process's private directory (once) under $TMPDIR or /tmp. */
static inline const char *fuzz_tmpdir(void)
{
    if (!fuzz_dir[0]) {
        const char *t = getenv("TMPDIR");
        snprintf(fuzz_dir, sizeof fuzz_dir, "%s/bumpgrad-fuzz.XXXXXX", t && *t ? t : "/tmp");
        if (!mkdtemp(fuzz_dir)) {
            perror("fuzz: mkdtemp");
            abort();
        }
        atexit(fuzz_remove_dir);
    }
    return fuzz_dir;
}

/* Write data to fuzz_dir/name; returns the path (static buffer). */
static inline const char *fuzz_write_file(const char *name, const uint8_t *data, size_t size)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", fuzz_tmpdir(), name);
    FILE *f = fopen(path, "wb");
    FUZZ_CHECK(f != NULL, "cannot create %s: %s", path, strerror(errno));
    FUZZ_CHECK(size == 0 || fwrite(data, 1, size, f) == size, "short write to %s", path);
    FUZZ_CHECK(fclose(f) == 0, "closing %s failed", path);
    return path;
}

/* Number of entries in fuzz_dir other than `except` (NULL: none excepted); the
 * name of the first one in *first (static buffer) for messages. */
static inline int fuzz_dir_entries(const char *except, const char *except2, const char **first)
{
    static char name[256];
    int n = 0;
    DIR *d = opendir(fuzz_tmpdir());
    FUZZ_CHECK(d != NULL, "cannot list %s", fuzz_dir);
    struct dirent *de;
    name[0] = '\0';
    while ((de = readdir(d))) {
        if (!strcmp(de->d_name, ".") || !strcmp(de->d_name, ".."))
            continue;
        if ((except && !strcmp(de->d_name, except)) || (except2 && !strcmp(de->d_name, except2)))
            continue;
        if (!n)
            snprintf(name, sizeof name, "%s", de->d_name);
        n++;
    }
    closedir(d);
    if (first)
        *first = name;
    return n;
}

/* ---- the child watchdog ---- */

static atomic_int fuzz_wd_armed;    /* 1 while a harness is in a forking call */
static atomic_int fuzz_wd_fired;    /* 1: timeout, 2: memory (since the last arm) */
static atomic_long fuzz_wd_peak_kb; /* largest child RSS seen since the last arm */
static long fuzz_wd_timeout_ms = 20000, fuzz_wd_max_kb = 2048L * 1024;

static inline long fuzz_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (long)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

/* Children of this process: the pids listed in /proc/self/task/(tid)/children. */
static inline int fuzz_children(pid_t *out, int cap)
{
    int n = 0;
    DIR *d = opendir("/proc/self/task");
    if (!d)
        return 0;
    struct dirent *de;
    while ((de = readdir(d)) && n < cap) {
        if (de->d_name[0] == '.')
            continue;
        char p[300];
        snprintf(p, sizeof p, "/proc/self/task/%s/children", de->d_name);
        FILE *f = fopen(p, "r");
        if (!f)
            continue;
        long pid;
        while (n < cap && fscanf(f, "%ld", &pid) == 1)
            out[n++] = (pid_t)pid;
        fclose(f);
    }
    closedir(d);
    return n;
}

static inline long fuzz_rss_kb(pid_t pid)
{
    char p[64];
    snprintf(p, sizeof p, "/proc/%ld/statm", (long)pid);
    FILE *f = fopen(p, "r");
    long pages_total = 0, pages_rss = 0;
    if (!f)
        return 0;
    if (fscanf(f, "%ld %ld", &pages_total, &pages_rss) != 2)
        pages_rss = 0;
    fclose(f);
    return pages_rss * (sysconf(_SC_PAGESIZE) / 1024);
}

static inline void *fuzz_watchdog(void *arg)
{
    (void)arg;
    pid_t seen[64];
    long since[64];
    int nseen = 0;
    for (;;) {
        struct timespec ts = {0, 50 * 1000 * 1000};
        nanosleep(&ts, NULL);
        pid_t kids[64];
        int n = atomic_load(&fuzz_wd_armed) ? fuzz_children(kids, 64) : 0;
        long now = fuzz_now_ms();
        pid_t nseen_pid[64];
        long nsince[64];
        int nn = 0;
        for (int i = 0; i < n; i++) {
            long t0 = now;
            for (int j = 0; j < nseen; j++)
                if (seen[j] == kids[i])
                    t0 = since[j];
            long rss = fuzz_rss_kb(kids[i]);
            if (rss > atomic_load(&fuzz_wd_peak_kb))
                atomic_store(&fuzz_wd_peak_kb, rss);
            if (now - t0 > fuzz_wd_timeout_ms || rss > fuzz_wd_max_kb) {
                fprintf(stderr, "fuzz watchdog: child %ld %s (%ld ms, %ld MiB resident): killed\n",
                        (long)kids[i], rss > fuzz_wd_max_kb ? "over the memory limit" : "hung",
                        now - t0, rss / 1024);
                atomic_store(&fuzz_wd_fired, rss > fuzz_wd_max_kb ? 2 : 1);
                kill(kids[i], SIGKILL);
                continue;
            }
            nseen_pid[nn] = kids[i];
            nsince[nn++] = t0;
        }
        memcpy(seen, nseen_pid, sizeof(pid_t) * (size_t)nn);
        memcpy(since, nsince, sizeof(long) * (size_t)nn);
        nseen = nn;
    }
    return NULL;
}

static inline void fuzz_watchdog_start(void)
{
    const char *t = getenv("FUZZ_CHILD_TIMEOUT"), *m = getenv("FUZZ_CHILD_MAX_MB");
    if (t && atol(t) > 0)
        fuzz_wd_timeout_ms = atol(t) * 1000;
    if (m && atol(m) > 0)
        fuzz_wd_max_kb = atol(m) * 1024;
    pthread_t th;
    pthread_attr_t a;
    pthread_attr_init(&a);
    pthread_attr_setdetachstate(&a, PTHREAD_CREATE_DETACHED);
    FUZZ_CHECK(pthread_create(&th, &a, fuzz_watchdog, NULL) == 0, "no watchdog thread");
    pthread_attr_destroy(&a);
}

/* With FUZZ_WATCHDOG defined before the include, the harness's libFuzzer
 * initializer is this one: it starts the watchdog before the first input. */
#ifdef FUZZ_WATCHDOG
int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    fuzz_watchdog_start();
    return 0;
}
#endif

static inline void fuzz_watchdog_arm(void)
{
    atomic_store(&fuzz_wd_fired, 0);
    atomic_store(&fuzz_wd_peak_kb, 0);
    atomic_store(&fuzz_wd_armed, 1);
}

/* Disarm; abort (a finding) if a child had to be killed. */
static inline void fuzz_watchdog_disarm(const char *what)
{
    atomic_store(&fuzz_wd_armed, 0);
    int f = atomic_load(&fuzz_wd_fired);
    FUZZ_CHECK(f == 0, "%s: a child process %s", what,
               f == 2 ? "went over FUZZ_CHILD_MAX_MB (unbounded memory)"
                      : "ran over FUZZ_CHILD_TIMEOUT (hang)");
}

/* A message that names the file it is about. */
static inline void fuzz_check_message(const char *what, int status, const char *msg, const char *path)
{
    if (status == 0)
        return;
    FUZZ_CHECK(msg[0] != '\0', "%s failed with status %d and an empty message", what, status);
    if (path) {
        const char *base = strrchr(path, '/');
        FUZZ_CHECK(strstr(msg, base ? base + 1 : path) != NULL,
                   "%s: message does not name the file: %s", what, msg);
    }
}

#endif
