/* SPDX-License-Identifier: MIT */
/* `bumpgrad accuracy`: speed against accuracy of every way to get the perturbed
 * normal n' = normalize(n - grad_S h) (Mikkelsen 2010, eq. 2 and 4), measured on
 * the same points with the real batch kernels, against the float64 analytic
 * reference. Writes accuracy.csv and a log-log chart (gnuplot) with the Pareto
 * front marked. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include "cli.h"
#include "study.h"

static const char *const CMD = "accuracy";

typedef struct acc_row {
    char method[32];
    char param[32];
    const char *precision;
    double ns, mean, p99, max;
} acc_row;

typedef struct acc_ctx {
    size_t n;
    float *px, *py, *pz, *nx, *ny, *nz;      /* sample points on the unit sphere, normals */
    double *rx, *ry, *rz;                    /* float64 analytic reference normals */
    float *ox, *oy, *oz, *h0, *h1, *h2, *h3; /* method outputs and scratch */
    float *qx, *qy, *qz;                     /* shifted positions */
    bg_height height;
    int runs;
} acc_ctx;

/* Angle statistics of (ox, oy, oz) against the reference normals. */
static void acc_errors(const acc_ctx *c, const float *ox, const float *oy, const float *oz,
                       acc_row *row)
{
    double *e = malloc(c->n * sizeof *e);
    double sum = 0;
    for (size_t i = 0; i < c->n; i++) {
        bg_dvec3 a = {ox[i], oy[i], oz[i]}, b = {c->rx[i], c->ry[i], c->rz[i]};
        double d = bg_angle_degd(a, b);
        e[i] = isnan(d) ? 180.0 : d; /* a sentinel (0,0,0) counts as the worst error */
        sum += e[i];
    }
    row->mean = sum / (double)c->n;
    study_percentiles(e, c->n, 0.99, &row->p99, &row->max);
    free(e);
}

/* ---- the methods: each fills (ox, oy, oz) for all n points ---- */

static void run_float_fused(acc_ctx *c, const bg_height *h)
{
    bg_perturb_height_batch(h, BG_PERTURB_SURFGRAD, c->px, c->py, c->pz, c->nx, c->ny, c->nz,
                            c->n, NULL, c->ox, c->oy, c->oz);
}

static double *g_d_out[3];
static void run_double(acc_ctx *c, const bg_height *h, int central, double step)
{
    double af = (double)h->amplitude * (double)h->frequency, f = h->frequency;
    for (size_t i = 0; i < c->n; i++) {
        bg_dvec3 g, nn = {c->nx[i], c->ny[i], c->nz[i]};
        double qx = c->px[i] * f, qy = c->py[i] * f, qz = c->pz[i] * f;
        if (central)
            bg_fractal3d_grad_central(&h->fractal, step, qx, qy, qz, &g);
        else
            bg_fractal3d_grad(&h->fractal, qx, qy, qz, &g);
        g.x *= af, g.y *= af, g.z *= af;
        bg_dvec3 r = bg_perturbd(BG_PERTURB_SURFGRAD, nn, g);
        g_d_out[0][i] = r.x, g_d_out[1][i] = r.y, g_d_out[2][i] = r.z;
    }
}

/* Forward differences with the value kernel: (F(q + h e) - F(q)) / ((q + h) - q). */
static void run_forward(acc_ctx *c, float step)
{
    const bg_height *h = &c->height;
    float f = h->frequency, af = h->amplitude * h->frequency;
    for (size_t i = 0; i < c->n; i++)
        c->qx[i] = c->px[i] * f, c->qy[i] = c->py[i] * f, c->qz[i] = c->pz[i] * f;
    bg_fractal3_batch(&h->fractal, c->qx, c->qy, c->qz, c->n, c->h0);
    float *axis[3] = {c->qx, c->qy, c->qz}, *out[3] = {c->h1, c->h2, c->h3};
    for (int a = 0; a < 3; a++) {
        float *q = axis[a];
        for (size_t i = 0; i < c->n; i++)
            q[i] += step;
        bg_fractal3_batch(&h->fractal, c->qx, c->qy, c->qz, c->n, out[a]);
        for (size_t i = 0; i < c->n; i++) {
            float base = (a == 0 ? c->px[i] : a == 1 ? c->py[i] : c->pz[i]) * f;
            float taken = q[i] - base;
            out[a][i] = af * (out[a][i] - c->h0[i]) / taken;
            q[i] = base;
        }
    }
    bg_perturb_batch(BG_PERTURB_SURFGRAD, c->nx, c->ny, c->nz, c->h1, c->h2, c->h3, c->n, c->ox,
                     c->oy, c->oz);
}

/* Listing 1 on 2x2 pixel quads: consecutive groups of 4 samples form a quad whose
 * pixels are at p, p + dx, p + dy, p + dx + dy projected onto the sphere (the
 * density sets |dx| = |dy| = 1 / density in object units). Each pixel evaluates
 * the height once; ddx_fine/ddy_fine are differences inside its row/column pair,
 * as a GPU computes them, then sign(det) and |det| as in Listing 1. */
static void run_listing1(acc_ctx *c)
{
    const bg_height *h = &c->height;
    float f = h->frequency;
    for (size_t i = 0; i < c->n; i++)
        c->qx[i] = c->px[i] * f, c->qy[i] = c->py[i] * f, c->qz[i] = c->pz[i] * f;
    bg_fractal3_batch(&h->fractal, c->qx, c->qy, c->qz, c->n, c->h0);
    for (size_t q = 0; q + 4 <= c->n; q += 4) {
        for (int k = 0; k < 4; k++) {
            size_t i = q + (size_t)k;
            /* quad layout: k = 0 (0,0), 1 (1,0), 2 (0,1), 3 (1,1) */
            size_t xa = q + (size_t)(k & 2), xb = xa + 1;  /* the row pair */
            size_t ya = q + (size_t)(k & 1), yb = ya + 2;  /* the column pair */
            float ssx = c->px[xb] - c->px[xa], ssy = c->py[xb] - c->py[xa], ssz = c->pz[xb] - c->pz[xa];
            float stx = c->px[yb] - c->px[ya], sty = c->py[yb] - c->py[ya], stz = c->pz[yb] - c->pz[ya];
            float dBs = h->amplitude * (c->h0[xb] - c->h0[xa]);
            float dBt = h->amplitude * (c->h0[yb] - c->h0[ya]);
            float nx = c->nx[i], ny = c->ny[i], nz = c->nz[i];
            /* vR1 = cross(vSigmaT, vN), vR2 = cross(vN, vSigmaS), fDet = dot(vSigmaS, vR1) */
            float r1x = sty * nz - stz * ny, r1y = stz * nx - stx * nz, r1z = stx * ny - sty * nx;
            float r2x = ny * ssz - nz * ssy, r2y = nz * ssx - nx * ssz, r2z = nx * ssy - ny * ssx;
            float det = ssx * r1x + ssy * r1y + ssz * r1z;
            float sg = det > 0 ? 1.0f : det < 0 ? -1.0f : 0.0f;
            float gx = sg * (dBs * r1x + dBt * r2x), gy = sg * (dBs * r1y + dBt * r2y),
                  gz = sg * (dBs * r1z + dBt * r2z);
            float ad = fabsf(det);
            float sx = ad * nx - gx, sy = ad * ny - gy, sz = ad * nz - gz;
            float l = sqrtf(sx * sx + sy * sy + sz * sz);
            if (l > 0)
                c->ox[i] = sx / l, c->oy[i] = sy / l, c->oz[i] = sz / l;
            else
                c->ox[i] = c->oy[i] = c->oz[i] = 0;
        }
    }
}

/* Place samples: random unit points; for Listing 1 mode, groups of 4 form a quad
 * with pixel spacing 1/density along a tangent basis, reprojected to the sphere. */
static void place_samples(acc_ctx *c, double density)
{
    uint64_t s = 0x9E3779B97F4A7C15ull;
    for (size_t q = 0; q < c->n; q += 4) {
        double p[3];
        study_random_unit(&s, p);
        double t1[3], t2[3];
        study_tangent_basis(p, t1, t2);
        for (int k = 0; k < 4 && q + (size_t)k < c->n; k++) {
            double d = density > 0 ? 1.0 / density : 0.0;
            double ox = (k & 1) ? d : 0, oy = (k & 2) ? d : 0;
            double v[3] = {p[0] + ox * t1[0] + oy * t2[0], p[1] + ox * t1[1] + oy * t2[1],
                           p[2] + ox * t1[2] + oy * t2[2]};
            double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            if (density <= 0)
                study_random_unit(&s, v), l = 1; /* independent points */
            size_t i = q + (size_t)k;
            c->px[i] = (float)(v[0] / l), c->py[i] = (float)(v[1] / l), c->pz[i] = (float)(v[2] / l);
            c->nx[i] = c->px[i], c->ny[i] = c->py[i], c->nz[i] = c->pz[i];
        }
    }
    /* The reference: float64 analytic gradient and eq. 4 in double. */
    g_d_out[0] = c->rx, g_d_out[1] = c->ry, g_d_out[2] = c->rz;
    run_double(c, &c->height, 0, 0);
}

static double median_time(acc_ctx *c, void (*fn)(acc_ctx *, const void *), const void *arg)
{
    double t[16];
    int runs = c->runs < 16 ? c->runs : 16;
    for (int r = 0; r < runs; r++) {
        double t0 = study_now();
        fn(c, arg);
        t[r] = study_now() - t0;
    }
    return study_median(t, (size_t)runs) * 1e9 / (double)c->n;
}

static void m_fused(acc_ctx *c, const void *a) { run_float_fused(c, (const bg_height *)a); }

/* Footprint-aware fused call: c->h0 holds each sample's footprint (world units). */
static void m_footprint(acc_ctx *c, const void *a)
{
    bg_perturb_height_footprint_batch((const bg_height *)a, BG_PERTURB_SURFGRAD, c->h0, c->px, c->py,
                                      c->pz, c->nx, c->ny, c->nz, c->n, NULL, c->ox, c->oy, c->oz);
}

/* What a pixel of width w around p should show: the average of the exact
 * perturbed normals over the pixel (K x K subsamples on the sphere, double),
 * renormalized. This replaces the point reference for the footprint rows. */
static void supersampled_reference(acc_ctx *c, double w)
{
    enum { K = 6 };
    const bg_height *h = &c->height;
    double af = (double)h->amplitude * h->frequency, f = h->frequency;
    for (size_t i = 0; i < c->n; i++) {
        double p[3] = {c->px[i], c->py[i], c->pz[i]}, t1[3], t2[3], acc[3] = {0, 0, 0};
        study_tangent_basis(p, t1, t2);
        for (int a = 0; a < K; a++)
            for (int b = 0; b < K; b++) {
                double u = ((a + 0.5) / K - 0.5) * w, v = ((b + 0.5) / K - 0.5) * w;
                double q[3] = {p[0] + u * t1[0] + v * t2[0], p[1] + u * t1[1] + v * t2[1],
                               p[2] + u * t1[2] + v * t2[2]};
                double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
                bg_dvec3 nn = {q[0] / l, q[1] / l, q[2] / l}, g;
                bg_fractal3d_grad(&h->fractal, nn.x * f, nn.y * f, nn.z * f, &g);
                g.x *= af, g.y *= af, g.z *= af;
                bg_dvec3 r = bg_perturbd(BG_PERTURB_SURFGRAD, nn, g);
                acc[0] += r.x, acc[1] += r.y, acc[2] += r.z;
            }
        double l = sqrt(acc[0] * acc[0] + acc[1] * acc[1] + acc[2] * acc[2]);
        c->rx[i] = acc[0] / l, c->ry[i] = acc[1] / l, c->rz[i] = acc[2] / l;
        c->h0[i] = (float)w;
    }
}
static void m_double(acc_ctx *c, const void *a)
{
    const double *step = a;
    run_double(c, &c->height, *step > 0, *step);
}
static void m_forward(acc_ctx *c, const void *a) { run_forward(c, *(const float *)a); }
static void m_listing1(acc_ctx *c, const void *a) { (void)a; run_listing1(c); }

static void usage(FILE *fp)
{
    fprintf(fp,
            "usage: bumpgrad accuracy [--out DIR] [--samples N] [--runs R] [height options]\n"
            "\n"
            "Speed against accuracy of every way to get the perturbed normal\n"
            "n' = normalize(n - grad_S h) (Mikkelsen 2010, eq. 2 and 4) on N points of the\n"
            "unit sphere (normal = position): analytic gradient in float32 (fused SIMD batch,\n"
            "best ISA) and float64; central differences in float32 and float64 over steps\n"
            "1e-7..1e-1; forward differences in float32; Listing 1 on 2x2 pixel quads at\n"
            "several pixel densities; the height truncated to fewer octaves. Error: angle in\n"
            "degrees to the float64 analytic reference normal (mean, p99, max). Time: median\n"
            "of R runs, one thread, ns per sample.\n"
            "Rows `fixed-octaves` and `footprint` (param: pixels per unit) compare all six\n"
            "octaves with footprint-aware octaves (bg_perturb_height_footprint_batch); their\n"
            "error is measured against what the pixel should show: the exact normal averaged\n"
            "over the pixel (6x6 supersampling in double).\n"
            "\n"
            "Writes DIR/accuracy.csv (method,param,precision,ns_per_sample,err_mean_deg,\n"
            "err_p99_deg,err_max_deg), DIR/accuracy.gp and, with gnuplot, DIR/accuracy.png\n"
            "and DIR/accuracy.svg (log-log time against mean error, Pareto front marked).\n"
            "\n"
            "  --out DIR       output folder (default accuracy-output)\n"
            "  --samples N     points (default 65536, multiple of 4)\n"
            "  --runs R        timing runs, median taken (default 5)\n"
            "  --no-chart      skip gnuplot\n"
            "Height options (defaults here: turbulence, 6 octaves, amplitude 0.05, frequency 4):\n");
    cli_height_help(fp);
}

int cmd_accuracy(int argc, char **argv)
{
    const char *out_dir = "accuracy-output";
    long samples = 65536, runs = 5;
    int chart = 1;
    cli_height ch;
    cli_height_init(&ch);
    ch.h.amplitude = 0.05f;
    ch.h.frequency = 4.0f;
    for (int i = 1; i < argc; i++) {
        const char *v;
        int r = cli_height_option(CMD, &ch, argc, argv, &i);
        if (r == 1)
            continue;
        if (r != 0)
            return r;
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            usage(stdout);
            return CLI_OK;
        } else if (!strcmp(argv[i], "--out")) {
            if ((r = cli_need_value(CMD, argc, argv, &i, &v)))
                return r;
            out_dir = v;
        } else if (!strcmp(argv[i], "--samples")) {
            if ((r = cli_need_value(CMD, argc, argv, &i, &v)) ||
                (r = cli_parse_int(CMD, "--samples", v, 4, 1L << 26, &samples)))
                return r;
        } else if (!strcmp(argv[i], "--runs")) {
            if ((r = cli_need_value(CMD, argc, argv, &i, &v)) ||
                (r = cli_parse_int(CMD, "--runs", v, 1, 15, &runs)))
                return r;
        } else if (!strcmp(argv[i], "--no-chart")) {
            chart = 0;
        } else {
            return cli_usage_error(CMD, "unknown option '%s' (see bumpgrad accuracy --help)", argv[i]);
        }
    }
    if (ch.grid_path)
        return cli_usage_error(CMD, "--height-grid is not supported here: the study needs an analytic reference");
    if (bg_height_validate(&ch.h) != BG_OK)
        return cli_usage_error(CMD, "invalid height parameters");
    samples &= ~3L;
    if (study_mkdir(CMD, out_dir))
        return CLI_FAIL;

    acc_ctx c;
    memset(&c, 0, sizeof c);
    c.n = (size_t)samples;
    c.height = ch.h;
    c.height.gradient = BG_GRADIENT_ANALYTIC;
    c.runs = (int)runs;
    float **fa[] = {&c.px, &c.py, &c.pz, &c.nx, &c.ny, &c.nz, &c.ox, &c.oy, &c.oz,
                    &c.h0, &c.h1, &c.h2, &c.h3, &c.qx, &c.qy, &c.qz};
    for (size_t k = 0; k < sizeof fa / sizeof fa[0]; k++)
        *fa[k] = malloc(c.n * sizeof(float));
    c.rx = malloc(c.n * sizeof(double)), c.ry = malloc(c.n * sizeof(double)),
    c.rz = malloc(c.n * sizeof(double));
    double *dx = malloc(c.n * sizeof(double)), *dy = malloc(c.n * sizeof(double)),
           *dz = malloc(c.n * sizeof(double));

    /* 43 fixed rows (2 analytic, 2 per central step, 3 forward, 8 footprint,
     * 4 listing1) and one "truncated" row per octave below the count: 64 rows
     * overflowed from --octaves 23 on. */
    acc_row rows[43 + BG_MAX_OCTAVES];
    int nr = 0;
    static const double steps[] = {1e-7, 3e-7, 1e-6, 3e-6, 1e-5, 3e-5, 1e-4,
                                   3e-4, 1e-3, 3e-3, 1e-2, 3e-2, 1e-1};
    const int nsteps = (int)(sizeof steps / sizeof steps[0]);
    cli_progress prog;
    cli_progress_begin(&prog, "accuracy", (size_t)(2 * nsteps + 20));
    size_t done = 0;

    place_samples(&c, 0);
    {
        acc_row *r = &rows[nr++];
        snprintf(r->method, sizeof r->method, "analytic");
        r->param[0] = 0, r->precision = "float32";
        r->ns = median_time(&c, m_fused, &c.height);
        acc_errors(&c, c.ox, c.oy, c.oz, r);
    }
    {
        acc_row *r = &rows[nr++];
        double st = 0;
        g_d_out[0] = dx, g_d_out[1] = dy, g_d_out[2] = dz;
        r->ns = median_time(&c, m_double, &st);
        snprintf(r->method, sizeof r->method, "analytic");
        r->param[0] = 0, r->precision = "float64";
        /* This is the reference itself; its error is 0 by construction. */
        r->mean = r->p99 = r->max = 0;
    }
    cli_progress_update(&prog, done += 2);
    for (int k = 0; k < nsteps; k++) {
        bg_height hc = c.height;
        hc.gradient = BG_GRADIENT_CENTRAL;
        hc.step = (float)steps[k];
        acc_row *r = &rows[nr++];
        snprintf(r->method, sizeof r->method, "central");
        snprintf(r->param, sizeof r->param, "%g", steps[k]);
        r->precision = "float32";
        r->ns = median_time(&c, m_fused, &hc);
        acc_errors(&c, c.ox, c.oy, c.oz, r);
        cli_progress_update(&prog, ++done);

        r = &rows[nr++];
        snprintf(r->method, sizeof r->method, "central");
        snprintf(r->param, sizeof r->param, "%g", steps[k]);
        r->precision = "float64";
        double st = steps[k];
        g_d_out[0] = dx, g_d_out[1] = dy, g_d_out[2] = dz;
        r->ns = median_time(&c, m_double, &st);
        {
            double *e = malloc(c.n * sizeof *e), sum = 0;
            for (size_t i = 0; i < c.n; i++) {
                bg_dvec3 a = {dx[i], dy[i], dz[i]}, b = {c.rx[i], c.ry[i], c.rz[i]};
                e[i] = bg_angle_degd(a, b);
                if (isnan(e[i]))
                    e[i] = 180;
                sum += e[i];
            }
            r->mean = sum / (double)c.n;
            study_percentiles(e, c.n, 0.99, &r->p99, &r->max);
            free(e);
        }
        cli_progress_update(&prog, ++done);
    }
    static const float fsteps[] = {1e-4f, 1e-3f, 1e-2f};
    for (int k = 0; k < 3; k++) {
        acc_row *r = &rows[nr++];
        snprintf(r->method, sizeof r->method, "forward");
        snprintf(r->param, sizeof r->param, "%g", (double)fsteps[k]);
        r->precision = "float32";
        r->ns = median_time(&c, m_forward, &fsteps[k]);
        acc_errors(&c, c.ox, c.oy, c.oz, r);
        cli_progress_update(&prog, ++done);
    }
    for (int oc = 1; oc < c.height.fractal.octaves && c.height.fractal.function != BG_FUNC_NOISE; oc++) {
        bg_height ht = c.height;
        ht.fractal.octaves = oc;
        acc_row *r = &rows[nr++];
        snprintf(r->method, sizeof r->method, "truncated");
        snprintf(r->param, sizeof r->param, "%d", oc);
        r->precision = "float32";
        r->ns = median_time(&c, m_fused, &ht);
        acc_errors(&c, c.ox, c.oy, c.oz, r);
        cli_progress_update(&prog, ++done);
    }
    /* Footprint-aware octaves against fixed 6 octaves, both judged against what
     * the pixel should show (the supersampled normal), at several densities. */
    {
        size_t n_all = c.n;
        c.n = n_all < 8192 ? n_all : 8192;
        static const double fdens[] = {16, 64, 256, 1024};
        for (int k = 0; k < 4; k++) {
            place_samples(&c, 0);
            supersampled_reference(&c, 1.0 / fdens[k]);
            acc_row *r = &rows[nr++];
            snprintf(r->method, sizeof r->method, "fixed-octaves");
            snprintf(r->param, sizeof r->param, "%g", fdens[k]);
            r->precision = "float32";
            r->ns = median_time(&c, m_fused, &c.height);
            acc_errors(&c, c.ox, c.oy, c.oz, r);
            r = &rows[nr++];
            snprintf(r->method, sizeof r->method, "footprint");
            snprintf(r->param, sizeof r->param, "%g", fdens[k]);
            r->precision = "float32";
            r->ns = median_time(&c, m_footprint, &c.height);
            acc_errors(&c, c.ox, c.oy, c.oz, r);
            cli_progress_update(&prog, ++done);
        }
        c.n = n_all;
    }
    /* Listing 1: pixel density in pixels per object unit on the unit sphere. */
    static const double dens[] = {64, 256, 1024, 4096};
    for (int k = 0; k < 4; k++) {
        place_samples(&c, dens[k]);
        acc_row *r = &rows[nr++];
        snprintf(r->method, sizeof r->method, "listing1");
        snprintf(r->param, sizeof r->param, "%g", dens[k]);
        r->precision = "float32";
        r->ns = median_time(&c, m_listing1, NULL);
        acc_errors(&c, c.ox, c.oy, c.oz, r);
        cli_progress_update(&prog, ++done);
    }
    cli_progress_end(&prog);

    /* CSV (temp + rename). */
    char *path = study_join(out_dir, "accuracy.csv");
    cli_outfile of;
    int rc = cli_outfile_open(CMD, path, &of);
    if (rc == 0) {
        fprintf(of.fp, "method,param,precision,ns_per_sample,err_mean_deg,err_p99_deg,err_max_deg\n");
        for (int k = 0; k < nr; k++)
            fprintf(of.fp, "%s,%s,%s,%.4g,%.6g,%.6g,%.6g\n", rows[k].method, rows[k].param,
                    rows[k].precision, rows[k].ns, rows[k].mean, rows[k].p99, rows[k].max);
        rc = cli_outfile_commit(CMD, &of);
    }
    if (rc == 0) {
        printf("%-10s %-8s %-8s %12s %12s %12s %12s\n", "method", "param", "precision",
               "ns/sample", "mean deg", "p99 deg", "max deg");
        for (int k = 0; k < nr; k++)
            printf("%-10s %-8s %-8s %12.3f %12.3g %12.3g %12.3g\n", rows[k].method, rows[k].param,
                   rows[k].precision, rows[k].ns, rows[k].mean, rows[k].p99, rows[k].max);
        printf("wrote %s\n", path);
        if (chart)
            rc = study_chart_accuracy(CMD, out_dir);
    }
    free(path);
    for (size_t k = 0; k < sizeof fa / sizeof fa[0]; k++)
        free(*fa[k]);
    free(c.rx), free(c.ry), free(c.rz), free(dx), free(dy), free(dz);
    return rc;
}
