/* SPDX-License-Identifier: MIT */
/* The mesh tool behind `bumpgrad mesh` (src/cli/cmd_mesh.c): the whole job
 * (bgt_mesh_run, mesh_job.c), and its pieces: mesh-level vertex normals and
 * tangents (mesh_frames.c), the PLY writer (mesh_ply.c) and the UV-space
 * normal-map baker (mesh_bake.c). Tools build only. */
#ifndef BUMPGRAD_TOOLS_MESH_TOOL_H
#define BUMPGRAD_TOOLS_MESH_TOOL_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include "bumpgrad.h"
#include "bumpgrad/image.h"
#include "bumpgrad/mesh.h"
#include "common/tool.h"
#include "height_source.h"
#include "mesh/mikktspace.h"

/* ---- degenerate input ----
 * A triangle is "unusable" when an index repeats, a corner position is NaN/Inf,
 * or its area is zero (the cross product of its edges is 0 in double). Unusable
 * triangles add nothing to vertex normals, tangents or the bake; they stay in
 * the output PLY as they were. */
int mesh_triangle_usable(const bg_mesh *m, size_t t);

/* Normalize the normals in place with the rule of surfgrad.h: a zero or
 * non-finite normal becomes (0,0,0), the "no normal" sentinel. Returns how
 * many sentinels there are. */
size_t mesh_normalize_normals(size_t n, float *nx, float *ny, float *nz);

/* Angle-weighted vertex normals (Thürmer and Wüthrich 1998): the sum over the
 * usable triangles around a vertex of (corner angle) * (unit face normal),
 * normalized. Face normals follow the winding (counter-clockwise = front).
 * A vertex with no usable triangle gets the (0,0,0) sentinel. Returns the
 * number of sentinels, or (size_t)-1 when out of memory. */
size_t mesh_vertex_normals(const bg_mesh *m, float *nx, float *ny, float *nz);

/* Tangent frames: per corner, in the mikkTSpace convention (mikktspace.h,
 * bgt_mikk_tangents); the bake and the glTF output use them. */
/* Signed UV area (twice) of triangle t: > 0 keeps orientation, < 0 mirrors. */
double mesh_uv_signed_area(const bg_mesh *m, size_t t);

/* ---- PLY output ---- */
typedef struct mesh_ply_out {
    size_t vertex_count, triangle_count;
    const float *px, *py, *pz;
    const float *nx, *ny, *nz;    /* perturbed unit normal */
    const float *ox, *oy, *oz;    /* original unit normal */
    const float *height;
    const float *compare;         /* NULL, or the surfgrad/additive angle (degrees) */
    const float *u, *v;           /* NULL when the mesh has no UVs */
    const uint32_t *indices;
    const char *comment;          /* one header comment line, or NULL */
    int ascii;
} mesh_ply_out;
/* Write the PLY into an open stream. 0, or nonzero on a write error. */
int mesh_ply_write(FILE *fp, const mesh_ply_out *d);

/* ---- normal-map bake ---- */
typedef enum mesh_bake_space { MESH_BAKE_TANGENT = 0, MESH_BAKE_OBJECT = 1 } mesh_bake_space;
/* Where the tangent frame of a tangent-space bake comes from. */
typedef enum mesh_tangent_source {
    MESH_TANGENTS_MIKK = 0, /* bgt_mikk_tangents of the unit vertex normals (default) */
    MESH_TANGENTS_FILE = 1  /* the file's per-vertex tangents (bg_mesh tx..tw) */
} mesh_tangent_source;
/* UDIM tiles (the Mari convention): tile number 1001 + u_tile + 10 * v_tile
 * with u_tile = floor(u) in 0..9 and v_tile = floor(v) in 0..MESH_UDIM_V_TILES-1
 * (four digits). A bake whose path holds the token writes one image per tile
 * that a triangle's UV bounding box touches and at least one texel centre of
 * which is covered; at most MESH_UDIM_MAX_TILES tiles (more is refused before
 * any baking: each tile is a full W x H bake). */
#define MESH_UDIM_TOKEN "<UDIM>"
#define MESH_UDIM_MAX_TILES 100
#define MESH_UDIM_V_TILES 899
typedef struct mesh_bake_opts {
    int width, height;   /* per tile */
    mesh_bake_space space;
    int padding;
    bg_perturb_method method;
    int threads;
    mesh_tangent_source tangents;
    int green_down;      /* store -m.y (DirectX normal maps, --normal-map-y -y) */
    int udim;            /* bake every UDIM tile (else the unit square only, tile 1001) */
    const bgt_progress *progress; /* texels shaded, over all tiles; may be NULL */
} mesh_bake_opts;
typedef struct mesh_bake_stats {
    size_t covered;      /* texels inside some triangle */
    size_t padded;       /* texels filled by the dilation */
    size_t skipped;      /* unusable triangles or triangles with zero / non-finite UV area */
    size_t islands;          /* UV islands (mesh_uv_islands) */
    size_t overlap_texels;   /* texel centres strictly inside two or more triangles */
    size_t overlap_islands;  /* islands with a triangle in such an overlap */
    bgt_mikk_stats mikk;     /* of the mikkTSpace tangents (tangent space, MESH_TANGENTS_MIKK) */
    size_t tiles;            /* images handed to the sink */
    int tile_udim[MESH_UDIM_MAX_TILES]; /* their UDIM numbers in order (1001 without udim) */
} mesh_bake_stats;
/* Receives each finished tile (3 channels, encoded 0.5 * m + 0.5), in UDIM
 * order; the image is freed after the call. A status other than BG_OK stops
 * the bake and is returned. */
typedef bg_status (*mesh_bake_sink)(void *ctx, int udim, const bg_image *img, bgt_err *e);
/* Rasterize the mesh in UV space, one tile after the other (tile (a, b)
 * holds u in [a, a + 1], v in [b, b + 1]; the tangent frames are computed once
 * from the unshifted UVs). `nx/ny/nz` are the unit vertex normals; `h` is
 * opened. BG_OK; BG_ERR_INVALID_ARGUMENT when a tile's memory exceeds the cap
 * (bgt_check_alloc) or the UVs span more than MESH_UDIM_MAX_TILES tiles;
 * BG_ERR_OUT_OF_MEMORY (also for more than INT32_MAX triangles); or the
 * sink's status; with a message in *e. */
bg_status mesh_bake(const bg_mesh *m, const float *nx, const float *ny, const float *nz,
                    const bgt_height *h, const mesh_bake_opts *o, mesh_bake_sink sink,
                    void *sink_ctx, mesh_bake_stats *stats, bgt_err *e);
/* The bytes a W x H tile needs while baking (per-texel buffers + the image). */
double mesh_bake_tile_bytes(int width, int height);

/* ---- the whole job of `bumpgrad mesh` (mesh_job.c) ---- */
typedef struct bgt_mesh_opts {
    const char *input;       /* any format assimp reads (required) */
    const char *output;      /* OUT.ply, "-" = stdout, or NULL (then bake_path is required) */
    const char *bake_path;   /* normal map (format from the extension), "-" = stdout
                              * (bake_format), or NULL */
    const char *bake_format; /* the format of bake_path "-" (an OpenImageIO name: png, exr,
                              * tif, ...; NULL: PNG); with a file map it must agree with
                              * the extension */
    const bgt_height *height; /* the height parameters, NOT opened: bgt_mesh_run opens
                               * (and closes) its own copy after the path checks */
    bg_perturb_method method;
    int compare;             /* add the compare_deg property */
    int ascii;               /* ASCII PLY instead of binary little-endian */
    int recompute_normals;   /* ignore the file's normals */
    unsigned join;           /* BG_MESH_JOIN_AUTO / _ALWAYS / _NEVER */
    int threads;             /* 0 = all cores */
    mesh_bake_opts bake;     /* width, height (> 0 with bake_path), space, padding;
                              * method and threads are taken from above */
    int bake_depth;          /* a bg_pixel_type, or -1: half for .exr, else 8 bits */
    const bgt_progress *progress; /* the bake's progress (texels), may be NULL */
} bgt_mesh_opts;

/* Mesh output formats, chosen by OUT's extension (case-insensitive); "-" and
 * a device (/dev/null, a FIFO) get PLY. */
typedef enum mesh_out_format {
    MESH_OUT_PLY = 0,
    MESH_OUT_GLB = 1,  /* binary glTF 2.0 (mesh_gltf.c), TANGENT when IN has UVs */
    MESH_OUT_GLTF = 2, /* glTF 2.0 with the buffer embedded */
    MESH_OUT_OBJ = 3,  /* Wavefront OBJ without a material file (assimp's exporter) */
    MESH_OUT_UNKNOWN = -1
} mesh_out_format;
mesh_out_format mesh_out_format_of(const char *path);
const char *mesh_out_format_name(mesh_out_format f, int ascii);

/* What `bumpgrad mesh` prints: the mesh, the normals, the perturbation
 * statistics (means over the vertices with a normal), the bake and the times. */
typedef struct bgt_mesh_result {
    size_t vertex_count, triangle_count, mesh_count, dropped_primitives;
    int file_normals;            /* normals came from the file (else angle-weighted) */
    size_t no_normal;            /* vertices with the (0,0,0) sentinel */
    size_t unusable_triangles, nonfinite_positions;
    size_t valid;                /* vertices with a normal */
    size_t finite_height, nonfinite_height;
    double mean_height;          /* over the finite heights (0 if none) */
    double mean_angle, max_angle; /* n vs n' of the chosen method, degrees */
    size_t inward_surf, inward_other; /* dot(n', n) <= 0: surfgrad, and the other method */
    double mean_compare, max_compare; /* surfgrad vs additive (or the chosen additive) */
    mesh_bake_stats bake;
    int threads;                 /* worker threads used */
    double t_load, t_normals, t_perturb, t_bake, t_write; /* seconds */
} bgt_mesh_result;

/* The checks on the paths of `o` that bgt_mesh_run makes before anything else
 * (so a caller may make them before its own preparations, e.g. opening the
 * height): one file named for OUT.ply and the map; OUT.ply over a non-PLY
 * input; a map path that exists and is not a regular file. BG_OK or
 * BG_ERR_INVALID_ARGUMENT. */
bg_status bgt_mesh_check(const bgt_mesh_opts *o, bgt_err *e);

/* Load the mesh (bg_mesh_load_ex: the import child), take or compute unit
 * vertex normals, evaluate the height and perturb every normal (Mikkelsen 2010
 * eq. 2 and 4, Listing 3), write OUT.ply (through common/safe_file.h; an
 * existing device such as /dev/null is written in place) and/or bake and write
 * the normal map, one image per UDIM tile when bake_path holds MESH_UDIM_TOKEN
 * (each tile written by bg_image_write_as to a temporary as soon as it is
 * baked; all tiles renamed into place at the end, then the mesh output). A
 * failure before the renames leaves no new file and every old one as it was.
 * bake_path "-" streams the one map to standard output as soon as it is baked
 * (before the mesh output, which then cannot be "-" too). *r is
 * filled on success (r->bake.tiles, r->bake.tile_udim: the tiles written).
 * Status: BG_ERR_INVALID_ARGUMENT / BG_ERR_FORMAT for bad input (paths,
 * height, a missing or malformed mesh, a bake without UVs, a map name without
 * an image format); BG_ERR_IO or BG_ERR_OUT_OF_MEMORY when the run fails. */
bg_status bgt_mesh_run(const bgt_mesh_opts *o, bgt_mesh_result *r, bgt_err *e);

#endif
