/* SPDX-License-Identifier: MIT */
/* The services the program (or libbumpgrad-io.so) lends the I/O module when it
 * loads it (io_loader.c). The module compiles none of them itself: the
 * temporary-file registry, its signal handlers and exit guard, the memory cap
 * and the strict reading of BUMPGRAD_* variables exist once per process, in
 * src/tools/common (safe_file.c, tool.c, env.c), whichever side writes.
 * Not installed; loader and module must come from the same build (the version
 * below is checked when the module is attached). Errors go to the caller's
 * err/errlen buffer: that buffer is the error sink. */
#ifndef BUMPGRAD_IO_HOST_H
#define BUMPGRAD_IO_HOST_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define BG_IO_HOST_VERSION 1u

typedef struct bg_io_host {
    unsigned version; /* BG_IO_HOST_VERSION */
    /* A registered, empty temporary next to `path` keeping its extension
     * (safe_file.h, bgt_safe_temp_path); malloc'd, give it back with release.
     * NULL with a message in err on failure. */
    char *(*temp_path)(const char *path, char *err, size_t errlen);
    /* fsync, mode, rename onto `path` (bgt_safe_commit_path). A bg_status. */
    int (*commit_path)(const char *tmp, const char *path, char *err, size_t errlen);
    /* Remove a temporary after a failed write (bgt_safe_discard_path). */
    void (*discard_path)(const char *tmp);
    void (*release)(void *p);
    /* The one allocation cap (tool.h): BG_OK, or a bg_status with the message. */
    int (*check_alloc)(double bytes, const char *what, char *err, size_t errlen);
    size_t (*memory_cap)(void);
    /* A BUMPGRAD_* number read strictly (env.h, bgt_env_uint): BG_OK and *out,
     * or BG_ERR_INVALID_ARGUMENT with a message naming the variable. */
    int (*env_uint)(const char *name, unsigned long long *out, char *err, size_t errlen);
} bg_io_host;

/* Exported by the module: called once by the loader right after dlopen.
 * Returns 0, or -1 if the version differs (a module from another build). */
typedef int (*bg_io_attach_fn)(const bg_io_host *host);
#define BG_IO_ATTACH_SYMBOL "bg_io_module_attach"

#ifdef __cplusplus
}
#endif

#endif
