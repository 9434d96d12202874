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
#include "common/tool.h"
#include "height_source.h"

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
    RENDER_METHOD_COUNT = 8
} render_method;

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
    float *pos;  /* 9 floats per triangle: the three vertex positions */
    float *nrm;  /* 9 floats per triangle: the three unit vertex normals */
    float *face; /* 3 floats per triangle: unit face normal, on the side of the vertex normals */
    render_bvh_node *nodes;
    size_t nnodes;
} render_mesh;

/* Marching tetrahedra of the implicit `shape` (blob or torus) on a grid of
 * `grid` cells per axis; vertex normals from the analytic field gradient.
 * 0 or BG_ERR_OUT_OF_MEMORY. */
bg_status render_mesh_build(render_shape shape, int grid, render_mesh *m);
void render_mesh_free(render_mesh *m);

typedef struct render_hit {
    float t;
    int prim;   /* triangle index, 0 for the sphere */
    float b1, b2; /* barycentrics of vertices 1 and 2 */
} render_hit;
/* Closest hit of the ray o + t d with t in (0, tmax); 1 on a hit. */
int render_mesh_intersect(const render_mesh *m, const float o[3], const float d[3], float tmax,
                          render_hit *hit);

/* ---- scene and job (render_core.c) ---- */
typedef struct render_scene {
    render_shape shape;
    const render_mesh *mesh; /* NULL for the sphere */
    float eye[3], fwd[3], right[3], up[3];
    float tan_half; /* tan(fov/2) / zoom */
    float light[3];
} render_scene;

/* Camera on the +z side looking at the origin from `distance`, with a slight
 * elevation; `zoom` scales the focal length. */
void render_scene_camera(render_scene *s, float distance, float zoom);

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
typedef enum render_preset { PRESET_NONE = 0, PRESET_FIG1, PRESET_FIG2, PRESET_FIG3 } render_preset;

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
    render_preset preset;
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
    size_t triangles; /* of the isosurface, 0 for the sphere */
    int nmethods;
    render_method methods[RENDER_MAX_METHODS];
    render_stats stats[RENDER_MAX_METHODS];
    int out_width, out_height; /* of the written image */
    int nsweep;
    render_sweep_row sweep[RENDER_MAX_SWEEP * RENDER_MAX_METHODS];
} render_result;

/* Check the output (extension, writable folder) first, then render the job
 * of `o` (with its height already opened by bgt_height_open), compose the
 * panel when o->compare, write o->output through bg_image_write (temporary +
 * rename), and run the density sweep when o->sweep. */
bg_status render_image(const render_opts *o, render_result *r, bgt_err *e);

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
