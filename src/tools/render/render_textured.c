/* SPDX-License-Identifier: MIT */
/* `bumpgrad render --mesh FILE`: a user's mesh (any format assimp reads, via
 * bg_mesh_load) with its texture coordinates, normals and textures, for the
 * texture methods of Mikkelsen 2010 section 6 / Figure 4:
 *  - the mesh is centred and scaled into the unit sphere (automatic framing:
 *    the camera of the built-in scenes then sees all of it);
 *  - vertex normals from the file, or angle-weighted ones when it has none,
 *    and per-corner mikkTSpace tangents and signs (src/tools/mesh: the frames
 *    `bumpgrad mesh --bake-normal-map` bakes in, so its maps render as baked);
 *  - textures from --height-map/--normal-map/--albedo, else from the file's
 *    materials, per triangle (bg_mesh.material/materials: the first diffuse,
 *    height and normal texture of each of assimp's materials, for every
 *    format assimp reads). Without a height map the height is
 *    the gray level of the albedo, the diffuse-to-height method of "Bump Map
 *    Generation"
 *    (bumpgrad heightmap: 0.33 R + 0.66 G + 0.11 B); without a normal map the
 *    normal map is baked from that height (central differences, as
 *    bumpgrad heightmap does).
 * Texture coordinates are (s, t) = st_scale * (u, 1 - v): t runs down the
 * image rows, as bg_height_texture addresses texels. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "bumpgrad/image.h"
#include "bumpgrad/mesh.h"
#include "mesh/mesh_texpath.h"
#include "mesh/mesh.h"
#include "mesh/mesh_frames.h"
#include "mesh/mikktspace.h"
#include "render/render_internal.h"
#include "vecmath.h"

int render_method_textured(render_method m)
{
    return m == RENDER_LISTING1_HEIGHTMAP || m == RENDER_LISTING1_HEIGHTMAP_CENTRAL ||
           m == RENDER_NORMALMAP || m == RENDER_SURFGRAD_HEIGHTMAP || m == RENDER_DETAIL;
}

void render_textures_free(render_textures *t)
{
    for (size_t m = 0; m < t->nmat; m++)
        for (int i = 0; i < 7; i++)
            free(t->mat[m].owned[i]);
    free(t->mat);
    memset(t, 0, sizeof *t);
}

/* Append a, b, c to the report line, truncating at its end; b is a path
 * (or ""), shown without its folder when it came from the material library
 * (*at's line then lists a set per material). */
static void desc_add(char *desc, size_t len, size_t *at, int desc_short, const char *a,
                     const char *b, const char *c)
{
    if (*at + 1 >= len)
        return;
    const char *slash = desc_short ? strrchr(b, '/') : NULL;
    b = slash ? slash + 1 : b;
    int n = snprintf(desc + *at, len - *at, "%s%s%s", a, b, c);
    *at = n < 0 ? *at : *at + (size_t)n < len ? *at + (size_t)n : len - 1;
}


static float srgb_to_linear(float c)
{
    return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
}

/* Read `path` as an image; any failure is the caller's input at fault (exit 2). */
static bg_status read_one(const char *what, const char *path, bg_image *img, bgt_err *e)
{
    char err[512];
    bg_status s = bg_image_read(path, img, err, sizeof err);
    if (s != BG_OK)
        return bgt_fail(e, s == BG_ERR_OUT_OF_MEMORY ? s : BG_ERR_FORMAT, "%s \"%s\": %s", what,
                        path, err);
    for (size_t i = 0; i < (size_t)img->width * img->height * img->channels; i++)
        if (!isfinite(img->pixels[i])) {
            bg_image_free(img);
            return bgt_fail(e, BG_ERR_FORMAT, "%s \"%s\": holds NaN or Inf texels", what, path);
        }
    return BG_OK;
}

/* ---- UDIM texture sets ----
 * `--normal-map 'n.<UDIM>.png'` (and --height-map, --albedo) reads the tiles
 * that `bumpgrad mesh` writes. The tiles are placed side by side in one
 * texture (tile (a, b) at column a, row nv - 1 - b: v grows upward) and the
 * mesh's UVs are divided by (nu, nv) when it is loaded, so that every sample
 * lands in its tile's part; a texture without the token is repeated in every
 * part, which is what its wrap did before. Texture slopes and mikkTSpace
 * directions do not change under this per-axis scaling of UVs and texels
 * alike. Missing tiles inside the nu x nv range are black. */
typedef struct udim_layout {
    int nu, nv; /* tiles across and up (0: no set) */
} udim_layout;

static int file_exists(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISREG(st.st_mode);
}

/* The tile range of the sets the options name (their union). */
static bg_status udim_scan(const render_opts *o, udim_layout *ul, bgt_err *e)
{
    static const char *const option[3] = {"--albedo", "--height-map", "--normal-map"};
    const char *const given[3] = {o->albedo_map, o->height_map, o->normal_map};
    ul->nu = ul->nv = 0;
    for (int k = 0; k < 3; k++) {
        if (!given[k] || !strstr(given[k], MESH_UDIM_TOKEN))
            continue;
        int found = 0;
        for (int b = 0; b < MESH_UDIM_V_TILES; b++)
            for (int a = 0; a < 10; a++) {
                char *p = mesh_udim_path(given[k], 1001 + a + 10 * b);
                if (!p)
                    return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
                if (file_exists(p)) {
                    found = 1;
                    ul->nu = a + 1 > ul->nu ? a + 1 : ul->nu;
                    ul->nv = b + 1 > ul->nv ? b + 1 : ul->nv;
                }
                free(p);
            }
        if (!found)
            return bgt_fail(e, BG_ERR_FORMAT,
                            "%s \"%s\": no tile of this UDIM set exists (the token stands for "
                            "1001, 1002, ...)",
                            option[k], given[k]);
    }
    return BG_OK;
}

/* A texture, or with a UDIM layout the nu x nv atlas of its tiles (or of
 * copies of a plain texture). */
static bg_status read_texture(const char *what, const char *path, const udim_layout *ul,
                              bg_image *img, bgt_err *e)
{
    if (!ul || ul->nu == 0)
        return read_one(what, path, img, e);
    const int set = strstr(path, MESH_UDIM_TOKEN) != NULL;
    bg_image atlas = {0}, tile;
    bg_status s = BG_OK;
    int W = 0, H = 0, C = 0;
    for (int b = 0; b < ul->nv && s == BG_OK; b++)
        for (int a = 0; a < ul->nu && s == BG_OK; a++) {
            char *p = set ? mesh_udim_path(path, 1001 + a + 10 * b) : strdup(path);
            if (!p)
                return bg_image_free(&atlas), bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
            if (set && !file_exists(p)) {
                free(p);
                continue;
            }
            if ((s = read_one(what, p, &tile, e)) == BG_OK) {
                if (!atlas.pixels) {
                    W = tile.width, H = tile.height, C = tile.channels;
                    s = bgt_check_alloc((double)W * H * C * ul->nu * ul->nv * sizeof(float),
                                        "the UDIM texture", e);
                    if (s == BG_OK && bg_image_alloc(&atlas, W * ul->nu, H * ul->nv, C) != BG_OK)
                        s = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
                    if (s == BG_OK)
                        memset(atlas.pixels, 0, (size_t)W * H * C * ul->nu * ul->nv * sizeof(float));
                }
                if (s == BG_OK && (tile.width != W || tile.height != H || tile.channels != C))
                    s = bgt_fail(e, BG_ERR_FORMAT,
                                 "%s \"%s\": %dx%d with %d channels, the set's first tile has "
                                 "%dx%d with %d",
                                 what, p, tile.width, tile.height, tile.channels, W, H, C);
                for (int y = 0; s == BG_OK && y < H; y++)
                    memcpy(atlas.pixels +
                               (((size_t)(ul->nv - 1 - b) * H + (size_t)y) * (size_t)W * ul->nu +
                                (size_t)a * W) * C,
                           tile.pixels + (size_t)y * W * C, (size_t)W * C * sizeof(float));
                bg_image_free(&tile);
            }
            free(p);
        }
    if (s != BG_OK) {
        bg_image_free(&atlas);
        return s;
    }
    *img = atlas;
    return BG_OK;
}

/* The gray level of "Bump Map Generation" (bumpgrad heightmap --gray diffuse):
 * 0.33 R + 0.66 G + 0.11 B
 * of the stored (not linearized) values; one- and two-channel images: channel 0. */
static float gray(const float *px, int ch)
{
    return ch >= 3 ? 0.33f * px[0] + 0.66f * px[1] + 0.11f * px[2] : px[0];
}

static int need_texture(const render_opts *o, render_method which)
{
    for (int i = 0; i < o->nmethods; i++)
        if (o->methods[i] == which)
            return 1;
    return 0;
}

static int any_textured(const render_opts *o)
{
    if (o->preset == PRESET_FIG4)
        return 1;
    for (int i = 0; i < o->nmethods; i++)
        if (render_method_textured(o->methods[i]))
            return 1;
    return 0;
}

/* dP/ds and dP/dt of triangle P with corner coordinates st (eq. 3's sigma_s,
 * sigma_t on the UV chart); 0 for a degenerate UV triangle. */
static int tri_chart(const float *P, const float *st, float ds[3], float dt[3])
{
    float e1[3], e2[3];
    for (int a = 0; a < 3; a++)
        e1[a] = P[3 + a] - P[a], e2[a] = P[6 + a] - P[a];
    float s1 = st[2] - st[0], t1 = st[3] - st[1], s2 = st[4] - st[0], t2 = st[5] - st[1];
    float det = s1 * t2 - s2 * t1;
    if (!(fabsf(det) > 0) || !isfinite(det))
        return 0;
    float r = 1.0f / det;
    for (int a = 0; a < 3; a++) {
        ds[a] = (t2 * e1[a] - t1 * e2[a]) * r;
        dt[a] = (s1 * e2[a] - s2 * e1[a]) * r;
    }
    return 1;
}

void render_tex_chart(const render_mesh *m, const render_textures *tx, int prim, float ds[3],
                      float dt[3])
{
    float st[6];
    for (int i = 0; i < 6; i++)
        st[i] = m->uv[(size_t)prim * 6 + i] * tx->st_scale;
    if (!tri_chart(m->pos + (size_t)prim * 9, st, ds, dt))
        for (int a = 0; a < 3; a++)
            ds[a] = dt[a] = 0.0f;
}

void render_tex_st(const render_mesh *m, const render_textures *tx, int prim, const float p[3],
                   float st[2])
{
    /* Barycentrics of p (on or off the triangle, in its plane) by least squares:
     * the affine extension a GPU's helper lanes interpolate. */
    const float *P = m->pos + (size_t)prim * 9, *UV = m->uv + (size_t)prim * 6;
    double e1[3], e2[3], w[3];
    for (int a = 0; a < 3; a++)
        e1[a] = P[3 + a] - P[a], e2[a] = P[6 + a] - P[a], w[a] = p[a] - P[a];
    double a11 = 0, a12 = 0, a22 = 0, r1 = 0, r2 = 0;
    for (int a = 0; a < 3; a++) {
        a11 += e1[a] * e1[a], a12 += e1[a] * e2[a], a22 += e2[a] * e2[a];
        r1 += e1[a] * w[a], r2 += e2[a] * w[a];
    }
    double det = a11 * a22 - a12 * a12;
    double b1 = det != 0 ? (a22 * r1 - a12 * r2) / det : 0, b2 = det != 0 ? (a11 * r2 - a12 * r1) / det : 0;
    for (int c = 0; c < 2; c++)
        st[c] = (float)((UV[c] + b1 * (UV[2 + c] - UV[c]) + b2 * (UV[4 + c] - UV[c])) *
                        tx->st_scale);
}

/* Texel conversions of image pixels (px: one pixel's `n` stored values). */
static float texel_albedo(const float *px, int n, int ch)
{
    return srgb_to_linear(px[ch < n ? ch : 0]);
}
static float texel_height(const float *px, int n, int ch)
{
    (void)ch;
    return gray(px, n);
}
static float texel_normal(const float *px, int n, int ch)
{
    /* Stored 0.5 m + 0.5 with +y up the image (OpenGL), i.e. along +v: the
     * mikkTSpace bitangent sign * n x t, which points along dP/dv (bumpgrad
     * mesh --bake-normal-map writes this). */
    (void)n;
    return 2.0f * px[ch] - 1.0f;
}

/* Convert img into `nch` textures (tex[c] owning owned[c]) with `texel`,
 * and free img. BG_OK or BG_ERR_OUT_OF_MEMORY. */
static bg_status image_to_textures(bg_image *img, int nch,
                                   float (*texel)(const float *, int, int), float **owned,
                                   bg_height_texture *tex, bgt_err *e)
{
    size_t np_ = (size_t)img->width * img->height;
    for (int ch = 0; ch < nch; ch++) {
        float *tx = malloc((np_ ? np_ : 1) * sizeof(float));
        if (!tx) {
            bg_image_free(img);
            return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
        }
        for (size_t i = 0; i < np_; i++)
            tx[i] = texel(img->pixels + i * img->channels, img->channels, ch);
        owned[ch] = tx;
        tex[ch] = (bg_height_texture){img->width, img->height, tx, BG_WRAP_REPEAT};
    }
    bg_image_free(img);
    return BG_OK;
}

/* The texture set of one material: the albedo (sRGB to linear), the height
 * (the height map's gray level, else the albedo's: the diffuse-to-height
 * method of "Bump Map Generation") and the tangent-space normal map (the file, else baked from the
 * height). hp, np, ap: paths or NULL; what[]: their origins in messages (the
 * option, or the material: texture_origins). ls, lt: the mesh's mean |dP/ds|,
 * |dP/dt|. */
static bg_status load_material(const render_opts *o, const udim_layout *ul, const char *hp,
                               const char *np, const char *ap, const char *const what[3],
                               int want_nmap,
                               double ls, double lt, const render_textures *t,
                               render_material *M, char *desc, size_t desclen, size_t *dl,
                               int short_names, bgt_err *e)
{
    bg_image img;
    bg_status s;
    if (ap && !o->no_albedo) {
        if ((s = read_texture(what[0], ap, ul, &img, e)) != BG_OK ||
            (s = image_to_textures(&img, 3, texel_albedo, M->owned, M->albedo, e)) != BG_OK)
            return s;
        desc_add(desc, desclen, dl, short_names, " albedo=", ap, "");
    }
    const char *hsrc = hp ? hp : ap;
    if (hsrc) {
        if ((s = read_texture(hp ? what[1] : what[0], hsrc, ul, &img, e)) != BG_OK ||
            (s = image_to_textures(&img, 1, texel_height, M->owned + 3, &M->height, e)) != BG_OK)
            return s;
        desc_add(desc, desclen, dl, short_names, " height=", hsrc, hp ? "" : "(gray-of-albedo)");
    }
    if (want_nmap && np) {
        if ((s = read_texture(what[2], np, ul, &img, e)) != BG_OK)
            return s;
        if (img.channels < 3) {
            bg_image_free(&img);
            return bgt_fail(e, BG_ERR_FORMAT, "%s \"%s\": needs 3 channels, has %d", what[2],
                            np, img.channels);
        }
        if ((s = image_to_textures(&img, 3, texel_normal, M->owned + 4, M->nmap, e)) != BG_OK)
            return s;
        desc_add(desc, desclen, dl, short_names, " normalmap=", np, "");
    } else if (want_nmap && M->height.texels) {
        /* Bake the tangent-space normal map of the height texture ("Bump Map
         * Generation"'s diffuse-to-normal step, bumpgrad heightmap): slopes per unit length
         * along unit tangents, using the mesh's average |dP/ds|, |dP/dt| (a
         * normal map stores one scale for the whole surface; that is the
         * approximation normal mapping makes, visible where the UV chart
         * stretches). */
        const int W = M->height.width, H = M->height.height;
        const float *h = M->height.texels;
        float ks = (float)(t->amplitude * W * t->st_scale / (ls > 0 ? ls : 1)),
              kt = (float)(t->amplitude * H * t->st_scale / (lt > 0 ? lt : 1));
        /* d/ds of the texture in st_scale-scaled coordinates: beta_s per texel * W;
         * |dP/ds| of the scaled chart is ls / st_scale. */
        for (int ch = 0; ch < 3; ch++) {
            M->owned[4 + ch] = malloc((size_t)W * H * sizeof(float));
            if (!M->owned[4 + ch])
                return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
            M->nmap[ch] = (bg_height_texture){W, H, M->owned[4 + ch], BG_WRAP_REPEAT};
        }
        for (int j = 0; j < H; j++)
            for (int i = 0; i < W; i++) {
                float a = 0.5f * (h[(size_t)j * W + (i + 1) % W] - h[(size_t)j * W + (i + W - 1) % W]);
                float b = 0.5f * (h[(size_t)((j + 1) % H) * W + i] - h[(size_t)((j + H - 1) % H) * W + i]);
                /* b is d/dt down the rows, = -d/dv: m.y = -dh/dv = +kt b
                 * (green up, the frame of the decoding in render_core). */
                float n[3] = {-ks * a, kt * b, 1.0f};
                bg_f3_normalize(n);
                for (int ch = 0; ch < 3; ch++)
                    M->owned[4 + ch][(size_t)j * W + i] = n[ch];
            }
        desc_add(desc, desclen, dl, short_names, " normalmap=baked-from-height", "", "");
    }
    return BG_OK;
}

/* Where the textures of one set come from (k: 0 albedo, 1 height, 2 normal
 * map; path[k] NULL when none is used): an option's file as given, labelled
 * by the option; else material `index`'s (me), looked for where an exported
 * mesh's textures usually are (mesh_texture_find: a path written on another
 * machine) and labelled by the material. path[k] is replaced by the file
 * found, owned by found[k]. */
static bg_status texture_origins(const render_opts *o, const bg_mesh_material *me, size_t index,
                                 const char *path[3], char *found[3], char what[3][600],
                                 bgt_err *e)
{
    static const char *const option[3] = {"--albedo", "--height-map", "--normal-map"};
    static const char *const kind[3] = {"diffuse", "height", "normal"};
    const char *const given[3] = {o->albedo_map, o->height_map, o->normal_map};
    for (int k = 0; k < 3; k++) {
        if (given[k] || !me) {
            snprintf(what[k], sizeof what[k], "%s", option[k]);
            continue;
        }
        char origin[512];
        snprintf(what[k], sizeof what[k], "%s, %s texture",
                 mesh_texture_origin(origin, sizeof origin, o->mesh_path, index, me->name),
                 kind[k]);
        if (path[k] && !(path[k] = found[k] = mesh_texture_find(o->mesh_path, index, me->name,
                                                                 kind[k], path[k], e)))
            return e && e->status != BG_OK ? e->status : BG_ERR_OUT_OF_MEMORY;
    }
    return BG_OK;
}

/* ---- loading ---- */
/* Triangle I (3 indices) has its corners in range and finite: others are dropped. */
static int tri_finite(const uint32_t *I, const float *vp, size_t nv)
{
    int ok = 1;
    for (int k = 0; k < 3; k++)
        ok &= I[k] < nv && isfinite(vp[I[k] * 3]) && isfinite(vp[I[k] * 3 + 1]) &&
              isfinite(vp[I[k] * 3 + 2]);
    return ok;
}

/* The mesh from --mesh; with a texture method it must have UVs. */
static bg_status read_mesh(const render_opts *o, bg_mesh *bm, bgt_err *e)
{
    char err[512];
    bg_status s = bg_mesh_load(o->mesh_path, bm, err, sizeof err);
    if (s != BG_OK)
        /* A missing or unreadable mesh is the caller's input at fault: exit 2. */
        return bgt_fail(e, s == BG_ERR_OUT_OF_MEMORY ? s : BG_ERR_FORMAT, "--mesh: %s", err);
    if (any_textured(o) && !bm->u) {
        bg_mesh_free(bm);
        return bgt_fail(e, BG_ERR_FORMAT,
                        "--mesh \"%s\": the mesh has no texture coordinates (UVs), which the "
                        "texture methods (listing1-heightmap, normalmap, surfgrad-heightmap, detail, "
                        "--preset fig4) need",
                        o->mesh_path);
    }
    return BG_OK;
}

/* Vertex attributes: vp the positions normalized into the unit sphere, vn
 * the unit vertex normals of the mesh tool (mesh_frames.c: the file's,
 * renormalized, else angle-weighted), so that a normal map baked by
 * `bumpgrad mesh` is decoded here in the frame it was baked in; sn the same
 * normals as three arrays (x, y, z), for mikkTSpace. All or none allocated. */
static bg_status vertex_arrays(const bg_mesh *bm, const double c[3], double rad, float **vp,
                               float **vn, float **sn)
{
    const size_t nv = bm->vertex_count;
    float *p = malloc(nv * 3 * sizeof(float)), *n = malloc(nv * 3 * sizeof(float));
    float *q = malloc((nv ? nv : 1) * 3 * sizeof(float));
    if (!p || !n || !q)
        goto oom;
    float *snx = q, *sny = q + nv, *snz = q + 2 * nv;
    if (bm->nx) {
        memcpy(snx, bm->nx, nv * sizeof(float));
        memcpy(sny, bm->ny, nv * sizeof(float));
        memcpy(snz, bm->nz, nv * sizeof(float));
        mesh_normalize_normals(nv, snx, sny, snz);
    } else if (mesh_vertex_normals(bm, snx, sny, snz) == (size_t)-1) {
        goto oom;
    }
    for (size_t i = 0; i < nv; i++) {
        p[i * 3] = mesh_model_coord(bm->px[i], c[0], rad);
        p[i * 3 + 1] = mesh_model_coord(bm->py[i], c[1], rad);
        p[i * 3 + 2] = mesh_model_coord(bm->pz[i], c[2], rad);
        n[i * 3] = snx[i], n[i * 3 + 1] = sny[i], n[i * 3 + 2] = snz[i];
        /* (0,0,0): the face normal is used there (render_core trace) */
    }
    *vp = p, *vn = n, *sn = q;
    return BG_OK;
oom:
    free(p), free(n), free(q);
    return BG_ERR_OUT_OF_MEMORY;
}

/* Per-corner mikkTSpace tangents and signs (mikktspace.h), of the file's
 * positions and UVs and the normals sn: the frames `bumpgrad mesh
 * --bake-normal-map` encodes in (mesh_bake.c). Only the normalmap method
 * reads them, and a million triangles take seconds (docs/FIGURES.md,
 * scale): computed only for it (want_nmap); *ctan stays NULL otherwise. */
static bg_status mesh_tangents(const render_opts *o, const bg_mesh *bm, const float *sn,
                               int want_nmap, float **ctan, bgt_err *e)
{
    *ctan = NULL;
    if (!bm->u || !want_nmap)
        return BG_OK;
    const size_t nv = bm->vertex_count;
    float *t = malloc((bm->triangle_count ? bm->triangle_count : 1) * 12 * sizeof(float));
    bgt_mikk_mesh mm = {nv, bm->triangle_count, bm->indices, bm->px, bm->py, bm->pz,
                        sn, sn + nv, sn + 2 * nv, bm->u, bm->v};
    bg_status s = t ? bgt_mikk_tangents(&mm, t, NULL) : BG_ERR_OUT_OF_MEMORY;
    if (s != BG_OK) {
        free(t);
        return bgt_fail(e, s, "--mesh \"%s\": mikkTSpace tangents failed (%s)", o->mesh_path,
                        bg_status_string(s));
    }
    *ctan = t;
    return BG_OK;
}

/* The kept triangles (finite corners) as the renderer's flat arrays, 3
 * corners each: positions, normals, UVs (v flipped) and tangents when the
 * mesh has them, the material set of each (tmat, with per-triangle ids)
 * and which sets are used; and the area-weighted mean |dP/ds|, |dP/dt|
 * (for the normal-map bake's scale). */
typedef struct flat_tris {
    size_t keep, nsets;
    float *pos, *nrm, *uv, *tan;
    uint32_t *tmat;
    unsigned char *used;
    double ls, lt;
} flat_tris;

static void flat_free(flat_tris *ft)
{
    free(ft->pos), free(ft->nrm), free(ft->uv), free(ft->tan), free(ft->tmat), free(ft->used);
    memset(ft, 0, sizeof *ft);
}

/* Materials: the loader's (bg_mesh.material, .materials): set i is material
 * i, triangle f uses ids[f]; without per-triangle ids (at most one material)
 * one set, material 0's, covers the mesh. A face with no known material (an
 * OBJ face before any usemtl) is in assimp's default material, which names
 * no texture. */
static bg_status flatten(const bg_mesh *bm, const float *vp, const float *vn, const float *ctan,
                         size_t keep, flat_tris *ft)
{
    const size_t nv = bm->vertex_count;
    const uint32_t *ids = bm->u ? bm->material : NULL;
    memset(ft, 0, sizeof *ft);
    ft->keep = keep;
    ft->nsets = ids ? (bm->u ? bm->material_count : 0) : 1;
    ft->used = calloc(ft->nsets, 1);
    ft->tmat = ids ? malloc(keep * sizeof *ft->tmat) : NULL;
    ft->pos = malloc(keep * 9 * sizeof(float)), ft->nrm = malloc(keep * 9 * sizeof(float));
    ft->uv = bm->u ? malloc(keep * 6 * sizeof(float)) : NULL;
    ft->tan = ctan ? malloc(keep * 12 * sizeof(float)) : NULL;
    if (!ft->pos || !ft->nrm || (bm->u && !ft->uv) || (ctan && !ft->tan) || !ft->used ||
        (ids && !ft->tmat)) {
        flat_free(ft);
        return BG_ERR_OUT_OF_MEMORY;
    }
    float *pos = ft->pos, *nrm = ft->nrm, *uv = ft->uv, *tan = ft->tan;
    size_t w = 0;
    double len_s = 0, len_t = 0, wsum = 0;
    for (size_t f = 0; f < bm->triangle_count; f++) {
        const uint32_t *I = bm->indices + f * 3;
        if (!tri_finite(I, vp, nv))
            continue;
        ft->used[ids ? ids[f] : 0] = 1;
        if (ft->tmat)
            ft->tmat[w] = ids[f];
        for (int k = 0; k < 3; k++) {
            memcpy(pos + w * 9 + k * 3, vp + I[k] * 3, 3 * sizeof(float));
            memcpy(nrm + w * 9 + k * 3, vn + I[k] * 3, 3 * sizeof(float));
            if (bm->u) {
                uv[w * 6 + k * 2] = bm->u[I[k]], uv[w * 6 + k * 2 + 1] = 1.0f - bm->v[I[k]];
                if (ctan)
                    memcpy(tan + w * 12 + k * 4, ctan + (f * 3 + k) * 4, 4 * sizeof(float));
            }
        }
        if (bm->u) {
            float ds[3], dt[3];
            const float *P = pos + w * 9;
            float e1[3] = {P[3] - P[0], P[4] - P[1], P[5] - P[2]}, e2[3] = {P[6] - P[0], P[7] - P[1], P[8] - P[2]}, fn[3];
            bg_f3_cross(e1, e2, fn);
            double area = sqrt((double)bg_f3_dot(fn, fn));
            if (tri_chart(P, uv + w * 6, ds, dt) && isfinite(area)) {
                len_s += area * sqrt((double)bg_f3_dot(ds, ds));
                len_t += area * sqrt((double)bg_f3_dot(dt, dt));
                wsum += area;
            }
        }
        w++;
    }
    ft->ls = wsum > 0 ? len_s / wsum : 1.0, ft->lt = wsum > 0 ? len_t / wsum : 1.0;
    return BG_OK;
}

/* The mesh as the renderer's flat triangles in m (and their material sets in
 * ft: used, nsets, ls, lt); the geometry of bm is freed on the way, as large
 * meshes need the memory, its materials stay. */
static bg_status mesh_geometry(const render_opts *o, bg_mesh *bm, int want_nmap, render_mesh *m,
                               flat_tris *ft, bgt_err *e)
{
    double c[3];
    const double rad = mesh_bounding_sphere(bm, c);
    if (!(rad > 0))
        return bgt_fail(e, BG_ERR_FORMAT, "--mesh \"%s\": no finite triangle of nonzero size",
                        o->mesh_path);
    float *vp, *vn, *sn, *ctan;
    if (vertex_arrays(bm, c, rad, &vp, &vn, &sn) != BG_OK)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    bg_status s = mesh_tangents(o, bm, sn, want_nmap, &ctan, e);
    free(sn);
    if (s != BG_OK) {
        free(vp), free(vn);
        return s;
    }
    size_t keep = 0;
    for (size_t f = 0; f < bm->triangle_count; f++)
        keep += tri_finite(bm->indices + f * 3, vp, bm->vertex_count);
    if (keep == 0)
        s = bgt_fail(e, BG_ERR_FORMAT, "--mesh \"%s\": no triangle with finite corners",
                     o->mesh_path);
    else if (flatten(bm, vp, vn, ctan, keep, ft) != BG_OK)
        s = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    free(vp), free(vn), free(ctan);
    if (s != BG_OK)
        return s;
    /* Keep only the materials (a mesh holding just them, for bg_mesh_free). */
    bg_mesh mats = {0};
    mats.materials = bm->materials, mats.material_count = bm->material_count;
    mats.embedded_textures = bm->embedded_textures;
    bm->materials = NULL, bm->material_count = 0;
    bg_mesh_free(bm);
    *bm = mats;
    if ((s = render_mesh_adopt(m, keep, ft->pos, ft->nrm, ft->uv, ft->tan)) != BG_OK) {
        ft->pos = ft->nrm = ft->uv = ft->tan = NULL; /* adopt freed them */
        flat_free(ft);
        return bgt_fail(e, s, "out of memory");
    }
    ft->pos = ft->nrm = ft->uv = ft->tan = NULL; /* m's now */
    m->mat = ft->tmat, ft->tmat = NULL;
    return BG_OK;
}

/* The textures of every used material set (mats: the mesh's materials),
 * then the checks that the methods asked for find theirs. */
static bg_status mesh_textures(const render_opts *o, const udim_layout *ul, const bg_mesh *mats,
                               const flat_tris *ft, int want_nmap, render_textures *t, char *desc,
                               size_t desclen, bgt_err *e)
{
    const size_t nsets = ft->nsets, nmt = mats->material_count;
    t->mat = calloc(nsets, sizeof *t->mat);
    if (!t->mat)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    t->nmat = nsets;
    size_t dl = 0;
    bg_status s;
    for (size_t i = 0; i < nsets; i++) {
        if (!ft->used[i])
            continue;
        /* set i: material i of the file (without per-triangle ids: material 0, if any) */
        const bg_mesh_material *me = i < nmt ? &mats->materials[i] : NULL;
        const char *hp = o->height_map ? o->height_map : me ? me->height : NULL;
        const char *np = o->normal_map ? o->normal_map : me ? me->normal : NULL;
        const char *ap = o->albedo_map ? o->albedo_map : me ? me->diffuse : NULL;
        if (nsets > 1 && me && (hp || np || ap))
            desc_add(desc, desclen, &dl, 0, " [", me->name, "]");
        const char *path[3] = {ap && (!o->no_albedo || !hp) ? ap : NULL, hp,
                               want_nmap ? np : NULL};
        char *found[3] = {NULL, NULL, NULL}, what[3][600];
        s = texture_origins(o, me, i, path, found, what, e);
        if (s == BG_OK) {
            const char *const labels[3] = {what[0], what[1], what[2]};
            s = load_material(o, ul, path[1], path[2], path[0], labels, want_nmap, ft->ls, ft->lt, t,
                              &t->mat[i], desc, desclen, &dl, nsets > 1, e);
        }
        free(found[0]), free(found[1]), free(found[2]);
        if (s != BG_OK)
            return s;
        t->any_height |= t->mat[i].height.texels != NULL;
        t->any_nmap |= t->mat[i].nmap[0].texels != NULL;
    }
    const size_t embedded = mats->embedded_textures;
    if (embedded) { /* the loader does not extract "*N" textures */
        char count[32];
        snprintf(count, sizeof count, "%zu", embedded);
        desc_add(desc, desclen, &dl, 0, " (embedded textures skipped: ", count, ")");
    }
    if (any_textured(o) && !t->any_height &&
        (need_texture(o, RENDER_LISTING1_HEIGHTMAP) || need_texture(o, RENDER_LISTING1_HEIGHTMAP_CENTRAL) ||
         need_texture(o, RENDER_SURFGRAD_HEIGHTMAP) || need_texture(o, RENDER_DETAIL) ||
         o->preset == PRESET_FIG4))
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--mesh \"%s\": no height texture: give --height-map or --albedo (its "
                        "materials name none%s)",
                        o->mesh_path,
                        embedded ? "; textures embedded in the file are not extracted" : "");
    if (need_texture(o, RENDER_NORMALMAP) && !t->any_nmap)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--mesh \"%s\": normalmap needs --normal-map, --height-map or --albedo",
                        o->mesh_path);
    return BG_OK;
}

bg_status render_load_mesh(const render_opts *o, render_mesh *m,
                           render_textures *t, char *desc, size_t desclen, bgt_err *e)
{
    memset(m, 0, sizeof *m);
    memset(t, 0, sizeof *t);
    if (desclen)
        desc[0] = '\0';
    bg_mesh bm;
    bg_status s = read_mesh(o, &bm, e);
    if (s != BG_OK)
        return s;
    const int has_uv = bm.u != NULL;
    udim_layout ul;
    if ((s = udim_scan(o, &ul, e)) != BG_OK) {
        bg_mesh_free(&bm);
        return s;
    }
    if (has_uv && ul.nu > 0) /* into the atlas of the UDIM tiles (read_texture) */
        for (size_t i = 0; i < bm.vertex_count; i++)
            bm.u[i] /= (float)ul.nu, bm.v[i] /= (float)ul.nv;
    const int want_nmap = need_texture(o, RENDER_NORMALMAP) || o->preset == PRESET_FIG4;
    flat_tris ft;
    if ((s = mesh_geometry(o, &bm, want_nmap, m, &ft, e)) != BG_OK) {
        bg_mesh_free(&bm);
        return s;
    }
    /* bm holds only the materials now */
    t->amplitude = o->tex_amplitude;
    t->st_scale = o->st_scale > 0 ? o->st_scale : 1.0f;
    if (!has_uv) {
        t->mat = calloc(1, sizeof *t->mat); /* one empty set: the procedural methods */
        t->nmat = t->mat ? 1 : 0;
        s = t->mat ? BG_OK : bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    } else {
        s = mesh_textures(o, &ul, &bm, &ft, want_nmap, t, desc, desclen, e);
    }
    bg_mesh_free(&bm);
    flat_free(&ft);
    if (s != BG_OK) {
        render_textures_free(t);
        render_mesh_free(m);
    }
    return s;
}
