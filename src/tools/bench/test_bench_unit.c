/* SPDX-License-Identifier: MIT */
/* The bench engine's own unit test (src/tools/bench/meson.build), for what
 * only bench_internal.h shows, which nothing outside the tool includes: the
 * grid rows (rows.c) split a thread's points into sub-grids of the lattice,
 * and whatever the split, the outputs must be those of one grid call on the
 * whole lattice. The engine as a library is tested through its face by
 * tests/bench/test_bench_engine.c. */
#include <stdlib.h>
#include <string.h>
#include "bench_internal.h"
#include "common/check.h"

/* The grid rows split a thread's points [b, e) into sub-grids: whatever the
 * split, the outputs are those of one grid call on the whole lattice. */
static void check_grid_rows(void)
{
    const size_t side = BENCH_GRID_SIDE, n = 2 * side * side + 3 * side + 5;
    bench_data d;
    CHECK(bench_data_init(&d, n) == 0, "bench data");
    bg_grid3 g = {.origin = {BENCH_GRID_ORIGIN, BENCH_GRID_ORIGIN, BENCH_GRID_ORIGIN},
                  .step = {BENCH_GRID_STEP, BENCH_GRID_STEP, BENCH_GRID_STEP},
                  .count = {side, side, 3}};
    size_t total = side * side * 3;
    float *want = malloc(5 * total * sizeof *want); /* noise, fbm v, gx, gy, gz */
    CHECK(want != NULL, "memory");
    if (!want || !d.v) {
        free(want);
        bench_data_free(&d);
        return;
    }
    bg_fractal f = bg_fractal_default(BG_FUNC_FBM);
    CHECK(bg_noise3_grid(&g, want) == BG_OK &&
              bg_fractal3_grad_grid(&f, &g, want + total, want + 2 * total, want + 3 * total,
                                    want + 4 * total) ==
                  BG_OK,
          "reference grid calls");
    /* Cuts inside a row, at a row end, inside a slice and across a slice. */
    const size_t cuts[] = {0, 7, side, 5 * side + 3, side * side + 1, n - 2, n};
    bench_job j = {.d = &d, .fbm = f};
    for (int k = 0; k < 2; k++) {
        j.kernel = k ? K_FBM3_GRAD_GRID : K_NOISE3_GRID;
        memset(d.v, 0xff, n * sizeof *d.v);
        for (size_t c = 0; c + 1 < sizeof cuts / sizeof cuts[0]; c++)
            bench_job_run(&j, cuts[c], cuts[c + 1]);
        const float *w = want + (k ? total : 0);
        size_t bad = 0;
        for (size_t i = 0; i < n; i++) {
            int differ = memcmp(&d.v[i], &w[i], sizeof(float)) != 0;
            if (k)
                differ |= memcmp(&d.ox[i], &want[2 * total + i], sizeof(float)) != 0 ||
                          memcmp(&d.oy[i], &want[3 * total + i], sizeof(float)) != 0 ||
                          memcmp(&d.oz[i], &want[4 * total + i], sizeof(float)) != 0;
            bad += differ;
        }
        CHECK(bad == 0, "%s: %zu of %zu samples differ from one grid call",
              bgt_bench_kernel_name((size_t)j.kernel), bad, n);
    }
    free(want);
    bench_data_free(&d);
}

/* The mesh rows (whole calls, seconds each) run only by name or "mesh". */
static void check_mesh_selection(void)
{
    bgt_err e;
    bench_sel sel;
    CHECK(bench_select("ours", NULL, 0, &sel, &e) == BG_OK && sel.ours[K_NOISE3] &&
              !sel.ours[K_MIKK] && !sel.ours[K_MESH_BAKE] &&
              bench_select("mesh", NULL, 0, &sel, &e) == BG_OK && sel.ours[K_MIKK] &&
              sel.ours[K_MESH_BAKE] && !sel.ours[K_NOISE3] &&
              bench_select("mikktspace", NULL, 0, &sel, &e) == BG_OK && sel.ours[K_MIKK] &&
              !sel.ours[K_MESH_BAKE],
          "mesh rows selected only by name");
}

int main(void)
{
    check_grid_rows();
    check_mesh_selection();
    return check_summary("test_bench_unit");
}
