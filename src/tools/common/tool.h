/* SPDX-License-Identifier: MIT */
/* What every tools-library call shares: a status, an error buffer and a
 * progress callback. The tools (src/tools) never print, never read argv and
 * never exit: they return a bg_status and, on failure, leave one line of text
 * in a bgt_err that the caller (the CLI, a test, a user's program) shows as it
 * likes. Exit codes are the CLI's business (bgt_exit_code in src/cli). */
#ifndef BUMPGRAD_TOOLS_TOOL_H
#define BUMPGRAD_TOOLS_TOOL_H

#include <stddef.h>
#include "bumpgrad/common.h"

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__) || defined(__clang__)
#define BGT_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define BGT_PRINTF(f, a)
#endif

/* One error: the status and a message (no "bumpgrad cmd: error:" prefix). */
typedef struct bgt_err {
    bg_status status;
    char msg[1024];
} bgt_err;

/* Set *e (if e is non-NULL) and return s, for `return bgt_fail(e, ...)`.
 * The message replaces any earlier one. */
bg_status bgt_fail(bgt_err *e, bg_status s, const char *fmt, ...) BGT_PRINTF(3, 4);
/* Prefix the message already in *e with "prefix: " (context on the way up). */
void bgt_err_prefix(bgt_err *e, const char *prefix);
void bgt_err_clear(bgt_err *e);
/* The one rule for the status of a failed file read or write (a bg_status of
 * the I/O shim), so that every tool exits alike. A read of an input the user
 * named: out of memory is a run failure, a malformed file BG_ERR_FORMAT, and
 * anything else (missing, unreadable) bad input, BG_ERR_INVALID_ARGUMENT. */
bg_status bgt_read_status(bg_status s);
/* A write of an output: a file name without an image format
 * (BG_ERR_INVALID_ARGUMENT) is bad input, out of memory stays, and the
 * writing itself failing is BG_ERR_IO. */
bg_status bgt_write_status(bg_status s);

/* ---- the one cap on input-driven allocations ----
 * Every allocation whose size an input decides (an image's declared size, a
 * volume's box, a render's size and samples, a bake's size) is checked against
 * this cap before it happens: BUMPGRAD_MAX_MB mebibytes (default 4096, i.e.
 * 4 GiB; 0 = no cap). The mesh import child has its own address-space cap
 * (BUMPGRAD_MESH_MAX_MB, docs/MESH.md). */
#define BGT_DEFAULT_MAX_MB 4096u
size_t bgt_memory_cap(void);
/* BG_OK if `bytes` (saturated: pass SIZE_MAX on overflow) fits the cap, else
 * BG_ERR_INVALID_ARGUMENT with a message naming `what`, the size and the cap. */
bg_status bgt_check_alloc(double bytes, const char *what, bgt_err *e);

/* BG_OK if the I/O module (images, volumes, meshes) loads; else BG_ERR_IO
 * with the loader's reason. Tools that read or write files through the shim
 * call it before their work (tools build only: common/io_ready.c). */
bg_status bgt_io_ready(bgt_err *e);

/* Progress of a long job: begin(label, total) once, update(done) from any
 * worker (the callback is responsible for its own rate limiting and locking),
 * end() once. Any member may be NULL, and so may the whole pointer. */
typedef struct bgt_progress {
    void (*begin)(void *ctx, const char *label, size_t total);
    void (*update)(void *ctx, size_t done);
    void (*end)(void *ctx);
    void *ctx;
} bgt_progress;

static inline void bgt_progress_begin(const bgt_progress *p, const char *label, size_t total)
{
    if (p && p->begin)
        p->begin(p->ctx, label, total);
}
static inline void bgt_progress_update(const bgt_progress *p, size_t done)
{
    if (p && p->update)
        p->update(p->ctx, done);
}
static inline void bgt_progress_end(const bgt_progress *p)
{
    if (p && p->end)
        p->end(p->ctx);
}

#ifdef __cplusplus
}
#endif

#endif
