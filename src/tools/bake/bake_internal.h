/* SPDX-License-Identifier: MIT */
/* What the image bakes (heightmap.c, generate.c) share: writing the finished
 * image. Internal to bake/; not a face. */
#ifndef BUMPGRAD_TOOLS_BAKE_INTERNAL_H
#define BUMPGRAD_TOOLS_BAKE_INTERNAL_H

#include <string.h>
#include "bumpgrad/image.h"
#include "common/tool.h"

/* IMG to PATH at BITS per sample (8, 16 or 32: float). A file's format is its
 * extension's; FORMAT names the format of "-" (standard output) only (the
 * shim takes "exr", ".exr" or "EXR" alike). A file name without an image
 * format is bad input (2); only the writing itself failing is a run failure. */
static inline bg_status bake_write_image(const char *path, const char *format, const bg_image *img,
                                         int bits, bgt_err *e)
{
    char err[1024];
    const bg_pixel_type type = bits == 8 ? BG_PIXEL_U8 : (bits == 16 ? BG_PIXEL_U16 : BG_PIXEL_F32);
    bg_status st = bg_image_write_as(path, strcmp(path, "-") == 0 ? format : NULL, img, type, 0,
                                     err, sizeof err);
    if (st == BG_OK)
        return BG_OK;
    return bgt_fail(e, bgt_write_status(st), "%s%s",
                    st == BG_ERR_INVALID_ARGUMENT && format ? "--format: " : "", err);
}

#endif
