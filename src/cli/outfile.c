/* SPDX-License-Identifier: MIT */
/* Safe output files: everything is written to a temporary file in the folder of
 * the destination and renamed over it only after a successful fsync. rename()
 * within one file system is atomic, so a reader sees either the old file or the
 * complete new one, and a failed or interrupted run never leaves a truncated
 * result behind nor destroys the previous one. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Temporary files still open, unlinked by the signal handler on Ctrl-C/SIGTERM/
 * SIGPIPE so an interrupted run does not litter the output folder. Few outputs
 * are open at once; extra ones are simply not cleaned up on a signal. */
#define MAX_LIVE_TEMPS 8
static char *volatile live_temps[MAX_LIVE_TEMPS];
static int handlers_installed;

static void on_signal(int sig)
{
    for (int i = 0; i < MAX_LIVE_TEMPS; i++)
        if (live_temps[i])
            unlink(live_temps[i]); /* async-signal-safe */
    signal(sig, SIG_DFL);
    raise(sig);
}

static void install_handlers(void)
{
    if (handlers_installed)
        return;
    handlers_installed = 1;
    const int sigs[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE};
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++) {
        struct sigaction sa, old;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_signal;
        sigemptyset(&sa.sa_mask);
        /* Keep an inherited "ignore" (nohup, a shell's SIGPIPE policy). */
        if (sigaction(sigs[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN)
            continue;
        sigaction(sigs[i], &sa, NULL);
    }
}

static void track(char *p)
{
    install_handlers();
    for (int i = 0; i < MAX_LIVE_TEMPS; i++)
        if (!live_temps[i]) {
            live_temps[i] = p;
            return;
        }
}

static void untrack(const char *p)
{
    for (int i = 0; i < MAX_LIVE_TEMPS; i++)
        if (live_temps[i] == p)
            live_temps[i] = NULL;
}

static char *dup_str(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

/* mkstemp creates 0600; give the result the mode a plain fopen would have. */
static void set_default_mode(int fd)
{
    mode_t mask = umask(0);
    umask(mask);
    (void)fchmod(fd, 0666 & ~mask);
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

int cli_outfile_open(const char *cmd, const char *path, cli_outfile *out)
{
    memset(out, 0, sizeof *out);
    /* "" would become a hidden ".tmp.XXXXXX" in the current folder and fail
     * only at the rename, after all the work, with a message naming nothing. */
    if (path[0] == '\0')
        return cli_usage_error(cmd, "the output file name is empty");
    if (strcmp(path, "-") == 0) {
        out->fp = stdout;
        out->path = dup_str(path);
        return out->path ? 0 : cli_fail(cmd, "out of memory");
    }
    /* An existing non-regular target (/dev/null, a FIFO, a terminal) is written
     * in place: renaming a temporary over it would replace the device node. */
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        if (S_ISDIR(st.st_mode))
            return cli_fail(cmd, "cannot write output %s: it is a folder", path);
        out->path = dup_str(path);
        out->fp = out->path ? fopen(path, "wb") : NULL;
        if (!out->fp) {
            int e = errno;
            free(out->path);
            out->path = NULL;
            return cli_fail(cmd, "cannot open output %s: %s", path, strerror(e));
        }
        return 0;
    }
    size_t n = strlen(path);
    out->path = dup_str(path);
    out->tmp_path = malloc(n + sizeof ".tmp.XXXXXX");
    if (!out->path || !out->tmp_path) {
        free(out->path), free(out->tmp_path);
        out->path = out->tmp_path = NULL;
        return cli_fail(cmd, "out of memory");
    }
    memcpy(out->tmp_path, path, n);
    memcpy(out->tmp_path + n, ".tmp.XXXXXX", sizeof ".tmp.XXXXXX");
    int fd = mkstemp(out->tmp_path);
    if (fd < 0) {
        int e = errno;
        free(out->path), free(out->tmp_path);
        out->path = out->tmp_path = NULL;
        return cli_fail(cmd, "cannot create output %s: %s", path, strerror(e));
    }
    track(out->tmp_path);
    set_default_mode(fd);
    out->fp = fdopen(fd, "wb");
    if (!out->fp) {
        int e = errno;
        close(fd);
        cli_outfile_abort(out);
        return cli_fail(cmd, "cannot create output %s: %s", path, strerror(e));
    }
    return 0;
}

int cli_outfile_commit(const char *cmd, cli_outfile *out)
{
    if (!out->fp)
        return cli_fail(cmd, "output %s is not open", out->path ? out->path : "?");
    if (!out->tmp_path) {
        /* stdout or a device/FIFO: a full disk or a closed pipe shows up only at
         * flush time. */
        int bad = fflush(out->fp) != 0 || ferror(out->fp);
        int e = errno;
        if (out->fp != stdout && fclose(out->fp) != 0 && !bad)
            bad = 1, e = errno;
        out->fp = NULL;
        free(out->path);
        out->path = NULL;
        return bad ? cli_fail(cmd, "writing the output failed: %s", strerror(e)) : 0;
    }
    int bad = fflush(out->fp) != 0 || ferror(out->fp);
    int e = errno;
    if (!bad && fsync(fileno(out->fp)) != 0 && errno != EINVAL && errno != EROFS)
        bad = 1, e = errno;
    if (fclose(out->fp) != 0 && !bad)
        bad = 1, e = errno;
    out->fp = NULL;
    if (!bad && rename(out->tmp_path, out->path) != 0)
        bad = 1, e = errno;
    if (bad) {
        int rc = cli_fail(cmd, "writing %s failed: %s", out->path, strerror(e));
        unlink(out->tmp_path);
        untrack(out->tmp_path);
        free(out->tmp_path), free(out->path);
        out->tmp_path = out->path = NULL;
        return rc;
    }
    untrack(out->tmp_path);
    sync_parent_dir(out->path);
    free(out->tmp_path), free(out->path);
    out->tmp_path = out->path = NULL;
    return 0;
}

void cli_outfile_abort(cli_outfile *out)
{
    if (out->fp && out->fp != stdout)
        fclose(out->fp);
    else if (out->fp)
        fflush(out->fp);
    out->fp = NULL;
    if (out->tmp_path) {
        unlink(out->tmp_path);
        untrack(out->tmp_path);
    }
    free(out->tmp_path), free(out->path);
    out->tmp_path = out->path = NULL;
}

char *cli_temp_path_like(const char *path)
{
    static unsigned counter;
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    /* ".png" stays last so OpenImageIO (and any writer that picks its format
     * by extension) writes the same format; a leading dot hides the file. */
    if (!dot || dot == base)
        dot = base + strlen(base);
    size_t dirlen = (size_t)(base - path), stemlen = (size_t)(dot - base);
    size_t cap = strlen(path) + 64;
    char *t = malloc(cap);
    if (!t)
        return NULL;
    for (int attempt = 0; attempt < 100; attempt++) {
        snprintf(t, cap, "%.*s.%.*s.tmp%ld-%u%s", (int)dirlen, path, (int)stemlen, base,
                 (long)getpid(), counter++, dot);
        struct stat st;
        if (lstat(t, &st) != 0 && errno == ENOENT)
            return t;
    }
    free(t);
    return NULL;
}

int cli_rename_into_place(const char *cmd, const char *tmp_path, const char *path)
{
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        unlink(tmp_path);
        return cli_fail(cmd, "refusing to replace %s: it is not a regular file", path);
    }
    /* The writer (OpenImageIO, OpenVDB) may not have synced: do it here, or a
     * crash right after the rename could leave an empty file under the real name. */
    int fd = open(tmp_path, O_RDONLY);
    if (fd >= 0) {
        (void)fsync(fd);
        close(fd);
    }
    if (rename(tmp_path, path) != 0) {
        int e = errno;
        unlink(tmp_path);
        return cli_fail(cmd, "cannot write %s: %s", path, strerror(e));
    }
    sync_parent_dir(path);
    return 0;
}
