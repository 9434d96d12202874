/* SPDX-License-Identifier: MIT */
/* One function per equation: heightmap's --to-derivative gives the same bits
 * as the library's bg_tangent_normal_to_derivs for the same inputs, on random
 * normals and on the degenerate ones (inward, zero). The renderer's Listing 1
 * is checked against bg_listing1_normal by its own unit test
 * (src/tools/render/test_render_unit.c); the studies (accuracy, stability)
 * call bg_listing1_normal directly.
 * Usage: test_one_rule SCRATCH_DIR */
#define _GNU_SOURCE
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bake/heightmap.h"
#include "bumpgrad/framework.h"
#include "bumpgrad/image.h"

static uint64_t rng = 0x9e3779b97f4a7c15u;
static float urand(void) /* [-1, 1) */
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return (float)((double)(rng >> 11) / 9007199254740992.0 * 2 - 1);
}

static int check_heightmap(const char *dir)
{
    enum { W = 64, H = 64 };
    char in[4200], out[4200], err[512];
    snprintf(in, sizeof in, "%s/one_rule_nm.exr", dir);
    snprintf(out, sizeof out, "%s/one_rule_d.exr", dir);
    bg_image nm;
    if (bg_image_alloc(&nm, W, H, 3) != BG_OK)
        return 0;
    for (int i = 0; i < W * H * 3; i++)
        nm.pixels[i] = 0.5f * urand() + 0.5f; /* m in [-1, 1): inward ones included */
    nm.pixels[0] = nm.pixels[1] = nm.pixels[2] = 0.5f; /* m = 0 */
    nm.pixels[3] = 1.0f, nm.pixels[4] = 0.5f, nm.pixels[5] = 0.25f; /* (1, 0, -0.5) */
    int ok = bg_image_write(in, &nm, BG_PIXEL_F32, 0, err, sizeof err) == BG_OK;
    bgt_heightmap_opts o = {.input = in, .output = out, .strength = 1.0f, .to_derivative = 1};
    bgt_err e;
    ok = ok && bgt_heightmap_run(&o, &e) == BG_OK;
    bg_image d;
    int bad = 0;
    if (ok && bg_image_read(out, &d, err, sizeof err) == BG_OK) {
        for (int p = 0; p < W * H; p++) {
            const float *s = nm.pixels + 3 * p;
            bg_vec3 m = {2.0f * s[0] - 1.0f, 2.0f * s[1] - 1.0f, 2.0f * s[2] - 1.0f};
            bg_vec2 want = bg_tangent_normal_to_derivs(m);
            if ((memcmp(&d.pixels[3 * p], &want.x, 4) || memcmp(&d.pixels[3 * p + 1], &want.y, 4)) &&
                bad++ < 5)
                printf("  FAIL heightmap texel %d: (%g %g) vs library (%g %g)\n", p,
                       (double)d.pixels[3 * p], (double)d.pixels[3 * p + 1], (double)want.x,
                       (double)want.y);
        }
        ok = d.pixels[3] == -2.0f; /* (1,0,-0.5): mirrored, -1/0.5 */
        bg_image_free(&d);
    } else {
        printf("  FAIL heightmap run: %s\n", ok ? err : e.msg);
        ok = 0;
    }
    bg_image_free(&nm);
    printf("heightmap: %d texels, %d mismatches\n", W * H, bad);
    return ok && bad == 0;
}

int main(int argc, char **argv)
{
    if (argc < 2)
        return 2;
    int ok = check_heightmap(argv[1]);
    printf(ok ? "all checks passed\n" : "FAILED\n");
    return ok ? 0 : 1;
}
