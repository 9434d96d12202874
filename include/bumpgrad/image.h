/* SPDX-License-Identifier: MIT */
/**
 * @file image.h
 * @brief Images for the tools, through OpenImageIO (libbumpgrad_io, C++ inside,
 *        C interface). Not part of the core library.
 *
 * The OpenImageIO code lives in a module loaded on first use (docs/IO.md):
 * if it cannot be loaded, the calls taking an error buffer return BG_ERR_IO
 * with the reason; bg_image_alloc / bg_image_free never need it.
 */
#ifndef BUMPGRAD_IMAGE_H
#define BUMPGRAD_IMAGE_H

#include "common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** An interleaved float image, row 0 at the top. Values are whatever the file
 *  holds, converted to float (8/16-bit integer formats map to [0, 1]). */
typedef struct bg_image {
    int width, height, channels;
    float *pixels; /**< width*height*channels floats, owned (free with bg_image_free) */
} bg_image;

/** Storage type of written pixels. */
typedef enum bg_pixel_type {
    BG_PIXEL_U8 = 0,
    BG_PIXEL_U16 = 1,
    BG_PIXEL_HALF = 2,
    BG_PIXEL_F32 = 3
} bg_pixel_type;

/** Allocate a zeroed image. */
BG_API bg_status bg_image_alloc(bg_image *img, int width, int height, int channels);
BG_API void bg_image_free(bg_image *img);

/** Read any format OpenImageIO reads. On failure returns BG_ERR_IO or BG_ERR_FORMAT
 *  and writes a message naming the file into err (errlen bytes, may be 0).
 *  `path` "-" is standard input, as for bg_image_read_as with no format. */
BG_API bg_status bg_image_read(const char *path, bg_image *out, char *err, size_t errlen);

/** bg_image_read with the reader chosen by `format` (an OpenImageIO format name
 *  or extension, in any case, with or without a leading dot: "png", ".EXR", ...;
 *  NULL or "" = by the file's extension
 *  and content, as bg_image_read).
 *  `path` "-" reads standard input to its end into memory (an image reader
 *  seeks), checked against the allocation cap BUMPGRAD_MAX_MB before the buffer
 *  grows past it (BG_ERR_INVALID_ARGUMENT), then decodes it through
 *  OpenImageIO's IOMemReader; with no format the first reader that accepts the
 *  content (its magic) is used. OpenImageIO 2.4 reads PNG, JPEG, TIFF, OpenEXR,
 *  HDR, PNM, TGA, BMP, GIF, WebP, DPX, ... from memory, not e.g. SGI, FITS or
 *  RLA: such a format named with "-" is BG_ERR_INVALID_ARGUMENT naming it.
 *  Unknown format name: BG_ERR_INVALID_ARGUMENT. Not thread-safe for "-". */
BG_API bg_status bg_image_read_as(const char *path, const char *format, bg_image *out, char *err,
                                  size_t errlen);

/** Write an image; the format comes from the extension (.png, .exr, .tif, ...).
 *  `srgb` nonzero: pixel values are linear and are encoded with the sRGB transfer
 *  curve before quantization (for display images); zero: stored as they are.
 *  The file is written to a temporary name in the same folder and renamed into
 *  place on success, so a failure never leaves a partial file or destroys an old
 *  one. Unwritable path: BG_ERR_IO with a message. */
BG_API bg_status bg_image_write(const char *path, const bg_image *img, bg_pixel_type type, int srgb,
                                char *err, size_t errlen);

/** bg_image_write with the writer chosen by `format` (an OpenImageIO format name
 *  or extension, in any case, with or without a leading dot: "png", ".EXR", ...;
 *  NULL or "" = by the extension).
 *  `path` "-" is standard output: the image is encoded in memory (OpenImageIO's
 *  IOVecOutput), PNG when `format` is NULL, and written out in one piece only
 *  once it is complete. A short write or a closed pipe (EPIPE: SIGPIPE is
 *  blocked for the write) is BG_ERR_IO with a message; a terminal as standard
 *  output, or a format OpenImageIO 2.4 cannot write to memory (e.g. SGI, FITS,
 *  RLA, ICO, HEIF), is BG_ERR_INVALID_ARGUMENT naming it, before anything is
 *  written. Flushes stdio's stdout first. Not thread-safe for "-". */
BG_API bg_status bg_image_write_as(const char *path, const char *format, const bg_image *img,
                                   bg_pixel_type type, int srgb, char *err, size_t errlen);

/** Draw a line of text (UTF-8) into `img` with OpenImageIO's FreeType renderer,
 *  for labelled panels. (x, y) is the top-left corner of the text in pixels,
 *  `size` the font height in pixels, `rgb` the colour written into the first
 *  three channels (fewer channels: the first ones; a 4th channel gets 1 where
 *  text is drawn). Text outside the image is clipped. The font is the one named
 *  by the BUMPGRAD_FONT environment variable (a name or a .ttf path), else
 *  DejaVuSans (Debian's fonts-dejavu-core), else OpenImageIO's default.
 *  No font found: BG_ERR_IO with a message, the image is unchanged.
 *  Not thread-safe against other calls on the same image. */
BG_API bg_status bg_image_draw_text(bg_image *img, int x, int y, const char *text,
                                    const float rgb[3], int size, char *err, size_t errlen);

#ifdef __cplusplus
}
#endif

#endif /* BUMPGRAD_IMAGE_H */
