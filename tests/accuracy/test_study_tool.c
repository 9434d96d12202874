/* SPDX-License-Identifier: MIT */
/* The studies as tools calls (src/tools/study/study.h), without the
 * command: argument checks and their statuses, the rows and files of a small
 * accuracy run, the callbacks, and a failing output folder. Measured facts of
 * the studies themselves are checked by test_study.py. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "study/study.h"
#include "study/stability.h" /* st_json_num: the summary's numbers */
#include "common/check.h"

typedef struct seen {
    int wrote, begin, end, nrows_at_first_wrote;
    size_t total, last;
    char first[512];
    const bgt_accuracy_result *res;
} seen;

static void on_wrote(void *ctx, const char *path)
{
    seen *s = ctx;
    if (s->wrote++ == 0) {
        snprintf(s->first, sizeof s->first, "%s", path);
        s->nrows_at_first_wrote = s->res ? s->res->nrows : -1;
    }
}
static void on_begin(void *ctx, const char *label, size_t total)
{
    seen *s = ctx;
    (void)label;
    s->begin++, s->total = total;
}
static void on_update(void *ctx, size_t done) { ((seen *)ctx)->last = done; }
static void on_end(void *ctx) { ((seen *)ctx)->end++; }

static int count_lines(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    int n = 0, c;
    while ((c = fgetc(f)) != EOF)
        n += c == '\n';
    fclose(f);
    return n;
}

static int exists(const char *dir, const char *name)
{
    char p[512];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    return access(p, F_OK) == 0;
}

int main(void)
{
    check_verbose = 1;
    char dir[] = "/tmp/bg-study-tool-XXXXXX";
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    char acc[600], stab[600], file[600], p[700];
    snprintf(acc, sizeof acc, "%s/acc", dir);
    snprintf(stab, sizeof stab, "%s/stab", dir);
    snprintf(file, sizeof file, "%s/a-file", dir);
    fclose(fopen(file, "w"));

    static bgt_accuracy_result res;
    seen s;
    memset(&s, 0, sizeof s);
    s.res = &res;
    bgt_study_report rep = {on_wrote, NULL, &s};
    bgt_progress prog = {on_begin, on_update, on_end, &s};
    bg_height h = bg_height_default();
    h.amplitude = 0.05f, h.frequency = 4.0f;
    bgt_accuracy_opts ao = {.out_dir = acc, .samples = 256, .runs = 1, .chart = 0, .height = h,
                            .progress = &prog, .report = &rep};
    bgt_err e;

    /* Bad arguments: BG_ERR_INVALID_ARGUMENT, nothing created. */
    ao.samples = 6;
    CHECK(bgt_accuracy_run(&ao, &res, &e) == BG_ERR_INVALID_ARGUMENT && e.status == BG_ERR_INVALID_ARGUMENT,
          "accuracy: samples 6 (not a multiple of 4) refused (%s)", e.msg);
    ao.samples = 256, ao.runs = 0;
    CHECK(bgt_accuracy_run(&ao, &res, &e) == BG_ERR_INVALID_ARGUMENT, "accuracy: runs 0 refused (%s)", e.msg);
    ao.runs = 1, ao.height.fractal.octaves = 0;
    CHECK(bgt_accuracy_run(&ao, &res, &e) == BG_ERR_INVALID_ARGUMENT &&
              strcmp(e.msg, "invalid height parameters") == 0,
          "accuracy: 0 octaves refused (%s)", e.msg);
    CHECK(access(acc, F_OK) != 0, "accuracy: no folder made for refused arguments");
    ao.height = h;
    bgt_stability_opts so = {.out_dir = stab, .samples = 0, .chart = 0};
    CHECK(bgt_stability_run(&so, &e) == BG_ERR_INVALID_ARGUMENT, "stability: 0 samples refused (%s)", e.msg);

    /* An output "folder" that is a file: BG_ERR_IO naming it. */
    ao.out_dir = file;
    CHECK(bgt_accuracy_run(&ao, &res, &e) == BG_ERR_IO && strstr(e.msg, "a-file") != NULL,
          "accuracy: output folder that is a file -> BG_ERR_IO (%s)", e.msg);
    so.out_dir = file, so.samples = 100;
    CHECK(bgt_stability_run(&so, &e) == BG_ERR_IO && strstr(e.msg, "not a folder") != NULL,
          "stability: output folder that is a file -> BG_ERR_IO (%s)", e.msg);

    /* A small run: turbulence with 6 octaves gives 2 analytic + 26 central +
     * 3 forward + 5 truncated + 8 footprint + 4 listing1 rows. */
    memset(&s, 0, sizeof s);
    s.res = &res;
    ao.out_dir = acc;
    bg_status st = bgt_accuracy_run(&ao, &res, &e);
    CHECK(st == BG_OK, "accuracy: small run succeeds (%s)", st ? e.msg : "");
    CHECK(res.nrows == 48, "accuracy: 48 rows (%d)", res.nrows);
    snprintf(p, sizeof p, "%s/accuracy.csv", acc);
    CHECK(count_lines(p) == res.nrows + 1, "accuracy.csv: header + one line per row (%d lines)", count_lines(p));
    CHECK(s.wrote == 1 && strcmp(s.first, p) == 0 && s.nrows_at_first_wrote == res.nrows,
          "accuracy: wrote reported once, for accuracy.csv, with the rows final (%d, %s)", s.wrote, s.first);
    CHECK(!exists(acc, "accuracy.gp"), "accuracy: no chart without chart");
    CHECK(s.begin == 1 && s.end == 1 && s.total > 0 && s.last > 0 && s.last <= s.total,
          "accuracy: progress begin/update/end (%zu of %zu)", s.last, s.total);
    int ref = -1, l1 = 0;
    for (int k = 0; k < res.nrows; k++) {
        if (!strcmp(res.rows[k].method, "analytic") && !strcmp(res.rows[k].precision, "float64"))
            ref = k;
        l1 += !strcmp(res.rows[k].method, "listing1");
    }
    CHECK(ref >= 0 && res.rows[ref].mean == 0 && res.rows[ref].max == 0,
          "accuracy: the float64 analytic row is the reference (error 0)");
    CHECK(l1 == 4, "accuracy: 4 Listing 1 densities (%d)", l1);
    CHECK(bgt_accuracy_run(&ao, &res, NULL) == BG_OK, "accuracy: NULL error buffer accepted");

    /* Stability without charts and callbacks: report and summary in place. */
    so.out_dir = stab, so.samples = 100;
    st = bgt_stability_run(&so, &e);
    CHECK(st == BG_OK, "stability: small run succeeds (%s)", st ? e.msg : "");
    CHECK(exists(stab, "STABILITY.md") && exists(stab, "summary.json") && exists(stab, "inward.csv") &&
              exists(stab, "listing1_det.csv") && !exists(stab, "inward.gp"),
          "stability: report, summary and CSVs written, no chart");

    /* summary.json is JSON: a number that is not finite is null, not nan. */
    char *buf = NULL;
    size_t len = 0;
    FILE *mem = open_memstream(&buf, &len);
    bgt_err je;
    st_out jo = {.json = mem, .json_first = 1, .e = &je};
    st_json_num(&jo, "a", 0.25);
    st_json_num(&jo, "b", NAN);
    st_json_num(&jo, "c", -INFINITY);
    fclose(mem);
    CHECK(buf && !strcmp(buf, "\n  \"a\": 0.25,\n  \"b\": null,\n  \"c\": null"),
          "summary numbers: NaN and -inf are null: %s", buf ? buf : "(none)");
    free(buf);

    char cmd[700];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    return check_summary("test_study_tool");
}
