/* SPDX-License-Identifier: MIT */
/* The BUMPGRAD_* environment variables, read strictly and in one place. A value
 * is digits only (no sign, no exponent, no spaces) within the variable's
 * documented range; anything else is an error whose message names the
 * variable, never a silent default and never "no cap". The CLI checks them all
 * before any work (bgt_env_check: exit 2). */
#ifndef BUMPGRAD_TOOLS_ENV_H
#define BUMPGRAD_TOOLS_ENV_H

#include "tool.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The value of a variable with no value set and no default ("auto"). */
#define BGT_ENV_AUTO (~0ull)

/* A numeric BUMPGRAD_* variable: unset or empty gives its default
 * (BGT_ENV_AUTO where the default is computed by the reader); a bad value
 * gives BG_ERR_INVALID_ARGUMENT and a message naming the variable.
 * BG_ERR_INVALID_ARGUMENT too for a name that is not a numeric variable. */
bg_status bgt_env_uint(const char *name, unsigned long long *out, bgt_err *e);

/* Every BUMPGRAD_* variable that is set: the numbers as above, and
 * BUMPGRAD_IO_MODULE must name a regular file (a FIFO would hang the load),
 * BUMPGRAD_TEXTURES_UNDER a folder. */
bg_status bgt_env_check(bgt_err *e);

#ifdef __cplusplus
}
#endif

#endif
