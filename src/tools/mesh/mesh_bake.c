/* SPDX-License-Identifier: MIT */
/* UV-space normal-map baker of `bumpgrad mesh --bake-normal-map`.
 *
 * Each texel centre inside a triangle's UV image gets barycentric weights;
 * position and vertex normal are interpolated with them, the solid height's
 * gradient is evaluated at that position and the interpolated normal is
 * perturbed with Listing 3 (Mikkelsen 2010): n' = normalize(n - grad_S h).
 * By default the height is band-limited to the texel's footprint on the
 * surface (its triangle's UV Jacobian gives the object-space size of a texel;
 * bg_perturb_height_footprint_batch fades out the octaves finer than that)
 * and taken at N x N stratified points of the texel whose normals are
 * averaged (docs/MESH.md, "Anti-aliasing"). No derivative of the UV map
 * enters the perturbation itself; UVs say where the result is stored, how
 * large a texel is and, for tangent space, in which frame it is expressed.
 *
 * Tangent space follows the mikkTSpace decoding convention: a renderer
 * interpolates the per-corner tangent t (bgt_mikk_tangents, or the file's),
 * the sign and the normal n, all unnormalized after interpolation, and uses
 * b = sign * cross(n, t), n_out = normalize(m.x t + m.y b + m.z n)
 * (mikktspace.h, "pixel shader (fast transform out)"). The baker stores
 * m = normalize(M^-1 n') with M = [t b n] built from the same interpolated
 * vectors (bgt_mikk_encode, the sampler of mikktspace.h), so that decoding
 * gives back n' exactly (up to quantization). */
#include <math.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include "bumpgrad/framework.h"
#include "common/parallel.h"
#include "mesh/mesh_internal.h"
#include "mesh/mesh_uv.h"

typedef struct bake_ctx {
    const bg_mesh *m;
    const float *nx, *ny, *nz;
    const float *ctan; /* 4 floats per corner; NULL for object space */
    int green_down;
    const bgt_height *h;
    bg_perturb_method method;
    int width;
    int height;
    double u0, v0;      /* the tile's origin in UV */
    /* The samples of a texel (offsets from its centre, in texels, and each
     * one's share of the texel's footprint): pattern 0 everywhere, or pattern
     * 1 on the triangles marked in dense (docs/MESH.md, "Anti-aliasing"). */
    struct bake_pattern {
        size_t n;
        float ox[MESH_MAX_SAMPLES * MESH_MAX_SAMPLES], oy[MESH_MAX_SAMPLES * MESH_MAX_SAMPLES];
        float fscale;
    } pat[2];
    size_t smax;          /* the larger pattern's count */
    const uint8_t *dense; /* per triangle: 1 for pattern 1; NULL: pattern 0 alone */
    const float *foot;  /* per triangle: one texel's object-space footprint, or NULL */
    const float *foot_all; /* the same, always (for the summary's texel size) */
    const int32_t *tri; /* triangle per texel, -1 = empty */
    const float *b1, *b2;
    float *vec; /* 3 floats per texel: the unit vector m to encode */
    atomic_int oom;
    const bgt_progress *progress;
    atomic_size_t done; /* texels of finished rows, over all tiles */
    /* --from (NULL without): per texel the mean signed distance of the hits
     * and the fraction of samples that missed (aux, 2 floats per texel) */
    const mesh_hi *hi;
    float *aux;
    atomic_size_t rays, misses, miss_texels, partial_texels;
} bake_ctx;

static void flat_vector(const bake_ctx *c, float *out)
{
    /* Where there is no frame the least surprising value is "unperturbed":
     * +z in tangent space; in object space there is no such direction, so 0. */
    out[0] = 0.0f;
    out[1] = 0.0f;
    out[2] = c->ctan ? 1.0f : 0.0f;
}

/* Barycentric weights (w1, w2) of the point (cx, cy) of the texel grid in
 * triangle t's UV image (the formula of raster_triangle; outside the
 * triangle they extrapolate its plane). */
static void weight_derivs(const bake_ctx *c, size_t t, double *d1x, double *d1y, double *d2x,
                          double *d2y);

/* --from: the samples' rays (mesh_hi_trace_n from LOW's point p along LOW's
 * normal q, or from the cage's point cg). A hit gives HIGH's point and its
 * interpolated normal m there; the result is the unit m. With detail, the
 * framework of Mikkelsen 2020 layers two influences on LOW's normal n: the
 * sculpt's surface gradient (bg_surfgrad_from_perturbed_normal(n, m)) and the
 * height's at HIGH's point (bg_surface_gradient(n, grad h)), resolved together
 * (bg_resolve_normal): what a renderer gets layering the map and the height
 * on LOW. A miss keeps LOW's own normal, without detail. The unit results go
 * to g; hm is scratch (3 ns floats). */
static void shade_high(bake_ctx *c, size_t ns, float *px, float *py, float *pz,
                       const float *qx, const float *qy, const float *qz, const float *cg,
                       float *dist, float *hit, float *hm, float *gx, float *gy, float *gz)
{
    mesh_hi_hit *hh = malloc((ns ? ns : 1) * sizeof *hh);
    if (!hh || !mesh_hi_trace_n(c->hi, ns, px, py, pz, qx, qy, qz, cg, hh, hit)) {
        free(hh);
        atomic_store(&c->oom, 1);
        memset(hit, 0, ns * sizeof *hit);
    } else {
        for (size_t s = 0; s < ns; s++) {
            dist[s] = 0.0f;
            if (hit[s] != 0.0f) {
                px[s] = hh[s].p[0], py[s] = hh[s].p[1], pz[s] = hh[s].p[2];
                memcpy(hm + 3 * s, hh[s].n, sizeof hh[s].n);
                dist[s] = hh[s].dist;
            }
        }
        free(hh);
    }
    if (c->hi->detail)
        bgt_height_gradient(c->h, px, py, pz, ns, NULL, gx, gy, gz);
    for (size_t s = 0; s < ns; s++) {
        bg_vec3 n = {qx[s], qy[s], qz[s]}, r;
        if (hit[s] == 0.0f) {
            r = bg_resolve_normal(n, NULL, NULL, 0);
        } else {
            bg_vec3 m = {hm[3 * s], hm[3 * s + 1], hm[3 * s + 2]};
            if (c->hi->detail) {
                bg_vec3 sg[2] = {bg_surfgrad_from_perturbed_normal(n, m),
                                 bg_surface_gradient(n, (bg_vec3){gx[s], gy[s], gz[s]})};
                r = bg_resolve_normal(n, sg, NULL, 2);
            } else {
                r = bg_resolve_normal(m, NULL, NULL, 0);
            }
        }
        gx[s] = r.x, gy[s] = r.y, gz[s] = r.z;
    }
}

static void shade_rows_work(bake_ctx *c, size_t begin, size_t end)
{
    const bg_mesh *m = c->m;
    size_t W = (size_t)c->width;
    const size_t S = c->smax;
    size_t cnt = 0;
    for (size_t k = begin * W; k < end * W; k++)
        cnt += c->tri[k] >= 0;
    if (cnt == 0)
        return;
    size_t ns = cnt * S; /* at most */
    float *buf = malloc(ns * (c->hi ? 18 : 10) * sizeof *buf);
    size_t *idx = malloc(2 * cnt * sizeof *idx); /* per texel: k, its first sample */
    if (!buf || !idx) {
        free(buf);
        free(idx);
        atomic_store(&c->oom, 1);
        return;
    }
    float *px = buf, *py = buf + ns, *pz = buf + 2 * ns;
    float *qx = buf + 3 * ns, *qy = buf + 4 * ns, *qz = buf + 5 * ns;
    float *gx = buf + 6 * ns, *gy = buf + 7 * ns, *gz = buf + 8 * ns, *fp = buf + 9 * ns;
    /* --from: the signed distance and hit flag of each sample, the cage's point
     * (and shade_high's scratch at 15 ns) */
    float *dist = buf + 10 * ns, *hit = buf + 11 * ns, *cg = buf + 12 * ns;
    const bg_mesh *cage = c->hi && c->hi->has_cage ? &c->hi->cage : NULL;
    size_t j = 0, s = 0, n_miss = 0, n_miss_texels = 0, n_partial = 0;
    int32_t tprev = -1;
    /* the texel-grid derivatives of the triangle's barycentric weights, and of
     * its interpolated position, normal and cage point */
    double d1x = 0.0, d1y = 0.0, d2x = 0.0, d2y = 0.0;
    float dp[2][3] = {{0}}, dq[2][3] = {{0}}, dc[2][3] = {{0}};
    for (size_t k = begin * W; k < end * W; k++) {
        int32_t t = c->tri[k];
        if (t < 0)
            continue;
        const uint32_t *ix = m->indices + 3 * (size_t)t;
        const struct bake_pattern *pt = &c->pat[c->dense ? c->dense[t] : 0];
        const uint32_t *cx = cage ? cage->indices + 3 * (size_t)t : NULL;
        if (pt->n > 1 && t != tprev) {
            tprev = t;
            weight_derivs(c, (size_t)t, &d1x, &d1y, &d2x, &d2y);
            const double dw[2][2] = {{d1x, d2x}, {d1y, d2y}};
            for (int a = 0; a < 2; a++) {
                const float *P[3] = {m->px, m->py, m->pz}, *Q[3] = {c->nx, c->ny, c->nz};
                for (int e = 0; e < 3; e++) {
                    dp[a][e] = (float)(dw[a][0] * ((double)P[e][ix[1]] - P[e][ix[0]]) +
                                       dw[a][1] * ((double)P[e][ix[2]] - P[e][ix[0]]));
                    dq[a][e] = (float)(dw[a][0] * ((double)Q[e][ix[1]] - Q[e][ix[0]]) +
                                       dw[a][1] * ((double)Q[e][ix[2]] - Q[e][ix[0]]));
                    if (cx) {
                        const float *G[3] = {cage->px, cage->py, cage->pz};
                        dc[a][e] = (float)(dw[a][0] * ((double)G[e][cx[1]] - G[e][cx[0]]) +
                                           dw[a][1] * ((double)G[e][cx[2]] - G[e][cx[0]]));
                    }
                }
            }
        }
        /* the texel centre; the samples move from it along the triangle's
         * plane (extended past its edges where a sample leaves it) */
        float w1 = c->b1[k], w2 = c->b2[k], w0 = 1.0f - w1 - w2;
        float p0[3] = {w0 * m->px[ix[0]] + w1 * m->px[ix[1]] + w2 * m->px[ix[2]],
                       w0 * m->py[ix[0]] + w1 * m->py[ix[1]] + w2 * m->py[ix[2]],
                       w0 * m->pz[ix[0]] + w1 * m->pz[ix[1]] + w2 * m->pz[ix[2]]};
        float q0[3] = {w0 * c->nx[ix[0]] + w1 * c->nx[ix[1]] + w2 * c->nx[ix[2]],
                       w0 * c->ny[ix[0]] + w1 * c->ny[ix[1]] + w2 * c->ny[ix[2]],
                       w0 * c->nz[ix[0]] + w1 * c->nz[ix[1]] + w2 * c->nz[ix[2]]};
        float c0[3] = {0};
        if (cx) /* the same weights on the cage's triangle */
            for (int e = 0; e < 3; e++) {
                const float *G = e == 0 ? cage->px : e == 1 ? cage->py : cage->pz;
                c0[e] = w0 * G[cx[0]] + w1 * G[cx[1]] + w2 * G[cx[2]];
            }
        const float f = c->foot ? c->foot[t] * pt->fscale : 0.0f;
        idx[2 * j] = k, idx[2 * j + 1] = s;
        j++;
        if (pt->n == 1) {
            px[s] = p0[0], py[s] = p0[1], pz[s] = p0[2];
            qx[s] = q0[0], qy[s] = q0[1], qz[s] = q0[2];
            fp[s] = f;
            if (cx)
                memcpy(cg + 3 * s, c0, sizeof c0);
            s++;
            continue;
        }
        for (size_t q = 0; q < pt->n; q++, s++) {
            const float ox = pt->ox[q], oy = pt->oy[q];
            px[s] = p0[0] + ox * dp[0][0] + oy * dp[1][0];
            py[s] = p0[1] + ox * dp[0][1] + oy * dp[1][1];
            pz[s] = p0[2] + ox * dp[0][2] + oy * dp[1][2];
            qx[s] = q0[0] + ox * dq[0][0] + oy * dq[1][0];
            qy[s] = q0[1] + ox * dq[0][1] + oy * dq[1][1];
            qz[s] = q0[2] + ox * dq[0][2] + oy * dq[1][2];
            fp[s] = f;
            if (cx)
                for (int e = 0; e < 3; e++)
                    cg[3 * s + (size_t)e] = c0[e] + ox * dc[0][e] + oy * dc[1][e];
        }
    }
    ns = s;
    if (c->hi) {
        shade_high(c, ns, px, py, pz, qx, qy, qz, cage ? cg : NULL, dist, hit, buf + 15 * ns, gx,
                   gy, gz);
    } else if (c->foot && !c->h->grid) {
        /* band-limited to each sample's footprint (the render's rule) */
        bg_perturb_height_footprint_batch(&c->h->h, c->method, fp, px, py, pz, qx, qy, qz, ns,
                                          NULL, gx, gy, gz);
    } else {
        bgt_height_gradient(c->h, px, py, pz, ns, NULL, gx, gy, gz);
        /* bg_perturb normalizes the interpolated normal itself. Outputs alias the
         * gradient inputs exactly, which the batch call allows. */
        bg_perturb_batch(c->method, qx, qy, qz, gx, gy, gz, ns, gx, gy, gz);
    }
    for (j = 0; j < cnt; j++) {
        size_t k = idx[2 * j], s0 = idx[2 * j + 1], s1 = j + 1 < cnt ? idx[2 * j + 3] : ns;
        size_t S = s1 - s0;
        float *out = c->vec + 3 * k;
        double n1x = 0.0, n1y = 0.0, n1z = 0.0;
        if (c->hi) { /* the texel's distance and misses */
            size_t hits = 0;
            double dsum = 0.0;
            for (size_t q = s0; q < s1; q++)
                if (hit[q] != 0.0f)
                    hits++, dsum += dist[q];
            c->aux[2 * k] = hits ? (float)(dsum / (double)hits) : 0.0f;
            c->aux[2 * k + 1] = (float)(S - hits) / (float)S;
            n_miss += S - hits;
            n_miss_texels += hits == 0;
            n_partial += hits > 0 && hits < S;
        }
        if (S == 1) {
            n1x = gx[s0], n1y = gy[s0], n1z = gz[s0];
        } else { /* the mean of the samples' unit normals, normalized */
            for (size_t q = s0; q < s1; q++)
                n1x += gx[q], n1y += gy[q], n1z += gz[q];
            double l = sqrt(n1x * n1x + n1y * n1y + n1z * n1z);
            if (l > 0.0 && isfinite(l))
                n1x /= l, n1y /= l, n1z /= l;
            else
                n1x = n1y = n1z = 0.0;
        }
        if (n1x == 0.0 && n1y == 0.0 && n1z == 0.0) {
            flat_vector(c, out); /* the sentinel: no normal to perturb here */
            continue;
        }
        if (!c->ctan) {
            out[0] = (float)n1x, out[1] = (float)n1y, out[2] = (float)n1z;
            continue;
        }
        size_t t = (size_t)c->tri[k];
        const uint32_t *ix = m->indices + 3 * t;
        /* the weights the renderer's rasterizer would use at the texel
         * centre: the float ones of the position and normal interpolation */
        float w1 = c->b1[k], w2 = c->b2[k];
        double w[3] = {1.0f - w1 - w2, w1, w2};
        float nv[3][3];
        const float *tc[3], *nc[3];
        for (int q = 0; q < 3; q++) {
            nv[q][0] = c->nx[ix[q]], nv[q][1] = c->ny[ix[q]], nv[q][2] = c->nz[ix[q]];
            nc[q] = nv[q];
            tc[q] = c->ctan + 4 * (3 * t + (size_t)q);
        }
        bgt_mikk_frame f;
        bgt_mikk_frame_at(tc, nc, w, &f);
        double n1[3] = {n1x, n1y, n1z}, mm[3];
        if (bgt_mikk_encode(&f, n1, mm) != 0) {
            flat_vector(c, out);
            continue;
        }
        out[0] = (float)mm[0], out[1] = (float)(c->green_down ? -mm[1] : mm[1]);
        out[2] = (float)mm[2];
    }
    if (c->hi) {
        atomic_fetch_add(&c->rays, ns);
        atomic_fetch_add(&c->misses, n_miss);
        atomic_fetch_add(&c->miss_texels, n_miss_texels);
        atomic_fetch_add(&c->partial_texels, n_partial);
    }
    free(buf);
    free(idx);
}

/* Progress in texels: every worker counts its rows, worker 0 reports (the
 * callback rate-limits, as for the render's tiles). */
static void shade_rows(void *ctxp, size_t begin, size_t end, int worker)
{
    bake_ctx *c = ctxp;
    shade_rows_work(c, begin, end);
    size_t n = (end - begin) * (size_t)c->width;
    size_t done = atomic_fetch_add(&c->done, n) + n;
    if (worker == 0)
        bgt_progress_update(c->progress, done);
}

/* The image of triangle t in the texel grid of tile (u0, v0): X = (u - u0) W,
 * Y = (1 - (v - v0)) H (the shift is exact in double). 0 when a UV is not
 * finite or the UV area is zero. */
static int uv_image(const bg_mesh *m, size_t t, double u0, double v0, int W, int H, double X[3],
                    double Y[3], double *area)
{
    const uint32_t *ix = m->indices + 3 * t;
    for (int k = 0; k < 3; k++) {
        X[k] = ((double)m->u[ix[k]] - u0) * W;
        Y[k] = (1.0 - ((double)m->v[ix[k]] - v0)) * H;
        if (!isfinite(X[k]) || !isfinite(Y[k]))
            return 0;
    }
    *area = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]);
    return *area != 0.0 && isfinite(*area);
}

/* The derivatives of the barycentric weights (w1, w2) of triangle t along the
 * texel grid's x and y (0 for a degenerate UV image). */
static void weight_derivs(const bake_ctx *c, size_t t, double *d1x, double *d1y, double *d2x,
                          double *d2y)
{
    double X[3], Y[3], area;
    if (!uv_image(c->m, t, c->u0, c->v0, c->width, c->height, X, Y, &area)) {
        *d1x = *d1y = *d2x = *d2y = 0.0;
        return;
    }
    double inv = 1.0 / area;
    double d0x = -(Y[2] - Y[1]) * inv, d0y = (X[2] - X[1]) * inv;
    *d1x = -(Y[0] - Y[2]) * inv, *d1y = (X[0] - X[2]) * inv;
    *d2x = -d0x - *d1x, *d2y = -d0y - *d1y;
}

/* N x N stratified: the centres of an N x N grid of the texel. */
static void pattern_grid(struct bake_pattern *p, int N)
{
    p->n = (size_t)N * (size_t)N;
    for (size_t q = 0; q < p->n; q++) {
        p->ox[q] = (float)(((double)(q % (size_t)N) + 0.5) / N - 0.5);
        p->oy[q] = (float)(((double)(q / (size_t)N) + 0.5) / N - 0.5);
    }
    p->fscale = 1.0f / (float)N;
}

/* A rank-1 lattice of K points with generator G (K, G coprime): x = (q + 1/2)
 * / K, y = ((q G mod K) + 1/2) / K, one point in each row and column of a
 * K x K grid (Keller's lattice rules). */
static void pattern_lattice(struct bake_pattern *p, int K, int G)
{
    p->n = (size_t)K;
    for (int q = 0; q < K; q++) {
        p->ox[q] = (float)(((double)q + 0.5) / K - 0.5);
        p->oy[q] = (float)(((double)((q * G) % K) + 0.5) / K - 0.5);
    }
    p->fscale = (float)(1.0 / sqrt((double)K));
}

/* The samples of a texel. With o->samples = N > 0: an N x N grid on every
 * triangle. With 0 (the default, docs/MESH.md "Anti-aliasing"): a 2 x 2 grid,
 * and MESH_DENSE_SAMPLES points of a rank-1 lattice on the triangles where
 * an octave that the 2 x 2 samples keep (weight > 0 at their footprint,
 * bg_octave_weight; every octave without the footprint filter) has lattice
 * cells narrower than MESH_DENSE_CELL texels: a few samples cannot average
 * such an octave over the texel, and the other triangles need no more. The
 * height of --from and of a grid has no octaves to look at: 2 x 2 there. */
static void sample_patterns(bake_ctx *c, const mesh_bake_opts *o, const float *foot,
                            uint8_t *dense)
{
    c->dense = NULL;
    pattern_grid(&c->pat[0], o->samples > 0 ? o->samples : 2);
    c->smax = c->pat[0].n;
    if (o->samples > 0 || c->hi || c->h->grid)
        return;
    pattern_lattice(&c->pat[1], MESH_DENSE_SAMPLES, MESH_DENSE_GENERATOR);
    c->smax = c->pat[1].n > c->smax ? c->pat[1].n : c->smax;
    const bg_height *h = &c->h->h;
    int oct = h->fractal.function == BG_FUNC_NOISE ? 1 : h->fractal.octaves;
    double freq = fabs((double)h->frequency), lac = h->fractal.lacunarity;
    for (size_t t = 0; t < c->m->triangle_count; t++) {
        double w = (double)foot[t], cellmin = INFINITY, fq = freq;
        for (int i = 0; i < oct; i++, fq *= lac) {
            float wt = c->foot ? bg_octave_weight((float)(w * c->pat[0].fscale * freq),
                                                  h->fractal.lacunarity, i)
                               : 1.0f;
            if (wt > 0.0f)
                cellmin = fmin(cellmin, 1.0 / fq);
        }
        dense[t] = w > 0.0 && cellmin < MESH_DENSE_CELL * w;
    }
    c->dense = dense;
}

/* One texel's footprint on the surface for every triangle, in object units:
 * with the UV Jacobian J = [dP/du dP/dv] of the triangle (from its edges),
 * max(|dP/du| / W, |dP/dv| / H), the isotropic rule the render uses for a
 * pixel (max(|dp/dx|, |dp/dy|)). 0 where the UV map is degenerate. */
static void texel_footprints(const bg_mesh *m, int W, int H, float *foot)
{
    for (size_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *ix = m->indices + 3 * t;
        double e1[3] = {(double)m->px[ix[1]] - m->px[ix[0]], (double)m->py[ix[1]] - m->py[ix[0]],
                        (double)m->pz[ix[1]] - m->pz[ix[0]]};
        double e2[3] = {(double)m->px[ix[2]] - m->px[ix[0]], (double)m->py[ix[2]] - m->py[ix[0]],
                        (double)m->pz[ix[2]] - m->pz[ix[0]]};
        double du1 = (double)m->u[ix[1]] - m->u[ix[0]], du2 = (double)m->u[ix[2]] - m->u[ix[0]];
        double dv1 = (double)m->v[ix[1]] - m->v[ix[0]], dv2 = (double)m->v[ix[2]] - m->v[ix[0]];
        double det = du1 * dv2 - du2 * dv1;
        double su = 0.0, sv = 0.0;
        for (int a = 0; a < 3; a++) {
            double pu = (e1[a] * dv2 - e2[a] * dv1) / det, pv = (e2[a] * du1 - e1[a] * du2) / det;
            su += pu * pu, sv += pv * pv;
        }
        double f = fmax(sqrt(su) / W, sqrt(sv) / H);
        foot[t] = det != 0.0 && isfinite(f) ? (float)f : 0.0f;
    }
}

/* Fill texel centres inside triangle t with its id and barycentric weights.
 * Texel (x, y) of tile (u0, v0) has its centre at u = u0 + (x + 0.5) / W,
 * v = v0 + 1 - (y + 0.5) / H: row 0 is the top of the image and v grows upward
 * (the OpenGL / glTF-after-assimp convention). Centres on a shared edge go to
 * the later triangle. UVs outside the tile are clipped, not wrapped. */
static int raster_triangle(const bg_mesh *m, size_t t, double u0, double v0, int W, int H,
                           int32_t *tri, float *b1, float *b2, const uint32_t *island,
                           uint8_t *overlapped, uint8_t *multi)
{
    double X[3], Y[3], area;
    if (!uv_image(m, t, u0, v0, W, H, X, Y, &area))
        return 0;
    double xmin = fmin(X[0], fmin(X[1], X[2])), xmax = fmax(X[0], fmax(X[1], X[2]));
    double ymin = fmin(Y[0], fmin(Y[1], Y[2])), ymax = fmax(Y[0], fmax(Y[1], Y[2]));
    double x0 = fmax(ceil(xmin - 0.5), 0.0), x1 = fmin(floor(xmax - 0.5), W - 1.0);
    double y0 = fmax(ceil(ymin - 0.5), 0.0), y1 = fmin(floor(ymax - 0.5), H - 1.0);
    double inv = 1.0 / area;
    for (double yy = y0; yy <= y1; yy += 1.0) {
        double cy = yy + 0.5;
        for (double xx = x0; xx <= x1; xx += 1.0) {
            double cx = xx + 0.5;
            double l0 = ((X[2] - X[1]) * (cy - Y[1]) - (Y[2] - Y[1]) * (cx - X[1])) * inv;
            double l1 = ((X[0] - X[2]) * (cy - Y[2]) - (Y[0] - Y[2]) * (cx - X[2])) * inv;
            double l2 = 1.0 - l0 - l1;
            if (l0 < 0.0 || l1 < 0.0 || l2 < 0.0)
                continue;
            size_t k = (size_t)yy * (size_t)W + (size_t)xx;
            /* Overlap: a texel centre strictly inside two triangles (not on
             * an edge they might share: meshes unwelded at the UV level have
             * every triangle an island of its own). The later one wins, as
             * before, but it is counted. multi: bit 0 overlapped, bit 1 the
             * current owner has the centre strictly inside. */
            int strict = l0 > 1e-9 && l1 > 1e-9 && l2 > 1e-9;
            if (tri[k] >= 0 && strict && (multi[k] & 2)) {
                overlapped[island[tri[k]]] = 1;
                overlapped[island[t]] = 1;
                multi[k] |= 1;
            }
            multi[k] = (uint8_t)((multi[k] & 1) | (strict ? 2 : 0));
            tri[k] = (int32_t)t;
            b1[k] = (float)l1;
            b2[k] = (float)l2;
        }
    }
    return 1;
}

/* Edge padding: each pass gives every empty texel that touches a filled one
 * (8-neighbourhood, filled before this pass) the normalized mean of those
 * neighbours that belong to ONE UV island (the island with the most of them;
 * a tie goes to the lower island number), and that island. So bilinear
 * filtering and mip-mapping near UV seams read the island's own normals
 * instead of the background, and a gutter between two islands is split
 * between them instead of mixing them; a texel that a triangle covers is
 * never written. level[k]: 0 empty, 1 baked, p + 1 filled by pass p;
 * isl[k]: the island of a filled texel. */
/* Pass p's work on texel k (empty): fill it from its neighbours filled
 * before the pass (level 1..p), as described above; 0 if it has none. */
static int pad_texel(float *vec, float *aux, uint16_t *level, int32_t *isl, int W, int H,
                     int p, int tangent, size_t k)
{
    int x = (int)(k % (size_t)W), y = (int)(k / (size_t)W);
    size_t nb[8];
    int n = 0;
    for (int dy = -1; dy <= 1; dy++) {
        for (int dx = -1; dx <= 1; dx++) {
            int xx = x + dx, yy = y + dy;
            if ((dx | dy) == 0 || xx < 0 || yy < 0 || xx >= W || yy >= H)
                continue;
            size_t q = (size_t)yy * (size_t)W + (size_t)xx;
            if (level[q] == 0 || level[q] > p)
                continue;
            nb[n++] = q;
        }
    }
    if (!n)
        return 0;
    int32_t best = isl[nb[0]];
    int best_count = 0;
    for (int i = 0; i < n; i++) {
        int cnt = 0;
        for (int j2 = 0; j2 < n; j2++)
            cnt += isl[nb[j2]] == isl[nb[i]];
        if (cnt > best_count || (cnt == best_count && isl[nb[i]] < best))
            best = isl[nb[i]], best_count = cnt;
    }
    double s[3] = {0, 0, 0}, a[2] = {0, 0};
    int na = 0;
    for (int i = 0; i < n; i++) {
        if (isl[nb[i]] != best)
            continue;
        const float *v = vec + 3 * nb[i];
        s[0] += v[0], s[1] += v[1], s[2] += v[2];
        if (aux) /* --from's distance and misses: the plain mean */
            a[0] += aux[2 * nb[i]], a[1] += aux[2 * nb[i] + 1], na++;
    }
    if (aux && na)
        aux[2 * k] = (float)(a[0] / na), aux[2 * k + 1] = (float)(a[1] / na);
    double l = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    float *o = vec + 3 * k;
    if (l > 0.0) {
        o[0] = (float)(s[0] / l), o[1] = (float)(s[1] / l), o[2] = (float)(s[2] / l);
    } else {
        o[0] = 0.0f, o[1] = 0.0f, o[2] = tangent ? 1.0f : 0.0f;
    }
    level[k] = (uint16_t)(p + 1);
    isl[k] = best;
    return 1;
}

/* The passes visit only the candidates: in pass 1 every empty texel, in pass
 * p > 1 the empty neighbours of the texels pass p - 1 filled (any other empty
 * texel has no neighbour of level p and, having none below p either, none at
 * all). A pass reads only levels 1..p, so the order of its texels does not
 * matter. front: room for W x H texel numbers; mark: W x H bytes, zeroed. */
static size_t pad(float *vec, float *aux, uint16_t *level, int32_t *isl, int W, int H,
                  int passes, int tangent, uint32_t *front, uint8_t *mark)
{
    size_t filled = 0, npix = (size_t)W * (size_t)H, nf = 0;
    for (int p = 1; p <= passes; p++) {
        size_t this_pass = 0, nn = 0;
        if (p == 1) {
            for (size_t k = 0; k < npix; k++)
                if (!level[k] && pad_texel(vec, aux, level, isl, W, H, p, tangent, k))
                    front[nn++] = (uint32_t)k;
        } else {
            /* front[0..nf) holds pass p - 1's texels; the candidates go after them */
            size_t nc = nf;
            for (size_t i = 0; i < nf; i++) {
                int x = (int)(front[i] % (uint32_t)W), y = (int)(front[i] / (uint32_t)W);
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++) {
                        int xx = x + dx, yy = y + dy;
                        if (xx < 0 || yy < 0 || xx >= W || yy >= H)
                            continue;
                        size_t q = (size_t)yy * (size_t)W + (size_t)xx;
                        if (level[q] || mark[q] == (uint8_t)p)
                            continue;
                        mark[q] = (uint8_t)p;
                        front[nc++] = (uint32_t)q;
                    }
            }
            /* fill them, keeping those filled at the front for the next pass */
            for (size_t i = nf; i < nc; i++)
                if (pad_texel(vec, aux, level, isl, W, H, p, tangent, front[i]))
                    front[nn++] = front[i];
        }
        this_pass = nn;
        nf = nn;
        filled += this_pass;
        if (!this_pass)
            break; /* nothing left that touches a filled texel */
    }
    return filled;
}

double mesh_bake_tile_bytes(int width, int height)
{
    /* tri, b1, b2 (4 + 4 + 4), vec (12), level (2), multi (1), image (12), isl (4),
     * front (4) */
    return (double)width * (double)height * 47.0;
}

/* The UV bounding box of triangle t; false when the triangle is not usable
 * or has no UV image (it is not baked). */
static bool uv_box(const bg_mesh *m, size_t t, double *u_lo, double *u_hi, double *v_lo,
                   double *v_hi)
{
    double X[3], Y[3], area;
    if (!mesh_triangle_usable(m, t) || !uv_image(m, t, 0.0, 0.0, 1, 1, X, Y, &area))
        return false;
    const uint32_t *ix = m->indices + 3 * t;
    *u_lo = *u_hi = m->u[ix[0]];
    *v_lo = *v_hi = m->v[ix[0]];
    for (int k = 1; k < 3; k++) {
        *u_lo = fmin(*u_lo, m->u[ix[k]]), *u_hi = fmax(*u_hi, m->u[ix[k]]);
        *v_lo = fmin(*v_lo, m->v[ix[k]]), *v_hi = fmax(*v_hi, m->v[ix[k]]);
    }
    return true;
}

/* The tiles (UDIM numbers, ascending) that the UV bounding box of a bakeable
 * triangle touches: u tiles 0..9, v tiles 0..MESH_UDIM_V_TILES-1, a box edge
 * on a tile boundary does not touch the next tile. Returns the count (also in
 * *wanted), (size_t)-1 when there are more than MESH_UDIM_MAX_TILES (*wanted:
 * how many), or (size_t)-2 when out of memory. */
static size_t udim_tiles(const bg_mesh *m, int *tiles, size_t *wanted)
{
    enum { U = 10, V = MESH_UDIM_V_TILES };
    uint8_t *mark = calloc((size_t)U * V, 1);
    if (!mark)
        return (size_t)-2;
    for (size_t t = 0; t < m->triangle_count; t++) {
        double u_lo, u_hi, v_lo, v_hi;
        if (!uv_box(m, t, &u_lo, &u_hi, &v_lo, &v_hi))
            continue;
        double a0 = fmax(floor(u_lo), 0.0), a1 = fmin(ceil(u_hi) - 1.0, U - 1.0);
        double b0 = fmax(floor(v_lo), 0.0), b1 = fmin(ceil(v_hi) - 1.0, V - 1.0);
        for (double b = b0; b <= b1; b += 1.0)
            for (double a = a0; a <= a1; a += 1.0)
                mark[(size_t)b * U + (size_t)a] = 1;
    }
    size_t n = 0;
    for (size_t k = 0; k < (size_t)U * V; k++) {
        if (!mark[k])
            continue;
        if (n < MESH_UDIM_MAX_TILES)
            tiles[n] = 1001 + (int)(k % U) + 10 * (int)(k / U);
        n++;
    }
    free(mark);
    *wanted = n;
    return n > MESH_UDIM_MAX_TILES ? (size_t)-1 : n;
}

/* Without <UDIM>: the triangles whose UV bounding box misses the unit
 * square (they are left out of the map), and the other tiles the UVs touch. */
static bg_status outside_unit_square(const bg_mesh *m, mesh_bake_stats *stats, bgt_err *e)
{
    int *all = malloc(MESH_UDIM_MAX_TILES * sizeof *all);
    if (!all)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the UDIM tiles");
    size_t wanted = 0;
    size_t n = udim_tiles(m, all, &wanted);
    if (n == (size_t)-2) {
        free(all);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the UDIM tiles");
    }
    size_t listed = wanted < MESH_UDIM_MAX_TILES ? wanted : MESH_UDIM_MAX_TILES;
    for (size_t i = 0; i < listed; i++) {
        if (all[i] == 1001)
            continue;
        if (stats->outside_tile_count < 8)
            stats->outside_tiles[stats->outside_tile_count] = all[i];
        stats->outside_tile_count++;
    }
    if (wanted > MESH_UDIM_MAX_TILES) /* the ones past the list are not 1001 */
        stats->outside_tile_count += wanted - MESH_UDIM_MAX_TILES;
    free(all);
    for (size_t t = 0; t < m->triangle_count; t++) {
        double u_lo, u_hi, v_lo, v_hi;
        if (!uv_box(m, t, &u_lo, &u_hi, &v_lo, &v_hi))
            continue;
        stats->outside_triangles += u_hi <= 0.0 || u_lo >= 1.0 || v_hi <= 0.0 || v_lo >= 1.0;
    }
    return BG_OK;
}

/* The tiles to bake: 1001 alone, or with o->udim those the UVs touch. */
static bg_status choose_tiles(const bg_mesh *m, const mesh_bake_opts *o,
                              int tiles[MESH_UDIM_MAX_TILES], size_t *ntiles,
                              mesh_bake_stats *stats, bgt_err *e)
{
    size_t wanted = 0;
    *ntiles = 1;
    tiles[0] = 1001;
    if (o->only_tile && !o->udim)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--tile %d: the map's name needs the <UDIM> token (e.g. n.<UDIM>.png)",
                        o->only_tile);
    if (!o->udim)
        return outside_unit_square(m, stats, e);
    *ntiles = udim_tiles(m, tiles, &wanted);
    if (*ntiles == (size_t)-2)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the UDIM tiles");
    if (*ntiles == (size_t)-1)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "the UVs span %zu UDIM tiles; at most %d are baked (each tile is a "
                        "full %dx%d bake)",
                        wanted, MESH_UDIM_MAX_TILES, o->width, o->height);
    if (*ntiles == 0)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "no triangle has UVs in the UDIM range (u in [0, 10), v in [0, %d)): "
                        "nothing to bake",
                        MESH_UDIM_V_TILES);
    if (o->only_tile) {
        /* One tile of the same bake: every tile is baked on its own (the
         * raster, the shading and the padding see only its texels), so this
         * is the full bake's tile. */
        char list[160] = "";
        for (size_t i = 0; i < *ntiles; i++) {
            if (tiles[i] == o->only_tile) {
                tiles[0] = o->only_tile;
                *ntiles = 1;
                return BG_OK;
            }
            if (strlen(list) < sizeof list - 16)
                snprintf(list + strlen(list), sizeof list - strlen(list), "%s%d", i ? ", " : "",
                         tiles[i]);
            else if (!strstr(list, "..."))
                strcat(list, ", ...");
        }
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--tile %d: no triangle's UVs touch that tile (they touch %s)",
                        o->only_tile, list);
    }
    return BG_OK;
}

/* The tangent frame of every corner (4 floats: xyz and the bitangent sign)
 * for a tangent-space bake: the file's per-vertex frames, as a renderer
 * given them uses them, or mikkTSpace's. *ctan stays NULL in object space. */
bg_status mesh_bake_corner_tangents(const bg_mesh *m, const float *nx, const float *ny,
                                    const float *nz, const mesh_bake_opts *o, float **ctan,
                                    mesh_bake_stats *stats, bgt_err *e)
{
    size_t C = 3 * m->triangle_count;
    *ctan = NULL;
    if (o->space != MESH_BAKE_TANGENT)
        return BG_OK;
    float *t = malloc((C ? C : 1) * 4 * sizeof *t);
    if (!t)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the tangents of %zu corners", C);
    if (o->tangents == MESH_TANGENTS_FILE) {
        for (size_t c = 0; c < C; c++) {
            uint32_t i = m->indices[c];
            t[4 * c] = m->tx[i], t[4 * c + 1] = m->ty[i], t[4 * c + 2] = m->tz[i];
            t[4 * c + 3] = m->tw[i] < 0.0f ? -1.0f : 1.0f;
        }
    } else {
        bgt_mikk_mesh mm = {m->vertex_count, m->triangle_count, m->indices, m->px, m->py,
                            m->pz, nx, ny, nz, m->u, m->v};
        bg_status rc = bgt_mikk_tangents_threads(&mm, t, &stats->mikk, o->threads);
        if (rc != BG_OK) {
            free(t);
            return bgt_fail(e, rc, "mikkTSpace tangents failed (%s)", bg_status_string(rc));
        }
    }
    *ctan = t;
    return BG_OK;
}

/* The per-texel buffers of one tile (bake_ctx points to tri, b1, b2, vec). */
typedef struct bake_bufs {
    int32_t *tri;
    float *b1, *b2, *vec;
    uint16_t *level;
    int32_t *isl; /* the UV island of a baked or padded texel */
    uint32_t *front; /* the padding's candidates */
    uint8_t *multi, *overlapped; /* overlapped: per island, over all tiles */
    bg_image img;
    float *aux;             /* --from: 2 floats per texel (bake_ctx.aux) */
    bg_image dist, miss;    /* --from: the height and miss tiles (1 channel) */
} bake_bufs;

static int bufs_alloc(bake_bufs *b, int W, int H, size_t islands, int hi)
{
    size_t npix = (size_t)W * (size_t)H;
    if (hi && (!(b->aux = malloc(npix * 2 * sizeof *b->aux)) ||
               bg_image_alloc(&b->dist, W, H, 1) != BG_OK ||
               bg_image_alloc(&b->miss, W, H, 1) != BG_OK))
        return 0;
    b->tri = malloc(npix * sizeof *b->tri);
    b->b1 = malloc(npix * sizeof *b->b1), b->b2 = malloc(npix * sizeof *b->b2);
    b->vec = malloc(npix * 3 * sizeof *b->vec);
    b->level = malloc(npix * sizeof *b->level);
    b->isl = malloc(npix * sizeof *b->isl);
    b->front = malloc(npix * sizeof *b->front);
    b->overlapped = calloc(islands ? islands : 1, 1);
    b->multi = malloc(npix);
    return b->tri && b->b1 && b->b2 && b->vec && b->level && b->isl && b->front && b->overlapped &&
           b->multi &&
           bg_image_alloc(&b->img, W, H, 3) == BG_OK;
}

static void bufs_free(bake_bufs *b)
{
    bg_image_free(&b->img);
    bg_image_free(&b->dist);
    bg_image_free(&b->miss);
    free(b->aux);
    free(b->tri);
    free(b->b1);
    free(b->b2);
    free(b->vec);
    free(b->level);
    free(b->isl);
    free(b->front);
    free(b->multi);
    free(b->overlapped);
}

/* The texels' vectors as colours, 0.5 v + 0.5; texels that no triangle or
 * padding reached get the flat vector (+z in tangent space, 0 in object). */
static void encode_tile(const bake_bufs *b, size_t npix, int tangent, float *pixels)
{
    for (size_t k = 0; k < npix; k++) {
        float v[3];
        if (b->level[k]) {
            v[0] = b->vec[3 * k], v[1] = b->vec[3 * k + 1], v[2] = b->vec[3 * k + 2];
        } else {
            v[0] = 0.0f, v[1] = 0.0f, v[2] = tangent ? 1.0f : 0.0f;
        }
        for (int ch = 0; ch < 3; ch++)
            pixels[3 * k + (size_t)ch] = 0.5f * v[ch] + 0.5f;
    }
}

/* One tile into b->img: rasterize the UVs, shade the covered texels (in
 * parallel), pad, encode. *empty when a UDIM tile has no covered texel (its
 * bounding box touched the tile, no texel centre is inside): nothing to
 * write. first: the tile whose skipped-triangle count goes to stats (the
 * same for every tile). */
static bg_status bake_tile(const bg_mesh *m, const mesh_bake_opts *o, bake_ctx *c, bake_bufs *b,
                           const uint32_t *island, int tile, int first, int *empty,
                           mesh_bake_stats *stats, bgt_err *e)
{
    int W = o->width, H = o->height;
    size_t npix = (size_t)W * (size_t)H;
    double u0 = (double)((tile - 1001) % 10), v0 = (double)((tile - 1001) / 10);
    c->u0 = u0, c->v0 = v0;
    for (size_t k = 0; k < npix; k++)
        b->tri[k] = -1;
    memset(b->vec, 0, npix * 3 * sizeof *b->vec);
    memset(b->level, 0, npix * sizeof *b->level);
    memset(b->multi, 0, npix);
    if (b->aux)
        memset(b->aux, 0, npix * 2 * sizeof *b->aux);
    size_t skipped = 0, covered = 0;
    for (size_t t = 0; t < m->triangle_count; t++) {
        if (!mesh_triangle_usable(m, t) ||
            !raster_triangle(m, t, u0, v0, W, H, b->tri, b->b1, b->b2, island, b->overlapped,
                             b->multi))
            skipped++;
    }
    if (first)
        stats->skipped = skipped;
    for (size_t k = 0; k < npix; k++)
        covered += b->tri[k] >= 0;
    if (!o->udim && covered == 0)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "nothing to bake: no usable triangle covers a texel centre of the %dx%d "
                        "map in the unit square of UV space (%zu of %zu triangles unusable or "
                        "with zero/non-finite UV area, %zu wholly outside it%s)",
                        W, H, skipped, m->triangle_count, stats->outside_triangles,
                        stats->outside_tile_count ? "; name the map with <UDIM> for the other "
                                                    "tiles"
                                                  : "");
    *empty = o->udim && covered == 0;
    if (*empty) {
        atomic_fetch_add(&c->done, npix);
        return BG_OK;
    }
    for (size_t k = 0; k < npix; k++)
        stats->overlap_texels += b->multi[k] & 1;
    if (c->foot_all)
        for (size_t k = 0; k < npix; k++)
            if (b->tri[k] >= 0)
                stats->texel_size += c->foot_all[b->tri[k]];

    size_t rows = (size_t)(16384 / ((size_t)W * c->smax)) + 1;
    bgt_parallel_for((size_t)H, rows, o->threads, shade_rows, c);
    if (atomic_load(&c->oom))
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory while baking");
    for (size_t k = 0; k < npix; k++) {
        b->level[k] = b->tri[k] >= 0;
        b->isl[k] = b->tri[k] >= 0 ? (int32_t)island[b->tri[k]] : -1;
    }
    stats->covered += covered;
    memset(b->multi, 0, npix); /* the padding's marks from here on */
    stats->padded += pad(b->vec, b->aux, b->level, b->isl, W, H, o->padding,
                         o->space == MESH_BAKE_TANGENT, b->front, b->multi);
    encode_tile(b, npix, o->space == MESH_BAKE_TANGENT, b->img.pixels);
    if (b->aux) /* texels nothing reached: distance 0, not a miss */
        for (size_t k = 0; k < npix; k++) {
            b->dist.pixels[k] = b->level[k] ? (float)(b->aux[2 * k] * o->hi->dist_unit) : 0.0f;
            b->miss.pixels[k] = b->level[k] ? b->aux[2 * k + 1] : 0.0f;
        }
    return BG_OK;
}

bg_status mesh_bake(const bg_mesh *m, const float *nx, const float *ny, const float *nz,
                    const bgt_height *h, const mesh_bake_opts *o, mesh_bake_sink sink,
                    void *sink_ctx, mesh_bake_stats *stats, bgt_err *e)
{
    memset(stats, 0, sizeof *stats);
    int W = o->width, H = o->height;
    size_t npix = (size_t)W * (size_t)H;
    if (m->triangle_count > (size_t)INT32_MAX)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "too many triangles to bake (%zu)",
                        m->triangle_count);
    if (o->samples < 0 || o->samples > MESH_MAX_SAMPLES)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "samples %d: expected 1..%d per axis",
                        o->samples, MESH_MAX_SAMPLES);
    /* the tile's buffers, and each worker's samples of one chunk of rows
     * (at least one row: W x N^2 samples of 10 floats) */
    const double ns = o->samples > 0 ? (double)o->samples : sqrt((double)MESH_DENSE_SAMPLES);
    const double chunk = fmax(16384.0, (double)W * ns * ns);
    bg_status rc = bgt_check_alloc(mesh_bake_tile_bytes(W, H) +
                                       (double)(o->threads > 0 ? o->threads : 1) * chunk * 40.0 +
                                       /* --from: aux (8 bytes) and the height and miss
                                        * tiles (4 + 4) per texel; a sample's 8 more floats
                                        * and its two rays (an RTCRayHit of 80 bytes, a
                                        * mesh_hi_hit of 28, its length) */
                                       (o->hi ? 16.0 * (double)npix +
                                                    (double)(o->threads > 0 ? o->threads : 1) *
                                                        chunk * 144.0
                                              : 0.0),
                                   "the bake buffers", e);
    if (rc != BG_OK)
        return rc;
    int tiles[MESH_UDIM_MAX_TILES];
    size_t ntiles;
    if ((rc = choose_tiles(m, o, tiles, &ntiles, stats, e)) != BG_OK)
        return rc;

    float *ctan = NULL;
    uint32_t *island = malloc((m->triangle_count ? m->triangle_count : 1) * sizeof *island);
    if (!island)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the UV islands");
    stats->islands = mesh_uv_islands(m->triangle_count, m->indices, m->u, m->v, island);
    if (stats->islands == (size_t)-1) {
        free(island);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the UV islands");
    }
    if ((rc = mesh_bake_corner_tangents(m, nx, ny, nz, o, &ctan, stats, e)) != BG_OK) {
        free(island);
        return rc;
    }

    float *foot = malloc((m->triangle_count ? m->triangle_count : 1) * sizeof *foot);
    uint8_t *dense = malloc(m->triangle_count ? m->triangle_count : 1);
    if (!foot || !dense) {
        free(foot);
        free(dense);
        free(ctan);
        free(island);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the texel footprints");
    }
    texel_footprints(m, W, H, foot);
    bgt_progress_begin(o->progress, "bake", ntiles * npix);
    bake_bufs b = {0};
    if (!bufs_alloc(&b, W, H, stats->islands, o->hi != NULL)) {
        rc = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for a %dx%d bake", W, H);
        goto done;
    }
    bake_ctx c = {.m = m, .nx = nx, .ny = ny, .nz = nz,
                  .ctan = ctan, .green_down = o->green_down,
                  .h = h, .method = o->method, .width = W, .tri = b.tri, .b1 = b.b1, .b2 = b.b2,
                  .vec = b.vec, .progress = o->progress, .height = H,
                  .foot = o->filter == MESH_FILTER_FOOTPRINT && !h->grid ? foot : NULL,
                  .foot_all = foot, .hi = o->hi, .aux = b.aux};
    sample_patterns(&c, o, foot, dense);
    atomic_init(&c.oom, 0);
    atomic_init(&c.done, 0);
    atomic_init(&c.rays, 0);
    atomic_init(&c.misses, 0);
    atomic_init(&c.miss_texels, 0);
    atomic_init(&c.partial_texels, 0);
    for (size_t ti = 0; ti < ntiles; ti++) {
        int empty = 0;
        rc = bake_tile(m, o, &c, &b, island, tiles[ti], ti == 0, &empty, stats, e);
        if (rc != BG_OK)
            goto done;
        if (empty)
            continue;
        if ((rc = sink(sink_ctx, tiles[ti], &b.img, e)) != BG_OK)
            goto done;
        if (o->hi && o->hi->height_sink &&
            (rc = o->hi->height_sink(o->hi->height_ctx, tiles[ti], &b.dist, e)) != BG_OK)
            goto done;
        if (o->hi && o->hi->miss_sink &&
            (rc = o->hi->miss_sink(o->hi->miss_ctx, tiles[ti], &b.miss, e)) != BG_OK)
            goto done;
        stats->tile_udim[stats->tiles++] = tiles[ti];
    }
    for (size_t i = 0; i < stats->islands; i++)
        stats->overlap_islands += b.overlapped[i];
    if (stats->tiles == 0) {
        rc = bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                      "nothing to bake: no usable triangle covers a texel centre of a %dx%d "
                      "tile",
                      W, H);
        goto done;
    }
    stats->texel_size = stats->covered ? stats->texel_size / (double)stats->covered : 0.0;
    stats->ray_samples = atomic_load(&c.rays);
    stats->ray_misses = atomic_load(&c.misses);
    stats->miss_texels = atomic_load(&c.miss_texels);
    stats->partial_miss_texels = atomic_load(&c.partial_texels);
done:
    bgt_progress_end(o->progress);
    bufs_free(&b);
    free(foot);
    free(dense);
    free(ctan);
    free(island);
    return rc;
}
