/* SPDX-License-Identifier: MIT */
/* A C program on the installed I/O library (image.h, io.h), linked with
 * `pkg-config --cflags --libs bumpgrad-io` only: checks that the module loads
 * from the installed tree (bg_io_available), writes a float image, reads it
 * back bit for bit. With "missing" as argv[2] (and BUMPGRAD_IO_MODULE naming a
 * file that does not exist) it checks instead that the failure is reported as
 * a status and message, up front, without any output on stderr.
 *
 * usage: io_consumer DIR [missing] */
#include <bumpgrad/image.h>
#include <bumpgrad/io.h>

#include <stdio.h>
#include <string.h>

int main(int argc, char **argv)
{
    char err[1024] = "";
    if (argc < 2)
        return 2;
    bg_status s = bg_io_available(err, sizeof err);
    if (argc > 2 && strcmp(argv[2], "missing") == 0) {
        if (s != BG_ERR_IO || !strstr(err, "no-such-module.so") || !strstr(err, "BUMPGRAD_IO_MODULE")) {
            printf("FAIL: missing module gave status %d, message '%s'\n", (int)s, err);
            return 1;
        }
        bg_image img;
        if (bg_image_alloc(&img, 2, 2, 1) != BG_OK)
            return 1;
        char err2[1024] = "";
        s = bg_image_write("/nonexistent-dir/x.exr", &img, BG_PIXEL_F32, 0, err2, sizeof err2);
        bg_image_free(&img);
        if (s != BG_ERR_IO || strcmp(err, err2) != 0) {
            printf("FAIL: write without module: %d '%s'\n", (int)s, err2);
            return 1;
        }
        printf("io_consumer: missing module reported: %s\n", err);
        return 0;
    }
    if (s != BG_OK) {
        printf("FAIL: bg_io_available: %s\n", err);
        return 1;
    }
    bg_image img, back;
    if (bg_image_alloc(&img, 7, 5, 3) != BG_OK)
        return 1;
    for (int i = 0; i < 7 * 5 * 3; i++)
        img.pixels[i] = (float)i / 7.0f - 3.0f;
    char path[4096];
    snprintf(path, sizeof path, "%s/io_consumer.exr", argv[1]);
    s = bg_image_write(path, &img, BG_PIXEL_F32, 0, err, sizeof err);
    if (s != BG_OK) {
        printf("FAIL: bg_image_write: %s: %s\n", bg_status_string(s), err);
        return 1;
    }
    s = bg_image_read(path, &back, err, sizeof err);
    if (s != BG_OK) {
        printf("FAIL: bg_image_read: %s: %s\n", bg_status_string(s), err);
        return 1;
    }
    int same = back.width == 7 && back.height == 5 && back.channels == 3 &&
               memcmp(back.pixels, img.pixels, sizeof(float) * 7 * 5 * 3) == 0;
    bg_image_free(&img);
    bg_image_free(&back);
    if (!same) {
        printf("FAIL: the image read back differs\n");
        return 1;
    }
    printf("io_consumer: wrote and read back %s (7x5x3 float) through libbumpgrad-io\n", path);
    return 0;
}
