/* SPDX-License-Identifier: MIT */
/* The job of `bumpgrad mesh`: bump a real mesh (any format assimp reads) with a
 * solid height field. Mikkelsen 2010 (eq. 2 and 4, Listing 3): n' = normalize(n
 * - grad_S h) with grad_S h = g - n (n.g) needs only the position and the
 * normal, so meshes without texture coordinates are bumped as they are. Per
 * vertex the result goes to a PLY; with a bake path the same perturbation is
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
#include "common/parallel.h"
#include "common/safe_file.h"
#include "mesh/mesh_gltf.h"
#include "mesh/mesh_internal.h"

/* Vertices per parallel chunk: large enough that the per-chunk scratch and the
 * chunk bookkeeping are noise, small enough to balance two to 64 workers. */
#define MESH_CHUNK 8192

/* The option spellings of the CLI, for the PLY header comment. */
static const char *function_name(bg_function f)
{
    static const char *const names[] = {"noise", "fbm", "turbulence"};
    return (unsigned)f < 3 ? names[f] : "?";
}
static const char *method_name(bg_perturb_method m)
{
    static const char *const names[] = {"surfgrad", "additive", "additive-perlin"};
    return (unsigned)m < 3 ? names[m] : "?";
}

/* Per-chunk summary, reduced in chunk order so that the means do not depend
 * on which worker ran which chunk. */
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
    const bgt_height *h;
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
     * bgt_height_gradient + bg_perturb_batch give the same bits as the fused
     * bgt_height_perturb. */
    bgt_height_gradient(j->h, j->m->px + b, j->m->py + b, j->m->pz + b, n, j->height + b, gx, gy,
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

mesh_out_format mesh_out_format_of(const char *path)
{
    struct stat sb;
    /* an existing folder keeps failing as it did, when it is opened (exit 1) */
    int folder = path && stat(path, &sb) == 0 && S_ISDIR(sb.st_mode);
    if (!path || folder || strcmp(path, "-") == 0 || is_device(path) || ends_with_ci(path, ".ply"))
        return MESH_OUT_PLY;
    if (ends_with_ci(path, ".glb"))
        return MESH_OUT_GLB;
    if (ends_with_ci(path, ".gltf"))
        return MESH_OUT_GLTF;
    if (ends_with_ci(path, ".obj"))
        return MESH_OUT_OBJ;
    return MESH_OUT_UNKNOWN;
}

const char *mesh_out_format_name(mesh_out_format f, int ascii)
{
    switch (f) {
    case MESH_OUT_PLY:
        return ascii ? "ASCII PLY" : "binary little-endian PLY";
    case MESH_OUT_GLB:
        return "binary glTF 2.0";
    case MESH_OUT_GLTF:
        return "glTF 2.0, embedded buffer";
    case MESH_OUT_OBJ:
        return "Wavefront OBJ";
    default:
        return "?";
    }
}

/* The options of a high-poly bake (--from): they need it and the map, and
 * their maps are files of their own, named with <UDIM> exactly when the
 * normal map is. */
static bg_status check_high(const bgt_mesh_opts *o, bgt_err *e)
{
    const char *aux[2] = {o->height_map, o->miss_map};
    const char *names[2] = {"--bake-height-map", "--miss-map"};
    if (!o->from && (o->cage || o->height_map || o->miss_map || o->ray_distance != 0.0))
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "%s is for a high-poly bake: give the high-poly mesh with --from HIGH",
                        o->cage ? "--cage" : o->height_map ? "--bake-height-map"
                                       : o->miss_map     ? "--miss-map"
                                                         : "--ray-distance");
    if (!o->from)
        return BG_OK;
    if (!o->bake_path)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--from bakes a normal map: give --bake-normal-map FILE and --size");
    if (o->ray_distance != 0.0 && !(o->ray_distance > 0.0 && isfinite(o->ray_distance)))
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--ray-distance %g: expected a finite distance > 0", o->ray_distance);
    int udim = strstr(o->bake_path, MESH_UDIM_TOKEN) != NULL;
    for (int i = 0; i < 2; i++) {
        if (!aux[i])
            continue;
        if (strcmp(aux[i], "-") == 0 || is_device(aux[i]))
            return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "%s %s: give a regular file's name",
                            names[i], aux[i]);
        if ((strstr(aux[i], MESH_UDIM_TOKEN) != NULL) != udim)
            return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                            "%s %s: name it with <UDIM> exactly when --bake-normal-map is (%s)",
                            names[i], aux[i], o->bake_path);
        if (same_file(aux[i], o->bake_path) || (o->output && same_file(aux[i], o->output)) ||
            (i == 1 && aux[0] && same_file(aux[0], aux[1])))
            return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                            "%s %s names the same file as another output", names[i], aux[i]);
    }
    if (o->height_map && !ends_with_ci(o->height_map, ".exr") &&
        !ends_with_ci(o->height_map, ".tif") && !ends_with_ci(o->height_map, ".tiff"))
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--bake-height-map %s: signed distances need a float image: name it "
                        ".exr or .tif",
                        o->height_map);
    return BG_OK;
}

bg_status bgt_mesh_check(const bgt_mesh_opts *o, bgt_err *e)
{
    if (!o || !o->input || !o->height)
        return bgt_fail(e, BG_ERR_NULL_POINTER, "no input mesh or height given");
    const char *in_path = o->input, *out_path = o->output, *bake_path = o->bake_path;
    if (!out_path && !bake_path)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "missing OUT.ply (or --bake-normal-map FILE)");
    if (bake_path && !(o->bake.width > 0 && o->bake.height > 0))
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "--bake-normal-map needs --size N (or WxH)");
    /* The format follows OUT's extension; a name we cannot write is refused
     * (it used to get a PLY under that name). */
    if (out_path && mesh_out_format_of(out_path) == MESH_OUT_UNKNOWN)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "OUT %s: cannot write a mesh in this format (the extension must be "
                        ".ply, .glb, .gltf or .obj)",
                        out_path);
    if (out_path && bake_path && strcmp(out_path, "-") == 0 && strcmp(bake_path, "-") == 0)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "OUT and --bake-normal-map are both \"-\": standard output takes one "
                        "of them");
    /* --format is for the map on "-"; with a file its extension decides and
     * a --format naming another is refused (render --format's rule). */
    if (o->bake_format && !bake_path)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--format %s: the format of --bake-normal-map -; there is no bake",
                        o->bake_format);
    if (o->bake_format && strcmp(bake_path, "-") != 0) {
        char ext[24];
        int n = snprintf(ext, sizeof ext, ".%s", o->bake_format + (o->bake_format[0] == '.'));
        for (char *c = ext; *c; c++)
            *c = (char)(*c >= 'A' && *c <= 'Z' ? *c - 'A' + 'a' : *c);
        if (n < 0 || (size_t)n >= sizeof ext || !ends_with_ci(bake_path, ext))
            return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                            "--format %s disagrees with the extension of --bake-normal-map %s "
                            "(the extension decides; --format is for --bake-normal-map -)",
                            o->bake_format, bake_path);
    }
    /* One path for the PLY and the map: the later rename silently replaced
     * the other output (exit 0, the bake lost). */
    if (out_path && bake_path && same_file(out_path, bake_path))
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "OUT.ply and --bake-normal-map name the same file %s", out_path);
    /* A PLY written over a mesh of another format destroys the source (a PLY
     * input may be updated in place: same format, like heightmap IN = OUT). */
    if (out_path && strcmp(out_path, "-") != 0 && !ends_with_ci(in_path, ".ply") &&
        same_file(in_path, out_path))
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "OUT.ply %s is the input mesh, which is not a PLY: writing it would "
                        "replace the source",
                        out_path);
    if (bake_path && is_device(bake_path))
        /* The image writer renames a temporary file into place, which would
         * replace a device node such as /dev/null with a regular file. */
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--bake-normal-map: %s exists and is not a regular file", bake_path);
    return check_high(o, e);
}

/* Vertex normals: the file's, normalized, or angle-weighted ones (allocated
 * into *ox..*oz). Returns the number of sentinels or (size_t)-1 (out of memory). */
static size_t take_normals(bg_mesh *m, int file_normals, float **ox, float **oy, float **oz)
{
    size_t nv = m->vertex_count;
    if (file_normals) {
        *ox = m->nx;
        *oy = m->ny;
        *oz = m->nz;
        return mesh_normalize_normals(nv, *ox, *oy, *oz);
    }
    *ox = malloc(nv * sizeof **ox);
    *oy = malloc(nv * sizeof **oy);
    *oz = malloc(nv * sizeof **oz);
    return *ox && *oy && *oz ? mesh_vertex_normals(m, *ox, *oy, *oz) : (size_t)-1;
}

/* The normal map's tiles (one without the <UDIM> token): each is written to
 * a temporary next to its final name as soon as it is baked (the image is
 * freed after that), and all are renamed into place together at the end,
 * after the mesh output was written too; a failure before that removes every
 * temporary and leaves all old tiles as they were. */
typedef struct map_out {
    const char *path; /* the map argument, with or without the token; "-": stdout */
    const char *format; /* the format of "-" (NULL: PNG) */
    int udim;
    bg_pixel_type type;
    size_t n;
    char *tmp[MESH_UDIM_MAX_TILES], *final[MESH_UDIM_MAX_TILES];
    double t_write;
    int gltf;             /* 0, or 1 (.glb) / 2 (.gltf): keep the map for OUT's material */
    const char *out_path; /* OUT, for the glTF's relative URI */
    mesh_gltf_map gmap[MESH_UDIM_MAX_TILES]; /* per tile written, for the glTF */
    int gtile[MESH_UDIM_MAX_TILES];
    size_t ng;
    const char *what;     /* for messages: "normal map" when NULL */
} map_out;

/* The map is OpenEXR: a file's extension says so, or on "-" its --format
 * (PNG without one). */
static int map_is_exr(const char *path, const char *format)
{
    if (strcmp(path, "-") != 0)
        return ends_with_ci(path, ".exr");
    if (!format)
        return 0;
    format += format[0] == '.';
    return strlen(format) == 3 && ends_with_ci(format, "exr");
}

/* A file tile goes to a temporary that map_commit renames; standard output
 * (one tile: "-" holds no token) takes the image as bg_image_write_as
 * encodes it, in memory and written out once complete. */
static bg_status map_sink(void *ctx, int udim, const bg_image *img, bgt_err *e)
{
    map_out *mo = ctx;
    double t0 = now_seconds();
    const int to_stdout = strcmp(mo->path, "-") == 0;
    const char *final = mo->path, *target = mo->path;
    if (!to_stdout) {
        char *fin = mo->udim ? mesh_udim_path(mo->path, udim) : strdup(mo->path);
        if (!fin)
            return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
        char *tmp = bgt_safe_temp_path(fin, e);
        if (!tmp) {
            free(fin);
            return e && e->status != BG_OK ? e->status : BG_ERR_IO;
        }
        mo->final[mo->n] = fin;
        mo->tmp[mo->n++] = tmp;
        final = fin, target = tmp;
    }
    char err[512];
    bg_status ws = bg_image_write_as(target, to_stdout ? mo->format : NULL, img, mo->type, 0,
                                     err, sizeof err);
    mo->t_write += now_seconds() - t0;
    if (ws != BG_OK)
        /* A file name without an image format is bad input, as in
         * heightmap; only the writing itself failing is an I/O failure. */
        return bgt_fail(e, bgt_write_status(ws), "%s %s: %s", mo->what ? mo->what : "normal map", final, err);
    if (mo->gltf && mo->ng < MESH_UDIM_MAX_TILES) {
        mo->gtile[mo->ng] = udim;
        return mesh_gltf_map_image(&mo->gmap[mo->ng++], img, to_stdout ? NULL : target, final,
                                   mo->out_path, mo->gltf == 1, e);
    }
    return BG_OK;
}

/* Rename every tile into place. Only a failing rename (same folder as its
 * temporary: rare) can leave a part of the set renamed; the message says how
 * much. */
static bg_status map_commit(map_out *mo, bgt_err *e)
{
    for (size_t i = 0; i < mo->n; i++) {
        bg_status st = bgt_safe_commit_path(mo->tmp[i], mo->final[i], e);
        free(mo->tmp[i]);
        mo->tmp[i] = NULL; /* renamed or removed either way */
        if (st != BG_OK) {
            if (mo->n > 1) {
                char what[64];
                snprintf(what, sizeof what, "%zu of %zu tiles were renamed into place before", i,
                         mo->n);
                bgt_err_prefix(e, what);
            }
            return st;
        }
    }
    return BG_OK;
}

static void map_free(map_out *mo)
{
    for (size_t i = 0; i < mo->n; i++) {
        if (mo->tmp[i]) {
            bgt_safe_discard_path(mo->tmp[i]);
            free(mo->tmp[i]);
        }
        free(mo->final[i]);
    }
    mo->n = 0;
    for (size_t i = 0; i < mo->ng; i++)
        mesh_gltf_map_free(&mo->gmap[i]);
    mo->ng = 0;
}

/* Sum the chunk statistics in chunk order into *r. */
static void reduce_stats(const chunk_stats *stats, size_t nchunks, bgt_mesh_result *r)
{
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
    double valid = tot.valid ? (double)tot.valid : 1.0;
    r->valid = tot.valid;
    r->finite_height = tot.finite_height;
    r->nonfinite_height = tot.nonfinite_height;
    r->mean_height = tot.finite_height ? tot.sum_height / (double)tot.finite_height : 0.0;
    r->mean_angle = tot.sum_angle / valid;
    r->max_angle = tot.max_angle;
    r->inward_surf = tot.inward_surf;
    r->inward_other = tot.inward_add;
    r->mean_compare = tot.sum_cmp / valid;
    r->max_compare = tot.max_cmp;
}

/* Load IN, and refuse a mesh that lacks what the bake needs (UVs, or the
 * file's tangents with --tangents file). On failure m holds nothing. */
static bg_status load_mesh(const bgt_mesh_opts *o, bg_mesh *m, bgt_err *e)
{
    char err[512];
    bg_status st = bg_mesh_load_ex(o->input, o->join | (o->recompute_normals ? BG_MESH_DROP_NORMALS : 0u),
                                   m, err, sizeof err);
    if (st != BG_OK)
        /* Missing, unreadable or malformed input is the user's to fix (2);
         * only running out of memory is a runtime failure. */
        return bgt_fail(e, bgt_read_status(st), "%s", err);
    if (o->bake_path && !m->u) {
        bg_mesh_free(m);
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "'%s' has no texture coordinates (UV set 0): --bake-normal-map needs "
                        "them; without the bake, vertex mode works on this mesh",
                        o->input);
    }
    if (o->bake_path && o->bake.space == MESH_BAKE_TANGENT &&
        o->bake.tangents == MESH_TANGENTS_FILE && !m->tx) {
        bg_mesh_free(m);
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "'%s' has no tangents (with normals and UVs in every mesh): --tangents "
                        "file needs them; --tangents mikktspace computes them",
                        o->input);
    }
    return BG_OK;
}

/* The triangles the perturbation cannot use, the non-finite positions and
 * the mean edge length of the usable triangles. */
static void count_defects(const bg_mesh *m, bgt_mesh_result *r)
{
    double sum = 0.0;
    size_t n = 0;
    for (size_t t = 0; t < m->triangle_count; t++) {
        if (!mesh_triangle_usable(m, t)) {
            r->unusable_triangles++;
            continue;
        }
        const uint32_t *ix = m->indices + 3 * t;
        for (int k = 0; k < 3; k++) {
            uint32_t a = ix[k], b = ix[(k + 1) % 3];
            double dx = (double)m->px[a] - m->px[b], dy = (double)m->py[a] - m->py[b];
            double dz = (double)m->pz[a] - m->pz[b];
            sum += sqrt(dx * dx + dy * dy + dz * dz);
            n++;
        }
    }
    r->mean_edge = n ? sum / (double)n : 0.0;
    for (size_t i = 0; i < m->vertex_count; i++)
        r->nonfinite_positions +=
            (size_t)!(isfinite(m->px[i]) && isfinite(m->py[i]) && isfinite(m->pz[i]));
}

/* The normal map of --bake-normal-map, through map_sink into mo's temporaries. */
static bg_status bake_map(const bgt_mesh_opts *o, const bg_mesh *m, const vertex_job *job,
                          int threads, map_out *mo, const mesh_hi *hi, bgt_mesh_result *r,
                          bgt_err *e)
{
    mesh_bake_opts bake = o->bake;
    bake.hi = hi;
    bake.method = job->method;
    bake.threads = threads;
    bake.progress = o->progress;
    bake.udim = mo->udim = strstr(o->bake_path, MESH_UDIM_TOKEN) != NULL;
    mo->path = o->bake_path;
    mo->format = o->bake_format; /* the shim takes "exr", ".exr" or "EXR" alike */
    mo->type = (bg_pixel_type)o->bake_depth;
    mo->out_path = o->output;
    mesh_out_format f = o->output ? mesh_out_format_of(o->output) : MESH_OUT_PLY;
    r->gltf_map_note = NULL;
    if (f == MESH_OUT_GLB || f == MESH_OUT_GLTF) {
        /* The map becomes the materials' normalTexture unless a viewer
         * would decode it wrongly (glTF normal textures are tangent space,
         * green up, one image per material). */
        if (o->gltf_normals == MESH_GLTF_NORMALS_BUMPED)
            r->gltf_map_note = "--gltf-normals bumped: the normals carry the bump, so no material "
                               "uses the map (it would bump twice)";
        else if (o->bake.space != MESH_BAKE_TANGENT)
            r->gltf_map_note = "an object-space map: glTF normal textures are tangent space, so "
                               "no material uses it";
        else if (o->bake.green_down)
            r->gltf_map_note = "--normal-map-y -y: glTF normal textures are green up (+y), so no "
                               "material uses the map";
        else
            mo->gltf = f == MESH_OUT_GLB ? 1 : 2;
    }
    if (o->bake_depth < 0)
        mo->type = map_is_exr(o->bake_path, o->bake_format) ? BG_PIXEL_HALF : BG_PIXEL_U8;
    return mesh_bake(m, job->ox, job->oy, job->oz, job->h, &bake, map_sink, mo, &r->bake, e);
}

/* OUT of bgt_mesh_run while it is written: a safe temporary (PLY, glTF), an
 * assimp-exported temporary (OBJ), or a device written in place. */
typedef struct mesh_out {
    const char *path;
    mesh_out_format fmt;
    bgt_safe_file of;
    FILE *devout;
    char *obj_tmp;
    float *gltf_tan;
    float *gltf_uv; /* per corner, shifted into the tile (a <UDIM> bake) */
} mesh_out;

static void out_free(mesh_out *w)
{
    if (w->devout)
        fclose(w->devout);
    if (w->obj_tmp) {
        bgt_safe_discard_path(w->obj_tmp);
        free(w->obj_tmp);
    }
    free(w->gltf_tan);
    free(w->gltf_uv);
    if (w->of.fp)
        bgt_safe_abort(&w->of);
    memset(w, 0, sizeof *w);
}

/* Open OUT; for OBJ, assimp's exporter wants a file name, so the whole file
 * (bumped normals, positions, UVs) is exported to a temporary next to OUT
 * here. /dev/null, a FIFO, a terminal: there is nothing to replace
 * atomically, and renaming a temporary file over the device node would
 * destroy it, so a device is written in place. */
static bg_status out_open(mesh_out *w, const bg_mesh *m, const vertex_job *job, bgt_err *e)
{
    if (w->fmt == MESH_OUT_OBJ) {
        bg_mesh view = *m;
        view.nx = job->nx, view.ny = job->ny, view.nz = job->nz;
        if (!(w->obj_tmp = bgt_safe_temp_path(w->path, e)))
            return BG_ERR_IO;
        char err[512];
        bg_status xs = bg_mesh_export(w->obj_tmp, "objnomtl", &view, err, sizeof err);
        if (xs != BG_OK)
            return bgt_fail(e, xs == BG_ERR_OUT_OF_MEMORY ? BG_ERR_OUT_OF_MEMORY : BG_ERR_IO, "%s",
                            err);
        return BG_OK;
    }
    /* A device or FIFO (written in place) or a planted link to one: the one
     * rule of safe_file.c decides (bgt_safe_open). */
    return bgt_safe_open(&w->of, w->path, e);
}

/* A <UDIM> bake in the glTF: each triangle belongs to the tile of its UV
 * centroid; its corners' UVs are shifted by the tile's origin into [0, 1)
 * (a triangle across a tile border keeps its corners outside it), and its
 * material is the pair (its material, that tile's map). */
static bg_status gltf_tiles(const bg_mesh *m, const map_out *mo, mesh_gltf_scene *sc,
                            uint32_t **tri_mat, float **corner_uv, bgt_err *e)
{
    size_t T = m->triangle_count;
    int *tri_map = malloc((T ? T : 1) * sizeof *tri_map);
    float *uv = malloc((T ? 3 * T : 1) * 2 * sizeof *uv);
    if (!tri_map || !uv) {
        free(tri_map), free(uv);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the glTF tiles");
    }
    for (size_t t = 0; t < T; t++) {
        const uint32_t *ix = m->indices + 3 * t;
        double uc = ((double)m->u[ix[0]] + m->u[ix[1]] + m->u[ix[2]]) / 3.0;
        double vc = ((double)m->v[ix[0]] + m->v[ix[1]] + m->v[ix[2]]) / 3.0;
        double a = floor(uc), b = floor(vc);
        int tile = a >= 0 && a < 10 && b >= 0 && b < MESH_UDIM_V_TILES
                       ? 1001 + (int)a + 10 * (int)b
                       : 0;
        tri_map[t] = -1;
        for (size_t j = 0; j < mo->ng; j++)
            if (mo->gtile[j] == tile)
                tri_map[t] = (int)j;
        for (int k = 0; k < 3; k++) {
            uv[6 * t + 2 * (size_t)k] = tile ? (float)(m->u[ix[k]] - a) : m->u[ix[k]];
            uv[6 * t + 2 * (size_t)k + 1] = tile ? (float)(m->v[ix[k]] - b) : m->v[ix[k]];
        }
    }
    bg_status st = mesh_gltf_scene_tiles(sc, m, mo->gmap, mo->gtile, mo->ng, tri_map, tri_mat, e);
    free(tri_map);
    if (st != BG_OK) {
        free(uv);
        return st;
    }
    *corner_uv = uv;
    return BG_OK;
}

/* glTF. With a baked map (and not --gltf-normals bumped): NORMAL holds the
 * original normals and TANGENT the frames the map was encoded in, and every
 * material's normalTexture is the map, so a viewer applies the bump once.
 * Without one: the bumped normals and their mikkTSpace frames, which is what
 * a glTF viewer computes from this file when it ignores the attribute. */
static bg_status out_gltf(mesh_out *w, const bgt_mesh_opts *o, const bg_mesh *m,
                          const vertex_job *job, map_out *mo, bgt_mesh_result *r, bgt_err *e)
{
    size_t nv = m->vertex_count, nt = m->triangle_count;
    int bumped = o->gltf_normals == MESH_GLTF_NORMALS_BUMPED ||
                 (o->gltf_normals == MESH_GLTF_NORMALS_AUTO && !o->bake_path);
    const float *nx = bumped ? job->nx : job->ox, *ny = bumped ? job->ny : job->oy;
    const float *nz = bumped ? job->nz : job->oz;
    r->gltf_bumped_normals = bumped;
    bg_status st;
    if (m->u) {
        if (!bumped && o->bake_path && o->bake.space == MESH_BAKE_TANGENT) {
            mesh_bake_stats scratch;
            memset(&scratch, 0, sizeof scratch);
            /* job->m: the positions the bake's frames came from */
            mesh_bake_opts bo = o->bake;
            bo.threads = o->threads;
            if ((st = mesh_bake_corner_tangents(job->m, nx, ny, nz, &bo, &w->gltf_tan, &scratch,
                                                e)) != BG_OK)
                return st;
        } else {
            w->gltf_tan = malloc((nt ? 3 * nt : 1) * 4 * sizeof *w->gltf_tan);
            bgt_mikk_mesh mm = {nv, nt, m->indices, job->m->px, job->m->py, job->m->pz,
                                nx, ny, nz, m->u, m->v};
            if (!w->gltf_tan ||
                bgt_mikk_tangents_threads(&mm, w->gltf_tan, NULL, o->threads) != BG_OK)
                return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the glTF tangents");
        }
    }
    const int binary = w->fmt == MESH_OUT_GLB;
    const int tiled = mo->udim && mo->ng > 0;
    mesh_gltf_scene sc;
    uint32_t *tri_mat = NULL;
    if ((st = mesh_gltf_scene_build(&sc, o->input, m, !tiled && mo->ng ? &mo->gmap[0] : NULL,
                                    w->path, binary, e)) == BG_OK &&
        tiled)
        st = gltf_tiles(m, mo, &sc, &tri_mat, &w->gltf_uv, e);
    if (st != BG_OK) {
        mesh_gltf_scene_free(&sc);
        return st;
    }
    r->gltf_map = mo->ng ? 1 + mo->gmap[0].converted : 0;
    r->gltf_materials = sc.material_count;
    r->gltf_textures = sc.textures_kept;
    r->gltf_textures_dropped = sc.textures_dropped;
    r->gltf_meshes = m->part_count ? m->part_count : 1;
    r->gltf_merged = !m->part_count;
    char gen[96];
    snprintf(gen, sizeof gen, "bumpgrad %s mesh", bg_version_string());
    mesh_gltf_in g = {.vertex_count = nv, .triangle_count = nt,
                      .px = m->px, .py = m->py, .pz = m->pz,
                      .nx = nx, .ny = ny, .nz = nz,
                      .u = m->u, .v = m->v, .corner_tangents = w->gltf_tan,
                      .indices = m->indices, .generator = gen,
                      .tri_material = tri_mat ? tri_mat : m->material_count > 1 ? m->material : NULL,
                      .corner_uv = w->gltf_uv,
                      .material_count = sc.material_count, .materials = sc.materials,
                      .image_count = sc.image_count, .images = sc.images,
                      .part_count = m->part_count, .parts = m->parts};
    st = mesh_gltf_write(w->devout ? w->devout : w->of.fp, binary, &g, e);
    mesh_gltf_scene_free(&sc);
    free(tri_mat);
    return st;
}

/* PLY: the per-vertex table of docs/MESH.md, the run's settings in a comment. */
static bg_status out_ply(mesh_out *w, const bgt_mesh_opts *o, const bg_mesh *m,
                         const vertex_job *job, int file_normals, bgt_err *e)
{
    char comment[400];
    const bg_height *hh = &job->h->h;
    snprintf(comment, sizeof comment,
             "bumpgrad %s mesh method=%s function=%s octaves=%d lacunarity=%g gain=%g "
             "amplitude=%g frequency=%g gradient=%s normals=%s units=%s",
             bg_version_string(), method_name(job->method), function_name(hh->fractal.function),
             hh->fractal.octaves, (double)hh->fractal.lacunarity, (double)hh->fractal.gain,
             (double)hh->amplitude, (double)hh->frequency,
             hh->gradient == BG_GRADIENT_CENTRAL ? "central" : "analytic",
             file_normals ? "file" : "angle-weighted",
             o->units == MESH_UNITS_FILE ? "file" : "model-radius");
    mesh_ply_out d = {.vertex_count = m->vertex_count, .triangle_count = m->triangle_count,
                      .px = m->px, .py = m->py, .pz = m->pz,
                      .nx = job->nx, .ny = job->ny, .nz = job->nz,
                      .ox = job->ox, .oy = job->oy, .oz = job->oz, .height = job->height,
                      .compare = job->compare, .u = m->u, .v = m->v, .indices = m->indices,
                      .comment = comment, .ascii = o->ascii};
    if (mesh_ply_write(w->devout ? w->devout : w->of.fp, &d))
        return bgt_fail(e, BG_ERR_IO, "writing %s failed", w->path);
    return BG_OK;
}

/* Put OUT in place: close the device, or rename the temporary over OUT. */
static bg_status out_commit(mesh_out *w, bgt_err *e)
{
    bg_status st = BG_OK;
    if (w->devout) {
        int bad = fclose(w->devout) != 0;
        w->devout = NULL;
        if (bad)
            st = bgt_fail(e, BG_ERR_IO, "writing %s failed: %s", w->path, strerror(errno));
    } else if (w->obj_tmp) {
        st = bgt_safe_commit_path(w->obj_tmp, w->path, e);
        free(w->obj_tmp);
        w->obj_tmp = NULL;
    } else {
        st = bgt_safe_commit(&w->of, e);
    }
    return st;
}

/* OUT written to its temporary (out_commit puts it in place). */
static bg_status out_write(mesh_out *w, const bgt_mesh_opts *o, const bg_mesh *m,
                           const vertex_job *job, int file_normals, map_out *mo,
                           bgt_mesh_result *r, bgt_err *e)
{
    w->path = o->output;
    w->fmt = mesh_out_format_of(o->output);
    bg_status st = out_open(w, m, job, e);
    if (st != BG_OK)
        return st;
    if (w->fmt == MESH_OUT_GLB || w->fmt == MESH_OUT_GLTF)
        return out_gltf(w, o, m, job, mo, r, e);
    if (w->fmt == MESH_OUT_PLY)
        return out_ply(w, o, m, job, file_normals, e);
    return BG_OK;
}

/* The per-vertex perturbation over all cores, then the stats in chunk order. */
static bg_status perturb_vertices(vertex_job *job, size_t nv, int threads, bgt_mesh_result *r,
                                  bgt_err *e)
{
    const size_t nchunks = (nv + MESH_CHUNK - 1) / MESH_CHUNK;
    atomic_init(&job->oom, 0);
    bgt_parallel_for(nv, MESH_CHUNK, threads, vertex_chunk, job);
    if (atomic_load(&job->oom))
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory while perturbing");
    reduce_stats(job->stats, nchunks, r);
    return BG_OK;
}

bg_status bgt_mesh_run(const bgt_mesh_opts *o, bgt_mesh_result *r, bgt_err *e)
{
    bg_status st = bgt_mesh_check(o, e);
    if (st != BG_OK)
        return st;
    if (!r)
        return bgt_fail(e, BG_ERR_NULL_POINTER, "no result given");
    memset(r, 0, sizeof *r);
    if ((st = bgt_io_ready(e)) != BG_OK)
        return st;
    bgt_height h = *o->height;
    h.grid = NULL;
    if ((st = bgt_height_open(&h, e)) != BG_OK)
        return st;
    const bg_perturb_method method = o->method;
    const int threads = o->threads == 0 ? bgt_threads_default() : o->threads;
    r->threads = threads;

    bg_mesh m;
    double t0 = now_seconds();
    if ((st = load_mesh(o, &m, e)) != BG_OK) {
        bgt_height_close(&h);
        return st;
    }
    size_t nv = m.vertex_count, nchunks = (nv + MESH_CHUNK - 1) / MESH_CHUNK;
    int file_normals = m.nx != NULL;
    float *ox = NULL, *oy = NULL, *oz = NULL, *outs = NULL, *fpos = NULL;
    chunk_stats *stats = NULL;
    map_out mo, ho, mm; /* the normal map; --from's height and miss maps */
    memset(&mo, 0, sizeof mo);
    memset(&ho, 0, sizeof ho);
    memset(&mm, 0, sizeof mm);
    mesh_hi hi;
    memset(&hi, 0, sizeof hi);
    int hi_open = 0;
    double t_hi = 0.0;
    mesh_out w;
    memset(&w, 0, sizeof w);
    r->vertex_count = nv;
    r->triangle_count = m.triangle_count;
    r->mesh_count = m.mesh_count;
    r->dropped_primitives = m.dropped_primitives;
    r->file_normals = file_normals;

    double t_load = now_seconds();
    size_t no_normal = take_normals(&m, file_normals, &ox, &oy, &oz);
    if (no_normal == (size_t)-1) {
        st = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the normals of %zu vertices", nv);
        goto done;
    }
    r->no_normal = no_normal;
    count_defects(&m, r);

    /* The height's frame: the model scaled into the unit sphere (the
     * default), or the file's units. */
    bg_mesh frame = m;
    r->unit = 1.0;
    r->model_radius = mesh_bounding_sphere(&m, r->model_centre);
    if (o->units == MESH_UNITS_MODEL) {
        if (!(r->model_radius > 0.0 && isfinite(r->model_radius))) {
            st = bgt_fail(e, BG_ERR_FORMAT,
                          "'%s': no finite extent, so no model size for --units model (use "
                          "--units file)",
                          o->input);
            goto done;
        }
        if (!(fpos = malloc((nv ? nv : 1) * 3 * sizeof *fpos))) {
            st = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for %zu vertices", nv);
            goto done;
        }
        for (size_t i = 0; i < nv; i++) {
            fpos[i] = mesh_model_coord(m.px[i], r->model_centre[0], r->model_radius);
            fpos[nv + i] = mesh_model_coord(m.py[i], r->model_centre[1], r->model_radius);
            fpos[2 * nv + i] = mesh_model_coord(m.pz[i], r->model_centre[2], r->model_radius);
        }
        frame.px = fpos, frame.py = fpos + nv, frame.pz = fpos + 2 * nv;
        r->unit = r->model_radius;
    }
    if (!h.grid) {
        const bg_fractal *fr = &h.h.fractal;
        int oct = fr->function == BG_FUNC_NOISE ? 1 : fr->octaves;
        r->coarsest_feature = r->unit / fabs((double)h.h.frequency);
        r->finest_feature = r->coarsest_feature / pow(fabs((double)fr->lacunarity), oct - 1);
    }

    /* nx ny nz height [compare]: the only per-vertex arrays besides the mesh. */
    outs = malloc(nv * (size_t)(o->compare ? 5 : 4) * sizeof *outs);
    stats = calloc(nchunks ? nchunks : 1, sizeof *stats);
    if (!outs || !stats) {
        st = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for %zu vertices", nv);
        goto done;
    }
    vertex_job job = {.m = &frame, .h = &h, .method = method,
                      .other = method == BG_PERTURB_SURFGRAD ? BG_PERTURB_ADDITIVE
                                                             : BG_PERTURB_SURFGRAD,
                      .ox = ox, .oy = oy, .oz = oz,
                      .nx = outs, .ny = outs + nv, .nz = outs + 2 * nv, .height = outs + 3 * nv,
                      .compare = o->compare ? outs + 4 * nv : NULL, .stats = stats};
    double t_normals = now_seconds();
    st = perturb_vertices(&job, nv, threads, r, e);
    double t_perturb = now_seconds();
    if (st != BG_OK)
        goto done;

    if (o->from) {
        /* HIGH (and the cage) in the height's frame; --ray-distance in its units */
        double c0[3] = {0.0, 0.0, 0.0};
        int model = o->units == MESH_UNITS_MODEL;
        double dist = o->ray_distance > 0.0 ? o->ray_distance
                      : model              ? MESH_DEFAULT_RAY_DISTANCE
                                           : MESH_DEFAULT_RAY_DISTANCE * r->model_radius;
        double tb = now_seconds();
        if ((st = mesh_hi_open(&hi, o->from, o->cage, &m, o->join, model ? r->model_centre : c0,
                               model ? r->model_radius : 1.0, dist, threads, e)) != BG_OK)
            goto done;
        hi_open = 1;
        t_hi = now_seconds() - tb;
        r->high_vertex_count = hi.high.vertex_count;
        r->high_triangle_count = hi.high.triangle_count;
        r->high_mesh_count = hi.high.mesh_count;
        r->high_usable = hi.usable;
        r->high_file_normals = hi.file_normals;
        r->t_bvh = hi.build_seconds;
        r->ray_distance = dist * r->unit;
        hi.detail = o->detail;
        hi.dist_unit = r->unit;
        int udim = strstr(o->bake_path, MESH_UDIM_TOKEN) != NULL;
        if (o->height_map) {
            ho.path = o->height_map, ho.udim = udim, ho.type = BG_PIXEL_F32;
            ho.what = "height map";
            hi.height_sink = map_sink, hi.height_ctx = &ho;
        }
        if (o->miss_map) {
            mm.path = o->miss_map, mm.udim = udim, mm.what = "miss map";
            mm.type = map_is_exr(o->miss_map, NULL) ? BG_PIXEL_HALF : BG_PIXEL_U8;
            hi.miss_sink = map_sink, hi.miss_ctx = &mm;
        }
    }
    double t_bake0 = now_seconds();
    if (o->bake_path &&
        (st = bake_map(o, &frame, &job, threads, &mo, o->from ? &hi : NULL, r, e)) != BG_OK)
        goto done;
    double t_bake1 = now_seconds();

    /* OUT goes to a temporary file first and is renamed only after the map
     * is in place too, so a failing bake leaves the old OUT alone. */
    if (o->output && (st = out_write(&w, o, &m, &job, file_normals, &mo, r, e)) != BG_OK)
        goto done;
    /* The set (tiles and OUT) is renamed under one lock, so two runs writing
     * it at once leave one run's set, never a mix (safe_file.h). */
    bgt_safe_lock lock;
    if ((st = bgt_safe_lock_outputs(&lock, o->bake_path, o->output, e)) != BG_OK)
        goto done;
    if (o->bake_path)
        st = map_commit(&mo, e);
    if (st == BG_OK)
        st = map_commit(&ho, e);
    if (st == BG_OK)
        st = map_commit(&mm, e);
    if (st == BG_OK && o->output)
        st = out_commit(&w, e);
    bgt_safe_unlock(&lock);
    if (st != BG_OK)
        goto done;

    if (o->output)
        r->output_format = mesh_out_format_name(mesh_out_format_of(o->output), o->ascii);
    double t_end = now_seconds();
    r->t_load = t_load - t0 + t_hi;
    r->t_normals = t_normals - t_load;
    r->t_perturb = t_perturb - t_normals;
    double t_maps = mo.t_write + ho.t_write + mm.t_write;
    r->t_bake = o->bake_path ? t_bake1 - t_bake0 - t_maps : 0.0;
    r->t_write = t_end - (o->bake_path ? t_bake1 : t_bake0) + t_maps;

done:
    out_free(&w);
    map_free(&mo);
    map_free(&ho);
    map_free(&mm);
    if (hi_open)
        mesh_hi_close(&hi);
    free(outs);
    free(fpos);
    free(stats);
    if (!file_normals) {
        free(ox);
        free(oy);
        free(oz);
    }
    bg_mesh_free(&m);
    bgt_height_close(&h);
    return st;
}
