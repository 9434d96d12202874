/* SPDX-License-Identifier: MIT */
/* The bench engine (src/tools/bench) as a library: rows come back, not text;
 * the selection, the ratios, the icount file and the errors behave as bench.h
 * says. A peer of the test's own stands in for the real ones, so this links
 * neither libnoise nor libstdc++. Timings are only checked to be positive and
 * ordered (min <= median <= max), never against a speed. The grid rows'
 * sub-grids are checked by the engine's own unit test
 * (src/tools/bench/test_bench_unit.c). */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench/bench.h"
#include "common/check.h"

static size_t fake_points, fake_calls;

/* A peer that does real work (so it cannot be timed at 0) and counts points. */
static void fake_value(const float *x, const float *y, const float *z, size_t n, float *v,
                       float *gx, float *gy, float *gz)
{
    (void)gx, (void)gy, (void)gz;
    for (size_t i = 0; i < n; i++)
        v[i] = bg_noise3(x[i], y[i], z[i]);
    fake_points += n;
    fake_calls++;
}

static size_t announced;
static void on_measuring(void *ctx, const bgt_bench_row *r)
{
    (void)ctx;
    if (r->name[0] && r->isa && r->threads >= 1)
        announced++;
}

static const bgt_bench_row *find(const bgt_bench_result *res, const char *name, const char *isa,
                                 int threads)
{
    for (size_t i = 0; i < res->nrows; i++)
        if (!strcmp(res->rows[i].name, name) && !strcmp(res->rows[i].isa, isa) &&
            res->rows[i].threads == threads)
            return &res->rows[i];
    return NULL;
}

static int nisas(void)
{
    int n = 0;
    bg_isa cap = bg_isa_active();
    for (int k = 0; k < BG_ISA_COUNT; k++)
        n += bg_isa_supported((bg_isa)k) &&
             (k == BG_ISA_SCALAR || k == (int)cap ||
              (k != BG_ISA_NEON && cap != BG_ISA_NEON && k < (int)cap));
    return n;
}

int main(void)
{
    const bgt_bench_peer peers[] = {{"fake", BGT_PEER_VALUE, fake_value}};
    const size_t samples = 4096;
    bgt_bench_opts o = {.samples = samples, .runs = 3, .threads = 2, .isa = -1,
                        .kernels = "noise3,fbm3_point,noise3_grid,peer:fake", .peers = peers, .npeers = 1,
                        .measuring = on_measuring};
    bgt_bench_result res;
    bgt_err e;
    bg_status s = bgt_bench_run(&o, &res, &e);
    CHECK(s == BG_OK, "run: %d %s", (int)s, e.msg);
    if (s == BG_OK) {
        /* peer (1 thread) + noise3 per ISA x {1, 2 threads} + fbm3_point and
         * noise3_grid at the active ISA x 2. */
        size_t want = 1 + 2 * (size_t)nisas() + 4;
        CHECK(res.nrows == want, "rows %zu, want %zu", res.nrows, want);
        CHECK(announced == res.nrows, "measuring called %zu times for %zu rows", announced,
              res.nrows);
        CHECK(res.samples == samples && res.runs == 3 && res.threads == 2, "result header");
        /* The peer ran the warm-up (the whole batch here, n/8 < 4096) and 3 runs. */
        CHECK(fake_calls == 4 && fake_points == 4 * samples, "peer calls %zu, points %zu",
              fake_calls, fake_points);
        CHECK(!strcmp(res.rows[0].name, "peer:fake:value") && res.rows[0].kernel == -1 &&
                  !strcmp(res.rows[0].isa, "baseline"),
              "peers come first: %s", res.rows[0].name);
        for (size_t i = 0; i < res.nrows; i++) {
            const bgt_bench_row *r = &res.rows[i];
            CHECK(r->median > 0 && r->min <= r->median && r->median <= r->max, "%s %s timing",
                  r->name, r->isa);
            CHECK(r->icount == 0, "no icount without a file");
            /* CPU time per sample: positive, and a one-thread run cannot use
             * much more CPU than wall time (2x leaves room for clock grain). */
            CHECK(r->cpu_ns > 0 && (r->threads > 1 || r->cpu_ns < 2e3 / r->min + 1e3),
                  "%s %s cpu_ns %g (wall %g ns)", r->name, r->isa, r->cpu_ns, 1e3 / r->median);
        }
        const bgt_bench_row *sc = find(&res, "noise3", "scalar", 1);
        const bgt_bench_row *sc2 = find(&res, "noise3", "scalar", 2);
        CHECK(sc && sc->speedup == 1.0 && sc->vs_peer > 0 && sc->best_peer &&
                  !strcmp(sc->best_peer, "peer:fake:value"),
              "scalar noise3: speedup 1 and set against the fake peer");
        CHECK(sc && sc->vs_peer == sc->median / res.rows[0].median, "vs_peer is the ratio");
        CHECK(sc2 && sc2->scaling > 0 && sc2->vs_peer == 0 && !sc2->best_peer,
              "2-thread rows: scaling, never a peer ratio");
        const char *act = bg_isa_name(bg_isa_active());
        CHECK(find(&res, "fbm3_point", act, 1) && find(&res, "noise3_grid", act, 2),
              "per-point and grid rows at the active ISA %s", act);
        for (size_t i = 0; i < res.nrows; i++)
            CHECK(res.rows[i].kernel < 0 || !strcmp(res.rows[i].name, "noise3") ||
                      !strcmp(res.rows[i].isa, act),
                  "%s at %s, not the active %s", res.rows[i].name, res.rows[i].isa, act);
        bgt_bench_result_free(&res);
        CHECK(res.rows == NULL && res.nrows == 0, "free clears the result");
    }

    /* --icount: the numbers land in exactly the named rows. */
    char path[] = "/tmp/bumpgrad-bench-icount-XXXXXX";
    int fd = mkstemp(path);
    FILE *fp = fd >= 0 ? fdopen(fd, "w") : NULL;
    CHECK(fp != NULL, "temp file");
    if (fp) {
        fprintf(fp, "noise3 scalar 239\nnoise3 nosuchisa 1\n");
        fclose(fp);
        bgt_bench_opts oi = o;
        oi.threads = 1;
        oi.kernels = "noise3";
        oi.icount_path = path;
        s = bgt_bench_run(&oi, &res, &e);
        CHECK(s == BG_OK, "icount run: %s", e.msg);
        if (s == BG_OK) {
            for (size_t i = 0; i < res.nrows; i++)
                CHECK(res.rows[i].icount == (!strcmp(res.rows[i].isa, "scalar") ? 239.0 : 0.0),
                      "icount of %s %s = %g", res.rows[i].name, res.rows[i].isa, res.rows[i].icount);
            bgt_bench_result_free(&res);
        }
        remove(path);
        s = bgt_bench_run(&oi, &res, &e);
        CHECK(s == BG_ERR_IO && strstr(e.msg, "--icount") && res.rows == NULL,
              "missing icount file: %d %s", (int)s, e.msg);
    }

    /* Errors: each names what is wrong and leaves no rows. */
    const char *bad[] = {"", ",", "bogus", "peer:glm:bar", "peer:libnoise:", "peer:fake:fbm"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        bgt_bench_opts ob = o;
        ob.kernels = bad[k];
        s = bgt_bench_run(&ob, &res, &e);
        CHECK(s == BG_ERR_INVALID_ARGUMENT && strstr(e.msg, "--kernels") && res.rows == NULL,
              "--kernels \"%s\": %d %s", bad[k], (int)s, e.msg);
    }
    /* A known library that is not built in selects nothing but is no error. */
    bgt_bench_opts ok = o;
    ok.kernels = "noise3,peer:glm";
    ok.threads = 1;
    ok.isa = BG_ISA_SCALAR;
    s = bgt_bench_run(&ok, &res, &e);
    CHECK(s == BG_OK && res.nrows == 1, "peer:glm absent is no error: %d %zu", (int)s, res.nrows);
    if (s == BG_OK)
        bgt_bench_result_free(&res);
    bgt_bench_opts oa = ok;
    oa.isa = BG_ISA_COUNT;
    s = bgt_bench_run(&oa, &res, &e);
    CHECK(s == BG_ERR_UNSUPPORTED_ISA, "isa out of range: %d", (int)s);
    oa = ok;
    oa.runs = 0;
    CHECK(bgt_bench_run(&oa, &res, &e) == BG_ERR_INVALID_ARGUMENT, "runs 0");
    oa = ok;
    oa.samples = (size_t)1 << 26; /* 13 arrays x 256 MiB: over a 64 MiB cap */
    setenv("BUMPGRAD_MAX_MB", "64", 1);
    s = bgt_bench_run(&oa, &res, &e);
    CHECK(s == BG_ERR_INVALID_ARGUMENT && strstr(e.msg, "cap"), "memory cap: %d %s", (int)s,
          e.msg);
    unsetenv("BUMPGRAD_MAX_MB");
    CHECK(bgt_bench_run(NULL, &res, &e) == BG_ERR_NULL_POINTER, "NULL options");

    /* --isa moves the public-call rows there for the run, and back after it. */
    bg_isa was = bg_isa_active();
    bgt_bench_opts os = o;
    os.isa = BG_ISA_SCALAR;
    os.threads = 1;
    os.kernels = "fbm3_point,fbm3_grid";
    s = bgt_bench_run(&os, &res, &e);
    CHECK(s == BG_OK && res.nrows == 2 && !strcmp(res.rows[0].isa, "scalar") &&
              !strcmp(res.rows[1].isa, "scalar") && bg_isa_active() == was,
          "--isa scalar: %d %zu rows, active %s after", (int)s, res.nrows,
          bg_isa_name(bg_isa_active()));
    if (s == BG_OK)
        bgt_bench_result_free(&res);


    /* The kernel names are the ones the JSON shows. */
    CHECK(bgt_bench_kernel_count() == 35 && !strcmp(bgt_bench_kernel_name(24), "pnoise3") &&
              !strcmp(bgt_bench_kernel_name(28), "fbm3_seed_grad") && !strcmp(bgt_bench_kernel_name(0), "noise3") &&
              !strcmp(bgt_bench_kernel_name(13), "noise3_batch1_point") &&
              !strcmp(bgt_bench_kernel_name(19), "noise3_n256") &&
              !strcmp(bgt_bench_kernel_name(22), "fbm3_grad_grid") &&
              !strcmp(bgt_bench_kernel_name(23), "stream3") && !strcmp(bgt_bench_kernel_name(29), "pfbm3_grad_xy") &&
              !strcmp(bgt_bench_kernel_name(30), "pfbm3_grad_p10") &&
              !strcmp(bgt_bench_kernel_name(31), "fbm3_grad_l3") &&
              !strcmp(bgt_bench_kernel_name(32), "pfbm3_grad_l3") &&
              !strcmp(bgt_bench_kernel_name(33), "mikktspace") &&
              !strcmp(bgt_bench_kernel_name(34), "mesh_bake") && !bgt_bench_kernel_name(35),
          "kernel names");
    return check_summary("test_bench_engine");
}
