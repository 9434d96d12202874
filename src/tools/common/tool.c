/* SPDX-License-Identifier: MIT */
#include "tool.h"
#include "env.h"
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bg_status bgt_fail(bgt_err *e, bg_status s, const char *fmt, ...)
{
    if (!e)
        return s;
    e->status = s;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(e->msg, sizeof e->msg, fmt, ap);
    va_end(ap);
    return s;
}

void bgt_err_prefix(bgt_err *e, const char *prefix)
{
    if (!e)
        return;
    size_t cap = sizeof e->msg, pl = strlen(prefix), ml = strlen(e->msg);
    if (pl + 2 >= cap)
        pl = cap - 3;
    if (pl + 2 + ml >= cap)
        ml = cap - 1 - pl - 2;
    memmove(e->msg + pl + 2, e->msg, ml);
    memcpy(e->msg, prefix, pl);
    e->msg[pl] = ':', e->msg[pl + 1] = ' ';
    e->msg[pl + 2 + ml] = '\0';
}

size_t bgt_memory_cap(void)
{
    /* A bad value never switches the cap off: the default holds, and
     * bgt_check_alloc (and the CLI, before any work) names the variable. */
    unsigned long long mb;
    if (bgt_env_uint("BUMPGRAD_MAX_MB", &mb, NULL) != BG_OK)
        mb = BGT_DEFAULT_MAX_MB;
    if (mb == 0 || mb > (unsigned long long)(SIZE_MAX >> 20))
        return SIZE_MAX;
    return (size_t)mb << 20;
}

bg_status bgt_check_alloc(double bytes, const char *what, bgt_err *e)
{
    unsigned long long mb;
    if (bgt_env_uint("BUMPGRAD_MAX_MB", &mb, e) != BG_OK)
        return BG_ERR_INVALID_ARGUMENT;
    size_t cap = bgt_memory_cap();
    if (cap == SIZE_MAX || bytes <= (double)cap)
        return BG_OK;
    return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                    "%s would need %.0f MiB, over the cap of %zu MiB (set BUMPGRAD_MAX_MB to "
                    "raise it, 0 for none)",
                    what, bytes / 1048576.0, cap >> 20);
}

bg_status bgt_read_status(bg_status s)
{
    return s == BG_ERR_OUT_OF_MEMORY || s == BG_ERR_FORMAT ? s : BG_ERR_INVALID_ARGUMENT;
}

bg_status bgt_write_status(bg_status s)
{
    return s == BG_ERR_INVALID_ARGUMENT || s == BG_ERR_OUT_OF_MEMORY ? s : BG_ERR_IO;
}

void bgt_err_clear(bgt_err *e)
{
    if (e) {
        e->status = BG_OK;
        e->msg[0] = '\0';
    }
}
