/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the streaming CSV reader of eval/perturb
 * (src/tools/common/csv.c), on a memory FILE (fmemopen).
 *
 * Input: byte 0 picks the mode (bit 0 double, bit 1 --allow-nonfinite, bit 2
 * the 6-column perturb header instead of eval's 3, bits 3-5 the block size),
 * the rest is the file. bgt_csv_open needs a path, so it opens /dev/null and
 * the harness swaps in the memory FILE (the struct is the reader's public state).
 *
 * Checks, besides ASan/UBSan: every failure has the status it returned in
 * err.status and a message starting "<name>:LINE:" with LINE at least 1; no
 * block is larger than asked; every value is finite unless nonfinite is allowed;
 * after the end of input the reader keeps returning 0 rows. */
#define _GNU_SOURCE
#include <math.h>
#include "common/csv.h"
#include "fuzz_util.h"

static const char *const eval_names[] = {"x", "y", "z"};
static const char *const perturb_names[] = {"x", "y", "z", "nx", "ny", "nz"};

static void check_failure(const bgt_err *err, bg_status st)
{
    FUZZ_CHECK(err->status == st, "returned %d, err.status %d", (int)st, (int)err->status);
    FUZZ_CHECK(err->msg[0] != '\0', "status %d without a message", (int)st);
    unsigned long line = 0;
    FUZZ_CHECK(sscanf(err->msg, "fuzz.csv:%lu:", &line) == 1 && line >= 1,
               "message does not start with FILE:LINE: \"%s\"", err->msg);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    const int mode = data[0];
    const int dbl = mode & 1, nonfinite = (mode >> 1) & 1;
    const int count = (mode & 4) ? 6 : 3;
    const size_t max = (size_t)1 << ((mode >> 3) & 7); /* 1..128 rows per block */
    data++;
    size--;

    bgt_err err;
    bgt_err_clear(&err);
    bgt_csv c;
    bg_status st = bgt_csv_open(&c, &err, "/dev/null", nonfinite);
    FUZZ_CHECK(st == BG_OK, "opening /dev/null: %s", err.msg);
    fclose(c.fp);
    /* fmemopen of 0 bytes is refused by some libcs: read an empty file then. */
    static const char empty[1];
    c.fp = fmemopen(size ? (void *)data : (void *)empty, size ? size : 1, "rb");
    FUZZ_CHECK(c.fp != NULL, "fmemopen: %s", strerror(errno));
    if (!size)
        fgetc(c.fp); /* at the end of the one-byte stream: an empty input */
    c.name = "fuzz.csv";
    c.size = size;

    st = bgt_csv_header(&c, count == 6 ? perturb_names : eval_names, count);
    if (st) {
        check_failure(&err, st);
        bgt_csv_close(&c);
        return 0;
    }
    float fbuf[6][128];
    double dbuf[6][128];
    float *fcols[6];
    double *dcols[6];
    for (int k = 0; k < 6; k++) {
        fcols[k] = fbuf[k];
        dcols[k] = dbuf[k];
    }
    int ended = 0;
    for (;;) {
        size_t rows = (size_t)-1;
        st = dbl ? bgt_csv_read_double(&c, count, dcols, max, &rows)
                 : bgt_csv_read_float(&c, count, fcols, max, &rows);
        if (st) {
            check_failure(&err, st);
            FUZZ_CHECK(!ended, "an error after the end of input");
            break;
        }
        FUZZ_CHECK(rows <= max, "%zu rows in a block of %zu", rows, max);
        for (size_t r = 0; r < rows && !nonfinite; r++)
            for (int k = 0; k < count; k++)
                FUZZ_CHECK(dbl ? isfinite(dbuf[k][r]) : isfinite(fbuf[k][r]),
                           "non-finite value accepted without --allow-nonfinite (row %zu)", r);
        if (rows == 0) {
            if (ended)
                break;
            ended = 1; /* one more call: still the end, no error */
        } else {
            FUZZ_CHECK(!ended, "rows after the end of input");
        }
    }
    bgt_csv_close(&c);
    return 0;
}
