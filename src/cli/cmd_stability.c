/* SPDX-License-Identifier: MIT */
/* `bumpgrad stability`: sweeps that show where each way of bumping a normal
 * fails, written as a markdown report, CSV tables, gnuplot charts and a JSON
 * summary that the tests read:
 *  1. inward normals of the additive method vs the surface gradient (eq. 4)
 *     as the amplitude grows (the paper's Figure 2 claim);
 *  2. the float32 central-difference step U-curve and its optimum;
 *  3. large coordinates: float vs double entry points;
 *  4. turbulence creases: analytic vs central near zero crossings of an octave;
 *  5. Listing 1 at grazing angles, across silhouettes and as det -> 0;
 *  6. degenerate inputs of the perturbation. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "study.h"

static const char *const CMD = "stability";

typedef struct st_out {
    const char *dir;
    FILE *md;   /* the report, built in memory order */
    FILE *json; /* summary for tests */
    int chart;
    int json_first;
} st_out;

static void json_num(st_out *o, const char *key, double v)
{
    fprintf(o->json, "%s\n  \"%s\": %.10g", o->json_first ? "" : ",", key, v);
    o->json_first = 0;
}

/* Writes one CSV (temp + rename) from a header and rows formatted by the caller. */
static FILE *csv_begin(st_out *o, const char *name, cli_outfile *of, const char *header)
{
    char *p = study_join(o->dir, name);
    int rc = cli_outfile_open(CMD, p, of);
    free(p);
    if (rc)
        return NULL;
    fprintf(of->fp, "%s\n", header);
    return of->fp;
}

/* A gnuplot chart of CSV columns (x column, then y columns), log axes as asked. */
static int chart(st_out *o, const char *name, const char *csv, const char *title,
                 const char *xlabel, const char *ylabel, int logx, int logy, const char *plot)
{
    if (!o->chart)
        return 0;
    char gpname[96], pngname[96], tmpname[96];
    snprintf(gpname, sizeof gpname, "%s.gp", name);
    snprintf(pngname, sizeof pngname, "%s.png", name);
    snprintf(tmpname, sizeof tmpname, ".%s.tmp.png", name);
    char *gp = study_join(o->dir, gpname), *png = study_join(o->dir, pngname),
         *tmp = study_join(o->dir, tmpname), *data = study_join(o->dir, csv);
    cli_outfile of;
    int rc = cli_outfile_open(CMD, gp, &of);
    if (rc == 0) {
        fprintf(of.fp,
                "# Made by `bumpgrad stability`; rerun it to regenerate.\n"
                "set datafile separator ','\nset grid\nset key autotitle columnhead\n"
                "set terminal pngcairo size 900,560 noenhanced\nset output '%s'\n"
                "set title '%s'\nset xlabel '%s'\nset ylabel '%s'\n%s%s"
                "data = '%s'\n%s\n",
                tmp, title, xlabel, ylabel, logx ? "set logscale x\nset format x '%.0e'\n" : "",
                logy ? "set logscale y\nset format y '%.0e'\n" : "", data, plot);
        rc = cli_outfile_commit(CMD, &of);
    }
    if (rc == 0) {
        const char *t[1] = {tmp}, *f[1] = {png};
        rc = study_gnuplot(CMD, gp, t, f, 1);
    }
    if (rc == 0)
        fprintf(o->md, "\n![%s](%s)\n", title, pngname);
    free(gp), free(png), free(tmp), free(data);
    return rc;
}

/* ---- 1. inward normals against amplitude ---- */
static int sweep_inward(st_out *o, size_t n)
{
    float *px = malloc(n * sizeof(float) * 9);
    float *py = px + n, *pz = py + n, *ox = pz + n, *oy = ox + n, *oz = oy + n;
    float *gx = oz + n, *gy = gx + n, *gz = gy + n;
    uint64_t s = 1;
    for (size_t i = 0; i < n; i++) {
        double v[3];
        study_random_unit(&s, v);
        px[i] = (float)v[0], py[i] = (float)v[1], pz[i] = (float)v[2];
    }
    /* Low-frequency noise, as for the paper's Figure 2; n = p on the unit sphere. */
    float *q[3];
    for (int a = 0; a < 3; a++)
        q[a] = malloc(n * sizeof(float));
    const float freq = 2.0f;
    for (size_t i = 0; i < n; i++)
        q[0][i] = px[i] * freq, q[1][i] = py[i] * freq, q[2][i] = pz[i] * freq;
    bg_noise3_grad_batch(q[0], q[1], q[2], n, NULL, gx, gy, gz);
    for (size_t i = 0; i < n; i++)
        gx[i] *= freq, gy[i] *= freq, gz[i] *= freq;
    cli_outfile of;
    FILE *f = csv_begin(o, "inward.csv", &of, "amplitude,additive_inward_fraction,surfgrad_inward_fraction,additive_perlin_inward_fraction");
    if (!f) {
        free(px);
        return CLI_FAIL;
    }
    double at1_add = 0, worst_surf = 0;
    float *sx = malloc(n * sizeof(float) * 3), *sy = sx + n, *sz = sy + n;
    fprintf(o->md, "\n## 1. Inward normals: additive vs surface gradient\n\n"
                   "Unit sphere, height = A * noise(2 p), n = p, %zu random points. A normal points inward "
                   "when dot(n', n) <= 0.\n\n| amplitude | additive inward | Perlin's + sign inward | surfgrad inward |\n|---|---|---|---|\n",
            n);
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
    int rc = cli_outfile_commit(CMD, &of);
    json_num(o, "inward_additive_at_amplitude_1", at1_add);
    json_num(o, "inward_surfgrad_max", worst_surf);
    fprintf(o->md, "\nThe surface gradient (eq. 4) keeps n' on the outer side for every amplitude: its "
                   "normal component stays 1 before normalization. The additive method's share of inward "
                   "normals grows with the amplitude (%.1f%% at A = 1).\n", 100 * at1_add);
    if (rc == 0)
        rc = chart(o, "inward", "inward.csv", "Inward-pointing normals vs amplitude", "amplitude",
                   "fraction of samples with dot(perturbed n, n) <= 0", 1, 0,
                   "plot data using 1:2 with linespoints lw 2, data using 1:4 with linespoints lw 2, data using 1:3 with linespoints lw 2");
    free(px), free(sx);
    for (int a = 0; a < 3; a++)
        free(q[a]);
    return rc;
}

/* ---- 2. float32 central-difference step ---- */
static int sweep_step(st_out *o, size_t n)
{
    bg_fractal f = bg_fractal_default(BG_FUNC_FBM);
    float *x = malloc(n * sizeof(float) * 7), *y = x + n, *z = y + n, *gx = z + n, *gy = gx + n,
          *gz = gy + n, *v = gz + n;
    double *rx = malloc(n * sizeof(double) * 3), *ry = rx + n, *rz = ry + n;
    uint64_t s = 2;
    for (size_t i = 0; i < n; i++) {
        x[i] = (float)(16 * study_random01(&s) - 8), y[i] = (float)(16 * study_random01(&s) - 8),
        z[i] = (float)(16 * study_random01(&s) - 8);
        bg_dvec3 g;
        bg_fractal3d_grad(&f, x[i], y[i], z[i], &g);
        rx[i] = g.x, ry[i] = g.y, rz[i] = g.z;
    }
    cli_outfile of;
    FILE *fp = csv_begin(o, "central_step.csv", &of, "step,fbm_grad_err_mean,fbm_grad_err_p99");
    if (!fp) {
        free(x), free(rx);
        return CLI_FAIL;
    }
    fprintf(o->md, "\n## 2. The float32 central-difference step\n\n"
                   "6-octave fBm, %zu random points in [-8, 8]^3; error = |g_central - g_analytic(double)| "
                   "(Euclidean), float32 kernels.\n\n| step h | mean error | p99 error |\n|---|---|---|\n", n);
    double best = INFINITY, best_h = 0;
    double *e = malloc(n * sizeof(double));
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
    int rc = cli_outfile_commit(CMD, &of);
    json_num(o, "central_f32_best_step", best_h);
    json_num(o, "central_f32_best_mean_error", best);
    fprintf(o->md, "\nRounding error (~eps/h) falls and truncation error (~h^2 f''') rises with h: the "
                   "optimum here is h = %.3g (mean error %.3g). The library default is "
                   "BG_DEFAULT_CENTRAL_STEP = %g.\n", best_h, best, (double)BG_DEFAULT_CENTRAL_STEP);
    if (rc == 0)
        rc = chart(o, "central_step", "central_step.csv", "float32 central differences: error vs step",
                   "step h (noise units)", "gradient error", 1, 1,
                   "plot data using 1:2 with linespoints lw 2, data using 1:3 with linespoints lw 2");
    free(x), free(rx), free(e);
    return rc;
}

/* ---- 3. large coordinates ---- */
static int sweep_large(st_out *o)
{
    cli_outfile of;
    FILE *fp = csv_begin(o, "large_coords.csv", &of,
                         "base,float_max_err,float_distinct,double_max_err,double_distinct,double_exact");
    if (!fp)
        return CLI_FAIL;
    fprintf(o->md, "\n## 3. Large coordinates: float vs double entry points\n\n"
                   "1000 points x = X + k/1024 (k = 0..999), y = 0.3, z = 0.7. Error against the double "
                   "noise at the reduced coordinate (X mod 256) + k/1024, which equals the exact value because "
                   "the noise has period 256. `distinct` counts different output values.\n\n"
                   "| X | float max error | float distinct | double max error | double distinct |\n|---|---|---|---|---|\n");
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
    int rc = cli_outfile_commit(CMD, &of);
    json_num(o, "double_exact_at_1e7", exact_1e7);
    json_num(o, "double_distinct_at_1e7", distinct_1e7);
    fprintf(o->md, "\nThe double entry points reduce the lattice cell modulo 256 before any integer "
                   "conversion and stay exact; float coordinates lose the fraction (float spacing at 1e7 is 1), "
                   "so float noise there sits on lattice planes.\n");
    if (rc == 0)
        rc = chart(o, "large_coords", "large_coords.csv", "Large coordinates: max error vs base",
                   "base coordinate X", "max |error| (0 not drawn)", 1, 1,
                   "plot data using 1:($2>0?$2:1/0) with linespoints lw 2 title 'float', data using 1:($4>0?$4:1/0) with linespoints lw 2 title 'double'");
    return rc;
}

/* ---- 4. turbulence creases ---- */
static int sweep_creases(st_out *o, size_t n)
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
    cli_outfile of;
    FILE *fp = csv_begin(o, "creases.csv", &of, "distance_to_crease,count,mean_angle_deg,max_angle_deg");
    if (!fp)
        return CLI_FAIL;
    fprintf(o->md, "\n## 4. Turbulence creases: analytic vs central differences\n\n"
                   "6-octave turbulence, %zu random points, double precision, central step h = %g, normal "
                   "(0,0,1) bumped with amplitude 0.05. Points are binned by their distance to the nearest zero "
                   "crossing of any octave (|noise_i| / |grad noise_i| in world units). Near a crease the "
                   "central difference straddles the kink of |noise| and disagrees with the one-sided analytic "
                   "gradient; away from creases both agree.\n\n| distance to crease | points | mean angle (deg) | max angle (deg) |\n|---|---|---|---|\n",
            n, h);
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
    int rc = cli_outfile_commit(CMD, &of);
    json_num(o, "crease_near_mean_deg", near_mean);
    json_num(o, "crease_mid_mean_deg", mid_mean);
    if (rc == 0)
        rc = chart(o, "creases", "creases.csv", "Turbulence: analytic vs central near creases",
                   "distance to nearest octave zero crossing (upper bin edge)", "angle between normals (deg)", 1, 1,
                   "plot data using 1:($3>0?$3:1/0) with linespoints lw 2, data using 1:($4>0?$4:1/0) with linespoints lw 2");
    return rc;
}

/* ---- 5. Listing 1 where it fails ---- */

/* Listing 1 from one pixel's fine differences (float, as a shader computes it). */
static bg_vec3 listing1(const float ss[3], const float st[3], float dBs, float dBt, const float n[3], float *det_out)
{
    float r1[3] = {st[1] * n[2] - st[2] * n[1], st[2] * n[0] - st[0] * n[2], st[0] * n[1] - st[1] * n[0]};
    float r2[3] = {n[1] * ss[2] - n[2] * ss[1], n[2] * ss[0] - n[0] * ss[2], n[0] * ss[1] - n[1] * ss[0]};
    float det = ss[0] * r1[0] + ss[1] * r1[1] + ss[2] * r1[2];
    float sg = det > 0 ? 1.0f : det < 0 ? -1.0f : 0.0f;
    float ad = fabsf(det);
    bg_vec3 s = {ad * n[0] - sg * (dBs * r1[0] + dBt * r2[0]), ad * n[1] - sg * (dBs * r1[1] + dBt * r2[1]),
                 ad * n[2] - sg * (dBs * r1[2] + dBt * r2[2])};
    float l = sqrtf(s.x * s.x + s.y * s.y + s.z * s.z);
    *det_out = det;
    if (l > 0)
        s.x /= l, s.y /= l, s.z /= l;
    return s;
}

static double height_at(const bg_fractal *f, double A, double F, const double p[3])
{
    return A * bg_fractal3d(f, F * p[0], F * p[1], F * p[2]);
}

/* One Listing 1 sample on the plane z = 0 (normal +z) at p, with screen-space
 * position derivatives sx, sy; returns the angle to the analytic eq. 4 normal. */
static double l1_error(const bg_fractal *f, double A, double F, const double p[3], const double sx[3],
                       const double sy[3], double *det)
{
    double px[3] = {p[0] + sx[0], p[1] + sx[1], p[2] + sx[2]}, py[3] = {p[0] + sy[0], p[1] + sy[1], p[2] + sy[2]};
    float h0 = (float)height_at(f, A, F, p), hx = (float)height_at(f, A, F, px), hy = (float)height_at(f, A, F, py);
    float ss[3] = {(float)sx[0], (float)sx[1], (float)sx[2]}, st[3] = {(float)sy[0], (float)sy[1], (float)sy[2]};
    float n[3] = {0, 0, 1}, d;
    bg_vec3 r = listing1(ss, st, hx - h0, hy - h0, n, &d);
    *det = d;
    bg_dvec3 g;
    bg_fractal3d_grad(f, F * p[0], F * p[1], F * p[2], &g);
    bg_dvec3 nn = {0, 0, 1}, gg = {A * F * g.x, A * F * g.y, A * F * g.z};
    bg_dvec3 ref = bg_perturbd(BG_PERTURB_SURFGRAD, nn, gg);
    bg_dvec3 rd = {r.x, r.y, r.z};
    double a = bg_angle_degd(rd, ref);
    return isnan(a) ? 180 : a;
}

static int sweep_listing1(st_out *o, size_t n)
{
    bg_fractal f = bg_fractal_default(BG_FUNC_TURBULENCE);
    const double A = 0.05, F = 4, pix = 1.0 / 4096; /* a pixel covers 1/4096 unit head-on */
    cli_outfile of;
    FILE *fp = csv_begin(o, "listing1_grazing.csv", &of, "view_angle_deg,mean_angle_deg,p99_angle_deg");
    if (!fp)
        return CLI_FAIL;
    fprintf(o->md, "\n## 5. Listing 1 where it fails\n\n"
                   "Plane z = 0, normal +z, height 0.05 * turbulence(4 p), %zu random pixels. A pixel covers "
                   "1/4096 units head-on; at view angle theta from the normal the footprint along one screen axis "
                   "stretches by 1/cos(theta). Error: angle between Listing 1 (float) and the analytic eq. 4 "
                   "normal (double).\n\n### Grazing angles\n\n| view angle (deg) | mean error (deg) | p99 error (deg) |\n|---|---|---|\n",
            n);
    double *e = malloc(n * sizeof(double));
    double err0 = 0, err85 = 0;
    static const double angles[] = {0, 30, 60, 75, 80, 85, 88, 89, 89.5};
    for (size_t k = 0; k < sizeof angles / sizeof angles[0]; k++) {
        uint64_t s = 5;
        double c = cos(angles[k] * 3.14159265358979323846 / 180), sum = 0, p99, mx, det;
        for (size_t i = 0; i < n; i++) {
            double p[3] = {8 * study_random01(&s), 8 * study_random01(&s), 0};
            double sx[3] = {pix / c, 0, 0}, sy[3] = {0, pix, 0};
            e[i] = l1_error(&f, A, F, p, sx, sy, &det);
            sum += e[i];
        }
        study_percentiles(e, n, 0.99, &p99, &mx);
        fprintf(fp, "%g,%.6g,%.6g\n", angles[k], sum / (double)n, p99);
        fprintf(o->md, "| %g | %.3g | %.3g |\n", angles[k], sum / (double)n, p99);
        if (angles[k] == 0)
            err0 = sum / (double)n;
        if (angles[k] == 85)
            err85 = sum / (double)n;
    }
    int rc = cli_outfile_commit(CMD, &of);
    json_num(o, "listing1_mean_deg_head_on", err0);
    json_num(o, "listing1_mean_deg_85", err85);
    if (rc == 0)
        rc = chart(o, "listing1_grazing", "listing1_grazing.csv", "Listing 1 error vs view angle",
                   "angle between view and normal (deg)", "angle error (deg)", 0, 1,
                   "plot data using 1:2 with linespoints lw 2, data using 1:3 with linespoints lw 2");
    if (rc) {
        free(e);
        return rc;
    }

    /* det -> 0: the two screen derivatives become parallel (a sliver triangle
     * seen edge-on); Listing 1 divides nothing but scales n by |det|, so the
     * normal collapses onto the height term. */
    fprintf(o->md, "\n### det -> 0 (screen derivatives nearly parallel)\n\n"
                   "sigma_t = pix * (cos a, sin a, 0) with a -> 0, sigma_s = (pix, 0, 0).\n\n"
                   "| angle between derivatives (deg) | |det| | mean error (deg) |\n|---|---|---|\n");
    FILE *fd = csv_begin(o, "listing1_det.csv", &of, "angle_between_derivatives_deg,abs_det,mean_angle_deg");
    if (!fd) {
        free(e);
        return CLI_FAIL;
    }
    static const double bet[] = {90, 30, 10, 3, 1, 0.3, 0.1, 0.01, 0};
    double err_det0 = 0;
    for (size_t k = 0; k < sizeof bet / sizeof bet[0]; k++) {
        uint64_t s = 6;
        double a = bet[k] * 3.14159265358979323846 / 180, sum = 0, det = 0;
        for (size_t i = 0; i < n; i++) {
            double p[3] = {8 * study_random01(&s), 8 * study_random01(&s), 0};
            double sx[3] = {pix, 0, 0}, sy[3] = {pix * cos(a), pix * sin(a), 0};
            sum += l1_error(&f, A, F, p, sx, sy, &det);
        }
        fprintf(fd, "%g,%.6g,%.6g\n", bet[k], fabs(det), sum / (double)n);
        fprintf(o->md, "| %g | %.3g | %.3g |\n", bet[k], fabs(det), sum / (double)n);
        if (bet[k] == 0)
            err_det0 = sum / (double)n;
    }
    rc = cli_outfile_commit(CMD, &of);
    json_num(o, "listing1_mean_deg_det0", err_det0);
    fprintf(o->md, "\nAt det = 0 exactly, sign(det) = 0 and |det| = 0: Listing 1 returns normalize(0), "
                   "which we count as a 180 degree error (a shader gets NaN).\n");

    /* Silhouettes: a quad whose neighbour pixel lands on a far surface (depth
     * jump of D units behind): the differences mix two surfaces. */
    fprintf(o->md, "\n### Across silhouettes\n\nThe neighbour pixel of the quad lands on another surface D units "
                   "behind (same normal, different height field sample): the finite differences mix two surfaces.\n\n"
                   "| depth jump D | mean error (deg) | p99 error (deg) |\n|---|---|---|\n");
    static const double jumps[] = {0, 0.01, 0.1, 1, 10};
    for (size_t k = 0; k < sizeof jumps / sizeof jumps[0]; k++) {
        uint64_t s = 7;
        double sum = 0, p99, mx, det;
        for (size_t i = 0; i < n; i++) {
            double p[3] = {8 * study_random01(&s), 8 * study_random01(&s), 0};
            double sx[3] = {pix, 0, -jumps[k]}, sy[3] = {0, pix, 0};
            e[i] = l1_error(&f, A, F, p, sx, sy, &det);
            sum += e[i];
        }
        study_percentiles(e, n, 0.99, &p99, &mx);
        fprintf(o->md, "| %g | %.3g | %.3g |\n", jumps[k], sum / (double)n, p99);
    }
    free(e);
    return rc;
}

/* ---- 6. degenerate inputs ---- */
static void degenerate(st_out *o)
{
    fprintf(o->md, "\n## 6. Degenerate inputs of the perturbation\n\n"
                   "Computed by the library now (bg_perturb, float; the batch and every ISA give the same bits).\n\n"
                   "| n | g | surfgrad n' | additive n' |\n|---|---|---|---|\n");
    const float inf = INFINITY, nan = NAN;
    struct {
        const char *nd, *gd;
        bg_vec3 n, g;
    } cases[] = {
        {"(0,0,1)", "(0,0,0)", {0, 0, 1}, {0, 0, 0}},
        {"(0,0,2) non-unit", "(1,0,0)", {0, 0, 2}, {1, 0, 0}},
        {"(0,0,0)", "(1,0,0)", {0, 0, 0}, {1, 0, 0}},
        {"(NaN,0,1)", "(1,0,0)", {nan, 0, 1}, {1, 0, 0}},
        {"(Inf,0,1)", "(1,0,0)", {inf, 0, 1}, {1, 0, 0}},
        {"(0,0,1)", "(NaN,0,0)", {0, 0, 1}, {nan, 0, 0}},
        {"(0,0,1)", "(Inf,0,0)", {0, 0, 1}, {inf, 0, 0}},
        {"(0,0,1)", "(1e30,0,0)", {0, 0, 1}, {1e30f, 0, 0}},
        {"(0,0,1)", "(0,0,1) (= n)", {0, 0, 1}, {0, 0, 1}},
        {"(0,0,1)", "(0,0,5) (along n)", {0, 0, 1}, {0, 0, 5}},
        {"(1e-30,0,0) tiny", "(0,1,0)", {1e-30f, 0, 0}, {0, 1, 0}},
        {"(3e38,3e38,0) huge", "(0,0,1)", {3e38f, 3e38f, 0}, {0, 0, 1}},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        bg_vec3 a = bg_perturb_normal(cases[k].n, cases[k].g);
        bg_vec3 b = bg_perturb_normal_additive(cases[k].n, cases[k].g);
        fprintf(o->md, "| %s | %s | (%.4g, %.4g, %.4g) | (%.4g, %.4g, %.4g) |\n", cases[k].nd, cases[k].gd,
                (double)a.x, (double)a.y, (double)a.z, (double)b.x, (double)b.y, (double)b.z);
    }
    fprintf(o->md, "\nRules (include/bumpgrad/surfgrad.h): zero or non-finite n gives the (0,0,0) sentinel; a "
                   "non-finite g leaves the unit n unperturbed; a huge finite g is rescaled so nothing overflows; "
                   "additive with n - g = 0 gives the unit n.\n");
}

static void usage(FILE *fp)
{
    fprintf(fp,
            "usage: bumpgrad stability [--out DIR] [--samples N] [--no-chart]\n"
            "\n"
            "Sweeps where bump-mapping methods fail and writes DIR/STABILITY.md (the report),\n"
            "one CSV and one PNG chart per sweep (gnuplot), and DIR/summary.json:\n"
            "  1. inward normals of additive vs surface gradient as the amplitude grows 0.1..10\n"
            "  2. the float32 central-difference step U-curve and its optimum\n"
            "  3. large coordinates 1e3..1e8: float vs double entry points\n"
            "  4. turbulence creases: analytic vs central near octave zero crossings\n"
            "  5. Listing 1 at grazing angles, as det -> 0, across silhouettes\n"
            "  6. degenerate inputs (zero, NaN, Inf, non-unit normals, huge gradients)\n"
            "\n"
            "  --out DIR     output folder (default stability-output)\n"
            "  --samples N   points per sweep (default 20000)\n"
            "  --no-chart    skip gnuplot\n");
}

int cmd_stability(int argc, char **argv)
{
    const char *out_dir = "stability-output";
    long samples = 20000;
    int charts = 1;
    for (int i = 1; i < argc; i++) {
        const char *v;
        int r;
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            usage(stdout);
            return CLI_OK;
        } else if (!strcmp(argv[i], "--out")) {
            if ((r = cli_need_value(CMD, argc, argv, &i, &v)))
                return r;
            out_dir = v;
        } else if (!strcmp(argv[i], "--samples")) {
            if ((r = cli_need_value(CMD, argc, argv, &i, &v)) ||
                (r = cli_parse_int(CMD, "--samples", v, 100, 10000000, &samples)))
                return r;
        } else if (!strcmp(argv[i], "--no-chart")) {
            charts = 0;
        } else {
            return cli_usage_error(CMD, "unknown option '%s' (see bumpgrad stability --help)", argv[i]);
        }
    }
    if (study_mkdir(CMD, out_dir))
        return CLI_FAIL;
    st_out o = {out_dir, NULL, NULL, charts, 1};
    char *mdp = study_join(out_dir, "STABILITY.md"), *jp = study_join(out_dir, "summary.json");
    cli_outfile md, js;
    int rc = cli_outfile_open(CMD, mdp, &md);
    if (rc == 0 && (rc = cli_outfile_open(CMD, jp, &js)) != 0)
        cli_outfile_abort(&md);
    if (rc == 0) {
        o.md = md.fp, o.json = js.fp;
        fprintf(o.json, "{");
        fprintf(o.md, "# Stability: where bump-mapping methods fail\n\n"
                      "Made by `bumpgrad stability --out %s --samples %ld` (bumpgrad %s, kernels: %s).\n",
                out_dir, samples, bg_version_string(), bg_isa_name(bg_isa_active()));
        size_t n = (size_t)samples;
        cli_progress pr;
        cli_progress_begin(&pr, "stability", 5);
        if (!rc) rc = sweep_inward(&o, n);
        cli_progress_update(&pr, 1);
        if (!rc) rc = sweep_step(&o, n);
        cli_progress_update(&pr, 2);
        if (!rc) rc = sweep_large(&o);
        cli_progress_update(&pr, 3);
        if (!rc) rc = sweep_creases(&o, n);
        cli_progress_update(&pr, 4);
        if (!rc) rc = sweep_listing1(&o, n / 4 > 1000 ? n / 4 : 1000);
        cli_progress_end(&pr);
        if (!rc)
            degenerate(&o);
        fprintf(o.json, "\n}\n");
        if (rc) {
            cli_outfile_abort(&md), cli_outfile_abort(&js);
        } else {
            rc = cli_outfile_commit(CMD, &md);
            if (rc == 0)
                rc = cli_outfile_commit(CMD, &js);
            else
                cli_outfile_abort(&js);
        }
    }
    if (rc == 0)
        printf("wrote %s and %s\n", mdp, jp);
    free(mdp), free(jp);
    return rc;
}
