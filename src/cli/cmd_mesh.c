/* SPDX-License-Identifier: MIT */
/* `bumpgrad mesh`: bump a real mesh (any format assimp reads) with a solid
 * height field. Mikkelsen 2010 (eq. 2 and 4, Listing 3): n' = normalize(n -
 * grad_S h) with grad_S h = g - n (n.g) needs only the position and the normal,
 * so meshes without texture coordinates are bumped as they are. Per vertex the
 * result goes to a PLY; with --bake-normal-map the same perturbation is
 * evaluated per texel of the UV layout and written as a normal map.
 * Format, conventions and measurements: docs/MESH.md. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include "mesh_tool.h"

/* Vertices per parallel chunk: large enough that the per-chunk scratch and the
 * chunk bookkeeping are noise, small enough to balance two to 64 workers. */
#define MESH_CHUNK 8192

static void mesh_help(FILE *fp)
{
    fprintf(fp,
            "Usage: bumpgrad mesh [options] IN [OUT.ply]\n"
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
            "  -h, --help            this help\n"
            "\n"
            "Normal-map bake (needs UV set 0):\n"
            "  --bake-normal-map FILE  write a normal map (format from the extension,\n"
            "                        through OpenImageIO; OUT.ply then optional)\n"
            "  --size N | WxH        map size in texels (required with the bake)\n"
            "  --space S             tangent (default; mikkTSpace convention) or object\n"
            "  --padding P           dilate the baked texels into empty ones P times\n"
            "                        (default 4)\n"
            "  --bake-depth D        8, 16, half or float (default: half for .exr, else 8)\n");
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

/* Per-chunk summary, reduced in chunk order so that the printed means do not
 * depend on which worker ran which chunk. */
typedef struct chunk_stats {
    size_t valid;        /* vertices with a normal */
    size_t inward_surf, inward_add;
    size_t nonfinite_height;
    double sum_angle, max_angle; /* n vs n' of the chosen method */
    double sum_cmp, max_cmp;     /* surfgrad vs additive */
    double sum_height;
    size_t finite_height;
} chunk_stats;

typedef struct vertex_job {
    const bg_mesh *m;
    const cli_height *h;
    bg_perturb_method method, other;
    const float *ox, *oy, *oz;
    float *nx, *ny, *nz, *height, *compare;
    chunk_stats *stats;
    atomic_int oom;
} vertex_job;

static int is_inward(const float *o, float x, float y, float z)
{
    double d = (double)o[0] * x + (double)o[1] * y + (double)o[2] * z;
    return !(d > 0);
}

static void vertex_chunk(void *ctx, size_t b, size_t e, int worker)
{
    (void)worker;
    vertex_job *j = ctx;
    size_t n = e - b;
    chunk_stats *st = &j->stats[b / MESH_CHUNK];
    memset(st, 0, sizeof *st);
    float *scratch = malloc(6 * n * sizeof *scratch);
    if (!scratch) {
        atomic_store(&j->oom, 1);
        return;
    }
    float *gx = scratch, *gy = scratch + n, *gz = scratch + 2 * n;
    float *ax = scratch + 3 * n, *ay = scratch + 4 * n, *az = scratch + 5 * n;
    /* One gradient evaluation serves both methods (the noise is the cost);
     * cli_height_gradient + bg_perturb_batch give the same bits as the fused
     * cli_height_perturb. */
    cli_height_gradient(j->h, j->m->px + b, j->m->py + b, j->m->pz + b, n, j->height + b, gx, gy,
                        gz);
    bg_perturb_batch(j->method, j->ox + b, j->oy + b, j->oz + b, gx, gy, gz, n, j->nx + b,
                     j->ny + b, j->nz + b);
    bg_perturb_batch(j->other, j->ox + b, j->oy + b, j->oz + b, gx, gy, gz, n, ax, ay, az);
    int main_is_surf = j->method == BG_PERTURB_SURFGRAD;
    for (size_t k = 0; k < n; k++) {
        size_t i = b + k;
        float hv = j->height[i];
        if (isfinite(hv)) {
            st->sum_height += hv;
            st->finite_height++;
        } else {
            st->nonfinite_height++;
        }
        float o[3] = {j->ox[i], j->oy[i], j->oz[i]};
        bg_vec3 ov = {o[0], o[1], o[2]};
        bg_vec3 mv = {j->nx[i], j->ny[i], j->nz[i]};
        bg_vec3 av = {ax[k], ay[k], az[k]};
        bg_vec3 sv = main_is_surf ? mv : av, dv = main_is_surf ? av : mv;
        if (o[0] == 0.0f && o[1] == 0.0f && o[2] == 0.0f) {
            if (j->compare)
                j->compare[i] = NAN; /* no normal, no angle */
            continue;
        }
        st->valid++;
        double a = bg_angle_deg(ov, mv);
        st->sum_angle += a;
        if (a > st->max_angle)
            st->max_angle = a;
        double c = bg_angle_deg(sv, dv);
        st->sum_cmp += c;
        if (c > st->max_cmp)
            st->max_cmp = c;
        if (j->compare)
            j->compare[i] = (float)c;
        st->inward_surf += (size_t)is_inward(o, sv.x, sv.y, sv.z);
        st->inward_add += (size_t)is_inward(o, dv.x, dv.y, dv.z);
    }
    free(scratch);
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

static int ends_with_ci(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix);
    if (k > n)
        return 0;
    for (size_t i = 0; i < k; i++) {
        char c = s[n - k + i];
        if (c >= 'A' && c <= 'Z')
            c = (char)(c - 'A' + 'a');
        if (c != suffix[i])
            return 0;
    }
    return 1;
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* An existing output that is not a regular file (and not a directory, which
 * the safe-output path reports as an error). */
static int is_device(const char *path)
{
    struct stat st;
    if (strcmp(path, "-") == 0 || stat(path, &st) != 0)
        return 0;
    return !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode);
}

/* Two names for one file: the same text, or both existing with one inode. */
static int same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (strcmp(a, b) == 0)
        return 1;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev &&
           sa.st_ino == sb.st_ino;
}

int cmd_mesh(int argc, char **argv)
{
    const char *cmd = "mesh", *in_path = NULL, *out_path = NULL, *bake_path = NULL, *v;
    bg_perturb_method method = BG_PERTURB_SURFGRAD;
    int compare = 0, ascii = 0, recompute = 0, quiet = 0, threads = 0, rc;
    unsigned join = BG_MESH_JOIN_AUTO;
    mesh_bake_opts bake = {.width = 0, .height = 0, .space = MESH_BAKE_TANGENT, .padding = 4};
    int bake_depth = -1;
    long l;
    cli_height h;
    cli_height_init(&h);
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
    /* One path for the PLY and the map: the later rename silently replaced
     * the other output (exit 0, the bake lost). */
    if (out_path && bake_path && same_file(out_path, bake_path))
        return cli_usage_error(cmd, "OUT.ply and --bake-normal-map name the same file %s",
                               out_path);
    /* A PLY written over a mesh of another format destroys the source (a PLY
     * input may be updated in place: same format, like heightmap IN = OUT). */
    if (out_path && strcmp(out_path, "-") != 0 && !ends_with_ci(in_path, ".ply") &&
        same_file(in_path, out_path))
        return cli_usage_error(cmd, "OUT.ply %s is the input mesh, which is not a PLY: writing "
                                    "it would replace the source",
                               out_path);
    if (bake_path && is_device(bake_path))
        /* The image writer renames a temporary file into place, which would
         * replace a device node such as /dev/null with a regular file. */
        return cli_usage_error(cmd, "--bake-normal-map: %s exists and is not a regular file",
                               bake_path);
    if ((rc = cli_height_open(cmd, &h)))
        return rc;
    if (threads == 0)
        threads = cli_threads_default();

    bg_mesh m;
    char err[512];
    double t0 = now_seconds();
    bg_status st = bg_mesh_load_ex(in_path, join | (recompute ? BG_MESH_DROP_NORMALS : 0u), &m,
                                   err, sizeof err);
    if (st != BG_OK) {
        cli_height_close(&h);
        /* Missing, unreadable or malformed input is the user's to fix (2);
         * only running out of memory is a runtime failure. */
        if (st == BG_ERR_OUT_OF_MEMORY)
            return cli_fail(cmd, "%s", err);
        return cli_usage_error(cmd, "%s", err);
    }
    if (bake_path && !m.u) {
        bg_mesh_free(&m);
        cli_height_close(&h);
        return cli_usage_error(cmd,
                               "'%s' has no texture coordinates (UV set 0): --bake-normal-map needs "
                               "them; without the bake, vertex mode works on this mesh",
                               in_path);
    }

    size_t nv = m.vertex_count, nt = m.triangle_count;
    size_t nchunks = (nv + MESH_CHUNK - 1) / MESH_CHUNK;
    int file_normals = m.nx != NULL;
    float *ox = m.nx, *oy = m.ny, *oz = m.nz;
    float *outs = NULL;
    chunk_stats *stats = NULL;
    bg_image img = {0, 0, 0, NULL};
    cli_outfile of = {NULL, NULL, NULL};
    FILE *devout = NULL;
    rc = CLI_OK;

    double t_load = now_seconds();
    size_t no_normal;
    if (!file_normals) {
        ox = malloc(nv * sizeof *ox);
        oy = malloc(nv * sizeof *oy);
        oz = malloc(nv * sizeof *oz);
        no_normal = ox && oy && oz ? mesh_vertex_normals(&m, ox, oy, oz) : (size_t)-1;
    } else {
        no_normal = mesh_normalize_normals(nv, ox, oy, oz);
    }
    if (no_normal == (size_t)-1) {
        rc = cli_fail(cmd, "out of memory for the normals of %zu vertices", nv);
        goto done;
    }
    size_t unusable = 0, nonfinite_pos = 0;
    for (size_t t = 0; t < nt; t++)
        unusable += (size_t)!mesh_triangle_usable(&m, t);
    for (size_t i = 0; i < nv; i++)
        nonfinite_pos += (size_t)!(isfinite(m.px[i]) && isfinite(m.py[i]) && isfinite(m.pz[i]));

    /* nx ny nz height [compare]: the only per-vertex arrays besides the mesh. */
    outs = malloc(nv * (size_t)(compare ? 5 : 4) * sizeof *outs);
    stats = calloc(nchunks ? nchunks : 1, sizeof *stats);
    if (!outs || !stats) {
        rc = cli_fail(cmd, "out of memory for %zu vertices", nv);
        goto done;
    }
    vertex_job job = {.m = &m, .h = &h, .method = method,
                      .other = method == BG_PERTURB_SURFGRAD ? BG_PERTURB_ADDITIVE
                                                             : BG_PERTURB_SURFGRAD,
                      .ox = ox, .oy = oy, .oz = oz,
                      .nx = outs, .ny = outs + nv, .nz = outs + 2 * nv, .height = outs + 3 * nv,
                      .compare = compare ? outs + 4 * nv : NULL, .stats = stats};
    atomic_init(&job.oom, 0);
    double t_normals = now_seconds();
    cli_parallel_for(nv, MESH_CHUNK, threads, vertex_chunk, &job);
    double t_perturb = now_seconds();
    if (atomic_load(&job.oom)) {
        rc = cli_fail(cmd, "out of memory while perturbing");
        goto done;
    }
    chunk_stats tot;
    memset(&tot, 0, sizeof tot);
    for (size_t c = 0; c < nchunks; c++) {
        const chunk_stats *s = &stats[c];
        tot.valid += s->valid;
        tot.inward_surf += s->inward_surf;
        tot.inward_add += s->inward_add;
        tot.nonfinite_height += s->nonfinite_height;
        tot.sum_angle += s->sum_angle;
        tot.sum_cmp += s->sum_cmp;
        tot.sum_height += s->sum_height;
        tot.finite_height += s->finite_height;
        if (s->max_angle > tot.max_angle)
            tot.max_angle = s->max_angle;
        if (s->max_cmp > tot.max_cmp)
            tot.max_cmp = s->max_cmp;
    }

    mesh_bake_stats bstats = {0, 0, 0};
    double t_bake0 = now_seconds();
    if (bake_path) {
        bake.method = method;
        bake.threads = threads;
        if ((rc = mesh_bake(cmd, &m, ox, oy, oz, &h, &bake, &img, &bstats)))
            goto done;
    }
    double t_bake1 = now_seconds();

    /* The PLY goes to a temporary file first and is renamed only after the
     * map is in place too, so a failing bake leaves the old OUT.ply alone. */
    if (out_path) {
        char comment[400];
        const bg_height *hh = &h.h;
        snprintf(comment, sizeof comment,
                 "bumpgrad %s mesh method=%s function=%s octaves=%d lacunarity=%g gain=%g "
                 "amplitude=%g frequency=%g gradient=%s normals=%s",
                 bg_version_string(), cli_method_name(method), cli_function_name(hh->fractal.function),
                 hh->fractal.octaves, (double)hh->fractal.lacunarity, (double)hh->fractal.gain,
                 (double)hh->amplitude, (double)hh->frequency,
                 hh->gradient == BG_GRADIENT_CENTRAL ? "central" : "analytic",
                 file_normals ? "file" : "angle-weighted");
        mesh_ply_out d = {.vertex_count = nv, .triangle_count = nt,
                          .px = m.px, .py = m.py, .pz = m.pz,
                          .nx = job.nx, .ny = job.ny, .nz = job.nz,
                          .ox = ox, .oy = oy, .oz = oz, .height = job.height,
                          .compare = job.compare, .u = m.u, .v = m.v, .indices = m.indices,
                          .comment = comment, .ascii = ascii};
        if (is_device(out_path)) {
            /* /dev/null, a FIFO, a terminal: there is nothing to replace
             * atomically, and renaming a temporary file over the device
             * node would destroy it. */
            if (!(devout = fopen(out_path, "wb"))) {
                rc = cli_fail(cmd, "cannot open output %s: %s", out_path, strerror(errno));
                goto done;
            }
        } else if ((rc = cli_outfile_open(cmd, out_path, &of))) {
            goto done;
        }
        if (mesh_ply_write(devout ? devout : of.fp, &d)) {
            rc = cli_fail(cmd, "writing %s failed", out_path);
            goto done;
        }
    }
    if (bake_path) {
        bg_pixel_type type = (bg_pixel_type)bake_depth;
        if (bake_depth < 0)
            type = ends_with_ci(bake_path, ".exr") ? BG_PIXEL_HALF : BG_PIXEL_U8;
        bg_status ws = bg_image_write(bake_path, &img, type, 0, err, sizeof err);
        if (ws != BG_OK) {
            /* A file name without an image format is a usage error, as in
             * heightmap; only the writing itself failing is an I/O failure. */
            rc = ws == BG_ERR_INVALID_ARGUMENT ? cli_usage_error(cmd, "%s", err)
                                               : cli_fail(cmd, "%s", err);
            goto done;
        }
    }
    if (devout) {
        int bad = fclose(devout) != 0;
        devout = NULL;
        if (bad) {
            rc = cli_fail(cmd, "writing %s failed: %s", out_path, strerror(errno));
            goto done;
        }
    } else if (out_path && (rc = cli_outfile_commit(cmd, &of))) {
        goto done;
    }

    double t_end = now_seconds();
    if (!quiet) {
        FILE *fp = out_path && strcmp(out_path, "-") == 0 ? stderr : stdout;
        double valid = tot.valid ? (double)tot.valid : 1.0;
        fprintf(fp, "mesh: %s: %zu vertices, %zu triangles (%zu scene meshes", in_path, nv, nt,
                m.mesh_count);
        if (m.dropped_primitives)
            fprintf(fp, ", %zu points/lines dropped", m.dropped_primitives);
        fprintf(fp, ")\n");
        fprintf(fp, "normals: %s; %zu vertices without a normal (sentinel 0,0,0)\n",
                file_normals ? "from the file" : "angle-weighted (computed)", no_normal);
        fprintf(fp, "degenerate: %zu unusable triangles (zero area, repeated index or NaN/Inf "
                    "corner), %zu vertices with NaN/Inf position\n",
                unusable, nonfinite_pos);
        fprintf(fp, "height: mean %.6g over %zu vertices (%zu non-finite)\n",
                tot.finite_height ? tot.sum_height / (double)tot.finite_height : 0.0,
                tot.finite_height, tot.nonfinite_height);
        fprintf(fp, "perturbation (%s): mean %.4f deg, max %.4f deg\n", cli_method_name(method),
                tot.sum_angle / valid, tot.max_angle);
        fprintf(fp, "inward (dot(n', n) <= 0): surfgrad %zu (%.4f%%), %s %zu (%.4f%%)\n",
                tot.inward_surf, 100.0 * (double)tot.inward_surf / valid,
                method == BG_PERTURB_SURFGRAD ? "additive" : cli_method_name(method), tot.inward_add,
                100.0 * (double)tot.inward_add / valid);
        fprintf(fp, "surfgrad vs additive: mean %.4f deg, max %.4f deg\n", tot.sum_cmp / valid,
                tot.max_cmp);
        if (bake_path)
            fprintf(fp, "bake: %s %dx%d %s space, %zu texels covered, %zu padded, %zu "
                        "triangles skipped (degenerate or zero UV area)\n",
                    bake_path, bake.width, bake.height,
                    bake.space == MESH_BAKE_TANGENT ? "tangent" : "object", bstats.covered,
                    bstats.padded, bstats.skipped);
        if (out_path)
            fprintf(fp, "wrote %s (%s PLY)\n", out_path, ascii ? "ASCII" : "binary little-endian");
        fprintf(fp, "time: load %.3f s, normals %.3f s, height+perturb %.3f s (%d threads), "
                    "bake %.3f s, write %.3f s\n",
                t_load - t0, t_normals - t_load, t_perturb - t_normals, threads,
                bake_path ? t_bake1 - t_bake0 : 0.0, t_end - (bake_path ? t_bake1 : t_bake0));
    }

done:
    if (devout)
        fclose(devout);
    if (of.fp)
        cli_outfile_abort(&of);
    bg_image_free(&img);
    free(outs);
    free(stats);
    if (!file_normals) {
        free(ox);
        free(oy);
        free(oz);
    }
    bg_mesh_free(&m);
    cli_height_close(&h);
    return rc;
}
