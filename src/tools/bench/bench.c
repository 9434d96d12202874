/* SPDX-License-Identifier: MIT */
/* bgt_bench_run: the rows of `bumpgrad bench`, peers first, then every
 * selected kernel on every selected ISA with one thread and with N. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench/bench_internal.h"

/* ISAs: all that this build and CPU have, or the one asked for. */
static bg_status select_isas(int isa, int on[BG_ISA_COUNT], bgt_err *e)
{
    memset(on, 0, sizeof(int) * BG_ISA_COUNT);
    if (isa >= 0) {
        if (isa >= BG_ISA_COUNT || !bg_kernels_for((bg_isa)isa))
            return bgt_fail(e, BG_ERR_UNSUPPORTED_ISA,
                            "--isa %s: not available in this build on this CPU (best: %s)",
                            isa < BG_ISA_COUNT ? bg_isa_name((bg_isa)isa) : "?",
                            bg_isa_name(bg_isa_best()));
        on[isa] = 1;
        return BG_OK;
    }
    /* Every ISA present, up to the cap of `bumpgrad --isa` / BUMPGRAD_ISA (which
     * set the active level), so that a capped run never measures above it. */
    bg_isa cap = bg_isa_active();
    for (int k = 0; k < BG_ISA_COUNT; k++) {
        int below = k == BG_ISA_SCALAR || k == (int)cap ||
                    (k != BG_ISA_NEON && cap != BG_ISA_NEON && k < (int)cap);
        on[k] = below && bg_kernels_for((bg_isa)k) != NULL;
    }
    return BG_OK;
}

static bg_status check_opts(const bgt_bench_opts *o, bgt_err *e)
{
    if (o->samples == 0 || o->runs < 1 || o->runs > BGT_BENCH_MAX_RUNS || o->threads < 1)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "samples must be > 0, runs in 1..%d and threads >= 1 (got %zu, %d, %d)",
                        BGT_BENCH_MAX_RUNS, o->samples, o->runs, o->threads);
    if (o->npeers > BGT_BENCH_MAX_PEERS || (o->npeers && !o->peers))
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "at most %d peers, and a peer array",
                        BGT_BENCH_MAX_PEERS);
    /* The samples decide the 13 float arrays: the documented cap first. */
    double bytes = (double)o->samples * BENCH_NARRAYS * sizeof(float);
    return bgt_check_alloc(bytes, "bench arrays (--samples)", e);
}

static bgt_bench_row *new_row(bgt_bench_result *res, const char *isa, int kernel, int peer_op)
{
    bgt_bench_row *r = &res->rows[res->nrows++];
    memset(r, 0, sizeof *r);
    r->isa = isa;
    r->kernel = kernel;
    r->peer_op = peer_op;
    return r;
}

static void announce(const bgt_bench_opts *o, bgt_bench_row *r, int threads)
{
    r->threads = threads;
    if (o->measuring)
        o->measuring(o->ctx, r);
}

/* A mesh row (bench_internal.h): its sphere made once, one whole call per
 * run on 1 and on N threads. */
static bg_status run_mesh_row(const bgt_bench_opts *o, int k, bench_team *team, bench_job *job,
                              double *rate, bgt_bench_result *res, bgt_err *e)
{
#ifndef BG_HAVE_TOOLS
    if (k == K_MESH_BAKE)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--kernels: mesh_bake needs the tools build (this one has none)");
#endif
    bg_status s = bgt_check_alloc(bench_mesh_bytes(k), "bench mesh rows", e);
    if (s != BG_OK)
        return s;
    bench_mesh bm;
    if (bench_mesh_init(&bm, k) != 0)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the %s row",
                        bgt_bench_kernel_name((size_t)k));
    int nthreads = bench_team_threads(team);
    job->mesh = &bm;
    job->kernel = k;
    job->t = NULL;
    for (int pass = 0; pass < (nthreads > 1 ? 2 : 1) && bm.status == BG_OK; pass++) {
        bgt_bench_row *r = new_row(res, bg_isa_name(bg_isa_active()), k, -1);
        snprintf(r->name, sizeof r->name, "%s", bgt_bench_kernel_name((size_t)k));
        r->samples = bench_mesh_samples(k);
        job->threads = pass ? nthreads : 1;
        announce(o, r, job->threads);
        bench_measure(team, job->threads, job, r->samples, o->runs, rate, r);
    }
    job->mesh = NULL;
    s = bm.status;
    bench_mesh_free(&bm);
    if (s != BG_OK)
        return bgt_fail(e, s, "the %s row failed (%s)", bgt_bench_kernel_name((size_t)k),
                        bg_status_string(s));
    return BG_OK;
}

/* Measure every selected row into res->rows (room for all of them). */
static bg_status run_rows(const bgt_bench_opts *o, const bench_sel *sel, const int isa_on[],
                          bench_team *team, bench_job *job, double *rate, bgt_bench_result *res,
                          bgt_err *e)
{
    int nthreads = bench_team_threads(team);
    for (size_t p = 0; p < o->npeers; p++) {
        if (!sel->peers[p])
            continue;
        bgt_bench_row *r = new_row(res, "baseline", -1, (int)o->peers[p].op);
        snprintf(r->name, sizeof r->name, "peer:%s:%s", o->peers[p].library,
                 bgt_bench_peer_op_names[o->peers[p].op]);
        announce(o, r, 1);
        job->t = NULL;
        job->peer = &o->peers[p];
        bench_measure(team, 1, job, o->samples, o->runs, rate, r);
    }
    job->peer = NULL;
    /* The per-point and grid rows call the public entry points, which run at the
     * active ISA (bgt_bench_run forced it to o->isa when one was asked for). */
    int active = (int)bg_isa_active();
    for (int k = 0; k < K_COUNT; k++) {
        if (!sel->ours[k])
            continue;
        if (bench_is_mesh(k)) {
            bg_status s = run_mesh_row(o, k, team, job, rate, res, e);
            if (s != BG_OK)
                return s;
            continue;
        }
        for (int isa = 0; isa < BG_ISA_COUNT; isa++) {
            if (!isa_on[isa] || (bench_at_active_isa(k) && isa != active))
                continue;
            job->t = bg_kernels_for((bg_isa)isa);
            job->kernel = k;
            for (int pass = 0; pass < (nthreads > 1 ? 2 : 1); pass++) {
                bgt_bench_row *r = new_row(res, bg_isa_name((bg_isa)isa), k, -1);
                snprintf(r->name, sizeof r->name, "%s", bgt_bench_kernel_name((size_t)k));
                announce(o, r, pass ? nthreads : 1);
                bench_measure(team, pass ? nthreads : 1, job, o->samples, o->runs, rate, r);
            }
        }
    }
    return BG_OK;
}

static void init_job(bench_job *job, const bench_data *d)
{
    memset(job, 0, sizeof *job);
    job->d = d;
    job->fbm = bg_fractal_default(BG_FUNC_FBM);
    job->turb = bg_fractal_default(BG_FUNC_TURBULENCE);
    job->height = bg_height_default();
    job->height.step = BG_DEFAULT_CENTRAL_STEP;
    job->step = BG_DEFAULT_CENTRAL_STEP;
}

bg_status bgt_bench_run(const bgt_bench_opts *o, bgt_bench_result *res, bgt_err *e)
{
    if (!o || !res)
        return bgt_fail(e, BG_ERR_NULL_POINTER, "bgt_bench_run: NULL options or result");
    memset(res, 0, sizeof *res);
    int isa_on[BG_ISA_COUNT];
    bench_sel sel;
    bg_status s = check_opts(o, e);
    if (s == BG_OK)
        s = select_isas(o->isa, isa_on, e);
    if (s == BG_OK)
        s = bench_select(o->kernels ? o->kernels : "all", o->peers, o->npeers, &sel, e);
    if (s != BG_OK)
        return s;

    size_t nrows_max = (size_t)K_COUNT * BG_ISA_COUNT * 2 + o->npeers;
    res->rows = calloc(nrows_max, sizeof *res->rows);
    double *rate = calloc(2 * (size_t)o->runs, sizeof *rate);
    bench_data d;
    /* The point arrays only when a point row is selected (the mesh rows make
     * their own input). */
    size_t points = 1;
    for (int k = 0; k < K_COUNT; k++)
        if (sel.ours[k] && !bench_is_mesh(k))
            points = o->samples;
    for (size_t p = 0; p < o->npeers && p < BGT_BENCH_MAX_PEERS; p++)
        if (sel.peers[p])
            points = o->samples;
    if (!res->rows || !rate || bench_data_init(&d, points) != 0) {
        free(rate);
        bgt_bench_result_free(res);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for %zu samples", o->samples);
    }
    bench_team *team = bench_team_start(o->threads);
    if (!team) {
        bench_data_free(&d);
        free(rate);
        bgt_bench_result_free(res);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "cannot start %d threads", o->threads);
    }
    res->samples = o->samples;
    res->runs = o->runs;
    res->threads = bench_team_threads(team);
    res->load_before = bench_load_average();
    bench_job job;
    init_job(&job, &d);
    /* --isa for the public-call rows: the active level, for the run only. */
    bg_isa was = bg_isa_active();
    if (o->isa >= 0 && o->isa != (int)was)
        s = bg_isa_force((bg_isa)o->isa);
    bg_status rows = BG_OK;
    if (s == BG_OK)
        rows = run_rows(o, &sel, isa_on, team, &job, rate, res, e);
    if (bg_isa_active() != was)
        (void)bg_isa_force(was);
    bench_team_stop(team);
    res->load_after = bench_load_average();
    bench_data_free(&d);
    free(rate);
    if (rows != BG_OK) {
        bgt_bench_result_free(res);
        return rows;
    }
    if (s != BG_OK) {
        bgt_bench_result_free(res);
        return bgt_fail(e, s, "--isa %s: cannot make it the active level here",
                        bg_isa_name((bg_isa)o->isa));
    }
    if (o->icount_path && (s = bench_read_icounts(o->icount_path, res->rows, res->nrows, e))) {
        bgt_bench_result_free(res);
        return s;
    }
    bench_derive(res->rows, res->nrows);
    return BG_OK;
}

void bgt_bench_result_free(bgt_bench_result *res)
{
    if (!res)
        return;
    free(res->rows);
    memset(res, 0, sizeof *res);
}
