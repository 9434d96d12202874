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
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

static char *dup_str(const char *s);

/* ---- registry of live temporaries ----------------------------------------
 * A fixed table of atomic pointers: the signal handler may only read it and
 * call unlink() (async-signal-safe). Slots are claimed with compare-exchange,
 * so threads may register concurrently. More than MAX_LIVE_TEMPS outputs open
 * at once is not an error; the extra ones are just not removed on a signal. */
#define MAX_LIVE_TEMPS 16
static _Atomic(char *) live_temps[MAX_LIVE_TEMPS];
/* The target each live temporary stands for (for the exit guard's report). */
static _Atomic(char *) live_targets[MAX_LIVE_TEMPS];
static atomic_int handlers_installed;
/* The exit guard's report (bgt_safe_on_exit_during_write); NULL: silent. */
static _Atomic(bgt_safe_exit_note) exit_note;

/* The handlers found when ours were installed (a host program's own): ours
 * clean the registry, then chain to them. This file is linked once per process
 * (bumpgrad_common); the I/O module borrows it (src/io/io_host.h). SIGABRT:
 * a third-party writer that aborts must not leave its temporary either. */
static const int caught[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE, SIGABRT};
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

/* exit() called while a temporary is live can only come from a library deep
 * inside a write (libjpeg's error_exit calls exit(1) on a full disk): our own
 * code returns errors instead. Remove every live temporary, let the host say
 * what happened, and never let such an exit pass as success. */
static void exit_guard(void)
{
    const char *target = NULL;
    for (int i = 0; i < MAX_LIVE_TEMPS; i++) {
        char *p = atomic_exchange(&live_temps[i], NULL);
        if (p) {
            unlink(p);
            /* The user's name, not a temporary's (a nested temporary's
             * target is the outer temporary). */
            const char *t = atomic_load(&live_targets[i]);
            if (t && (!target || strstr(target, ".tmp-bumpgrad-")) && !strstr(t, ".tmp-bumpgrad-"))
                target = t;
            if (!target)
                target = t ? t : p;
        }
    }
    bgt_safe_exit_note note = atomic_load(&exit_note);
    if (target && note) {
        int code = note(target);
        if (code >= 0)
            _exit(code);
    }
}

void bgt_safe_on_exit_during_write(bgt_safe_exit_note note) { atomic_store(&exit_note, note); }

static void install_handlers(void)
{
    if (atomic_exchange(&handlers_installed, 1))
        return;
    atexit(exit_guard);
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

static void track(char *p, const char *target)
{
    install_handlers();
    for (int i = 0; i < MAX_LIVE_TEMPS; i++) {
        char *expected = NULL;
        if (atomic_compare_exchange_strong(&live_temps[i], &expected, p)) {
            free(atomic_exchange(&live_targets[i], dup_str(target)));
            return;
        }
    }
}

/* By name, so a caller may pass a copy of the registered string. Returns the
 * registered pointer (NULL if none): the path API frees its own copy. */
static char *untrack(const char *p)
{
    for (int i = 0; i < MAX_LIVE_TEMPS; i++) {
        char *cur = atomic_load(&live_temps[i]);
        if (cur && (cur == p || strcmp(cur, p) == 0) &&
            atomic_compare_exchange_strong(&live_temps[i], &cur, NULL)) {
            free(atomic_exchange(&live_targets[i], NULL));
            return cur;
        }
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

/* The mode the output gets: a replaced regular file keeps its own (as cp and
 * editors do: a 0600 file stays private); only a new file (or a name that was
 * a link, which is replaced, not written through) gets 0666 & ~umask. */
static mode_t output_mode(const char *path)
{
    struct stat st;
    if (lstat(path, &st) == 0 && S_ISREG(st.st_mode))
        return st.st_mode & 07777;
    return new_file_mode();
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
 * by extension still see it). Where that name would pass NAME_MAX, the short
 * form DIR/.tmp-bumpgrad-PID-XXXXXX.EXT is used. A writer handed a temporary
 * as its target makes a nested one (..BASE.tmp-bumpgrad-P-X.EXT.tmp-bumpgrad-
 * P-Y.EXT). A run killed by SIGKILL (or a power cut) cannot clean up; the next
 * run that writes the same target in the same folder removes that target's
 * temporaries, nested ones included, and every short-form one (their target
 * cannot be told), whose creator (the PID after the last tag) no longer
 * exists. Other targets' temporaries are left to the runs that write them. */
#define TEMP_TAG ".tmp-bumpgrad-"
#define NAME_MAX_BYTES 255

/* The PID that made `name` if it is a temporary of target `base` (any depth
 * of nesting, or the short form, whose target cannot be told), else -1. */
static long temp_owner(const char *name, const char *base)
{
    if (name[0] != '.')
        return -1;
    const char *q = name;
    while (*q == '.')
        q++;
    while (*base == '.')
        base++;
    size_t bl = strlen(base), tl = sizeof TEMP_TAG - 1;
    int short_form = strncmp(q - 1, TEMP_TAG, tl) == 0;
    int full_form = strncmp(q, base, bl) == 0 && strncmp(q + bl, TEMP_TAG, tl) == 0;
    if (!short_form && !full_form)
        return -1;
    const char *last = NULL;
    for (const char *t = strstr(name, TEMP_TAG); t; t = strstr(t + 1, TEMP_TAG))
        last = t;
    const char *digits = last + tl;
    char *end;
    long pid = strtol(digits, &end, 10);
    if (end == digits || *end != '-' || pid <= 0)
        return -1;
    /* Six mkstemps letters follow the PID, then the extension or the end. */
    if (strlen(end + 1) < 6)
        return -1;
    return pid;
}

static void remove_stale_temps(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    size_t dirlen = (size_t)(base - path);
    char dir[4096];
    if (dirlen + 2 > sizeof dir)
        return;
    if (dirlen) {
        memcpy(dir, path, dirlen);
        dir[dirlen] = '\0';
    } else {
        strcpy(dir, ".");
    }
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *ent;
    while ((ent = readdir(d)) != NULL) {
        long pid = temp_owner(ent->d_name, base);
        if (pid <= 0 || pid == (long)getpid())
            continue;
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH)
            continue; /* alive (or not ours to judge): maybe a concurrent run */
        char full[4096 + 256];
        snprintf(full, sizeof full, "%s/%s", dir, ent->d_name);
        struct stat st;
        if (lstat(full, &st) == 0 && S_ISREG(st.st_mode))
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
    if (extlen > 32) /* not an extension any writer chooses a format by */
        dot = base + strlen(base), extlen = 0;
    size_t cap = strlen(path) + sizeof TEMP_TAG + 32 + extlen;
    char *t = malloc(cap);
    if (!t) {
        bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
        return NULL;
    }
    remove_stale_temps(path);
    char pid[24];
    int pidlen = snprintf(pid, sizeof pid, "%ld", (long)getpid());
    /* "." BASE TAG PID "-XXXXXX" EXT must fit one name; else the short form. */
    int long_name = 1 + strlen(base) + (sizeof TEMP_TAG - 1) + (size_t)pidlen + 7 + extlen >
                    NAME_MAX_BYTES;
    if (long_name)
        snprintf(t, cap, "%.*s" TEMP_TAG "%s-XXXXXX%s", (int)(base - path), path, pid, dot);
    else
        snprintf(t, cap, "%.*s.%s" TEMP_TAG "%s-XXXXXX%s", (int)(base - path), path, base, pid,
                 dot);
    int fd = mkstemps(t, (int)extlen);
    if (fd < 0) {
        int err = errno;
        free(t);
        bgt_fail(e, BG_ERR_IO, "cannot create output %s: %s", path, strerror(err));
        return NULL;
    }
    track(t, path);
    (void)fchmod(fd, output_mode(path));
    *fd_out = fd;
    return t;
}

/* Why an existing FIFO or device (or a link to one) must not be written in
 * place, or NULL if it may: see bgt_safe_open. */
static const char *in_place_refusal(const char *path, const struct stat *lst, int is_link)
{
    const char *slash = strrchr(path, '/');
    char dir[4096];
    size_t n = slash ? (slash == path ? 1 : (size_t)(slash - path)) : 1;
    if (n >= sizeof dir)
        return "its folder's name is too long to check";
    memcpy(dir, slash ? path : ".", n);
    dir[n] = '\0';
    struct stat ds;
    if (stat(dir, &ds) != 0)
        return "its folder cannot be checked";
    if (!(ds.st_mode & S_ISVTX))
        return NULL; /* only the folder's users can plant names here */
    if (is_link)
        return "it is a link to a FIFO or device in a shared (sticky) folder, which anyone "
               "could have planted; name the FIFO or device itself";
    if (lst->st_uid != geteuid() && lst->st_uid != ds.st_uid)
        return "it is a FIFO or device owned by another user in a shared (sticky) folder";
    return NULL;
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
    /* The rule for what is already there (docs/RELIABILITY.md), decided on
     * lstat, so a link is seen as a link:
     *  - nothing, a regular file, or a link to one: a temporary renamed over
     *    the name (a link is replaced, never written through);
     *  - a FIFO or device named directly: written in place, opened with
     *    O_NOFOLLOW (a link swapped in meanwhile is refused), unless it sits
     *    in a sticky folder and belongs to neither us nor the folder's owner;
     *  - a link to a FIFO or device: followed only outside sticky folders
     *    (/dev/stdout, /proc/self/fd/N); in a sticky folder (/tmp) anyone may
     *    have planted it, so it is refused;
     *  - a folder: refused.
     * After the open, the opened file must be the one judged (same device and
     * inode), or the write is refused. */
    struct stat lst, st;
    if (lstat(path, &lst) == 0 && !S_ISREG(lst.st_mode)) {
        int is_link = S_ISLNK(lst.st_mode);
        if (stat(path, &st) != 0) /* a dangling link: replaced like a file */
            goto replace;
        if (S_ISDIR(st.st_mode)) {
            bgt_safe_abort(f);
            return bgt_fail(e, BG_ERR_IO, "cannot write output %s: it is a folder", path);
        }
        if (S_ISREG(st.st_mode)) /* a link to a regular file: replaced */
            goto replace;
        const char *why = in_place_refusal(path, &lst, is_link);
        if (why) {
            bgt_safe_abort(f);
            return bgt_fail(e, BG_ERR_IO, "refusing to write output %s: %s", path, why);
        }
        int fd = open(path, O_WRONLY | O_NOCTTY | O_CLOEXEC | (is_link ? 0 : O_NOFOLLOW));
        struct stat got;
        if (fd >= 0 && (fstat(fd, &got) != 0 || got.st_dev != st.st_dev || got.st_ino != st.st_ino)) {
            close(fd);
            bgt_safe_abort(f);
            return bgt_fail(e, BG_ERR_IO, "refusing to write output %s: it changed while opening it",
                            path);
        }
        f->fp = fd >= 0 ? fdopen(fd, "wb") : NULL;
        if (!f->fp) {
            int err = errno;
            if (fd >= 0)
                close(fd);
            bgt_safe_abort(f);
            return bgt_fail(e, BG_ERR_IO, "cannot open output %s: %s", path,
                            err == ELOOP ? "it was replaced by a link" : strerror(err));
        }
        return BG_OK;
    }
replace:;
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

/* ---- sets of outputs ------------------------------------------------------- */

/* The folder of `path`, opened for flock; -1 with *e set on failure, -2 for
 * "-" or NULL (nothing to lock). */
static int open_folder(const char *path, struct stat *st, bgt_err *e)
{
    if (!path || !*path || strcmp(path, "-") == 0)
        return -2;
    const char *slash = strrchr(path, '/');
    char dir[4096];
    size_t n = slash ? (slash == path ? 1 : (size_t)(slash - path)) : 1;
    if (n >= sizeof dir) {
        bgt_fail(e, BG_ERR_IO, "cannot lock the folder of %s: name too long", path);
        return -1;
    }
    memcpy(dir, slash ? path : ".", n);
    dir[n] = '\0';
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0 || fstat(fd, st) != 0) {
        int err = errno;
        if (fd >= 0)
            close(fd);
        bgt_fail(e, BG_ERR_IO, "cannot lock the folder of %s: %s", path, strerror(err));
        return -1;
    }
    return fd;
}

bg_status bgt_safe_lock_outputs(bgt_safe_lock *l, const char *a, const char *b, bgt_err *e)
{
    struct stat sa, sb;
    l->fd[0] = l->fd[1] = -1;
    int fa = open_folder(a, &sa, e), fb = open_folder(b, &sb, e);
    if (fa == -1 || fb == -1) {
        if (fa >= 0)
            close(fa);
        if (fb >= 0)
            close(fb);
        return BG_ERR_IO;
    }
    if (fa >= 0 && fb >= 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino) {
        close(fb);
        fb = -2;
    }
    /* One order for every run (device, then inode): no two runs wait on each other. */
    if (fa >= 0 && fb >= 0 &&
        (sb.st_dev < sa.st_dev || (sb.st_dev == sa.st_dev && sb.st_ino < sa.st_ino))) {
        int t = fa;
        fa = fb, fb = t;
    }
    l->fd[0] = fa >= 0 ? fa : -1;
    l->fd[1] = fb >= 0 ? fb : -1;
    for (int i = 0; i < 2; i++) {
        if (l->fd[i] < 0)
            continue;
        int r;
        while ((r = flock(l->fd[i], LOCK_EX)) != 0 && errno == EINTR)
            ;
        /* A file system without flock (some network mounts): per-file
         * atomicity only, as without the lock. */
        if (r != 0 && errno != ENOLCK && errno != EOPNOTSUPP) {
            int err = errno;
            bgt_safe_unlock(l);
            return bgt_fail(e, BG_ERR_IO, "cannot lock the output folder: %s", strerror(err));
        }
    }
    return BG_OK;
}

void bgt_safe_unlock(bgt_safe_lock *l)
{
    for (int i = 0; i < 2; i++) {
        if (l->fd[i] >= 0)
            close(l->fd[i]); /* closing drops the flock */
        l->fd[i] = -1;
    }
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
    (void)chmod(tmp_path, output_mode(path));
    if (rename(tmp_path, path) != 0) {
        int err = errno;
        bgt_safe_discard_path(tmp_path);
        return bgt_fail(e, BG_ERR_IO, "cannot write '%s': %s", path, strerror(err));
    }
    forget_path(tmp_path);
    sync_parent_dir(path);
    return BG_OK;
}
