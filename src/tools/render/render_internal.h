/* SPDX-License-Identifier: MIT */
/* Inside `bumpgrad render` (the face is render.h): render_mesh.c (marching
 * tetrahedra + BVH), render_embree.c (Embree scenes), render_textured.c (mesh
 * loading and textures), render_core.c (camera, ray casting, per-tile
 * G-buffer, methods, shading), render_panel.c (bitmap font, heat map,
 * panels), render_image.c (bgt_render_run: options to file, presets). Only
 * the tool's own files and its unit tests include this header. */
#ifndef BUMPGRAD_TOOLS_RENDER_INTERNAL_H
#define BUMPGRAD_TOOLS_RENDER_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include "bumpgrad/framework.h"
#include "render/render.h"

/* 1 for the methods that need UVs and a height (or normal) texture. */
int render_method_textured(render_method m);

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
    /* With a grid height (height->grid): the hits it was sampled at, those in
     * its active voxels' box (one voxel of margin) and those where its height
     * is 0 (no bump there), counted by render_run. */
    size_t grid_points, grid_in_box, grid_zero;
} render_job;

/* Render all methods of the job. 0 or BG_ERR_OUT_OF_MEMORY. */
bg_status render_run(render_job *job);
void render_job_free(render_job *job);

bg_status render_stats_compute(const render_job *job, int k, render_stats *out); /* BG_OK or BG_ERR_OUT_OF_MEMORY */

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
