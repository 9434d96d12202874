/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: image input (bg_image_read, include/bumpgrad/image.h),
 * through the I/O shim and its OpenImageIO module: heightmap's input path.
 *
 * Input: byte 0 picks the file extension (OpenImageIO chooses the reader by
 * it first), the rest is the file. Checks, besides ASan/UBSan in our code: a
 * failure returns BG_ERR_IO or BG_ERR_FORMAT with a message naming the file
 * and an empty image; a success gives a non-empty image whose pixel array
 * holds width*height*channels floats (ASan checks the last one is readable). */
#define _GNU_SOURCE
#include "bumpgrad/image.h"
#include "fuzz_util.h"

static const char *const exts[] = {"png", "tga", "exr", "tif", "jpg", "bmp",
                                   "hdr", "pnm", "psd", "dds", "gif", "ico",
                                   "sgi", "rla", "webp", "cin"};

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    char name[32];
    snprintf(name, sizeof name, "in.%s", exts[data[0] % (sizeof exts / sizeof exts[0])]);
    const char *path = fuzz_write_file(name, data + 1, size - 1);
    bg_image img;
    memset(&img, 0x5a, sizeof img);
    char err[512];
    bg_status st = bg_image_read(path, &img, err, sizeof err);
    if (st != BG_OK) {
        FUZZ_CHECK(st == BG_ERR_IO || st == BG_ERR_FORMAT || st == BG_ERR_OUT_OF_MEMORY,
                   "unexpected status %d: %s", (int)st, err);
        fuzz_check_message("bg_image_read", st, err, path);
        unlink(path);
        return 0;
    }
    FUZZ_CHECK(img.width > 0 && img.height > 0 && img.channels > 0 && img.pixels,
               "success with an empty image %dx%dx%d", img.width, img.height, img.channels);
    size_t n = (size_t)img.width * (size_t)img.height * (size_t)img.channels;
    volatile float last = img.pixels[n - 1];
    (void)last;
    bg_image_free(&img);
    unlink(path);
    return 0;
}
