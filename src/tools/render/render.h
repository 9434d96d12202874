/* SPDX-License-Identifier: MIT */
/* Internal interface of `bumpgrad render`: a small CPU ray caster that models
 * just what the paper's scenes need (Mikkelsen 2010, sections 4-6): an analytic
 * sphere and a triangulated isosurface, one point light, a solid height field,
 * and the normal-perturbation methods the paper compares (Figures 1, 2, 3).
 * Files: render_mesh.c (marching tetrahedra + BVH), render_core.c (camera,
 * ray casting, per-tile G-buffer, methods, shading), render_panel.c (bitmap
 * font, heat map, panels), cmd_render.c (options, presets, statistics). */
#ifndef BUMPGRAD_TOOLS_RENDER_H
#define BUMPGRAD_TOOLS_RENDER_H

#include <stddef.h>
#include <stdint.h>
#include "common/tool.h"
#include "height_source.h"
#include "bumpgrad/framework.h"

/* Normal-perturbation methods of --method / --compare. */
typedef enum render_method {
    RENDER_NONE = 0,             /* the unperturbed (interpolated) normal */
    RENDER_SURFGRAD = 1,         /* Listing 3, analytic gradient (eq. 2, 4) */
    RENDER_SURFGRAD_CENTRAL = 2, /* Listing 3, central-difference gradient */
    RENDER_LISTING1 = 3,         /* Listing 1 with ddx_fine/ddy_fine on 2x2 quads */
    RENDER_LISTING1_COARSE = 4,  /* Listing 1 with one derivative per quad */
    RENDER_ADDITIVE = 5,         /* Perlin: normalize(n - grad h), Figure 2(a) */
    RENDER_FLAT = 6,             /* cross(tau_s, tau_t) of the displaced position, Figure 1(a) */
    RENDER_SURFGRAD_FOOTPRINT = 7, /* Listing 3 with no octave finer than the sample's footprint */
    /* Height / normal textures on a mesh with UVs (render_textured.c): */
    RENDER_LISTING1_HEIGHTMAP = 8,  /* Listing 1 fed by Listing 2 forward taps (quad ddx/ddy of st) */
    RENDER_LISTING1_HEIGHTMAP_CENTRAL = 9, /* the same with Listing 2's central taps */
    RENDER_NORMALMAP = 10,          /* tangent-space normal map, mikkTSpace frames */
    RENDER_SURFGRAD_HEIGHTMAP = 11, /* eq. 3 on the UV chart, bicubic texel derivatives */
    RENDER_DETAIL = 12,             /* the Listing 1/2 height texture + turbulence, resolved */
    RENDER_METHOD_COUNT = 13
} render_method;
/* 1 for the methods that need UVs and a height (or normal) texture. */
int render_method_textured(render_method m);

const char *render_method_name(render_method m);
/* 0 and *out on success, -1 for an unknown name. */
int render_method_parse(const char *name, render_method *out);

typedef enum render_shape { RENDER_SPHERE = 0, RENDER_BLOB = 1, RENDER_TORUS = 2 } render_shape;
const char *render_shape_name(render_shape s);
int render_shape_parse(const char *name, render_shape *out);

/* ---- triangle mesh with a bounding-volume hierarchy (render_mesh.c) ---- */
typedef struct render_bvh_node {
    float lo[3], hi[3];
    int left;  /* interior: index of the first child (the second is left + 1) */
    int first; /* leaf: first triangle in the reordered list; interior: -1 */
    int count; /* leaf: triangle count */
} render_bvh_node;

typedef struct render_mesh {
    size_t ntri;
    float *uv;   /* 6 floats per triangle: (s, t) texture coordinates of the corners
                    (s = u, t = 1 - v: the image's row direction), or NULL */
    float *tan;  /* 12 floats per triangle: the mikkTSpace tangent (along dP/du) and
                    bitangent sign (b = sign * n x t, along dP/dv) per corner
                    (bgt_mikk_tangents), or NULL */
    float *pos;  /* 9 floats per triangle: the three vertex positions */
    float *nrm;  /* 9 floats per triangle: the three unit vertex normals */
    float *face; /* 3 floats per triangle: unit face normal, on the side of the vertex normals */
    uint32_t *mat; /* per triangle: its material (render_textures.mat), or NULL: all 0 */
    render_bvh_node *nodes;
    size_t nnodes;
} render_mesh;

/* Marching tetrahedra of the implicit `shape` (blob or torus) on a grid of
 * `grid` cells per axis; vertex normals from the analytic field gradient.
 * 0 or BG_ERR_OUT_OF_MEMORY. */
bg_status render_mesh_build(render_shape shape, int grid, render_mesh *m);
void render_mesh_free(render_mesh *m);
/* Take ownership of a triangle soup (pos, nrm 9 floats per triangle, uv 6 or
 * NULL, tan 12 or NULL; malloc'ed) and compute the face normals. 0 or
 * BG_ERR_OUT_OF_MEMORY (the arrays are freed on failure). */
bg_status render_mesh_adopt(render_mesh *m, size_t ntri, float *pos, float *nrm, float *uv,
                            float *tan);
/* Build the median-split BVH (reorders the triangles). 0 or BG_ERR_OUT_OF_MEMORY
 * (the mesh is freed on failure). */
bg_status render_mesh_bvh(render_mesh *m);

typedef struct render_hit {
    float t;
    int prim;   /* triangle index, 0 for the sphere */
    float b1, b2; /* barycentrics of vertices 1 and 2 */
} render_hit;
/* Closest hit of the ray o + t d with t in (0, tmax); 1 on a hit. */
int render_mesh_intersect(const render_mesh *m, const float o[3], const float d[3], float tmax,
                          render_hit *hit);

/* ---- Embree (render_embree.c; stubs that fail without BG_HAVE_EMBREE) ---- */
typedef struct render_embree render_embree;
/* 1 when the tool was built with Embree. */
int render_embree_available(void);
/* Build an Embree scene of the mesh's triangles (same prim ids and barycentrics
 * as render_mesh_intersect) with `threads` build threads (0: every core);
 * *build_seconds gets the BVH build's wall time.
 * BG_ERR_INVALID_ARGUMENT without Embree, BG_ERR_OUT_OF_MEMORY on failure. */
bg_status render_embree_build(const render_mesh *m, int threads, render_embree **out,
                              double *build_seconds, bgt_err *e);
void render_embree_free(render_embree *r);
int render_embree_intersect(const render_embree *r, const float o[3], const float d[3],
                            render_hit *hit);

/* ---- textures of a mesh (render_textured.c) ---- */
/* The texture set of one material of the file (or the --height-map,
 * --normal-map, --albedo given for all). */
typedef struct render_material {
    bg_height_texture height; /* heights in [0, 1] (gray levels); texels NULL: none */
    bg_height_texture nmap[3]; /* tangent-space normal, t/b/n components; texels NULL: none */
    bg_height_texture albedo[3]; /* linear RGB; texels NULL: none */
    float *owned[7];
} render_material;
typedef struct render_textures {
    render_material *mat; /* nmat >= 1 sets; triangle k uses mat[mesh->mat[k]] */
    size_t nmat;
    int any_height, any_nmap; /* some material has a height texture / a normal map */
    float amplitude;  /* world height of a texel value 1 (the mesh fits the unit sphere) */
    float st_scale;   /* texture coordinates multiplied by this (< 1 magnifies) */
} render_textures;
void render_textures_free(render_textures *t);
/* The material of triangle `prim` (the first without per-triangle ids). */
static inline const render_material *render_tex_material(const render_textures *t,
                                                         const render_mesh *m, int prim)
{
    size_t i = m->mat ? m->mat[prim] : 0;
    return &t->mat[i < t->nmat ? i : 0];
}
/* dP/ds, dP/dt of triangle `prim` on its (scaled) UV chart; zero when its UVs
 * are degenerate. */
void render_tex_chart(const render_mesh *m, const render_textures *tx, int prim, float ds[3],
                      float dt[3]);
/* (s, t) of a point p of the plane of triangle `prim` (affine extension). */
void render_tex_st(const render_mesh *m, const render_textures *tx, int prim, const float p[3],
                   float st[2]);

/* ---- scene and job (render_core.c) ---- */
typedef struct render_scene {
    render_shape shape;
    const render_mesh *mesh; /* NULL for the sphere */
    const render_embree *embree; /* non-NULL: rays through Embree instead of the BVH */
    const render_textures *tex;  /* non-NULL: a loaded mesh with textures */
    float eye[3], fwd[3], right[3], up[3];
    float tan_half; /* tan(fov/2) / zoom */
    float light[3];
} render_scene;

/* Camera on the +z side looking at the origin from `distance`, with a slight
 * elevation; `zoom` scales the focal length. */
void render_scene_camera(render_scene *s, float distance, float zoom);
/* The same camera looking at the origin from direction `view` (towards the eye). */
void render_scene_camera_dir(render_scene *s, const float view[3], float distance, float zoom);

#define RENDER_MAX_METHODS 8

typedef struct render_job {
    const render_scene *scene;
    const bgt_height *height;
    int width, height_px; /* output pixels */
    int ss;               /* samples per axis per pixel: spp = ss * ss */
    int nmethods;
    render_method methods[RENDER_MAX_METHODS];
    int threads;
    const bgt_progress *progress; /* may be NULL */
    unsigned albedo_mask; /* bit k: method k is shaded with the albedo texture */
    /* outputs, allocated by render_run, freed by render_job_free: */
    float *rgb[RENDER_MAX_METHODS];   /* width*height_px*3 linear RGB per method */
    float *heat[RENDER_MAX_METHODS];  /* width*height_px mean angle error (deg), NaN for no hit */
    float *err[RENDER_MAX_METHODS];   /* per sample angle error vs surfgrad, NaN for no hit */
    unsigned char *inward[RENDER_MAX_METHODS]; /* per sample: 1 if dot(n', n) <= 0 */
    size_t nsamples;                  /* width*ss * height_px*ss */
} render_job;

/* Render all methods of the job. 0 or BG_ERR_OUT_OF_MEMORY. */
bg_status render_run(render_job *job);
void render_job_free(render_job *job);

/* Summary of one method against analytic surfgrad, over the samples that hit. */
typedef struct render_stats {
    size_t hits;
    double mean_deg, p99_deg, max_deg;
    double inward_fraction;
} render_stats;
bg_status render_stats_compute(const render_job *job, int k, render_stats *out); /* BG_OK or BG_ERR_OUT_OF_MEMORY */

/* The presets of --preset: the paper's figures (docs/FIGURES.md). */
typedef enum render_preset { PRESET_NONE = 0, PRESET_FIG1, PRESET_FIG2, PRESET_FIG3, PRESET_FIG4 } render_preset;

typedef enum render_tracer { TRACER_AUTO = 0, TRACER_BVH = 1, TRACER_EMBREE = 2 } render_tracer;

typedef struct render_opts {
    render_shape shape;
    int grid;
    int width, height, ss;
    float distance, zoom, heat_max;
    float light[3];
    int threads;
    int nmethods, compare;
    render_method methods[RENDER_MAX_METHODS];
    int closeup; /* magnification of the close-up row, 0 = none */
    int sweep;   /* print the error against pixel density */
    const char *output;
    /* The image format (an extension without the dot: "png", "exr", ...) of
     * output "-" (standard output); NULL = png. With a file name the extension
     * decides and a format that disagrees with it is refused. */
    const char *format;
    render_preset preset;
    render_tracer tracer;
    /* A mesh file (any format assimp reads) instead of the built-in scenes,
     * and its textures (NULL: the ones its materials name, bg_mesh.materials). */
    const char *mesh_path, *height_map, *normal_map, *albedo_map;
    float tex_amplitude; /* height of texel value 1 in units of the mesh's bounding radius */
    float st_scale;      /* texture-coordinate scale (< 1 magnifies the textures) */
    int no_albedo;       /* do not shade with the albedo texture */
    int view_set;        /* view[] given: camera direction (towards the eye) */
    int zoom_set;        /* --zoom given; else a loaded mesh is framed automatically */
    float view[3];
    float fig4_zoom;     /* --preset fig4: magnification of the close-up panels (e), (f) */
    float fig4_target[2]; /* and the image point (0..1, from the top left) they look at */
    unsigned albedo_mask; /* set by render_image from no_albedo / the preset */
    bgt_height h;
    const bgt_progress *progress; /* may be NULL */
} render_opts;

/* The defaults of `bumpgrad render` (sphere, 384x384, surfgrad, ...). */
void render_opts_default(render_opts *o);
/* Set the scene, height and methods of a preset (o->preset); options set
 * afterwards override it. */
void render_apply_preset(render_opts *o);

/* What a render reports, printed by the CLI. */
#define RENDER_MAX_SWEEP 5
typedef struct render_sweep_row {
    render_method method;
    double density;
    int width, height, spp;
    render_stats st;
} render_sweep_row;
typedef struct render_result {
    size_t triangles; /* of the isosurface or loaded mesh, 0 for the sphere */
    const char *tracer;   /* "bvh", "embree" or "analytic" */
    double build_seconds; /* acceleration structure build (BVH or Embree) */
    double load_seconds;  /* mesh and texture loading */
    double render_seconds;
    char textures[512];   /* the textures used, for the report line */
    int nmethods;
    render_method methods[RENDER_MAX_METHODS];
    render_stats stats[RENDER_MAX_METHODS];
    const char *labels[RENDER_MAX_METHODS]; /* panel captions (--preset fig4), or NULL */
    int out_width, out_height; /* of the written image */
    int nsweep;
    render_sweep_row sweep[RENDER_MAX_SWEEP * RENDER_MAX_METHODS];
} render_result;

/* Check the output (extension, writable folder) first, then render the job
 * of `o` (with its height already opened by bgt_height_open), compose the
 * panel when o->compare, write o->output through bg_image_write (temporary +
 * rename), and run the density sweep when o->sweep. */
bg_status render_image(const render_opts *o, render_result *r, bgt_err *e);

/* Load a mesh (bg_mesh_load) into a render_mesh centred at the origin and
 * scaled to fit the unit sphere, with UVs when the file has them, mikkTSpace
 * tangents when the normalmap method is rendered, the material of each
 * triangle (bg_mesh.material, any format assimp reads) and each material's textures (render_textured.c). Errors name the file:
 * BG_ERR_INVALID_ARGUMENT / BG_ERR_FORMAT (exit 2) for a missing, unreadable
 * or corrupt mesh or texture, or a textured method on a mesh without UVs.
 * No BVH: the caller builds Embree's or render_mesh_bvh. */
bg_status render_load_mesh(const render_opts *o, render_mesh *m,
                           render_textures *t, char *desc, size_t desclen, bgt_err *e);

/* ---- Listing 1 on one 2x2 quad (render_core.c; exposed for the unit test) ----
 * pos[lane][3], h[lane] for lanes 0 (x0,y0), 1 (x1,y0), 2 (x0,y1), 3 (x1,y1);
 * `lane` is the pixel whose normal is wanted, n its unit normal. fine != 0:
 * ddx_fine/ddy_fine (row/column pair of the lane), else one difference per quad. */
void render_listing1(const float pos[4][3], const float h[4], int lane, int fine,
                     const float n[3], float out[3]);

/* ---- images and panels (render_panel.c) ---- */
typedef struct render_canvas {
    int w, h;
    float *rgb; /* linear RGB */
} render_canvas;
bg_status render_canvas_alloc(render_canvas *c, int w, int h, const float bg[3]);
void render_canvas_free(render_canvas *c);
/* Copy a w x h RGB image to (x, y), magnified by an integer factor (nearest). */
void render_canvas_blit(render_canvas *c, int x, int y, const float *rgb, int w, int h, int scale);
/* Text in the 5x7 font, `scale` canvas pixels per font pixel; returns the width. */
int render_canvas_text(render_canvas *c, int x, int y, const char *text, int scale,
                       const float color[3]);
int render_text_width(const char *text, int scale);
/* Heat-map colour of an angle error in [0, max_deg] (linear RGB). */
void render_heat_color(float deg, float max_deg, float out[3]);

#endif
