/* SPDX-License-Identifier: MIT */
/* `bumpgrad volume`: bake a height function and its gradient into an OpenVDB
 * file (FloatGrid "height" + Vec3SGrid "gradient"), densely over a box or only
 * in a narrow band around a sphere. This file parses the options, runs the
 * bake (bgt_volume_run, src/tools/bake/volume.c) and prints its summary. */
#include <math.h>
#include <stdint.h>
#include <string.h>
#include "bake/bake.h"
#include "cli.h"

#define CMD "volume"

static void volume_help(FILE *fp)
{
    fputs("Usage: bumpgrad volume --bbox X0,Y0,Z0,X1,Y1,Z1 --voxel-size S\n"
          "                       [height options] [--band-sphere CX,CY,CZ,R,W]\n"
          "                       --output FILE.vdb\n"
          "\n"
          "Bake the height h(p) and its gradient into an OpenVDB file: a FloatGrid\n"
          "\"height\" and a Vec3SGrid \"gradient\" (world units, covariant). Voxel\n"
          "(i,j,k) sits at world position S*(i,j,k); the baked voxels are those whose\n"
          "centre lies in the box (inclusive). Read it back with --height-grid.\n"
          "\n"
          "Options:\n"
          "  --bbox X0,Y0,Z0,X1,Y1,Z1  world box to bake, X0 <= X1 etc. (required)\n"
          "  --voxel-size S            voxel edge in world units, > 0 (required)\n"
          "  --band-sphere CX,CY,CZ,R,W\n"
          "                            narrow band: only voxels whose centre is within\n"
          "                            W of the sphere of centre C and radius R\n"
          "                            (| |p - C| - R | <= W); others stay inactive\n"
          "                            (background 0). Sample at least one voxel inside\n"
          "                            the band's edge.\n"
          "  -o, --output FILE.vdb     output (required); written to a temporary file\n"
          "                            and renamed on success\n"
          "  --threads N               worker threads (default: all cores)\n"
          "  -h, --help                this help\n"
          "\n",
          fp);
    cli_height_help(fp);
    fputs("(--height-grid is not accepted here: volume bakes a function.)\n"
          "\n"
          "Prints the number of active voxels. Exit status: 0 success, 1 the output\n"
          "cannot be written (or out of memory), 2 bad usage.\n"
          "\n"
          "Example:\n"
          "  bumpgrad volume --function fbm --octaves 4 --bbox -1,-1,-1,1,1,1 \\\n"
          "      --voxel-size 0.02 --band-sphere 0,0,0,0.8,0.06 --output ball.vdb\n",
          fp);
}

/* "a,b,c,..." with exactly n numbers. */
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
        if (!isfinite(out[count]))
            return cli_usage_error(CMD, "%s: numbers must be finite, got \"%s\"", opt, text);
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

int cmd_volume(int argc, char **argv)
{
    bgt_height height;
    bgt_height_init(&height);
    const char *out_path = NULL;
    double bbox[6] = {0}, voxel = 0.0, band[5] = {0};
    int have_bbox = 0, have_band = 0;
    long threads = 0;
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i], *v;
        int rc = cli_height_option(CMD, &height, argc, argv, &i);
        if (rc == 1)
            continue;
        if (rc != 0)
            return rc;
        if (strcmp(o, "-h") == 0 || strcmp(o, "--help") == 0) {
            volume_help(stdout);
            return CLI_OK;
        } else if (strcmp(o, "--bbox") == 0) {
            if (cli_need_value(CMD, argc, argv, &i, &v) || parse_list(o, v, 6, bbox))
                return CLI_USAGE;
            have_bbox = 1;
        } else if (strcmp(o, "--voxel-size") == 0) {
            if (cli_need_value(CMD, argc, argv, &i, &v) || cli_parse_double(CMD, o, v, &voxel))
                return CLI_USAGE;
            if (!(voxel > 0.0 && isfinite(voxel)))
                return cli_usage_error(CMD, "--voxel-size: must be finite and > 0, got \"%s\"", v);
        } else if (strcmp(o, "--band-sphere") == 0) {
            if (cli_need_value(CMD, argc, argv, &i, &v) || parse_list(o, v, 5, band))
                return CLI_USAGE;
            if (!(band[3] >= 0.0) || !(band[4] >= 0.0))
                return cli_usage_error(CMD, "--band-sphere: radius and width must be >= 0, got "
                                            "\"%s\"", v);
            have_band = 1;
        } else if (strcmp(o, "-o") == 0 || strcmp(o, "--output") == 0) {
            if (cli_need_value(CMD, argc, argv, &i, &out_path))
                return CLI_USAGE;
        } else if (strcmp(o, "--threads") == 0) {
            if (cli_need_value(CMD, argc, argv, &i, &v) ||
                cli_parse_int(CMD, o, v, 1, 4096, &threads))
                return CLI_USAGE;
        } else {
            return cli_usage_error(CMD, "unknown argument \"%s\" (see bumpgrad volume --help)", o);
        }
    }
    if (!have_bbox)
        return cli_usage_error(CMD, "--bbox is required");
    if (voxel == 0.0)
        return cli_usage_error(CMD, "--voxel-size is required");
    if (!out_path)
        return cli_usage_error(CMD, "--output is required");
    cli_progress prog;
    bgt_progress sink = cli_progress_sink(&prog);
    bgt_volume_opts opts = {.height = &height, .output = out_path, .voxel = voxel,
                            .have_band = have_band, .threads = (int)threads, .progress = &sink};
    memcpy(opts.bbox, bbox, sizeof bbox);
    if (have_band)
        memcpy(opts.band, band, sizeof band);
    bgt_volume_result r;
    bgt_err err;
    bg_status st = bgt_volume_run(&opts, &r, &err);
    if (st != BG_OK)
        return cli_report(CMD, st, &err);
    printf("%s: %llu active voxels (height + gradient), voxel size %g, index box "
           "[%lld,%lld,%lld]..[%lld,%lld,%lld]\n",
           out_path, (unsigned long long)r.voxels, voxel, r.lo[0], r.lo[1], r.lo[2], r.hi[0],
           r.hi[1], r.hi[2]);
    return CLI_OK;
}
