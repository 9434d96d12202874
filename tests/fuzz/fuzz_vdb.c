/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: VDB input (bg_vdb_height_open, include/bumpgrad/volume.h),
 * --height-grid's path: the I/O shim reads the file once in a forked probe
 * child, then for real in-process, then the harness samples the grid.
 *
 * Input: byte 0 bit 0 picks the grid name ("height" or the first FloatGrid),
 * the rest is the .vdb file. Checks, besides ASan/UBSan in our code and the
 * child watchdog (fuzz_util.h): a failure is BG_ERR_IO or BG_ERR_FORMAT with a
 * message naming the file and no handle; a success gives a handle whose info
 * and samples can be read (samples at the centre of the active box and at a
 * NaN position, which must give NaN). */
#define _GNU_SOURCE
#include <math.h>
#include "bumpgrad/volume.h"
#define FUZZ_WATCHDOG /* fuzz_util.h starts the watchdog in LLVMFuzzerInitialize */
#include "fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    const char *grid = (data[0] & 1) ? "height" : NULL;
    const char *path = fuzz_write_file("in.vdb", data + 1, size - 1);
    bg_vdb_height *h = (bg_vdb_height *)(uintptr_t)1;
    char err[512];
    fuzz_watchdog_arm();
    bg_status st = bg_vdb_height_open(path, grid, &h, err, sizeof err);
    fuzz_watchdog_disarm("bg_vdb_height_open");
    if (st != BG_OK) {
        FUZZ_CHECK(st == BG_ERR_IO || st == BG_ERR_FORMAT || st == BG_ERR_OUT_OF_MEMORY,
                   "unexpected status %d: %s", (int)st, err);
        FUZZ_CHECK(h == NULL, "failure with a handle");
        fuzz_check_message("bg_vdb_height_open", st, err, path);
        return 0;
    }
    FUZZ_CHECK(h != NULL, "success without a handle");
    bg_vdb_height_info info;
    bg_vdb_height_get_info(h, &info);
    float px[2], py[2], pz[2], v[2], gx[2], gy[2], gz[2];
    px[0] = (float)(0.5 * (info.world_min[0] + info.world_max[0]));
    py[0] = (float)(0.5 * (info.world_min[1] + info.world_max[1]));
    pz[0] = (float)(0.5 * (info.world_min[2] + info.world_max[2]));
    px[1] = py[1] = pz[1] = NAN;
    bg_vdb_height_sample_batch(h, px, py, pz, 2, v, gx, gy, gz);
    FUZZ_CHECK(isnan(v[1]) && isnan(gx[1]) && isnan(gy[1]) && isnan(gz[1]),
               "a NaN position gave a number");
    bg_vdb_height_close(h);
    return 0;
}
