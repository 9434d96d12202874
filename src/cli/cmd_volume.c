/* SPDX-License-Identifier: MIT */
/* `bumpgrad volume`: bake a height function and its gradient into an OpenVDB
 * file (FloatGrid "height" + Vec3SGrid "gradient"), densely over a box or only
 * in a narrow band around a sphere. This file parses the options, runs the
 * bake (bgt_volume_run, src/tools/bake/volume.c) and prints its summary. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "args.h"
#include "bake/volume.h"
#include "bumpgrad/volume.h"
#include "cli.h"
#include "json.h"

#define CMD "volume"

typedef struct volume_args {
    bgt_height height;
    const char *output;
    double bbox[6], voxel;
    struct band_arg {
        int have;
        double v[5];
    } band;
    struct brick_arg {
        int i, n;
    } brick;
    const char *merge;
    int threads, json;
} volume_args;

/* A first try without --bbox/--voxel-size bakes the unit cube [-1,1]^3 at 101^3
 * voxels (about a million, a second or so): enough to look at, quick to write. */
static void volume_defaults(void *p)
{
    volume_args *a = p;
    memset(a, 0, sizeof *a);
    bgt_height_init(&a->height);
    static const double box[6] = {-1, -1, -1, 1, 1, 1};
    memcpy(a->bbox, box, sizeof box);
    a->voxel = 0.02;
}

/* "a,b,c,..." with exactly n finite numbers. */
static int parse_list(const char *opt, const char *text, int n, double *out)
{
    char buf[512];
    if (strlen(text) >= sizeof buf)
        return cli_usage_error(CMD, "%s: value too long", opt);
    strcpy(buf, text);
    int count = 0;
    char *p = buf;
    for (;;) {
        char *comma = strchr(p, ',');
        if (comma)
            *comma = '\0';
        if (count >= n)
            return cli_usage_error(CMD, "%s: expected %d comma-separated numbers, got \"%s\"",
                                   opt, n, text);
        if (cli_parse_double(CMD, opt, p, &out[count]))
            return CLI_USAGE;
        count++;
        if (!comma)
            break;
        p = comma + 1;
    }
    if (count != n)
        return cli_usage_error(CMD, "%s: expected %d comma-separated numbers, got \"%s\"", opt, n,
                               text);
    return 0;
}

static int parse_bbox(const char *cmd, const char *opt, char *text, void *field)
{
    (void)cmd;
    return parse_list(opt, text, 6, field);
}

static int format_bbox(const void *field, char *buf, size_t len)
{
    const double *b = field;
    snprintf(buf, len, "%g,%g,%g,%g,%g,%g", b[0], b[1], b[2], b[3], b[4], b[5]);
    return 1;
}

static int parse_band(const char *cmd, const char *opt, char *text, void *field)
{
    struct band_arg *b = field;
    if (parse_list(opt, text, 5, b->v))
        return CLI_USAGE;
    if (!(b->v[3] >= 0.0) || !(b->v[4] >= 0.0))
        return cli_usage_error(cmd, "%s: radius and width must be >= 0, got \"%s\"", opt, text);
    b->have = 1;
    return 0;
}

/* "I/N": brick I (0-based, as a job array's task id) of N. */
static int parse_brick(const char *cmd, const char *opt, char *text, void *field)
{
    struct brick_arg *b = field;
    char *slash = strchr(text, '/'), *end;
    if (!slash)
        return cli_usage_error(cmd, "%s: expected I/N (brick I of N, 0 <= I < N), got \"%s\"",
                               opt, text);
    *slash = '\0';
    long i = strtol(text, &end, 10);
    int bad = end == text || *end != '\0';
    long n = strtol(slash + 1, &end, 10);
    bad |= end == slash + 1 || *end != '\0';
    *slash = '/';
    if (bad || n < 1 || n > 1000000 || i < 0 || i >= n)
        return cli_usage_error(cmd, "%s: expected I/N with 1 <= N <= 1000000 and 0 <= I < N, got "
                               "\"%s\"", opt, text);
    b->i = (int)i;
    b->n = (int)n;
    return 0;
}

#define A(m) offsetof(volume_args, m)
static const cli_opt volume_opts[] = {
    {.name = "bbox", .kind = CLI_KIND_CUSTOM, .offset = A(bbox), .metavar = "X0,Y0,Z0,X1,Y1,Z1",
     .help = "world box to bake, X0 <= X1 etc.", .parse = parse_bbox, .format = format_bbox},
    {.name = "voxel-size", .kind = CLI_KIND_DOUBLE, .offset = A(voxel), .metavar = "S",
     .help = "voxel edge in world units, > 0", .flags = CLI_GT_LO, .lo = 0},
    {.name = "band-sphere", .kind = CLI_KIND_CUSTOM, .offset = A(band),
     .metavar = "CX,CY,CZ,R,W",
     .help = "narrow band: only voxels whose centre is within W of the sphere of centre C and "
             "radius R (| |p - C| - R | <= W); others stay inactive (background 0). Sample at "
             "least one voxel inside the band's edge.",
     .parse = parse_band},
    {.name = "output", .short_name = 'o', .kind = CLI_KIND_STRING, .offset = A(output),
     .metavar = "FILE.vdb", .help = "output; written to a temporary file and renamed on success "
                                    "(\"-\" is refused: OpenVDB writes files)",
     .flags = CLI_FILE, .complete_ext = "vdb"},
    {.name = "brick", .kind = CLI_KIND_CUSTOM, .offset = A(brick), .metavar = "I/N",
     .help = "bake only brick I (0 <= I < N) of N: slabs of the box along z on the 8-voxel "
             "leaf lattice, the same voxels as the whole bake; join them with --merge. The "
             "voxel limit holds per brick", .parse = parse_brick},
    {.name = "merge", .kind = CLI_KIND_STRING, .offset = A(merge), .metavar = "OUT.vdb",
     .help = "merge the brick files given as arguments into OUT.vdb (OpenVDB's tree merge; "
             "same grids, voxel size and height parameters, no shared voxel) and bake nothing",
     .flags = CLI_FILE, .complete_ext = "vdb"},
    {.name = "threads", .kind = CLI_KIND_INT, .offset = A(threads), .metavar = "N",
     .help = "worker threads, 0 = all cores", .lo = 0, .hi = 4096},
    {.name = "json", .kind = CLI_KIND_FLAG, .offset = A(json),
     .help = "print one JSON object of statistics on standard output instead of the summary "
             "line (voxels, index box, time, ISA, every parameter)"},
    CLI_OPT_INCLUDE(A(height), cli_height_opts, cli_height_heading),
    CLI_OPT_END,
};
#undef A

CLI_SPEC(volume,
    .summary = "bake a height function and its gradient into an OpenVDB file",
    .usage = "[--bbox X0,Y0,Z0,X1,Y1,Z1] [--voxel-size S] [height options]\n"
             "[--band-sphere CX,CY,CZ,R,W] [--brick I/N] --output FILE.vdb\n"
             "--merge OUT.vdb BRICK.vdb...",
    .max_positional = CLI_MAX_POSITIONAL,
    .about = "Bake the height h(p) and its gradient into an OpenVDB file: a FloatGrid\n"
             "\"height\" and a Vec3SGrid \"gradient\" (world units, covariant). Voxel\n"
             "(i,j,k) sits at world position S*(i,j,k); the baked voxels are those whose\n"
             "centre lies in the box (inclusive). Read it back with --height-grid.\n"
             "Without --bbox and --voxel-size, the unit cube [-1,1]^3 is baked at 0.02\n"
             "(101^3 voxels).\n",
    .opts = volume_opts,
    .more = "(--height-grid is not accepted here: volume bakes a function.)\n"
            "\n"
            "Prints the number of active voxels (a warning on stderr if none). Exit status:\n"
            "0 success, 1 the output cannot be written (or out of memory), 2 bad usage.\n"
            "\n"
            "Example:\n"
            "  bumpgrad volume --function fbm --octaves 4 --bbox -1,-1,-1,1,1,1 \\\n"
            "      --voxel-size 0.02 --band-sphere 0,0,0,0.8,0.06 --output ball.vdb\n"
            "In 4 bricks (4 jobs anywhere), then merged (docs/DISTRIBUTED.md):\n"
            "  for i in 0 1 2 3; do bumpgrad volume --brick $i/4 --output b$i.vdb; done\n"
            "  bumpgrad volume --merge whole.vdb b0.vdb b1.vdb b2.vdb b3.vdb\n",
);

/* The summary line: the file, its voxels and their index box. */
static void print_text(const volume_args *a, const bgt_volume_result *r)
{
    printf("%s: %llu active voxels (height + gradient), voxel size %g, index box "
           "[%lld,%lld,%lld]..[%lld,%lld,%lld]\n",
           a->output, (unsigned long long)r->voxels, a->voxel, r->lo[0], r->lo[1], r->lo[2],
           r->hi[0], r->hi[1], r->hi[2]);
}

/* One JSON object instead of the summary line (--json). */
static void print_json(const volume_args *a, const bgt_volume_result *r, double dt)
{
    cli_json j;
    cli_json_begin(&j, stdout);
    cli_json_common(&j, CMD, dt);
    cli_json_int(&j, "active_voxels", (long long)r->voxels);
    double lo[3] = {(double)r->lo[0], (double)r->lo[1], (double)r->lo[2]};
    double hi[3] = {(double)r->hi[0], (double)r->hi[1], (double)r->hi[2]};
    cli_json_nums(&j, "index_min", lo, 3);
    cli_json_nums(&j, "index_max", hi, 3);
    cli_json_object(&j, "parameters");
    cli_json_str(&j, "output", a->output);
    cli_json_nums(&j, "bbox", a->bbox, 6);
    cli_json_num(&j, "voxel_size", a->voxel);
    if (a->band.have)
        cli_json_nums(&j, "band_sphere", a->band.v, 5);
    cli_json_int(&j, "threads", a->threads);
    if (a->brick.n) {
        cli_json_int(&j, "brick_index", a->brick.i);
        cli_json_int(&j, "brick_count", a->brick.n);
    }
    cli_json_height(&j, "height", &a->height);
    cli_json_close(&j);
    cli_json_end(&j);
}

/* --merge OUT.vdb BRICK.vdb...: bg_vdb_merge, then the summary. */
static int run_merge(const volume_args *a, const char *const *pos, int npos)
{
    if (npos < 1)
        return cli_usage_error(CMD, "--merge %s: give the brick files to merge", a->merge);
    if (a->output || a->brick.n)
        return cli_usage_error(CMD, "--merge takes no --output or --brick (it bakes nothing)");
    if (strcmp(a->merge, "-") == 0)
        return cli_usage_error(CMD, "--merge -: OpenVDB writes files, not streams");
    char msg[1024];
    double t0 = cli_now();
    bg_status st = bg_vdb_merge(pos, (size_t)npos, a->merge, msg, sizeof msg);
    double dt = cli_now() - t0;
    if (st != BG_OK) {
        bgt_err err;
        bgt_fail(&err, st, "%s", msg);
        return cli_report(CMD, st, &err);
    }
    if (a->json) {
        cli_json j;
        cli_json_begin(&j, stdout);
        cli_json_common(&j, CMD, dt);
        cli_json_str(&j, "merged", a->merge);
        cli_json_int(&j, "bricks", npos);
        cli_json_end(&j);
    } else if (!cli_quiet()) {
        printf("%s: %d bricks merged\n", a->merge, npos);
    }
    return CLI_OK;
}

static int run_volume(void *args, const char *const *pos, int npos)
{
    volume_args a = *(volume_args *)args;
    if (a.merge)
        return run_merge(&a, pos, npos);
    if (npos > 0)
        return cli_usage_error(CMD, "unexpected argument \"%s\" (brick files go with --merge)",
                               pos[0]);
    if (!a.output)
        return cli_usage_error(CMD, "--output FILE.vdb is required");
    if (strcmp(a.output, "-") == 0)
        return cli_usage_error(CMD, "--output -: OpenVDB writes files, not streams; give a "
                                    "FILE.vdb");
    cli_progress prog;
    bgt_progress sink = cli_progress_sink(&prog);
    bgt_volume_opts opts = {.height = &a.height, .output = a.output, .voxel = a.voxel,
                            .have_band = a.band.have, .threads = a.threads, .progress = &sink,
                            .brick = a.brick.i, .bricks = a.brick.n};
    memcpy(opts.bbox, a.bbox, sizeof a.bbox);
    if (a.band.have)
        memcpy(opts.band, a.band.v, sizeof a.band.v);
    bgt_volume_result r;
    bgt_err err;
    double t0 = cli_now();
    bg_status st = bgt_volume_run(&opts, &r, &err);
    double dt = cli_now() - t0;
    if (st != BG_OK)
        return cli_report(CMD, st, &err);
    if (r.voxels == 0 && a.brick.n)
        cli_warn(CMD, "brick %d/%d holds no voxel (an empty file; it merges as nothing)", a.brick.i,
                 a.brick.n);
    else if (r.voxels == 0)
        cli_warn(CMD, "no voxel was baked: no voxel centre lies in the box%s",
                 a.band.have ? " and the band (check --band-sphere against --bbox and "
                               "--voxel-size)"
                             : " (--voxel-size larger than --bbox?)");
    if (a.json)
        print_json(&a, &r, dt);
    else if (!cli_quiet())
        print_text(&a, &r);
    return CLI_OK;
}
