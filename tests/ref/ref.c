/* SPDX-License-Identifier: MIT */
/* Independent double-precision reference (see ref.h). Written from Perlin's
 * published algorithm, not from src/: the permutation is kept as 256 entries and
 * indexed `& 255` (his 512-entry copy is only there to avoid that mask), the
 * gradient uses the trilinear product form instead of differentiating the lerp
 * chain, and the corner gradient vectors are obtained by evaluating grad() on the
 * unit vectors (grad is linear in its offset), not by decoding the hash bits. */
#include "ref.h"

#include <math.h>
#include <stdint.h>

/* Perlin's permutation from "Improving Noise" (SIGGRAPH 2002). */
static const int perm[256] = {
    151, 160, 137, 91,  90,  15,  131, 13,  201, 95,  96,  53,  194, 233, 7,   225, 140, 36,
    103, 30,  69,  142, 8,   99,  37,  240, 21,  10,  23,  190, 6,   148, 247, 120, 234, 75,
    0,   26,  197, 62,  94,  252, 219, 203, 117, 35,  11,  32,  57,  177, 33,  88,  237, 149,
    56,  87,  174, 20,  125, 136, 171, 168, 68,  175, 74,  165, 71,  134, 139, 48,  27,  166,
    77,  146, 158, 231, 83,  111, 229, 122, 60,  211, 133, 230, 220, 105, 92,  41,  55,  46,
    245, 40,  244, 102, 143, 54,  65,  25,  63,  161, 1,   216, 80,  73,  209, 76,  132, 187,
    208, 89,  18,  169, 200, 196, 135, 130, 116, 188, 159, 86,  164, 100, 109, 198, 173, 186,
    3,   64,  52,  217, 226, 250, 124, 123, 5,   202, 38,  147, 118, 126, 255, 82,  85,  212,
    207, 206, 59,  227, 47,  16,  58,  17,  182, 189, 28,  42,  223, 183, 170, 213, 119, 248,
    152, 2,   44,  154, 163, 70,  221, 153, 101, 155, 167, 43,  172, 9,   129, 22,  39,  253,
    19,  98,  108, 110, 79,  113, 224, 232, 178, 185, 112, 104, 218, 246, 97,  228, 251, 34,
    242, 193, 238, 210, 144, 12,  191, 179, 162, 241, 81,  51,  145, 235, 249, 14,  239, 107,
    49,  192, 214, 31,  181, 199, 106, 157, 184, 84,  204, 176, 115, 121, 50,  45,  127, 4,
    150, 254, 138, 236, 205, 93,  222, 114, 67,  29,  24,  72,  243, 141, 128, 195, 78,  66,
    215, 61,  156, 180};

static int P(int i) { return perm[i & 255]; }
int ref_permutation(int i) { return perm[i & 255]; }

/* Perlin's fade 6t^5 - 15t^4 + 10t^3 in his evaluation order (needed for the
 * published value to come out bit for bit). */
static double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }
/* Its derivative 30 t^2 (1 - t)^2, from the polynomial directly. */
static double dfade(double t) { return 30 * t * t * (1 - t) * (1 - t); }
static double lerp(double t, double a, double b) { return a + t * (b - a); }

/* Perlin's grad(): the 12 edge directions (+4 repeats) selected from the low 4
 * bits of the hash, dotted with the offset (x, y, z). */
static double grad(int hash, double x, double y, double z)
{
    int h = hash & 15;
    double u = h < 8 ? x : y;
    double v = h < 4 ? y : (h == 12 || h == 14 ? x : z);
    return ((h & 1) == 0 ? u : -u) + ((h & 2) == 0 ? v : -v);
}

/* Integer cell modulo 256 and fraction. The cell is reduced in floating point
 * before the conversion, so coordinates beyond the int range keep period 256. */
static int cell_of(double x, double *frac)
{
    double fl = floor(x);
    double c = fl - 256.0 * floor(fl / 256.0);
    *frac = x - fl;
    return (int)c & 255;
}

/* The 8 corner hashes, indexed [i + 2j + 4k] for corner offset (i, j, k). */
static void corner_hashes(int X, int Y, int Z, int h[8])
{
    int A = P(X) + Y, AA = P(A) + Z, AB = P(A + 1) + Z;
    int B = P(X + 1) + Y, BA = P(B) + Z, BB = P(B + 1) + Z;
    h[0] = P(AA);
    h[1] = P(BA);
    h[2] = P(AB);
    h[3] = P(BB);
    h[4] = P(AA + 1);
    h[5] = P(BA + 1);
    h[6] = P(AB + 1);
    h[7] = P(BB + 1);
}

double ref_noise(double x, double y, double z)
{
    double fx, fy, fz;
    int X = cell_of(x, &fx), Y = cell_of(y, &fy), Z = cell_of(z, &fz);
    int h[8];
    corner_hashes(X, Y, Z, h);
    double u = fade(fx), v = fade(fy), w = fade(fz);
    return lerp(w,
                lerp(v, lerp(u, grad(h[0], fx, fy, fz), grad(h[1], fx - 1, fy, fz)),
                     lerp(u, grad(h[2], fx, fy - 1, fz), grad(h[3], fx - 1, fy - 1, fz))),
                lerp(v, lerp(u, grad(h[4], fx, fy, fz - 1), grad(h[5], fx - 1, fy, fz - 1)),
                     lerp(u, grad(h[6], fx, fy - 1, fz - 1), grad(h[7], fx - 1, fy - 1, fz - 1))));
}

double ref_noise_grad(double x, double y, double z, double out[3])
{
    double value = ref_noise(x, y, z);
    if (!out)
        return value;
    double f[3];
    int X = cell_of(x, &f[0]), Y = cell_of(y, &f[1]), Z = cell_of(z, &f[2]);
    int h[8];
    corner_hashes(X, Y, Z, h);
    double wt[3][2], dwt[3][2];
    for (int a = 0; a < 3; a++) {
        double s = fade(f[a]), ds = dfade(f[a]);
        wt[a][0] = 1 - s, wt[a][1] = s;
        dwt[a][0] = -ds, dwt[a][1] = ds;
    }
    double g[3] = {0, 0, 0};
    for (int c = 0; c < 8; c++) {
        int i = c & 1, j = (c >> 1) & 1, k = (c >> 2) & 1;
        double d[3] = {f[0] - i, f[1] - j, f[2] - k};
        /* grad() is linear in the offset, so its vector is its value on the axes. */
        double gv[3] = {grad(h[c], 1, 0, 0), grad(h[c], 0, 1, 0), grad(h[c], 0, 0, 1)};
        double dot = gv[0] * d[0] + gv[1] * d[1] + gv[2] * d[2];
        double W = wt[0][i] * wt[1][j] * wt[2][k];
        g[0] += dwt[0][i] * wt[1][j] * wt[2][k] * dot + W * gv[0];
        g[1] += wt[0][i] * dwt[1][j] * wt[2][k] * dot + W * gv[1];
        g[2] += wt[0][i] * wt[1][j] * dwt[2][k] * dot + W * gv[2];
    }
    out[0] = g[0], out[1] = g[1], out[2] = g[2];
    return value;
}

/* Long double noise for the finite-difference check: the trilinear sum written
 * out, with the cell taken from the (double) center so that all samples of one
 * difference share a cell (the caller guarantees that they do). */
static long double noise_ld(const int h[8], long double fx, long double fy, long double fz)
{
    long double f[3] = {fx, fy, fz}, wt[3][2];
    for (int a = 0; a < 3; a++) {
        long double t = f[a];
        long double s = t * t * t * (t * (t * 6 - 15) + 10);
        wt[a][0] = 1 - s, wt[a][1] = s;
    }
    long double sum = 0;
    for (int c = 0; c < 8; c++) {
        int i = c & 1, j = (c >> 1) & 1, k = (c >> 2) & 1;
        long double d[3] = {f[0] - i, f[1] - j, f[2] - k};
        long double dot = grad(h[c], 1, 0, 0) * d[0] + grad(h[c], 0, 1, 0) * d[1] +
                          grad(h[c], 0, 0, 1) * d[2];
        sum += wt[0][i] * wt[1][j] * wt[2][k] * dot;
    }
    return sum;
}

int ref_noise_grad_richardson(double x, double y, double z, double h, double out[3])
{
    double f[3];
    int X = cell_of(x, &f[0]), Y = cell_of(y, &f[1]), Z = cell_of(z, &f[2]);
    for (int a = 0; a < 3; a++)
        if (!(f[a] - h > 0 && f[a] + h < 1))
            return 0;
    int hs[8];
    corner_hashes(X, Y, Z, hs);
    for (int a = 0; a < 3; a++) {
        long double D[2];
        for (int s = 0; s < 2; s++) {
            long double step = (long double)h / (s ? 2 : 1);
            long double p[3] = {f[0], f[1], f[2]}, m[3] = {f[0], f[1], f[2]};
            p[a] += step;
            m[a] -= step;
            D[s] = (noise_ld(hs, p[0], p[1], p[2]) - noise_ld(hs, m[0], m[1], m[2])) / (2 * step);
        }
        out[a] = (double)((4 * D[1] - D[0]) / 3);
    }
    return 1;
}

double ref_fractal_grad(const ref_fractal *f, double x, double y, double z, double grad_out[3],
                        double *min_abs_octave)
{
    int octaves = f->function == REF_NOISE ? 1 : f->octaves;
    double amp = 1, freq = 1, sum = 0, g[3] = {0, 0, 0}, minabs = INFINITY;
    for (int i = 0; i < octaves; i++) {
        double og[3];
        double n = ref_noise_grad(freq * x, freq * y, freq * z, og);
        double s = 1;
        if (f->function == REF_TURBULENCE) {
            s = n < 0 ? -1 : 1;
            sum += amp * fabs(n);
        } else {
            sum += amp * n;
        }
        for (int a = 0; a < 3; a++)
            g[a] += s * amp * freq * og[a];
        if (fabs(n) < minabs)
            minabs = fabs(n);
        amp *= f->gain;
        freq *= f->lacunarity;
    }
    if (grad_out)
        grad_out[0] = g[0], grad_out[1] = g[1], grad_out[2] = g[2];
    if (min_abs_octave)
        *min_abs_octave = minabs;
    return sum;
}

unsigned long ref_fractal_sign_mask(const ref_fractal *f, double x, double y, double z)
{
    int octaves = f->function == REF_NOISE ? 1 : f->octaves;
    double freq = 1;
    unsigned long mask = 0;
    for (int i = 0; i < octaves && i < 32; i++) {
        if (ref_noise(freq * x, freq * y, freq * z) < 0)
            mask |= 1ul << i;
        freq *= f->lacunarity;
    }
    return mask;
}

static void normalize3(const double v[3], double out[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    out[0] = v[0] / l, out[1] = v[1] / l, out[2] = v[2] / l;
}

void ref_surface_gradient(const double n_in[3], const double g[3], double out[3])
{
    double n[3];
    normalize3(n_in, n);
    double d = n[0] * g[0] + n[1] * g[1] + n[2] * g[2];
    for (int a = 0; a < 3; a++)
        out[a] = g[a] - n[a] * d;
}

void ref_perturb_surfgrad(const double n_in[3], const double g[3], double out[3])
{
    double n[3], sg[3], s[3];
    normalize3(n_in, n);
    ref_surface_gradient(n, g, sg);
    for (int a = 0; a < 3; a++)
        s[a] = n[a] - sg[a];
    normalize3(s, out);
}

void ref_perturb_additive(const double n_in[3], const double g[3], double out[3])
{
    double n[3], s[3];
    normalize3(n_in, n);
    for (int a = 0; a < 3; a++)
        s[a] = n[a] - g[a];
    if (s[0] == 0 && s[1] == 0 && s[2] == 0) {
        out[0] = n[0], out[1] = n[1], out[2] = n[2];
        return;
    }
    normalize3(s, out);
}

void ref_rng_seed(ref_rng *r, unsigned long long seed) { r->state = seed; }

unsigned long long ref_rng_u64(ref_rng *r)
{
    uint64_t z = (r->state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

double ref_rng_uniform(ref_rng *r, double lo, double hi)
{
    double u = (double)(ref_rng_u64(r) >> 11) * (1.0 / 9007199254740992.0);
    return lo + (hi - lo) * u;
}

void ref_rng_unit_vector(ref_rng *r, double out[3])
{
    /* Rejection from the cube keeps the distribution uniform on the sphere. */
    for (;;) {
        double v[3] = {ref_rng_uniform(r, -1, 1), ref_rng_uniform(r, -1, 1),
                       ref_rng_uniform(r, -1, 1)};
        double l2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        if (l2 > 1e-4 && l2 <= 1) {
            normalize3(v, out);
            return;
        }
    }
}
