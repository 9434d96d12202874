/* SPDX-License-Identifier: MIT */
/* Sections 1-4 of the stability study (stability.h): inward normals, the
 * float32 central-difference step, large coordinates, turbulence creases. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include "stability.h"

/* ---- 1. inward normals against amplitude ---- */
static void sweep_inward_free(float *px, float *sx, float *q[3])
{
    free(px), free(sx);
    for (int a = 0; a < 3; a++)
        free(q[a]);
}

bg_status st_sweep_inward(st_out *o, size_t n)
{
    /* 9 columns, the scaled positions q and gradients (sx, sy, sz) */
    float *px = malloc(n * sizeof(float) * 9), *sx = malloc(n * sizeof(float) * 3), *q[3];
    for (int a = 0; a < 3; a++)
        q[a] = calloc(n, sizeof(float)); /* zeroed: gcc cannot see n > 0 */
    if (!px || !sx || !q[0] || !q[1] || !q[2]) {
        sweep_inward_free(px, sx, q);
        return st_oom(o);
    }
    float *py = px + n, *pz = py + n, *ox = pz + n, *oy = ox + n, *oz = oy + n;
    float *gx = oz + n, *gy = gx + n, *gz = gy + n;
    uint64_t s = 1;
    for (size_t i = 0; i < n; i++) {
        double v[3];
        study_random_unit(&s, v);
        px[i] = (float)v[0], py[i] = (float)v[1], pz[i] = (float)v[2];
    }
    /* Low-frequency noise, as for the paper's Figure 2; n = p on the unit sphere. */
    const float freq = 2.0f;
    for (size_t i = 0; i < n; i++)
        q[0][i] = px[i] * freq, q[1][i] = py[i] * freq, q[2][i] = pz[i] * freq;
    bg_noise3_grad_batch(q[0], q[1], q[2], n, NULL, gx, gy, gz);
    for (size_t i = 0; i < n; i++)
        gx[i] *= freq, gy[i] *= freq, gz[i] *= freq;
    bgt_safe_file of;
    FILE *f = st_csv_begin(o, "inward.csv", &of, "amplitude,additive_inward_fraction,surfgrad_inward_fraction,additive_perlin_inward_fraction",
                           "\n## 1. Inward normals: additive vs surface gradient\n\n"
                           "Unit sphere, height = A * noise(2 p), n = p, %zu random points. A normal points inward "
                           "when dot(n', n) <= 0.\n\n| amplitude | additive inward | Perlin's + sign inward | surfgrad inward |\n|---|---|---|---|\n",
                           n);
    if (!f) {
        sweep_inward_free(px, sx, q);
        return o->e->status;
    }
    double at1_add = 0, worst_surf = 0;
    float *sy = sx + n, *sz = sy + n;
    static const double amps[] = {0.1, 0.2, 0.3, 0.5, 0.7, 1, 1.5, 2, 3, 5, 7, 10};
    for (size_t k = 0; k < sizeof amps / sizeof amps[0]; k++) {
        float A = (float)amps[k];
        for (size_t i = 0; i < n; i++)
            sx[i] = A * gx[i], sy[i] = A * gy[i], sz[i] = A * gz[i];
        size_t cnt[3] = {0, 0, 0};
        bg_perturb_method ms[3] = {BG_PERTURB_ADDITIVE, BG_PERTURB_SURFGRAD, BG_PERTURB_ADDITIVE_PERLIN};
        for (int m = 0; m < 3; m++) {
            bg_perturb_batch(ms[m], px, py, pz, sx, sy, sz, n, ox, oy, oz);
            for (size_t i = 0; i < n; i++)
                cnt[m] += ox[i] * px[i] + oy[i] * py[i] + oz[i] * pz[i] <= 0;
        }
        double fa = (double)cnt[0] / (double)n, fs = (double)cnt[1] / (double)n,
               fp = (double)cnt[2] / (double)n;
        fprintf(f, "%g,%.6g,%.6g,%.6g\n", amps[k], fa, fs, fp);
        fprintf(o->md, "| %g | %.2f%% | %.2f%% | %.2f%% |\n", amps[k], 100 * fa, 100 * fp, 100 * fs);
        if (amps[k] == 1)
            at1_add = fa;
        if (fs > worst_surf)
            worst_surf = fs;
    }
    bg_status rc = bgt_safe_commit(&of, o->e);
    st_json_num(o, "inward_additive_at_amplitude_1", at1_add);
    st_json_num(o, "inward_surfgrad_max", worst_surf);
    fprintf(o->md, "\nThe surface gradient (eq. 4) keeps n' on the outer side for every amplitude: its "
                   "normal component stays 1 before normalization. The additive method's share of inward "
                   "normals grows with the amplitude (%.1f%% at A = 1).\n", 100 * at1_add);
    if (rc == 0)
        rc = st_chart(o, "inward", "inward.csv", "Inward-pointing normals vs amplitude", "amplitude",
                   "fraction of samples with dot(perturbed n, n) <= 0", 1, 0,
                   "set key left top\nset yrange [-0.03:*]\n"
                   "plot data using 1:2 with linespoints lw 2 title 'additive, n - grad h', "
                   "data using 1:4 with linespoints lw 2 title 'additive with Perlin sign, n + grad h', "
                   "data using 1:3 with linespoints lw 3 dt 2 pt 7 title 'surface gradient (eq. 4): always 0'");
    sweep_inward_free(px, sx, q);
    return rc;
}

/* ---- 2. float32 central-difference step ---- */
bg_status st_sweep_step(st_out *o, size_t n)
{
    bg_fractal f = bg_fractal_default(BG_FUNC_FBM);
    float *x = malloc(n * sizeof(float) * 7), *y = x + n, *z = y + n, *gx = z + n, *gy = gx + n,
          *gz = gy + n, *v = gz + n;
    double *rx = malloc(n * sizeof(double) * 4), *ry = rx + n, *rz = ry + n, *e = rz + n;
    if (!x || !rx) {
        free(x), free(rx);
        return st_oom(o);
    }
    uint64_t s = 2;
    for (size_t i = 0; i < n; i++) {
        x[i] = (float)(16 * study_random01(&s) - 8), y[i] = (float)(16 * study_random01(&s) - 8),
        z[i] = (float)(16 * study_random01(&s) - 8);
        bg_dvec3 g;
        bg_fractal3d_grad(&f, x[i], y[i], z[i], &g);
        rx[i] = g.x, ry[i] = g.y, rz[i] = g.z;
    }
    bgt_safe_file of;
    FILE *fp = st_csv_begin(o, "central_step.csv", &of, "step,fbm_grad_err_mean,fbm_grad_err_p99",
                            "\n## 2. The float32 central-difference step\n\n"
                            "6-octave fBm, %zu random points in [-8, 8]^3; error = |g_central - g_analytic(double)| "
                            "(Euclidean), float32 kernels.\n\n| step h | mean error | p99 error |\n|---|---|---|\n", n);
    if (!fp) {
        free(x), free(rx);
        return o->e->status;
    }
    double best = INFINITY, best_h = 0;
    for (int k = 0; k <= 24; k++) {
        double h = pow(10.0, -7.0 + k * 0.25);
        bg_fractal3_grad_central_batch(&f, (float)h, x, y, z, n, v, gx, gy, gz);
        double sum = 0, p99, mx;
        for (size_t i = 0; i < n; i++) {
            double dx = gx[i] - rx[i], dy = gy[i] - ry[i], dz = gz[i] - rz[i];
            e[i] = sqrt(dx * dx + dy * dy + dz * dz);
            sum += e[i];
        }
        study_percentiles(e, n, 0.99, &p99, &mx);
        fprintf(fp, "%.4g,%.6g,%.6g\n", h, sum / (double)n, p99);
        fprintf(o->md, "| %.3g | %.3g | %.3g |\n", h, sum / (double)n, p99);
        if (sum / (double)n < best)
            best = sum / (double)n, best_h = h;
    }
    bg_status rc = bgt_safe_commit(&of, o->e);
    st_json_num(o, "central_f32_best_step", best_h);
    st_json_num(o, "central_f32_best_mean_error", best);
    fprintf(o->md, "\nRounding error (~eps/h) falls and truncation error (~h^2 f''') rises with h: the "
                   "optimum here is h = %.3g (mean error %.3g). The library default is "
                   "BG_DEFAULT_CENTRAL_STEP = %g.\n", best_h, best, (double)BG_DEFAULT_CENTRAL_STEP);
    if (rc == 0)
        rc = st_chart(o, "central_step", "central_step.csv", "float32 central differences: error vs step",
                   "step h (noise units)", "gradient error", 1, 1,
                   "plot data using 1:2 with linespoints lw 2 title 'fBm gradient error, mean', "
                   "data using 1:3 with linespoints lw 2 title 'fBm gradient error, p99'");
    free(x), free(rx);
    return rc;
}

/* ---- 3. large coordinates ---- */
bg_status st_sweep_large(st_out *o)
{
    bgt_safe_file of;
    FILE *fp = st_csv_begin(o, "large_coords.csv", &of,
                            "base,float_max_err,float_distinct,double_max_err,double_distinct,double_exact",
                            "\n## 3. Large coordinates: float vs double entry points\n\n"
                            "1000 points x = X + k/1024 (k = 0..999), y = 0.3, z = 0.7. Error against the double "
                            "noise at the reduced coordinate (X mod 256) + k/1024, which equals the exact value because "
                            "the noise has period 256. `distinct` counts different output values.\n\n"
                            "| X | float max error | float distinct | double max error | double distinct |\n|---|---|---|---|---|\n");
    if (!fp)
        return o->e->status;
    int exact_1e7 = 0, distinct_1e7 = 0;
    for (int e10 = 3; e10 <= 8; e10++) {
        double X = pow(10.0, e10);
        double red = X - 256.0 * floor(X / 256.0);
        double fmax_err = 0, dmax_err = 0;
        float fv[1000];
        double dv[1000];
        for (int k = 0; k < 1000; k++) {
            double t = k / 1024.0;
            double ref = bg_noise3d(red + t, 0.3, 0.7);
            fv[k] = bg_noise3((float)(X + t), 0.3f, 0.7f);
            dv[k] = bg_noise3d(X + t, 0.3, 0.7);
            fmax_err = fmax(fmax_err, fabs(fv[k] - ref));
            dmax_err = fmax(dmax_err, fabs(dv[k] - ref));
        }
        int fd = 0, dd = 0;
        for (int k = 0; k < 1000; k++) {
            int fn = 1, dn = 1;
            for (int j = 0; j < k; j++) {
                fn &= fv[j] != fv[k];
                dn &= dv[j] != dv[k];
            }
            fd += fn, dd += dn;
        }
        fprintf(fp, "%g,%.6g,%d,%.6g,%d,%d\n", X, fmax_err, fd, dmax_err, dd, dmax_err == 0);
        fprintf(o->md, "| %g | %.3g | %d | %.3g | %d |\n", X, fmax_err, fd, dmax_err, dd);
        if (e10 == 7)
            exact_1e7 = dmax_err == 0, distinct_1e7 = dd;
    }
    bg_status rc = bgt_safe_commit(&of, o->e);
    st_json_num(o, "double_exact_at_1e7", exact_1e7);
    st_json_num(o, "double_distinct_at_1e7", distinct_1e7);
    fprintf(o->md, "\nThe double entry points reduce the lattice cell modulo 256 before any integer "
                   "conversion and stay exact; float coordinates lose the fraction (float spacing at 1e7 is 1), "
                   "so float noise there sits on lattice planes.\n");
    if (rc == 0)
        rc = st_chart(o, "large_coords", "large_coords.csv", "Large coordinates: max error vs base",
                   "base coordinate X", "max |error| (float: 0 not drawn)", 1, 1,
                   "set key left center\nset yrange [1e-18:3]\n"
                   "plot data using 1:($2>0?$2:1/0) with linespoints lw 2 title 'float', "
                   "data using 1:($4>0?$4:1e-17) with linespoints lw 2 dt 2 title 'double (exact: drawn at 1e-17)'");
    return rc;
}

/* ---- 4. turbulence creases ---- */
bg_status st_sweep_creases(st_out *o, size_t n)
{
    bg_fractal f = bg_fractal_default(BG_FUNC_TURBULENCE);
    enum { BINS = 8 };
    static const double edges[BINS + 1] = {0, 1e-5, 1e-4, 1e-3, 3e-3, 1e-2, 3e-2, 1e-1, 2};
    double sum[BINS] = {0}, mx[BINS] = {0};
    size_t cnt[BINS] = {0};
    uint64_t s = 4;
    const double h = 1e-3; /* float32-optimal order of step, evaluated in double */
    for (size_t i = 0; i < n; i++) {
        double x = 8 * study_random01(&s), y = 8 * study_random01(&s), z = 8 * study_random01(&s);
        /* Distance to the nearest crease, in value: min over octaves of |noise_i| / slope. */
        double dist = INFINITY, freq = 1;
        for (int oc = 0; oc < f.octaves; oc++) {
            bg_dvec3 g;
            double v = bg_noise3d_grad(x * freq, y * freq, z * freq, &g);
            double sl = sqrt(g.x * g.x + g.y * g.y + g.z * g.z) * freq;
            if (sl > 0)
                dist = fmin(dist, fabs(v) / sl);
            freq *= 2;
        }
        bg_dvec3 ga, gc;
        bg_fractal3d_grad(&f, x, y, z, &ga);
        bg_fractal3d_grad_central(&f, h, x, y, z, &gc);
        bg_dvec3 n0 = {0, 0, 1}, ga2 = {0.05 * ga.x, 0.05 * ga.y, 0.05 * ga.z},
                 gc2 = {0.05 * gc.x, 0.05 * gc.y, 0.05 * gc.z};
        double ang = bg_angle_degd(bg_perturbd(BG_PERTURB_SURFGRAD, n0, ga2),
                                   bg_perturbd(BG_PERTURB_SURFGRAD, n0, gc2));
        for (int b = 0; b < BINS; b++)
            if (dist >= edges[b] && dist < edges[b + 1]) {
                sum[b] += ang, cnt[b]++, mx[b] = fmax(mx[b], ang);
                break;
            }
    }
    bgt_safe_file of;
    FILE *fp = st_csv_begin(o, "creases.csv", &of, "distance_to_crease,count,mean_angle_deg,max_angle_deg",
                   "\n## 4. Turbulence creases: analytic vs central differences\n\n"
                   "6-octave turbulence, %zu random points, double precision, central step h = %g, normal "
                   "(0,0,1) bumped with amplitude 0.05. Points are binned by their distance to the nearest zero "
                   "crossing of any octave (|noise_i| / |grad noise_i| in world units). Near a crease the "
                   "central difference straddles the kink of |noise| and disagrees with the one-sided analytic "
                   "gradient; away from creases both agree.\n\n| distance to crease | points | mean angle (deg) | max angle (deg) |\n|---|---|---|---|\n",
            n, h);
    if (!fp)
        return o->e->status;
    double near_mean = 0, mid_mean = 0;
    for (int b = 0; b < BINS; b++) {
        double m = cnt[b] ? sum[b] / (double)cnt[b] : 0;
        fprintf(fp, "%g,%zu,%.6g,%.6g\n", edges[b + 1], cnt[b], m, mx[b]);
        fprintf(o->md, "| [%g, %g) | %zu | %.3g | %.3g |\n", edges[b], edges[b + 1], cnt[b], m, mx[b]);
        if (b == 2)
            near_mean = m;
        if (b == 4)
            mid_mean = m;
    }
    bg_status rc = bgt_safe_commit(&of, o->e);
    st_json_num(o, "crease_near_mean_deg", near_mean);
    st_json_num(o, "crease_mid_mean_deg", mid_mean);
    if (rc == 0)
        rc = st_chart(o, "creases", "creases.csv", "Turbulence: analytic vs central near creases",
                   "distance to nearest octave zero crossing (upper bin edge)", "angle between normals (deg)", 1, 1,
                   "plot data using 1:($3>0?$3:1/0) with linespoints lw 2 title 'mean angle error', "
                   "data using 1:($4>0?$4:1/0) with linespoints lw 2 title 'max angle error'");
    return rc;
}
