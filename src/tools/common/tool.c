/* SPDX-License-Identifier: MIT */
#include "tool.h"
#include <stdarg.h>
#include <stdio.h>
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

void bgt_err_clear(bgt_err *e)
{
    if (e) {
        e->status = BG_OK;
        e->msg[0] = '\0';
    }
}
