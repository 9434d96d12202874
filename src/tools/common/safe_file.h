/* SPDX-License-Identifier: MIT */
/* The one safe-output protocol of bumpgrad, used by the C tools and by the C++
 * I/O shim alike: everything is written to a temporary file in the folder of
 * the destination and renamed over it only after every write, flush, fsync and
 * close succeeded. rename() within one file system is atomic, so a reader sees
 * either the old file or the complete new one, and a failed or interrupted run
 * never leaves a truncated result behind nor destroys the previous one.
 *
 * Rules shared by both entry points:
 *  - the new file gets the mode a plain open(O_CREAT, 0666) would give it
 *    (0666 & ~umask; mkstemp's 0600 is not kept);
 *  - an existing target that is not a regular file (/dev/null, a FIFO, a
 *    terminal) is never renamed over: the stream API writes it in place, the
 *    path API refuses it; a folder is refused by both;
 *  - temporaries (DIR/.BASE.tmp-bumpgrad-PID-XXXXXX.EXT) are registered, so
 *    SIGINT/SIGTERM/SIGHUP/SIGPIPE remove them; SIGKILL cannot be caught, and a
 *    killed run leaves its temporary behind until the next run that writes the
 *    same target in the same folder removes it (its PID no longer exists).
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
