/* SPDX-License-Identifier: MIT */
/* safe_file.h: temporary + fsync + rename, and the registry of live
 * temporaries that a signal removes. */
#define _GNU_SOURCE /* mkstemps */
#include "safe_file.h"
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- registry of live temporaries ----------------------------------------
 * A fixed table of atomic pointers: the signal handler may only read it and
 * call unlink() (async-signal-safe). Slots are claimed with compare-exchange,
 * so threads may register concurrently. More than MAX_LIVE_TEMPS outputs open
 * at once is not an error; the extra ones are just not removed on a signal. */
#define MAX_LIVE_TEMPS 16
static _Atomic(char *) live_temps[MAX_LIVE_TEMPS];
static atomic_int handlers_installed;

/* The handlers found when ours were installed. This file is compiled into the
 * program and into the I/O module (which has its own registry), so each copy
 * chains to the one installed before it: a signal cleans both registries. */
static const int caught[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE};
#define NCAUGHT (sizeof caught / sizeof caught[0])
static struct sigaction previous[NCAUGHT];

static void on_signal(int sig)
{
    for (int i = 0; i < MAX_LIVE_TEMPS; i++) {
        char *p = atomic_load(&live_temps[i]);
        if (p)
            unlink(p);
    }
    for (size_t k = 0; k < NCAUGHT; k++)
        if (caught[k] == sig && !(previous[k].sa_flags & SA_SIGINFO) &&
            previous[k].sa_handler != SIG_DFL && previous[k].sa_handler != SIG_IGN) {
            previous[k].sa_handler(sig); /* the other registry; it re-raises */
            break;
        }
    signal(sig, SIG_DFL);
    raise(sig);
}

static void install_handlers(void)
{
    if (atomic_exchange(&handlers_installed, 1))
        return;
    for (size_t i = 0; i < NCAUGHT; i++) {
        struct sigaction sa;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_signal;
        sigemptyset(&sa.sa_mask);
        /* Keep an inherited "ignore" (nohup, a shell's SIGPIPE policy). */
        if (sigaction(caught[i], NULL, &previous[i]) != 0 || previous[i].sa_handler == SIG_IGN)
            continue;
        sigaction(caught[i], &sa, NULL);
    }
}

static void track(char *p)
{
    install_handlers();
    for (int i = 0; i < MAX_LIVE_TEMPS; i++) {
        char *expected = NULL;
        if (atomic_compare_exchange_strong(&live_temps[i], &expected, p))
            return;
    }
}

/* By name, so a caller may pass a copy of the registered string. Returns the
 * registered pointer (NULL if none): the path API frees its own copy. */
static char *untrack(const char *p)
{
    for (int i = 0; i < MAX_LIVE_TEMPS; i++) {
        char *cur = atomic_load(&live_temps[i]);
        if (cur && (cur == p || strcmp(cur, p) == 0) &&
            atomic_compare_exchange_strong(&live_temps[i], &cur, NULL))
            return cur;
    }
    return NULL;
}

/* ---- helpers ---------------------------------------------------------------- */

static char *dup_str(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

/* 0666 & ~umask, read from /proc so that no other thread sees a changed umask
 * (umask() can only be read by setting it); the umask() round trip is the
 * fallback where /proc is missing. */
static mode_t new_file_mode(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    if (f) {
        char line[256];
        unsigned m;
        while (fgets(line, sizeof line, f))
            if (sscanf(line, "Umask: %o", &m) == 1) {
                fclose(f);
                return (mode_t)(0666 & ~m);
            }
        fclose(f);
    }
    mode_t mask = umask(022);
    umask(mask);
    return (mode_t)(0666 & ~mask);
}

/* Make a rename durable: the new directory entry must reach the disk too. */
static void sync_parent_dir(const char *path)
{
    const char *slash = strrchr(path, '/');
    char *dir = slash ? malloc((size_t)(slash - path) + 2) : NULL;
    if (slash && !dir)
        return;
    if (dir) {
        size_t n = slash == path ? 1 : (size_t)(slash - path);
        memcpy(dir, path, n);
        dir[n] = '\0';
    }
    int fd = open(dir ? dir : ".", O_RDONLY);
    if (fd >= 0) {
        (void)fsync(fd);
        close(fd);
    }
    free(dir);
}

/* Temporaries are DIR/.BASE.tmp-bumpgrad-PID-XXXXXX.EXT: BASE is the target's
 * whole file name and EXT its extension again (writers that choose the format
 * by extension still see it). A run killed by SIGKILL (or a power cut) cannot
 * clean up; the next run that writes the same target in the same folder
 * removes the temporaries of that target whose process no longer exists. */
#define TEMP_TAG ".tmp-bumpgrad-"

static void remove_stale_temps(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    size_t dirlen = (size_t)(base - path);
    char dir[4096], prefix[512];
    if (dirlen + 2 > sizeof dir || strlen(base) + sizeof TEMP_TAG + 2 > sizeof prefix)
        return;
    if (dirlen) {
        memcpy(dir, path, dirlen);
        dir[dirlen] = '\0';
    } else {
        strcpy(dir, ".");
    }
    int plen = snprintf(prefix, sizeof prefix, ".%s" TEMP_TAG, base);
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *ent;
    while ((ent = readdir(d)) != NULL) {
        if (strncmp(ent->d_name, prefix, (size_t)plen) != 0)
            continue;
        char *end;
        long pid = strtol(ent->d_name + plen, &end, 10);
        if (end == ent->d_name + plen || *end != '-' || pid <= 0 || pid == (long)getpid())
            continue;
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH)
            continue; /* alive (or not ours to judge): maybe a concurrent run */
        char full[4096 + 256];
        snprintf(full, sizeof full, "%s/%s", dir, ent->d_name);
        unlink(full);
    }
    closedir(d);
}

/* The temporary of `path`, created with mkstemps (race-free), fd returned. */
static char *make_temp(const char *path, int *fd_out, bgt_err *e)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    if (!*base) {
        bgt_fail(e, BG_ERR_IO, "cannot write '%s': not a file name", path);
        return NULL;
    }
    const char *dot = strrchr(base, '.');
    if (!dot || dot == base)
        dot = base + strlen(base);
    size_t extlen = strlen(dot);
    size_t cap = strlen(path) + sizeof TEMP_TAG + 32 + extlen;
    char *t = malloc(cap);
    if (!t) {
        bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
        return NULL;
    }
    remove_stale_temps(path);
    snprintf(t, cap, "%.*s.%s" TEMP_TAG "%ld-XXXXXX%s", (int)(base - path), path, base,
             (long)getpid(), dot);
    int fd = mkstemps(t, (int)extlen);
    if (fd < 0) {
        int err = errno;
        free(t);
        bgt_fail(e, BG_ERR_IO, "cannot create output %s: %s", path, strerror(err));
        return NULL;
    }
    track(t);
    (void)fchmod(fd, new_file_mode());
    *fd_out = fd;
    return t;
}

/* ---- stream API ------------------------------------------------------------- */

bg_status bgt_safe_open(bgt_safe_file *f, const char *path, bgt_err *e)
{
    memset(f, 0, sizeof *f);
    /* "" would become a hidden temporary in the current folder and fail only
     * at the rename, after all the work, with a message naming nothing. */
    if (!path || path[0] == '\0')
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "the output file name is empty");
    f->path = dup_str(path);
    if (!f->path)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    if (strcmp(path, "-") == 0) {
        f->fp = stdout;
        return BG_OK;
    }
    /* An existing non-regular target (/dev/null, a FIFO, a terminal) is written
     * in place: renaming a temporary over it would replace the device node. */
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        if (S_ISDIR(st.st_mode)) {
            bgt_safe_abort(f);
            return bgt_fail(e, BG_ERR_IO, "cannot write output %s: it is a folder", path);
        }
        f->fp = fopen(path, "wb");
        if (!f->fp) {
            int err = errno;
            bgt_safe_abort(f);
            return bgt_fail(e, BG_ERR_IO, "cannot open output %s: %s", path, strerror(err));
        }
        return BG_OK;
    }
    int fd = -1;
    f->tmp_path = make_temp(path, &fd, e);
    if (!f->tmp_path) {
        bg_status s = e ? e->status : BG_ERR_IO;
        bgt_safe_abort(f);
        return s;
    }
    f->fp = fdopen(fd, "wb");
    if (!f->fp) {
        int err = errno;
        close(fd);
        bgt_safe_abort(f);
        return bgt_fail(e, BG_ERR_IO, "cannot create output %s: %s", path, strerror(err));
    }
    return BG_OK;
}

static void release(bgt_safe_file *f)
{
    if (f->tmp_path) {
        unlink(f->tmp_path);
        untrack(f->tmp_path);
    }
    free(f->tmp_path), free(f->path);
    f->tmp_path = f->path = NULL;
}

bg_status bgt_safe_commit(bgt_safe_file *f, bgt_err *e)
{
    if (!f->fp) {
        bg_status s = bgt_fail(e, BG_ERR_IO, "output %s is not open", f->path ? f->path : "?");
        release(f);
        return s;
    }
    /* A full disk or a closed pipe shows up only at flush or close time. */
    int bad = fflush(f->fp) != 0 || ferror(f->fp);
    int err = errno;
    if (!bad && f->tmp_path && fsync(fileno(f->fp)) != 0 && errno != EINVAL && errno != EROFS)
        bad = 1, err = errno;
    if (f->fp != stdout && fclose(f->fp) != 0 && !bad)
        bad = 1, err = errno;
    f->fp = NULL;
    if (!f->tmp_path) { /* stdout, or a device/FIFO written in place */
        bg_status s = bad ? bgt_fail(e, BG_ERR_IO, "writing the output failed: %s", strerror(err))
                          : BG_OK;
        release(f);
        return s;
    }
    if (!bad && rename(f->tmp_path, f->path) != 0)
        bad = 1, err = errno;
    if (bad) {
        bg_status s = bgt_fail(e, BG_ERR_IO, "writing %s failed: %s", f->path, strerror(err));
        release(f);
        return s;
    }
    untrack(f->tmp_path);
    sync_parent_dir(f->path);
    free(f->tmp_path);
    f->tmp_path = NULL;
    release(f);
    return BG_OK;
}

void bgt_safe_abort(bgt_safe_file *f)
{
    if (f->fp && f->fp != stdout)
        fclose(f->fp);
    else if (f->fp)
        fflush(f->fp);
    f->fp = NULL;
    release(f);
}

/* ---- path API --------------------------------------------------------------- */

char *bgt_safe_temp_path(const char *path, bgt_err *e)
{
    if (!path || !*path) {
        bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "the output file name is empty");
        return NULL;
    }
    int fd = -1;
    char *t = make_temp(path, &fd, e);
    if (!t)
        return NULL;
    close(fd);
    /* The registry keeps `t` (the signal handler unlinks through it) until the
     * commit or the discard; the caller gets a copy of its own to free. */
    char *copy = dup_str(t);
    if (!copy) {
        unlink(t);
        untrack(t);
        free(t);
        bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    }
    return copy;
}

/* Unregisters a path-API temporary and frees the registry's string. */
static void forget_path(const char *tmp_path)
{
    char *reg = untrack(tmp_path);
    if (reg != tmp_path)
        free(reg);
}

void bgt_safe_discard_path(const char *tmp_path)
{
    if (!tmp_path)
        return;
    unlink(tmp_path);
    forget_path(tmp_path);
}

bg_status bgt_safe_commit_path(const char *tmp_path, const char *path, bgt_err *e)
{
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        bgt_safe_discard_path(tmp_path);
        return bgt_fail(e, BG_ERR_IO, "refusing to replace '%s': it is not a regular file", path);
    }
    /* The writer (OpenImageIO, OpenVDB) may not have synced, and may not have
     * reported a short write: fsync here and check the result, so a full disk
     * is an error and not a truncated file under the real name. */
    int fd = open(tmp_path, O_RDONLY);
    if (fd < 0 || (fsync(fd) != 0 && errno != EINVAL && errno != EROFS)) {
        int err = errno;
        if (fd >= 0)
            close(fd);
        bgt_safe_discard_path(tmp_path);
        return bgt_fail(e, BG_ERR_IO, "cannot write '%s': %s", path, strerror(err));
    }
    close(fd);
    (void)chmod(tmp_path, new_file_mode());
    if (rename(tmp_path, path) != 0) {
        int err = errno;
        bgt_safe_discard_path(tmp_path);
        return bgt_fail(e, BG_ERR_IO, "cannot write '%s': %s", path, strerror(err));
    }
    forget_path(tmp_path);
    sync_parent_dir(path);
    return BG_OK;
}
