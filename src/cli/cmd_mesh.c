/* SPDX-License-Identifier: MIT */
/* `bumpgrad mesh`: bump a real mesh (any format assimp reads) with a solid
 * height field, per vertex into a PLY and/or baked into a normal map. This
 * file parses the options (one table, args.h), runs the tool (bgt_mesh_run, src/tools/mesh/
 * mesh_job.c) and prints its summary. Format, conventions and measurements:
 * docs/MESH.md. */
#include <stdlib.h>
#include <string.h>
#include "args.h"
#include "cli.h"
#include "json.h"
#include "mesh/mesh.h"

static void print_json(const bgt_mesh_opts *o, const bgt_mesh_result *r)
{
    cli_json j;
    cli_json_begin(&j, stdout);
    cli_json_common(&j, "mesh", r->t_load + r->t_normals + r->t_perturb + r->t_bake + r->t_write);
    cli_json_int(&j, "vertices", (long long)r->vertex_count);
    cli_json_int(&j, "triangles", (long long)r->triangle_count);
    cli_json_int(&j, "scene_meshes", (long long)r->mesh_count);
    cli_json_int(&j, "dropped_primitives", (long long)r->dropped_primitives);
    cli_json_bool(&j, "file_normals", r->file_normals);
    cli_json_int(&j, "vertices_without_normal", (long long)r->no_normal);
    cli_json_int(&j, "unusable_triangles", (long long)r->unusable_triangles);
    cli_json_num(&j, "mean_height", r->mean_height);
    cli_json_int(&j, "nonfinite_heights", (long long)r->nonfinite_height);
    cli_json_num(&j, "mean_angle_deg", r->mean_angle);
    cli_json_num(&j, "max_angle_deg", r->max_angle);
    cli_json_num(&j, "inward_fraction_surfgrad",
                 r->valid ? (double)r->inward_surf / (double)r->valid : 0.0);
    cli_json_num(&j, "inward_fraction_other",
                 r->valid ? (double)r->inward_other / (double)r->valid : 0.0);
    cli_json_num(&j, "compare_mean_deg", r->mean_compare);
    cli_json_num(&j, "compare_max_deg", r->max_compare);
    if (o->bake_path) {
        cli_json_object(&j, "bake");
        cli_json_str(&j, "path", o->bake_path);
        cli_json_int(&j, "width", o->bake.width);
        cli_json_int(&j, "height", o->bake.height);
        cli_json_int(&j, "covered_texels", (long long)r->bake.covered);
        cli_json_int(&j, "padded_texels", (long long)r->bake.padded);
        cli_json_int(&j, "skipped_triangles", (long long)r->bake.skipped);
        cli_json_int(&j, "uv_islands", (long long)r->bake.islands);
        cli_json_int(&j, "overlap_texels", (long long)r->bake.overlap_texels);
        cli_json_ints(&j, "tiles", r->bake.tile_udim, (int)r->bake.tiles);
        if (o->from) {
            cli_json_str(&j, "from", o->from);
            cli_json_int(&j, "high_triangles", (long long)r->high_triangle_count);
            cli_json_num(&j, "ray_distance", r->ray_distance);
            cli_json_int(&j, "ray_samples", (long long)r->bake.ray_samples);
            cli_json_int(&j, "ray_misses", (long long)r->bake.ray_misses);
            cli_json_int(&j, "miss_texels", (long long)r->bake.miss_texels);
            cli_json_int(&j, "partial_miss_texels", (long long)r->bake.partial_miss_texels);
            cli_json_bool(&j, "detail", o->detail);
            cli_json_num(&j, "bvh_build_s", r->t_bvh);
        }
        cli_json_str(&j, "filter", o->bake.filter == MESH_FILTER_NONE ? "none" : "footprint");
        if (o->bake.samples > 0)
            cli_json_int(&j, "samples", o->bake.samples);
        else
            cli_json_str(&j, "samples", "auto");
        cli_json_int(&j, "padding", o->bake.padding);
        cli_json_num(&j, "texel_size", r->bake.texel_size * r->unit);
        cli_json_int(&j, "triangles_outside_unit_square", (long long)r->bake.outside_triangles);
        cli_json_ints(&j, "other_tiles", r->bake.outside_tiles,
                      (int)(r->bake.outside_tile_count < 8 ? r->bake.outside_tile_count : 8));
        cli_json_close(&j);
    }
    cli_json_object(&j, "scale");
    cli_json_str(&j, "units", o->units == MESH_UNITS_FILE ? "file" : "model");
    cli_json_num(&j, "model_radius", r->model_radius);
    cli_json_num(&j, "coarsest_feature", r->coarsest_feature);
    cli_json_num(&j, "finest_feature", r->finest_feature);
    cli_json_close(&j);
    if (r->output_format && (r->gltf_materials || r->gltf_bumped_normals || r->gltf_map)) {
        cli_json_object(&j, "gltf");
        cli_json_bool(&j, "bumped_normals", r->gltf_bumped_normals);
        cli_json_int(&j, "meshes", (long long)r->gltf_meshes);
        cli_json_bool(&j, "nodes_merged", r->gltf_merged);
        cli_json_int(&j, "materials", (long long)r->gltf_materials);
        cli_json_int(&j, "base_color_textures", (long long)r->gltf_textures);
        cli_json_int(&j, "base_color_textures_left_out", (long long)r->gltf_textures_dropped);
        cli_json_bool(&j, "normal_texture", r->gltf_map != 0);
        cli_json_str(&j, "note", r->gltf_map_note);
        cli_json_close(&j);
    }
    cli_json_object(&j, "timing_s");
    cli_json_num(&j, "load", r->t_load);
    cli_json_num(&j, "normals", r->t_normals);
    cli_json_num(&j, "perturb", r->t_perturb);
    cli_json_num(&j, "bake", r->t_bake);
    cli_json_num(&j, "write", r->t_write);
    cli_json_close(&j);
    cli_json_object(&j, "parameters");
    cli_json_str(&j, "input", o->input);
    cli_json_str(&j, "output", o->output);
    cli_json_str(&j, "method", cli_method_name(o->method));
    cli_json_int(&j, "threads", r->threads);
    cli_json_height(&j, "height", o->height);
    cli_json_close(&j);
    cli_json_end(&j);
}

/* The summary as text: the mesh, normals, perturbation, bake, scale, glTF
 * and times. */
static void print_text(FILE *fp, const bgt_mesh_opts *o, int units, const bgt_mesh_result *r)
{
    const char *in_path = o->input, *out_path = o->output, *bake_path = o->bake_path;
    const bg_perturb_method method = o->method;
    const mesh_bake_opts bake = o->bake;
    fprintf(fp, "mesh: %s: %zu vertices, %zu triangles (%zu scene meshes", in_path,
            r->vertex_count, r->triangle_count, r->mesh_count);
    if (r->dropped_primitives)
        fprintf(fp, ", %zu points/lines dropped", r->dropped_primitives);
    fprintf(fp, ")\n");
    fprintf(fp, "normals: %s; %zu vertices without a normal (sentinel 0,0,0)\n",
            r->file_normals ? "from the file" : "angle-weighted (computed)", r->no_normal);
    fprintf(fp, "degenerate: %zu unusable triangles (zero area, repeated index or NaN/Inf "
                "corner), %zu vertices with NaN/Inf position\n",
            r->unusable_triangles, r->nonfinite_positions);
    fprintf(fp, "height: mean %.6g over %zu vertices (%zu non-finite)\n", r->mean_height,
            r->finite_height, r->nonfinite_height);
    fprintf(fp, "perturbation (%s): mean %.4f deg, max %.4f deg\n", cli_method_name(method),
            r->mean_angle, r->max_angle);
    double valid = r->valid ? (double)r->valid : 1.0;
    fprintf(fp, "inward (dot(n', n) <= 0): surfgrad %zu (%.4f%%), %s %zu (%.4f%%)\n",
            r->inward_surf, 100.0 * (double)r->inward_surf / valid,
            method == BG_PERTURB_SURFGRAD ? "additive" : cli_method_name(method),
            r->inward_other, 100.0 * (double)r->inward_other / valid);
    fprintf(fp, "surfgrad vs additive: mean %.4f deg, max %.4f deg\n", r->mean_compare,
            r->max_compare);
    if (o->from)
        fprintf(fp, "high-poly: %s: %zu vertices, %zu triangles (%zu usable, %zu scene "
                    "meshes), normals %s; Embree BVH %.3f s; rays %s%.4g file units; "
                    "%zu samples, %zu missed; %zu texels all missed (kept the low-poly "
                    "normal), %zu partly; detail: %s\n",
                o->from, r->high_vertex_count, r->high_triangle_count, r->high_usable,
                r->high_mesh_count, r->high_file_normals ? "from the file" : "angle-weighted",
                r->t_bvh, o->cage ? "from the cage toward IN and as far past it; unused: "
                                  : "both ways up to ",
                r->ray_distance, r->bake.ray_samples, r->bake.ray_misses, r->bake.miss_texels,
                r->bake.partial_miss_texels, o->detail ? "the height at the hit points" : "none");
    if (bake_path)
        fprintf(fp, "bake: %s %dx%d %s space, %zu texels covered, %zu padded, %zu "
                    "triangles skipped (degenerate or zero UV area)\n",
                bake_path, bake.width, bake.height,
                bake.space == MESH_BAKE_TANGENT ? "tangent" : "object", r->bake.covered,
                r->bake.padded, r->bake.skipped);
    fprintf(fp, "scale: %s; model radius %.6g file units, mean edge %.4g; height features "
                "from %.4g down to %.4g file units",
            r->unit == 1.0 && units == MESH_UNITS_FILE ? "--units file" : "--units model",
            r->model_radius, r->mean_edge, r->coarsest_feature, r->finest_feature);
    if (bake_path)
        fprintf(fp, "; a texel spans %.4g file units on the surface (mean)",
                r->bake.texel_size * r->unit);
    fprintf(fp, "\n");
    if (bake_path && bake.space == MESH_BAKE_TANGENT && bake.tangents == MESH_TANGENTS_FILE)
        fprintf(fp, "tangents: from the file, green %s\n", bake.green_down ? "-y" : "+y");
    else if (bake_path && bake.space == MESH_BAKE_TANGENT)
        fprintf(fp, "tangents: mikkTSpace, %zu welded vertices, %zu fans, %zu degenerate and "
                    "%zu zero-UV-area triangles, %zu corners without a fan; green %s\n",
                r->bake.mikk.welded_vertices, r->bake.mikk.fans, r->bake.mikk.degenerate,
                r->bake.mikk.zero_uv_area, r->bake.mikk.unreached,
                bake.green_down ? "-y" : "+y");
    if (bake_path)
        fprintf(fp, "UV islands: %zu, %zu of them in overlaps (%zu texels strictly inside two "
                    "or more triangles; the later triangle wins)%s\n",
                r->bake.islands, r->bake.overlap_islands, r->bake.overlap_texels,
                r->bake.overlap_islands ? " WARNING: overlapping UVs" : "");
    if (bake_path && strstr(bake_path, MESH_UDIM_TOKEN)) {
        fprintf(fp, "%zu tiles written:", r->bake.tiles);
        for (size_t k = 0; k < r->bake.tiles; k++)
            fprintf(fp, "%s %d", k ? "," : "", r->bake.tile_udim[k]);
        fprintf(fp, "\n");
    }
    if (out_path)
        fprintf(fp, "wrote %s (%s)\n", out_path,
                r->output_format);
    char merged[96] = "";
    if (r->gltf_merged)
        snprintf(merged, sizeof merged,
                 " (the scene has more than %d nodes with triangles: merged into one)",
                 BG_MESH_MAX_PARTS);
    if (out_path && r->gltf_materials + r->gltf_bumped_normals + r->gltf_map)
        fprintf(fp, "glTF: %s normals, %zu mesh%s%s, %zu materials, %zu base colour textures "
                    "kept (%zu left out: not PNG/JPEG or not found), normalTexture: %s\n",
                r->gltf_bumped_normals ? "bumped" : "original", r->gltf_meshes,
                r->gltf_meshes == 1 ? "" : "es",
                merged,
                r->gltf_materials,
                r->gltf_textures, r->gltf_textures_dropped,
                r->gltf_map == 2 ? "the map as an embedded 8-bit PNG"
                : r->gltf_map    ? "the map"
                                : "none");
    if (out_path && r->gltf_map_note)
        fprintf(fp, "glTF: %s\n", r->gltf_map_note);
    fprintf(fp, "time: load %.3f s, normals %.3f s, height+perturb %.3f s (%d threads), "
                "bake %.3f s, write %.3f s\n",
            r->t_load, r->t_normals, r->t_perturb, r->threads, r->t_bake, r->t_write);
}

typedef struct mesh_args {
    const char *bake_path, *format;
    int method, compare, ascii, recompute, json, threads, join, bake_depth, gltf_normals, units;
    mesh_bake_opts bake;
    bgt_height h;
    const char *from, *cage, *height_map, *miss_map; /* high-poly to low-poly */
    double ray_distance;
} mesh_args;

_Static_assert(sizeof(mesh_bake_space) == sizeof(int), "mesh_bake_space is stored as int");
_Static_assert(sizeof(mesh_tangent_source) == sizeof(int), "mesh_tangent_source is stored as int");
_Static_assert(sizeof(mesh_bake_filter) == sizeof(int), "mesh_bake_filter is stored as int");

static const char *const join_choices[] = {"auto", "always", "never", NULL};
static const int join_values[] = {BG_MESH_JOIN_AUTO, BG_MESH_JOIN_ALWAYS, BG_MESH_JOIN_NEVER};
static const char *const space_choices[] = {"tangent", "object", NULL};
static const int space_values[] = {MESH_BAKE_TANGENT, MESH_BAKE_OBJECT};
static const char *const tangents_choices[] = {"mikktspace", "file", NULL};
static const int tangents_values[] = {MESH_TANGENTS_MIKK, MESH_TANGENTS_FILE};
static const char *const gltf_normals_choices[] = {"auto", "original", "bumped", NULL};
static const int gltf_normals_values[] = {MESH_GLTF_NORMALS_AUTO, MESH_GLTF_NORMALS_ORIGINAL,
                                          MESH_GLTF_NORMALS_BUMPED};
static const char *const filter_choices[] = {"footprint", "none", NULL};
static const int filter_values[] = {MESH_FILTER_FOOTPRINT, MESH_FILTER_NONE};
static const char *const units_choices[] = {"model", "file", NULL};
static const int units_values[] = {MESH_UNITS_MODEL, MESH_UNITS_FILE};
static const char *const y_choices[] = {"+y", "-y", NULL};
static const char *const depth_choices[] = {"8", "16", "half", "float", NULL};
static const int depth_values[] = {BG_PIXEL_U8, BG_PIXEL_U16, BG_PIXEL_HALF, BG_PIXEL_F32};

static void mesh_defaults(void *p)
{
    mesh_args *a = p;
    memset(a, 0, sizeof *a);
    a->method = BG_PERTURB_SURFGRAD;
    a->join = BG_MESH_JOIN_AUTO;
    a->bake_depth = -1; /* half for .exr, else 8 bits */
    a->bake.space = MESH_BAKE_TANGENT;
    a->bake.padding = 16;
    a->bake.samples = 0;
    a->bake.tangents = MESH_TANGENTS_MIKK;
    bgt_height_init(&a->h);
}

/* --size N or WxH; the field is the mesh_bake_opts. */
static int parse_size(const char *cmd, const char *opt, char *text, void *field)
{
    mesh_bake_opts *b = field;
    return cli_parse_size(cmd, opt, text, 1, 1, "texels", &b->width, &b->height);
}

#define A(m) offsetof(mesh_args, m)
static const cli_opt mesh_opts_table[] = {
    {.name = "method", .kind = CLI_KIND_CHOICE, .offset = A(method), .metavar = "M",
     .help = "surfgrad, additive or additive-perlin", .choices = cli_method_choices,
     .choice_values = cli_method_values},
    {.name = "compare", .kind = CLI_KIND_FLAG, .offset = A(compare),
     .help = "add compare_deg: angle between the surfgrad and the additive normal, in degrees"},
    {.name = "recompute-normals", .kind = CLI_KIND_FLAG, .offset = A(recompute),
     .help = "ignore normals in IN; use angle-weighted vertex normals (the default when IN has "
             "none)"},
    {.name = "join", .kind = CLI_KIND_CHOICE, .offset = A(join), .metavar = "MODE",
     .help = "auto (keep PLY vertices one for one, merge identical vertices of other formats), "
             "always, never; a mesh with a NaN/Inf position is never merged",
     .choices = join_choices, .choice_values = join_values},
    {.name = "units", .kind = CLI_KIND_CHOICE, .offset = A(units), .metavar = "U",
     .help = "units of --frequency and --amplitude: model (the default: per model radius, the "
             "model scaled into the unit sphere about its bounding box's centre, as render "
             "--mesh does; the same bake at any scale) or file (the file's own units)",
     .choices = units_choices, .choice_values = units_values},
    {.name = "gltf-normals", .kind = CLI_KIND_CHOICE, .offset = A(gltf_normals),
     .metavar = "N", .help = "NORMAL of OUT.glb/.gltf: auto (the original normals when a map is "
                             "baked, so the map bumps once; else the bumped ones), original, or "
                             "bumped (then no material uses the map)",
     .choices = gltf_normals_choices, .choice_values = gltf_normals_values},
    {.name = "ascii", .kind = CLI_KIND_FLAG, .offset = A(ascii),
     .help = "ASCII PLY instead of binary little-endian"},
    CLI_OPT_INCLUDE(A(threads), cli_threads_opts, NULL),
    {.name = "json", .kind = CLI_KIND_FLAG, .offset = A(json),
     .help = "the summary as one JSON object on stdout"},
    CLI_OPT_END,
};
static const cli_opt mesh_bake_table[] = {
    {.name = "bake-normal-map", .kind = CLI_KIND_STRING, .offset = A(bake_path),
     .metavar = "FILE", .help = "write a normal map (format from the extension, through "
                                "OpenImageIO; OUT then optional). FILE with `<UDIM>`: one map "
                                "per UDIM tile (1001 + u + 10 v, at most 100 tiles; `--size` is "
                                "per tile); - for standard output (--format)",
     .flags = CLI_FILE},
    {.name = "format", .kind = CLI_KIND_STRING, .offset = A(format), .metavar = "FMT",
     .help = "the format of --bake-normal-map - (standard output; the summary then goes to "
             "stderr): png (the default), exr, tif, ... (any OpenImageIO writes to memory); "
             "with a map file the extension decides, and a --format that disagrees with it is "
             "an error",
     .flags = CLI_NO_DEFAULT},
    {.name = "size", .kind = CLI_KIND_CUSTOM, .offset = A(bake), .metavar = "N|WxH",
     .help = "map size in texels (required with the bake)", .parse = parse_size},
    {.name = "space", .kind = CLI_KIND_CHOICE, .offset = A(bake.space), .metavar = "S",
     .help = "tangent (mikkTSpace convention) or object", .choices = space_choices,
     .choice_values = space_values},
    {.name = "filter", .kind = CLI_KIND_CHOICE, .offset = A(bake.filter), .metavar = "F",
     .help = "footprint (the default: each texel's height keeps only the octaves its "
             "footprint on the surface can show, from its triangle's UV Jacobian, as render "
             "does; a --height-grid is not filtered) or none (every octave at the sample point)",
     .choices = filter_choices, .choice_values = filter_values},
    {.name = "samples", .kind = CLI_KIND_INT, .offset = A(bake.samples), .metavar = "N",
     .help = "N x N stratified samples per texel, each with its share of the footprint, "
             "averaged (1 = the texel centre alone; more for a --height-grid or a smoother "
             "map). Default: 2 x 2, and 7 per texel on triangles where an octave has cells "
             "narrower than 4 texels",
     .lo = 1, .hi = MESH_MAX_SAMPLES},
    {.name = "tile", .kind = CLI_KIND_INT, .offset = A(bake.only_tile), .metavar = "UDIM",
     .help = "with a <UDIM> map name: bake only this tile (1001..1999), texel for texel the "
             "same as the full bake's tile; one job per tile on a farm (docs/DISTRIBUTED.md)",
     .lo = 1001, .hi = 1999},
    {.name = "padding", .kind = CLI_KIND_INT, .offset = A(bake.padding), .metavar = "P",
     .help = "dilate the baked texels into empty ones P times (default 16, as Blender); an "
             "empty texel takes the normals of one UV island, never a mix of two",
     .lo = 0, .hi = 4096},
    {.name = "bake-depth", .kind = CLI_KIND_CHOICE, .offset = A(bake_depth), .metavar = "D",
     .help = "8, 16, half or float (default: half for .exr, else 8)", .flags = CLI_NO_DEFAULT,
     .choices = depth_choices, .choice_values = depth_values},
    {.name = "tangents", .kind = CLI_KIND_CHOICE, .offset = A(bake.tangents), .metavar = "T",
     .help = "tangent frame of --space tangent: mikktspace (mikkTSpace of the vertex normals "
             "and UVs, what Blender, Unity, Unreal, Substance and glTF viewers rebuild) or file "
             "(the tangents stored in IN, e.g. glTF TANGENT)",
     .choices = tangents_choices, .choice_values = tangents_values},
    {.name = "normal-map-y", .kind = CLI_KIND_CHOICE, .offset = A(bake.green_down),
     .metavar = "Y", .help = "+y (OpenGL, Blender, glTF, Unity) or -y (DirectX, Unreal): the "
                             "green channel's direction",
     .choices = y_choices},
    CLI_OPT_END,
};
static const cli_opt mesh_high_table[] = {
    {.name = "from", .kind = CLI_KIND_STRING, .offset = A(from), .metavar = "HIGH",
     .help = "bake the normals of the high-poly mesh HIGH (any format assimp reads; UVs not "
             "needed; several meshes are one) onto IN's UVs: from each sample's point on IN "
             "rays along IN's normal, both ways, up to --ray-distance; the nearest hit's "
             "interpolated normal is encoded in IN's frame (a sample that misses keeps IN's "
             "normal). A height option that differs from its default adds that height's "
             "detail at the hit point; without one nothing is added",
     .flags = CLI_FILE},
    {.name = "cage", .kind = CLI_KIND_STRING, .offset = A(cage), .metavar = "CAGE",
     .help = "cast from the matching point of CAGE (IN's triangles, in IN's order, with the "
             "vertices moved outward) toward IN, as far again past it, instead of both ways",
     .flags = CLI_FILE},
    {.name = "ray-distance", .kind = CLI_KIND_DOUBLE, .offset = A(ray_distance), .metavar = "D",
     .help = "how far the rays reach, front and back, in the units of --units (default 0.1: a "
             "tenth of IN's bounding-sphere radius)",
     .flags = CLI_GT_LO | CLI_NO_DEFAULT, .lo = 0},
    {.name = "bake-height-map", .kind = CLI_KIND_STRING, .offset = A(height_map),
     .metavar = "FILE", .help = "also write the signed distance from IN to HIGH along the rays "
                                "(file units, + outside), a float .exr or .tif (mean over the "
                                "hits of a texel, 0 where all missed)",
     .flags = CLI_FILE},
    {.name = "miss-map", .kind = CLI_KIND_STRING, .offset = A(miss_map), .metavar = "FILE",
     .help = "also write the fraction of each texel's samples whose rays missed HIGH (1: the "
             "texel kept IN's normal)",
     .flags = CLI_FILE},
    CLI_OPT_END,
};
static const cli_opt mesh_table[] = {
    CLI_OPT_INCLUDE(0, mesh_opts_table, NULL),
    CLI_OPT_INCLUDE(0, mesh_bake_table, "Normal-map bake (needs UV set 0):"),
    CLI_OPT_INCLUDE(0, mesh_high_table, "High-poly to low-poly (IN is the low-poly mesh):"),
    CLI_OPT_INCLUDE(A(h), cli_height_opts, cli_height_heading),
    CLI_OPT_END,
};
#undef A

CLI_SPEC(mesh,
    .summary = "bump the vertex normals of a mesh file (OBJ, PLY, STL, glTF, ...) or bake a "
               "normal map",
    .usage = "[options] IN [OUT.ply|OUT.glb|OUT.gltf|OUT.obj]",
    .about =
        "Bump the vertex normals of a mesh (OBJ, PLY, OFF, STL, glTF, ... through\n"
        "assimp) with a solid height field h, and/or bake a normal map:\n"
        "  surfgrad   n' = normalize(n - grad_S h), grad_S h = g - n (n.g)\n"
        "             (Mikkelsen 2010, eq. 2 and 4; never faces inward)\n"
        "  additive   n' = normalize(n - g)   (Perlin's rule, for comparison)\n"
        "No texture coordinates are needed for OUT.ply; the bake needs UV set 0.\n"
        "\n"
        "OUT.ply (binary little-endian unless --ascii), per vertex: x y z, nx ny nz\n"
        "(perturbed unit normal), ox oy oz (original unit normal), height, then\n"
        "compare_deg with --compare, then s t if IN has UVs; faces as triangles.\n"
        "A vertex without a valid normal has (0,0,0) in nx..nz and ox..oz.\n"
        "OUT.glb / OUT.gltf (glTF 2.0), to load in a viewer: POSITION, NORMAL,\n"
        "TEXCOORD_0 and TANGENT (VEC4 with the sign) if IN has UVs; one mesh per node\n"
        "of IN, under a node of its name (the hierarchy flattened: node transforms are\n"
        "in the vertices), with one primitive per material of IN (its name and\n"
        "PNG/JPEG base colour texture kept). With a\n"
        "tangent-space map baked, NORMAL holds the ORIGINAL normals, TANGENT the frame\n"
        "the map was encoded in, and every material's normalTexture is the map\n"
        "(embedded in .glb; referenced beside .gltf, or embedded as an 8-bit PNG when\n"
        "the map is not PNG/JPEG; with <UDIM>, one material per material and tile):\n"
        "the viewer applies the bump once. Without a map,\n"
        "NORMAL holds the bumped normals (and TANGENT their mikkTSpace frame);\n"
        "--gltf-normals bumped asks for them with a map too (no material uses it then).\n"
        "OUT.obj: positions, perturbed normals, UVs. Other extensions: refused.\n"
        "OUT \"-\" writes the PLY to standard output (the summary then goes to stderr).\n",
    .opts = mesh_table,
    .more = "UV islands that overlap in the map are counted in the summary (the later\n"
            "triangle wins a shared texel); that is not an error.\n"
            "\n"
            "Outputs are written to temporary files and renamed into place only when\n"
            "everything succeeded. Exit status: 0 success, 1 I/O failure or out of\n"
            "memory, 2 bad input (missing, corrupt or empty mesh; bake without UVs;\n"
            "nothing to bake) or usage. Warnings (stderr, also with --quiet): UVs\n"
            "outside the unit square without <UDIM>, a bump finer than a texel or\n"
            "coarser than the model.\n"
            "\n"
            "Examples:\n"
            "  bumpgrad mesh --compare model.obj bumped.ply\n"
            "  bumpgrad mesh --function fbm --frequency 8 --amplitude 0.02 \\\n"
            "      --bake-normal-map normals.png --size 1024 model.ply\n",
    .max_positional = 2,
);

static int run_mesh(void *args, const char *const *pos, int npos)
{
    const char *cmd = "mesh";
    mesh_args a = *(mesh_args *)args;
    const char *in_path = npos > 0 ? pos[0] : NULL, *out_path = npos > 1 ? pos[1] : NULL;
    const char *bake_path = a.bake_path;
    bg_perturb_method method = (bg_perturb_method)a.method;
    const mesh_bake_opts bake = a.bake;
    int ascii = a.ascii;
    if (!in_path)
        return cli_usage_error(cmd, "missing the input mesh (see bumpgrad mesh --help)");
    if (!out_path && !bake_path)
        return cli_usage_error(cmd, "missing OUT.ply (or --bake-normal-map FILE)");
    if (bake_path && bake.width == 0)
        return cli_usage_error(cmd, "--bake-normal-map needs --size N (or WxH)");
    if (a.json && ((bake_path && strcmp(bake_path, "-") == 0) ||
                   (out_path && strcmp(out_path, "-") == 0)))
        return cli_usage_error(cmd, "--json writes to standard output: give the outputs file "
                                    "names");
    if (bake.only_tile && (!bake_path || out_path))
        return cli_usage_error(cmd, "--tile bakes one tile of --bake-normal-map NAME.<UDIM>.EXT "
                                    "and writes no mesh (the mesh output needs every tile)");
    if (!bake_path && bake.width != 0)
        return cli_usage_error(cmd, "--size is for --bake-normal-map");
    bgt_mesh_opts opts = {.input = in_path, .output = out_path, .bake_path = bake_path,
                          .height = &a.h, .method = method, .compare = a.compare, .ascii = ascii,
                          .recompute_normals = a.recompute, .join = (unsigned)a.join,
                          .threads = a.threads, .bake = bake, .bake_depth = a.bake_depth,
                          .bake_format = a.format, .gltf_normals = a.gltf_normals,
                          .units = a.units, .from = a.from, .cage = a.cage,
                          .ray_distance = a.ray_distance, .height_map = a.height_map,
                          .miss_map = a.miss_map};
    {
        /* --from adds the height's detail only when a height option changed it */
        bgt_height d;
        bgt_height_init(&d);
        opts.detail = a.h.grid_path != NULL || memcmp(&a.h.h, &d.h, sizeof d.h) != 0;
    }
    cli_progress prog;
    bgt_progress sink = cli_progress_sink(&prog);
    opts.progress = &sink;
    bgt_mesh_result r;
    bgt_err err;
    bg_status st = bgt_mesh_run(&opts, &r, &err);
    if (st != BG_OK)
        return cli_report(cmd, st, &err);
    /* Nothing silent: what the map leaves out, and a bump the map or the
     * model cannot show (on stderr, also with --quiet). */
    if (bake_path && r.bake.outside_triangles) {
        char tiles[128] = "";
        size_t n = r.bake.outside_tile_count < 8 ? r.bake.outside_tile_count : 8;
        for (size_t k = 0; k < n; k++)
            snprintf(tiles + strlen(tiles), sizeof tiles - strlen(tiles), "%s%d", k ? ", " : "",
                     r.bake.outside_tiles[k]);
        cli_warn(cmd, "%zu triangles have UVs wholly outside the unit square (UDIM tile 1001) "
                      "and are not in the map; the UVs reach %zu other tile%s (%s%s); name the "
                      "map with <UDIM> (e.g. n.<UDIM>.png) to bake every tile",
                 r.bake.outside_triangles, r.bake.outside_tile_count,
                 r.bake.outside_tile_count == 1 ? "" : "s", n ? tiles : "outside 1001..1999",
                 r.bake.outside_tile_count > n ? ", ..." : "");
    }
    int shows_height = !a.from || opts.detail;
    if (shows_height && bake_path && r.finest_feature > 0 && r.finest_feature < r.bake.texel_size * r.unit)
        cli_warn(cmd, "the finest bump feature (%.4g file units) is smaller than a texel "
                      "(%.4g on the surface): the map cannot hold it%s; raise --size, or lower "
                      "--octaves or --frequency",
                 r.finest_feature, r.bake.texel_size * r.unit,
                 a.from ? " (it aliases: a high-poly bake does not filter the detail; raise "
                          "--samples)"
                 : bake.filter == MESH_FILTER_FOOTPRINT ? " (the footprint filter fades it out)"
                                                        : " (it aliases: --filter none)");
    if (shows_height && r.coarsest_feature > 0 && r.model_radius > 0 && r.coarsest_feature > 4.0 * r.model_radius)
        cli_warn(cmd, "the bump is coarser than the model: its largest feature (%.4g file units) "
                      "exceeds the model's size (diameter %.4g); raise --frequency",
                 r.coarsest_feature, 2.0 * r.model_radius);
    if (a.from && r.bake.miss_texels)
        cli_warn(cmd, "%zu of %zu texels: every ray missed %s within %.4g file units; they keep "
                      "the low-poly normal (raise --ray-distance, or give a --cage)",
                 r.bake.miss_texels, r.bake.covered, a.from, r.ray_distance);
    if (a.json) {
        print_json(&opts, &r);
        return CLI_OK;
    }
    if (!cli_quiet()) {
        /* a stream on stdout (the PLY or the map) keeps it for the data */
        FILE *fp = (out_path && strcmp(out_path, "-") == 0) ||
                           (bake_path && strcmp(bake_path, "-") == 0)
                       ? stderr
                       : stdout;
        print_text(fp, &opts, a.units, &r);
    }
    return CLI_OK;
}
