/* SPDX-License-Identifier: MIT */
/**
 * @file mesh.h
 * @brief Triangle meshes for the tools, loaded through assimp (libbumpgrad_io,
 *        C++ inside, C interface). Not part of the core library.
 *
 * Every mesh of a file's scene is flattened into one indexed triangle list:
 * node transforms are applied (a mesh referenced by two nodes appears twice),
 * polygons are triangulated, points and lines are dropped (and counted).
 * Which triangles came from which node is kept in bg_mesh.parts.
 * Attributes are kept per vertex as SoA arrays, the layout the batch calls of
 * noise.h and surfgrad.h take, so a caller feeds them without copying.
 */
#ifndef BUMPGRAD_MESH_H
#define BUMPGRAD_MESH_H

#include <stdint.h>

#include "common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** One material of the file (an aiMaterial): its name and the first texture
 *  of each kind it names, as a path resolved against the mesh file's folder
 *  (backslashes turned into '/', a leading "./" dropped; an absolute path is
 *  kept), or NULL for none. Textures embedded in the file ("*N") are not
 *  extracted: they are left NULL and counted in bg_mesh.embedded_textures. */
typedef struct bg_mesh_material {
    char *name;    /**< the material's name ("" when it has none), never NULL */
    char *diffuse; /**< first aiTextureType_DIFFUSE (OBJ map_Kd) */
    char *height;  /**< first aiTextureType_HEIGHT (OBJ map_bump/bump), else DISPLACEMENT */
    char *normal;  /**< first aiTextureType_NORMALS (OBJ norm) */
    /** The base colour factor (glTF baseColorFactor, else the diffuse colour:
     *  OBJ Kd), RGBA as the file stores it, each finite; valid when
     *  has_base_color. */
    float base_color[4];
    int has_base_color;
} bg_mesh_material;

/** The triangles of one node of the file's scene (an aiNode that references
 *  meshes, visited once per path from the root: an instanced node appears
 *  once per instance): triangles [first_triangle, first_triangle +
 *  triangle_count) of the flattened mesh, which use only vertices of their
 *  own (vertices are never shared between parts, whatever the joining). */
typedef struct bg_mesh_part {
    size_t first_triangle, triangle_count; /**< triangle_count > 0 */
    char *name;      /**< the node's name ("" when it has none), never NULL */
    char *mesh_name; /**< the name of the node's meshes: their common name, or with
                          several meshes "NAME-0", "NAME-1", ... (one glTF mesh split by
                          primitive) NAME, else the first one's; "" when none */
} bg_mesh_part;

/** An indexed triangle mesh. All arrays are owned (free with bg_mesh_free). */
typedef struct bg_mesh {
    size_t vertex_count;   /**< <= UINT32_MAX */
    size_t triangle_count;
    float *px, *py, *pz;   /**< positions; may hold NaN/Inf when the file does */
    float *nx, *ny, *nz;   /**< per-vertex normals as stored in the file (not
                                renormalized unless a node transform was applied),
                                or all three NULL when the file has none */
    float *u, *v;          /**< texture coordinate set 0, or both NULL when absent
                                (in a multi-mesh scene: absent if any mesh lacks it) */
    uint32_t *indices;     /**< 3 * triangle_count vertex indices, counter-clockwise
                                seen from the side the normals point to */
    size_t mesh_count;     /**< meshes of the scene that were flattened (instances counted) */
    size_t dropped_primitives; /**< points and lines that were not triangles */
    /** Per-vertex tangents stored in the file (glTF TANGENT, FBX, ...): unit
     *  xyz and the bitangent sign tw = +1 / -1 (b = tw cross(n, t)), or all
     *  four NULL unless every mesh has tangents, normals and UVs. Normals and
     *  tangents went through the node transform alike (normals by the inverse
     *  transpose); tw is the handedness after it. */
    float *tx, *ty, *tz, *tw;
    /** Per triangle, its material: an index < material_count (the
     *  aiMesh::mMaterialIndex of the mesh the triangle came from), or NULL
     *  when the scene has at most one material (then every triangle uses
     *  materials[0], if any). */
    uint32_t *material;
    size_t material_count;        /**< entries of materials (<= BG_MESH_MAX_MATERIALS) */
    bg_mesh_material *materials;  /**< the scene's materials in assimp's order, or NULL */
    size_t embedded_textures;     /**< texture references to embedded images ("*N") that
                                       were skipped (left NULL in materials) */
    /** The parts in triangle order, contiguous and covering every triangle,
     *  or NULL (part_count 0) when the scene has more than BG_MESH_MAX_PARTS
     *  of them (the flattened mesh is the same either way). */
    size_t part_count;
    bg_mesh_part *parts;
} bg_mesh;

/** The most materials a loaded mesh carries (a file with more is refused with
 *  BG_ERR_FORMAT), and the longest texture path or name kept (longer ones are
 *  refused too). */
#define BG_MESH_MAX_MATERIALS 65536
#define BG_MESH_MAX_STRING 4096
/** The most parts (node instances with triangles) kept in bg_mesh.parts; a
 *  scene with more loads with no parts. Part names longer than
 *  BG_MESH_MAX_STRING bytes are cut to it (at a UTF-8 character boundary). */
#define BG_MESH_MAX_PARTS 65536

/** Loading options (bit flags) for bg_mesh_load_ex. */
typedef enum bg_mesh_flags {
    /** Default vertex joining: PLY keeps the file's vertices one for one and in
     *  order (so output vertex i is input vertex i); the other formats, whose
     *  importers emit one vertex per face corner (OBJ, STL, OFF, ...), get
     *  vertices with identical position, normal and UV merged, so that smooth
     *  vertex normals can be formed across triangles. A mesh with a NaN/Inf
     *  vertex position is never merged (assimp would merge it into others). */
    BG_MESH_JOIN_AUTO = 0,
    BG_MESH_JOIN_ALWAYS = 1, /**< merge identical vertices for every format */
    BG_MESH_JOIN_NEVER = 2,  /**< never merge: vertices as the importer produced them */
    /** Ignore normals stored in the file (then nx/ny/nz are NULL), before
     *  joining, so that vertices differing only in their normal merge. STL
     *  files are always loaded this way: their normals are per facet, not per
     *  vertex. */
    BG_MESH_DROP_NORMALS = 4
} bg_mesh_flags;

/** Load a mesh with bg_mesh_load_ex(path, BG_MESH_JOIN_AUTO, ...). */
BG_API bg_status bg_mesh_load(const char *path, bg_mesh *out, char *err, size_t errlen);

/** Load any format assimp reads (OBJ, PLY, OFF, STL, glTF, ...).
 *  Errors (the message in err names the file; *out is left empty):
 *   - BG_ERR_IO: missing or unreadable file;
 *   - BG_ERR_FORMAT: assimp cannot parse it, or it holds no triangle
 *     (empty scene, point cloud, lines only), or it has more than UINT32_MAX
 *     vertices;
 *   - BG_ERR_OUT_OF_MEMORY.
 *  Degenerate content is loaded as it is: zero-area triangles, triangles with
 *  repeated indices and NaN/Inf coordinates stay, for the caller to handle.
 *
 *  On POSIX systems the import runs in a forked child process that sends the
 *  mesh back through a pipe, so that an importer crash or an assimp internal
 *  assertion (abort) on a corrupt file becomes BG_ERR_FORMAT with a message
 *  instead of ending the caller; if no child can be started the import runs
 *  in-process. The child only loads and writes to the pipe, then _exit()s.
 *  Thread-safe (each call uses its own importer). */
BG_API bg_status bg_mesh_load_ex(const char *path, unsigned flags, bg_mesh *out, char *err,
                                 size_t errlen);

/** Write positions, normals (if nx), UV set 0 (if u) and the triangles of
 *  `mesh` to `path` with assimp's exporter `format_id` (as `assimp
 *  listexport` names them, e.g. "objnomtl": Wavefront OBJ without a material
 *  file). Writes `path` directly: the caller gives a temporary name and
 *  renames it. BG_OK; BG_ERR_NULL_POINTER; BG_ERR_INVALID_ARGUMENT (more than
 *  2^32-1 vertices or triangles); BG_ERR_IO (the exporter failed, message in
 *  err); BG_ERR_OUT_OF_MEMORY. */
BG_API bg_status bg_mesh_export(const char *path, const char *format_id, const bg_mesh *mesh,
                                char *err, size_t errlen);

/** Free the arrays of a mesh and zero it; NULL and an already freed mesh are fine. */
BG_API void bg_mesh_free(bg_mesh *mesh);

#ifdef __cplusplus
}
#endif

#endif /* BUMPGRAD_MESH_H */
