// SPDX-License-Identifier: MIT
#include "io_util.h"

#include <cerrno>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
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

bg_status bg_io_check_readable(const char *path, char *err, size_t errlen)
{
    struct stat st;
    if (::stat(path, &st) != 0) {
        bg_io_set_error(err, errlen, "'%s': %s", path, std::strerror(errno));
        return BG_ERR_IO;
    }
    if (S_ISDIR(st.st_mode)) {
        bg_io_set_error(err, errlen, "'%s': is a directory", path);
        return BG_ERR_IO;
    }
    int fd = ::open(path, O_RDONLY);
    if (fd < 0) {
        bg_io_set_error(err, errlen, "'%s': %s", path, std::strerror(errno));
        return BG_ERR_IO;
    }
    ::close(fd);
    return BG_OK;
}

bg_status bg_io_make_temp(const char *path, std::string *tmp, char *err, size_t errlen)
{
    std::string p(path);
    size_t slash = p.find_last_of('/');
    std::string dir = slash == std::string::npos ? std::string() : p.substr(0, slash + 1);
    std::string base = slash == std::string::npos ? p : p.substr(slash + 1);
    if (base.empty()) {
        bg_io_set_error(err, errlen, "cannot write '%s': not a file name", path);
        return BG_ERR_IO;
    }
    size_t dot = base.find_last_of('.');
    std::string ext = (dot == std::string::npos || dot == 0) ? std::string() : base.substr(dot);
    std::string stem = (dot == std::string::npos || dot == 0) ? base : base.substr(0, dot);
    std::string templ = dir + "." + stem + ".tmpXXXXXX" + ext;
    std::vector<char> buf(templ.begin(), templ.end());
    buf.push_back('\0');
    int fd = ::mkstemps(buf.data(), static_cast<int>(ext.size()));
    if (fd < 0) {
        int e = errno;
        bg_io_set_error(err, errlen, "cannot write '%s': %s", path, std::strerror(e));
        return BG_ERR_IO;
    }
    ::close(fd);
    tmp->assign(buf.data());
    return BG_OK;
}

// mkstemps creates 0600 files; an output should get the usual 0666 & ~umask.
// The umask is read from /proc (umask() itself would have to change it, which
// races with other threads creating files).
static mode_t new_file_mode(void)
{
    mode_t mask = 022;
    if (FILE *f = std::fopen("/proc/self/status", "r")) {
        char line[256];
        while (std::fgets(line, sizeof line, f)) {
            unsigned m;
            if (std::sscanf(line, "Umask: %o", &m) == 1) {
                mask = static_cast<mode_t>(m);
                break;
            }
        }
        std::fclose(f);
    }
    return static_cast<mode_t>(0666 & ~mask);
}

bg_status bg_io_commit_temp(const std::string &tmp, const char *path, char *err, size_t errlen)
{
    // Renaming over a device node or FIFO (say /dev/null, as root) would replace
    // it with a regular file: refuse instead.
    struct stat st;
    if (::stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        std::remove(tmp.c_str());
        bg_io_set_error(err, errlen, "refusing to replace '%s': it is not a regular file", path);
        return BG_ERR_IO;
    }
    (void)::chmod(tmp.c_str(), new_file_mode());
    if (std::rename(tmp.c_str(), path) != 0) {
        int e = errno;
        std::remove(tmp.c_str());
        bg_io_set_error(err, errlen, "cannot write '%s': %s", path, std::strerror(e));
        return BG_ERR_IO;
    }
    return BG_OK;
}
