/* SPDX-License-Identifier: MIT */
/* Section 5 of the stability study (stability.h): Listing 1 (Mikkelsen 2010)
 * where it fails: at grazing angles, as det -> 0, across silhouettes. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include "bumpgrad/framework.h"
#include "stability.h"


/* Listing 1's fDet = dot(sigma_s, cross(sigma_t, n)), reported by the det
 * sweep (the same float operations as inside bg_listing1_normal). */
static float listing1_det(bg_vec3 n, bg_vec3 sigma_s, bg_vec3 sigma_t)
{
    float r1x = sigma_t.y * n.z - sigma_t.z * n.y, r1y = sigma_t.z * n.x - sigma_t.x * n.z,
          r1z = sigma_t.x * n.y - sigma_t.y * n.x;
    return sigma_s.x * r1x + sigma_s.y * r1y + sigma_s.z * r1z;
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
    bg_vec3 ss = {(float)sx[0], (float)sx[1], (float)sx[2]}, st = {(float)sy[0], (float)sy[1], (float)sy[2]};
    bg_vec3 n = {0, 0, 1};
    bg_vec3 r = bg_listing1_normal(n, ss, st, hx - h0, hy - h0);
    *det = listing1_det(n, ss, st);
    bg_dvec3 g;
    bg_fractal3d_grad(f, F * p[0], F * p[1], F * p[2], &g);
    bg_dvec3 nn = {0, 0, 1}, gg = {A * F * g.x, A * F * g.y, A * F * g.z};
    bg_dvec3 ref = bg_perturbd(BG_PERTURB_SURFGRAD, nn, gg);
    bg_dvec3 rd = {r.x, r.y, r.z};
    double a = bg_angle_degd(rd, ref);
    return isnan(a) ? 180 : a;
}

/* The height of every Listing 1 sweep: 0.05 * turbulence(4 p); a pixel covers
 * 1/4096 unit head-on. */
typedef struct l1_setup {
    bg_fractal f;
    double A, F, pix;
    size_t n;
    double *e; /* n errors */
} l1_setup;

/* One row of a Listing 1 sweep: the mean error over u->n random pixels of the
 * plane (seeded with `seed`) with screen derivatives sx, sy; *p99 (if not NULL)
 * its 99th percentile, *det that of the last pixel. */
static double l1_sweep(const l1_setup *u, uint64_t seed, const double sx[3], const double sy[3],
                       double *p99, double *det)
{
    uint64_t s = seed;
    double sum = 0, mx;
    for (size_t i = 0; i < u->n; i++) {
        double p[3] = {8 * study_random01(&s), 8 * study_random01(&s), 0};
        u->e[i] = l1_error(&u->f, u->A, u->F, p, sx, sy, det);
        sum += u->e[i];
    }
    if (p99)
        study_percentiles(u->e, u->n, 0.99, p99, &mx);
    return sum / (double)u->n;
}

static bg_status l1_grazing(st_out *o, const l1_setup *u)
{
    bgt_safe_file of;
    FILE *fp = st_csv_begin(o, "listing1_grazing.csv", &of, "view_angle_deg,mean_angle_deg,p99_angle_deg",
                   "\n## 5. Listing 1 where it fails\n\n"
                   "Plane z = 0, normal +z, height 0.05 * turbulence(4 p), %zu random pixels. A pixel covers "
                   "1/4096 units head-on; at view angle theta from the normal the footprint along one screen axis "
                   "stretches by 1/cos(theta). Error: angle between Listing 1 (float) and the analytic eq. 4 "
                   "normal (double).\n\n### Grazing angles\n\n| view angle (deg) | mean error (deg) | p99 error (deg) |\n|---|---|---|\n",
            u->n);
    if (!fp)
        return o->e->status;
    double err0 = 0, err85 = 0;
    static const double angles[] = {0, 30, 60, 75, 80, 85, 88, 89, 89.5};
    for (size_t k = 0; k < sizeof angles / sizeof angles[0]; k++) {
        double c = cos(angles[k] * 3.14159265358979323846 / 180), p99, det;
        double sx[3] = {u->pix / c, 0, 0}, sy[3] = {0, u->pix, 0};
        double mean = l1_sweep(u, 5, sx, sy, &p99, &det);
        fprintf(fp, "%g,%.6g,%.6g\n", angles[k], mean, p99);
        fprintf(o->md, "| %g | %.3g | %.3g |\n", angles[k], mean, p99);
        if (angles[k] == 0)
            err0 = mean;
        if (angles[k] == 85)
            err85 = mean;
    }
    bg_status rc = bgt_safe_commit(&of, o->e);
    st_json_num(o, "listing1_mean_deg_head_on", err0);
    st_json_num(o, "listing1_mean_deg_85", err85);
    if (rc == BG_OK)
        rc = st_chart(o, "listing1_grazing", "listing1_grazing.csv", "Listing 1 error vs view angle",
                      "angle between view and normal (deg)", "angle error (deg)", 0, 1,
                      "plot data using 1:2 with linespoints lw 2, data using 1:3 with linespoints lw 2");
    return rc;
}

/* det -> 0: the two screen derivatives become parallel (a sliver triangle
 * seen edge-on); Listing 1 divides nothing but scales n by |det|, so the
 * normal collapses onto the height term. */
static bg_status l1_det(st_out *o, const l1_setup *u)
{
    bgt_safe_file of;
    FILE *fd = st_csv_begin(o, "listing1_det.csv", &of, "angle_between_derivatives_deg,abs_det,mean_angle_deg",
                            "\n### det -> 0 (screen derivatives nearly parallel)\n\n"
                            "sigma_t = pix * (cos a, sin a, 0) with a -> 0, sigma_s = (pix, 0, 0).\n\n"
                            "| angle between derivatives (deg) | |det| | mean error (deg) |\n|---|---|---|\n");
    if (!fd)
        return o->e->status;
    static const double bet[] = {90, 30, 10, 3, 1, 0.3, 0.1, 0.01, 0};
    double err_det0 = 0;
    for (size_t k = 0; k < sizeof bet / sizeof bet[0]; k++) {
        double a = bet[k] * 3.14159265358979323846 / 180, det = 0;
        double sx[3] = {u->pix, 0, 0}, sy[3] = {u->pix * cos(a), u->pix * sin(a), 0};
        double mean = l1_sweep(u, 6, sx, sy, NULL, &det);
        fprintf(fd, "%g,%.6g,%.6g\n", bet[k], fabs(det), mean);
        fprintf(o->md, "| %g | %.3g | %.3g |\n", bet[k], fabs(det), mean);
        if (bet[k] == 0)
            err_det0 = mean;
    }
    bg_status rc = bgt_safe_commit(&of, o->e);
    st_json_num(o, "listing1_mean_deg_det0", err_det0);
    fprintf(o->md, "\nAt det = 0 exactly, HLSL's sign(det) = 0 and |det| = 0 would give normalize(0) "
                   "(NaN in a shader); bumpgrad's one rule (bg_listing1_normal) keeps the unperturbed "
                   "normal there, so the error is that of no bump at all.\n");
    return rc;
}

/* Silhouettes: a quad whose neighbour pixel lands on a far surface (depth
 * jump of D units behind): the differences mix two surfaces. */
static void l1_silhouettes(st_out *o, const l1_setup *u)
{
    fprintf(o->md, "\n### Across silhouettes\n\nThe neighbour pixel of the quad lands on another surface D units "
                   "behind (same normal, different height field sample): the finite differences mix two surfaces.\n\n"
                   "| depth jump D | mean error (deg) | p99 error (deg) |\n|---|---|---|\n");
    static const double jumps[] = {0, 0.01, 0.1, 1, 10};
    for (size_t k = 0; k < sizeof jumps / sizeof jumps[0]; k++) {
        double p99, det;
        double sx[3] = {u->pix, 0, -jumps[k]}, sy[3] = {0, u->pix, 0};
        double mean = l1_sweep(u, 7, sx, sy, &p99, &det);
        fprintf(o->md, "| %g | %.3g | %.3g |\n", jumps[k], mean, p99);
    }
}

bg_status st_sweep_listing1(st_out *o, size_t n)
{
    l1_setup u = {bg_fractal_default(BG_FUNC_TURBULENCE), 0.05, 4, 1.0 / 4096, n, malloc(n * sizeof(double))};
    if (!u.e)
        return st_oom(o);
    bg_status rc = l1_grazing(o, &u);
    if (rc == BG_OK)
        rc = l1_det(o, &u);
    if (rc == BG_OK)
        l1_silhouettes(o, &u);
    free(u.e);
    return rc;
}
