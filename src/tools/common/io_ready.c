/* SPDX-License-Identifier: MIT */
/* bgt_io_ready (tool.h): the I/O module checked before a long job starts, so
 * that a broken install fails at once with the loader's reason, not after
 * the whole render or bake at write time. */
#include "common/tool.h"
#include "bumpgrad/io.h"

bg_status bgt_io_ready(bgt_err *e)
{
    char why[768];
    if (bg_io_available(why, sizeof why) == BG_OK)
        return BG_OK;
    return bgt_fail(e, BG_ERR_IO, "the I/O module (OpenImageIO, OpenVDB, assimp) cannot be loaded: %s",
                    why);
}
