// SPDX-License-Identifier: MIT
#include "io_util.h"
#include "io_host.h"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

void bg_io_set_error(char *err, size_t errlen, const char *fmt, ...)
{
    if (!err || errlen == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    std::vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
    // OpenImageIO's messages span lines; the CLI prints one line per error.
    std::string s;
    for (const char *p = err; *p; ++p) {
        if (*p == '\r')
            continue;
        if (*p == '\n') {
            if (p[1] != '\0')
                s += "; ";
        } else {
            s += *p;
        }
    }
    std::snprintf(err, errlen, "%s", s.c_str());
}

bool bg_io_mul_size(size_t a, size_t b, size_t *out)
{
    if (a != 0 && b > static_cast<size_t>(-1) / a)
        return false;
    *out = a * b;
    return true;
}

bg_status bg_io_check_readable(const char *path, const char *kind, char *err, size_t errlen,
                               off_t *size)
{
    struct stat st;
    if (::stat(path, &st) != 0) {
        bg_io_set_error(err, errlen, "'%s': %s", path, std::strerror(errno));
        return BG_ERR_IO;
    }
    if (S_ISDIR(st.st_mode)) {
        bg_io_set_error(err, errlen, "'%s': is a directory%s%s", path, kind ? ", not a " : "",
                        kind ? kind : "");
        return BG_ERR_IO;
    }
    // A FIFO or device would block the open (and the readers need to seek).
    if (!S_ISREG(st.st_mode)) {
        bg_io_set_error(err, errlen, "'%s': not a regular file (a FIFO or device cannot be read)",
                        path);
        return BG_ERR_IO;
    }
    int fd = ::open(path, O_RDONLY);
    if (fd < 0) {
        bg_io_set_error(err, errlen, "'%s': %s", path, std::strerror(errno));
        return BG_ERR_IO;
    }
    ::close(fd);
    if (size)
        *size = st.st_size;
    return BG_OK;
}

// One loop for both directions: EINTR is retried, a short transfer continued.
static size_t transfer(int fd, char *p, size_t n, bool out)
{
    size_t done = 0;
    while (done < n) {
        const ssize_t k = out ? ::write(fd, p + done, n - done) : ::read(fd, p + done, n - done);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0) {
            if (k == 0)
                errno = 0;
            break;
        }
        done += static_cast<size_t>(k);
    }
    return done;
}

size_t bg_io_write_all(int fd, const void *p, size_t n)
{
    return transfer(fd, const_cast<char *>(static_cast<const char *>(p)), n, true);
}

size_t bg_io_read_all(int fd, void *p, size_t n) { return transfer(fd, static_cast<char *>(p), n, false); }

// The process-wide services come from the program (or libbumpgrad-io.so) that
// loaded this module: io_loader.c attaches them before any other call
// (io_host.h). The module compiles none of them, so a process has one
// registry of temporaries, one set of signal handlers and one memory cap.
static const bg_io_host *host;

extern "C" int bg_io_module_attach(const bg_io_host *h)
{
    if (!h || h->version != BG_IO_HOST_VERSION)
        return -1;
    host = h;
    return 0;
}

static bool no_host(char *err, size_t errlen)
{
    if (host)
        return false;
    bg_io_set_error(err, errlen, "the I/O module was loaded without its host services "
                                 "(load it through libbumpgrad-io, not dlopen)");
    return true;
}

bg_status bg_io_make_temp(const char *path, std::string *tmp, char *err, size_t errlen)
{
    if (no_host(err, errlen))
        return BG_ERR_IO;
    char *t = host->temp_path(path, err, errlen);
    if (!t)
        return err && *err && std::strstr(err, "out of memory") ? BG_ERR_OUT_OF_MEMORY : BG_ERR_IO;
    tmp->assign(t);
    host->release(t);
    return BG_OK;
}

void bg_io_discard_temp(const std::string &tmp)
{
    if (host)
        host->discard_path(tmp.c_str());
}

bg_status bg_io_commit_temp(const std::string &tmp, const char *path, char *err, size_t errlen)
{
    if (no_host(err, errlen))
        return BG_ERR_IO;
    return static_cast<bg_status>(host->commit_path(tmp.c_str(), path, err, errlen));
}

bg_status bg_io_check_alloc(double bytes, const char *what, char *err, size_t errlen)
{
    if (no_host(err, errlen))
        return BG_ERR_IO;
    return static_cast<bg_status>(host->check_alloc(bytes, what, err, errlen));
}

size_t bg_io_memory_cap(void) { return host ? host->memory_cap() : 0; }

// ---- child processes (mesh import, VDB probe) ----------------------------

size_t bg_io_child_memory_cap(const char *path, const char *env_name)
{
    struct stat st;
    uint64_t file = stat(path, &st) == 0 && st.st_size > 0 ? static_cast<uint64_t>(st.st_size) : 0;
    uint64_t extra = std::max<uint64_t>(uint64_t(2) << 30, file * 256);
    // Read strictly (env.c); a bad value was refused by the CLI before any
    // work, and for a library caller it leaves the computed cap, never none.
    unsigned long long mb = ~0ull;
    if (host && host->env_uint(env_name, &mb, nullptr, 0) == BG_OK && mb != ~0ull) {
        if (mb == 0)
            return 0;
        extra = static_cast<uint64_t>(mb) << 20;
    }
    // The mappings the process already has (libraries, the caller's data).
    FILE *f = std::fopen("/proc/self/statm", "r");
    unsigned long long pages = 0;
    if (!f)
        return 0;
    int got = std::fscanf(f, "%llu", &pages);
    std::fclose(f);
    if (got != 1)
        return 0;
    uint64_t now = pages * static_cast<uint64_t>(sysconf(_SC_PAGESIZE));
    return static_cast<size_t>(std::min<uint64_t>(now + extra, SIZE_MAX));
}

unsigned bg_io_child_timeout(void)
{
    unsigned long long v = 60;
    if (!host || host->env_uint("BUMPGRAD_CHILD_TIMEOUT", &v, nullptr, 0) != BG_OK)
        v = 60;
    return static_cast<unsigned>(v);
}

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/common_interface_defs.h>
// Under AddressSanitizer, a child that runs into its address-space cap does
// not get a NULL or a std::bad_alloc: ASan's own allocator reports "out of
// memory" (or fails to map its internal memory) and ends the child with
// status 1, which the parent would read as a corrupt file. ASan calls this
// just before it ends the process: if the child's address space is within
// 64 MiB of its cap, it was stopped by the cap, and says so with the same
// status as a std::bad_alloc in a build without the sanitizer.
static size_t child_cap;
static void child_death_check(void)
{
    // No stdio and no allocation here: the allocator is what just failed
    // (an fopen here deadlocked the child until its time-out).
    char buf[64];
    const int fd = ::open("/proc/self/statm", O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return;
    const ssize_t n = ::read(fd, buf, sizeof buf - 1);
    ::close(fd);
    uint64_t pages = 0;
    for (ssize_t i = 0; i < n && buf[i] >= '0' && buf[i] <= '9'; ++i)
        pages = pages * 10 + static_cast<uint64_t>(buf[i] - '0');
    const uint64_t size = pages * static_cast<uint64_t>(sysconf(_SC_PAGESIZE));
    if (n > 0 && child_cap && size + (uint64_t(64) << 20) >= child_cap)
        _exit(BG_IO_CHILD_OVER_CAP);
}
#endif

void bg_io_child_limits(pid_t parent, size_t mem_cap, unsigned timeout_s)
{
#if defined(__SANITIZE_ADDRESS__)
    child_cap = mem_cap;
    __sanitizer_set_death_callback(child_death_check);
#endif
    // Die with the parent: an orphaned importer stuck in a loop would
    // otherwise run at 100% CPU forever. (The parent may already be gone.)
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent)
        _exit(1);
    if (mem_cap) {
        struct rlimit rl;
        if (getrlimit(RLIMIT_AS, &rl) == 0 && (rl.rlim_cur == RLIM_INFINITY || rl.rlim_cur > mem_cap)) {
            rl.rlim_cur = mem_cap;
            setrlimit(RLIMIT_AS, &rl);
        }
    }
    // SIGALRM's default action ends the child; the parent reports the time-out.
    signal(SIGALRM, SIG_DFL);
    alarm(timeout_s);
}

namespace {
long ms_since(const struct timespec &t0)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (t.tv_sec - t0.tv_sec) * 1000L + (t.tv_nsec - t0.tv_nsec) / 1000000L;
}

int reap(pid_t pid, int *status)
{
    while (waitpid(pid, status, 0) < 0)
        if (errno != EINTR)
            return -1;
    return 0;
}
} // namespace

int bg_io_wait_child(pid_t pid, long ms, int *status)
{
    struct timespec t0;
    clock_gettime(CLOCK_MONOTONIC, &t0);
#ifdef SYS_pidfd_open
    const int pfd = static_cast<int>(syscall(SYS_pidfd_open, pid, 0));
    if (pfd >= 0) {
        for (;;) {
            const long left = ms - ms_since(t0);
            struct pollfd p = {pfd, POLLIN, 0};
            const int r = left > 0 ? poll(&p, 1, static_cast<int>(std::min(left, 1L << 30))) : 0;
            if (r < 0 && errno == EINTR)
                continue;
            close(pfd);
            if (r == 0) // the deadline
                break;
            // Readable (the child ended), or poll failed: waitpid decides.
            return reap(pid, status) < 0 ? -1 : 0;
        }
        kill(pid, SIGKILL);
        return reap(pid, status) < 0 ? -1 : 1;
    }
#endif
    for (;;) {
        const pid_t r = waitpid(pid, status, WNOHANG);
        if (r == pid)
            return 0;
        if (r < 0 && errno != EINTR)
            return -1;
        if (ms_since(t0) >= ms)
            break;
        struct timespec ts = {0, 10 * 1000 * 1000};
        nanosleep(&ts, nullptr);
    }
    kill(pid, SIGKILL);
    return reap(pid, status) < 0 ? -1 : 1;
}
