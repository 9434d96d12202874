/* SPDX-License-Identifier: MIT */
/* The face of the mesh tool behind `bumpgrad mesh` (src/cli/cmd_mesh.c): its
 * options, its result and bgt_mesh_run (mesh_job.c). The pieces (frames, PLY
 * and glTF writers, the baker) are declared in mesh_internal.h, which only the
 * tool's own files include. Tools build only. */
#ifndef BUMPGRAD_TOOLS_MESH_H
#define BUMPGRAD_TOOLS_MESH_H

#include <stddef.h>
#include <stdint.h>
#include "bumpgrad.h"
#include "bumpgrad/image.h"
#include "bumpgrad/mesh.h"
#include "common/tool.h"
#include "height_source.h"
#include "mesh/mesh_texpath.h"
#include "mesh/mikktspace.h"

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
#define MESH_UDIM_MAX_TILES 100
#define MESH_UDIM_V_TILES 899
/* How a texel's height is band-limited (docs/MESH.md, "Anti-aliasing"). */
typedef enum mesh_bake_filter {
    MESH_FILTER_FOOTPRINT = 0, /* octaves finer than the texel's object-space footprint (from
                                * its triangle's UV Jacobian) fade out (bg_octave_weight);
                                * a VDB height is not filtered (use samples) */
    MESH_FILTER_NONE = 1       /* every octave at the sample point */
} mesh_bake_filter;
#define MESH_MAX_SAMPLES 16
/* The default sampling (samples = 0, mesh_bake.c sample_patterns): 2 x 2 per
 * texel, and a rank-1 lattice of MESH_DENSE_SAMPLES points (generator
 * MESH_DENSE_GENERATOR) on triangles where an octave the 2 x 2 samples keep
 * has cells narrower than MESH_DENSE_CELL texels. */
#define MESH_DENSE_SAMPLES 7
#define MESH_DENSE_GENERATOR 3
#define MESH_DENSE_CELL 4.0

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
    mesh_bake_filter filter;
    int samples;         /* N: N x N stratified samples per texel, averaged (1: the texel
                          * centre; 0: the default, 2 x 2 or MESH_DENSE_SAMPLES per
                          * triangle), at most MESH_MAX_SAMPLES */
    const struct mesh_hi *hi; /* the high-poly source of --from (mesh_internal.h), or NULL */
    int only_tile;       /* 0, or with udim one UDIM number: bake that tile alone (texel
                          * for texel the same tile as the full bake; an error if the UVs
                          * do not touch it) */
} mesh_bake_opts;
typedef struct mesh_bake_stats {
    size_t covered;      /* texels inside some triangle */
    size_t padded;       /* texels filled by the dilation */
    size_t skipped;      /* unusable triangles or triangles with zero / non-finite UV area */
    size_t islands;          /* UV islands (mesh_uv_islands) */
    size_t overlap_texels;   /* texel centres strictly inside two or more triangles */
    size_t overlap_islands;  /* islands with a triangle in such an overlap */
    bgt_mikk_stats mikk;     /* of the mikkTSpace tangents (tangent space, MESH_TANGENTS_MIKK) */
    /* Without udim: triangles whose UVs lie wholly outside the unit square
     * (left out of the map), and the first UDIM tiles they touch. */
    size_t outside_triangles;
    size_t outside_tile_count;   /* tiles other than 1001 that the UVs touch */
    int outside_tiles[8];        /* the first of them, ascending */
    double texel_size;           /* mean object-space footprint of a covered texel (model units) */
    size_t tiles;            /* images handed to the sink */
    int tile_udim[MESH_UDIM_MAX_TILES]; /* their UDIM numbers in order (1001 without udim) */
    /* --from: samples cast, samples whose rays missed HIGH, texels all of whose
     * samples missed (they keep LOW's normal), texels with some missed */
    size_t ray_samples, ray_misses, miss_texels, partial_miss_texels;
} mesh_bake_stats;
/* The vertex normals of an OUT.glb / OUT.gltf. */
typedef enum mesh_gltf_normals {
    MESH_GLTF_NORMALS_AUTO = 0,     /* original with a baked map, else bumped */
    MESH_GLTF_NORMALS_ORIGINAL = 1, /* the unbumped normals (the map carries the bump) */
    MESH_GLTF_NORMALS_BUMPED = 2    /* the bumped normals; then no material uses the map */
} mesh_gltf_normals;

/* The units of --frequency and --amplitude (docs/MESH.md, "Scale"). */
typedef enum mesh_units {
    MESH_UNITS_MODEL = 0, /* per model radius: the height sees the model scaled into the unit
                           * sphere (mesh_frames.h), as `render --mesh` does */
    MESH_UNITS_FILE = 1   /* the file's own units */
} mesh_units;

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
    int gltf_normals;        /* a mesh_gltf_normals */
    int units;               /* a mesh_units */
    /* High-poly to low-poly (docs/MESH.md): with `from`, the map holds the normals of
     * HIGH where the rays from each texel's point of IN (LOW) hit it. */
    const char *from;        /* HIGH: any mesh assimp reads, or NULL */
    const char *cage;        /* LOW with its vertices moved outward (same triangles), or NULL */
    double ray_distance;     /* front and back, in the units of `units`; 0: the default
                              * MESH_DEFAULT_RAY_DISTANCE model radii of LOW */
    const char *height_map;  /* signed distance LOW -> HIGH along the rays (file units), a
                              * float image (.exr, .tif), or NULL */
    const char *miss_map;    /* the fraction of each texel's samples that missed, or NULL */
    int detail;              /* add the height's surface gradient at the hit points */
} bgt_mesh_opts;
#define MESH_DEFAULT_RAY_DISTANCE 0.1

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
    const char *output_format;   /* OUT's format in words ("binary glTF 2.0", ...), or NULL */
    double model_centre[3], model_radius; /* the model frame (file units) */
    double unit;                 /* one height unit in file units: model_radius, or 1 */
    double finest_feature, coarsest_feature; /* the height's finest and coarsest lattice
                                  * cells, file units (0 for a VDB height) */
    double mean_edge;            /* mean edge length of the usable triangles, file units */
    /* glTF output: */
    int gltf_bumped_normals;     /* NORMAL holds the bumped normals */
    int gltf_map;                /* 0: no material uses the map; 1: the normalTexture is the
                                  * map's file; 2: an 8-bit PNG of it (embedded) */
    const char *gltf_map_note;   /* why the map is not a normalTexture, or NULL */
    size_t gltf_materials, gltf_textures, gltf_textures_dropped;
    size_t gltf_meshes;          /* meshes (and nodes): the source's node instances with
                                  * triangles, or 1 over BG_MESH_MAX_PARTS */
    int gltf_merged;             /* the scene had more than BG_MESH_MAX_PARTS of them */
    double t_load, t_normals, t_perturb, t_bake, t_write; /* seconds */
    /* --from: HIGH, the Embree scene's build time (inside t_load), the ray distance
     * (file units) */
    size_t high_vertex_count, high_triangle_count, high_mesh_count, high_usable;
    int high_file_normals;
    double t_bvh, ray_distance;
} bgt_mesh_result;

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

/* The bake of bgt_mesh_run in memory, for `bumpgrad bench` (mesh_bench.c):
 * `m` (with UVs) and its unit vertex normals nx..nz baked with `o` (the
 * height `h` opened); the tiles are made and dropped. Status and stats as
 * mesh_bake's. */
bg_status bgt_mesh_bake_dropped(const bg_mesh *m, const float *nx, const float *ny,
                                const float *nz, const bgt_height *h, const mesh_bake_opts *o,
                                mesh_bake_stats *stats, bgt_err *e);

#endif
