// SPDX-License-Identifier: MIT
#include "io_util.h"
#include "common/safe_file.h"

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

// The temporary-file protocol is src/tools/common/safe_file.c, the same code
// the C tools use (compiled into this module too): one rule for the new
// file's mode, for non-regular targets and for the signal-time cleanup.
static bg_status from_tool(bg_status st, const bgt_err &e, char *err, size_t errlen)
{
    if (st != BG_OK)
        bg_io_set_error(err, errlen, "%s", e.msg);
    return st;
}

bg_status bg_io_make_temp(const char *path, std::string *tmp, char *err, size_t errlen)
{
    bgt_err e;
    char *t = bgt_safe_temp_path(path, &e);
    if (!t)
        return from_tool(e.status, e, err, errlen);
    tmp->assign(t);
    std::free(t);
    return BG_OK;
}

void bg_io_discard_temp(const std::string &tmp) { bgt_safe_discard_path(tmp.c_str()); }

bg_status bg_io_commit_temp(const std::string &tmp, const char *path, char *err, size_t errlen)
{
    bgt_err e;
    return from_tool(bgt_safe_commit_path(tmp.c_str(), path, &e), e, err, errlen);
}
