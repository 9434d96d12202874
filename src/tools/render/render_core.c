/* SPDX-License-Identifier: MIT */
/* The ray caster of `bumpgrad render`: camera, ray hits, a per-tile G-buffer,
 * the normal-perturbation methods compared in Mikkelsen 2010 and shading.
 *
 * Samples. --spp N = s*s puts s x s samples in each pixel on a regular grid at
 * the sub-cell centres (stratified, deterministic) and renders the s-times
 * finer sample grid exactly as a GPU renders a larger target: the screen-space
 * derivatives of Listing 1 are taken on 2x2 quads of that sample grid, so
 * supersampling raises the pixel density the paper's section 6 talks about
 * ("Increasing the resolution or super-sampling will also achieve this").
 *
 * Heights are solid: h(p) = amplitude * F(frequency * p) at the hit point,
 * no texture coordinates (section 3). Every height and gradient goes through
 * the library's batch calls (via bgt_height_perturb / bgt_height_gradient),
 * one batch per tile. */
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include "mesh/mikktspace.h"
#include "render/render_internal.h"
#include "bumpgrad/framework.h"
#include "vecmath.h"
#include "common/parallel.h"
#if BG_HAVE_TOOLS
#include "bumpgrad/volume.h"
#endif

#define TILE 8 /* output pixels per tile side */

static const char *const method_names[RENDER_METHOD_COUNT] = {
    "none", "surfgrad", "surfgrad-central", "listing1", "listing1-coarse", "additive", "flat",
    "surfgrad-footprint", "listing1-heightmap", "listing1-heightmap-central", "normalmap",
    "surfgrad-heightmap", "detail"};

const char *render_method_name(render_method m)
{
    return (unsigned)m < RENDER_METHOD_COUNT ? method_names[m] : "?";
}

int render_method_parse(const char *name, render_method *out)
{
    for (int i = 0; i < RENDER_METHOD_COUNT; i++)
        if (strcmp(name, method_names[i]) == 0) {
            *out = (render_method)i;
            return 0;
        }
    return -1;
}

static const char *const shape_names[3] = {"sphere", "blob", "torus"};
const char *render_shape_name(render_shape s) { return (unsigned)s < 3 ? shape_names[s] : "?"; }
int render_shape_parse(const char *name, render_shape *out)
{
    for (int i = 0; i < 3; i++)
        if (strcmp(name, shape_names[i]) == 0) {
            *out = (render_shape)i;
            return 0;
        }
    return -1;
}

void render_scene_camera(render_scene *s, float distance, float zoom)
{
    /* A slight elevation shows the top of the objects, like the paper's views. */
    float dir[3] = {0.0f, 0.28f, 1.0f};
    render_scene_camera_dir(s, dir, distance, zoom);
}

void render_scene_camera_dir(render_scene *s, const float view[3], float distance, float zoom)
{
    float dir[3] = {view[0], view[1], view[2]};
    if (!bg_f3_normalize(dir))
        dir[0] = 0, dir[1] = 0, dir[2] = 1;
    for (int a = 0; a < 3; a++)
        s->eye[a] = distance * dir[a], s->fwd[a] = -dir[a];
    /* World up is +y, unless the view looks along it. */
    float wup[3] = {0, 1, 0};
    if (fabsf(dir[1]) > 0.999f)
        wup[1] = 0, wup[2] = -1;
    bg_f3_cross(s->fwd, wup, s->right);
    bg_f3_normalize(s->right);
    bg_f3_cross(s->right, s->fwd, s->up);
    s->tan_half = 0.36397023f / zoom; /* tan(20 degrees): a 40-degree field of view */
    /* One point light above, left and in front (section 6: "a single point light"). */
    s->light[0] = -5.0f, s->light[1] = 4.0f, s->light[2] = 3.0f;
}

void render_listing1(const float pos[4][3], const float h[4], int lane, int fine, const float n[3],
                     float out[3])
{
    /* ddx_fine pairs the two pixels of the lane's row, ddy_fine the two of its
     * column (section 4: "the same result for pixel pairs in blocks of 2x1 and
     * 1x2"); coarse uses the top row and left column for the whole quad. */
    int lx = lane & 1, ly = lane >> 1;
    int r = fine ? 2 * ly : 0, c = fine ? lx : 0;
    float sS[3], sT[3];
    for (int a = 0; a < 3; a++)
        sS[a] = pos[r + 1][a] - pos[r][a], sT[a] = pos[c + 2][a] - pos[c][a];
    float dBs = h[r + 1] - h[r], dBt = h[c + 2] - h[c];
    /* Listing 1 itself (and its det = 0 rule) is the library's, shared with
     * the studies: bg_listing1_normal (framework.h). */
    bg_vec3 o = bg_listing1_normal((bg_vec3){n[0], n[1], n[2]}, (bg_vec3){sS[0], sS[1], sS[2]},
                                   (bg_vec3){sT[0], sT[1], sT[2]}, dBs, dBt);
    out[0] = o.x, out[1] = o.y, out[2] = o.z;
}

/* Figure 1(a): the normal of the displaced surface tau = sigma + h n from its
 * own screen-space derivatives, cross(tau_s, tau_t), oriented by sign(det) as
 * in Listing 1. On a triangle n is the face normal, so this perturbs the face
 * normal and shows the facets. */
static void flat_normal(const float tau[4][3], const float pos[4][3], int lane, const float nf[3],
                        float out[3])
{
    int lx = lane & 1, ly = lane >> 1;
    int r = 2 * ly, c = lx;
    float tS[3], tT[3], sS[3], sT[3], cs[3];
    for (int a = 0; a < 3; a++) {
        tS[a] = tau[r + 1][a] - tau[r][a], tT[a] = tau[c + 2][a] - tau[c][a];
        sS[a] = pos[r + 1][a] - pos[r][a], sT[a] = pos[c + 2][a] - pos[c][a];
    }
    bg_f3_cross(sS, sT, cs);
    float det = bg_f3_dot(nf, cs);
    bg_f3_cross(tS, tT, out);
    if (det < 0)
        out[0] = -out[0], out[1] = -out[1], out[2] = -out[2];
    if (!bg_f3_normalize(out))
        out[0] = nf[0], out[1] = nf[1], out[2] = nf[2];
}

static const float grey_albedo[3] = {0.60f, 0.57f, 0.54f};

static void shade(const render_scene *s, const float p[3], const float d[3], const float n[3],
                  const float albedo[3], float rgb[3])
{
    float L[3] = {s->light[0] - p[0], s->light[1] - p[1], s->light[2] - p[2]};
    bg_f3_normalize(L);
    float V[3] = {-d[0], -d[1], -d[2]}, H[3] = {L[0] + V[0], L[1] + V[1], L[2] + V[2]};
    bg_f3_normalize(H);
    float nl = bg_f3_dot(n, L), diff = nl > 0 ? nl : 0, spec = 0;
    if (nl > 0) {
        float nh = bg_f3_dot(n, H);
        /* Blinn-Phong; the highlight makes normal errors easy to see. */
        spec = nh > 0 ? 0.35f * powf(nh, 40.0f) : 0;
    }
    for (int a = 0; a < 3; a++)
        rgb[a] = albedo[a] * (0.03f + diff) + spec;
}

static const float background[3] = {0.012f, 0.014f, 0.02f};

/* ---- one tile ---- */
typedef struct tile_buf {
    int ts;           /* samples per tile side */
    float *dir;       /* 3 per sample */
    unsigned char *hit;
    int *prim;
    float *p, *n, *nf; /* 3 per sample: position, interpolated normal, face/plane normal */
    float *h;          /* height */
    float *ref;        /* 3 per sample: analytic surfgrad normal */
    float *out;        /* 3 per sample per method */
    /* quad neighbourhoods (Listing 1, flat): per sample 4 lanes */
    float *qp, *qh, *qn; /* 12, 4, 12 per sample */
    unsigned char *qok;  /* 4 per sample */
    float *bc;           /* 2 per sample: barycentrics of the hit (vertices 1, 2) */
    float *st, *qst;     /* 2 per sample, 8 per sample (quad lanes): texture coordinates */
    float *gd;           /* 3 per sample: the detail's turbulence surface gradient */
    /* compacted batches */
    float *bx, *by, *bz, *bnx, *bny, *bnz, *bh, *box, *boy, *boz;
    int *bidx; /* batch entry -> sample*4 + lane (helpers) or sample */
} tile_buf;

static void tile_free(tile_buf *t)
{
    void *ptrs[] = {t->dir, t->hit, t->prim, t->p,   t->n,   t->nf,  t->h,   t->ref,
                    t->out, t->qp,  t->qh,   t->qn,  t->qok, t->bx,  t->by,  t->bz,
                    t->bnx, t->bny, t->bnz,  t->bh,  t->box, t->boy, t->boz, t->bidx,
                    t->bc,  t->st,  t->qst,  t->gd};
    for (size_t i = 0; i < sizeof ptrs / sizeof ptrs[0]; i++)
        free(ptrs[i]);
    memset(t, 0, sizeof *t);
}

static int tile_alloc(tile_buf *t, int ts, int nmethods)
{
    memset(t, 0, sizeof *t);
    size_t ns = (size_t)ts * ts, nb = ns * 4;
    t->ts = ts;
    t->dir = malloc(ns * 3 * sizeof(float));
    t->hit = malloc(ns);
    t->prim = malloc(ns * sizeof(int));
    t->p = malloc(ns * 3 * sizeof(float));
    t->n = malloc(ns * 3 * sizeof(float));
    t->nf = malloc(ns * 3 * sizeof(float));
    t->h = malloc(ns * sizeof(float));
    t->ref = malloc(ns * 3 * sizeof(float));
    t->out = malloc(ns * 3 * (size_t)nmethods * sizeof(float));
    t->qp = malloc(ns * 12 * sizeof(float));
    t->qh = malloc(ns * 4 * sizeof(float));
    t->qn = malloc(ns * 12 * sizeof(float));
    t->qok = malloc(ns * 4);
    t->bc = malloc(ns * 2 * sizeof(float));
    t->st = malloc(ns * 2 * sizeof(float));
    t->qst = malloc(ns * 8 * sizeof(float));
    t->gd = malloc(ns * 3 * sizeof(float));
    float **b[] = {&t->bx, &t->by, &t->bz, &t->bnx, &t->bny, &t->bnz, &t->bh, &t->box, &t->boy, &t->boz};
    int ok = 1;
    for (size_t i = 0; i < sizeof b / sizeof b[0]; i++)
        ok &= (*b[i] = malloc(nb * sizeof(float))) != NULL;
    t->bidx = malloc(nb * sizeof(int));
    if (!ok || !t->dir || !t->hit || !t->prim || !t->p || !t->n || !t->nf || !t->h || !t->ref ||
        !t->out || !t->qp || !t->qh || !t->qn || !t->qok || !t->bidx || !t->bc || !t->st ||
        !t->qst || !t->gd) {
        tile_free(t);
        return -1;
    }
    return 0;
}

typedef struct run_ctx {
    render_job *job;
    int tiles_x, tiles_y;
    int need_quads;
    int tex_ref; /* the reference is surfgrad-heightmap (a job with a height texture) */
    int need_detail;
    int need_solid; /* some method uses the solid height at the hits (not texture-only) */
    atomic_int failed;
    atomic_size_t done;
    bgt_height analytic, central;
    float grid_box[6];                  /* a grid height: its active box, one voxel of margin */
    atomic_size_t grid_points, grid_in_box, grid_zero;
} run_ctx;

static int trace(const render_scene *s, const float d[3], float p[3], float n[3], float nf[3],
                 int *prim, float bc[2])
{
    if (!s->mesh) {
        /* Unit sphere at the origin, solved in double: |e + t d|^2 = 1. */
        double e[3] = {s->eye[0], s->eye[1], s->eye[2]};
        double b = e[0] * d[0] + e[1] * d[1] + e[2] * d[2];
        double c = e[0] * e[0] + e[1] * e[1] + e[2] * e[2] - 1.0;
        double disc = b * b - c;
        if (disc < 0)
            return 0;
        double t = -b - sqrt(disc);
        if (t <= 0)
            return 0;
        for (int a = 0; a < 3; a++)
            p[a] = (float)(e[a] + t * d[a]);
        for (int a = 0; a < 3; a++)
            n[a] = p[a];
        bg_f3_normalize(n);
        memcpy(nf, n, 3 * sizeof(float));
        *prim = 0;
        bc[0] = bc[1] = 0.0f;
        return 1;
    }
    render_hit h;
    if (s->embree ? !render_embree_intersect(s->embree, s->eye, d, &h)
                  : !render_mesh_intersect(s->mesh, s->eye, d, INFINITY, &h))
        return 0;
    const float *P = s->mesh->pos + (size_t)h.prim * 9, *N = s->mesh->nrm + (size_t)h.prim * 9;
    float b0 = 1.0f - h.b1 - h.b2;
    for (int a = 0; a < 3; a++) {
        /* On the triangle's plane exactly, so the helper lanes' plane extension
         * (below) and the hit lanes describe one plane. */
        p[a] = P[a] + h.b1 * (P[3 + a] - P[a]) + h.b2 * (P[6 + a] - P[a]);
        n[a] = b0 * N[a] + h.b1 * N[3 + a] + h.b2 * N[6 + a];
        nf[a] = s->mesh->face[(size_t)h.prim * 3 + a];
    }
    if (!bg_f3_normalize(n))
        memcpy(n, nf, 3 * sizeof(float));
    if (s->tex) {
        /* A user's mesh may be open or wound either way: the face normal goes
         * to the side of the vertex normals, and both face the viewer (two-sided). */
        if (bg_f3_dot(nf, n) < 0)
            nf[0] = -nf[0], nf[1] = -nf[1], nf[2] = -nf[2];
        if (bg_f3_dot(nf, d) > 0)
            for (int a = 0; a < 3; a++)
                nf[a] = -nf[a], n[a] = -n[a];
    }
    *prim = h.prim;
    bc[0] = h.b1, bc[1] = h.b2;
    return 1;
}

/* ---- texture methods (Mikkelsen 2010 section 6, Figure 4) ---- */
static bg_vec3 v3(const float a[3]) { return (bg_vec3){a[0], a[1], a[2]}; }
static void put3(bg_vec3 v, float o[3]) { o[0] = v.x, o[1] = v.y, o[2] = v.z; }

/* Eq. 3 on the triangle's UV chart: sigma_s = dP/ds, sigma_t = dP/dt, and the
 * height texture's derivatives along s and t from the reference's bicubic
 * (high-quality magnification) derivative, per texel times the texel count. */
static bg_vec3 tex_surfgrad(const render_scene *S, int prim, const float st[2], const float n[3])
{
    const render_textures *X = S->tex;
    const bg_height_texture *H = &render_tex_material(X, S->mesh, prim)->height;
    if (!H->texels)
        return (bg_vec3){0, 0, 0}; /* a material without a height: no perturbation */
    float ds[3], dt[3];
    render_tex_chart(S->mesh, X, prim, ds, dt);
    bg_vec2 d = bg_height_texture_derivs_bicubic(H, (bg_vec2){st[0], st[1]});
    return bg_surfgrad_from_param_derivs(v3(n), v3(ds), v3(dt),
                                         X->amplitude * d.x * (float)H->width,
                                         X->amplitude * d.y * (float)H->height);
}

/* Listing 1's inputs on the quad: sigma_s, sigma_t = ddx_fine/ddy_fine of the
 * position (the lane's row / column pair, as render_listing1), and Listing 2's
 * taps along ddx/ddy of the texture coordinate, height per pixel. */
static void quad_listing2(const render_scene *S, int prim, const float qp[4][3],
                          const float qst[4][2], int lane, bg_diff_mode mode, float sS[3],
                          float sT[3], float dB[2])
{
    const bg_height_texture *H = &render_tex_material(S->tex, S->mesh, prim)->height;
    int lx = lane & 1, ly = lane >> 1, r = 2 * ly, c = lx;
    for (int a = 0; a < 3; a++)
        sS[a] = qp[r + 1][a] - qp[r][a], sT[a] = qp[c + 2][a] - qp[c][a];
    bg_vec2 dx = {qst[r + 1][0] - qst[r][0], qst[r + 1][1] - qst[r][1]};
    bg_vec2 dy = {qst[c + 2][0] - qst[c][0], qst[c + 2][1] - qst[c][1]};
    bg_vec2 d = H->texels ? bg_height_texture_derivs(H, mode,
                                                     (bg_vec2){qst[lane][0], qst[lane][1]}, dx, dy)
                          : (bg_vec2){0, 0};
    dB[0] = S->tex->amplitude * d.x, dB[1] = S->tex->amplitude * d.y;
}

/* Tangent-space normal mapping in mikkTSpace frames, as its pixel shader
 * decodes ("fast transform out", mikktspace.h): the corner tangents, signs and
 * vertex normals interpolated unnormalized, b = sign n x t, normalize(m.x t +
 * m.y b + m.z n) (bgt_mikk_frame_at, bgt_mikk_decode: the same functions the
 * baker of `bumpgrad mesh` inverts). n is the hit's shading normal, which
 * trace() turns to the viewer on a two-sided mesh: the decoded normal turns
 * with it. */
static bg_vec3 tex_normalmap(const render_scene *S, int prim, const float bc[2], const float st[2],
                             const float n[3])
{
    const render_material *X = render_tex_material(S->tex, S->mesh, prim);
    if (!X->nmap[0].texels)
        return v3(n); /* a material without a normal map: unperturbed */
    const float *T4 = S->mesh->tan + (size_t)prim * 12, *N = S->mesh->nrm + (size_t)prim * 9;
    const float *tc[3] = {T4, T4 + 4, T4 + 8}, *nc[3] = {N, N + 3, N + 6};
    const double w[3] = {1.0f - bc[0] - bc[1], bc[0], bc[1]};
    bgt_mikk_frame f;
    bgt_mikk_frame_at(tc, nc, w, &f);
    bg_vec2 q = {st[0], st[1]};
    const double m[3] = {bg_height_texture_sample(&X->nmap[0], q),
                         bg_height_texture_sample(&X->nmap[1], q),
                         bg_height_texture_sample(&X->nmap[2], q)};
    double out[3];
    if (bgt_mikk_decode(&f, m, out) != 0)
        return v3(n);
    const double side = f.n[0] * n[0] + f.n[1] * n[1] + f.n[2] * n[2] < 0 ? -1.0 : 1.0;
    return (bg_vec3){(float)(side * out[0]), (float)(side * out[1]), (float)(side * out[2])};
}

/* The samples of one tile: tx, ty in tiles, the sample grid SW x SH. */
typedef struct tile_geom {
    int ts, ss, SW, SH;
    int sx0, sy0; /* first sample of the tile */
    size_t ns;    /* samples in the tile */
    float aspect;
    int textured; /* the mesh has UVs and the job textures */
} tile_geom;

/* Copy the hit samples' positions and normals into the batch arrays;
 * bidx maps batch entries back to samples. */
static size_t gather_hits(tile_buf *T, size_t ns)
{
    size_t nb = 0;
    for (size_t k = 0; k < ns; k++)
        if (T->hit[k]) {
            T->bx[nb] = T->p[k * 3], T->by[nb] = T->p[k * 3 + 1], T->bz[nb] = T->p[k * 3 + 2];
            T->bnx[nb] = T->n[k * 3], T->bny[nb] = T->n[k * 3 + 1], T->bnz[nb] = T->n[k * 3 + 2];
            T->bidx[nb++] = (int)k;
        }
    return nb;
}

/* The batch's normals (box, boy, boz) back to their samples, 3 per sample. */
static void scatter_normals(const tile_buf *T, size_t nb, float *dst)
{
    for (size_t b = 0; b < nb; b++) {
        size_t k = (size_t)T->bidx[b];
        dst[k * 3] = T->box[b], dst[k * 3 + 1] = T->boy[b], dst[k * 3 + 2] = T->boz[b];
    }
}

/* 1. Rays and hits for the whole tile, also past the image edge: the quads
 * there still need all four lanes, as on a GPU. Sample (sx, sy) looks through
 * ((sx + 0.5) / SW, (sy + 0.5) / SH) of the image: pixel centres for s = 1,
 * the sub-cell centres otherwise. */
static void tile_rays(const render_scene *S, tile_buf *T, const tile_geom *G)
{
    const int ts = G->ts;
    for (int j = 0; j < ts; j++)
        for (int i = 0; i < ts; i++) {
            size_t k = (size_t)j * ts + i;
            float u = ((2.0f * ((float)(G->sx0 + i) + 0.5f)) / (float)G->SW - 1.0f) * G->aspect *
                      S->tan_half;
            float v = (1.0f - (2.0f * ((float)(G->sy0 + j) + 0.5f)) / (float)G->SH) * S->tan_half;
            float *d = T->dir + k * 3;
            for (int a = 0; a < 3; a++)
                d[a] = S->fwd[a] + u * S->right[a] + v * S->up[a];
            bg_f3_normalize(d);
            T->hit[k] = (unsigned char)trace(S, d, T->p + k * 3, T->n + k * 3, T->nf + k * 3,
                                             &T->prim[k], T->bc + k * 2);
        }
}

/* A grid height is 0 and flat outside its active voxels: count the hits in
 * its active box and those where it gave height 0, for the report. */
static void count_grid(run_ctx *C, const tile_buf *T, size_t nb)
{
    size_t in_box = 0, zero = 0;
    for (size_t b = 0; b < nb; b++) {
        const float p[3] = {T->bx[b], T->by[b], T->bz[b]};
        int in = 1;
        for (int k = 0; k < 3; k++)
            in &= p[k] >= C->grid_box[k] && p[k] <= C->grid_box[3 + k];
        in_box += (size_t)in;
        zero += T->bh[b] == 0.0f;
    }
    atomic_fetch_add(&C->grid_points, nb);
    atomic_fetch_add(&C->grid_in_box, in_box);
    atomic_fetch_add(&C->grid_zero, zero);
}

/* 2. Heights and the reference (analytic surfgrad, Listing 3) in one batch. */
static void tile_solid(run_ctx *C, tile_buf *T, const tile_geom *G)
{
    size_t nb = gather_hits(T, G->ns);
    if (!C->need_solid)
        nb = 0; /* a texture-only job: the solid height is not used */
    bgt_height_perturb(&C->analytic, BG_PERTURB_SURFGRAD, T->bx, T->by, T->bz, T->bnx, T->bny,
                       T->bnz, nb, T->bh, T->box, T->boy, T->boz);
    for (size_t b = 0; b < nb; b++)
        T->h[T->bidx[b]] = T->bh[b];
    if (C->analytic.grid && nb)
        count_grid(C, T, nb);
    scatter_normals(T, nb, T->ref);
}

/* 2b. Texture coordinates of the hits; the reference of a textured job is
 * eq. 3 on the UV chart (surfgrad-heightmap). */
static void tile_texcoords(const run_ctx *C, tile_buf *T, const tile_geom *G)
{
    const render_scene *S = C->job->scene;
    for (size_t k = 0; k < G->ns; k++) {
        if (!T->hit[k])
            continue;
        const float *UV = S->mesh->uv + (size_t)T->prim[k] * 6, *bc = T->bc + k * 2;
        float b0 = 1.0f - bc[0] - bc[1];
        for (int c = 0; c < 2; c++)
            T->st[k * 2 + c] = (b0 * UV[c] + bc[0] * UV[2 + c] + bc[1] * UV[4 + c]) * S->tex->st_scale;
        if (C->tex_ref) {
            bg_vec3 g = tex_surfgrad(S, T->prim[k], T->st + k * 2, T->n + k * 3);
            put3(bg_resolve_normal(v3(T->n + k * 3), &g, NULL, 1), T->ref + k * 3);
        }
    }
}

/* The footprint of sample k on the surface from the ray differentials at the
 * hit (bg_ray_differentials on the face plane, bg_footprint_from_differentials). */
static float hit_footprint(const render_scene *S, const tile_buf *T, const tile_geom *G, size_t k)
{
    const float dxs = 2.0f * G->aspect * S->tan_half / (float)G->SW,
                dys = -2.0f * S->tan_half / (float)G->SH;
    const float *p = T->p + k * 3, *d = T->dir + k * 3;
    /* d is unit: its derivative is (dD - d (d . dD)) / |D|, |D| = 1 / (d . fwd). */
    float invD = bg_f3_dot(d, S->fwd), ddx[3], ddy[3];
    float ddotx = dxs * bg_f3_dot(d, S->right), ddoty = dys * bg_f3_dot(d, S->up);
    for (int a = 0; a < 3; a++) {
        ddx[a] = (dxs * S->right[a] - d[a] * ddotx) * invD;
        ddy[a] = (dys * S->up[a] - d[a] * ddoty) * invD;
    }
    bg_vec3 dpdx, dpdy;
    bg_ray_differentials(v3(p), v3(T->nf + k * 3), v3(S->eye), v3(d), v3(ddx), v3(ddy), &dpdx,
                         &dpdy);
    return bg_footprint_from_differentials(dpdx, dpdy);
}

/* 2c. The detail map of `detail`: the solid turbulence's surface gradient
 * with no octave finer than the sample's footprint (hit_footprint). */
static void tile_detail(run_ctx *C, tile_buf *T, const tile_geom *G)
{
    const render_scene *S = C->job->scene;
    size_t nb = gather_hits(T, G->ns);
    for (size_t b = 0; b < nb; b++)
        T->bh[b] = hit_footprint(S, T, G, (size_t)T->bidx[b]);
    if (C->analytic.grid_path)
        bgt_height_perturb(&C->analytic, BG_PERTURB_SURFGRAD, T->bx, T->by, T->bz, T->bnx, T->bny,
                           T->bnz, nb, NULL, T->box, T->boy, T->boz);
    else
        bg_perturb_height_footprint_batch(&C->analytic.h, BG_PERTURB_SURFGRAD, T->bh, T->bx, T->by,
                                          T->bz, T->bnx, T->bny, T->bnz, nb, NULL, T->box, T->boy,
                                          T->boz);
    for (size_t b = 0; b < nb; b++) {
        size_t k = (size_t)T->bidx[b];
        /* The perturbed normal back to its surface gradient (exact for m . n > 0). */
        bg_vec3 g = bg_surfgrad_from_perturbed_normal(v3(T->n + k * 3),
                                                      (bg_vec3){T->box[b], T->boy[b], T->boz[b]});
        put3(g, T->gd + k * 3);
    }
}

/* 3, one lane l of hit sample k's quad. A lane covered by the same primitive
 * contributes its own values; any other lane is what a GPU makes a helper
 * lane: it interpolates the primitive's attributes beyond its edge. For a
 * triangle that is the extension of its plane; for the analytic sphere we
 * extend the tangent plane of the nearest hit lane of the quad (the ray meets
 * that plane). Returns 1 for a helper lane whose height is still to be
 * evaluated (at qp), 0 otherwise. */
static int quad_lane(const render_scene *S, tile_buf *T, int ts, size_t k, int l)
{
    int i = (int)(k % (size_t)ts), j = (int)(k / (size_t)ts);
    int qi = i & ~1, qj = j & ~1;
    size_t m = (size_t)(qj + (l >> 1)) * ts + (size_t)(qi + (l & 1));
    float *qp = T->qp + k * 12 + l * 3, *qn = T->qn + k * 12 + l * 3;
    T->qok[k * 4 + l] = 1;
    if (T->hit[m] && (!S->mesh || T->prim[m] == T->prim[k])) {
        memcpy(qp, T->p + m * 3, 3 * sizeof(float));
        memcpy(qn, S->mesh ? T->nf + k * 3 : T->n + m * 3, 3 * sizeof(float));
        T->qh[k * 4 + l] = T->h[m];
        return 0;
    }
    const float *P0, *N0;
    if (S->mesh) {
        P0 = S->mesh->pos + (size_t)T->prim[k] * 9;
        N0 = T->nf + k * 3;
    } else {
        size_t src = k;
        for (int x = 1; x < 4; x++) {
            int o = l ^ x;
            size_t mm = (size_t)(qj + (o >> 1)) * ts + (size_t)(qi + (o & 1));
            if (T->hit[mm]) {
                src = mm;
                break;
            }
        }
        P0 = T->p + src * 3;
        N0 = T->n + src * 3;
    }
    const float *d = T->dir + m * 3;
    float w[3] = {P0[0] - S->eye[0], P0[1] - S->eye[1], P0[2] - S->eye[2]};
    float dn = bg_f3_dot(d, N0), t = dn != 0 ? bg_f3_dot(w, N0) / dn : -1.0f;
    if (!(t > 0) || !isfinite(t)) {
        T->qok[k * 4 + l] = 0; /* the plane is edge-on or behind the eye */
        return 0;
    }
    for (int a = 0; a < 3; a++)
        qp[a] = S->eye[a] + t * d[a];
    memcpy(qn, N0, 3 * sizeof(float));
    return 1;
}

/* 3. Quad neighbourhoods for the screen-space methods (quad_lane), their
 * texture coordinates, and the helper lanes' solid heights in one batch. */
static void tile_quads(run_ctx *C, tile_buf *T, const tile_geom *G)
{
    const render_scene *S = C->job->scene;
    size_t nh = 0;
    for (size_t k = 0; k < G->ns; k++) {
        if (!T->hit[k])
            continue;
        for (int l = 0; l < 4; l++)
            if (quad_lane(S, T, G->ts, k, l)) {
                const float *qp = T->qp + k * 12 + l * 3;
                T->bx[nh] = qp[0], T->by[nh] = qp[1], T->bz[nh] = qp[2];
                T->bidx[nh++] = (int)(k * 4 + (size_t)l);
            }
    }
    /* Texture coordinates of the four lanes: the affine extension of the
     * centre sample's triangle, which is what a GPU interpolates for the
     * lanes of a quad (covered or helper) while shading that triangle. */
    if (G->textured)
        for (size_t k = 0; k < G->ns; k++)
            if (T->hit[k])
                for (int l = 0; l < 4; l++)
                    if (T->qok[k * 4 + l])
                        render_tex_st(S->mesh, S->tex, T->prim[k], T->qp + k * 12 + l * 3,
                                      T->qst + k * 8 + l * 2);
    /* Helper-lane heights, one batch (gradients unused: scratch). */
    if (!C->need_solid)
        nh = 0;
    bgt_height_gradient(&C->analytic, T->bx, T->by, T->bz, nh, T->bh, T->box, T->boy, T->boz);
    for (size_t b = 0; b < nh; b++)
        T->qh[T->bidx[b]] = T->bh[b];
}

/* 4, the batch methods: surfgrad-central, additive and surfgrad-footprint,
 * one library batch per tile. surfgrad-footprint (without a VDB height) takes
 * the sample's footprint on the surface from its ray differential: the angle
 * between neighbouring samples times the hit distance, stretched by 1/cos of
 * the view angle (the long axis of the footprint ellipse, so no octave aliases
 * along it; capped at 64x at grazing angles). */
static void method_batch(run_ctx *C, tile_buf *T, const tile_geom *G, render_method M, float *out)
{
    const render_scene *S = C->job->scene;
    size_t nb = gather_hits(T, G->ns);
    if (M == RENDER_SURFGRAD_FOOTPRINT && !C->analytic.grid_path) {
        const float ang = 2.0f * S->tan_half / (float)G->SH;
        for (size_t b = 0; b < nb; b++) {
            size_t k = (size_t)T->bidx[b];
            const float *p = T->p + k * 3, *n = T->n + k * 3, *d = T->dir + k * 3;
            float w[3] = {p[0] - S->eye[0], p[1] - S->eye[1], p[2] - S->eye[2]};
            float c = fabsf(bg_f3_dot(d, n));
            T->bh[b] = sqrtf(bg_f3_dot(w, w)) * ang / (c > 1.0f / 64 ? c : 1.0f / 64);
        }
        bg_perturb_height_footprint_batch(&C->analytic.h, BG_PERTURB_SURFGRAD, T->bh, T->bx, T->by,
                                          T->bz, T->bnx, T->bny, T->bnz, nb, NULL, T->box, T->boy,
                                          T->boz);
    } else {
        bgt_height_perturb(M == RENDER_SURFGRAD_CENTRAL ? &C->central : &C->analytic,
                           M == RENDER_ADDITIVE ? BG_PERTURB_ADDITIVE : BG_PERTURB_SURFGRAD, T->bx,
                           T->by, T->bz, T->bnx, T->bny, T->bnz, nb, T->bh, T->box, T->boy, T->boz);
    }
    scatter_normals(T, nb, out);
}

/* 4, the quad methods of a textured mesh: Listing 1 fed by Listing 2's taps
 * of the height texture, and `detail` (Figure 4(f)): the texture's gradient
 * (Listing 1 as eq. 3 on the screen chart) plus the turbulence detail, one
 * resolve. */
static void method_tex_quad(const render_scene *S, const tile_buf *T, render_method M, size_t k,
                            int lane, float o[3])
{
    const float *n = T->n + k * 3;
    float sS[3], sT[3], dB[2];
    quad_listing2(S, T->prim[k], (const float(*)[3])(T->qp + k * 12),
                  (const float(*)[2])(T->qst + k * 8), lane,
                  M == RENDER_LISTING1_HEIGHTMAP_CENTRAL ? BG_DIFF_CENTRAL : BG_DIFF_FORWARD, sS,
                  sT, dB);
    if (M != RENDER_DETAIL) {
        put3(bg_listing1_normal(v3(n), v3(sS), v3(sT), dB[0], dB[1]), o);
        return;
    }
    bg_vec3 g[2] = {bg_surfgrad_from_screen_derivs(v3(n), v3(sS), v3(sT), dB[0], dB[1]),
                    v3(T->gd + k * 3)};
    put3(bg_resolve_normal(v3(n), g, NULL, 2), o);
}

/* 4, the per-sample methods at hit sample k (lane: its place in its quad). */
static void method_sample(const render_scene *S, const tile_buf *T, render_method M, size_t k,
                          float o[3])
{
    const int ts = T->ts;
    const float *n = T->n + k * 3;
    int i = (int)(k % (size_t)ts), j = (int)(k / (size_t)ts);
    int lane = (i & 1) | ((j & 1) << 1);
    int quad_ok = T->qok[k * 4] & T->qok[k * 4 + 1] & T->qok[k * 4 + 2] & T->qok[k * 4 + 3];
    switch (M) {
    case RENDER_SURFGRAD:
        memcpy(o, T->ref + k * 3, 3 * sizeof(float));
        break;
    case RENDER_LISTING1:
    case RENDER_LISTING1_COARSE:
        if (quad_ok)
            render_listing1((const float(*)[3])(T->qp + k * 12), T->qh + k * 4, lane,
                            M == RENDER_LISTING1, n, o);
        else
            memcpy(o, n, 3 * sizeof(float));
        break;
    case RENDER_SURFGRAD_HEIGHTMAP: {
        bg_vec3 g = tex_surfgrad(S, T->prim[k], T->st + k * 2, n);
        put3(bg_resolve_normal(v3(n), &g, NULL, 1), o);
        break;
    }
    case RENDER_NORMALMAP:
        put3(tex_normalmap(S, T->prim[k], T->bc + k * 2, T->st + k * 2, n), o);
        break;
    case RENDER_LISTING1_HEIGHTMAP:
    case RENDER_LISTING1_HEIGHTMAP_CENTRAL:
    case RENDER_DETAIL:
        if (quad_ok)
            method_tex_quad(S, T, M, k, lane, o);
        else
            memcpy(o, n, 3 * sizeof(float));
        break;
    case RENDER_FLAT: {
        float tau[4][3];
        const float *qp = T->qp + k * 12, *qn = T->qn + k * 12;
        for (int l = 0; l < 4; l++)
            for (int a = 0; a < 3; a++)
                tau[l][a] = qp[l * 3 + a] + T->qh[k * 4 + l] * qn[l * 3 + a];
        if (quad_ok)
            flat_normal((const float(*)[3])tau, (const float(*)[3])qp, lane, T->nf + k * 3, o);
        else
            memcpy(o, T->nf + k * 3, 3 * sizeof(float));
        break;
    }
    default: /* RENDER_NONE */
        memcpy(o, n, 3 * sizeof(float));
        break;
    }
}

/* 4. The methods, each into its slice of T->out. */
static void tile_methods(run_ctx *C, tile_buf *T, const tile_geom *G)
{
    const render_job *J = C->job;
    for (int mi = 0; mi < J->nmethods; mi++) {
        render_method M = J->methods[mi];
        float *out = T->out + (size_t)mi * G->ns * 3;
        if (M == RENDER_SURFGRAD_CENTRAL || M == RENDER_ADDITIVE || M == RENDER_SURFGRAD_FOOTPRINT) {
            method_batch(C, T, G, M, out);
            continue;
        }
        for (size_t k = 0; k < G->ns; k++)
            if (T->hit[k])
                method_sample(J->scene, T, M, k, out + k * 3);
    }
}

/* 5, one sample k of method mi at image sample g: its shaded colour, and its
 * angle error against the reference into the job's error and inward maps.
 * Returns the error (NaN for a miss, which gets the background). */
static float shade_sample(const run_ctx *C, const tile_buf *T, int mi, const float *out,
                          int use_albedo, size_t k, size_t g, float c[3])
{
    render_job *J = C->job;
    const render_scene *S = J->scene;
    if (!T->hit[k]) {
        memcpy(c, background, 3 * sizeof(float));
        J->err[mi][g] = NAN;
        J->inward[mi][g] = 0;
        return NAN;
    }
    const float *o = out + k * 3;
    float alb[3];
    const bg_height_texture *A =
        use_albedo ? render_tex_material(S->tex, S->mesh, T->prim[k])->albedo : NULL;
    if (A && A[0].texels) {
        bg_vec2 q = {T->st[k * 2], T->st[k * 2 + 1]};
        for (int a = 0; a < 3; a++)
            alb[a] = bg_height_texture_sample(&A[a], q);
    } else {
        memcpy(alb, grey_albedo, sizeof alb);
    }
    shade(S, T->p + k * 3, T->dir + k * 3, o, alb, c);
    bg_vec3 a = {o[0], o[1], o[2]}, b = {T->ref[k * 3], T->ref[k * 3 + 1], T->ref[k * 3 + 2]};
    float e = (float)bg_angle_deg(a, b);
    if (!(e == e))
        e = 180.0f; /* a zero normal counts as a total failure */
    J->err[mi][g] = e;
    J->inward[mi][g] = bg_f3_dot(o, T->n + k * 3) <= 0;
    return e;
}

/* 5. Shade, resolve the s x s samples of each pixel, record the errors. */
static void tile_resolve(const run_ctx *C, const tile_buf *T, const tile_geom *G, int tx, int ty)
{
    render_job *J = C->job;
    const int ss = G->ss, px0 = tx * TILE, py0 = ty * TILE;
    const float inv = 1.0f / (float)(ss * ss);
    for (int mi = 0; mi < J->nmethods; mi++) {
        const float *out = T->out + (size_t)mi * G->ns * 3;
        const int use_albedo = G->textured && (J->albedo_mask >> mi & 1u);
        for (int py = py0; py < py0 + TILE && py < J->height_px; py++)
            for (int px = px0; px < px0 + TILE && px < J->width; px++) {
                float acc[3] = {0, 0, 0}, esum = 0;
                int ecount = 0;
                for (int sj = 0; sj < ss; sj++)
                    for (int si = 0; si < ss; si++) {
                        int li = (px - px0) * ss + si, lj = (py - py0) * ss + sj;
                        size_t k = (size_t)lj * G->ts + li;
                        size_t g = (size_t)(py * ss + sj) * (size_t)G->SW + (size_t)(px * ss + si);
                        float c[3];
                        float e = shade_sample(C, T, mi, out, use_albedo, k, g, c);
                        if (T->hit[k])
                            esum += e, ecount++;
                        acc[0] += c[0], acc[1] += c[1], acc[2] += c[2];
                    }
                float *dst = J->rgb[mi] + ((size_t)py * J->width + px) * 3;
                dst[0] = acc[0] * inv, dst[1] = acc[1] * inv, dst[2] = acc[2] * inv;
                J->heat[mi][(size_t)py * J->width + px] = ecount ? esum / (float)ecount : NAN;
            }
    }
}

/* One tile: its G-buffer (steps 1-3), the methods (4), the pixels (5). */
static void tile_render(run_ctx *C, tile_buf *T, int tx, int ty)
{
    const render_job *J = C->job;
    const render_scene *S = J->scene;
    tile_geom G;
    G.ts = T->ts, G.ss = J->ss, G.SW = J->width * J->ss, G.SH = J->height_px * J->ss;
    G.sx0 = tx * TILE * J->ss, G.sy0 = ty * TILE * J->ss;
    G.ns = (size_t)G.ts * G.ts;
    G.aspect = (float)J->width / (float)J->height_px;
    G.textured = S->tex && S->mesh && S->mesh->uv;

    tile_rays(S, T, &G);
    tile_solid(C, T, &G);
    if (G.textured)
        tile_texcoords(C, T, &G);
    if (C->need_detail && G.textured)
        tile_detail(C, T, &G);
    if (C->need_quads)
        tile_quads(C, T, &G);
    tile_methods(C, T, &G);
    tile_resolve(C, T, &G, tx, ty);
}

static void tile_worker(void *ctx, size_t begin, size_t end, int worker)
{
    run_ctx *C = ctx;
    tile_buf T;
    if (tile_alloc(&T, TILE * C->job->ss, C->job->nmethods) != 0) {
        atomic_store(&C->failed, 1);
        return;
    }
    for (size_t t = begin; t < end && !atomic_load(&C->failed); t++) {
        tile_render(C, &T, (int)(t % (size_t)C->tiles_x), (int)(t / (size_t)C->tiles_x));
        size_t done = atomic_fetch_add(&C->done, 1) + 1;
        if (worker == 0)
            bgt_progress_update(C->job->progress, done);
    }
    tile_free(&T);
}

void render_job_free(render_job *job)
{
    for (int i = 0; i < RENDER_MAX_METHODS; i++) {
        free(job->rgb[i]);
        free(job->heat[i]);
        free(job->err[i]);
        free(job->inward[i]);
        job->rgb[i] = job->heat[i] = job->err[i] = NULL;
        job->inward[i] = NULL;
    }
}

bg_status render_run(render_job *job)
{
    size_t npx = (size_t)job->width * job->height_px;
    job->nsamples = npx * (size_t)job->ss * job->ss;
    for (int i = 0; i < job->nmethods; i++) {
        job->rgb[i] = malloc(npx * 3 * sizeof(float));
        job->heat[i] = malloc(npx * sizeof(float));
        job->err[i] = malloc(job->nsamples * sizeof(float));
        job->inward[i] = malloc(job->nsamples);
        if (!job->rgb[i] || !job->heat[i] || !job->err[i] || !job->inward[i]) {
            render_job_free(job);
            return BG_ERR_OUT_OF_MEMORY;
        }
    }
    run_ctx C;
    memset(&C, 0, sizeof C);
    C.job = job;
    C.tiles_x = (job->width + TILE - 1) / TILE;
    C.tiles_y = (job->height_px + TILE - 1) / TILE;
    for (int i = 0; i < job->nmethods; i++)
        if (job->methods[i] == RENDER_LISTING1 || job->methods[i] == RENDER_LISTING1_COARSE ||
            job->methods[i] == RENDER_FLAT || job->methods[i] == RENDER_LISTING1_HEIGHTMAP ||
            job->methods[i] == RENDER_LISTING1_HEIGHTMAP_CENTRAL || job->methods[i] == RENDER_DETAIL)
            C.need_quads = 1;
    /* A textured job with a height texture is compared with eq. 3 of that
     * texture (surfgrad-heightmap); one with only a normal map with the solid
     * height's analytic surface gradient, what a map baked from that height
     * (bumpgrad mesh --bake-normal-map) encodes. */
    const int has_height = job->scene->tex && job->scene->tex->any_height;
    for (int i = 0; i < job->nmethods; i++) {
        C.tex_ref |= render_method_textured(job->methods[i]) && has_height;
        C.need_detail |= job->methods[i] == RENDER_DETAIL;
        C.need_solid |= !render_method_textured(job->methods[i]) && job->methods[i] != RENDER_NONE;
    }
    if (!C.tex_ref)
        C.need_solid = 1; /* the reference is the solid surfgrad */
    /* The reference is always the analytic gradient; surfgrad-central always
     * differences (with the --step the user gave). */
    C.analytic = *job->height;
    C.analytic.h.gradient = BG_GRADIENT_ANALYTIC;
    C.central = *job->height;
    C.central.h.gradient = BG_GRADIENT_CENTRAL;
    atomic_init(&C.failed, 0);
    atomic_init(&C.done, 0);
    atomic_init(&C.grid_points, 0);
    atomic_init(&C.grid_in_box, 0);
    atomic_init(&C.grid_zero, 0);
#if BG_HAVE_TOOLS
    if (C.analytic.grid) {
        bg_vdb_height_info info;
        bg_vdb_height_get_info((const bg_vdb_height *)C.analytic.grid, &info);
        for (int k = 0; k < 3; k++) {
            C.grid_box[k] = (float)(info.world_min[k] - info.voxel_size[k]);
            C.grid_box[3 + k] = (float)(info.world_max[k] + info.voxel_size[k]);
        }
    }
#endif
    size_t ntiles = (size_t)C.tiles_x * C.tiles_y;
    bgt_progress_begin(job->progress, "render", ntiles);
    bgt_parallel_for(ntiles, 1, job->threads, tile_worker, &C);
    bgt_progress_end(job->progress);
    if (atomic_load(&C.failed)) {
        render_job_free(job);
        return BG_ERR_OUT_OF_MEMORY;
    }
    job->grid_points = atomic_load(&C.grid_points);
    job->grid_in_box = atomic_load(&C.grid_in_box);
    job->grid_zero = atomic_load(&C.grid_zero);
    return 0;
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

bg_status render_stats_compute(const render_job *job, int k, render_stats *out)
{
    memset(out, 0, sizeof *out);
    float *v = malloc((job->nsamples ? job->nsamples : 1) * sizeof *v);
    if (!v)
        return BG_ERR_OUT_OF_MEMORY;
    size_t n = 0, inward = 0;
    double sum = 0;
    for (size_t i = 0; i < job->nsamples; i++) {
        float e = job->err[k][i];
        if (e == e) {
            v[n++] = e;
            sum += e;
            inward += job->inward[k][i];
        }
    }
    out->hits = n;
    if (n) {
        qsort(v, n, sizeof *v, cmp_float);
        out->mean_deg = sum / (double)n;
        size_t r = (size_t)ceil(0.99 * (double)n);
        out->p99_deg = v[r ? r - 1 : 0];
        out->max_deg = v[n - 1];
        out->inward_fraction = (double)inward / (double)n;
    }
    free(v);
    return 0;
}
