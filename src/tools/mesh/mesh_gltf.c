/* SPDX-License-Identifier: MIT */
/* glTF 2.0 writer of `bumpgrad mesh` (.gltf with the buffer embedded as a
 * base64 data URI, or binary .glb): one node and one mesh per part of the
 * source (bg_mesh_part: a node of its scene, instances apart), each node named
 * after the source node and with the identity transform (the vertices are in
 * the model space they were baked in), each mesh with one triangle primitive
 * per run of one material, whose POSITION, NORMAL, TANGENT (VEC4: xyz and the
 * bitangent sign w, the mikkTSpace frame) and TEXCOORD_0 are the mesh's own
 * vertices (shared by its primitives; one bufferView per attribute for all
 * meshes), uint32 indices, and the materials with their base colour and
 * normal textures (embedded as bufferViews, or referenced by a relative URI).
 * Our own writer:
 * assimp 5.2's glTF exporter writes TANGENT as VEC3 without the sign, which
 * the glTF 2.0 specification (3.7.2.1, "XYZW vertex tangents where the XYZ
 * portion is normalized, and the W component is a sign value (-1 or +1)")
 * does not allow.
 *
 * mikkTSpace frames are per corner; glTF attributes are per vertex. So a
 * vertex whose corners carry different tangents (a fan split, a mirrored
 * seam) is written once per distinct tangent, as mikktspace.h asks ("generate
 * a new index list"); positions, normals and UVs are copied, the triangles
 * and their winding are kept.
 *
 * UVs: ours have v up (OpenGL); glTF's origin is the top-left corner, so
 * TEXCOORD_0 = (u, 1 - v), which is also what assimp's importer flips back.
 * The tangent frame is the one our tangent-space bake encodes in, so a glTF
 * viewer that uses the file's tangents decodes our maps. */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh/mesh_gltf.h"
#include "mesh/mesh_sort.h"

/* k: part, vertex, the corner tangent's 4 float bit patterns, the corner
 * UV's 2 (with corner_uv), corner */
#define CKEYS 9
typedef struct ckey {
    uint32_t k[CKEYS];
} ckey;

static int cmp_ckey(const void *a, const void *b)
{
    return mesh_keys_cmp(((const ckey *)a)->k, ((const ckey *)b)->k, CKEYS);
}

static uint32_t fbits(float f)
{
    uint32_t b;
    memcpy(&b, &f, sizeof b);
    return b;
}

/* little-endian float / uint32 into a byte buffer, on any host */
static void put_u32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v & 0xff), p[1] = (unsigned char)((v >> 8) & 0xff);
    p[2] = (unsigned char)((v >> 16) & 0xff), p[3] = (unsigned char)(v >> 24);
}
static void put_f32(unsigned char *p, float f) { put_u32(p, fbits(f)); }

/* JSON number: finite floats with 9 significant digits (round trip), other
 * values (which JSON cannot hold) as 0. */
static void json_num(char *buf, size_t n, double x)
{
    if (!isfinite(x))
        x = 0.0;
    snprintf(buf, n, "%.9g", x);
}

typedef struct sbuf {
    char *p;
    size_t n, cap;
    int oom;
} sbuf;

static void sb_add(sbuf *s, const char *fmt, ...) BGT_PRINTF(2, 3);
static void sb_add(sbuf *s, const char *fmt, ...)
{
    if (s->oom)
        return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int k = vsnprintf(s->p ? s->p + s->n : NULL, s->p ? s->cap - s->n : 0, fmt, ap);
        va_end(ap);
        if (k < 0) {
            s->oom = 1;
            return;
        }
        if (s->p && s->n + (size_t)k < s->cap) {
            s->n += (size_t)k;
            return;
        }
        size_t cap = (s->cap ? 2 * s->cap : 4096) + (size_t)k + 1;
        char *q = realloc(s->p, cap);
        if (!q) {
            s->oom = 1;
            return;
        }
        s->p = q;
        s->cap = cap;
    }
}

static const char b64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

static int write_base64(FILE *fp, const unsigned char *d, size_t n)
{
    char out[4 * 1024];
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)d[i] << 16;
        if (i + 1 < n)
            v |= (uint32_t)d[i + 1] << 8;
        if (i + 2 < n)
            v |= d[i + 2];
        out[o++] = b64[(v >> 18) & 63];
        out[o++] = b64[(v >> 12) & 63];
        out[o++] = i + 1 < n ? b64[(v >> 6) & 63] : '=';
        out[o++] = i + 2 < n ? b64[v & 63] : '=';
        if (o == sizeof out) {
            if (fwrite(out, 1, o, fp) != o)
                return -1;
            o = 0;
        }
    }
    return fwrite(out, 1, o, fp) == o ? 0 : -1;
}

/* The glTF meshes: part p holds triangles [first[p], first[p + 1]) (one
 * part of all triangles when d has no valid parts). */
typedef struct gltf_parts {
    size_t n;
    int named;       /* the parts are d->parts (else one part, no names) */
    size_t *first;   /* n + 1 */
    size_t *vfirst;  /* n + 1: part p's glTF vertices are [vfirst[p], vfirst[p + 1]) */
    double *mn, *mx; /* 3 per part: the bounds of its finite positions */
} gltf_parts;

static int parts_init(const mesh_gltf_in *d, size_t T, gltf_parts *ps)
{
    size_t end = 0, p = 0;
    for (; d->parts && p < d->part_count; p++) {
        if (d->parts[p].first_triangle != end || d->parts[p].triangle_count == 0 ||
            d->parts[p].triangle_count > T - end)
            break;
        end += d->parts[p].triangle_count;
    }
    /* no parts, or not a partition of the triangles: one mesh */
    ps->named = d->parts && d->part_count && p == d->part_count && end == T;
    size_t n = ps->named ? d->part_count : 1;
    ps->n = n;
    ps->first = malloc((n + 1) * sizeof *ps->first);
    ps->vfirst = calloc(n + 1, sizeof *ps->vfirst);
    ps->mn = malloc(3 * n * sizeof *ps->mn);
    ps->mx = malloc(3 * n * sizeof *ps->mx);
    if (!ps->first || !ps->vfirst || !ps->mn || !ps->mx)
        return -1;
    for (p = 0; p < n; p++) {
        ps->first[p] = ps->named ? d->parts[p].first_triangle : 0;
        for (int a = 0; a < 3; a++)
            ps->mn[3 * p + (size_t)a] = INFINITY, ps->mx[3 * p + (size_t)a] = -INFINITY;
    }
    ps->first[n] = T;
    return 0;
}

static void parts_free(gltf_parts *ps)
{
    free(ps->first);
    free(ps->vfirst);
    free(ps->mn);
    free(ps->mx);
}

/* The glTF vertices: one per (part, vertex, corner tangent, corner UV), in
 * that order, so that each part's vertices are a range (ps->vfirst).
 * newidx[c] is corner c's new vertex, src[i] a corner of new vertex i;
 * returns their count. */
static size_t split_vertices(const mesh_gltf_in *d, size_t C, gltf_parts *ps, ckey *keys,
                             uint32_t *newidx, uint32_t *src)
{
    int has_tan = d->corner_tangents != NULL;
    size_t p = 0;
    for (size_t c = 0; c < C; c++) {
        while (c / 3 >= ps->first[p + 1])
            p++;
        keys[c].k[0] = (uint32_t)p;
        keys[c].k[1] = d->indices[c];
        keys[c].k[6] = d->corner_uv ? fbits(d->corner_uv[2 * c]) : 0u;
        keys[c].k[7] = d->corner_uv ? fbits(d->corner_uv[2 * c + 1]) : 0u;
        keys[c].k[8] = (uint32_t)c;
        for (int j = 0; j < 4; j++)
            keys[c].k[2 + j] = has_tan ? fbits(d->corner_tangents[4 * c + (size_t)j]) : 0u;
    }
    qsort(keys, C, sizeof *keys, cmp_ckey);
    size_t NV = 0;
    for (size_t i = 0; i < C; i++) {
        if (i == 0 || mesh_keys_cmp(keys[i].k, keys[i - 1].k, CKEYS - 1) != 0)
            src[NV++] = keys[i].k[CKEYS - 1];
        newidx[keys[i].k[CKEYS - 1]] = (uint32_t)(NV - 1);
        ps->vfirst[keys[i].k[0] + 1] = NV; /* ends up as the part's end */
    }
    for (size_t q = 1; q <= ps->n; q++) /* a part without corners (none: parts_init) */
        if (ps->vfirst[q] < ps->vfirst[q - 1])
            ps->vfirst[q] = ps->vfirst[q - 1];
    return NV;
}

/* The binary buffer's layout: positions, normals, tangents, uvs (in part
 * order), indices (in the input's order), then the embedded images (all
 * 4-byte aligned). */
typedef struct gltf_buf {
    size_t nv, corners;
    int has_uv, has_tan;
    size_t off_p, off_n, off_t, off_uv, off_i, len;
    size_t ngroups;          /* primitives */
    size_t *group_first;     /* per primitive its first triangle, and T at the end */
    uint32_t *group_mat;     /* per primitive its material */
    size_t *group_part;      /* per primitive its part (mesh) */
    size_t *off_img;         /* per image: its offset (embedded ones) */
} gltf_buf;

static size_t align4(size_t n) { return (n + 3) & ~(size_t)3; }

static int buf_layout(const mesh_gltf_in *d, size_t NV, size_t C, const gltf_parts *ps,
                      gltf_buf *b)
{
    memset(b, 0, sizeof *b);
    b->nv = NV, b->corners = C, b->has_uv = d->u && d->v, b->has_tan = d->corner_tangents != NULL;
    b->off_p = 0, b->off_n = b->off_p + 12 * NV, b->off_t = b->off_n + 12 * NV;
    b->off_uv = b->off_t + (b->has_tan ? 16 * NV : 0), b->off_i = b->off_uv + (b->has_uv ? 8 * NV : 0);
    b->len = b->off_i + 4 * C;
    /* one primitive per run of consecutive triangles of one part with one
     * material: the triangles keep their order (the bake's "later triangle
     * wins" holds in the file too) */
    size_t T = C / 3;
    b->group_first = malloc((T + 1) * sizeof *b->group_first);
    b->group_mat = malloc((T ? T : 1) * sizeof *b->group_mat);
    b->group_part = malloc((T ? T : 1) * sizeof *b->group_part);
    b->off_img = calloc(d->image_count ? d->image_count : 1, sizeof *b->off_img);
    if (!b->group_first || !b->group_mat || !b->group_part || !b->off_img)
        return -1;
    size_t M = 0, p = 0;
    for (size_t t = 0; t < T; t++) {
        uint32_t g = d->tri_material && d->material_count ? d->tri_material[t] : 0;
        if (g >= d->material_count)
            g = 0;
        int new_part = t == ps->first[p + 1];
        if (new_part)
            p++;
        if (M == 0 || new_part || b->group_mat[M - 1] != g) {
            b->group_first[M] = t;
            b->group_part[M] = p;
            b->group_mat[M++] = g;
        }
    }
    b->group_first[M] = T;
    b->ngroups = M;
    for (size_t i = 0; i < d->image_count; i++) {
        if (d->images[i].uri)
            continue;
        b->len = align4(b->len);
        b->off_img[i] = b->len;
        b->len += d->images[i].len;
    }
    return 0;
}

static void fill_buffer(const mesh_gltf_in *d, const uint32_t *newidx, const uint32_t *src,
                        gltf_parts *ps, gltf_buf *b, unsigned char *bin)
{
    memset(bin, 0, b->len);
    size_t part = 0;
    for (size_t i = 0; i < b->nv; i++) {
        while (i >= ps->vfirst[part + 1])
            part++;
        double *mn = ps->mn + 3 * part, *mx = ps->mx + 3 * part;
        size_t c = src[i];
        uint32_t v = d->indices[c];
        float p[3] = {d->px[v], d->py[v], d->pz[v]};
        float n[3] = {d->nx[v], d->ny[v], d->nz[v]};
        if (n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f)
            n[2] = 1.0f; /* the no-normal sentinel: glTF needs unit normals */
        for (int a = 0; a < 3; a++) {
            put_f32(bin + b->off_p + 12 * i + 4 * (size_t)a, p[a]);
            put_f32(bin + b->off_n + 12 * i + 4 * (size_t)a, n[a]);
            if (isfinite(p[a])) {
                mn[a] = p[a] < mn[a] ? p[a] : mn[a];
                mx[a] = p[a] > mx[a] ? p[a] : mx[a];
            }
        }
        if (b->has_tan)
            for (int a = 0; a < 4; a++)
                put_f32(bin + b->off_t + 16 * i + 4 * (size_t)a, d->corner_tangents[4 * c + (size_t)a]);
        if (b->has_uv) {
            float u = d->corner_uv ? d->corner_uv[2 * c] : d->u[v];
            float w = d->corner_uv ? d->corner_uv[2 * c + 1] : d->v[v];
            put_f32(bin + b->off_uv + 8 * i, u);
            put_f32(bin + b->off_uv + 8 * i + 4, 1.0f - w);
        }
    }
    /* indices count from the first vertex of their part */
    part = 0;
    for (size_t c = 0; c < b->corners; c++) {
        while (c / 3 >= ps->first[part + 1])
            part++;
        put_u32(bin + b->off_i + 4 * c, newidx[c] - (uint32_t)ps->vfirst[part]);
    }
    for (size_t i = 0; i < d->image_count; i++)
        if (!d->images[i].uri && d->images[i].len)
            memcpy(bin + b->off_img[i], d->images[i].bytes, d->images[i].len);
}

/* The length of the well-formed UTF-8 sequence at s (1 to 4), or 0. */
static int utf8_len(const unsigned char *s)
{
    if (s[0] < 0x80)
        return 1;
    int n = s[0] >= 0xC2 && s[0] <= 0xDF ? 2 : s[0] >= 0xE0 && s[0] <= 0xEF ? 3
          : s[0] >= 0xF0 && s[0] <= 0xF4 ? 4 : 0;
    for (int i = 1; i < n; i++)
        if ((s[i] & 0xC0) != 0x80)
            return 0;
    /* no overlong forms, surrogates or code points above U+10FFFF */
    if ((s[0] == 0xE0 && s[1] < 0xA0) || (s[0] == 0xED && s[1] > 0x9F) ||
        (s[0] == 0xF0 && s[1] < 0x90) || (s[0] == 0xF4 && s[1] > 0x8F))
        return 0;
    return n;
}

/* A JSON string's contents: quotes, backslashes and control characters
 * escaped; UTF-8 as it is, and a byte that is not part of well-formed UTF-8
 * (a Latin-1 name, say) as U+FFFD, so the JSON stays valid. */
static void sb_json_str(sbuf *js, const char *s)
{
    const unsigned char *u = (const unsigned char *)s;
    while (*u) {
        unsigned char c = *u;
        int n = utf8_len(u);
        if (c == '"' || c == '\\')
            sb_add(js, "\\%c", c);
        else if (c < 0x20)
            sb_add(js, "\\u%04x", c);
        else if (n == 0)
            sb_add(js, "\\ufffd");
        else
            sb_add(js, "%.*s", n, (const char *)u);
        u += n ? n : 1;
    }
}

/* materials, textures, samplers and images */
static void gltf_materials(sbuf *js, const mesh_gltf_in *d, const gltf_buf *b, int first_img_view)
{
    if (!d->material_count)
        return;
    sb_add(js, "\"materials\":[");
    for (size_t i = 0; i < d->material_count; i++) {
        const mesh_gltf_material *mt = &d->materials[i];
        sb_add(js, "%s{", i ? "," : "");
        if (mt->name) {
            sb_add(js, "\"name\":\"");
            sb_json_str(js, mt->name);
            sb_add(js, "\",");
        }
        sb_add(js, "\"pbrMetallicRoughness\":{\"metallicFactor\":0,\"roughnessFactor\":1");
        if (mt->has_base_color) {
            char c[4][32];
            for (int k = 0; k < 4; k++)
                json_num(c[k], sizeof c[k], mt->base_color[k]);
            sb_add(js, ",\"baseColorFactor\":[%s,%s,%s,%s]", c[0], c[1], c[2], c[3]);
        }
        if (mt->base_color_image >= 0)
            sb_add(js, ",\"baseColorTexture\":{\"index\":%d}", mt->base_color_image);
        sb_add(js, "}");
        if (mt->normal_image >= 0)
            sb_add(js, ",\"normalTexture\":{\"index\":%d}", mt->normal_image);
        sb_add(js, "}");
    }
    sb_add(js, "],");
    if (!d->image_count)
        return;
    /* texture i shows image i with the one sampler: linear, mip-mapped, repeat */
    sb_add(js, "\"samplers\":[{\"magFilter\":9729,\"minFilter\":9987}],\"textures\":[");
    for (size_t i = 0; i < d->image_count; i++)
        sb_add(js, "%s{\"sampler\":0,\"source\":%zu}", i ? "," : "", i);
    sb_add(js, "],\"images\":[");
    int view = first_img_view;
    for (size_t i = 0; i < d->image_count; i++) {
        const mesh_gltf_image *im = &d->images[i];
        if (im->uri) {
            sb_add(js, "%s{\"uri\":\"", i ? "," : "");
            sb_json_str(js, im->uri);
            sb_add(js, "\"}");
        } else {
            sb_add(js, "%s{\"bufferView\":%d,\"mimeType\":\"%s\"}", i ? "," : "", view++, im->mime);
        }
    }
    sb_add(js, "],");
    (void)b;
}

/* Part p's node name: the source node's, else its mesh's, else "mesh<p>". */
static void sb_node_name(sbuf *js, const mesh_gltf_in *d, const gltf_parts *ps, size_t p)
{
    const bg_mesh_part *pt = ps->named ? &d->parts[p] : NULL;
    if (pt && pt->name && *pt->name)
        sb_json_str(js, pt->name);
    else if (pt && pt->mesh_name && *pt->mesh_name)
        sb_json_str(js, pt->mesh_name);
    else
        sb_add(js, "mesh%zu", p);
}

/* The JSON of the file, up to the buffer's data URI when !binary. */
static void gltf_json(sbuf *js, const mesh_gltf_in *d, const gltf_parts *ps, const gltf_buf *b,
                      int binary)
{
    int has_uv = b->has_uv, has_tan = b->has_tan;
    const size_t P = ps->n;
    const int named = ps->named;
    const size_t NV = b->nv;
    sb_add(js, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"%s\"},", d->generator);
    /* the hierarchy flattened: one root node per part, the identity transform */
    sb_add(js, "\"scene\":0,\"scenes\":[{\"nodes\":[");
    for (size_t p = 0; p < P; p++)
        sb_add(js, "%s%zu", p ? "," : "", p);
    sb_add(js, "]}],\"nodes\":[");
    for (size_t p = 0; p < P; p++) {
        sb_add(js, "%s{\"name\":\"", p ? "," : "");
        sb_node_name(js, d, ps, p);
        sb_add(js, "\",\"mesh\":%zu}", p);
    }
    sb_add(js, "],");
    /* accessors: per part its POSITION, NORMAL, [TANGENT], [TEXCOORD_0];
     * then per primitive its indices */
    const int nattr = 2 + has_tan + has_uv;
    int view = 0;
    int vp = view++, vn = view++, vt = has_tan ? view++ : -1, vu = has_uv ? view++ : -1;
    int vi = view++;
    sb_add(js, "\"meshes\":[");
    size_t g = 0;
    for (size_t p = 0; p < P; p++) {
        const size_t acc = (size_t)nattr * p;
        sb_add(js, "%s{", p ? "," : "");
        if (named && d->parts[p].mesh_name && *d->parts[p].mesh_name) {
            sb_add(js, "\"name\":\"");
            sb_json_str(js, d->parts[p].mesh_name);
            sb_add(js, "\",");
        }
        sb_add(js, "\"primitives\":[");
        for (int first = 1; g < b->ngroups && b->group_part[g] == p; g++, first = 0) {
            sb_add(js, "%s{\"attributes\":{\"POSITION\":%zu,\"NORMAL\":%zu", first ? "" : ",",
                   acc, acc + 1);
            if (has_tan)
                sb_add(js, ",\"TANGENT\":%zu", acc + 2);
            if (has_uv)
                sb_add(js, ",\"TEXCOORD_0\":%zu", acc + 2 + (size_t)has_tan);
            sb_add(js, "},\"indices\":%zu,\"mode\":4", (size_t)nattr * P + g);
            if (d->material_count)
                sb_add(js, ",\"material\":%u", (unsigned)b->group_mat[g]);
            sb_add(js, "}");
        }
        sb_add(js, "]}");
    }
    sb_add(js, "],");
    gltf_materials(js, d, b, view);
    sb_add(js, "\"accessors\":[");
    for (size_t p = 0; p < P; p++) {
        const size_t v0 = ps->vfirst[p], nv = ps->vfirst[p + 1] - v0;
        char a[6][32];
        for (int k = 0; k < 3; k++) {
            json_num(a[k], sizeof a[k], nv ? ps->mn[3 * p + (size_t)k] : 0.0);
            json_num(a[3 + k], sizeof a[3 + k], nv ? ps->mx[3 * p + (size_t)k] : 0.0);
        }
        sb_add(js, "%s{\"bufferView\":%d,\"byteOffset\":%zu,\"componentType\":5126,"
                   "\"count\":%zu,\"type\":\"VEC3\",\"min\":[%s,%s,%s],\"max\":[%s,%s,%s]},",
               p ? "," : "", vp, 12 * v0, nv, a[0], a[1], a[2], a[3], a[4], a[5]);
        sb_add(js, "{\"bufferView\":%d,\"byteOffset\":%zu,\"componentType\":5126,"
                   "\"count\":%zu,\"type\":\"VEC3\"}", vn, 12 * v0, nv);
        if (has_tan)
            sb_add(js, ",{\"bufferView\":%d,\"byteOffset\":%zu,\"componentType\":5126,"
                       "\"count\":%zu,\"type\":\"VEC4\"}", vt, 16 * v0, nv);
        if (has_uv)
            sb_add(js, ",{\"bufferView\":%d,\"byteOffset\":%zu,\"componentType\":5126,"
                       "\"count\":%zu,\"type\":\"VEC2\"}", vu, 8 * v0, nv);
    }
    for (size_t k = 0; k < b->ngroups; k++) {
        size_t n = b->group_first[k + 1] - b->group_first[k];
        sb_add(js, ",{\"bufferView\":%d,\"byteOffset\":%zu,\"componentType\":5125,"
                   "\"count\":%zu,\"type\":\"SCALAR\"}",
               vi, 12 * b->group_first[k], 3 * n);
    }
    sb_add(js, "],\"bufferViews\":[");
    sb_add(js, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"target\":34962},", b->off_p,
           12 * NV);
    sb_add(js, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"target\":34962},", b->off_n,
           12 * NV);
    if (has_tan)
        sb_add(js, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"target\":34962},",
               b->off_t, 16 * NV);
    if (has_uv)
        sb_add(js, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"target\":34962},",
               b->off_uv, 8 * NV);
    sb_add(js, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"target\":34963}", b->off_i,
           4 * b->corners);
    for (size_t i = 0; i < d->image_count; i++)
        if (!d->images[i].uri)
            sb_add(js, ",{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}", b->off_img[i],
                   d->images[i].len);
    sb_add(js, "],");
    if (binary) {
        sb_add(js, "\"buffers\":[{\"byteLength\":%zu}]}", b->len);
    } else {
        sb_add(js, "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"data:application/octet-stream;base64,",
               b->len);
    }
}

/* .glb: the 12-byte header, the JSON chunk (padded with blanks) and the BIN
 * chunk (padded with zeros). */
static bg_status write_glb(FILE *fp, const sbuf *js, const unsigned char *bin, size_t blen,
                           bgt_err *e)
{
    size_t jpad = (4 - js->n % 4) % 4, bpad = (4 - blen % 4) % 4;
    size_t total = 12 + 8 + js->n + jpad + 8 + blen + bpad;
    if (total > UINT32_MAX)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "mesh too large for .glb (%zu bytes)", total);
    int werr = 0;
    unsigned char h[20];
    memcpy(h, "glTF", 4);
    put_u32(h + 4, 2);
    put_u32(h + 8, (uint32_t)total);
    put_u32(h + 12, (uint32_t)(js->n + jpad));
    memcpy(h + 16, "JSON", 4);
    werr |= fwrite(h, 1, 20, fp) != 20;
    werr |= fwrite(js->p, 1, js->n, fp) != js->n;
    werr |= fwrite("   ", 1, jpad, fp) != jpad;
    put_u32(h, (uint32_t)(blen + bpad));
    memcpy(h + 4, "BIN\0", 4);
    werr |= fwrite(h, 1, 8, fp) != 8;
    werr |= fwrite(bin, 1, blen, fp) != blen;
    werr |= fwrite("\0\0\0", 1, bpad, fp) != bpad;
    return werr ? bgt_fail(e, BG_ERR_IO, "write error") : BG_OK;
}

/* .gltf: the JSON with the buffer as its base64 data URI. */
static bg_status write_gltf_text(FILE *fp, const sbuf *js, const unsigned char *bin, size_t blen,
                                 bgt_err *e)
{
    int werr = 0;
    werr |= fwrite(js->p, 1, js->n, fp) != js->n;
    werr |= write_base64(fp, bin, blen) != 0;
    werr |= fputs("\"}]}\n", fp) == EOF;
    return werr ? bgt_fail(e, BG_ERR_IO, "write error") : BG_OK;
}

bg_status mesh_gltf_write(FILE *fp, int binary, const mesh_gltf_in *d, bgt_err *e)
{
    size_t T = d->triangle_count, C = 3 * T;
    ckey *keys = malloc((C ? C : 1) * sizeof *keys);
    uint32_t *newidx = malloc((C ? C : 1) * sizeof *newidx);
    uint32_t *src = malloc((C ? C : 1) * sizeof *src); /* new vertex -> a corner */
    unsigned char *bin = NULL;
    sbuf js = {0};
    gltf_parts ps = {0};
    gltf_buf b = {0};
    bg_status rc = BG_OK;
    if (!keys || !newidx || !src || parts_init(d, T, &ps) != 0) {
        rc = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the glTF of %zu triangles", T);
        goto done;
    }
    size_t NV = split_vertices(d, C, &ps, keys, newidx, src);
    if (NV > UINT32_MAX) {
        rc = bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "too many vertices for glTF (%zu)", NV);
        goto done;
    }
    if (buf_layout(d, NV, C, &ps, &b) != 0) {
        rc = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the glTF of %zu triangles", T);
        goto done;
    }
    bin = malloc(b.len ? b.len : 1);
    if (!bin) {
        rc = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the glTF buffer (%zu bytes)",
                      b.len);
        goto done;
    }
    fill_buffer(d, newidx, src, &ps, &b, bin);
    gltf_json(&js, d, &ps, &b, binary);
    if (js.oom) {
        rc = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the glTF JSON");
        goto done;
    }
    rc = binary ? write_glb(fp, &js, bin, b.len, e) : write_gltf_text(fp, &js, bin, b.len, e);
done:
    free(keys);
    free(newidx);
    free(src);
    free(bin);
    free(js.p);
    parts_free(&ps);
    free(b.group_first); /* the layout's tables */
    free(b.group_mat);
    free(b.group_part);
    free(b.off_img);
    return rc;
}
