/* SPDX-License-Identifier: MIT */
/* glTF 2.0 output of `bumpgrad mesh` (mesh_gltf.c). */
#ifndef BUMPGRAD_TOOLS_MESH_GLTF_H
#define BUMPGRAD_TOOLS_MESH_GLTF_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include "bumpgrad/image.h"
#include "bumpgrad/mesh.h"
#include "common/tool.h"

/* An image of the file: referenced by a relative URI (beside a .gltf), or
 * its bytes embedded in the buffer (a bufferView; .glb and .gltf alike). */
typedef struct mesh_gltf_image {
    const char *uri;             /* percent-encoded relative reference, or NULL: embedded */
    const unsigned char *bytes;  /* the encoded file when embedded */
    size_t len;
    const char *mime;            /* "image/png" or "image/jpeg" */
} mesh_gltf_image;

/* A glTF material (pbrMetallicRoughness, metallic 0, roughness 1: a matte
 * surface, as OBJ and Collada diffuse materials are). */
typedef struct mesh_gltf_material {
    const char *name;            /* UTF-8 (escaped on output), or NULL */
    int has_base_color;
    float base_color[4];         /* baseColorFactor (linear RGBA) when has_base_color */
    int base_color_image;        /* baseColorTexture: an index of images, or -1 */
    int normal_image;            /* normalTexture: an index of images, or -1 */
} mesh_gltf_material;

typedef struct mesh_gltf_in {
    size_t vertex_count, triangle_count;
    const float *px, *py, *pz;
    const float *nx, *ny, *nz;     /* unit normals, or the (0,0,0) sentinel */
    const float *u, *v;            /* NULL: no TEXCOORD_0 */
    const float *corner_tangents;  /* 4 per corner (bgt_mikk_tangents), NULL: no TANGENT */
    const float *corner_uv;        /* 2 per corner (u, v up), NULL: the vertices' u, v; a
                                    * vertex is split where its corners' UVs differ */
    const uint32_t *indices;
    const char *generator;         /* asset.generator, plain ASCII without quotes */
    /* Materials: in each mesh (part, below), one primitive per run of
     * consecutive triangles of one material (triangle order kept);
     * material_count 0: one primitive per mesh, no material. */
    const uint32_t *tri_material;  /* per triangle (< material_count), NULL: all 0 */
    size_t material_count;
    const mesh_gltf_material *materials;
    size_t image_count;
    const mesh_gltf_image *images;
    /* Meshes: one glTF mesh per part (bg_mesh_part: the source's nodes), under
     * a root node with the identity transform named after the part's node
     * (else its mesh, else "mesh<i>"). part_count 0, or parts that do not
     * cover the triangles in order: one mesh, one node "mesh0". */
    size_t part_count;
    const bg_mesh_part *parts;
} mesh_gltf_in;

/* ---- the materials and images of `bumpgrad mesh`'s glTF (mesh_gltf_scene.c) ---- */
/* The baked map as a glTF image: a PNG or JPEG map is referenced beside a
 * .gltf (relative URI) or embedded in a .glb as it was written; a map in
 * another format (EXR, TIFF, 16 bits, ...) is embedded as an 8-bit PNG
 * encoding of the same image (glTF images are PNG or JPEG). */
typedef struct mesh_gltf_map {
    int ready;
    char *uri;              /* malloc'd, or NULL */
    unsigned char *bytes;   /* malloc'd, or NULL */
    size_t len;
    const char *mime;
    int converted;          /* the embedded image is an 8-bit PNG of a map in another format */
} mesh_gltf_map;

/* Fill *map for the tile `img` just written to `tmp` (a file, or NULL for
 * standard output) that becomes `final` ("-" for standard output); out_path
 * is the glTF's own path (a relative URI starts from its folder). */
bg_status mesh_gltf_map_image(mesh_gltf_map *map, const bg_image *img, const char *tmp,
                              const char *final, const char *out_path, int binary, bgt_err *e);
void mesh_gltf_map_free(mesh_gltf_map *map);

/* The materials and images of the output glTF. */
typedef struct mesh_gltf_scene {
    mesh_gltf_material *materials;
    size_t material_count;
    mesh_gltf_image *images;
    size_t image_count;
    size_t textures_kept, textures_dropped; /* base colour textures (dropped: not PNG/JPEG,
                                             * or not found) */
    char **names;                /* material names made here (owned), names_count of them */
    size_t names_count;
} mesh_gltf_scene;

/* One glTF material per material of the mesh (or one, when it has none and a
 * map is given), each with its name and base colour texture (mesh_texture_find
 * locates it; embedded in a .glb, referenced beside a .gltf) and, when map
 * is given, the map as its normalTexture. BG_OK or BG_ERR_OUT_OF_MEMORY /
 * BG_ERR_INVALID_ARGUMENT (a texture over the memory cap). */
bg_status mesh_gltf_scene_build(mesh_gltf_scene *sc, const char *mesh_path, const bg_mesh *m,
                                const mesh_gltf_map *map, const char *out_path, int binary,
                                bgt_err *e);
/* A <UDIM> bake: sc (built without a map) gets one material per pair of
 * (material of triangle t, tile map tri_map[t]) that a triangle uses, a copy
 * of the source material named "NAME TILE" whose normalTexture is that
 * tile's map (maps[j], tile number tiles[j]; tri_map[t] = -1: none), and
 * *tri_material (malloc'd, T entries) says which. BG_OK or
 * BG_ERR_OUT_OF_MEMORY. */
bg_status mesh_gltf_scene_tiles(mesh_gltf_scene *sc, const bg_mesh *m, const mesh_gltf_map *maps,
                                const int *tiles, size_t nmaps, const int *tri_map,
                                uint32_t **tri_material, bgt_err *e);
void mesh_gltf_scene_free(mesh_gltf_scene *sc);

/* Write a .glb (binary != 0) or a .gltf with an embedded buffer into an open
 * stream. BG_OK, BG_ERR_IO (write error), BG_ERR_OUT_OF_MEMORY or
 * BG_ERR_INVALID_ARGUMENT (too large for the format), with *e set. */
bg_status mesh_gltf_write(FILE *fp, int binary, const mesh_gltf_in *d, bgt_err *e);

#endif
