/* SPDX-License-Identifier: MIT */
/* mikkTSpace per-corner tangents, our implementation of the published
 * description (see mikktspace.h for the rules and their sources). Sums and
 * projections run in double and are rounded to float once at the end. */
#include "mesh/mikktspace.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "common/parallel.h"
#include "mesh/mesh_sort.h"

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
/* a minus its component along the unit n, normalized when it has a direction */
static d3 d3_tangential(d3 a, d3 n) { return d3_unit_if(d3_sub(a, d3_scale(n, d3_dot(n, a)))); }

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

typedef struct mikk {
    const bgt_mikk_mesh *m;
    size_t T;
    uint32_t *weld;   /* per vertex: representative vertex of its welded class */
    uint8_t *flags;   /* per triangle */
    d3 *os, *ot;      /* per triangle: unit dP/du and dP/dv directions, oriented */
    f3 *fos, *fot;    /* the same in float (the split test of rule 5) */
    int32_t *nb;      /* per triangle edge k (corner k to k+1): neighbour, -1 */
    int32_t *grp;     /* per corner: fan, -1 */
    /* fans */
    uint32_t *g_vert;
    uint8_t *g_pres;
    size_t *g_start, *g_count;
    size_t groups;
    int32_t *members; /* fan members, fans stored one after the other */
    size_t nmembers;
    int32_t *stack;
} mikk;

static uint32_t wv(const mikk *k, size_t corner) { return k->weld[k->m->indices[corner]]; }

static d3 pos(const bgt_mikk_mesh *m, uint32_t i) { return (d3){m->px[i], m->py[i], m->pz[i]}; }
static d3 nrm(const bgt_mikk_mesh *m, uint32_t i) { return (d3){m->nx[i], m->ny[i], m->nz[i]}; }
static f3 fpos(const bgt_mikk_mesh *m, uint32_t i) { return (f3){m->px[i], m->py[i], m->pz[i]}; }
static f3 fnrm(const bgt_mikk_mesh *m, uint32_t i) { return (f3){m->nx[i], m->ny[i], m->nz[i]}; }

/* Rule 3 in float for the split test: dP/du = dv2 e1 - dv1 e2 and
 * dP/dv = -du2 e1 + du1 e2 (UV differences and edges rounded to float first),
 * scaled by (sign of the float area) / length. */
static void float_directions(mikk *k, size_t t)
{
    const bgt_mikk_mesh *m = k->m;
    const uint32_t *ix = m->indices + 3 * t;
    float du1 = m->u[ix[1]] - m->u[ix[0]], dv1 = m->v[ix[1]] - m->v[ix[0]];
    float du2 = m->u[ix[2]] - m->u[ix[0]], dv2 = m->v[ix[2]] - m->v[ix[0]];
    f3 p0 = fpos(m, ix[0]);
    f3 e1 = f3_sub(fpos(m, ix[1]), p0), e2 = f3_sub(fpos(m, ix[2]), p0);
    float area = du1 * dv2 - dv1 * du2;
    f3 s = f3_sub(f3_scale(dv2, e1), f3_scale(dv1, e2));
    f3 a = f3_scale(-du2, e1), b = f3_scale(du1, e2);
    f3 tt = {a.x + b.x, a.y + b.y, a.z + b.z};
    k->fos[t] = k->fot[t] = (f3){0.0f, 0.0f, 0.0f};
    if (!(fabsf(area) > FLT_MIN))
        return;
    float sg = area > 0.0f ? 1.0f : -1.0f;
    float ls = sqrtf(f3_dot(s, s)), lt = sqrtf(f3_dot(tt, tt));
    if (ls > FLT_MIN)
        k->fos[t] = f3_scale(sg / ls, s);
    if (lt > FLT_MIN)
        k->fot[t] = f3_scale(sg / lt, tt);
}

/* ---- 1. welding ---- */

/* k: the 8 attributes as keys (-0 welds with +0, as float == does), then
 * the vertex index */
typedef struct vkey {
    uint32_t k[9];
    uint32_t nan; /* some attribute is NaN: equal to nothing */
} vkey;

static int cmp_vkey(const void *a, const void *b)
{
    return mesh_keys_cmp(((const vkey *)a)->k, ((const vkey *)b)->k, 9);
}

/* weld[i] = smallest vertex index with the same attributes; returns the
 * number of distinct referenced vertices, or (size_t)-1 out of memory. */
static size_t weld_vertices(mikk *k)
{
    const bgt_mikk_mesh *m = k->m;
    size_t nv = m->vertex_count;
    uint8_t *used = calloc(nv ? nv : 1, 1);
    if (!used)
        return (size_t)-1;
    for (size_t c = 0; c < 3 * k->T; c++)
        used[m->indices[c]] = 1;
    size_t nu = 0;
    for (size_t i = 0; i < nv; i++)
        nu += used[i];
    vkey *keys = malloc((nu ? nu : 1) * sizeof *keys);
    if (!keys) {
        free(used);
        return (size_t)-1;
    }
    nu = 0;
    for (size_t i = 0; i < nv; i++) {
        k->weld[i] = (uint32_t)i;
        if (!used[i])
            continue;
        const float f[8] = {m->px[i], m->py[i], m->pz[i], m->nx[i],
                            m->ny[i], m->nz[i], m->u[i],  m->v[i]};
        vkey *q = keys + nu++;
        q->k[8] = (uint32_t)i;
        q->nan = 0;
        for (int j = 0; j < 8; j++) {
            q->k[j] = mesh_float_key(f[j]);
            q->nan |= isnan(f[j]) ? 1u : 0u;
        }
    }
    free(used);
    qsort(keys, nu, sizeof *keys, cmp_vkey);
    size_t classes = 0;
    for (size_t j = 0; j < nu; j++) {
        const vkey *q = keys + j;
        if (j > 0 && !q->nan && !q[-1].nan && mesh_keys_cmp(q->k, q[-1].k, 8) == 0) {
            k->weld[q->k[8]] = k->weld[q[-1].k[8]];
        } else {
            k->weld[q->k[8]] = q->k[8]; /* first of its run = smallest index */
            classes++;
        }
    }
    free(keys);
    return classes;
}

/* ---- 2./3. triangle classification and UV directions ---- */

static void classify(mikk *k, bgt_mikk_stats *st)
{
    const bgt_mikk_mesh *m = k->m;
    for (size_t t = 0; t < k->T; t++) {
        const uint32_t *ix = m->indices + 3 * t;
        d3 p0 = pos(m, ix[0]), p1 = pos(m, ix[1]), p2 = pos(m, ix[2]);
        k->os[t] = k->ot[t] = (d3){0, 0, 0};
        k->fos[t] = k->fot[t] = (f3){0.0f, 0.0f, 0.0f};
        k->flags[t] = 0;
        int finite = isfinite(p0.x) && isfinite(p0.y) && isfinite(p0.z) && isfinite(p1.x) &&
                     isfinite(p1.y) && isfinite(p1.z) && isfinite(p2.x) && isfinite(p2.y) &&
                     isfinite(p2.z);
        int eq01 = p0.x == p1.x && p0.y == p1.y && p0.z == p1.z;
        int eq02 = p0.x == p2.x && p0.y == p2.y && p0.z == p2.z;
        int eq12 = p1.x == p2.x && p1.y == p2.y && p1.z == p2.z;
        if (!finite || eq01 || eq02 || eq12) {
            k->flags[t] = TRI_DEGENERATE;
            st->degenerate++;
            continue;
        }
        double du1 = (double)m->u[ix[1]] - m->u[ix[0]], dv1 = (double)m->v[ix[1]] - m->v[ix[0]];
        double du2 = (double)m->u[ix[2]] - m->u[ix[0]], dv2 = (double)m->v[ix[2]] - m->v[ix[0]];
        double area = du1 * dv2 - du2 * dv1;
        d3 e1 = d3_sub(p1, p0), e2 = d3_sub(p2, p0);
        d3 s = d3_sub(d3_scale(e1, dv2), d3_scale(e2, dv1)); /* area * dP/du */
        d3 tt = d3_sub(d3_scale(e2, du1), d3_scale(e1, du2)); /* area * dP/dv */
        uint8_t f = area > 0.0 ? TRI_PRESERVING : 0;
        int any = 1;
        if (fabs(area) > FLT_MIN) {
            double sg = area > 0.0 ? 1.0 : -1.0;
            double ls = sqrt(d3_dot(s, s)), lt = sqrt(d3_dot(tt, tt));
            if (ls > FLT_MIN)
                k->os[t] = d3_scale(s, sg / ls);
            if (lt > FLT_MIN)
                k->ot[t] = d3_scale(tt, sg / lt);
            double ms = ls / fabs(area), mt = lt / fabs(area);
            any = !(ms > FLT_MIN && mt > FLT_MIN);
        }
        if (any) {
            f |= TRI_ANY;
            st->zero_uv_area++;
        }
        float_directions(k, t);
        k->flags[t] = f;
    }
}

/* ---- 4a. edge neighbours ---- */

/* k: lower and higher welded vertex, triangle, edge number in it */
typedef struct edge {
    uint32_t k[4];
} edge;
enum { E_LO, E_HI, E_TRI, E_K };

static int cmp_edge(const void *a, const void *b)
{
    return mesh_keys_cmp(((const edge *)a)->k, ((const edge *)b)->k, 4);
}

/* Stable LSD radix sort of e[0..n) by (k[E_LO], k[E_HI]), 16-bit digits, low
 * digit of E_HI first: the edges are made in (triangle, edge) order, so the
 * result is the order of cmp_edge's full key, which qsort gave (the keys are
 * distinct, so any correct sort gives this one order): the same neighbours,
 * without qsort's comparator calls (42% of the instructions of 180k
 * triangles under callgrind). tmp holds n edges. */
static void sort_edges(edge *e, edge *tmp, size_t n)
{
    static const int field[4] = {E_HI, E_HI, E_LO, E_LO};
    size_t *count = calloc(65536, sizeof *count);
    if (!count) {
        qsort(e, n, sizeof *e, cmp_edge);
        return;
    }
    edge *src = e, *dst = tmp;
    for (int pass = 0; pass < 4; pass++) {
        const int f = field[pass], sh = (pass & 1) ? 16 : 0;
        memset(count, 0, 65536 * sizeof *count);
        for (size_t i = 0; i < n; i++)
            count[(src[i].k[f] >> sh) & 0xffff]++;
        size_t sum = 0;
        for (size_t d = 0; d < 65536; d++) {
            size_t c = count[d];
            count[d] = sum;
            sum += c;
        }
        for (size_t i = 0; i < n; i++)
            dst[count[(src[i].k[f] >> sh) & 0xffff]++] = src[i];
        edge *t = src;
        src = dst, dst = t;
    }
    free(count); /* 4 passes: the result is back in e */
}

static int build_neighbours(mikk *k)
{
    size_t T = k->T, n = 0;
    for (size_t t = 0; t < T; t++)
        n += (k->flags[t] & TRI_DEGENERATE) ? 0 : 3;
    edge *e = malloc((n ? n : 1) * sizeof *e);
    if (!e)
        return -1;
    n = 0;
    for (size_t t = 0; t < T; t++) {
        k->nb[3 * t] = k->nb[3 * t + 1] = k->nb[3 * t + 2] = -1;
        if (k->flags[t] & TRI_DEGENERATE)
            continue;
        for (int c = 0; c < 3; c++) {
            uint32_t a = wv(k, 3 * t + (size_t)c), b = wv(k, 3 * t + (size_t)((c + 1) % 3));
            e[n++] = (edge){{a < b ? a : b, a < b ? b : a, (uint32_t)t, (uint32_t)c}};
        }
    }
    edge *tmp = malloc((n ? n : 1) * sizeof *tmp);
    if (tmp) {
        sort_edges(e, tmp, n);
        free(tmp);
    } else {
        qsort(e, n, sizeof *e, cmp_edge);
    }
    for (size_t i = 0; i < n; i++) {
        const uint32_t *ei = e[i].k;
        size_t ca = 3 * (size_t)ei[E_TRI] + ei[E_K];
        if (k->nb[ca] >= 0)
            continue;
        uint32_t from = wv(k, ca), to = wv(k, 3 * (size_t)ei[E_TRI] + (ei[E_K] + 1) % 3);
        for (size_t j = i + 1; j < n && mesh_keys_cmp(e[j].k, ei, 2) == 0; j++) {
            const uint32_t *ej = e[j].k;
            size_t cb = 3 * (size_t)ej[E_TRI] + ej[E_K];
            uint32_t bf = wv(k, cb), bt = wv(k, 3 * (size_t)ej[E_TRI] + (ej[E_K] + 1) % 3);
            if (bf == to && bt == from && k->nb[cb] < 0) {
                k->nb[ca] = (int32_t)ej[E_TRI];
                k->nb[cb] = (int32_t)ei[E_TRI];
                break;
            }
        }
    }
    free(e);
    return 0;
}

/* ---- 4b. fans ---- */

static int corner_of(const mikk *k, size_t t, uint32_t vert)
{
    for (int c = 0; c < 3; c++)
        if (wv(k, 3 * t + (size_t)c) == vert)
            return c;
    return -1;
}

/* Grow fan g from its seed triangle: depth first, first across the edge that
 * leaves the fan's corner forward (corner c to c+1), then across the edge that
 * arrives at it (c-1 to c). The traversal order matters only for zero-UV-area
 * triangles, which take the orientation of the first fan that reaches them. */
static void grow_fan(mikk *k, size_t g, size_t seed, int seed_corner)
{
    uint32_t vert = k->g_vert[g];
    size_t sp = 0;
    k->grp[3 * seed + (size_t)seed_corner] = (int32_t)g;
    k->members[k->nmembers++] = (int32_t)seed;
    k->g_count[g]++;
    /* push the second edge first so that the first is explored first */
    int32_t r = k->nb[3 * seed + (size_t)((seed_corner + 2) % 3)];
    int32_t l = k->nb[3 * seed + (size_t)seed_corner];
    if (r >= 0)
        k->stack[sp++] = r;
    if (l >= 0)
        k->stack[sp++] = l;
    while (sp > 0) {
        size_t t = (size_t)k->stack[--sp];
        int c = corner_of(k, t, vert);
        if (c < 0)
            continue; /* cannot happen: the shared edge holds the vertex */
        int32_t *slot = &k->grp[3 * t + (size_t)c];
        if (*slot >= 0)
            continue; /* already in this fan, or in another */
        if (k->flags[t] & TRI_ANY) {
            const int32_t *gs = k->grp + 3 * t;
            if (gs[0] < 0 && gs[1] < 0 && gs[2] < 0)
                k->flags[t] = (uint8_t)((k->flags[t] & ~TRI_PRESERVING) |
                                        (k->g_pres[g] ? TRI_PRESERVING : 0));
        }
        if (((k->flags[t] & TRI_PRESERVING) != 0) != (k->g_pres[g] != 0))
            continue;
        *slot = (int32_t)g;
        k->members[k->nmembers++] = (int32_t)t;
        k->g_count[g]++;
        r = k->nb[3 * t + (size_t)((c + 2) % 3)];
        l = k->nb[3 * t + (size_t)c];
        if (r >= 0)
            k->stack[sp++] = r;
        if (l >= 0)
            k->stack[sp++] = l;
    }
}

static void build_fans(mikk *k)
{
    for (size_t c = 0; c < 3 * k->T; c++)
        k->grp[c] = -1;
    for (size_t t = 0; t < k->T; t++) {
        if (k->flags[t] & (TRI_DEGENERATE | TRI_ANY))
            continue;
        for (int c = 0; c < 3; c++) {
            if (k->grp[3 * t + (size_t)c] >= 0)
                continue;
            size_t g = k->groups++;
            k->g_vert[g] = wv(k, 3 * t + (size_t)c);
            k->g_pres[g] = (k->flags[t] & TRI_PRESERVING) != 0;
            k->g_start[g] = k->nmembers;
            k->g_count[g] = 0;
            grow_fan(k, g, t, c);
        }
    }
}

/* ---- 5. tangent of a (sub)fan ---- */

/* Corner angle at corner c of triangle t, between the edges projected onto
 * the plane orthogonal to n. */
static double projected_angle(const mikk *k, size_t t, int c, d3 n)
{
    const bgt_mikk_mesh *m = k->m;
    const uint32_t *ix = m->indices + 3 * t;
    d3 p = pos(m, ix[c]);
    d3 a = d3_tangential(d3_sub(pos(m, ix[(c + 2) % 3]), p), n);
    d3 b = d3_tangential(d3_sub(pos(m, ix[(c + 1) % 3]), p), n);
    double cs = d3_dot(a, b);
    cs = cs < -1.0 ? -1.0 : cs > 1.0 ? 1.0 : cs;
    return acos(cs);
}

static d3 fan_tangent(const mikk *k, const int32_t *tris, size_t n, uint32_t vert)
{
    const bgt_mikk_mesh *m = k->m;
    d3 sum = {0, 0, 0};
    for (size_t i = 0; i < n; i++) {
        size_t t = (size_t)tris[i];
        if (k->flags[t] & TRI_ANY)
            continue; /* no direction of its own */
        int c = corner_of(k, t, vert);
        d3 nn = nrm(m, m->indices[3 * t + (size_t)c]);
        d3 os = d3_tangential(k->os[t], nn);
        sum = d3_add(sum, d3_scale(os, projected_angle(k, t, c, nn)));
    }
    return d3_unit_if(sum);
}

/* Split fan g where projected directions point exactly opposite (the
 * reference's angular threshold at its default of 180 degrees) and write the
 * tangents of its corners. */
#define MIKK_SPLIT_MAX 256
static void fan_output(const mikk *k, size_t g, float *out, int32_t *scratch)
{
    const bgt_mikk_mesh *m = k->m;
    const int32_t *mem = k->members + k->g_start[g];
    size_t n = k->g_count[g];
    uint32_t vert = k->g_vert[g];
    float w = k->g_pres[g] ? 1.0f : -1.0f;
    if (n > MIKK_SPLIT_MAX) {
        d3 tg = fan_tangent(k, mem, n, vert);
        for (size_t i = 0; i < n; i++) {
            size_t c = 3 * (size_t)mem[i] + (size_t)corner_of(k, (size_t)mem[i], vert);
            out[4 * c] = (float)tg.x, out[4 * c + 1] = (float)tg.y, out[4 * c + 2] = (float)tg.z;
            out[4 * c + 3] = w;
        }
        return;
    }
    f3 ps[MIKK_SPLIT_MAX], pt[MIKK_SPLIT_MAX];
    for (size_t i = 0; i < n; i++) {
        size_t t = (size_t)mem[i];
        f3 nn = fnrm(m, m->indices[3 * t + (size_t)corner_of(k, t, vert)]);
        ps[i] = f3_tangential(k->fos[t], nn);
        pt[i] = f3_tangential(k->fot[t], nn);
    }
    /* scratch: member lists of the distinct subfans found so far, each
     * preceded by its length; tangents alongside. */
    size_t nsub = 0, used = 0;
    size_t sub_off[MIKK_SPLIT_MAX];
    d3 sub_tan[MIKK_SPLIT_MAX];
    /* cos(180 deg) rounded to float, the reference's default threshold: -1,
     * so only a float cosine that rounds to -1 splits */
    const float pi_f = 3.14159265358979323846f;
    const float opposite = (float)cos((180.0f * pi_f) / 180.0f);
    for (size_t i = 0; i < n; i++) {
        size_t t = (size_t)mem[i];
        int32_t *list = scratch + used + 1;
        size_t cnt = 0;
        for (size_t j = 0; j < n; j++) {
            size_t u = (size_t)mem[j];
            int any = ((k->flags[t] | k->flags[u]) & TRI_ANY) != 0;
            if (any || i == j ||
                (f3_dot(ps[i], ps[j]) > opposite && f3_dot(pt[i], pt[j]) > opposite))
                list[cnt++] = (int32_t)u;
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
            sub_tan[nsub] = fan_tangent(k, list, cnt, vert);
            used += cnt + 1;
            nsub++;
        }
        size_t c = 3 * t + (size_t)corner_of(k, t, vert);
        out[4 * c] = (float)sub_tan[s].x, out[4 * c + 1] = (float)sub_tan[s].y;
        out[4 * c + 2] = (float)sub_tan[s].z, out[4 * c + 3] = w;
    }
}

/* The fans in parallel: every corner belongs to one fan (its group), so each
 * fan writes only its own corners and the result does not depend on the
 * threads; each worker has its own scratch. */
#define MIKK_SCRATCH ((size_t)MIKK_SPLIT_MAX * (MIKK_SPLIT_MAX + 1))
typedef struct fan_job {
    const mikk *k;
    float *out;
    int32_t *scratch; /* MIKK_SCRATCH per worker */
} fan_job;
static void fan_chunk(void *ctx, size_t b, size_t e, int worker)
{
    const fan_job *j = ctx;
    for (size_t g = b; g < e; g++)
        fan_output(j->k, g, j->out, j->scratch + (size_t)worker * MIKK_SCRATCH);
}

bg_status bgt_mikk_tangents(const bgt_mikk_mesh *m, float *out, bgt_mikk_stats *stats)
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
    for (size_t c = 0; c < 3 * T; c++)
        if (m->indices[c] >= m->vertex_count)
            return BG_ERR_INVALID_ARGUMENT;

    mikk k;
    memset(&k, 0, sizeof k);
    k.m = m;
    k.T = T;
    size_t nv = m->vertex_count;
    k.weld = malloc(nv * sizeof *k.weld);
    k.flags = malloc(T);
    k.os = malloc(T * sizeof *k.os);
    k.ot = malloc(T * sizeof *k.ot);
    k.fos = malloc(T * sizeof *k.fos);
    k.fot = malloc(T * sizeof *k.fot);
    k.nb = malloc(3 * T * sizeof *k.nb);
    k.grp = malloc(3 * T * sizeof *k.grp);
    k.g_vert = malloc(3 * T * sizeof *k.g_vert);
    k.g_pres = malloc(3 * T);
    k.g_start = malloc(3 * T * sizeof *k.g_start);
    k.g_count = malloc(3 * T * sizeof *k.g_count);
    k.members = malloc(3 * T * sizeof *k.members);
    k.stack = malloc((2 * T + 4) * sizeof *k.stack);
    const int threads = bgt_threads_default();
    int32_t *scratch = malloc((size_t)threads * MIKK_SCRATCH * sizeof *scratch);
    int32_t *first = NULL;
    bg_status rc = BG_ERR_OUT_OF_MEMORY;
    if (!k.weld || !k.flags || !k.os || !k.ot || !k.fos || !k.fot || !k.nb || !k.grp || !k.g_vert || !k.g_pres ||
        !k.g_start || !k.g_count || !k.members || !k.stack || !scratch)
        goto done;
    st.welded_vertices = weld_vertices(&k);
    if (st.welded_vertices == (size_t)-1)
        goto done;
    classify(&k, &st);
    if (build_neighbours(&k) != 0)
        goto done;
    build_fans(&k);
    st.fans = k.groups;

    /* 6. default frame for corners no fan reaches, then the fans */
    for (size_t c = 0; c < 3 * T; c++) {
        out[4 * c] = 1.0f, out[4 * c + 1] = 0.0f, out[4 * c + 2] = 0.0f, out[4 * c + 3] = -1.0f;
    }
    fan_job fj = {&k, out, scratch};
    bgt_parallel_for(k.groups, 4096, threads, fan_chunk, &fj);
    for (size_t c = 0; c < 3 * T; c++)
        if (!(k.flags[c / 3] & TRI_DEGENERATE) && k.grp[c] < 0)
            st.unreached++;

    /* 2. degenerate triangles inherit from the first non-degenerate corner
     * at the same welded vertex */
    if (st.degenerate) {
        first = malloc(nv * sizeof *first);
        if (!first)
            goto done;
        for (size_t i = 0; i < nv; i++)
            first[i] = -1;
        for (size_t c = 3 * T; c-- > 0;)
            if (!(k.flags[c / 3] & TRI_DEGENERATE))
                first[wv(&k, c)] = (int32_t)c;
        for (size_t c = 0; c < 3 * T; c++) {
            if (!(k.flags[c / 3] & TRI_DEGENERATE))
                continue;
            int32_t s = first[wv(&k, c)];
            if (s >= 0)
                memcpy(out + 4 * c, out + 4 * (size_t)s, 4 * sizeof *out);
        }
    }
    rc = BG_OK;
done:
    free(k.weld);
    free(k.flags);
    free(k.os);
    free(k.ot);
    free(k.fos);
    free(k.fot);
    free(k.nb);
    free(k.grp);
    free(k.g_vert);
    free(k.g_pres);
    free(k.g_start);
    free(k.g_count);
    free(k.members);
    free(k.stack);
    free(scratch);
    free(first);
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
