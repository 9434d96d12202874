/* SPDX-License-Identifier: MIT */
/* The engine of `bumpgrad bench` as a tools call: throughput of every batch
 * kernel on every ISA this machine has, with one thread and with N threads,
 * next to peer noise libraries measured in the same run (docs/PERFORMANCE.md).
 * A benchmark only: it checks nothing. It never prints: the rows come back in
 * a bgt_bench_result and the caller formats them (the CLI as a table or JSON).
 *
 * Split by concern: rows.c (what is measured: the kernel table, one job's
 * loop, the --kernels selection, the derived ratios), timer.c (inputs, the
 * thread team, the timed runs), bench.c (the run), peers.c + peer_*.c(c) (the
 * peers, a separate library: see bench/meson.build). */
#ifndef BUMPGRAD_TOOLS_BENCH_BENCH_H
#define BUMPGRAD_TOOLS_BENCH_BENCH_H

#include <stddef.h>
#include "bumpgrad.h"
#include "common/tool.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- peers: other noise libraries, measured on the same points ----
 * The three operations every peer is measured on (the same meaning for all):
 *  value        : one octave of 3-D Perlin noise per point;
 *  fbm          : 6 octaves, lacunarity 2, gain 0.5, first octave at frequency 1;
 *  grad_central : value plus a central-difference gradient with step
 *                 BG_DEFAULT_CENTRAL_STEP, i.e. 7 evaluations of one octave, the
 *                 way a caller without an analytic gradient gets one. */
typedef enum bgt_bench_peer_op {
    BGT_PEER_VALUE = 0,
    BGT_PEER_FBM = 1,
    BGT_PEER_GRAD_CENTRAL = 2,
    BGT_PEER_OP_COUNT = 3
} bgt_bench_peer_op;

/* A batch over SoA points; gx/gy/gz are written only by BGT_PEER_GRAD_CENTRAL.
 * Reentrant (the peers keep no mutable state between calls). */
typedef void (*bgt_bench_peer_fn)(const float *x, const float *y, const float *z, size_t n,
                                  float *v, float *gx, float *gy, float *gz);

typedef struct bgt_bench_peer {
    const char *library; /* "stb_perlin", "libnoise", "glm" */
    bgt_bench_peer_op op;
    bgt_bench_peer_fn run;
} bgt_bench_peer;

enum { BGT_BENCH_MAX_PEERS = 16 };

/* The peers built into this binary (libbumpgrad_bench_peers, peers.c): fills
 * out[0..cap-1], returns the count. *missing (may be NULL) is set to a static
 * text naming the libraries not built in (" stb_perlin (libstb-dev) ..."), or
 * NULL when none is missing. */
size_t bgt_bench_peers_builtin(bgt_bench_peer *out, size_t cap, const char **missing);
/* The names of the peer libraries the bench knows of, built in or not. */
extern const char *const bgt_bench_peer_libraries[3];
extern const char *const bgt_bench_peer_op_names[BGT_PEER_OP_COUNT];

/* ---- what is measured ---- */
/* Our kernel names (rows.c), in the order the rows come out:
 * noise3 noise3_grad fbm3_grad turbulence3_grad turbulence3_grad_central
 * perturb_surfgrad perturb_additive perturb_height fbm3 noise3_point
 * noise3_grad_point fbm3_point fbm3_grad_point noise3_n1 ... noise3_n256
 * noise3_grid fbm3_grid fbm3_grad_grid (a 128 x 128 x k lattice, rows.c) ...
 * mikktspace mesh_bake (whole calls on a generated mesh, selected only by
 * name or "mesh": samples are triangles and texels, mesh_rows.c). */
size_t bgt_bench_kernel_count(void);
const char *bgt_bench_kernel_name(size_t k);

/* One measured row: our kernel on one ISA table, or one peer. */
typedef struct bgt_bench_row {
    char name[64];   /* kernel name, or "peer:<library>:<op>" */
    const char *isa; /* ISA name, or "baseline" for peers (built with the default target) */
    int kernel;      /* index of bgt_bench_kernel_name, or -1 for a peer */
    int peer_op;     /* bgt_bench_peer_op of a peer, -1 for ours */
    int threads;
    size_t samples;          /* per run: the run's samples, or 0 for the result's (the mesh
                              * rows: triangles for mikktspace, texels for mesh_bake) */
    double median, min, max; /* M samples/s over the runs */
    /* CPU time the process got over wall time x threads, summed over the runs:
     * about 1 on a quiet machine, 0.5 when another job took half the cores. The
     * workers of an idle team sleep in the barrier and use none. */
    double cpu_share;
    /* Median over the runs of the process CPU time of one run per sample, in ns
     * (all threads together): what a sample costs in CPU, which, unlike the
     * wall-time median, does not grow when other processes hold the core. */
    double cpu_ns;
    /* Instructions per sample from opts.icount_path (scripts/kernel_icount.sh
     * --bench, callgrind: load-independent), 0 if not given. */
    double icount;
    /* Derived once all rows are measured; 0 (NULL) where not applicable. */
    double speedup;        /* median over the scalar row of the same kernel and threads */
    double scaling;        /* median over the one-thread row of the same kernel and ISA */
    double vs_peer;        /* one-thread median over the fastest comparable peer */
    const char *best_peer; /* that peer's row name (points into the result's rows) */
} bgt_bench_row;

typedef struct bgt_bench_opts {
    size_t samples; /* points per run (> 0) */
    int runs;       /* timed runs per row, 1..BGT_BENCH_MAX_RUNS */
    int threads;    /* the N of the N-thread rows (1: one-thread rows only) */
    /* -1: every ISA this build and CPU have, up to bg_isa_active() (the cap of
     * BUMPGRAD_ISA / bg_isa_force); else only this bg_isa. The per-point and
     * grid rows call the public entry points, which run at the active ISA: they
     * are measured once, at bg_isa_active() for -1, else at this ISA, which the
     * run makes the active level (bg_isa_force) and restores before returning;
     * so no other thread may make batch calls during such a run. */
    int isa;
    /* Comma-separated selection (NULL: "all"): kernel names, "ours", "peers",
     * "peer:<library>", "peer:<library>:<op>". */
    const char *kernels;
    /* "<kernel> <isa> <instructions per sample>" per line, or NULL. */
    const char *icount_path;
    /* The peers to measure (bgt_bench_peers_builtin, or the caller's own). */
    const bgt_bench_peer *peers;
    size_t npeers;
    /* Called from the calling thread before each row is measured (may be NULL):
     * only name, isa and threads of `row` are set then. */
    void (*measuring)(void *ctx, const bgt_bench_row *row);
    void *ctx;
} bgt_bench_opts;

enum { BGT_BENCH_MAX_RUNS = 1000 };

typedef struct bgt_bench_result {
    bgt_bench_row *rows; /* peers first, then ours (kernel, ISA, 1 then N threads) */
    size_t nrows;
    size_t samples;
    int runs, threads;       /* threads: the N actually used */
    double load_before, load_after; /* 1-minute load average, -1 where unknown */
} bgt_bench_result;

/* Measure. BG_ERR_INVALID_ARGUMENT for a bad selection (the message names the
 * token and starts with "--kernels:") or samples over the memory cap
 * (BUMPGRAD_MAX_MB), BG_ERR_UNSUPPORTED_ISA for an ISA absent here,
 * BG_ERR_IO for an unreadable icount file, BG_ERR_OUT_OF_MEMORY when the
 * arrays or the threads cannot be had. On success *res owns its rows
 * (bgt_bench_result_free); on failure it holds none. */
bg_status bgt_bench_run(const bgt_bench_opts *o, bgt_bench_result *res, bgt_err *e);
void bgt_bench_result_free(bgt_bench_result *res);

#ifdef __cplusplus
}
#endif

#endif
