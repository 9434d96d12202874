/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: `eval` and `perturb` end to end (src/tools/points), from a
 * CSV file on disk to a CSV file written through the safe writer.
 *
 * Input: byte 0 picks the run (bit 0 perturb instead of eval, bit 1 double,
 * bit 2 central differences, bit 3 --allow-nonfinite, bits 4-5 the function,
 * bits 6-7 the perturbation method), byte 1 the octaves (1..16), the rest is
 * the input file.
 *
 * Checks, besides ASan/UBSan: a failure carries a message with its status and
 * leaves no output and no temporary behind; a success leaves exactly the
 * output, whose header holds our columns (an id column before them and the
 * input's extra columns after them are passed through) and whose every line
 * has at least our number of fields (passed-through quoted fields may hold
 * commas of their own). */
#define _GNU_SOURCE
#include "fuzz_util.h"
#include "height_source.h"
#include "points/points.h"

static const char *out_name = "out.csv";

/* Lines of the output file; 0 if every line has at least `fields` fields. */
static int check_output(const char *path, const char *header, int fields, size_t *lines)
{
    FILE *f = fopen(path, "rb");
    FUZZ_CHECK(f != NULL, "success without an output file");
    /* getline, not fgets + strlen: passed-through fields are copied byte for
     * byte, NUL bytes included, and make lines of any length. */
    char *line = NULL;
    size_t cap = 0;
    ssize_t got;
    *lines = 0;
    int bad = 0;
    while ((got = getline(&line, &cap, f)) > 0) {
        size_t n = (size_t)got;
        FUZZ_CHECK(line[n - 1] == '\n', "output line %zu unterminated", *lines + 1);
        if (*lines == 0)
            FUZZ_CHECK(strstr(line, header) != NULL, "output header is \"%s\"", line);
        int commas = 0;
        for (size_t i = 0; i < n; i++)
            commas += line[i] == ',';
        bad |= commas < fields - 1;
        ++*lines;
    }
    free(line);
    fclose(f);
    return bad;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 2)
        return 0;
    const int mode = data[0];
    const int octaves = 1 + (data[1] & 15);
    const char *in = fuzz_write_file("in.csv", data + 2, size - 2);
    char out[512];
    snprintf(out, sizeof out, "%s/%s", fuzz_tmpdir(), out_name);
    unlink(out);

    bgt_err err;
    bgt_err_clear(&err);
    bg_status st;
    int perturb = mode & 1;
    bg_function fn = (bg_function)(((mode >> 4) & 3) % 3);
    if (!perturb) {
        bgt_eval_opts o;
        memset(&o, 0, sizeof o);
        o.input = in;
        o.output = out;
        o.fractal = bg_fractal_default(fn);
        o.fractal.octaves = octaves;
        o.central = (mode >> 2) & 1;
        o.dbl = (mode >> 1) & 1;
        o.step = 1e-3;
        o.threads = 1;
        o.allow_nonfinite = (mode >> 3) & 1;
        st = bgt_eval_run(&o, &err);
    } else {
        bgt_height h;
        bgt_height_init(&h);
        h.h.fractal = bg_fractal_default(fn);
        h.h.fractal.octaves = octaves;
        bgt_perturb_opts o;
        memset(&o, 0, sizeof o);
        o.input = in;
        o.output = out;
        o.height = &h;
        o.method = (bg_perturb_method)(((mode >> 6) & 3) % 3);
        o.threads = 1;
        o.allow_nonfinite = (mode >> 3) & 1;
        st = bgt_perturb_run(&o, &err);
    }
    const char *other;
    if (st != BG_OK) {
        FUZZ_CHECK(err.status == st, "returned %d, err.status %d", (int)st, (int)err.status);
        fuzz_check_message(perturb ? "perturb" : "eval", st, err.msg, in);
        FUZZ_CHECK(fuzz_dir_entries("in.csv", NULL, &other) == 0,
                   "a failed run left %s behind (%s)", other, err.msg);
        return 0;
    }
    FUZZ_CHECK(fuzz_dir_entries("in.csv", out_name, &other) == 0, "a run left %s behind", other);
    size_t lines;
    int bad = perturb ? check_output(out, "x,y,z,nx,ny,nz,height,px,py,pz,inward", 11, &lines)
                      : check_output(out, "x,y,z,value,dx,dy,dz", 7, &lines);
    FUZZ_CHECK(!bad, "an output line with the wrong number of fields");
    FUZZ_CHECK(lines >= 1, "empty output");
    unlink(out);
    return 0;
}
