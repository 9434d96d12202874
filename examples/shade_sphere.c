/* SPDX-License-Identifier: MIT */
/* shade_sphere: the smallest complete use of bumpgrad. Shades an analytic unit
 * sphere on the CPU with a turbulence bump (Mikkelsen 2010, eq. 4 / Listing 3,
 * through the fused bg_perturb_height_batch), one directional light, and writes
 * a binary PPM (P6).
 *
 *   cc shade_sphere.c $(pkg-config --cflags --libs bumpgrad) -lm -o shade_sphere
 *   ./shade_sphere sphere.ppm [size]
 *
 * The height field is solid (a function of the 3D position), so the sphere
 * needs no UV parametrization: that is the point of the surface gradient. */
#include <bumpgrad.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    if (argc < 2 || argc > 3) {
        fprintf(stderr, "usage: %s OUT.ppm [size]\n", argv[0]);
        return 2;
    }
    const char *out_path = argv[1];
    int size = argc == 3 ? atoi(argv[2]) : 256;
    if (size < 8 || size > 8192) {
        fprintf(stderr, "size must be between 8 and 8192\n");
        return 2;
    }

    /* h(p) = A * turbulence(f p): six octaves, as in the paper's figures. */
    bg_height h = bg_height_default();
    h.frequency = 4.0f;
    h.amplitude = 0.04f;
    bg_status st = bg_height_validate(&h);
    if (st != BG_OK) {
        fprintf(stderr, "height field: %s\n", bg_status_string(st));
        return 1;
    }

    /* One row at a time: SoA arrays of positions and normals (the normal of a
     * unit sphere is its position), then one batch call per row. */
    size_t w = (size_t)size;
    float *buf = malloc(w * 6 * sizeof(float));
    int *cols = malloc(w * sizeof(int)); /* pixel column of each packed sample */
    unsigned char *img = malloc(w * (size_t)size * 3);
    if (!buf || !cols || !img) {
        fprintf(stderr, "out of memory\n");
        free(buf), free(cols), free(img);
        return 1;
    }
    float *px = buf, *py = buf + w, *pz = buf + 2 * w, *ox = buf + 3 * w, *oy = buf + 4 * w,
          *oz = buf + 5 * w;

    const float L[3] = {-0.45f, 0.55f, 0.70f}; /* light direction, towards the light */
    const float Ll = sqrtf(L[0] * L[0] + L[1] * L[1] + L[2] * L[2]);

    for (int row = 0; row < size; row++) {
        float y = 1.0f - 2.0f * ((float)row + 0.5f) / (float)size;
        size_t m = 0;
        for (int col = 0; col < size; col++) {
            float x = 2.0f * ((float)col + 0.5f) / (float)size - 1.0f;
            float r2 = x * x + y * y;
            if (r2 < 1.0f) {
                px[m] = x, py[m] = y, pz[m] = sqrtf(1.0f - r2);
                cols[m] = col;
                m++;
            }
        }
        /* positions double as normals; outputs go to ox/oy/oz */
        bg_perturb_height_batch(&h, BG_PERTURB_SURFGRAD, px, py, pz, px, py, pz, m, NULL, ox, oy,
                                oz);
        unsigned char *line = img + (size_t)row * w * 3;
        for (int col = 0; col < size; col++) {
            line[3 * col] = 24, line[3 * col + 1] = 26, line[3 * col + 2] = 32; /* background */
        }
        for (size_t i = 0; i < m; i++) {
            float ndl = (ox[i] * L[0] + oy[i] * L[1] + oz[i] * L[2]) / Ll;
            float lum = 0.08f + 0.92f * (ndl > 0 ? ndl : 0);
            /* display gamma 2.2, warm stone albedo */
            float g = powf(lum, 1.0f / 2.2f);
            const float albedo[3] = {0.95f, 0.85f, 0.72f};
            int col = cols[i];
            for (int c = 0; c < 3; c++) {
                float v = 255.0f * g * albedo[c] + 0.5f;
                line[3 * col + c] = (unsigned char)(v > 255 ? 255 : v);
            }
        }
    }

    FILE *fp = fopen(out_path, "wb");
    if (!fp) {
        perror(out_path);
        free(buf), free(cols), free(img);
        return 1;
    }
    int ok = fprintf(fp, "P6\n%d %d\n255\n", size, size) > 0 &&
             fwrite(img, 1, w * (size_t)size * 3, fp) == w * (size_t)size * 3;
    ok &= fclose(fp) == 0;
    free(buf), free(cols), free(img);
    if (!ok) {
        fprintf(stderr, "%s: write failed\n", out_path);
        return 1;
    }
    printf("wrote %s (%dx%d, bumpgrad %s, ISA %s)\n", out_path, size, size, bg_version_string(),
           bg_isa_name(bg_isa_active()));
    return 0;
}
