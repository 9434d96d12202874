/* SPDX-License-Identifier: MIT */
/* The tools library's mesh, volume and heightmap jobs called directly (no CLI):
 * bgt_heightmap_run, bgt_volume_run, bgt_mesh_run.
 * Usage: test_bake {heightmap|volume|mesh} SCRATCH_DIR
 * Expected values come from the formulas recomputed here in double (the seed's
 * normal map, the framework's derivative ratios, the band test over the whole
 * box), never from files saved by an earlier run. */
#define _GNU_SOURCE /* mkdtemp */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "bake/heightmap.h"
#include "bake/volume.h"
#include "bumpgrad/image.h"
#include "mesh/mesh.h"
#include "scratch.h"

static int is_bad_input(bg_status s)
{
    return s == BG_ERR_INVALID_ARGUMENT || s == BG_ERR_FORMAT || s == BG_ERR_NULL_POINTER;
}

/* ---- heightmap ---- */
#define HW 7
#define HH 5
static double height_at(int x, int y) { return 0.1 * x * x - 0.05 * y + 0.02 * x * y; }

static void test_heightmap(void)
{
    printf("heightmap: normal map from a height image, derivative map from a normal map\n");
    bg_image in;
    CHECK(bg_image_alloc(&in, HW, HH, 1) == BG_OK, "alloc");
    for (int y = 0; y < HH; y++)
        for (int x = 0; x < HW; x++)
            in.pixels[y * HW + x] = (float)height_at(x, y);
    char err[512];
    CHECK(bg_image_write(path_in("h.exr"), &in, BG_PIXEL_F32, 0, err, sizeof err) == BG_OK, "%s",
          err);
    for (int mode = 0; mode < 2; mode++) { /* 0: clamp, 1: wrap + y-down */
        bgt_heightmap_opts o = {.input = path_in("h.exr"), .output = path_in("n.exr"),
                                .strength = 1.5f, .wrap = mode, .y_down = mode, .bits = 32};
        bgt_err e;
        bg_status st = bgt_heightmap_run(&o, &e);
        CHECK(st == BG_OK, "run (mode %d): %s", mode, st == BG_OK ? "" : e.msg);
        bg_image out;
        if (bg_image_read(path_in("n.exr"), &out, err, sizeof err) != BG_OK) {
            CHECK(0, "%s", err);
            continue;
        }
        CHECK(out.width == HW && out.height == HH && out.channels == 3, "size %dx%dx%d",
              out.width, out.height, out.channels);
        double maxerr = 0;
        for (int y = 0; y < HH && out.channels == 3; y++)
            for (int x = 0; x < HW; x++) {
                int l = x - 1, r = x + 1, u = y - 1, d = y + 1;
                if (mode) {
                    l = (l + HW) % HW, r = r % HW, u = (u + HH) % HH, d = d % HH;
                } else {
                    l = l < 0 ? 0 : l, r = r >= HW ? HW - 1 : r;
                    u = u < 0 ? 0 : u, d = d >= HH ? HH - 1 : d;
                }
                /* Heights as stored in float, differences in double (the seed: a over
                 * two pixels, b = row above minus row below). */
                double a = (double)(float)height_at(r, y) - (double)(float)height_at(l, y);
                double b = (double)(float)height_at(x, u) - (double)(float)height_at(x, d);
                if (mode)
                    b = -b;
                double n[3] = {-1.5 * a, -1.5 * b, 1.0};
                double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
                for (int c = 0; c < 3; c++) {
                    double want = 0.5 * n[c] / len + 0.5;
                    double got = out.pixels[3 * (y * HW + x) + c];
                    if (fabs(got - want) > maxerr)
                        maxerr = fabs(got - want);
                }
            }
        CHECK(maxerr < 1e-6, "mode %d: max error %.3g against the seed formula", mode, maxerr);
        bg_image_free(&out);
    }
    bg_image_free(&in);

    /* Derivative map: m = normalize(-p, -q, 1) gives back (p, q); m.z < 0 is
     * mirrored (the library's rule, bg_tangent_normal_to_derivs): (1,0,-0.5)
     * gives (-2, 0); all-zero m gives 0. */
    bg_image nm;
    CHECK(bg_image_alloc(&nm, 4, 1, 3) == BG_OK, "alloc");
    const double p[2] = {0.75, -3.0}, q[2] = {-0.25, 10.0};
    for (int k = 0; k < 2; k++) {
        double len = sqrt(p[k] * p[k] + q[k] * q[k] + 1.0);
        nm.pixels[3 * k + 0] = (float)(0.5 * -p[k] / len + 0.5);
        nm.pixels[3 * k + 1] = (float)(0.5 * -q[k] / len + 0.5);
        nm.pixels[3 * k + 2] = (float)(0.5 * 1.0 / len + 0.5);
    }
    const float inward[3] = {1.0f, 0.5f, 0.25f}, zero[3] = {0.5f, 0.5f, 0.5f}; /* (1,0,-0.5), 0 */
    memcpy(nm.pixels + 6, inward, sizeof inward);
    memcpy(nm.pixels + 9, zero, sizeof zero);
    CHECK(bg_image_write(path_in("nm.exr"), &nm, BG_PIXEL_F32, 0, err, sizeof err) == BG_OK, "%s",
          err);
    bg_image_free(&nm);
    bgt_heightmap_opts o = {.input = path_in("nm.exr"), .output = path_in("d.exr"),
                            .strength = 1.0f, .to_derivative = 1};
    bgt_err e;
    bg_status st = bgt_heightmap_run(&o, &e);
    CHECK(st == BG_OK, "derivative run: %s", st == BG_OK ? "" : e.msg);
    bg_image d;
    if (bg_image_read(path_in("d.exr"), &d, err, sizeof err) == BG_OK && d.channels == 3) {
        for (int k = 0; k < 2; k++)
            CHECK(fabs(d.pixels[3 * k] - p[k]) < 1e-5 * (1 + fabs(p[k])) &&
                      fabs(d.pixels[3 * k + 1] - q[k]) < 1e-5 * (1 + fabs(q[k])),
                  "texel %d: (%g, %g), want (%g, %g)", k, d.pixels[3 * k], d.pixels[3 * k + 1],
                  p[k], q[k]);
        CHECK(d.pixels[6] == -2.0f && d.pixels[7] == 0.0f, "inward texel: (%g, %g), want (-2, 0)",
              d.pixels[6], d.pixels[7]);
        CHECK(d.pixels[9] == 0.0f && d.pixels[10] == 0.0f, "zero texel: (%g, %g)", d.pixels[9],
              d.pixels[10]);
        bg_image_free(&d);
    } else {
        CHECK(0, "cannot read the derivative map");
    }

    /* Errors: the status says whose fault it is; nothing is left behind. */
    bgt_heightmap_opts bad = {.input = path_in("h.exr"), .output = path_in("x.jpg"), .bits = 16,
                              .strength = 1.0f};
    st = bgt_heightmap_run(&bad, &e);
    CHECK(st == BG_ERR_INVALID_ARGUMENT && strstr(e.msg, "16-bit"), "16 bits to JPEG: %d %s", st,
          e.msg);
    bad.output = path_in("x.png");
    bad.input = path_in("missing.png");
    bad.bits = 8;
    st = bgt_heightmap_run(&bad, &e);
    CHECK(is_bad_input(st), "missing input: status %d (%s)", st, e.msg);
    bad.input = path_in("h.exr");
    bad.output = path_in("no_dir/x.png");
    st = bgt_heightmap_run(&bad, &e);
    CHECK(st == BG_ERR_IO, "unwritable output: status %d (%s)", st, e.msg);
    bad.output = path_in("x.png");
    bad.to_derivative = 1; /* a one-channel image is no normal map */
    bad.bits = 32;
    bad.output = path_in("x.exr");
    st = bgt_heightmap_run(&bad, &e);
    CHECK(st == BG_ERR_INVALID_ARGUMENT && strstr(e.msg, "3 channels"), "1-channel normal map: %d %s",
          st, e.msg);
    CHECK(temp_leftovers() == 0, "temporary files left behind");
}

/* ---- volume ---- */
typedef struct progress_log {
    int begins, ends;
    size_t total, last;
} progress_log;
static void pl_begin(void *c, const char *label, size_t total)
{
    progress_log *l = c;
    (void)label;
    l->begins++;
    l->total = total;
}
static void pl_update(void *c, size_t done) { ((progress_log *)c)->last = done; }
static void pl_end(void *c) { ((progress_log *)c)->ends++; }

static void test_volume(void)
{
    printf("volume: band voxel count against a scan of the whole box, errors\n");
    bgt_height h;
    bgt_height_init(&h);
    h.h.fractal = bg_fractal_default(BG_FUNC_FBM);
    const double voxel = 0.05, bbox[6] = {-0.52, -0.61, -0.5, 0.7, 0.5, 0.43};
    const double band[5] = {0.1, -0.05, 0.02, 0.37, 0.08};
    progress_log log = {0, 0, 0, 0};
    bgt_progress prog = {pl_begin, pl_update, pl_end, &log};
    bgt_volume_opts o = {.height = &h, .output = path_in("b.vdb"), .voxel = voxel,
                         .have_band = 1, .threads = 2, .progress = &prog};
    memcpy(o.bbox, bbox, sizeof bbox);
    memcpy(o.band, band, sizeof band);
    bgt_volume_result r;
    bgt_err e;
    bg_status st = bgt_volume_run(&o, &r, &e);
    CHECK(st == BG_OK, "band bake: %s", st == BG_OK ? "" : e.msg);
    /* The exact band test on every voxel centre of the box. */
    uint64_t want = 0;
    long long lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = (long long)ceil(bbox[a] / voxel);
        hi[a] = (long long)floor(bbox[a + 3] / voxel);
    }
    for (long long k = lo[2]; k <= hi[2]; k++)
        for (long long j = lo[1]; j <= hi[1]; j++)
            for (long long i = lo[0]; i <= hi[0]; i++) {
                double dx = voxel * (double)i - band[0], dy = voxel * (double)j - band[1],
                       dz = voxel * (double)k - band[2];
                want += fabs(sqrt(dx * dx + dy * dy + dz * dz) - band[3]) <= band[4];
            }
    CHECK(st == BG_OK && r.voxels == want && want > 0, "band voxels %llu, scan gives %llu",
          (unsigned long long)r.voxels, (unsigned long long)want);
    for (int a = 0; a < 3; a++)
        CHECK(st == BG_OK && r.lo[a] == lo[a] && r.hi[a] == hi[a], "index box axis %d", a);
    CHECK(log.begins == 1 && log.ends == 1 && log.last <= log.total && log.total > 0,
          "progress: %d begin, %d end, %zu of %zu", log.begins, log.ends, log.last, log.total);

    o.have_band = 0;
    o.progress = NULL;
    o.output = path_in("dense.vdb");
    st = bgt_volume_run(&o, &r, &e);
    uint64_t dense = 1;
    for (int a = 0; a < 3; a++)
        dense *= (uint64_t)(hi[a] - lo[a] + 1);
    CHECK(st == BG_OK && r.voxels == dense, "dense voxels %llu, want %llu",
          (unsigned long long)r.voxels, (unsigned long long)dense);

    bgt_volume_opts bad = o;
    bad.output = "-";
    CHECK(bgt_volume_run(&bad, &r, &e) == BG_ERR_INVALID_ARGUMENT, "output \"-\"");
    bad = o;
    bad.bbox[0] = 1.0;
    CHECK(bgt_volume_run(&bad, &r, &e) == BG_ERR_INVALID_ARGUMENT && strstr(e.msg, "axis x"),
          "inverted box: %s", e.msg);
    bad = o;
    bad.voxel = 1e-4;
    CHECK(bgt_volume_run(&bad, &r, &e) == BG_ERR_INVALID_ARGUMENT && strstr(e.msg, "limit"),
          "too many voxels: %s", e.msg);
    bgt_height g = h;
    g.grid_path = path_in("b.vdb");
    bad = o;
    bad.height = &g;
    CHECK(bgt_volume_run(&bad, &r, &e) == BG_ERR_INVALID_ARGUMENT, "grid as the height");
    bad = o;
    bad.output = path_in("no_dir/x.vdb");
    st = bgt_volume_run(&bad, &r, &e);
    CHECK(st == BG_ERR_IO, "unwritable output: status %d (%s)", st, e.msg);
    CHECK(temp_leftovers() == 0, "temporary files left behind");
}

/* ---- mesh ---- */
static long file_size(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 ? (long)st.st_size : -1;
}

static void test_mesh(void)
{
    printf("mesh: a written OBJ through bgt_mesh_run, path checks, a failed bake\n");
    /* A unit quad in z = 0 (two triangles) and a tilted one, with UVs, no normals. */
    FILE *fp = fopen(path_in("q.obj"), "w");
    if (!fp) {
        CHECK(0, "cannot write q.obj");
        return;
    }
    fputs("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0.5\nv 2 1 0.5\n"
          "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.9 0\nvt 0.9 1\n"
          "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\nf 2/2 5/5 6/6\nf 2/2 6/6 3/3\n",
          fp);
    fclose(fp);
    bgt_height h;
    bgt_height_init(&h);
    h.h.amplitude = 0.05f;
    h.h.frequency = 3.0f;
    bgt_mesh_opts o = {.input = path_in("q.obj"), .output = path_in("q.ply"), .height = &h,
                       .method = BG_PERTURB_SURFGRAD, .compare = 1, .join = BG_MESH_JOIN_AUTO,
                       .threads = 2, .bake_depth = -1,
                       .units = MESH_UNITS_FILE, /* the recomputation below is in file units */
                       .bake = {.width = 16, .height = 8, .space = MESH_BAKE_TANGENT, .padding = 2}};
    bgt_mesh_result r;
    bgt_err e;
    bg_status st = bgt_mesh_run(&o, &r, &e);
    CHECK(st == BG_OK, "vertex run: %s", st == BG_OK ? "" : e.msg);
    if (st == BG_OK) {
        CHECK(r.vertex_count == 6 && r.triangle_count == 4, "%zu vertices, %zu triangles",
              r.vertex_count, r.triangle_count);
        CHECK(!r.file_normals && r.no_normal == 0 && r.valid == 6, "normals: file %d, %zu none",
              r.file_normals, r.no_normal);
        CHECK(r.finite_height == 6 && r.mean_angle > 0 && r.mean_angle <= r.max_angle &&
                  r.max_angle < 90 && r.inward_surf == 0,
              "statistics: mean %g max %g inward %zu", r.mean_angle, r.max_angle, r.inward_surf);
        /* The heights at the vertices, recomputed with the library's single-point API. */
        static const float pos[6][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0},
                                        {0, 1, 0}, {2, 0, 0.5f}, {2, 1, 0.5f}};
        double sum = 0;
        for (int i = 0; i < 6; i++) {
            bg_vec3 grad;
            sum += bg_height_eval(&h.h, (bg_vec3){pos[i][0], pos[i][1], pos[i][2]}, &grad);
        }
        CHECK(fabs(r.mean_height - sum / 6) < 1e-6, "mean height %.9g, recomputed %.9g",
              r.mean_height, sum / 6);
    }
    long ply_size = file_size(path_in("q.ply"));
    CHECK(ply_size > 0, "q.ply written");

    /* A bake into a folder that does not exist: BG_ERR_IO, and the PLY of the
     * same run is not renamed over the old one. */
    o.compare = 0;
    o.bake_path = path_in("no_dir/n.png");
    st = bgt_mesh_run(&o, &r, &e);
    CHECK(st == BG_ERR_IO, "bake into a missing folder: status %d (%s)", st, e.msg);
    CHECK(file_size(path_in("q.ply")) == ply_size, "old q.ply replaced by a failed run");
    o.bake_path = path_in("n.png");
    st = bgt_mesh_run(&o, &r, &e);
    CHECK(st == BG_OK && r.bake.covered > 0 && r.bake.skipped == 0, "bake: %s, %zu covered",
          st == BG_OK ? "ok" : e.msg, r.bake.covered);

    /* Path checks and bad input. */
    bgt_mesh_opts bad = o;
    bad.bake_path = bad.output;
    CHECK(bgt_mesh_run(&bad, &r, &e) == BG_ERR_INVALID_ARGUMENT && strstr(e.msg, "same file"),
          "same file: %s", e.msg);
    bad = o;
    bad.bake_path = NULL;
    bad.output = bad.input; /* OBJ replaced by a PLY */
    CHECK(bgt_mesh_run(&bad, &r, &e) == BG_ERR_INVALID_ARGUMENT &&
              file_size(path_in("q.obj")) > 0 && strstr(e.msg, "not a PLY"),
          "PLY over the OBJ input: %s", e.msg);
    bad = o;
    bad.input = path_in("missing.obj");
    st = bgt_mesh_run(&bad, &r, &e);
    CHECK(is_bad_input(st), "missing input: status %d (%s)", st, e.msg);
    bad = o;
    bad.bake_path = path_in("n.txt");
    st = bgt_mesh_run(&bad, &r, &e);
    CHECK(st == BG_ERR_INVALID_ARGUMENT, "map without an image format: status %d (%s)", st, e.msg);
    CHECK(temp_leftovers() == 0, "temporary files left behind");
}

int main(int argc, char **argv)
{
    static const scratch_group groups[] = {
        {"heightmap", test_heightmap},
        {"volume", test_volume},
        {"mesh", test_mesh}};
    return scratch_main(argc, argv, "test_bake", groups, sizeof groups / sizeof groups[0]);
}
