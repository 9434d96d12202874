/* SPDX-License-Identifier: MIT */
/* `bumpgrad bench`: throughput of every batch kernel on every ISA this machine
 * has, with one thread and with N threads, next to peer noise libraries measured
 * in the same run (docs/PERFORMANCE.md explains the method and keeps the
 * numbers). The measuring is bgt_bench_run (src/tools/bench); this file parses,
 * calls and prints the rows as a table or as JSON. A benchmark only: it checks
 * nothing and its exit status says only whether it could run. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "args.h"
#include "bench/bench.h"
#include "cli.h"
#include "kernels/kernels.h" /* bg_isa_list */

static const char *const CMD = "bench";
#define BENCH_DEFAULT_SAMPLES ((size_t)1 << 22)
#define BENCH_QUICK_SAMPLES ((size_t)1 << 18)
/* Median of an odd count, and at least 5 runs by default, so that one
 * preempted run on a shared machine moves neither the median nor the verdict. */
#define BENCH_DEFAULT_RUNS 7
#define BENCH_QUICK_RUNS 5

typedef struct bench_args {
    int json, quick, threads, samples, runs, isa;
    const char *kernels, *icount;
} bench_args;

static void bench_defaults(void *p)
{
    bench_args *a = p;
    memset(a, 0, sizeof *a);
    a->isa = -1;
    a->kernels = "all";
}

static int parse_isa(const char *cmd, const char *opt, char *text, void *field)
{
    bg_isa want;
    if (bg_isa_parse(text, &want) != BG_OK) {
        char all[96];
        bg_isa_list(all, sizeof all, 0);
        return cli_usage_error(cmd, "%s: unknown ISA '%s' (%s)", opt, text, all);
    }
    *(int *)field = (int)want;
    return 0;
}

static int format_none(const void *field, char *buf, size_t len)
{
    (void)field, (void)buf, (void)len;
    return 0;
}

#define A(m) offsetof(bench_args, m)
static const cli_opt bench_opts[] = {
    {.name = "json", .kind = CLI_KIND_FLAG, .offset = A(json),
     .help = "one JSON array on stdout, one record per line, with the keys kernel, isa, threads, "
             "samples, runs, msamples_per_s (median), ns_per_sample, min, max (M samples/s), "
             "cpu_share, cpu_ns_per_sample (median CPU time of a run per sample, all threads: "
             "the load-robust figure on a shared machine), speedup_vs_scalar, thread_scaling, "
             "vs_best_peer, best_peer, "
             "instructions_per_sample (null when n/a); peers have isa \"baseline\" (the build's "
             "default target)"},
    {.name = "threads", .kind = CLI_KIND_INT, .offset = A(threads), .metavar = "N",
     .help = "also measure with N threads (default: all cores; 1: one thread only)", .lo = 1,
     .hi = 1024, .flags = CLI_ZERO_NONE},
    {.name = "isa", .kind = CLI_KIND_CUSTOM, .offset = A(isa), .metavar = "ISA",
     .help = "only this ISA: scalar, sse2, avx2, avx512, neon (default: all present, up to the "
             "cap of bumpgrad --isa or BUMPGRAD_ISA)",
     .parse = parse_isa, .format = format_none},
    {.name = "samples", .kind = CLI_KIND_INT, .offset = A(samples), .metavar = "N",
     .help = "points per run (default 4194304 = 2^22; --quick 262144)", .lo = 1, .hi = 1L << 28,
     .flags = CLI_ZERO_NONE},
    {.name = "runs", .kind = CLI_KIND_INT, .offset = A(runs), .metavar = "R",
     .help = "timed runs per row (default 7; --quick 5)", .lo = 1, .hi = BGT_BENCH_MAX_RUNS,
     .flags = CLI_ZERO_NONE},
    {.name = "kernels", .kind = CLI_KIND_STRING, .offset = A(kernels), .metavar = "LIST",
     .help = "comma-separated subset: noise3, noise3_grad, fbm3_grad, turbulence3_grad, "
             "turbulence3_grad_central, perturb_surfgrad, perturb_additive, perturb_height, "
             "fbm3, noise3_point, noise3_grad_point, fbm3_point, fbm3_grad_point, "
             "noise3_batch1_point (per-point calls, the last one bg_noise3_batch with n = 1, at "
             "the active ISA or --isa), noise3_n1, noise3_n4, noise3_n8, noise3_n16, "
             "noise3_n64, noise3_n256 (kernel-table batch calls of that many points on every "
             "ISA), noise3_grid, "
             "fbm3_grid, fbm3_grad_grid (grid calls on a 128 x 128 x k lattice of the same "
             "sample count, step 1/8, at the active ISA or --isa), stream3 (v = x + y + z over "
             "the same arrays: the memory traffic of the noise3 row with no work, its floor), "
             "pnoise3, pnoise3_grad, pfbm3, pfbm3_grad (tileable noise and 6-octave fBm, "
             "periods 16,16,16), fbm3_seed_grad (fBm with seed 1), pfbm3_grad_xy (periods "
             "16,16,0), pfbm3_grad_p10 (periods 10,10,10, not a power of two), fbm3_grad_l3 "
             "and pfbm3_grad_l3 (lacunarity 3, plain and with periods 10,10,10), "
             "ours (all of the above), peers, peer:<library>, "
             "peer:<library>:<value|fbm|grad_central> (libraries: stb_perlin, libnoise, glm); "
             "only when named: mikktspace (mikkTSpace tangents of a 1,002,528-triangle UV "
             "sphere, samples = triangles), mesh_bake (the whole tangent-space normal-map "
             "bake of a 131,072-triangle UV sphere into 1024 x 1024, samples = texels), mesh "
             "(both); their sizes are fixed (--samples does not apply)"},
    {.name = "icount", .kind = CLI_KIND_STRING, .offset = A(icount), .metavar = "FILE",
     .help = "instructions per sample to put in the JSON, lines of \"<kernel> <isa> "
             "<instructions>\" (scripts/kernel_icount.sh --bench)",
     .flags = CLI_FILE},
    {.name = "quick", .kind = CLI_KIND_FLAG, .offset = A(quick),
     .help = "2^18 points and 5 runs (the meson benchmark); a full run with the defaults takes "
             "minutes, mostly in the scalar rows"},
    CLI_OPT_END,
};
#undef A

CLI_SPEC(bench,
    .summary = "throughput of every kernel and ISA, 1 and N threads, against peer libraries",
    .usage = "[--json] [--threads N] [--isa ISA] [--samples N] [--runs R] [--kernels LIST] "
             "[--icount FILE] [--quick]",
    .about = "Throughput (M samples/s) of every batch kernel on every ISA this machine has,\n"
             "with one thread and with N threads splitting the batch, and of peer noise\n"
             "libraries (one thread) measured in the same run. Inputs: N random points\n"
             "uniform in [-64,64]^3 with a fixed seed, random unit normals and gradients.\n"
             "Each row is timed R times after a warm-up; the median, min and max are shown.\n"
             "A benchmark: it never fails on slow numbers. See docs/PERFORMANCE.md.\n",
    .opts = bench_opts,
);

static void json_number(FILE *fp, const char *key, double v)
{
    if (v > 0)
        fprintf(fp, ", \"%s\": %.6g", key, v);
    else
        fprintf(fp, ", \"%s\": null", key);
}

/* One JSON array, one record per line (names contain no characters to escape). */
static void print_json(FILE *fp, const bgt_bench_result *res)
{
    fputs("[\n", fp);
    for (size_t i = 0; i < res->nrows; i++) {
        const bgt_bench_row *r = &res->rows[i];
        fprintf(fp,
                "  {\"kernel\": \"%s\", \"isa\": \"%s\", \"threads\": %d, \"samples\": %zu, "
                "\"runs\": %d, \"msamples_per_s\": %.6g, \"ns_per_sample\": %.6g, "
                "\"min\": %.6g, \"max\": %.6g",
                r->name, r->isa, r->threads, r->samples ? r->samples : res->samples, res->runs,
                r->median,
                r->median > 0 ? 1e3 / r->median : 0.0, r->min, r->max);
        json_number(fp, "cpu_share", r->cpu_share);
        json_number(fp, "cpu_ns_per_sample", r->cpu_ns);
        json_number(fp, "speedup_vs_scalar", r->speedup);
        json_number(fp, "thread_scaling", r->scaling);
        json_number(fp, "vs_best_peer", r->vs_peer);
        json_number(fp, "instructions_per_sample", r->icount);
        if (r->best_peer)
            fprintf(fp, ", \"best_peer\": \"%s\"", r->best_peer);
        else
            fputs(", \"best_peer\": null", fp);
        fprintf(fp, "}%s\n", i + 1 < res->nrows ? "," : "");
    }
    fputs("]\n", fp);
}

static void print_rows(FILE *fp, const bgt_bench_result *res)
{
    fprintf(fp, "%-30s %-8s %3s %9s %9s %9s  %4s %8s %7s %6s  %s\n", "kernel", "isa", "thr",
            "median", "min", "max", "cpu%", "ns/smp", "x scal", "x thr", "vs best peer");
    int noisy = 0;
    for (size_t i = 0; i < res->nrows; i++) {
        const bgt_bench_row *r = &res->rows[i];
        char sp[16] = "-", sc[16] = "-", vp[96] = "";
        if (r->speedup > 0)
            snprintf(sp, sizeof sp, "%.2f", r->speedup);
        if (r->scaling > 0)
            snprintf(sc, sizeof sc, "%.2f", r->scaling);
        if (r->vs_peer > 0)
            snprintf(vp, sizeof vp, "%.2fx %s", r->vs_peer, r->best_peer);
        /* A spread above 10% of the median flags a row disturbed by other load. */
        int flag = r->median > 0 && (r->max - r->min) > 0.10 * r->median;
        noisy |= flag;
        /* cpu% is capped at 100 for display: thread start-up can tip it a hair over. */
        double share = r->cpu_share > 1.0 ? 1.0 : r->cpu_share;
        fprintf(fp, "%-30s %-8s %3d %9.2f %9.2f %9.2f%c %4.0f %8.2f %7s %6s  %s\n", r->name, r->isa,
                r->threads, r->median, r->min, r->max, flag ? '~' : ' ', 100.0 * share,
                r->median > 0 ? 1e3 / r->median : 0.0, sp, sc, vp);
    }
    fputs(
        "\nM samples/s: median, min and max over the runs; ns/smp = 1000 / median (wall time,\n"
        "all threads); x scal = median / scalar median (same kernel, threads); x thr = median /\n"
        "one-thread median (same kernel, ISA); vs best peer: one-thread median over the fastest\n"
        "peer of the comparable operation (noise3: value; noise3_grad: grad_central;\n"
        "fbm3_grad and turbulence3_grad: fbm value, without a gradient). cpu% = CPU time the\n"
        "process got / (wall time x threads): well below 100 means other jobs shared the cores.\n",
        fp);
    for (size_t i = 0; i < res->nrows; i++)
        if (res->rows[i].samples) {
            fputs("mikktspace: M triangles/s of a 1,002,528-triangle UV sphere; mesh_bake: M\n"
                  "texels/s of the whole 1024 x 1024 tangent-space bake (one call per run).\n",
                  fp);
            break;
        }
    if (noisy)
        fputs(
            "~ : max - min above 10% of the median: the machine was busy, rerun on a quiet one.\n",
            fp);
}

static void print_header(const bgt_bench_result *res)
{
    char isas[64] = "";
    for (int k = 0; k < BG_ISA_COUNT; k++)
        if (bg_isa_supported((bg_isa)k)) {
            strcat(isas, " ");
            strcat(isas, bg_isa_name((bg_isa)k));
        }
    printf("bumpgrad %s bench: %zu points in [-64,64]^3 (fixed seed), %d runs per row,\n"
           "threads 1 and %d, ISAs on this machine:%s; central step %g; cores online %ld\n",
           bg_version_string(), res->samples, res->runs, res->threads, isas,
           (double)BG_DEFAULT_CENTRAL_STEP, sysconf(_SC_NPROCESSORS_ONLN));
    if (res->load_before >= 0)
        printf("load average (1 min) %.2f before, %.2f after the run\n", res->load_before,
               res->load_after);
    putchar('\n');
}

/* The header, the table of rows and the peers left out. */
static void print_text(const bgt_bench_result *res, const char *missing)
{
    print_header(res);
    print_rows(stdout, res);
    if (missing)
        printf("note: peers not built in (library or C++ compiler absent at configure "
               "time):%s\n",
               missing);
}

/* Progress goes to stderr, so it never mixes into the table or the JSON. */
static void on_measuring(void *ctx, const bgt_bench_row *r)
{
    (void)ctx;
    if (r->kernel < 0)
        fprintf(stderr, "\rmeasuring %-40s", r->name);
    else
        fprintf(stderr, "\rmeasuring %-24s %-8s %3d thr", r->name, r->isa, r->threads);
}

/* The command once parsed (cli_run_command has parsed argv into bench_args). */
static int run_bench(void *args, const char *const *pos, int npos)
{
    (void)pos, (void)npos;
    const bench_args *ap = args;
    bench_args a = *ap;
    bgt_bench_peer peers[BGT_BENCH_MAX_PEERS];
    const char *missing;
    int show = isatty(fileno(stderr));
    bgt_bench_opts o = {
        .samples = a.samples > 0 ? (size_t)a.samples
                   : a.quick     ? BENCH_QUICK_SAMPLES
                                 : BENCH_DEFAULT_SAMPLES,
        .runs = a.runs > 0 ? a.runs : a.quick ? BENCH_QUICK_RUNS : BENCH_DEFAULT_RUNS,
        .threads = a.threads > 0 ? a.threads : bgt_threads_default(),
        .isa = a.isa,
        .kernels = a.kernels,
        .icount_path = a.icount,
        .peers = peers,
        .npeers = bgt_bench_peers_builtin(peers, BGT_BENCH_MAX_PEERS, &missing),
        .measuring = show ? on_measuring : NULL,
    };
    if (o.threads < 1)
        o.threads = 1;
    bgt_bench_result res;
    bgt_err err;
    bg_status s = bgt_bench_run(&o, &res, &err);
    if (show)
        fprintf(stderr, "\r%70s\r", "");
    if (s != BG_OK)
        return cli_report(CMD, s, &err);
    if (a.json) {
        print_json(stdout, &res);
        if (missing)
            fprintf(stderr, "bumpgrad bench: note: peers not built in:%s\n", missing);
    } else {
        print_text(&res, missing);
    }
    bgt_bench_result_free(&res);
    if (fflush(stdout) != 0 || ferror(stdout))
        return cli_fail(CMD, "cannot write the results: %s", strerror(errno));
    return CLI_OK;
}
