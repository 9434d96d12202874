/* SPDX-License-Identifier: MIT */
/* `bumpgrad mesh`: bump a real mesh (any format assimp reads) with a solid
 * height field, per vertex into a PLY and/or baked into a normal map. This
 * file parses the options, runs the tool (bgt_mesh_run, src/tools/mesh/
 * mesh_job.c) and prints its summary. Format, conventions and measurements:
 * docs/MESH.md. */
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "json.h"
#include "mesh/mesh_tool.h"

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

static void mesh_help(FILE *fp)
{
    fprintf(fp,
            "Usage: bumpgrad mesh [options] IN [OUT.ply|OUT.glb|OUT.gltf|OUT.obj]\n"
            "\n"
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
            "OUT.glb / OUT.gltf (glTF 2.0): POSITION, NORMAL (perturbed), TEXCOORD_0 and\n"
            "TANGENT (mikkTSpace of the perturbed normals, VEC4 with the sign) if IN has\n"
            "UVs. OUT.obj: positions, perturbed normals, UVs. Other extensions: refused.\n"
            "\n"
            "Options:\n"
            "  --method M            surfgrad (default), additive or additive-perlin\n"
            "  --compare             add compare_deg: angle between the surfgrad and the\n"
            "                        additive normal, in degrees\n"
            "  --recompute-normals   ignore normals in IN; use angle-weighted vertex\n"
            "                        normals (the default when IN has none)\n"
            "  --join MODE           auto (default: keep PLY vertices one for one, merge\n"
            "                        identical vertices of other formats), always, never;\n"
            "                        a mesh with a NaN/Inf position is never merged\n"
            "  --ascii               ASCII PLY instead of binary little-endian\n"
            "  --threads N           worker threads (default: all cores)\n"
            "  --quiet               no summary\n"
            "  --json                the summary as one JSON object on stdout\n"
            "  -h, --help            this help\n"
            "\n"
            "Normal-map bake (needs UV set 0):\n"
            "  --bake-normal-map FILE  write a normal map (format from the extension,\n"
            "                        through OpenImageIO; OUT.ply then optional)\n"
            "  --size N | WxH        map size in texels (required with the bake)\n"
            "  --space S             tangent (default; mikkTSpace convention) or object\n"
            "  --padding P           dilate the baked texels into empty ones P times\n"
            "                        (default 4)\n"
            "  --bake-depth D        8, 16, half or float (default: half for .exr, else 8)\n"
            "  --tangents T          tangent frame of --space tangent: mikktspace (default;\n"
            "                        mikkTSpace of the vertex normals and UVs, what Blender,\n"
            "                        Unity, Unreal, Substance and glTF viewers rebuild) or\n"
            "                        file (the tangents stored in IN, e.g. glTF TANGENT)\n"
            "  --normal-map-y Y      +y (default; OpenGL, Blender, glTF, Unity) or -y\n"
            "                        (DirectX, Unreal): the green channel's direction\n"
            "UV islands that overlap in the map are counted in the summary (the later\n"
            "triangle wins a shared texel); that is not an error.\n");
    cli_height_help(fp);
    fprintf(fp,
            "\n"
            "Outputs are written to temporary files and renamed into place only when\n"
            "everything succeeded. Exit status: 0 success, 1 I/O failure or out of\n"
            "memory, 2 bad input (missing, corrupt or empty mesh; bake without UVs) or\n"
            "usage.\n"
            "\n"
            "Examples:\n"
            "  bumpgrad mesh --compare model.obj bumped.ply\n"
            "  bumpgrad mesh --function fbm --frequency 8 --amplitude 0.02 \\\n"
            "      --bake-normal-map normals.png --size 1024 model.ply\n");
}

static int parse_size(const char *cmd, const char *text, int *w, int *h)
{
    char *end;
    long a = strtol(text, &end, 10), b = a;
    if (end != text && (*end == 'x' || *end == 'X')) {
        const char *s = end + 1;
        b = strtol(s, &end, 10);
        if (end == s)
            b = 0;
    }
    if (end == text || *end || a < 1 || b < 1 || a > 16384 || b > 16384)
        return cli_usage_error(cmd, "--size: expected N or WxH with 1..16384 texels, got \"%s\"",
                               text);
    *w = (int)a;
    *h = (int)b;
    return 0;
}

int cmd_mesh(int argc, char **argv)
{
    const char *cmd = "mesh", *in_path = NULL, *out_path = NULL, *bake_path = NULL, *v;
    bg_perturb_method method = BG_PERTURB_SURFGRAD;
    int compare = 0, ascii = 0, recompute = 0, quiet = 0, json = 0, threads = 0, rc;
    unsigned join = BG_MESH_JOIN_AUTO;
    mesh_bake_opts bake = {.width = 0, .height = 0, .space = MESH_BAKE_TANGENT, .padding = 4};
    int bake_depth = -1;
    bake.tangents = MESH_TANGENTS_MIKK;
    bake.green_down = 0;
    long l;
    bgt_height h;
    bgt_height_init(&h);
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i];
        if (strcmp(o, "-h") == 0 || strcmp(o, "--help") == 0) {
            mesh_help(stdout);
            return CLI_OK;
        } else if (strcmp(o, "--method") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)))
                return rc;
            if ((rc = cli_parse_method(cmd, o, v, &method)))
                return rc;
        } else if (strcmp(o, "--compare") == 0) {
            compare = 1;
        } else if (strcmp(o, "--ascii") == 0) {
            ascii = 1;
        } else if (strcmp(o, "--recompute-normals") == 0) {
            recompute = 1;
        } else if (strcmp(o, "--quiet") == 0) {
            quiet = 1;
        } else if (strcmp(o, "--json") == 0) {
            json = 1;
        } else if (strcmp(o, "--join") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)))
                return rc;
            if (strcmp(v, "auto") == 0)
                join = BG_MESH_JOIN_AUTO;
            else if (strcmp(v, "always") == 0)
                join = BG_MESH_JOIN_ALWAYS;
            else if (strcmp(v, "never") == 0)
                join = BG_MESH_JOIN_NEVER;
            else
                return cli_usage_error(cmd, "--join: expected auto, always or never, got \"%s\"", v);
        } else if (strcmp(o, "--threads") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)) ||
                (rc = cli_parse_int(cmd, o, v, 0, 1024, &l)))
                return rc;
            threads = (int)l;
        } else if (strcmp(o, "--bake-normal-map") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &bake_path)))
                return rc;
        } else if (strcmp(o, "--size") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)) ||
                (rc = parse_size(cmd, v, &bake.width, &bake.height)))
                return rc;
        } else if (strcmp(o, "--space") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)))
                return rc;
            if (strcmp(v, "tangent") == 0)
                bake.space = MESH_BAKE_TANGENT;
            else if (strcmp(v, "object") == 0)
                bake.space = MESH_BAKE_OBJECT;
            else
                return cli_usage_error(cmd, "--space: expected tangent or object, got \"%s\"", v);
        } else if (strcmp(o, "--padding") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)) ||
                (rc = cli_parse_int(cmd, o, v, 0, 4096, &l)))
                return rc;
            bake.padding = (int)l;
        } else if (strcmp(o, "--tangents") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)))
                return rc;
            if (strcmp(v, "mikktspace") == 0)
                bake.tangents = MESH_TANGENTS_MIKK;
            else if (strcmp(v, "file") == 0)
                bake.tangents = MESH_TANGENTS_FILE;
            else
                return cli_usage_error(cmd, "--tangents: expected mikktspace or file, got \"%s\"",
                                       v);
        } else if (strcmp(o, "--normal-map-y") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)))
                return rc;
            if (strcmp(v, "+y") == 0)
                bake.green_down = 0;
            else if (strcmp(v, "-y") == 0)
                bake.green_down = 1;
            else
                return cli_usage_error(cmd, "--normal-map-y: expected +y or -y, got \"%s\"", v);
        } else if (strcmp(o, "--bake-depth") == 0) {
            if ((rc = cli_need_value(cmd, argc, argv, &i, &v)))
                return rc;
            if (strcmp(v, "8") == 0)
                bake_depth = BG_PIXEL_U8;
            else if (strcmp(v, "16") == 0)
                bake_depth = BG_PIXEL_U16;
            else if (strcmp(v, "half") == 0)
                bake_depth = BG_PIXEL_HALF;
            else if (strcmp(v, "float") == 0)
                bake_depth = BG_PIXEL_F32;
            else
                return cli_usage_error(cmd, "--bake-depth: expected 8, 16, half or float, got \"%s\"",
                                       v);
        } else if (o[0] == '-' && o[1] != '\0') {
            int r = cli_height_option(cmd, &h, argc, argv, &i);
            if (r == CLI_USAGE)
                return r;
            if (r == 0)
                return cli_usage_error(cmd, "unknown option \"%s\" (see bumpgrad mesh --help)", o);
        } else if (!in_path) {
            in_path = o;
        } else if (!out_path) {
            out_path = o;
        } else {
            return cli_usage_error(cmd, "unexpected argument \"%s\" (IN and OUT.ply already given)",
                                   o);
        }
    }
    if (!in_path)
        return cli_usage_error(cmd, "missing the input mesh (see bumpgrad mesh --help)");
    if (!out_path && !bake_path)
        return cli_usage_error(cmd, "missing OUT.ply (or --bake-normal-map FILE)");
    if (bake_path && bake.width == 0)
        return cli_usage_error(cmd, "--bake-normal-map needs --size N (or WxH)");
    if (!bake_path && bake.width != 0)
        return cli_usage_error(cmd, "--size is for --bake-normal-map");
    bgt_mesh_opts opts = {.input = in_path, .output = out_path, .bake_path = bake_path,
                          .height = &h, .method = method, .compare = compare, .ascii = ascii,
                          .recompute_normals = recompute, .join = join, .threads = threads,
                          .bake = bake, .bake_depth = bake_depth};
    bgt_mesh_result r;
    bgt_err err;
    bg_status st = bgt_mesh_run(&opts, &r, &err);
    if (st != BG_OK)
        return cli_report(cmd, st, &err);
    if (json) {
        print_json(&opts, &r);
        return CLI_OK;
    }
    if (!quiet) {
        FILE *fp = out_path && strcmp(out_path, "-") == 0 ? stderr : stdout;
        fprintf(fp, "mesh: %s: %zu vertices, %zu triangles (%zu scene meshes", in_path,
                r.vertex_count, r.triangle_count, r.mesh_count);
        if (r.dropped_primitives)
            fprintf(fp, ", %zu points/lines dropped", r.dropped_primitives);
        fprintf(fp, ")\n");
        fprintf(fp, "normals: %s; %zu vertices without a normal (sentinel 0,0,0)\n",
                r.file_normals ? "from the file" : "angle-weighted (computed)", r.no_normal);
        fprintf(fp, "degenerate: %zu unusable triangles (zero area, repeated index or NaN/Inf "
                    "corner), %zu vertices with NaN/Inf position\n",
                r.unusable_triangles, r.nonfinite_positions);
        fprintf(fp, "height: mean %.6g over %zu vertices (%zu non-finite)\n", r.mean_height,
                r.finite_height, r.nonfinite_height);
        fprintf(fp, "perturbation (%s): mean %.4f deg, max %.4f deg\n", cli_method_name(method),
                r.mean_angle, r.max_angle);
        double valid = r.valid ? (double)r.valid : 1.0;
        fprintf(fp, "inward (dot(n', n) <= 0): surfgrad %zu (%.4f%%), %s %zu (%.4f%%)\n",
                r.inward_surf, 100.0 * (double)r.inward_surf / valid,
                method == BG_PERTURB_SURFGRAD ? "additive" : cli_method_name(method),
                r.inward_other, 100.0 * (double)r.inward_other / valid);
        fprintf(fp, "surfgrad vs additive: mean %.4f deg, max %.4f deg\n", r.mean_compare,
                r.max_compare);
        if (bake_path)
            fprintf(fp, "bake: %s %dx%d %s space, %zu texels covered, %zu padded, %zu "
                        "triangles skipped (degenerate or zero UV area)\n",
                    bake_path, bake.width, bake.height,
                    bake.space == MESH_BAKE_TANGENT ? "tangent" : "object", r.bake.covered,
                    r.bake.padded, r.bake.skipped);
        if (bake_path && bake.space == MESH_BAKE_TANGENT && bake.tangents == MESH_TANGENTS_FILE)
            fprintf(fp, "tangents: from the file, green %s\n", bake.green_down ? "-y" : "+y");
        else if (bake_path && bake.space == MESH_BAKE_TANGENT)
            fprintf(fp, "tangents: mikkTSpace, %zu welded vertices, %zu fans, %zu degenerate and "
                        "%zu zero-UV-area triangles, %zu corners without a fan; green %s\n",
                    r.bake.mikk.welded_vertices, r.bake.mikk.fans, r.bake.mikk.degenerate,
                    r.bake.mikk.zero_uv_area, r.bake.mikk.unreached,
                    bake.green_down ? "-y" : "+y");
        if (bake_path)
            fprintf(fp, "UV islands: %zu, %zu of them in overlaps (%zu texels strictly inside two "
                        "or more triangles; the later triangle wins)%s\n",
                    r.bake.islands, r.bake.overlap_islands, r.bake.overlap_texels,
                    r.bake.overlap_islands ? " WARNING: overlapping UVs" : "");
        if (out_path)
            fprintf(fp, "wrote %s (%s)\n", out_path,
                    mesh_out_format_name(mesh_out_format_of(out_path), ascii));
        fprintf(fp, "time: load %.3f s, normals %.3f s, height+perturb %.3f s (%d threads), "
                    "bake %.3f s, write %.3f s\n",
                r.t_load, r.t_normals, r.t_perturb, r.threads, r.t_bake, r.t_write);
    }
    return CLI_OK;
}
