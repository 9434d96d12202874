/* SPDX-License-Identifier: MIT */
/* The triangulated isosurface of the paper's first scene (Mikkelsen 2010,
 * section 6: "a triangulated isosurface with a single point light") built by
 * marching tetrahedra, which needs no case tables: each grid cube is cut into
 * six tetrahedra around its main diagonal, and a tetrahedron crosses the
 * surface in 0, 1 or 2 triangles. Vertex normals come from the field gradient
 * and are interpolated and renormalized per pixel, as the paper does for
 * `surf_norm` (section 4, Figure 1b). A median-split BVH serves the rays. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "render/render_internal.h"

/* Implicit fields: negative inside, positive outside, so grad F points out. */
static double field_blob(const double p[3])
{
    /* Four Gaussian metaballs: a lumpy closed surface with regions of every
     * curvature sign, which is what shows the faceting of Figure 1(a). */
    static const double c[4][4] = {
        {-0.55, -0.20, 0.00, 1.0},
        {0.55, 0.00, 0.05, 1.0},
        {-0.05, 0.60, -0.10, 0.9},
        {0.05, -0.55, 0.35, 0.85},
    };
    double s = 0.0;
    for (int i = 0; i < 4; i++) {
        double dx = p[0] - c[i][0], dy = p[1] - c[i][1], dz = p[2] - c[i][2];
        s += c[i][3] * exp(-4.0 * (dx * dx + dy * dy + dz * dz));
    }
    return 0.4 - s;
}

static double field_torus(const double p[3])
{
    /* Tilted 60 degrees about x so that the hole faces the camera. */
    const double ca = 0.5, sa = 0.8660254037844386;
    double x = p[0], y = ca * p[1] - sa * p[2], z = sa * p[1] + ca * p[2];
    double R = 0.8, r = 0.38;
    double q = sqrt(x * x + z * z) - R;
    return q * q + y * y - r * r;
}

static double field(render_shape s, const double p[3])
{
    return s == RENDER_TORUS ? field_torus(p) : field_blob(p);
}

static void field_normal(render_shape s, const double p[3], float n[3])
{
    /* Central differences in double: the normal only needs a few digits, and
     * one formula serves every field. */
    const double h = 1e-5;
    double g[3];
    for (int a = 0; a < 3; a++) {
        double q[3] = {p[0], p[1], p[2]}, r[3] = {p[0], p[1], p[2]};
        q[a] += h;
        r[a] -= h;
        g[a] = (field(s, q) - field(s, r)) / (q[a] - r[a]);
    }
    double l = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    if (!(l > 0))
        l = 1, g[0] = 0, g[1] = 0, g[2] = 1;
    for (int a = 0; a < 3; a++)
        n[a] = (float)(g[a] / l);
}

typedef struct mesh_builder {
    float *pos, *nrm;
    size_t n, cap;
    int failed;
} mesh_builder;

static void edge_point(const double *pa, double fa, const double *pb, double fb,
                       double out[3])
{
    double t = fa / (fa - fb);
    for (int a = 0; a < 3; a++)
        out[a] = pa[a] + t * (pb[a] - pa[a]);
}

static void emit(mesh_builder *b, render_shape s, const double v[3][3])
{
    double e1[3], e2[3], c[3];
    for (int a = 0; a < 3; a++)
        e1[a] = v[1][a] - v[0][a], e2[a] = v[2][a] - v[0][a];
    c[0] = e1[1] * e2[2] - e1[2] * e2[1];
    c[1] = e1[2] * e2[0] - e1[0] * e2[2];
    c[2] = e1[0] * e2[1] - e1[1] * e2[0];
    if (!(c[0] * c[0] + c[1] * c[1] + c[2] * c[2] > 1e-24))
        return; /* a sliver where the surface passes through a grid vertex */
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 4096;
        float *p = realloc(b->pos, cap * 9 * sizeof *p);
        if (!p) {
            b->failed = 1;
            return;
        }
        b->pos = p;
        float *q = realloc(b->nrm, cap * 9 * sizeof *q);
        if (!q) {
            b->failed = 1;
            return;
        }
        b->nrm = q;
        b->cap = cap;
    }
    float nv[3][3];
    for (int k = 0; k < 3; k++)
        field_normal(s, v[k], nv[k]);
    /* Orient every triangle like its vertex normals (outward), so the face
     * normal of the flat method (Figure 1a) and the interpolated normal agree. */
    double side = 0;
    for (int k = 0; k < 3; k++)
        side += c[0] * nv[k][0] + c[1] * nv[k][1] + c[2] * nv[k][2];
    int order[3] = {0, 1, 2};
    if (side < 0)
        order[1] = 2, order[2] = 1;
    float *P = b->pos + b->n * 9, *N = b->nrm + b->n * 9;
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 3; a++) {
            P[k * 3 + a] = (float)v[order[k]][a];
            N[k * 3 + a] = nv[order[k]][a];
        }
    b->n++;
}

/* One tetrahedron (Figure-free classic: 1 or 3 corners inside -> a triangle,
 * 2 inside -> a quad split in two). */
static void tetra(mesh_builder *b, render_shape s, const double *p[4], const double f[4])
{
    int in[4], nin = 0, out[4], nout = 0;
    for (int i = 0; i < 4; i++) {
        if (f[i] < 0)
            in[nin++] = i;
        else
            out[nout++] = i;
    }
    double v[4][3];
    if (nin == 1 || nin == 3) {
        int lone = nin == 1 ? in[0] : out[0];
        const int *other = nin == 1 ? out : in;
        for (int k = 0; k < 3; k++)
            edge_point(p[lone], f[lone], p[other[k]], f[other[k]], v[k]);
        emit(b, s, (const double(*)[3])v);
    } else if (nin == 2) {
        int a = in[0], bb = in[1], c = out[0], d = out[1];
        edge_point(p[a], f[a], p[c], f[c], v[0]);
        edge_point(p[a], f[a], p[d], f[d], v[1]);
        edge_point(p[bb], f[bb], p[d], f[d], v[2]);
        edge_point(p[bb], f[bb], p[c], f[c], v[3]);
        double t1[3][3], t2[3][3];
        memcpy(t1[0], v[0], sizeof t1[0]);
        memcpy(t1[1], v[1], sizeof t1[0]);
        memcpy(t1[2], v[2], sizeof t1[0]);
        memcpy(t2[0], v[0], sizeof t1[0]);
        memcpy(t2[1], v[2], sizeof t1[0]);
        memcpy(t2[2], v[3], sizeof t1[0]);
        emit(b, s, (const double(*)[3])t1);
        emit(b, s, (const double(*)[3])t2);
    }
}

/* ---- BVH ---- */
typedef struct bvh_build {
    render_bvh_node *nodes;
    size_t nnodes;
    int *idx;
    const float *cen; /* 3 per triangle */
    const float *pos;
} bvh_build;

static int cmp_axis;
static const float *cmp_cen;
static int cmp_idx(const void *a, const void *b)
{
    float x = cmp_cen[*(const int *)a * 3 + cmp_axis], y = cmp_cen[*(const int *)b * 3 + cmp_axis];
    if (x != y)
        return x < y ? -1 : 1;
    return *(const int *)a - *(const int *)b; /* stable, deterministic order */
}

static void bvh_node(bvh_build *B, int node, int first, int count)
{
    render_bvh_node *nd = &B->nodes[node];
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    float clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = first; i < first + count; i++) {
        const float *P = B->pos + (size_t)B->idx[i] * 9;
        for (int k = 0; k < 9; k++) {
            lo[k % 3] = fminf(lo[k % 3], P[k]);
            hi[k % 3] = fmaxf(hi[k % 3], P[k]);
        }
        for (int a = 0; a < 3; a++) {
            float c = B->cen[B->idx[i] * 3 + a];
            clo[a] = fminf(clo[a], c);
            chi[a] = fmaxf(chi[a], c);
        }
    }
    memcpy(nd->lo, lo, sizeof lo);
    memcpy(nd->hi, hi, sizeof hi);
    if (count <= 4) {
        nd->first = first, nd->count = count, nd->left = -1;
        return;
    }
    int axis = 0;
    for (int a = 1; a < 3; a++)
        if (chi[a] - clo[a] > chi[axis] - clo[axis])
            axis = a;
    /* qsort is not reentrant with a comparator context in C11; the build runs
     * once, single-threaded, before any rendering. */
    cmp_axis = axis;
    cmp_cen = B->cen;
    qsort(B->idx + first, (size_t)count, sizeof(int), cmp_idx);
    int half = count / 2, left = (int)B->nnodes;
    B->nnodes += 2;
    nd->left = left, nd->first = -1, nd->count = 0;
    bvh_node(B, left, first, half);
    bvh_node(B, left + 1, first + half, count - half);
}

bg_status render_mesh_build(render_shape shape, int grid, render_mesh *m)
{
    memset(m, 0, sizeof *m);
    const double B = shape == RENDER_TORUS ? 1.35 : 1.3;
    int N = grid, S = grid + 1;
    double *f = malloc((size_t)S * S * S * sizeof *f);
    if (!f)
        return BG_ERR_OUT_OF_MEMORY;
    for (int k = 0; k < S; k++)
        for (int j = 0; j < S; j++)
            for (int i = 0; i < S; i++) {
                double p[3] = {-B + 2 * B * i / N, -B + 2 * B * j / N, -B + 2 * B * k / N};
                f[((size_t)k * S + j) * S + i] = field(shape, p);
            }
    /* Six tetrahedra around the diagonal 0-6; neighbouring cubes cut their
     * shared face along the same diagonal, so the surface has no cracks. */
    static const int tets[6][4] = {{0, 5, 1, 6}, {0, 1, 2, 6}, {0, 2, 3, 6},
                                   {0, 3, 7, 6}, {0, 7, 4, 6}, {0, 4, 5, 6}};
    static const int corner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                     {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    mesh_builder b = {0};
    for (int k = 0; k < N && !b.failed; k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                double cp[8][3], cf[8];
                for (int c = 0; c < 8; c++) {
                    int ii = i + corner[c][0], jj = j + corner[c][1], kk = k + corner[c][2];
                    cp[c][0] = -B + 2 * B * ii / N;
                    cp[c][1] = -B + 2 * B * jj / N;
                    cp[c][2] = -B + 2 * B * kk / N;
                    cf[c] = f[((size_t)kk * S + jj) * S + ii];
                }
                for (int t = 0; t < 6; t++) {
                    const double *tp[4];
                    double tf[4];
                    for (int v = 0; v < 4; v++)
                        tp[v] = cp[tets[t][v]], tf[v] = cf[tets[t][v]];
                    tetra(&b, shape, tp, tf);
                }
            }
    free(f);
    if (b.failed || b.n == 0) {
        free(b.pos);
        free(b.nrm);
        return BG_ERR_OUT_OF_MEMORY;
    }
    bg_status rc = render_mesh_adopt(m, b.n, b.pos, b.nrm, NULL, NULL);
    return rc != BG_OK ? rc : render_mesh_bvh(m);
}

static void reorder(float **arr, size_t per, const int *idx, size_t n, float *tmp)
{
    if (!*arr)
        return;
    for (size_t t = 0; t < n; t++)
        memcpy(tmp + t * per, *arr + (size_t)idx[t] * per, per * sizeof(float));
    *arr = tmp; /* the caller frees the old array */
}

static void face_normals(render_mesh *m);

bg_status render_mesh_adopt(render_mesh *m, size_t n, float *pos, float *nrm, float *uv,
                            float *tan)
{
    memset(m, 0, sizeof *m);
    m->pos = pos, m->nrm = nrm, m->uv = uv, m->tan = tan, m->ntri = n;
    m->face = malloc((n ? n : 1) * 3 * sizeof *m->face);
    if (!m->face) {
        render_mesh_free(m);
        return BG_ERR_OUT_OF_MEMORY;
    }
    face_normals(m);
    return BG_OK;
}

bg_status render_mesh_bvh(render_mesh *m)
{
    size_t n = m->ntri;
    float *pos = m->pos, *uv = m->uv, *tan = m->tan;
    if (n > (size_t)(INT32_MAX / 2)) {
        render_mesh_free(m);
        return BG_ERR_OUT_OF_MEMORY;
    }
    {
        float *cen = malloc(n * 3 * sizeof *cen);
        int *idx = malloc(n * sizeof *idx);
        m->nodes = malloc(2 * n * sizeof *m->nodes);
        /* Scratch for the reordering, 12 floats per triangle (the widest array). */
        float *tmp[4] = {malloc(n * 9 * sizeof(float)), malloc(n * 9 * sizeof(float)),
                         uv ? malloc(n * 6 * sizeof(float)) : NULL,
                         tan ? malloc(n * 12 * sizeof(float)) : NULL};
        if (!cen || !idx || !m->nodes || !tmp[0] || !tmp[1] || (uv && !tmp[2]) || (tan && !tmp[3])) {
            free(cen);
            free(idx);
            for (int i = 0; i < 4; i++)
                free(tmp[i]);
            render_mesh_free(m);
            return BG_ERR_OUT_OF_MEMORY;
        }
        for (size_t t = 0; t < n; t++) {
            idx[t] = (int)t;
            for (int a = 0; a < 3; a++)
                cen[t * 3 + a] = (pos[t * 9 + a] + pos[t * 9 + 3 + a] + pos[t * 9 + 6 + a]) / 3;
        }
        bvh_build bb = {m->nodes, 1, idx, cen, pos};
        bvh_node(&bb, 0, 0, (int)n);
        m->nnodes = bb.nnodes;
        if (m->mat) {
            /* the material ids follow their triangles (the scratch cen holds n * 3 floats) */
            uint32_t *mt = (uint32_t *)(void *)cen;
            for (size_t t = 0; t < n; t++)
                mt[t] = m->mat[idx[t]];
            memcpy(m->mat, mt, n * sizeof *mt);
        }
        float **arrs[4] = {&m->pos, &m->nrm, &m->uv, &m->tan};
        static const size_t per[4] = {9, 9, 6, 12};
        for (int i = 0; i < 4; i++) {
            float *old = *arrs[i];
            reorder(arrs[i], per[i], idx, n, tmp[i]);
            if (old && old != *arrs[i])
                free(old);
        }
        free(cen);
        free(idx);
    }
    face_normals(m);
    return 0;
}

static void face_normals(render_mesh *m)
{
    for (size_t t = 0; t < m->ntri; t++) {
        const float *P = m->pos + t * 9;
        float e1[3] = {P[3] - P[0], P[4] - P[1], P[5] - P[2]};
        float e2[3] = {P[6] - P[0], P[7] - P[1], P[8] - P[2]};
        float c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                      e1[0] * e2[1] - e1[1] * e2[0]};
        float l = sqrtf(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        for (int a = 0; a < 3; a++)
            m->face[t * 3 + a] = l > 0 ? c[a] / l : 0.0f;
    }
}

void render_mesh_free(render_mesh *m)
{
    free(m->mat);
    free(m->uv);
    free(m->tan);
    free(m->pos);
    free(m->nrm);
    free(m->face);
    free(m->nodes);
    memset(m, 0, sizeof *m);
}

static int ray_box(const render_bvh_node *nd, const float o[3], const float inv[3], float tmax)
{
    float t0 = 0, t1 = tmax;
    for (int a = 0; a < 3; a++) {
        float ta = (nd->lo[a] - o[a]) * inv[a], tb = (nd->hi[a] - o[a]) * inv[a];
        if (ta > tb) {
            float x = ta;
            ta = tb, tb = x;
        }
        t0 = ta > t0 ? ta : t0;
        t1 = tb < t1 ? tb : t1;
        if (t0 > t1)
            return 0;
    }
    return 1;
}

int render_mesh_intersect(const render_mesh *m, const float o[3], const float d[3], float tmax,
                          render_hit *hit)
{
    float inv[3] = {1.0f / d[0], 1.0f / d[1], 1.0f / d[2]};
    int stack[64], sp = 0, found = 0;
    stack[sp++] = 0;
    while (sp > 0) {
        const render_bvh_node *nd = &m->nodes[stack[--sp]];
        if (!ray_box(nd, o, inv, tmax))
            continue;
        if (nd->left >= 0) {
            stack[sp++] = nd->left;
            stack[sp++] = nd->left + 1;
            continue;
        }
        for (int t = nd->first; t < nd->first + nd->count; t++) {
            /* Moller-Trumbore; the small tolerance on the barycentrics keeps
             * rays from slipping through shared edges. */
            const float *P = m->pos + (size_t)t * 9;
            float e1[3] = {P[3] - P[0], P[4] - P[1], P[5] - P[2]};
            float e2[3] = {P[6] - P[0], P[7] - P[1], P[8] - P[2]};
            float pv[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2],
                           d[0] * e2[1] - d[1] * e2[0]};
            float det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
            if (det == 0)
                continue;
            float id = 1.0f / det;
            float tv[3] = {o[0] - P[0], o[1] - P[1], o[2] - P[2]};
            float u = (tv[0] * pv[0] + tv[1] * pv[1] + tv[2] * pv[2]) * id;
            if (u < -1e-6f || u > 1 + 1e-6f)
                continue;
            float qv[3] = {tv[1] * e1[2] - tv[2] * e1[1], tv[2] * e1[0] - tv[0] * e1[2],
                           tv[0] * e1[1] - tv[1] * e1[0]};
            float v = (d[0] * qv[0] + d[1] * qv[1] + d[2] * qv[2]) * id;
            if (v < -1e-6f || u + v > 1 + 1e-6f)
                continue;
            float tt = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) * id;
            if (tt > 1e-6f && tt < tmax) {
                tmax = tt;
                hit->t = tt, hit->prim = t, hit->b1 = u, hit->b2 = v;
                found = 1;
            }
        }
    }
    return found;
}
