/* SPDX-License-Identifier: MIT */
/* The one safe-output protocol of bumpgrad, used by the C tools and by the C++
 * I/O shim alike: everything is written to a temporary file in the folder of
 * the destination and renamed over it only after every write, flush, fsync and
 * close succeeded. rename() within one file system is atomic, so a reader sees
 * either the old file or the complete new one, and a failed or interrupted run
 * never leaves a truncated result behind nor destroys the previous one.
 *
 * Rules shared by both entry points:
 *  - a replaced regular file keeps its mode; a new file gets the mode a plain
 *    open(O_CREAT, 0666) would give it (0666 & ~umask; mkstemp's 0600 is not
 *    kept);
 *  - what is there is judged with lstat: a link is replaced, never written
 *    through; a FIFO or device is written in place by the stream API only
 *    when named directly (O_NOFOLLOW) or through a link outside a sticky
 *    folder, and the path API refuses it; a folder is refused by both
 *    (bgt_safe_open has the whole rule);
 *  - temporaries (DIR/.BASE.tmp-bumpgrad-PID-XXXXXX.EXT, or the short
 *    DIR/.tmp-bumpgrad-PID-XXXXXX.EXT when the name is long) are registered,
 *    so SIGINT/SIGTERM/SIGHUP/SIGPIPE/SIGABRT and an exit() from inside a
 *    library remove them; SIGKILL cannot be caught, and a killed run leaves
 *    its temporary behind until the next run that writes the same target
 *    in the same folder removes it and any nested or short-form one (their
 *    PID no longer exists).
 */
#ifndef BUMPGRAD_TOOLS_SAFE_FILE_H
#define BUMPGRAD_TOOLS_SAFE_FILE_H

#include <stdio.h>
#include "tool.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- stream API (CSV, PLY, JSON, markdown): fopen-like ---- */
typedef struct bgt_safe_file {
    FILE *fp;
    char *path;     /* final path */
    char *tmp_path; /* temporary path; NULL for stdout or an in-place device/FIFO */
} bgt_safe_file;

/* Open `path` for writing ("-" = stdout). BG_ERR_INVALID_ARGUMENT for an empty
 * name, BG_ERR_IO (folder, no permission, ...) or BG_ERR_OUT_OF_MEMORY. */
bg_status bgt_safe_open(bgt_safe_file *f, const char *path, bgt_err *e);
/* Flush, fsync, close and rename into place. BG_OK or BG_ERR_IO; on failure
 * the temporary is removed and the old file is untouched. */
bg_status bgt_safe_commit(bgt_safe_file *f, bgt_err *e);
/* Close and remove the temporary (no effect on the target). */
void bgt_safe_abort(bgt_safe_file *f);

/* ---- sets of outputs ----
 * Several files that belong together (a bake's UDIM tiles and its mesh) are
 * each replaced atomically; two runs writing the same set at once could still
 * interleave their renames and leave a mixed set. Holding this advisory lock
 * (flock on each folder that holds one of the files, taken in a fixed order)
 * around the renames makes the runs commit one after the other: the set is
 * always one run's. Names "-" and NULL are skipped. It does not stop another
 * program that does not take it. */
typedef struct bgt_safe_lock {
    int fd[2];
} bgt_safe_lock;
bg_status bgt_safe_lock_outputs(bgt_safe_lock *l, const char *a, const char *b, bgt_err *e);
void bgt_safe_unlock(bgt_safe_lock *l);

/* ---- the exit guard ----
 * An exit() while a temporary is live can only come from a third-party
 * library inside a write (libjpeg calls exit(1) on a full disk). The guard
 * removes every live temporary and, if a note is set, calls it with the
 * target being written; a note returning a code >= 0 ends the process with
 * that code (_exit), so such an exit never passes as success. The CLI sets
 * one that prints the message; without one the guard is silent. */
typedef int (*bgt_safe_exit_note)(const char *target);
void bgt_safe_on_exit_during_write(bgt_safe_exit_note note);

/* ---- path API, for writers that need a file name (OpenImageIO, OpenVDB) ---- */
/* Create an empty, unique temporary next to `path` that keeps its extension
 * (DIR/.BASE.tmp-bumpgrad-PID-XXXXXX.EXT), so writers that pick the format by extension
 * still work, and register it. Returns a malloc'd path, or NULL with *e set. */
char *bgt_safe_temp_path(const char *path, bgt_err *e);
/* fsync the finished temporary, give it the new-file mode and rename it onto
 * `path`; refuses a non-regular target. The temporary is gone afterwards
 * either way (renamed or removed). BG_OK or BG_ERR_IO. */
bg_status bgt_safe_commit_path(const char *tmp_path, const char *path, bgt_err *e);
/* Remove a temporary made by bgt_safe_temp_path (the write failed). */
void bgt_safe_discard_path(const char *tmp_path);

#ifdef __cplusplus
}
#endif

#endif
