/* SPDX-License-Identifier: MIT */
/* The bake's progress (bgt_mesh_opts.progress, docs/MESH.md "Progress") and
 * the UDIM tile list of the result, through bgt_mesh_run on a two-tile quad
 * written here: begin once with tiles x W x H texels, updates that never
 * decrease and never pass the total (with one thread: the last equals it),
 * end once; the result lists tiles 1001 and 1002. Tools build. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "common/check.h"
#include "mesh/mesh.h"

typedef struct seen {
    int begins, ends, bad_order;
    size_t total, updates, last;
    char label[32];
} seen;

static void on_begin(void *ctx, const char *label, size_t total)
{
    seen *s = ctx;
    s->begins++;
    s->total = total;
    snprintf(s->label, sizeof s->label, "%s", label);
}
static void on_update(void *ctx, size_t done)
{
    seen *s = ctx; /* only worker 0 reports: no lock needed here */
    s->bad_order += done < s->last || done > s->total;
    s->last = done;
    s->updates++;
}
static void on_end(void *ctx) { ((seen *)ctx)->ends++; }

int main(void)
{
    check_verbose = 1;
    char dir[] = "/tmp/bg-mesh-progress-XXXXXX";
    if (!mkdtemp(dir))
        return 1;
    char ply[128], map[128], t1[128], t2[128];
    snprintf(ply, sizeof ply, "%s/quad.ply", dir);
    snprintf(map, sizeof map, "%s/n.<UDIM>.png", dir);
    snprintf(t1, sizeof t1, "%s/n.1001.png", dir);
    snprintf(t2, sizeof t2, "%s/n.1002.png", dir);
    FILE *f = fopen(ply, "w");
    /* two unit quads side by side, UVs in tiles 1001 and 1002 */
    fprintf(f, "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
               "property float z\nproperty float s\nproperty float t\nelement face 4\n"
               "property list uchar int vertex_indices\nend_header\n"
               "0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n"
               "2 0 0 1 0\n3 0 0 2 0\n3 1 0 2 1\n2 1 0 1 1\n"
               "3 0 1 2\n3 0 2 3\n3 4 5 6\n3 4 6 7\n");
    fclose(f);
    for (int threads = 1; threads <= 2; threads++) {
        bgt_height h;
        bgt_height_init(&h);
        seen s;
        memset(&s, 0, sizeof s);
        bgt_progress p = {on_begin, on_update, on_end, &s};
        bgt_mesh_opts o;
        memset(&o, 0, sizeof o);
        o.input = ply;
        o.bake_path = map;
        o.height = &h;
        o.method = BG_PERTURB_SURFGRAD;
        o.join = BG_MESH_JOIN_AUTO;
        o.threads = threads;
        o.bake.width = 64, o.bake.height = 48, o.bake.padding = 2;
        o.bake_depth = -1;
        o.progress = &p;
        bgt_mesh_result r;
        bgt_err e;
        memset(&e, 0, sizeof e);
        bg_status st = bgt_mesh_run(&o, &r, &e);
        CHECK(st == BG_OK, "%d thread(s): bgt_mesh_run: %s", threads, st == BG_OK ? "ok" : e.msg);
        if (st != BG_OK) {
            if (e.status == BG_ERR_IO && strstr(e.msg, "I/O module")) {
                printf("skip: %s\n", e.msg);
                return 77;
            }
            continue;
        }
        size_t total = 2u * 64u * 48u;
        CHECK(s.begins == 1 && s.ends == 1 && strcmp(s.label, "bake") == 0 && s.total == total,
              "begin once (\"%s\", %zu texels, want %zu), end once (%d)", s.label, s.total, total,
              s.ends);
        CHECK(s.updates > 0 && s.bad_order == 0 && (threads > 1 || s.last == total),
              "%zu updates, never decreasing nor past the total, last %zu", s.updates, s.last);
        CHECK(r.bake.tiles == 2 && r.bake.tile_udim[0] == 1001 && r.bake.tile_udim[1] == 1002 &&
                  access(t1, F_OK) == 0 && access(t2, F_OK) == 0,
              "result lists tiles %d, %d (%zu tiles), both written",
              r.bake.tiles > 0 ? r.bake.tile_udim[0] : 0, r.bake.tiles > 1 ? r.bake.tile_udim[1] : 0,
              r.bake.tiles);
        /* the whole quad of each tile is covered: 64 x 48 texels per tile */
        CHECK(r.bake.covered == total, "covered texels summed over the tiles: %zu", r.bake.covered);
        remove(t1);
        remove(t2);
    }
    remove(ply);
    rmdir(dir);
    return check_summary("test_mesh_progress");
}
