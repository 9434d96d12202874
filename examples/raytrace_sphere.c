/* SPDX-License-Identifier: MIT */
/* raytrace_sphere: how a ray tracer uses bumpgrad. A pinhole camera shoots one
 * ray per pixel at a unit sphere; at each hit the ray differentials give dP/dx
 * and dP/dy (bg_ray_differentials), their footprint on the surface
 * (bg_footprint_from_differentials) tells the fused bump call which octaves of
 * the solid turbulence the pixel can show, and the surface gradient bumps the
 * normal (Mikkelsen 2010, eq. 4). Octaves finer than a pixel fade out instead
 * of aliasing, most visibly towards the silhouette where the footprint grows.
 * Writes a binary PPM (P6) through a temporary file renamed on success.
 *
 *   cc raytrace_sphere.c $(pkg-config --cflags --libs bumpgrad) -lm -o raytrace_sphere
 *   ./raytrace_sphere out.ppm [size] [--no-footprint]
 */
#include <bumpgrad.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static bg_vec3 vec(float x, float y, float z)
{
    bg_vec3 v = {x, y, z};
    return v;
}

static float dot(bg_vec3 a, bg_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

static bg_vec3 mad(bg_vec3 a, float s, bg_vec3 b) /* a + s b */
{
    return vec(a.x + s * b.x, a.y + s * b.y, a.z + s * b.z);
}

static int write_ppm(const char *path, const unsigned char *rgb, int w, int h)
{
    char tmp[4096];
    if (snprintf(tmp, sizeof tmp, "%s.tmp", path) >= (int)sizeof tmp)
        return 0;
    FILE *fp = fopen(tmp, "wb");
    if (!fp)
        return 0;
    size_t n = (size_t)w * (size_t)h * 3;
    int ok = fprintf(fp, "P6\n%d %d\n255\n", w, h) > 0 && fwrite(rgb, 1, n, fp) == n;
    ok &= fclose(fp) == 0;
    if (!ok || rename(tmp, path) != 0) {
        remove(tmp);
        return 0;
    }
    return 1;
}

int main(int argc, char **argv)
{
    int size = 320, footprint_on = 1;
    const char *out = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--no-footprint") == 0)
            footprint_on = 0;
        else if (!out)
            out = argv[i];
        else
            size = atoi(argv[i]);
    }
    if (!out || size < 8 || size > 8192) {
        fprintf(stderr, "usage: %s OUT.ppm [size 8..8192] [--no-footprint]\n", argv[0]);
        return 2;
    }

    /* h(p) = A turbulence(f p): six octaves, fine enough that the last ones are
     * below a pixel over most of the sphere at the default size. */
    bg_height h = bg_height_default();
    h.frequency = 24.0f;
    h.amplitude = 0.006f;
    if (bg_height_validate(&h) != BG_OK)
        return 1;

    /* Camera at z = 3 looking down -z, 40 degree field of view. The ray
     * direction is unnormalized, dir = fwd + sx right + sy up, so its per-pixel
     * derivatives are constant: ddx = right * (2 t / W), ddy = -up * (2 t / H). */
    const bg_vec3 eye = vec(0, 0, 3), fwd = vec(0, 0, -1), right = vec(1, 0, 0), up = vec(0, 1, 0);
    const float t = tanf(20.0f * 3.14159265f / 180.0f);
    const bg_vec3 ddx = vec(2 * t / size, 0, 0), ddy = vec(0, -2 * t / size, 0);
    const bg_vec3 light = vec(-0.5f, 0.6f, 0.62f); /* towards the light, unit */

    size_t w = (size_t)size;
    float *buf = malloc(w * 10 * sizeof(float));
    int *cols = malloc(w * sizeof(int));
    unsigned char *img = malloc(w * w * 3);
    if (!buf || !cols || !img) {
        fprintf(stderr, "out of memory\n");
        free(buf), free(cols), free(img);
        return 1;
    }
    float *px = buf, *py = px + w, *pz = py + w, *nx = pz + w, *ny = nx + w, *nz = ny + w,
          *fp = nz + w, *ox = fp + w, *oy = ox + w, *oz = oy + w;
    double octaves_sum = 0;
    size_t hits = 0;

    for (int row = 0; row < size; row++) {
        size_t m = 0;
        for (int col = 0; col < size; col++) {
            float sx = t * (2.0f * (col + 0.5f) / size - 1.0f), sy = t * (1.0f - 2.0f * (row + 0.5f) / size);
            bg_vec3 dir = mad(mad(fwd, sx, right), sy, up);
            /* |eye + s dir| = 1: a s^2 + 2 b s + c = 0 */
            float a = dot(dir, dir), b = dot(eye, dir), c = dot(eye, eye) - 1.0f;
            float disc = b * b - a * c;
            if (disc < 0)
                continue;
            float s = (-b - sqrtf(disc)) / a;
            bg_vec3 p = mad(eye, s, dir); /* on the unit sphere: p is its normal */
            bg_vec3 dpdx, dpdy;
            bg_ray_differentials(p, p, eye, dir, ddx, ddy, &dpdx, &dpdy);
            px[m] = nx[m] = p.x, py[m] = ny[m] = p.y, pz[m] = nz[m] = p.z;
            fp[m] = footprint_on ? bg_footprint_from_differentials(dpdx, dpdy) : 0.0f;
            octaves_sum += bg_octaves_for_footprint(fp[m] * h.frequency, h.fractal.octaves);
            cols[m++] = col;
        }
        /* One batch per row: footprint in world units (times h.frequency inside). */
        if (bg_perturb_height_footprint_batch(&h, BG_PERTURB_SURFGRAD, fp, px, py, pz, nx, ny, nz, m,
                                              NULL, ox, oy, oz) != BG_OK)
            return 1;
        unsigned char *line = img + (size_t)row * w * 3;
        for (int col = 0; col < size; col++)
            line[3 * col] = 24, line[3 * col + 1] = 26, line[3 * col + 2] = 32;
        for (size_t i = 0; i < m; i++) {
            float ndl = dot(vec(ox[i], oy[i], oz[i]), light);
            float g = powf(0.06f + 0.94f * (ndl > 0 ? ndl : 0), 1.0f / 2.2f);
            const float albedo[3] = {0.80f, 0.88f, 0.96f};
            for (int k = 0; k < 3; k++)
                line[3 * cols[i] + k] = (unsigned char)(255.0f * g * albedo[k] + 0.5f);
        }
        hits += m;
    }
    free(buf), free(cols);
    int ok = write_ppm(out, img, size, size);
    free(img);
    if (!ok) {
        fprintf(stderr, "%s: cannot write\n", out);
        return 1;
    }
    printf("wrote %s (%dx%d): %zu hits, %.2f octaves per hit on average (%s)\n", out, size, size,
           hits, hits ? octaves_sum / (double)hits : 0.0,
           footprint_on ? "footprint from ray differentials" : "no footprint: all 6 octaves");
    /* With the footprint some octaves are dropped (all of them for a small
     * image: every pixel is wider than the finest cell); without it, none. */
    double avg = hits ? octaves_sum / (double)hits : 0.0;
    return hits > 0 && (footprint_on ? avg < 6.0 : avg == 6.0) ? 0 : 1;
}
