/* SPDX-License-Identifier: MIT */
/* bg_image_alloc / bg_image_free (bumpgrad/image.h): plain C, compiled into
 * both libbumpgrad-io (so that allocating works without loading the module)
 * and the I/O module (which allocates for its own reads): one source, the
 * same libc allocator on both sides. */
#include <stdlib.h>
#include "bumpgrad/image.h"

bg_status bg_image_alloc(bg_image *img, int width, int height, int channels)
{
    if (!img)
        return BG_ERR_NULL_POINTER;
    img->width = img->height = img->channels = 0;
    img->pixels = NULL;
    if (width <= 0 || height <= 0 || channels <= 0 || channels > 64)
        return BG_ERR_INVALID_ARGUMENT;
    size_t n = (size_t)width;
    if (n > (size_t)-1 / (size_t)height)
        return BG_ERR_OUT_OF_MEMORY;
    n *= (size_t)height;
    if (n > (size_t)-1 / sizeof(float) / (size_t)channels)
        return BG_ERR_OUT_OF_MEMORY;
    img->pixels = calloc(n * (size_t)channels, sizeof(float));
    if (!img->pixels)
        return BG_ERR_OUT_OF_MEMORY;
    img->width = width;
    img->height = height;
    img->channels = channels;
    return BG_OK;
}

void bg_image_free(bg_image *img)
{
    if (!img)
        return;
    free(img->pixels); /* same libc allocator as the module's bg_image_alloc */
    img->pixels = NULL;
    img->width = img->height = img->channels = 0;
}

