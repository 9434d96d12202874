/* SPDX-License-Identifier: MIT */
#include "bumpgrad/common.h"

const char *bg_status_string(bg_status s)
{
    switch (s) {
    case BG_OK: return "ok";
    case BG_ERR_INVALID_ARGUMENT: return "invalid argument";
    case BG_ERR_NULL_POINTER: return "null pointer";
    case BG_ERR_UNSUPPORTED_ISA: return "instruction set not supported by this CPU";
    case BG_ERR_OUT_OF_MEMORY: return "out of memory";
    case BG_ERR_IO: return "input/output error";
    case BG_ERR_FORMAT: return "malformed input";
    case BG_ERR_OVERFLOW: return "parameters overflow the float range (octave scaling)";
    }
    return "unknown status";
}

#define BG_STR2(x) #x
#define BG_STR(x) BG_STR2(x)

/* From the version macros of common.h (meson.build checks them against the
 * project version: one version, written once). */
const char *bg_version_string(void)
{
    return BG_STR(BG_VERSION_MAJOR) "." BG_STR(BG_VERSION_MINOR) "." BG_STR(BG_VERSION_PATCH);
}
