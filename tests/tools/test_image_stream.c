/* SPDX-License-Identifier: MIT */
/* Images on "-" (standard input / output) through the I/O shim and the
 * heightmap tool, for test_image_stream.py, which checks the bytes:
 *   test_image_stream write FORMAT|default W H [random]  image -> stdout
 *   test_image_stream read FORMAT|auto                   stdin -> "W H C v0 v1 ..." (v: round(255 x))
 *   test_image_stream heightmap                          heightmap - - (8-bit, default PNG)
 * Exit 0 on success, 2 for bad input or usage (invalid argument, format), 1 for
 * a failed run (I/O, memory), with the message on stderr. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bumpgrad/image.h"
#include "bake/heightmap.h"

static int status_exit(bg_status st, const char *msg)
{
    if (st == BG_OK)
        return 0;
    fprintf(stderr, "test_image_stream: %s\n", msg);
    return st == BG_ERR_IO || st == BG_ERR_OUT_OF_MEMORY ? 1 : 2;
}

/* The pattern test_image_stream.py expects: ((7x + 13y + 5c) mod 256) / 255,
 * or (random) bytes of a fixed LCG, which PNG cannot compress much. */
static void fill(bg_image *img, int random)
{
    uint32_t s = 12345u;
    for (int y = 0; y < img->height; y++)
        for (int x = 0; x < img->width; x++)
            for (int c = 0; c < img->channels; c++) {
                s = s * 1664525u + 1013904223u;
                unsigned v = random ? (s >> 24) : (unsigned)(7 * x + 13 * y + 5 * c) % 256u;
                img->pixels[((size_t)y * img->width + x) * img->channels + c] = (float)v / 255.0f;
            }
}

int main(int argc, char **argv)
{
    char err[1024] = "";
    if (argc >= 5 && strcmp(argv[1], "write") == 0) {
        bg_image img;
        if (bg_image_alloc(&img, atoi(argv[3]), atoi(argv[4]), 3) != BG_OK)
            return status_exit(BG_ERR_INVALID_ARGUMENT, "bad size");
        fill(&img, argc > 5 && strcmp(argv[5], "random") == 0);
        const char *fmt = strcmp(argv[2], "default") == 0 ? NULL : argv[2];
        bg_status st = bg_image_write_as("-", fmt, &img, BG_PIXEL_U8, 0, err, sizeof err);
        bg_image_free(&img);
        return status_exit(st, err);
    }
    if (argc == 3 && strcmp(argv[1], "read") == 0) {
        bg_image img;
        const char *fmt = strcmp(argv[2], "auto") == 0 ? NULL : argv[2];
        bg_status st = bg_image_read_as("-", fmt, &img, err, sizeof err);
        if (st != BG_OK)
            return status_exit(st, err);
        printf("%d %d %d", img.width, img.height, img.channels);
        const size_t n = (size_t)img.width * img.height * img.channels;
        for (size_t i = 0; i < n; i++)
            printf(" %ld", lrintf(255.0f * img.pixels[i]));
        printf("\n");
        bg_image_free(&img);
        return 0;
    }
    if (argc == 2 && strcmp(argv[1], "heightmap") == 0) {
        bgt_heightmap_opts o = {.input = "-", .output = "-", .gray = BGT_GRAY_SEED,
                                .strength = 1.0f, .bits = 8};
        bgt_err e;
        bg_status st = bgt_heightmap_run(&o, &e);
        return status_exit(st, st == BG_OK ? "" : e.msg);
    }
    fprintf(stderr, "usage: test_image_stream write FORMAT|default W H [random] | "
                    "read FORMAT|auto | heightmap\n");
    return 2;
}
