/* SPDX-License-Identifier: MIT */
/* mikkTSpace per-corner tangents, our implementation of the published
 * description (see mikktspace.h for the rules and their sources). Sums and
 * projections run in double and are rounded to float once at the end.
 *
 * The passes: welding (a hash table in vertex order), the corners of each
 * welded vertex (a counting sort), the triangles (parallel), then per
 * welded vertex in parallel the edge neighbours and the fans with their
 * tangents. Every corner belongs to one vertex and each vertex's work reads
 * only what the earlier passes made, so the result does not depend on the
 * thread count (zero-UV-area triangles, whose orientation depends on the
 * order of the fans, take a serial path). */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE /* MADV_HUGEPAGE */
#include "mesh/mikktspace.h"

#include <float.h>
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include "common/parallel.h"
#include "mesh/mesh_sort.h"
#if defined(__linux__)
#include <sys/mman.h>
#endif

/* All the per-call arrays live in one zeroed block (arena_open), carved in
 * 64-byte aligned pieces: about 80 bytes per triangle for a welded mesh
 * (docs/PERFORMANCE.md), which the first writes fault in. On Linux the block
 * is one anonymous mapping asked for in huge pages (transparent huge pages in
 * madvise mode) over its whole length, 2 MB per fault instead of 4 KB, and
 * unmapped in one call; elsewhere it is one calloc. */
typedef struct arena {
    char *base;
    size_t len, used;
    int mapped;
} arena;

static size_t arena_round(size_t bytes) { return (bytes + 63) & ~(size_t)63; }

static int arena_open(arena *a, size_t bytes)
{
    a->used = 0;
    a->mapped = 0;
    a->len = bytes ? bytes : 1;
#if defined(__linux__) && defined(MAP_ANONYMOUS)
    const size_t huge = (size_t)2 << 20;
    if (a->len >= huge) {
        /* whole huge pages from a huge-page-aligned start: mapped one huge
         * page longer, the ends around them unmapped */
        size_t r = (a->len + huge - 1) / huge * huge;
        char *p = mmap(NULL, r + huge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (p != MAP_FAILED) {
            char *b = (char *)(((uintptr_t)p + huge - 1) & ~(uintptr_t)(huge - 1));
            size_t head = (size_t)(b - p);
            if (head)
                (void)munmap(p, head);
            if (huge - head)
                (void)munmap(b + r, huge - head);
#if defined(MADV_HUGEPAGE)
            (void)madvise(b, r, MADV_HUGEPAGE); /* advice only: may fail */
#endif
            a->base = b;
            a->len = r;
            a->mapped = 1;
            return 0;
        }
    }
#endif
    a->base = calloc(1, a->len);
    return a->base ? 0 : -1;
}

/* the next `bytes` of the block (zero unless an earlier piece was rewound) */
static void *arena_take(arena *a, size_t bytes)
{
    void *p = a->base + a->used;
    a->used += arena_round(bytes);
    return p;
}

static void arena_close(arena *a)
{
    if (!a->base)
        return;
#if defined(__linux__) && defined(MAP_ANONYMOUS)
    if (a->mapped) {
        (void)munmap(a->base, a->len);
        return;
    }
#endif
    free(a->base);
}

typedef struct d3 {
    double x, y, z;
} d3;

static d3 d3_sub(d3 a, d3 b) { return (d3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static d3 d3_add(d3 a, d3 b) { return (d3){a.x + b.x, a.y + b.y, a.z + b.z}; }
static d3 d3_scale(d3 a, double s) { return (d3){a.x * s, a.y * s, a.z * s}; }
static double d3_dot(d3 a, d3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

/* "Has a direction": some component above FLT_MIN in magnitude (the
 * description's test for a usable vector); otherwise it is left as it is. */
static int d3_nonzero(d3 a) { return fabs(a.x) > FLT_MIN || fabs(a.y) > FLT_MIN || fabs(a.z) > FLT_MIN; }
static d3 d3_unit_if(d3 a)
{
    if (!d3_nonzero(a))
        return a;
    return d3_scale(a, 1.0 / sqrt(d3_dot(a, a)));
}
/* a minus its component along the unit n, normalized when it has a direction
 * (fan_terms does this two at a time where SSE2 is there) */
#if !(defined(__GNUC__) && defined(__SSE2__))
static d3 d3_tangential(d3 a, d3 n) { return d3_unit_if(d3_sub(a, d3_scale(n, d3_dot(n, a)))); }
#endif

/* The same in float, in the reference's order of operations: only the split
 * test of rule 5 uses these. Whether two projected directions point "exactly
 * opposite" is decided by float rounding there (a cosine of -0.99999999999
 * rounds to -1 or not), so the test repeats the float arithmetic the
 * algorithm prescribes operation for operation (v - (n . v) n, then v scaled
 * by 1 / |v|, dot products summed x, y, z) rather than a double approximation
 * of it; sums and weights stay in double (docs/MESH.md, "the 180 degree
 * split"). FLT_EVAL_METHOD 0 and -ffp-contract=off keep every step a float
 * operation. */
typedef struct f3 {
    float x, y, z;
} f3;
static f3 f3_sub(f3 a, f3 b) { return (f3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static f3 f3_scale(float s, f3 a) { return (f3){s * a.x, s * a.y, s * a.z}; }
static float f3_dot(f3 a, f3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static int f3_nonzero(f3 a) { return fabsf(a.x) > FLT_MIN || fabsf(a.y) > FLT_MIN || fabsf(a.z) > FLT_MIN; }
static f3 f3_tangential(f3 a, f3 n)
{
    f3 r = f3_sub(a, f3_scale(f3_dot(n, a), n));
    return f3_nonzero(r) ? f3_scale(1.0f / sqrtf(f3_dot(r, r)), r) : r;
}

enum { TRI_DEGENERATE = 1, TRI_ANY = 2, TRI_PRESERVING = 4 };

/* What one worker thread owns: buffers sized by the largest vertex valence
 * (the triangles around one welded vertex), and its counts. */
typedef struct mikk_worker {
    int32_t *stack;   /* fan growth: at most 2 per member + 2 */
    int32_t *members; /* the fan being grown */
    int32_t *scratch; /* MIKK_SCRATCH: the subfans of fan_output, on first need */
    int oom;          /* the scratch could not be had */
    uint64_t *edges;  /* neighbour matching: (other vertex, triangle, edge) */
    struct d3 *term;  /* the fan's members' terms (fan_term) */
    uint8_t *corner;  /* the fan's members' corners at its vertex */
    size_t fans, unreached, degenerate, zero_uv_area;
} mikk_worker;

typedef struct mikk {
    const bgt_mikk_mesh *m;
    size_t T, nv;
    int threads;
    uint32_t *weld;   /* per vertex: representative vertex of its welded class */
    uint8_t *flags;   /* per triangle */
    d3 *os;           /* per triangle: unit dP/du direction, oriented */
    f3 *fos, *fot;    /* dP/du and dP/dv in float (the split test of rule 5) */
    int32_t *nb;      /* per triangle edge k (corner k to k+1): neighbour, -1 */
    uint8_t *grouped; /* per corner: taken by a fan */
    /* the corners of each welded vertex in corner order: v_corner[v_start[v]
     * .. v_start[v + 1]) (empty for a vertex that is not a representative) */
    uint32_t *v_start, *v_corner;
    uint8_t *touched; /* per vertex: a corner of a zero-UV-area triangle */
    float *out;
    mikk_worker *w;
} mikk;

/* the welded vertex of a corner */
static uint32_t wv(const mikk *k, size_t corner) { return k->weld[k->m->indices[corner]]; }

static f3 fnrm(const bgt_mikk_mesh *m, uint32_t i) { return (f3){m->nx[i], m->ny[i], m->nz[i]}; }



/* ---- 1. welding ----
 * Each vertex's 8 attributes as keys whose equality is float == (-0 welds
 * with +0; a vertex with a NaN attribute welds with nothing), hashed into an
 * open-addressing table in vertex order: the first vertex of a class to be
 * inserted, i.e. its smallest index, is the class's representative. */

/* The 8 attributes of vertex i as keys whose equality is float ==. */
static void vertex_keys(const bgt_mikk_mesh *m, size_t i, uint32_t key[8], int *nan)
{
    const float f[8] = {m->px[i], m->py[i], m->pz[i], m->nx[i],
                        m->ny[i], m->nz[i], m->u[i],  m->v[i]};
    *nan = 0;
    for (int a = 0; a < 8; a++) {
        key[a] = mesh_float_key(f[a]);
        *nan |= isnan(f[a]);
    }
}

/* used[i] = 1 for each vertex a triangle references, marked by the workers
 * (relaxed atomic byte stores: plain stores on common targets); an index out
 * of range sets `bad`. */
typedef _Atomic uint8_t mark8;
typedef struct mark_job {
    const uint32_t *idx;
    size_t nv;
    mark8 *used;
    atomic_int bad;
} mark_job;

static void mark_used(void *ctx, size_t b, size_t e, int worker)
{
    (void)worker;
    mark_job *j = ctx;
    for (size_t c = b; c < e; c++) {
        uint32_t i = j->idx[c];
        if (i >= j->nv) {
            atomic_store_explicit(&j->bad, 1, memory_order_relaxed);
            return;
        }
        atomic_store_explicit(&j->used[i], 1, memory_order_relaxed);
    }
}

typedef struct weld_job {
    const bgt_mikk_mesh *m;
    uint32_t *hash; /* UINT32_MAX marks a NaN vertex (a hash of UINT32_MAX is remapped) */
} weld_job;

static void weld_hashes(void *ctx, size_t b, size_t e, int worker)
{
    (void)worker;
    const weld_job *j = ctx;
    const bgt_mikk_mesh *m = j->m;
    const float *a[8] = {m->px, m->py, m->pz, m->nx, m->ny, m->nz, m->u, m->v};
    uint32_t *hash = j->hash;
    for (size_t i = b; i < e; i++) {
        uint64_t h = UINT64_C(0x9e3779b97f4a7c15);
        int nan = 0;
        for (int q = 0; q < 8; q++) {
            float f = a[q][i];
            nan |= f != f;
            h = (h ^ mesh_float_key(f)) * UINT64_C(0xff51afd7ed558ccd);
        }
        uint32_t h32 = (uint32_t)(h >> 32) ^ (uint32_t)h;
        hash[i] = nan ? UINT32_MAX : (h32 == UINT32_MAX ? 0 : h32);
    }
}

/* The table is cut into one region per part; part p inserts the vertices
 * whose hash falls to it, in vertex order. A class lies in one part, so the
 * parts run in parallel and the result is that of one table. */
typedef struct weld_part_job {
    mikk *k;
    const mark8 *used;
    const uint32_t *hash;
    uint32_t *table; /* vertex + 1, 0 = empty */
    size_t parts, region;
    size_t *merged; /* per part: vertices welded to an earlier one */
} weld_part_job;

static void weld_part(void *ctx, size_t b, size_t e, int worker)
{
    (void)worker;
    const weld_part_job *j = ctx;
    mikk *k = j->k;
    enum { BATCH = 512, AHEAD = 8 };
    uint32_t cand[BATCH];
    for (size_t p = b; p < e; p++) {
        uint32_t *table = j->table + p * j->region;
        size_t mask = j->region - 1, merged = 0;
        for (size_t i0 = 0; i0 < k->nv; i0 += BATCH) {
            /* this part's vertices of the batch, in order, gathered without
             * branches; the first table slot of each is fetched a few
             * vertices ahead */
            size_t i1 = k->nv - i0 < BATCH ? k->nv : i0 + BATCH, nc = 0;
            for (size_t i = i0; i < i1; i++) {
                uint32_t h = j->hash[i];
                cand[nc] = (uint32_t)i;
                nc += atomic_load_explicit(&j->used[i], memory_order_relaxed) &
                      (h != UINT32_MAX) & (h % j->parts == p);
            }
            for (size_t q = 0; q < nc; q++) {
                size_t i = cand[q];
                uint32_t h = j->hash[i];
#if defined(__GNUC__)
                if (q + AHEAD < nc)
                    __builtin_prefetch(&table[(j->hash[cand[q + AHEAD]] / j->parts) & mask], 1);
#endif
                uint32_t ki[8], ko[8];
                int nan, have = 0;
                for (size_t s = (h / j->parts) & mask;; s = (s + 1) & mask) {
                    uint32_t o = table[s];
                    if (o == 0) {
                        table[s] = (uint32_t)i + 1;
                        break;
                    }
                    o--;
                    if (j->hash[o] != h)
                        continue;
                    if (!have)
                        vertex_keys(k->m, i, ki, &nan), have = 1;
                    vertex_keys(k->m, o, ko, &nan);
                    if (memcmp(ko, ki, sizeof ki) == 0) {
                        k->weld[i] = o; /* o < i: the class's first vertex */
                        merged++;
                        break;
                    }
                }
            }
        }
        j->merged[p] = merged;
    }
}

/* weld[i] = smallest vertex index with the same attributes; `used` marks the
 * vertices the triangles reference. Returns the number of distinct referenced
 * vertices, or (size_t)-1 out of memory. */
typedef struct weld_init_job {
    mikk *k;
    const mark8 *used;
    size_t *nu; /* per worker */
} weld_init_job;

/* weld[i] = i (first touched by the workers) and the count of used vertices. */
static void weld_init(void *ctx, size_t b, size_t e, int worker)
{
    const weld_init_job *j = ctx;
    uint32_t *weld = j->k->weld;
    size_t nu = 0;
    for (size_t i = b; i < e; i++) {
        nu += atomic_load_explicit(&j->used[i], memory_order_relaxed);
        weld[i] = (uint32_t)i;
    }
    j->nu[worker] += nu;
}

/* The weld table's size in entries for `nu` referenced vertices: one region
 * per part, a power of two of at least 16, together at least 2 nu. */
static size_t weld_region(size_t nu, size_t parts)
{
    size_t region = 16;
    while (region * parts < 2 * nu)
        region *= 2;
    return region;
}

/* hash: nv entries; table: weld_region(nv, threads) * threads entries, zero */
static size_t weld_vertices(mikk *k, const mark8 *used, uint32_t *hash, uint32_t *table)
{
    size_t nv = k->nv, nu = 0;
    size_t *nuw = calloc((size_t)k->threads, sizeof *nuw);
    if (!nuw)
        return (size_t)-1;
    weld_init_job ij = {k, used, nuw};
    bgt_parallel_for(nv, 65536, k->threads, weld_init, &ij);
    for (int t = 0; t < k->threads; t++)
        nu += nuw[t];
    free(nuw);
    size_t parts = (size_t)k->threads, region = weld_region(nu, parts);
    size_t *merged = calloc(parts, sizeof *merged);
    size_t classes = (size_t)-1;
    if (merged) {
        weld_job j = {k->m, hash};
        bgt_parallel_for(nv, 16384, k->threads, weld_hashes, &j);
        weld_part_job pj = {k, used, hash, table, parts, region, merged};
        bgt_parallel_for(parts, 1, k->threads, weld_part, &pj);
        classes = nu;
        for (size_t p = 0; p < parts; p++)
            classes -= merged[p];
    }
    free(merged);
    return classes;
}

/* ---- 2./3. triangle classification and UV directions ---- */

/* Rule 3 per triangle: the orientation, the zero-UV-area test and the unit
 * oriented dP/du in double (k->os), and dP/du, dP/dv in float for the split
 * test of rule 5 (k->fos, k->fot): dP/du = dv2 e1 - dv1 e2 and dP/dv = -du2
 * e1 + du1 e2 (UV differences and edges rounded to float first there),
 * scaled by (sign of the area) / length. Each array element is written once,
 * and the arrays of the mesh are read through local pointers (the stores
 * could alias them). */
static void classify_chunk(void *ctx, size_t b, size_t e, int worker)
{
    mikk *k = ctx;
    mikk_worker *w = &k->w[worker];
    const bgt_mikk_mesh *m = k->m;
    const float *px = m->px, *py = m->py, *pz = m->pz, *us = m->u, *vs = m->v;
    const uint32_t *idx = m->indices;
    int32_t *nb = k->nb;
    uint8_t *flags = k->flags;
    d3 *os = k->os;
    f3 *fos = k->fos, *fot = k->fot;
    size_t degenerate = 0, zero = 0;
    for (size_t t = b; t < e; t++) {
        const uint32_t *ix = idx + 3 * t;
        uint32_t i0 = ix[0], i1 = ix[1], i2 = ix[2];
        nb[3 * t] = nb[3 * t + 1] = nb[3 * t + 2] = -1; /* (grouped comes zero) */
        float x0 = px[i0], y0 = py[i0], z0 = pz[i0];
        float x1 = px[i1], y1 = py[i1], z1 = pz[i1];
        float x2 = px[i2], y2 = py[i2], z2 = pz[i2];
        /* x - x is +0 for a finite x, NaN for an infinity or a NaN */
        float nf = (x0 - x0) + (y0 - y0) + (z0 - z0) + (x1 - x1) + (y1 - y1) + (z1 - z1) +
                   (x2 - x2) + (y2 - y2) + (z2 - z2);
        int eq01 = (x0 == x1) & (y0 == y1) & (z0 == z1);
        int eq02 = (x0 == x2) & (y0 == y2) & (z0 == z2);
        int eq12 = (x1 == x2) & (y1 == y2) & (z1 == z2);
        d3 o = {0, 0, 0};
        f3 fs = {0.0f, 0.0f, 0.0f}, ft = {0.0f, 0.0f, 0.0f};
        uint8_t f;
        if (!(nf == 0.0f) || eq01 || eq02 || eq12) {
            f = TRI_DEGENERATE;
            degenerate++;
        } else {
            float u0 = us[i0], u1 = us[i1], u2 = us[i2], v0 = vs[i0], v1 = vs[i1], v2 = vs[i2];
            double du1 = (double)u1 - u0, dv1 = (double)v1 - v0;
            double du2 = (double)u2 - u0, dv2 = (double)v2 - v0;
            double area = du1 * dv2 - du2 * dv1;
            d3 p0 = {x0, y0, z0};
            d3 e1 = d3_sub((d3){x1, y1, z1}, p0), e2 = d3_sub((d3){x2, y2, z2}, p0);
            d3 sd = d3_sub(d3_scale(e1, dv2), d3_scale(e2, dv1));  /* area * dP/du */
            d3 td = d3_sub(d3_scale(e2, du1), d3_scale(e1, du2)); /* area * dP/dv */
            f = area > 0.0 ? TRI_PRESERVING : 0;
            int any = 1;
            if (fabs(area) > FLT_MIN) {
                double sg = area > 0.0 ? 1.0 : -1.0;
                double ls = sqrt(d3_dot(sd, sd)), lt = sqrt(d3_dot(td, td));
                if (ls > FLT_MIN)
                    o = d3_scale(sd, sg / ls);
                double ms = ls / fabs(area), mt = lt / fabs(area);
                any = !(ms > FLT_MIN && mt > FLT_MIN);
            }
            if (any) {
                f |= TRI_ANY;
                zero++;
            }
            /* the same in float */
            float fdu1 = u1 - u0, fdv1 = v1 - v0, fdu2 = u2 - u0, fdv2 = v2 - v0;
            f3 fp0 = {x0, y0, z0};
            f3 fe1 = f3_sub((f3){x1, y1, z1}, fp0), fe2 = f3_sub((f3){x2, y2, z2}, fp0);
            float farea = fdu1 * fdv2 - fdv1 * fdu2;
            f3 ss = f3_sub(f3_scale(fdv2, fe1), f3_scale(fdv1, fe2));
            f3 ta = f3_scale(-fdu2, fe1), tb = f3_scale(fdu1, fe2);
            f3 ts = {ta.x + tb.x, ta.y + tb.y, ta.z + tb.z};
            if (fabsf(farea) > FLT_MIN) {
                float sg = farea > 0.0f ? 1.0f : -1.0f;
                float ls = sqrtf(f3_dot(ss, ss)), lt = sqrtf(f3_dot(ts, ts));
                if (ls > FLT_MIN)
                    fs = f3_scale(sg / ls, ss);
                if (lt > FLT_MIN)
                    ft = f3_scale(sg / lt, ts);
            }
        }
        os[t] = o;
        fos[t] = fs;
        fot[t] = ft;
        flags[t] = f;
    }
    w->degenerate += degenerate;
    w->zero_uv_area += zero;
}

/* ---- 4a. edge neighbours ----
 * Every edge of a non-degenerate triangle, as (lower welded vertex, higher,
 * triangle, edge number), matched with the first unmatched edge after it in
 * that order that runs the opposite way. Only edges between the same two
 * vertices can match, so each lower vertex's edges are matched on their own
 * (in parallel): they come from that vertex's corners, already in triangle
 * order, and are sorted stably by the higher vertex. */

/* Edge records of one lower vertex: (higher vertex) << 32 | corner << 1 |
 * leaves, with corner = 3 triangle + edge number (the edge's first corner,
 * below 2^31: checked on entry) and leaves = 1 when that corner is at the
 * lower vertex, so that their numeric order is the (higher, triangle, edge)
 * order. */
static void sort_edges(uint64_t *e, size_t n)
{
    for (size_t i = 1; i < n; i++) {
        uint64_t x = e[i];
        size_t j = i;
        for (; j > 0 && e[j - 1] > x; j--)
            e[j] = e[j - 1];
        e[j] = x;
    }
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* corner k's next (k + 1 mod 3) and previous (k + 2 mod 3) corner */
static const uint8_t next3[3] = {1, 2, 0}, prev3[3] = {2, 0, 1};

static void neighbours_chunk(void *ctx, size_t b, size_t e, int worker)
{
    /* corner k of a triangle: the edge that leaves it is k, the one that
     * arrives is prev (k + 2 mod 3); next is k + 1 mod 3 */
    mikk *k = ctx;
    uint64_t *ed = k->w[worker].edges;
    const uint32_t *vs = k->v_start, *vc = k->v_corner, *weld = k->weld, *idx = k->m->indices;
    const uint8_t *flags = k->flags;
    int32_t *nb = k->nb;
    for (size_t v = b; v < e; v++) {
        size_t n = 0;
        for (uint32_t i = vs[v], i1 = vs[v + 1]; i < i1; i++) {
            uint32_t c = vc[i], t = c / 3, kc = c - 3 * t, kp = prev3[kc];
            if (flags[t] & TRI_DEGENERATE)
                continue;
            /* edge kc leaves v, edge kp arrives at it: in edge-number order
             * (the corners of a non-degenerate triangle are at three
             * different welded vertices) */
            uint32_t t3 = 3 * t;
            uint32_t next = weld[idx[t3 + next3[kc]]], prev = weld[idx[t3 + kp]];
            if (kp < kc && prev > v)
                ed[n++] = (uint64_t)prev << 32 | (uint64_t)(t3 + kp) << 1;
            if (next > v)
                ed[n++] = (uint64_t)next << 32 | (uint64_t)c << 1 | 1;
            if (kp > kc && prev > v)
                ed[n++] = (uint64_t)prev << 32 | (uint64_t)(t3 + kp) << 1;
        }
        if (n <= 32)
            sort_edges(ed, n);
        else
            qsort(ed, n, sizeof *ed, cmp_u64); /* the records are distinct */
        /* Two edges between v and the same vertex match when they run
         * opposite ways: one leaves v (its first corner is at v), the other
         * arrives. */
        for (size_t i = 0; i < n; i++) {
            size_t ca = (size_t)(ed[i] >> 1 & 0x7fffffff);
            if (nb[ca] >= 0)
                continue;
            uint64_t leaves = ed[i] & 1;
            for (size_t j = i + 1; j < n && ed[j] >> 32 == ed[i] >> 32; j++) {
                size_t cb = (size_t)(ed[j] >> 1 & 0x7fffffff);
                if ((ed[j] & 1) != leaves && nb[cb] < 0) {
                    nb[ca] = (int32_t)cb;
                    nb[cb] = (int32_t)ca;
                    break;
                }
            }
        }
    }
}

/* ---- 4b. fans ---- */


/* The corner at the fan's vertex of the triangle across an edge of corner
 * c's triangle t: nb holds the matched edge (3 t' + k', from its corner k' to
 * k' + 1), which runs the opposite way. Across the edge that arrives at c
 * (prev3[c] to c) the matched edge leaves the vertex: its first corner.
 * Across the edge that leaves c, its second. -1: no neighbour. */
static int32_t across_arriving(const mikk *k, size_t corner)
{
    return k->nb[corner - (size_t)(corner % 3) + prev3[corner % 3]];
}
static int32_t across_leaving(const mikk *k, size_t corner)
{
    int32_t e = k->nb[corner];
    return e < 0 ? -1 : e - e % 3 + next3[e % 3];
}

/* Grow the fan of `vert` from its seed corner into w->members and the
 * members' corners at `vert` into w->corner (returns the count): depth
 * first, first across the edge that leaves the fan's corner forward (corner
 * c to c+1), then across the edge that arrives at it (c-1 to c). The
 * traversal order matters only for zero-UV-area triangles, which take the
 * orientation of the first fan that reaches them, and for the order of the
 * fan's sum. The stack holds corners at `vert`. */
static size_t grow_fan(mikk *k, mikk_worker *w, int pres, size_t seed, int seed_corner)
{
    size_t sp = 0, n = 0;
    size_t sc = 3 * seed + (size_t)seed_corner;
    k->grouped[sc] = 1;
    w->corner[n] = (uint8_t)seed_corner;
    w->members[n++] = (int32_t)seed;
    /* push the second edge first so that the first is explored first; a
     * corner already in a fan would be skipped when popped, so it is not
     * pushed (grouped marks are never cleared) */
    int32_t r = across_arriving(k, sc), l = across_leaving(k, sc);
    if (r >= 0 && !k->grouped[r])
        w->stack[sp++] = r;
    if (l >= 0 && !k->grouped[l])
        w->stack[sp++] = l;
    while (sp > 0) {
        size_t cn = (size_t)w->stack[--sp], t = cn / 3;
        uint8_t *slot = &k->grouped[cn];
        if (*slot)
            continue; /* already in this fan, or in another */
        if (k->flags[t] & TRI_ANY) {
            const uint8_t *gs = k->grouped + 3 * t;
            if (!gs[0] && !gs[1] && !gs[2])
                k->flags[t] = (uint8_t)((k->flags[t] & ~TRI_PRESERVING) |
                                        (pres ? TRI_PRESERVING : 0));
        }
        if (((k->flags[t] & TRI_PRESERVING) != 0) != (pres != 0))
            continue;
        *slot = 1;
        w->corner[n] = (uint8_t)(cn - 3 * t);
        w->members[n++] = (int32_t)t;
        r = across_arriving(k, cn);
        l = across_leaving(k, cn);
        if (r >= 0 && !k->grouped[r])
            w->stack[sp++] = r;
        if (l >= 0 && !k->grouped[l])
            w->stack[sp++] = l;
    }
    return n;
}

/* ---- 5. tangent of a (sub)fan ---- */

/* The terms of a fan's members, two at a time: a member triangle's term of
 * its fan's sum is angle * normalize(os projected), with angle the corner
 * angle between the two edges projected onto the plane orthogonal to the
 * corner's normal n (zero-UV-area triangles have none). Each lane does the
 * double operations of one member on its own, in the same order (products,
 * sums, a square root and a division, each correctly rounded; no fused
 * multiply-add), so the pairs change nothing in the bits: they let one SSE2
 * instruction do two members' work. An odd last member is paired with
 * itself. */
#if defined(__GNUC__) && defined(__SSE2__)
#include <emmintrin.h>
typedef double vd2 __attribute__((vector_size(16)));
typedef struct v3 {
    vd2 x, y, z;
} v3;
/* a minus its component along n, normalized when it has a direction
 * (d3_tangential lane by lane) */
static inline __attribute__((always_inline)) v3 v3_tangential(v3 a, v3 n)
{
    vd2 d = n.x * a.x + n.y * a.y + n.z * a.z;
    v3 r = {a.x - n.x * d, a.y - n.y * d, a.z - n.z * d};
    vd2 inv = (vd2){1.0, 1.0} / (vd2)_mm_sqrt_pd((__m128d)(r.x * r.x + r.y * r.y + r.z * r.z));
    v3 u = {r.x * inv, r.y * inv, r.z * inv};
    const __m128d fmin = _mm_set1_pd(FLT_MIN), sign = _mm_set1_pd(-0.0);
    __m128d nz = _mm_or_pd(_mm_or_pd(_mm_cmpgt_pd(_mm_andnot_pd(sign, (__m128d)r.x), fmin),
                                     _mm_cmpgt_pd(_mm_andnot_pd(sign, (__m128d)r.y), fmin)),
                           _mm_cmpgt_pd(_mm_andnot_pd(sign, (__m128d)r.z), fmin));
    if (_mm_movemask_pd(nz) == 3)
        return u;
    return (v3){(vd2)_mm_or_pd(_mm_and_pd(nz, (__m128d)u.x), _mm_andnot_pd(nz, (__m128d)r.x)),
                (vd2)_mm_or_pd(_mm_and_pd(nz, (__m128d)u.y), _mm_andnot_pd(nz, (__m128d)r.y)),
                (vd2)_mm_or_pd(_mm_and_pd(nz, (__m128d)u.z), _mm_andnot_pd(nz, (__m128d)r.z))};
}
#define MIKK_PAIRS 1
#endif

static void fan_terms(const mikk *k, const int32_t *mem, const uint8_t *corner, size_t n, d3 *term)
{
    const bgt_mikk_mesh *m = k->m;
    const float *px = m->px, *py = m->py, *pz = m->pz;
    const float *nx = m->nx, *ny = m->ny, *nz = m->nz;
    const uint32_t *idx = m->indices;
    const d3 *os = k->os;
#if defined(MIKK_PAIRS)
    for (size_t i0 = 0; i0 < n; i0 += 2) {
        size_t i1 = i0 + 1 < n ? i0 + 1 : i0;
        size_t t0 = (size_t)mem[i0], t1 = (size_t)mem[i1];
        int c0 = corner[i0], c1 = corner[i1];
        const uint32_t *x0 = idx + 3 * t0, *x1 = idx + 3 * t1;
        uint32_t v0 = x0[c0], a0 = x0[prev3[c0]], b0 = x0[next3[c0]];
        uint32_t v1 = x1[c1], a1 = x1[prev3[c1]], b1 = x1[next3[c1]];
        v3 nn = {{nx[v0], nx[v1]}, {ny[v0], ny[v1]}, {nz[v0], nz[v1]}};
        v3 o = {{os[t0].x, os[t1].x}, {os[t0].y, os[t1].y}, {os[t0].z, os[t1].z}};
        v3 p = {{px[v0], px[v1]}, {py[v0], py[v1]}, {pz[v0], pz[v1]}};
        v3 ea = {(vd2){px[a0], px[a1]} - p.x, (vd2){py[a0], py[a1]} - p.y,
                 (vd2){pz[a0], pz[a1]} - p.z};
        v3 eb = {(vd2){px[b0], px[b1]} - p.x, (vd2){py[b0], py[b1]} - p.y,
                 (vd2){pz[b0], pz[b1]} - p.z};
        o = v3_tangential(o, nn);
        ea = v3_tangential(ea, nn);
        eb = v3_tangential(eb, nn);
        vd2 cs = ea.x * eb.x + ea.y * eb.y + ea.z * eb.z;
        for (int l = 0; l < 2 && i0 + (size_t)l < n; l++) {
            if (k->flags[mem[i0 + (size_t)l]] & TRI_ANY)
                continue;
            double c = cs[l];
            double ang = acos(c < -1.0 ? -1.0 : c > 1.0 ? 1.0 : c);
            term[i0 + (size_t)l] = (d3){o.x[l] * ang, o.y[l] * ang, o.z[l] * ang};
        }
    }
#else
    for (size_t i = 0; i < n; i++) {
        size_t t = (size_t)mem[i];
        int c = corner[i];
        if (k->flags[t] & TRI_ANY)
            continue;
        const uint32_t *ix = idx + 3 * t;
        uint32_t v0 = ix[c], va = ix[prev3[c]], vb = ix[next3[c]];
        d3 nn = {nx[v0], ny[v0], nz[v0]}, p = {px[v0], py[v0], pz[v0]};
        d3 o = d3_tangential(os[t], nn);
        d3 ea = d3_tangential(d3_sub((d3){px[va], py[va], pz[va]}, p), nn);
        d3 eb = d3_tangential(d3_sub((d3){px[vb], py[vb], pz[vb]}, p), nn);
        double cs = d3_dot(ea, eb);
        term[i] = d3_scale(o, acos(cs < -1.0 ? -1.0 : cs > 1.0 ? 1.0 : cs));
    }
#endif
}

/* The tangent of the members list[0..n-1] (indices into the fan's terms):
 * their terms summed in list order, normalized. */
static d3 fan_tangent(const mikk *k, const int32_t *mem, const d3 *term, const int32_t *list,
                      size_t n)
{
    d3 sum = {0, 0, 0};
    for (size_t i = 0; i < n; i++)
        if (!(k->flags[mem[list[i]]] & TRI_ANY))
            sum = d3_add(sum, term[list[i]]);
    return d3_unit_if(sum);
}

static void put_corner(float *out, size_t c, d3 tg, float w)
{
    out[4 * c] = (float)tg.x, out[4 * c + 1] = (float)tg.y, out[4 * c + 2] = (float)tg.z;
    out[4 * c + 3] = w;
}

/* One tangent for the whole fan: the terms summed in member order. */
static void whole_fan(const mikk *k, const int32_t *mem, const d3 *term, const uint8_t *corner,
                      size_t n, float w, float *out)
{
    d3 tg = {0, 0, 0};
    for (size_t i = 0; i < n; i++)
        if (!(k->flags[mem[i]] & TRI_ANY))
            tg = d3_add(tg, term[i]);
    tg = d3_unit_if(tg);
    for (size_t i = 0; i < n; i++)
        put_corner(out, 3 * (size_t)mem[i] + corner[i], tg, w);
}

/* Split the fan mem[0..n-1] (corner[i]: member i's corner at the fan's vertex)
 * where projected directions point exactly opposite (the reference's angular
 * threshold at its default of 180 degrees) and write the tangents of its
 * corners. */
#define MIKK_SPLIT_MAX 256

/* A cheap sufficient test that no pair of the fan splits (the usual case),
 * which spares the float projections, normalizations and the n^2 cosines of
 * the exact test: the projections r = v - n (n . v) of every member's float
 * directions (computed as f3_tangential computes them, before its
 * normalization) within 60 degrees of the first member's, tested without a
 * square root as d > 0 and d^2 > |r|^2 |r0|^2 / 4 with d = r . r0. Two such
 * directions are at most about 120 degrees apart, so their normalized float
 * cosine is near -0.5, far above -1 whatever the float rounding. Anything
 * else (a member beyond 60 degrees, a projection too short or too long for
 * these squares to be exact to a few ulps: |r|^2 outside [1e-12, 1e12];
 * NaN) answers "may split", and the exact test decides. */
#if defined(__GNUC__) && defined(__SSE2__)
/* The same test, four members at a time (SSE float lanes). */
static int may_split(const mikk *k, const int32_t *mem, size_t n, const uint8_t *corner)
{
    const bgt_mikk_mesh *m = k->m;
    const float *nxs = m->nx, *nys = m->ny, *nzs = m->nz;
    const uint32_t *idx = m->indices;
    const uint8_t *flags = k->flags;
    const f3 *fos = k->fos, *fot = k->fot;
    size_t first = 0;
    while (first < n && (flags[mem[first]] & TRI_ANY))
        first++;
    if (first >= n)
        return 0;
    /* The members' corners are at one welded vertex, so their normals are
     * equal as floats (up to the sign of a zero, which changes no comparison
     * below): the first member's serves all. */
    uint32_t v0 = idx[3 * (size_t)mem[first] + corner[first]];
    const __m128 nx = _mm_set1_ps(nxs[v0]), ny = _mm_set1_ps(nys[v0]), nz = _mm_set1_ps(nzs[v0]);
    __m128 s0x = _mm_setzero_ps(), s0y = s0x, s0z = s0x, t0x = s0x, t0y = s0x, t0z = s0x,
           ls0 = s0x, lt0 = s0x;
    const __m128 lo = _mm_set1_ps(1e-12f), hi = _mm_set1_ps(1e12f), zero = _mm_setzero_ps(),
                 quarter = _mm_set1_ps(0.25f);
    int ok = 1;
    for (size_t i0 = first; i0 < n && ok; i0 += 4) {
        size_t il[4];
        int dead[4];
        for (int l = 0; l < 4; l++) {
            size_t i = i0 + (size_t)l < n ? i0 + (size_t)l : first;
            il[l] = (size_t)mem[i];
            dead[l] = !(i0 + (size_t)l < n) || (flags[il[l]] & TRI_ANY);
        }
        /* lanes built from scalars (not stored and reloaded: a 16-byte load
         * of four 4-byte stores stalls) */
#define MIKK_G(arr, f) _mm_set_ps(arr[L(3)] f, arr[L(2)] f, arr[L(1)] f, arr[L(0)] f)
#define L(l) il[l]
        __m128 ax = MIKK_G(fos, .x), ay = MIKK_G(fos, .y), az = MIKK_G(fos, .z);
        __m128 bx = MIKK_G(fot, .x), by = MIKK_G(fot, .y), bz = MIKK_G(fot, .z);
#undef L
#undef MIKK_G
        __m128 deadm = _mm_castsi128_ps(_mm_set_epi32(-dead[3], -dead[2], -dead[1], -dead[0]));
        __m128 da = _mm_add_ps(_mm_add_ps(_mm_mul_ps(nx, ax), _mm_mul_ps(ny, ay)), _mm_mul_ps(nz, az));
        __m128 db = _mm_add_ps(_mm_add_ps(_mm_mul_ps(nx, bx), _mm_mul_ps(ny, by)), _mm_mul_ps(nz, bz));
        __m128 sx = _mm_sub_ps(ax, _mm_mul_ps(da, nx)), sy = _mm_sub_ps(ay, _mm_mul_ps(da, ny)),
               sz = _mm_sub_ps(az, _mm_mul_ps(da, nz));
        __m128 tx = _mm_sub_ps(bx, _mm_mul_ps(db, nx)), ty = _mm_sub_ps(by, _mm_mul_ps(db, ny)),
               tz = _mm_sub_ps(bz, _mm_mul_ps(db, nz));
        __m128 ls = _mm_add_ps(_mm_add_ps(_mm_mul_ps(sx, sx), _mm_mul_ps(sy, sy)), _mm_mul_ps(sz, sz));
        __m128 lt = _mm_add_ps(_mm_add_ps(_mm_mul_ps(tx, tx), _mm_mul_ps(ty, ty)), _mm_mul_ps(tz, tz));
        if (i0 == first) { /* lane 0 is the first member: the reference */
            s0x = _mm_shuffle_ps(sx, sx, 0), s0y = _mm_shuffle_ps(sy, sy, 0);
            s0z = _mm_shuffle_ps(sz, sz, 0), t0x = _mm_shuffle_ps(tx, tx, 0);
            t0y = _mm_shuffle_ps(ty, ty, 0), t0z = _mm_shuffle_ps(tz, tz, 0);
            ls0 = _mm_shuffle_ps(ls, ls, 0), lt0 = _mm_shuffle_ps(lt, lt, 0);
        }
        __m128 ds = _mm_add_ps(_mm_add_ps(_mm_mul_ps(sx, s0x), _mm_mul_ps(sy, s0y)), _mm_mul_ps(sz, s0z));
        __m128 dt = _mm_add_ps(_mm_add_ps(_mm_mul_ps(tx, t0x), _mm_mul_ps(ty, t0y)), _mm_mul_ps(tz, t0z));
        __m128 good = _mm_and_ps(_mm_and_ps(_mm_cmpge_ps(ls, lo), _mm_cmple_ps(ls, hi)),
                                 _mm_and_ps(_mm_cmpge_ps(lt, lo), _mm_cmple_ps(lt, hi)));
        good = _mm_and_ps(good, _mm_and_ps(_mm_cmpgt_ps(ds, zero), _mm_cmpgt_ps(dt, zero)));
        good = _mm_and_ps(good, _mm_cmpgt_ps(_mm_mul_ps(ds, ds), _mm_mul_ps(quarter, _mm_mul_ps(ls, ls0))));
        good = _mm_and_ps(good, _mm_cmpgt_ps(_mm_mul_ps(dt, dt), _mm_mul_ps(quarter, _mm_mul_ps(lt, lt0))));
        /* lanes of zero-UV-area members and past the end pass */
        good = _mm_or_ps(good, deadm);
        ok = _mm_movemask_ps(good) == 15;
    }
    return !ok;
}
#else
static int proj_ok(float l) { return l >= 1e-12f && l <= 1e12f; }
static int may_split(const mikk *k, const int32_t *mem, size_t n, const uint8_t *corner)
{
    const bgt_mikk_mesh *m = k->m;
    const float *nxs = m->nx, *nys = m->ny, *nzs = m->nz;
    const uint32_t *idx = m->indices;
    const uint8_t *flags = k->flags;
    const f3 *fos = k->fos, *fot = k->fot;
    float s0x = 0, s0y = 0, s0z = 0, t0x = 0, t0y = 0, t0z = 0, ls0 = 0, lt0 = 0;
    int have = 0;
    for (size_t i = 0; i < n; i++) {
        size_t t = (size_t)mem[i];
        if (flags[t] & TRI_ANY)
            continue;
        uint32_t vi = idx[3 * t + corner[i]];
        float nx = nxs[vi], ny = nys[vi], nz = nzs[vi];
        float ax = fos[t].x, ay = fos[t].y, az = fos[t].z;
        float bx = fot[t].x, by = fot[t].y, bz = fot[t].z;
        float da = nx * ax + ny * ay + nz * az, db = nx * bx + ny * by + nz * bz;
        float sx = ax - da * nx, sy = ay - da * ny, sz = az - da * nz;
        float tx = bx - db * nx, ty = by - db * ny, tz = bz - db * nz;
        float ls = sx * sx + sy * sy + sz * sz, lt = tx * tx + ty * ty + tz * tz;
        if (!proj_ok(ls) || !proj_ok(lt))
            return 1;
        if (!have) {
            s0x = sx, s0y = sy, s0z = sz, t0x = tx, t0y = ty, t0z = tz;
            ls0 = ls, lt0 = lt;
            have = 1;
            continue;
        }
        float ds = sx * s0x + sy * s0y + sz * s0z, dt = tx * t0x + ty * t0y + tz * t0z;
        if (!(ds > 0.0f && ds * ds > 0.25f * (ls * ls0) && dt > 0.0f &&
              dt * dt > 0.25f * (lt * lt0)))
            return 1;
    }
    return 0;
}
#endif

/* scratch: the member lists of the distinct subfans, each preceded by its
 * length (at most MIKK_SPLIT_MAX lists of MIKK_SPLIT_MAX) */
#define MIKK_SCRATCH ((size_t)MIKK_SPLIT_MAX * (MIKK_SPLIT_MAX + 1))
static void fan_split(const mikk *k, mikk_worker *wk, const int32_t *mem, size_t n, float w,
                      float *out, const d3 *term, const uint8_t *corner);
static void fan_output(const mikk *k, mikk_worker *wk, const int32_t *mem, size_t n, int pres,
                       float *out, d3 *term, const uint8_t *corner)
{
    float w = pres ? 1.0f : -1.0f;
    fan_terms(k, mem, corner, n, term);
    if (n > MIKK_SPLIT_MAX || !may_split(k, mem, n, corner))
        whole_fan(k, mem, term, corner, n, w, out);
    else
        fan_split(k, wk, mem, n, w, out, term, corner);
}

/* The exact test of rule 5 and, where a pair points opposite, the subfans. */
__attribute__((noinline)) static void fan_split(const mikk *k, mikk_worker *wk,
                                                const int32_t *mem, size_t n, float w,
                                                float *out, const d3 *term,
                                                const uint8_t *corner)
{
    const bgt_mikk_mesh *m = k->m;
    f3 ps[MIKK_SPLIT_MAX], pt[MIKK_SPLIT_MAX];
    uint8_t anyf[MIKK_SPLIT_MAX];
    for (size_t i = 0; i < n; i++) {
        size_t t = (size_t)mem[i];
        f3 nn = fnrm(m, m->indices[3 * t + corner[i]]);
        ps[i] = f3_tangential(k->fos[t], nn);
        pt[i] = f3_tangential(k->fot[t], nn);
        anyf[i] = (k->flags[t] & TRI_ANY) != 0;
    }
    /* cos(180 deg) rounded to float, the reference's default threshold: -1,
     * so only a float cosine that rounds to -1 splits */
    const float pi_f = 3.14159265358979323846f;
    const float opposite = (float)cos((180.0f * pi_f) / 180.0f);
    /* No pair points opposite, so every member's subfan is the whole fan
     * (the test is symmetric: a float dot product does not depend on the
     * order of its operands). */
    int split = 0;
    for (size_t i = 0; i < n && !split; i++) {
        if (anyf[i])
            continue;
        for (size_t j = i + 1; j < n && !split; j++)
            split = !anyf[j] &&
                    !(f3_dot(ps[i], ps[j]) > opposite && f3_dot(pt[i], pt[j]) > opposite);
    }
    if (!split) {
        whole_fan(k, mem, term, corner, n, w, out);
        return;
    }
    if (!wk->scratch && !(wk->scratch = malloc(MIKK_SCRATCH * sizeof *wk->scratch))) {
        wk->oom = 1;
        return;
    }
    int32_t *scratch = wk->scratch;
    size_t nsub = 0, used = 0;
    size_t sub_off[MIKK_SPLIT_MAX];
    d3 sub_tan[MIKK_SPLIT_MAX];
    for (size_t i = 0; i < n; i++) {
        size_t t = (size_t)mem[i];
        int32_t *list = scratch + used + 1;
        size_t cnt = 0;
        for (size_t j = 0; j < n; j++) {
            size_t u = (size_t)mem[j];
            int any = ((k->flags[t] | k->flags[u]) & TRI_ANY) != 0;
            if (any || i == j ||
                (f3_dot(ps[i], ps[j]) > opposite && f3_dot(pt[i], pt[j]) > opposite))
                list[cnt++] = (int32_t)j;
        }
        size_t s;
        for (s = 0; s < nsub; s++) {
            const int32_t *o = scratch + sub_off[s];
            if ((size_t)o[0] == cnt && memcmp(o + 1, list, cnt * sizeof *list) == 0)
                break;
        }
        if (s == nsub) {
            scratch[used] = (int32_t)cnt;
            sub_off[nsub] = used;
            sub_tan[nsub] = fan_tangent(k, mem, term, list, cnt);
            used += cnt + 1;
            nsub++;
        }
        put_corner(out, 3 * t + corner[i], sub_tan[s], w);
    }
}

/* One fan from its seed corner: grown, then its tangents written. */
static void seed_fan(mikk *k, mikk_worker *w, size_t t, int c)
{
    int pres = (k->flags[t] & TRI_PRESERVING) != 0;
    size_t n = grow_fan(k, w, pres, t, c);
    fan_output(k, w, w->members, n, pres, k->out, w->term, w->corner);
    w->fans++;
}

/* The fans of the vertices [b, e) that no zero-UV-area triangle touches, in
 * parallel: such a vertex's fans read and write only its own corners and the
 * flags of triangles that keep them, so the result does not depend on the
 * threads. Then every corner of [b, e) that no fan reached: the default frame,
 * or for a degenerate triangle's corner the frame of the first non-degenerate
 * corner at the same welded vertex. */
static void fans_chunk(void *ctx, size_t b, size_t e, int worker)
{
    mikk *k = ctx;
    mikk_worker *w = &k->w[worker];
    for (size_t v = b; v < e; v++) {
        const uint32_t *cs = k->v_corner + k->v_start[v];
        size_t nc = k->v_start[v + 1] - k->v_start[v];
        /* plain: all of v's corners seed or join fans here (none degenerate
         * or zero-UV-area), so afterwards each is in a fan and the passes
         * below would write nothing */
        int plain = !k->touched || !k->touched[v];
        if (plain)
            for (size_t i = 0; i < nc; i++) {
                size_t t = cs[i] / 3;
                if (k->flags[t] & (TRI_DEGENERATE | TRI_ANY))
                    plain = 0;
                else if (!k->grouped[cs[i]])
                    seed_fan(k, w, t, (int)(cs[i] % 3));
            }
        if (plain)
            continue;
        int64_t first = -1;
        int degenerate = 0;
        for (size_t i = 0; i < nc; i++) {
            if (k->flags[cs[i] / 3] & TRI_DEGENERATE) {
                degenerate = 1;
                continue;
            }
            if (first < 0)
                first = cs[i];
            if (!k->grouped[cs[i]]) {
                put_corner(k->out, cs[i], (d3){1, 0, 0}, -1.0f);
                w->unreached++;
            }
        }
        for (size_t i = 0; degenerate && i < nc; i++) {
            if (!(k->flags[cs[i] / 3] & TRI_DEGENERATE))
                continue;
            if (first >= 0)
                memcpy(k->out + 4 * (size_t)cs[i], k->out + 4 * (size_t)first, 4 * sizeof(float));
            else
                put_corner(k->out, cs[i], (d3){1, 0, 0}, -1.0f);
        }
    }
}

/* The corners of each welded vertex, in corner order: a counting sort cut
 * into parts (consecutive corner ranges) that count and place their corners
 * in parallel; part p's corners of a vertex go after those of the parts
 * before it, so the order is that of one pass. */
#define MIKK_CSR_PARTS 4
typedef struct csr_job {
    mikk *k;
    uint32_t *cnt; /* per part, per vertex: count, then next slot */
    size_t per;    /* corners per part */
    int place;     /* 0: count, 1: place */
} csr_job;

static void csr_part(void *ctx, size_t b, size_t e, int worker)
{
    (void)worker;
    const csr_job *j = ctx;
    mikk *k = j->k;
    size_t nc = 3 * k->T;
    const uint32_t *weld = k->weld, *idx = k->m->indices;
    uint32_t *vcorner = k->v_corner;
    for (size_t p = b; p < e; p++) {
        uint32_t *cnt = j->cnt + p * k->nv;
        size_t c1 = (p + 1) * j->per < nc ? (p + 1) * j->per : nc;
        if (j->place)
            for (size_t c = p * j->per; c < c1; c++)
                vcorner[cnt[weld[idx[c]]]++] = (uint32_t)c;
        else
            for (size_t c = p * j->per; c < c1; c++)
                cnt[weld[idx[c]]]++;
    }
}

/* The prefix sum over the vertices in two levels: blocks of vertices sum
 * their counts in parallel, one short serial scan gives each block its start,
 * then the blocks write their starts in parallel (the same sums as one pass).
 * The largest valence comes out of the first level. */
#define MIKK_CSR_BLOCK 16384
typedef struct csr_scan {
    mikk *k;
    uint32_t *cnt;
    size_t parts;
    uint32_t *sum, *maxv; /* per block */
    int fill;
} csr_scan;

static void csr_scan_blocks(void *ctx, size_t b, size_t e, int worker)
{
    (void)worker;
    const csr_scan *j = ctx;
    size_t nv = j->k->nv;
    uint32_t *cnt = j->cnt, *v_start = j->k->v_start;
    for (size_t blk = b; blk < e; blk++) {
        size_t v0 = blk * MIKK_CSR_BLOCK, v1 = v0 + MIKK_CSR_BLOCK < nv ? v0 + MIKK_CSR_BLOCK : nv;
        if (!j->fill) {
            uint32_t sum = 0, mx = 0;
            for (size_t v = v0; v < v1; v++) {
                uint32_t n = 0;
                for (size_t p = 0; p < j->parts; p++)
                    n += cnt[p * nv + v];
                sum += n;
                mx = n > mx ? n : mx;
            }
            j->sum[blk] = sum;
            j->maxv[blk] = mx;
        } else {
            uint32_t at = j->sum[blk];
            for (size_t v = v0; v < v1; v++) {
                v_start[v] = at;
                for (size_t p = 0; p < j->parts; p++) {
                    uint32_t n = cnt[p * nv + v];
                    cnt[p * nv + v] = at;
                    at += n;
                }
            }
        }
    }
}

static size_t csr_parts(int threads)
{
    return threads < MIKK_CSR_PARTS ? (size_t)threads : MIKK_CSR_PARTS;
}
static size_t csr_blocks(size_t nv) { return (nv + MIKK_CSR_BLOCK - 1) / MIKK_CSR_BLOCK; }

/* cnt: csr_parts * nv zero counts; bs: 2 (csr_blocks + 1) */
static void corners_by_vertex(mikk *k, size_t *maxv, uint32_t *cnt, uint32_t *bs)
{
    size_t nv = k->nv, nc = 3 * k->T;
    size_t parts = csr_parts(k->threads);
    size_t blocks = csr_blocks(nv);
    csr_job j = {k, cnt, (nc + parts - 1) / parts, 0};
    bgt_parallel_for(parts, 1, k->threads, csr_part, &j);
    csr_scan sc = {k, j.cnt, parts, bs, bs + blocks + 1, 0};
    bgt_parallel_for(blocks, 1, k->threads, csr_scan_blocks, &sc);
    uint32_t at = 0, mx = 0;
    for (size_t blk = 0; blk < blocks; blk++) {
        uint32_t n = sc.sum[blk];
        sc.sum[blk] = at;
        at += n;
        mx = sc.maxv[blk] > mx ? sc.maxv[blk] : mx;
    }
    sc.fill = 1;
    bgt_parallel_for(blocks, 1, k->threads, csr_scan_blocks, &sc);
    k->v_start[nv] = at;
    *maxv = mx;
    j.place = 1;
    bgt_parallel_for(parts, 1, k->threads, csr_part, &j);
}

static void free_workers(mikk *k)
{
    for (int i = 0; k->w && i < k->threads; i++) {
        free(k->w[i].stack);
        free(k->w[i].members);
        free(k->w[i].scratch);
        free(k->w[i].edges);
        free(k->w[i].term);
        free(k->w[i].corner);
    }
    free(k->w);
}

/* Per-worker buffers for a largest valence of `maxv` corners. */
static int alloc_workers(mikk *k, size_t maxv)
{
    for (int i = 0; i < k->threads; i++) {
        mikk_worker *w = &k->w[i];
        w->stack = malloc((2 * maxv + 4) * sizeof *w->stack);
        w->members = malloc((maxv + 1) * sizeof *w->members);
        w->edges = malloc((2 * maxv + 2) * sizeof *w->edges);
        w->term = malloc((maxv + 1) * sizeof *w->term);
        w->corner = malloc(maxv + 1);
        if (!w->stack || !w->members || !w->edges || !w->term || !w->corner)
            return -1;
    }
    return 0;
}

bg_status bgt_mikk_tangents(const bgt_mikk_mesh *m, float *out, bgt_mikk_stats *stats)
{
    return bgt_mikk_tangents_threads(m, out, stats, 0);
}

bg_status bgt_mikk_tangents_threads(const bgt_mikk_mesh *m, float *out, bgt_mikk_stats *stats,
                                    int threads)
{
    bgt_mikk_stats st;
    memset(&st, 0, sizeof st);
    if (stats)
        *stats = st;
    if (!m || !out)
        return BG_ERR_NULL_POINTER;
    size_t T = m->triangle_count;
    if (T == 0)
        return BG_OK;
    if (!m->indices || !m->px || !m->py || !m->pz || !m->nx || !m->ny || !m->nz || !m->u ||
        !m->v)
        return BG_ERR_NULL_POINTER;
    if (T > (size_t)INT32_MAX / 3 || m->vertex_count > UINT32_MAX)
        return BG_ERR_INVALID_ARGUMENT;
    size_t nv = m->vertex_count;
    if (T > SIZE_MAX / 128 || nv > SIZE_MAX / 128) /* the block size below stays in size_t */
        return BG_ERR_OUT_OF_MEMORY;
    int threads_used = threads > 0 ? (threads < 256 ? threads : 256) : bgt_threads_default();

    /* The block's pieces. Kept to the end: weld, v_start and the per-triangle
     * arrays. v_corner is written last (corners_by_vertex's placing), so its
     * space first holds the welding's scratch (used, hash, table); the
     * corner counts of corners_by_vertex run before the triangle pass and
     * use the space of os, which that pass writes. Both scratches come out
     * of the block untouched, i.e. zero. */
    size_t parts = (size_t)threads_used, cparts = csr_parts(threads_used);
    size_t blocks = csr_blocks(nv);
    size_t tbl = weld_region(nv, parts) * parts;
    size_t weld_scratch = arena_round(nv) + arena_round(4 * nv) + arena_round(4 * tbl);
    size_t csr_scratch = arena_round(cparts * nv * 4) + arena_round(2 * (blocks + 1) * 4);
    size_t vc_bytes = arena_round(3 * T * 4), os_bytes = arena_round(T * sizeof(d3));
    size_t vc_space = vc_bytes > weld_scratch ? vc_bytes : weld_scratch;
    size_t os_space = os_bytes > csr_scratch ? os_bytes : csr_scratch;
    arena ar;
    memset(&ar, 0, sizeof ar);
    if (arena_open(&ar, arena_round(4 * nv) + arena_round(4 * (nv + 1)) + arena_round(T) +
                            os_space + 2 * arena_round(T * sizeof(f3)) +
                            arena_round(3 * T * 4) + arena_round(3 * T) + vc_space) != 0)
        return BG_ERR_OUT_OF_MEMORY;
    mikk k;
    memset(&k, 0, sizeof k);
    k.m = m;
    k.T = T;
    k.out = out;
    k.threads = threads_used;
    k.nv = nv;
    k.weld = arena_take(&ar, 4 * nv);
    k.v_start = arena_take(&ar, 4 * (nv + 1));
    k.flags = arena_take(&ar, T);
    k.os = arena_take(&ar, os_space);
    k.fos = arena_take(&ar, T * sizeof(f3));
    k.fot = arena_take(&ar, T * sizeof(f3));
    k.nb = arena_take(&ar, 3 * T * 4);
    k.grouped = arena_take(&ar, 3 * T);
    k.v_corner = arena_take(&ar, vc_space);
    mark8 *used = (mark8 *)(void *)k.v_corner;
    uint32_t *hash = (uint32_t *)(void *)((char *)k.v_corner + arena_round(nv));
    uint32_t *table = (uint32_t *)(void *)((char *)hash + arena_round(4 * nv));
    uint32_t *cnt = (uint32_t *)(void *)k.os;
    uint32_t *bs = (uint32_t *)(void *)((char *)k.os + arena_round(cparts * nv * 4));

    bg_status rc = BG_ERR_INVALID_ARGUMENT;
    mark_job mj = {m->indices, nv, used, 0};
    bgt_parallel_for(3 * T, 65536, threads_used, mark_used, &mj);
    if (atomic_load(&mj.bad))
        goto done;
    rc = BG_ERR_OUT_OF_MEMORY;
    st.welded_vertices = weld_vertices(&k, used, hash, table);
    k.w = calloc((size_t)k.threads, sizeof *k.w);
    if (st.welded_vertices == (size_t)-1 || !k.w)
        goto done;
    size_t maxv = 0;
    corners_by_vertex(&k, &maxv, cnt, bs);
    bgt_parallel_for(T, 8192, k.threads, classify_chunk, &k);
    if (alloc_workers(&k, maxv) != 0)
        goto done;
    bgt_parallel_for(nv, 4096, k.threads, neighbours_chunk, &k);
    size_t zero = 0;
    for (int i = 0; i < k.threads; i++)
        zero += k.w[i].zero_uv_area;
    if (zero) {
        /* Zero-UV-area triangles take the orientation of the first fan that
         * reaches them, in the order of the fans' seeds: the fans of the
         * vertices they touch are grown one after the other in that order. */
        k.touched = calloc(nv, 1);
        if (!k.touched)
            goto done;
        for (size_t t = 0; t < T; t++)
            if (k.flags[t] & TRI_ANY)
                for (int c = 0; c < 3; c++)
                    k.touched[wv(&k, 3 * t + (size_t)c)] = 1;
        for (size_t t = 0; t < T; t++) {
            if (k.flags[t] & (TRI_DEGENERATE | TRI_ANY))
                continue;
            for (int c = 0; c < 3; c++)
                if (k.touched[wv(&k, 3 * t + (size_t)c)] && !k.grouped[3 * t + (size_t)c])
                    seed_fan(&k, &k.w[0], t, c);
        }
    }
    bgt_parallel_for(nv, 4096, k.threads, fans_chunk, &k);
    for (int i = 0; i < k.threads; i++)
        if (k.w[i].oom)
            goto done;
    for (int i = 0; i < k.threads; i++) {
        st.degenerate += k.w[i].degenerate;
        st.zero_uv_area += k.w[i].zero_uv_area;
        st.fans += k.w[i].fans;
        st.unreached += k.w[i].unreached;
    }
    rc = BG_OK;
done:
    arena_close(&ar);
    free(k.touched);
    free_workers(&k);
    if (stats)
        *stats = st;
    return rc;
}

/* ---- the renderer's frame and its exact inverse ---- */

void bgt_mikk_frame_at(const float *const tan[3], const float *const nrm[3], const double w[3],
                       bgt_mikk_frame *f)
{
    double s = 0.0;
    for (int a = 0; a < 3; a++) {
        f->t[a] = w[0] * tan[0][a] + w[1] * tan[1][a] + w[2] * tan[2][a];
        f->n[a] = w[0] * nrm[0][a] + w[1] * nrm[1][a] + w[2] * nrm[2][a];
    }
    s = w[0] * tan[0][3] + w[1] * tan[1][3] + w[2] * tan[2][3];
    const double *n = f->n, *t = f->t;
    f->b[0] = s * (n[1] * t[2] - n[2] * t[1]);
    f->b[1] = s * (n[2] * t[0] - n[0] * t[2]);
    f->b[2] = s * (n[0] * t[1] - n[1] * t[0]);
}

int bgt_mikk_decode(const bgt_mikk_frame *f, const double m[3], double out[3])
{
    double l2 = 0.0;
    for (int a = 0; a < 3; a++) {
        out[a] = m[0] * f->t[a] + m[1] * f->b[a] + m[2] * f->n[a];
        l2 += out[a] * out[a];
    }
    double l = sqrt(l2);
    if (!(isfinite(l) && l > 0.0)) {
        out[0] = out[1] = out[2] = 0.0;
        return -1;
    }
    for (int a = 0; a < 3; a++)
        out[a] /= l;
    return 0;
}

static void cross3(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

int bgt_mikk_encode(const bgt_mikk_frame *f, const double v[3], double m[3])
{
    double r0[3], r1[3], r2[3];
    cross3(f->b, f->n, r0);
    cross3(f->n, f->t, r1);
    cross3(f->t, f->b, r2);
    /* r_i . v = det(M) (M^-1 v)_i with M = [t b n] */
    double det = f->t[0] * r0[0] + f->t[1] * r0[1] + f->t[2] * r0[2];
    double s = det < 0.0 ? -1.0 : 1.0;
    m[0] = s * (r0[0] * v[0] + r0[1] * v[1] + r0[2] * v[2]);
    m[1] = s * (r1[0] * v[0] + r1[1] * v[1] + r1[2] * v[2]);
    m[2] = s * (r2[0] * v[0] + r2[1] * v[1] + r2[2] * v[2]);
    double l = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    if (!(isfinite(l) && l > 0.0 && det != 0.0 && isfinite(det))) {
        m[0] = m[1] = m[2] = 0.0;
        return -1;
    }
    m[0] /= l, m[1] /= l, m[2] /= l;
    return 0;
}
