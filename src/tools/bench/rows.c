/* SPDX-License-Identifier: MIT */
/* What `bumpgrad bench` measures: the kernel table, the loop of one row's job,
 * the --kernels selection and the ratios derived from the rows. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench/bench_internal.h"

typedef struct kernel_info {
    const char *name;
    int peer_op; /* bgt_bench_peer_op of the comparable peer operation, -1 if none */
} kernel_info;

/* Comparable peer operation: the peers have no analytic gradient, so our value +
 * gradient kernels are set against their value + 7-evaluation gradient; our
 * fractal kernels, which also return a gradient, against their fBm value alone
 * (so that ratio understates ours). */
static const kernel_info kernels[K_COUNT] = {
    {"noise3", BGT_PEER_VALUE},             /* improved noise value */
    {"noise3_grad", BGT_PEER_GRAD_CENTRAL}, /* value + analytic gradient */
    {"fbm3_grad", BGT_PEER_FBM},            /* 6-octave fBm + analytic gradient */
    {"turbulence3_grad", BGT_PEER_FBM},     /* 6-octave turbulence + analytic gradient */
    {"turbulence3_grad_central", -1},       /* + central gradient (7 evaluations) */
    {"perturb_surfgrad", -1},               /* normalize(n - (g - n(n.g))), Listing 3, SoA */
    {"perturb_additive", -1},               /* normalize(n - g), SoA */
    {"perturb_height", -1},                 /* fused turbulence gradient -> surfgrad normal */
    {"fbm3", BGT_PEER_FBM},                 /* 6-octave fBm value */
    {"noise3_point", BGT_PEER_VALUE},       /* bg_noise3, one call per point */
    {"noise3_grad_point", BGT_PEER_GRAD_CENTRAL},
    {"fbm3_point", BGT_PEER_FBM},           /* bg_fractal3 6-octave fBm per point */
    {"fbm3_grad_point", BGT_PEER_FBM},
    {"noise3_batch1_point", BGT_PEER_VALUE}, /* bg_noise3_batch with n = 1, per point */
    {"noise3_n1", BGT_PEER_VALUE},          /* noise3 batch calls of 1 point */
    {"noise3_n4", BGT_PEER_VALUE},
    {"noise3_n8", BGT_PEER_VALUE},
    {"noise3_n16", BGT_PEER_VALUE},
    {"noise3_n64", BGT_PEER_VALUE},
    {"noise3_n256", BGT_PEER_VALUE},
    {"noise3_grid", BGT_PEER_VALUE},        /* bg_noise3_grid on the bench lattice */
    {"fbm3_grid", BGT_PEER_FBM},            /* bg_fractal3_grid, 6-octave fBm */
    {"fbm3_grad_grid", BGT_PEER_FBM},       /* bg_fractal3_grad_grid */
    {"stream3", -1},                        /* v = x + y + z: noise3's memory traffic */
    {"pnoise3", BGT_PEER_VALUE},            /* periodic noise, periods (16, 16, 16) */
    {"pnoise3_grad", BGT_PEER_GRAD_CENTRAL}, /* + analytic gradient */
    {"pfbm3", BGT_PEER_FBM},                /* periodic 6-octave fBm value */
    {"pfbm3_grad", BGT_PEER_FBM},           /* + analytic gradient */
    {"fbm3_seed_grad", BGT_PEER_FBM},       /* 6-octave fBm, seed 1, + analytic gradient */
    {"pfbm3_grad_xy", BGT_PEER_FBM},        /* pfbm3_grad with periods (16, 16, 0) */
    {"pfbm3_grad_p10", BGT_PEER_FBM},       /* pfbm3_grad with periods (10, 10, 10) */
    {"fbm3_grad_l3", BGT_PEER_FBM},         /* fbm3_grad with lacunarity 3 */
    {"pfbm3_grad_l3", BGT_PEER_FBM},        /* ... and periods (10, 10, 10) */
    {"mikktspace", -1},                     /* mikkTSpace tangents: triangles/s */
    {"mesh_bake", -1},                      /* the whole normal-map bake: texels/s */
};

/* The domains of the rows above. */
static const bg_domain bench_tiled = {{16, 16, 16}, 0}, bench_seeded = {{0, 0, 0}, 1},
                       bench_tiled_xy = {{16, 16, 0}, 0}, bench_tiled_10 = {{10, 10, 10}, 0};
static const bg_fractal bench_noise = {BG_FUNC_NOISE, 1, 2.0f, 0.5f},
                        bench_fbm_l3 = {BG_FUNC_FBM, BG_DEFAULT_OCTAVES, 3.0f, 0.5f};

const char *const bgt_bench_peer_op_names[BGT_PEER_OP_COUNT] = {"value", "fbm", "grad_central"};
const char *const bgt_bench_peer_libraries[3] = {"stb_perlin", "libnoise", "glm"};

size_t bgt_bench_kernel_count(void) { return K_COUNT; }
const char *bgt_bench_kernel_name(size_t k) { return k < K_COUNT ? kernels[k].name : NULL; }
int bench_peer_op_of(int k) { return k >= 0 && k < K_COUNT ? kernels[k].peer_op : -1; }
int bench_is_point(int k) { return k >= K_NOISE3_POINT && k <= K_NOISE3_BATCH1_POINT; }
static int is_grid(int k) { return k >= K_NOISE3_GRID && k <= K_FBM3_GRAD_GRID; }
int bench_is_mesh(int k) { return k == K_MIKK || k == K_MESH_BAKE; }
int bench_at_active_isa(int k)
{
    return bench_is_point(k) || is_grid(k) || k == K_STREAM3 || bench_is_mesh(k);
}

/* Points per call of the K_NOISE3_N* rows. */
static size_t chunk_of(int k)
{
    static const size_t c[] = {1, 4, 8, 16, 64, 256};
    return k >= K_NOISE3_N1 && k <= K_NOISE3_N256 ? c[k - K_NOISE3_N1] : 0;
}

/* One call per point of the public single-point functions (at the active ISA). */
static void run_points(const bench_job *j, size_t b, size_t e)
{
    const bench_data *d = j->d;
    bg_vec3 g;
    for (size_t i = b; i < e; i++) {
        switch (j->kernel) {
        case K_NOISE3_POINT: d->v[i] = bg_noise3(d->px[i], d->py[i], d->pz[i]); continue;
        case K_FBM3_POINT: d->v[i] = bg_fractal3(&j->fbm, d->px[i], d->py[i], d->pz[i]); continue;
        case K_NOISE3_BATCH1_POINT:
            (void)bg_noise3_batch(d->px + i, d->py + i, d->pz + i, 1, d->v + i);
            continue;
        case K_NOISE3_GRAD_POINT: d->v[i] = bg_noise3_grad(d->px[i], d->py[i], d->pz[i], &g); break;
        default: d->v[i] = bg_fractal3_grad(&j->fbm, d->px[i], d->py[i], d->pz[i], &g); break;
        }
        d->ox[i] = g.x, d->oy[i] = g.y, d->oz[i] = g.z;
    }
}

/* The grid rows' lattice (bench_internal.h): sample index i is (i % side,
 * i / side % side, i / side^2), the grid calls' storage order, so the points
 * [b, e) of a thread are at most five sub-grids (a partial row, whole rows,
 * whole slices, whole rows, a partial row) whose outputs are d->v + b onwards
 * in order. The random px/py/pz do not apply. */
static void run_grid(const bench_job *j, size_t b, size_t e)
{
    const bench_data *d = j->d;
    const size_t side = BENCH_GRID_SIDE, plane = side * side;
    while (b < e) {
        size_t at[3] = {b % side, b / side % side, b / plane}, left = e - b;
        bg_grid3 g = {.count = {side, 1, 1}};
        if (at[0] || left < side)
            g.count[0] = left < side - at[0] ? left : side - at[0];
        else if (at[1] || left < plane)
            g.count[1] = left / side < side - at[1] ? left / side : side - at[1];
        else
            g.count[1] = side, g.count[2] = left / plane;
        for (int a = 0; a < 3; a++) {
            g.origin[a] = BENCH_GRID_ORIGIN + (double)at[a] * BENCH_GRID_STEP;
            g.step[a] = BENCH_GRID_STEP;
        }
        /* A valid grid and descriptor: the status is always BG_OK. */
        if (j->kernel == K_NOISE3_GRID)
            (void)bg_noise3_grid(&g, d->v + b);
        else if (j->kernel == K_FBM3_GRID)
            (void)bg_fractal3_grid(&j->fbm, &g, d->v + b);
        else
            (void)bg_fractal3_grad_grid(&j->fbm, &g, d->v + b, d->ox + b, d->oy + b, d->oz + b);
        b += g.count[0] * g.count[1] * g.count[2];
    }
}

void bench_job_run(const bench_job *j, size_t b, size_t e)
{
    const bench_data *d = j->d;
    size_t n = e - b;
    if (n == 0)
        return;
    if (bench_is_mesh(j->kernel)) {
        bench_mesh_run(j);
        return;
    }
    if (j->peer) {
        j->peer->run(d->px + b, d->py + b, d->pz + b, n, d->v + b, d->ox + b, d->oy + b, d->oz + b);
        return;
    }
    if (bench_is_point(j->kernel)) {
        run_points(j, b, e);
        return;
    }
    if (is_grid(j->kernel)) {
        run_grid(j, b, e);
        return;
    }
    if (j->kernel == K_STREAM3) {
        /* What the noise3 row moves (3 loads, 1 store per sample) with no
         * work: the floor its time per sample cannot go below at this size. */
        for (size_t i = b; i < e; i++)
            d->v[i] = d->px[i] + d->py[i] + d->pz[i];
        return;
    }
    const bg_kernel_table *t = j->t;
    size_t chunk = chunk_of(j->kernel);
    if (chunk) {
        for (size_t i = b; i < e; i += chunk)
            t->noise3(d->px + i, d->py + i, d->pz + i, e - i < chunk ? e - i : chunk, d->v + i);
        return;
    }
    const float *px = d->px + b, *py = d->py + b, *pz = d->pz + b;
    float *v = d->v + b, *ox = d->ox + b, *oy = d->oy + b, *oz = d->oz + b;
    switch (j->kernel) {
    case K_FBM3: t->fractal3(&j->fbm, px, py, pz, n, v); break;
    case K_NOISE3: t->noise3(px, py, pz, n, v); break;
    case K_NOISE3_GRAD: t->noise3_grad(px, py, pz, n, v, ox, oy, oz); break;
    case K_FBM3_GRAD:
    case K_TURB3_GRAD:
        t->fractal3_grad(j->kernel == K_FBM3_GRAD ? &j->fbm : &j->turb, px, py, pz, n, v, ox, oy,
                         oz);
        break;
    case K_TURB3_GRAD_CENTRAL:
        t->fractal3_grad_central(&j->turb, j->step, px, py, pz, n, v, ox, oy, oz);
        break;
    case K_PERTURB_SURFGRAD:
    case K_PERTURB_ADDITIVE:
        t->perturb(j->kernel == K_PERTURB_SURFGRAD ? BG_PERTURB_SURFGRAD : BG_PERTURB_ADDITIVE,
                   d->nx + b, d->ny + b, d->nz + b, d->gx + b, d->gy + b, d->gz + b, n, ox, oy, oz);
        break;
    case K_PNOISE3: t->dfractal3(&bench_noise, &bench_tiled, px, py, pz, n, v); break;
    case K_PNOISE3_GRAD:
        t->dfractal3_grad(&bench_noise, &bench_tiled, px, py, pz, n, v, ox, oy, oz);
        break;
    case K_PFBM3: t->dfractal3(&j->fbm, &bench_tiled, px, py, pz, n, v); break;
    case K_PFBM3_GRAD: t->dfractal3_grad(&j->fbm, &bench_tiled, px, py, pz, n, v, ox, oy, oz); break;
    case K_SFBM3_GRAD: t->dfractal3_grad(&j->fbm, &bench_seeded, px, py, pz, n, v, ox, oy, oz); break;
    case K_PFBM3_GRAD_XY:
    case K_PFBM3_GRAD_P10:
        t->dfractal3_grad(&j->fbm, j->kernel == K_PFBM3_GRAD_XY ? &bench_tiled_xy : &bench_tiled_10,
                          px, py, pz, n, v, ox, oy, oz);
        break;
    case K_FBM3_GRAD_L3: t->fractal3_grad(&bench_fbm_l3, px, py, pz, n, v, ox, oy, oz); break;
    case K_PFBM3_GRAD_L3:
        t->dfractal3_grad(&bench_fbm_l3, &bench_tiled_10, px, py, pz, n, v, ox, oy, oz);
        break;
    case K_PERTURB_HEIGHT:
        t->perturb_height(&j->height, BG_PERTURB_SURFGRAD, px, py, pz, d->nx + b, d->ny + b,
                          d->nz + b, n, v, ox, oy, oz);
        break;
    default: break;
    }
}

/* ---- selection: --kernels ---- */

/* "peer:<library>" or "peer:<library>:<op>" naming a library the bench knows
 * but that is not built in: not an error (the result's note says why it is
 * missing); a misspelt library or operation is. */
static int known_peer_token(const char *tok)
{
    for (size_t k = 0; k < 3; k++) {
        const char *lib = bgt_bench_peer_libraries[k];
        size_t len = strlen(lib);
        if (strncmp(tok, "peer:", 5) != 0 || strncmp(tok + 5, lib, len) != 0)
            continue;
        const char *rest = tok + 5 + len;
        if (rest[0] == '\0')
            return 1;
        for (size_t op = 0; rest[0] == ':' && op < BGT_PEER_OP_COUNT; op++)
            if (strcmp(rest + 1, bgt_bench_peer_op_names[op]) == 0)
                return 1;
    }
    return 0;
}

static int select_token(const char *tok, bench_sel *sel, const bgt_bench_peer *peers,
                        size_t npeers)
{
    int hit = 0;
    int all = strcmp(tok, "all") == 0;
    for (int k = 0; k < K_COUNT; k++)
        if (((all || strcmp(tok, "ours") == 0) && !bench_is_mesh(k)) ||
            strcmp(tok, kernels[k].name) == 0 || (strcmp(tok, "mesh") == 0 && bench_is_mesh(k)))
            sel->ours[k] = hit = 1;
    int all_peers = all || strcmp(tok, "peers") == 0;
    hit |= all_peers;
    for (size_t p = 0; p < npeers && p < BGT_BENCH_MAX_PEERS; p++) {
        char full[64];
        const char *op = bgt_bench_peer_op_names[peers[p].op];
        snprintf(full, sizeof full, "peer:%s:%s", peers[p].library, op);
        size_t len = strlen(full) - strlen(op) - 1;
        if (all_peers || strcmp(tok, full) == 0 ||
            (strncmp(tok, full, len) == 0 && tok[len] == '\0'))
            sel->peers[p] = hit = 1;
    }
    return hit || known_peer_token(tok);
}

bg_status bench_select(const char *list, const bgt_bench_peer *peers, size_t npeers,
                       bench_sel *sel, bgt_err *e)
{
    memset(sel, 0, sizeof *sel);
    char *copy = malloc(strlen(list) + 1);
    if (!copy)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    strcpy(copy, list);
    bg_status s = BG_OK;
    int tokens = 0;
    char *save = NULL;
    for (char *tok = strtok_r(copy, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        tokens++;
        if (!select_token(tok, sel, peers, npeers)) {
            s = bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                         "--kernels: unknown kernel '%s' (see bumpgrad bench --help)", tok);
            break;
        }
    }
    /* "" or "," would run nothing and still succeed, like a passing benchmark. */
    if (s == BG_OK && tokens == 0)
        s = bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                     "--kernels: empty list \"%s\" (see bumpgrad bench --help)", list);
    free(copy);
    return s;
}

/* ---- derived ratios ---- */

static const bgt_bench_row *find_row(const bgt_bench_row *rows, size_t nrows, const char *name,
                                     const char *isa, int threads)
{
    for (size_t i = 0; i < nrows; i++)
        if (strcmp(rows[i].name, name) == 0 && strcmp(rows[i].isa, isa) == 0 &&
            rows[i].threads == threads)
            return &rows[i];
    return NULL;
}

static const bgt_bench_row *best_peer(const bgt_bench_row *rows, size_t nrows, int op)
{
    const bgt_bench_row *best = NULL;
    for (size_t i = 0; i < nrows; i++)
        if (rows[i].kernel < 0 && rows[i].peer_op == op && (!best || rows[i].median > best->median))
            best = &rows[i];
    return best;
}

void bench_derive(bgt_bench_row *rows, size_t nrows)
{
    for (size_t i = 0; i < nrows; i++) {
        bgt_bench_row *r = &rows[i];
        r->speedup = r->scaling = r->vs_peer = 0;
        r->best_peer = NULL;
        if (r->kernel < 0)
            continue;
        const bgt_bench_row *s = find_row(rows, nrows, r->name, "scalar", r->threads);
        if (s && s->median > 0)
            r->speedup = r->median / s->median;
        if (r->threads > 1) {
            const bgt_bench_row *one = find_row(rows, nrows, r->name, r->isa, 1);
            if (one && one->median > 0)
                r->scaling = r->median / one->median;
        }
        int op = bench_peer_op_of(r->kernel);
        /* Peers run on one thread, so only one-thread rows are set against them. */
        const bgt_bench_row *p = op >= 0 && r->threads == 1 ? best_peer(rows, nrows, op) : NULL;
        if (p && p->median > 0) {
            r->vs_peer = r->median / p->median;
            r->best_peer = p->name;
        }
    }
}

/* "<kernel> <isa> <instructions per sample>" per line; rows not listed keep 0. */
bg_status bench_read_icounts(const char *path, bgt_bench_row *rows, size_t nrows, bgt_err *e)
{
    FILE *fp = fopen(path, "r");
    if (!fp)
        return bgt_fail(e, BG_ERR_IO, "--icount %s: cannot read it", path);
    char name[64], isa[32];
    double v;
    while (fscanf(fp, "%63s %31s %lf", name, isa, &v) == 3)
        for (size_t i = 0; i < nrows; i++)
            if (strcmp(rows[i].name, name) == 0 && strcmp(rows[i].isa, isa) == 0)
                rows[i].icount = v;
    int bad = ferror(fp) || !feof(fp);
    fclose(fp);
    return bad ? bgt_fail(e, BG_ERR_IO, "--icount %s: cannot read it", path) : BG_OK;
}
