/* SPDX-License-Identifier: MIT */
/* The face of `bumpgrad render` (src/tools/render): the options, the result
 * and bgt_render_run, with the names of the methods and scenes an option
 * parser needs. A small CPU ray caster that models just what the paper's
 * scenes need (Mikkelsen 2010, sections 4-6): an analytic sphere, a
 * triangulated isosurface or a loaded mesh, one point light, a solid height
 * field, and the normal-perturbation methods the paper compares (Figures 1-4).
 * The pieces behind it are in render_internal.h. */
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
    /* Height / normal textures on a mesh with UVs (render_textured.c): */
    RENDER_LISTING1_HEIGHTMAP = 8,  /* Listing 1 fed by Listing 2 forward taps (quad ddx/ddy of st) */
    RENDER_LISTING1_HEIGHTMAP_CENTRAL = 9, /* the same with Listing 2's central taps */
    RENDER_NORMALMAP = 10,          /* tangent-space normal map, mikkTSpace frames */
    RENDER_SURFGRAD_HEIGHTMAP = 11, /* eq. 3 on the UV chart, bicubic texel derivatives */
    RENDER_DETAIL = 12,             /* the Listing 1/2 height texture + turbulence, resolved */
    RENDER_METHOD_COUNT = 13
} render_method;
const char *render_method_name(render_method m);
/* 0 and *out on success, -1 for an unknown name. */
int render_method_parse(const char *name, render_method *out);

typedef enum render_shape { RENDER_SPHERE = 0, RENDER_BLOB = 1, RENDER_TORUS = 2 } render_shape;
const char *render_shape_name(render_shape s);
int render_shape_parse(const char *name, render_shape *out);

#define RENDER_MAX_METHODS 8

/* Summary of one method against analytic surfgrad, over the samples that hit. */
typedef struct render_stats {
    size_t hits;
    double mean_deg, p99_deg, max_deg;
    double inward_fraction;
} render_stats;

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
    unsigned albedo_mask; /* set by bgt_render_run from no_albedo / the preset */
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
    /* With a --height-grid (grid = 1): the hit points the grid was sampled
     * at, those inside the box of its active voxel centres (one voxel of
     * margin, as `perturb` counts) and those where its height is 0 (outside
     * its active voxels: no bump there); grid_box = that box without margin
     * (min xyz, max xyz). */
    int grid;
    size_t grid_points, grid_in_box, grid_zero;
    double grid_box[6];
} render_result;

/* The job: open the height source o->h (bgt_height_open; closed before
 * returning), check the output (extension, writable folder), render the
 * methods of `o`, compose the panel when o->compare, write o->output through
 * bg_image_write (temporary + rename), and run the density sweep when
 * o->sweep. BG_OK, or an error with a message in *e; a failure after the
 * image was written (the sweep) leaves r->out_width set. */
bg_status bgt_render_run(const render_opts *o, render_result *r, bgt_err *e);

#endif
