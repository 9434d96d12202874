/* SPDX-License-Identifier: MIT */
/* env.h: the BUMPGRAD_* variables and their ranges. */
#include "env.h"
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* 2^24 MiB = 16 TiB: more than any machine this runs on, and far below the
 * point where MiB << 20 overflows a 64-bit size. */
#define MAX_MIB (1ull << 24)

typedef struct num_var {
    const char *name;
    unsigned long long def, lo, hi;
    const char *what; /* the unit and the meaning of 0, for the message */
} num_var;

/* The caps accept 0 ("no cap", documented) or a value from `lo`. A child cap
 * too small for a valid file is reported by the reader, naming the variable
 * (mesh.cc, volume.cc), never as the file's fault. */
static const num_var num_vars[] = {
    {"BUMPGRAD_MAX_MB", BGT_DEFAULT_MAX_MB, 1, MAX_MIB, "MiB (0 for no cap)"},
    {"BUMPGRAD_MESH_MAX_MB", BGT_ENV_AUTO, 1, MAX_MIB, "MiB (0 for no cap)"},
    {"BUMPGRAD_VDB_MAX_MB", BGT_ENV_AUTO, 1, MAX_MIB, "MiB (0 for no cap)"},
    {"BUMPGRAD_CHILD_TIMEOUT", 60, 1, 86399, "seconds, 1 to 86399"},
};
#define NVARS (sizeof num_vars / sizeof num_vars[0])

static bg_status parse(const num_var *v, const char *s, unsigned long long *out, bgt_err *e)
{
    unsigned long long x = 0;
    int ok = *s != '\0';
    for (const char *p = s; ok && *p; p++) {
        if (*p < '0' || *p > '9' || x > (~0ull - 9) / 10)
            ok = 0;
        else
            x = x * 10 + (unsigned)(*p - '0');
    }
    /* 0 is allowed only where it is documented to switch the cap off. */
    int zero_ok = strstr(v->what, "0 for no cap") != NULL;
    if (ok && x == 0 && zero_ok) {
        *out = 0;
        return BG_OK;
    }
    if (!ok || x < v->lo || x > v->hi)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "environment variable %s=\"%.64s\": %s (a whole number of %s, at "
                        "most %llu)",
                        v->name, s, ok ? "out of range" : "not a whole number", v->what, v->hi);
    *out = x;
    return BG_OK;
}

bg_status bgt_env_uint(const char *name, unsigned long long *out, bgt_err *e)
{
    for (size_t i = 0; i < NVARS; i++) {
        if (strcmp(num_vars[i].name, name) != 0)
            continue;
        *out = num_vars[i].def;
        const char *s = getenv(name);
        if (!s || !*s)
            return BG_OK;
        return parse(&num_vars[i], s, out, e);
    }
    return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "%s is not a numeric bumpgrad variable", name);
}

bg_status bgt_env_check(bgt_err *e)
{
    unsigned long long v;
    for (size_t i = 0; i < NVARS; i++)
        if (bgt_env_uint(num_vars[i].name, &v, e) != BG_OK)
            return e ? e->status : BG_ERR_INVALID_ARGUMENT;
    const char *tex = getenv("BUMPGRAD_TEXTURES_UNDER");
    struct stat ts;
    if (tex && *tex && (stat(tex, &ts) != 0 || !S_ISDIR(ts.st_mode)))
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "environment variable BUMPGRAD_TEXTURES_UNDER=%s: not a folder", tex);
    const char *mod = getenv("BUMPGRAD_IO_MODULE");
    if (mod && *mod) {
        struct stat st;
        if (stat(mod, &st) != 0)
            return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "environment variable BUMPGRAD_IO_MODULE=%s: %s",
                            mod, strerror(errno));
        if (!S_ISREG(st.st_mode))
            return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                            "environment variable BUMPGRAD_IO_MODULE=%s: not a regular file", mod);
    }
    return BG_OK;
}
