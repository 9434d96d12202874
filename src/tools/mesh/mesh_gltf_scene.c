/* SPDX-License-Identifier: MIT */
/* The materials and images of the glTF that `bumpgrad mesh` writes
 * (mesh_gltf.h): the baked map as every material's normalTexture, and the
 * source's materials with their names and base colour textures. glTF 2.0
 * images are PNG or JPEG (specification 3.9.3), so other texture formats are
 * left out and counted; a map in another format is embedded as an 8-bit PNG
 * of the same image. */
#define _XOPEN_SOURCE 700
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include "common/safe_file.h"
#include "mesh/mesh_gltf.h"
#include "mesh/mesh_texpath.h"

/* "image/png", "image/jpeg" from the first bytes, or NULL */
static const char *image_mime(const unsigned char *p, size_t n)
{
    if (n >= 8 && memcmp(p, "\x89PNG\r\n\x1a\n", 8) == 0)
        return "image/png";
    if (n >= 3 && p[0] == 0xff && p[1] == 0xd8 && p[2] == 0xff)
        return "image/jpeg";
    return NULL;
}

/* The whole file (its size checked against the memory cap first). */
static bg_status read_bytes(const char *path, unsigned char **out, size_t *len, bgt_err *e)
{
    *out = NULL, *len = 0;
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return bgt_fail(e, BG_ERR_IO, "cannot read %s: %s", path, strerror(errno));
    struct stat st;
    bg_status rc = BG_OK;
    if (fstat(fileno(fp), &st) != 0 || !S_ISREG(st.st_mode)) {
        rc = bgt_fail(e, BG_ERR_IO, "cannot read %s: not a regular file", path);
        goto done;
    }
    if ((rc = bgt_check_alloc((double)st.st_size, "a texture for the glTF", e)) != BG_OK)
        goto done;
    size_t n = (size_t)st.st_size;
    *out = malloc(n ? n : 1);
    if (!*out) {
        rc = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for %s (%zu bytes)", path, n);
        goto done;
    }
    if (fread(*out, 1, n, fp) != n) {
        free(*out);
        *out = NULL;
        rc = bgt_fail(e, BG_ERR_IO, "cannot read %s: short read", path);
        goto done;
    }
    *len = n;
done:
    fclose(fp);
    return rc;
}

/* The absolute folder of `path` (realpath of its directory part). */
static char *abs_dir(const char *path)
{
    char *copy = strdup(path);
    if (!copy)
        return NULL;
    char *slash = strrchr(copy, '/');
    const char *dir = ".";
    if (slash == copy)
        dir = "/";
    else if (slash) {
        *slash = '\0';
        dir = copy;
    }
    char *r = realpath(dir, NULL);
    free(copy);
    return r;
}

/* A relative URI from the folder of `from` to the file `to` (percent-encoded
 * as RFC 3986 asks for a path), or NULL (no memory, a folder that does not
 * resolve). */
static char *relative_uri(const char *from, const char *to)
{
    char *a = abs_dir(from), *b = abs_dir(to);
    const char *base = strrchr(to, '/') ? strrchr(to, '/') + 1 : to;
    char *out = NULL;
    if (!a || !b)
        goto done;
    /* the common leading folders */
    size_t i = 0, last = 0;
    while (a[i] && a[i] == b[i]) {
        if (a[i] == '/')
            last = i;
        i++;
    }
    if ((a[i] == '\0' || a[i] == '/') && (b[i] == '\0' || b[i] == '/'))
        last = i;
    size_t ups = 0;
    for (const char *p = a + last; *p; p++)
        ups += *p == '/';
    const char *rest = b + last + (b[last] == '/');
    size_t cap = 3 * ups + 3 * (strlen(rest) + strlen(base)) + 8;
    out = malloc(cap);
    if (!out)
        goto done;
    char *o = out;
    for (size_t k = 0; k < ups; k++)
        o += sprintf(o, "../");
    const char *parts[2] = {rest, base};
    for (int k = 0; k < 2; k++) {
        if (k == 1 && *rest)
            *o++ = '/';
        for (const unsigned char *p = (const unsigned char *)parts[k]; *p; p++) {
            if ((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') ||
                strchr("-._~/!$&'()*+,;=:@", *p))
                *o++ = (char)*p;
            else
                o += sprintf(o, "%%%02X", *p);
        }
    }
    *o = '\0';
done:
    free(a);
    free(b);
    return out;
}

static int is_png_or_jpeg_name(const char *p)
{
    size_t n = strlen(p);
    const char *exts[] = {".png", ".jpg", ".jpeg"};
    for (int k = 0; k < 3; k++) {
        size_t m = strlen(exts[k]);
        if (n >= m && strncasecmp(p + n - m, exts[k], m) == 0)
            return 1;
    }
    return 0;
}

bg_status mesh_gltf_map_image(mesh_gltf_map *map, const bg_image *img, const char *tmp,
                              const char *final, const char *out_path, int binary, bgt_err *e)
{
    memset(map, 0, sizeof *map);
    bg_status rc;
    if (tmp && is_png_or_jpeg_name(final)) {
        if (!binary) {
            if (!(map->uri = relative_uri(out_path, final)))
                return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "cannot form a URI from %s to %s",
                                out_path, final);
            map->ready = 1;
            return BG_OK;
        }
        if ((rc = read_bytes(tmp, &map->bytes, &map->len, e)) != BG_OK)
            return rc;
        map->mime = image_mime(map->bytes, map->len);
        if (map->mime) {
            map->ready = 1;
            return BG_OK;
        }
        free(map->bytes);
        map->bytes = NULL;
    }
    /* an 8-bit PNG of the same tile, through a temporary next to OUT */
    char *png = bgt_safe_temp_path(out_path, e);
    if (!png)
        return e && e->status != BG_OK ? e->status : BG_ERR_IO;
    char err[512];
    bg_status ws = bg_image_write_as(png, "png", img, BG_PIXEL_U8, 0, err, sizeof err);
    if (ws != BG_OK) {
        bgt_safe_discard_path(png);
        free(png);
        return bgt_fail(e, ws == BG_ERR_OUT_OF_MEMORY ? ws : BG_ERR_IO,
                        "the PNG of the map for the glTF: %s", err);
    }
    rc = read_bytes(png, &map->bytes, &map->len, e);
    bgt_safe_discard_path(png);
    free(png);
    if (rc != BG_OK)
        return rc;
    map->mime = "image/png";
    map->converted = 1;
    map->ready = 1;
    return BG_OK;
}

void mesh_gltf_map_free(mesh_gltf_map *map)
{
    free(map->uri);
    free(map->bytes);
    memset(map, 0, sizeof *map);
}

/* Add the base colour texture of material i, if it is PNG/JPEG and found.
 * Returns its image index, -1 (left out), or -2 (out of memory). */
static int add_base_color(mesh_gltf_scene *sc, const char *mesh_path, const bg_mesh *m, size_t i,
                          const char *out_path, int binary)
{
    const bg_mesh_material *mt = &m->materials[i];
    if (!mt->diffuse)
        return -1;
    bgt_err le = {0};
    char *found = mesh_texture_find(mesh_path, i, mt->name, "diffuse", mt->diffuse, &le);
    if (!found) {
        sc->textures_dropped++;
        return le.status == BG_ERR_OUT_OF_MEMORY ? -2 : -1;
    }
    unsigned char *bytes = NULL;
    size_t len = 0;
    int idx = -1;
    if (read_bytes(found, &bytes, &len, &le) != BG_OK || !image_mime(bytes, len)) {
        sc->textures_dropped++;
        goto done;
    }
    mesh_gltf_image *im = &sc->images[sc->image_count];
    memset(im, 0, sizeof *im);
    im->mime = image_mime(bytes, len);
    if (binary) {
        im->bytes = bytes, im->len = len;
        bytes = NULL;
    } else if (!(im->uri = relative_uri(out_path, found))) {
        idx = -2;
        goto done;
    }
    idx = (int)sc->image_count++;
    sc->textures_kept++;
done:
    free(bytes);
    free(found);
    return idx;
}

bg_status mesh_gltf_scene_build(mesh_gltf_scene *sc, const char *mesh_path, const bg_mesh *m,
                                const mesh_gltf_map *map, const char *out_path, int binary,
                                bgt_err *e)
{
    memset(sc, 0, sizeof *sc);
    int has_map = map && map->ready;
    size_t nm = m->material_count ? m->material_count : (has_map ? 1 : 0);
    if (!nm)
        return BG_OK;
    sc->materials = calloc(nm, sizeof *sc->materials);
    sc->images = calloc(nm + 1, sizeof *sc->images);
    if (!sc->materials || !sc->images)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for %zu glTF materials", nm);
    sc->material_count = nm;
    int map_image = -1;
    if (has_map) {
        mesh_gltf_image *im = &sc->images[sc->image_count];
        im->mime = map->mime;
        im->len = map->len;
        im->uri = map->uri ? strdup(map->uri) : NULL;
        if (map->bytes && (im->bytes = malloc(map->len)) != NULL)
            memcpy((unsigned char *)im->bytes, map->bytes, map->len);
        if ((map->uri && !im->uri) || (map->bytes && !im->bytes))
            return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the glTF map");
        map_image = (int)sc->image_count++;
    }
    for (size_t i = 0; i < nm; i++) {
        mesh_gltf_material *g = &sc->materials[i];
        g->name = i < m->material_count ? m->materials[i].name : "bumpgrad";
        g->normal_image = map_image;
        g->base_color_image = -1;
        if (i < m->material_count && m->materials[i].has_base_color) {
            g->has_base_color = 1;
            for (int k = 0; k < 4; k++) { /* glTF: each in [0, 1] */
                float v = m->materials[i].base_color[k];
                g->base_color[k] = v < 0.0f ? 0.0f : v > 1.0f ? 1.0f : v;
            }
        }
        if (i < m->material_count) {
            int k = add_base_color(sc, mesh_path, m, i, out_path, binary);
            if (k == -2)
                return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the glTF textures");
            g->base_color_image = k;
        }
    }
    return BG_OK;
}

bg_status mesh_gltf_scene_tiles(mesh_gltf_scene *sc, const bg_mesh *m, const mesh_gltf_map *maps,
                                const int *tiles, size_t nmaps, const int *tri_map,
                                uint32_t **tri_material, bgt_err *e)
{
    const size_t T = m->triangle_count;
    *tri_material = NULL;
    if (!sc->material_count) { /* one plain material to pair with the tiles */
        if (!(sc->materials = calloc(1, sizeof *sc->materials)))
            return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the glTF materials");
        sc->materials[0] = (mesh_gltf_material){.name = "bumpgrad", .base_color_image = -1,
                                                .normal_image = -1};
        sc->material_count = 1;
    }
    const size_t nbase = sc->material_count, K = nbase * (nmaps + 1);
    mesh_gltf_image *im = realloc(sc->images, (sc->image_count + nmaps + 1) * sizeof *im);
    int32_t *pair = malloc(K * sizeof *pair);
    uint32_t *tm = malloc((T ? T : 1) * sizeof *tm);
    if (im)
        sc->images = im;
    if (!im || !pair || !tm) {
        free(pair), free(tm);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the glTF tiles");
    }
    const size_t first_map = sc->image_count;
    for (size_t j = 0; j < nmaps; j++) {
        mesh_gltf_image *g = &sc->images[sc->image_count++];
        memset(g, 0, sizeof *g);
        g->mime = maps[j].mime;
        g->len = maps[j].len;
        g->uri = maps[j].uri ? strdup(maps[j].uri) : NULL;
        if (maps[j].bytes && (g->bytes = malloc(maps[j].len)) != NULL)
            memcpy((unsigned char *)g->bytes, maps[j].bytes, maps[j].len);
        if ((maps[j].uri && !g->uri) || (maps[j].bytes && !g->bytes)) {
            free(pair), free(tm);
            return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the glTF tiles");
        }
    }
    /* the pairs in order of first use */
    for (size_t k = 0; k < K; k++)
        pair[k] = -1;
    size_t npairs = 0;
    for (size_t t = 0; t < T; t++) {
        size_t b = m->material && m->material_count > 1 ? m->material[t] : 0;
        size_t k = (b < nbase ? b : 0) * (nmaps + 1) + (size_t)(tri_map[t] + 1);
        if (pair[k] < 0)
            pair[k] = (int32_t)npairs++;
        tm[t] = (uint32_t)pair[k];
    }
    mesh_gltf_material *mt = calloc(npairs ? npairs : 1, sizeof *mt);
    char **names = calloc(npairs ? npairs : 1, sizeof *names);
    if (!mt || !names) {
        free(mt), free(names), free(pair), free(tm);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the glTF materials");
    }
    for (size_t k = 0; k < K; k++) {
        if (pair[k] < 0)
            continue;
        size_t b = k / (nmaps + 1);
        int j = (int)(k % (nmaps + 1)) - 1;
        mesh_gltf_material *g = &mt[pair[k]];
        *g = sc->materials[b];
        g->normal_image = j >= 0 ? (int)(first_map + (size_t)j) : -1;
        if (j >= 0) {
            const char *base = sc->materials[b].name ? sc->materials[b].name : "";
            size_t n = strlen(base) + 8;
            if ((names[pair[k]] = malloc(n)) != NULL)
                snprintf(names[pair[k]], n, "%s%s%04d", base, *base ? " " : "", tiles[j]);
            g->name = names[pair[k]];
        }
    }
    free(pair);
    free(sc->materials);
    sc->materials = mt;
    sc->material_count = npairs;
    sc->names = names;
    sc->names_count = npairs;
    *tri_material = tm;
    return BG_OK;
}

void mesh_gltf_scene_free(mesh_gltf_scene *sc)
{
    for (size_t i = 0; i < sc->names_count; i++)
        free(sc->names[i]);
    free(sc->names);
    for (size_t i = 0; i < sc->image_count; i++) {
        free((char *)sc->images[i].uri);
        free((unsigned char *)sc->images[i].bytes);
    }
    free(sc->images);
    free(sc->materials);
    memset(sc, 0, sizeof *sc);
}
