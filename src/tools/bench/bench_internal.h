/* SPDX-License-Identifier: MIT */
/* Inside the bench engine (the face is bench.h): the pieces rows.c, timer.c
 * and bench.c share. */
#ifndef BUMPGRAD_TOOLS_BENCH_INTERNAL_H
#define BUMPGRAD_TOOLS_BENCH_INTERNAL_H

#include <stddef.h>
#include "bench/bench.h"
#include "kernels.h" /* src/kernels: the per-ISA tables (bench/meson.build) */

/* Our kernels, in row order (bgt_bench_kernel_name). */
enum {
    K_NOISE3,
    K_NOISE3_GRAD,
    K_FBM3_GRAD,
    K_TURB3_GRAD,
    K_TURB3_GRAD_CENTRAL,
    K_PERTURB_SURFGRAD,
    K_PERTURB_ADDITIVE,
    K_PERTURB_HEIGHT,
    K_FBM3,
    /* Per-point entry points: public calls, which run at the active ISA (bg_noise3 and
     * bg_noise3_grad on the scalar point code at every ISA, bg_fractal3(_grad) on the
     * active table's point function): measured once, at that ISA (bench.c). */
    K_NOISE3_POINT,
    K_NOISE3_GRAD_POINT,
    K_FBM3_POINT,
    K_FBM3_GRAD_POINT,
    K_NOISE3_BATCH1_POINT, /* bg_noise3_batch(.., 1, ..) per point: the public n = 1 path */
    /* noise3 batch calls of a few points each (the batch kernel on each ISA). */
    K_NOISE3_N1,
    K_NOISE3_N4,
    K_NOISE3_N8,
    K_NOISE3_N16,
    K_NOISE3_N64,
    K_NOISE3_N256,
    /* Grid entry points (bg_noise3_grid, bg_fractal3_grid, bg_fractal3_grad_grid):
     * public calls at the active ISA, measured once like the per-point rows. */
    K_NOISE3_GRID,
    K_FBM3_GRID,
    K_FBM3_GRAD_GRID,
    /* The memory floor of the noise3 row: v = x + y + z over the same arrays
     * (the same 16 bytes per sample), plain C, measured once. */
    K_STREAM3,
    /* Over a domain (noise.h bg_domain), on each ISA's table: periodic noise
     * and 6-octave fBm with periods (16, 16, 16), and fBm with seed 1. */
    K_PNOISE3,
    K_PNOISE3_GRAD,
    K_PFBM3,
    K_PFBM3_GRAD,
    K_SFBM3_GRAD,
    K_PFBM3_GRAD_XY, /* periods (16, 16, 0): a tileable texture's x and y */
    K_PFBM3_GRAD_P10, /* periods (10, 10, 10): not a power of two (the float reduction) */
    K_FBM3_GRAD_L3,   /* plain 6-octave fBm with lacunarity 3 (no domain) */
    K_PFBM3_GRAD_L3,  /* lacunarity 3, periods (10, 10, 10): periods 10 3^i */
    /* The mesh rows (mesh_rows.c): whole calls on a generated mesh, threaded
     * inside, measured once; selected only by name (not by "all" or "ours"). */
    K_MIKK,      /* mikkTSpace tangents: samples are triangles */
    K_MESH_BAKE, /* the whole normal-map bake (tools build): samples are texels */
    K_COUNT
};

/* The input and output arrays, SoA, allocated once for the largest batch. */
enum { BENCH_NARRAYS = 13 };
typedef struct bench_data {
    size_t n;
    float *px, *py, *pz; /* positions */
    float *nx, *ny, *nz; /* unit normals */
    float *gx, *gy, *gz; /* volume gradients fed to the perturb kernels */
    float *v, *ox, *oy, *oz;
    float *arrays[BENCH_NARRAYS];
} bench_data;

/* The input of a mesh row: a UV sphere (SoA attributes px py pz nx ny nz u v,
 * nv floats each) and room for its corner tangents. */
typedef struct bench_mesh {
    int kernel;
    size_t vertex_count, triangle_count;
    float *attr;
    uint32_t *indices;
    float *tangents;
    bg_status status; /* of the last run */
} bench_mesh;
/* mikktspace: a 708 x 708-quad sphere, 1,002,528 triangles; mesh_bake: a
 * 256 x 256-quad sphere (131,072 triangles) baked into a 1024 x 1024 map. */
#define BENCH_MIKK_SIDE 708
#define BENCH_BAKE_SIDE 256
#define BENCH_BAKE_TEXELS 1024

/* One measured row's work: our kernel on one ISA table, or one peer. */
typedef struct bench_job {
    const bench_data *d;
    const bg_kernel_table *t; /* NULL for a peer */
    int kernel;
    const bgt_bench_peer *peer;
    bg_fractal fbm, turb;
    bg_height height;
    float step;
    bench_mesh *mesh; /* a mesh row's input */
    int threads;      /* a mesh row's thread count */
} bench_job;

/* The grid rows' lattice: BENCH_GRID_SIDE x BENCH_GRID_SIDE samples per z
 * slice, as many slices as the samples fill (128 x 128 x 16 for --quick's
 * 2^18, x 256 for 2^22; the last slice partial when the count is not a
 * multiple of 16384), spacing 1/8 on every axis (8 samples per lattice cell
 * along each axis, as in an image or voxel bake), origin off the integer
 * lattice. */
#define BENCH_GRID_SIDE ((size_t)128)
#define BENCH_GRID_STEP 0.125
#define BENCH_GRID_ORIGIN (-7.9765625)

/* rows.c */
/* Run `j` over the points [b, e). */
void bench_job_run(const bench_job *j, size_t b, size_t e);
int bench_is_point(int k);
/* 1 for the rows that go through the public entry points (per-point and grid),
 * which run at the active ISA: measured at one ISA only (bench.c). */
int bench_at_active_isa(int k);
/* 1 for the mesh rows: one whole call per run, threaded inside. */
int bench_is_mesh(int k);
/* bgt_bench_peer_op of the comparable peer operation of kernel k, -1 if none. */
int bench_peer_op_of(int k);
typedef struct bench_sel {
    int ours[K_COUNT];
    int peers[BGT_BENCH_MAX_PEERS];
} bench_sel;
bg_status bench_select(const char *list, const bgt_bench_peer *peers, size_t npeers,
                       bench_sel *sel, bgt_err *e);
/* Fill speedup, scaling, vs_peer, best_peer of every row. */
void bench_derive(bgt_bench_row *rows, size_t nrows);
bg_status bench_read_icounts(const char *path, bgt_bench_row *rows, size_t nrows, bgt_err *e);

/* mesh_rows.c */
/* The samples of a mesh row's run (triangles, texels), and the bytes its
 * input and the call take (about). */
size_t bench_mesh_samples(int kernel);
double bench_mesh_bytes(int kernel);
/* 0, or -1 out of memory (then *bm holds nothing). */
int bench_mesh_init(bench_mesh *bm, int kernel);
void bench_mesh_free(bench_mesh *bm);
void bench_mesh_run(const bench_job *j);

/* timer.c */
int bench_data_init(bench_data *d, size_t n);
void bench_data_free(bench_data *d);
typedef struct bench_team bench_team;
/* NULL when the threads or their memory cannot be had; threads <= 1 runs inline. */
bench_team *bench_team_start(int threads);
int bench_team_threads(const bench_team *t);
void bench_team_stop(bench_team *t);
/* Time `job` over [0, n) `runs` times on `threads` of the team (after a
 * warm-up) into row->median/min/max/cpu_share/cpu_ns/threads; rate has room
 * for 2 x runs. */
void bench_measure(bench_team *team, int threads, const bench_job *job, size_t n, int runs,
                   double *rate, bgt_bench_row *row);
double bench_load_average(void);

#endif
