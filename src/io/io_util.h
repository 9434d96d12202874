// SPDX-License-Identifier: MIT
// Helpers shared by the translation units of the I/O shim (not installed):
// error messages, overflow-checked sizes, and the temp-file + rename protocol
// that keeps a failed write from leaving a partial file or destroying an old one.
#ifndef BUMPGRAD_IO_UTIL_H
#define BUMPGRAD_IO_UTIL_H

#include <cstddef>
#include <exception>
#include <new>
#include <string>
#include <sys/types.h>

#include "bumpgrad/common.h"

#define BG_IO_STR2(x) #x
#define BG_IO_STR(x) BG_IO_STR2(x)
#define BG_IO_VERSION_STRING                                                                       \
    BG_IO_STR(BG_VERSION_MAJOR) "." BG_IO_STR(BG_VERSION_MINOR) "." BG_IO_STR(BG_VERSION_PATCH)

#if defined(__GNUC__) || defined(__clang__)
#define BG_IO_PRINTF(f, a) __attribute__((format(printf, f, a)))
/* Internal to the module: not part of what the program may look up. */
#define BG_IO_HIDDEN __attribute__((visibility("hidden")))
#else
#define BG_IO_PRINTF(f, a)
#define BG_IO_HIDDEN
#endif

/* printf into err (errlen may be 0, err may be NULL). */
BG_IO_HIDDEN void bg_io_set_error(char *err, size_t errlen, const char *fmt, ...)
    BG_IO_PRINTF(3, 4);

/* a*b without overflow: returns false on overflow. */
BG_IO_HIDDEN bool bg_io_mul_size(size_t a, size_t b, size_t *out);

/* BG_OK if `path` is an existing regular file we may read, else BG_ERR_IO with
 * a message naming it (missing, a directory, permission denied). `kind`, if not
 * NULL, names what was expected ("is a directory, not a mesh file"). The file's
 * size goes to *size if size is not NULL. */
BG_IO_HIDDEN bg_status bg_io_check_readable(const char *path, const char *kind, char *err,
                                            size_t errlen, off_t *size = nullptr);

/* Move all n bytes to or from fd, retrying after EINTR and short transfers.
 * Returns how many moved: n on success; fewer at end of file or on an error
 * (then errno is set, or 0 at end of file). */
BG_IO_HIDDEN size_t bg_io_write_all(int fd, const void *p, size_t n);
BG_IO_HIDDEN size_t bg_io_read_all(int fd, void *p, size_t n);

/* The one exception barrier of the extern "C" entry points: no C++ exception
 * may cross into C. Runs body() and turns std::bad_alloc into
 * BG_ERR_OUT_OF_MEMORY ("PREFIX: OOM"), any other exception into `other`
 * ("PREFIX: what()", or "PREFIX: LABEL (what())" when label is not empty, or
 * "PREFIX: LABEL" for a non-standard exception); cleanup() runs first on
 * either path (drop a temporary, free a half-made result). */
template <class Body, class Cleanup>
bg_status bg_io_guard(const std::string &prefix, const char *oom, const char *label,
                      bg_status other, char *err, size_t errlen, Body &&body, Cleanup &&cleanup)
{
    try {
        return body();
    } catch (const std::bad_alloc &) {
        cleanup();
        bg_io_set_error(err, errlen, "%s: %s", prefix.c_str(), oom);
        return BG_ERR_OUT_OF_MEMORY;
    } catch (const std::exception &e) {
        cleanup();
        if (*label)
            bg_io_set_error(err, errlen, "%s: %s (%s)", prefix.c_str(), label, e.what());
        else
            bg_io_set_error(err, errlen, "%s: %s", prefix.c_str(), e.what());
        return other;
    } catch (...) {
        cleanup();
        bg_io_set_error(err, errlen, "%s: %s", prefix.c_str(), *label ? label : "unknown error");
        return other;
    }
}

template <class Body>
bg_status bg_io_guard(const std::string &prefix, const char *oom, const char *label,
                      bg_status other, char *err, size_t errlen, Body &&body)
{
    return bg_io_guard(prefix, oom, label, other, err, errlen, body, [] {});
}

/* Create an empty, unique temporary file next to `path` that keeps its
 * extension (dir/.name.tmpXXXXXX.ext), so writers that pick the format from
 * the extension still work. BG_ERR_IO with a message if the folder is not
 * writable. */
BG_IO_HIDDEN bg_status bg_io_make_temp(const char *path, std::string *tmp, char *err, size_t errlen);

/* Remove a temporary of bg_io_make_temp after a failed write. */
BG_IO_HIDDEN void bg_io_discard_temp(const std::string &tmp);

/* Give the temporary file the permissions a new file would get, and rename it
 * onto `path`. On failure removes it and returns BG_ERR_IO. */
BG_IO_HIDDEN bg_status bg_io_commit_temp(const std::string &tmp, const char *path, char *err, size_t errlen);

/* The one allocation cap of the process (BUMPGRAD_MAX_MB, tool.h), through
 * the host: BG_OK, or an error with the message in err. */
BG_IO_HIDDEN bg_status bg_io_check_alloc(double bytes, const char *what, char *err, size_t errlen);
/* The cap in bytes (SIZE_MAX: none). */
BG_IO_HIDDEN size_t bg_io_memory_cap(void);

/* ---- child processes (the mesh import, the VDB probe) ----
 * Address-space cap for a child reading `path`: the mappings the process has
 * now plus max(2 GiB, 256 x the file size), or env_name in MiB (0 = none). */
BG_IO_HIDDEN size_t bg_io_child_memory_cap(const char *path, const char *env_name);
/* Seconds a child may run: BUMPGRAD_CHILD_TIMEOUT, default 60. */
BG_IO_HIDDEN unsigned bg_io_child_timeout(void);
/* In the child, right after fork: die with the parent (PR_SET_PDEATHSIG),
 * cap the address space (0 = no cap), and end by SIGALRM after timeout_s.
 * A child stopped by the cap exits with BG_IO_CHILD_OVER_CAP, under
 * AddressSanitizer too (whose allocator would otherwise exit with 1). */
#define BG_IO_CHILD_OVER_CAP 4
BG_IO_HIDDEN void bg_io_child_limits(pid_t parent, size_t mem_cap, unsigned timeout_s);
/* In the parent: wait for child `pid` to end, for at most `ms` milliseconds,
 * then SIGKILL it and reap it. The wait sleeps on a pidfd (poll), so it returns
 * as soon as the child ends; without pidfd_open (Linux < 5.3) it polls
 * waitpid every 10 ms. *status is the wait status. Returns 0 if the child
 * ended by itself, 1 if it was killed at the deadline, -1 if waitpid failed. */
BG_IO_HIDDEN int bg_io_wait_child(pid_t pid, long ms, int *status);

#endif
