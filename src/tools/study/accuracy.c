/* SPDX-License-Identifier: MIT */
/* bgt_accuracy_run (study.h), the study of `bumpgrad accuracy`: speed
 * against accuracy of every way to get the perturbed normal
 * n' = normalize(n - grad_S h) (Mikkelsen 2010, eq. 2 and 4), measured on the
 * same points with the real batch kernels, against the float64 analytic
 * reference. Writes accuracy.csv and a log-log chart (accuracy_chart.c). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bumpgrad/framework.h"
#include "common/safe_file.h"
#include "study_internal.h"

typedef struct acc_ctx {
    size_t n;
    float *px, *py, *pz, *nx, *ny, *nz;      /* sample points on the unit sphere, normals */
    double *rx, *ry, *rz;                    /* float64 analytic reference normals */
    float *ox, *oy, *oz, *h0, *h1, *h2, *h3; /* method outputs and scratch */
    float *qx, *qy, *qz;                     /* shifted positions */
    double *dx, *dy, *dz;                    /* float64 method outputs */
    double *dout[3];                         /* where run_double writes */
    double *err;                             /* per-sample errors, for the statistics */
    bg_height height;
    int runs;
    bgt_accuracy_result *res;
    const bgt_progress *prog;
    size_t done;
} acc_ctx;

/* Mean, p99 and max of the n errors in c->err. */
static void acc_stats(const acc_ctx *c, double sum, bgt_accuracy_row *row)
{
    row->mean = sum / (double)c->n;
    study_percentiles(c->err, c->n, 0.99, &row->p99, &row->max);
}

/* Angle statistics of (ox, oy, oz) against the reference normals. */
static void acc_errors(const acc_ctx *c, const float *ox, const float *oy, const float *oz,
                       bgt_accuracy_row *row)
{
    double sum = 0;
    for (size_t i = 0; i < c->n; i++) {
        bg_dvec3 a = {ox[i], oy[i], oz[i]}, b = {c->rx[i], c->ry[i], c->rz[i]};
        double d = bg_angle_degd(a, b);
        c->err[i] = isnan(d) ? 180.0 : d; /* a sentinel (0,0,0) counts as the worst error */
        sum += c->err[i];
    }
    acc_stats(c, sum, row);
}

/* The same for the float64 outputs (dx, dy, dz). */
static void acc_errors_d(const acc_ctx *c, bgt_accuracy_row *row)
{
    double sum = 0;
    for (size_t i = 0; i < c->n; i++) {
        bg_dvec3 a = {c->dx[i], c->dy[i], c->dz[i]}, b = {c->rx[i], c->ry[i], c->rz[i]};
        c->err[i] = bg_angle_degd(a, b);
        if (isnan(c->err[i]))
            c->err[i] = 180;
        sum += c->err[i];
    }
    acc_stats(c, sum, row);
}


/* ---- the methods: each fills (ox, oy, oz), or dout, for all n points ---- */

static void run_float_fused(acc_ctx *c, const bg_height *h)
{
    bg_perturb_height_batch(h, BG_PERTURB_SURFGRAD, c->px, c->py, c->pz, c->nx, c->ny, c->nz,
                            c->n, NULL, c->ox, c->oy, c->oz);
}

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
        c->dout[0][i] = r.x, c->dout[1][i] = r.y, c->dout[2][i] = r.z;
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
 * as a GPU computes them, then Listing 1 (bg_listing1_normal, framework.h). */
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
            bg_vec3 ss = {c->px[xb] - c->px[xa], c->py[xb] - c->py[xa], c->pz[xb] - c->pz[xa]};
            bg_vec3 st = {c->px[yb] - c->px[ya], c->py[yb] - c->py[ya], c->pz[yb] - c->pz[ya]};
            float dBs = h->amplitude * (c->h0[xb] - c->h0[xa]);
            float dBt = h->amplitude * (c->h0[yb] - c->h0[ya]);
            bg_vec3 n = {c->nx[i], c->ny[i], c->nz[i]};
            bg_vec3 o = bg_listing1_normal(n, ss, st, dBs, dBt);
            c->ox[i] = o.x, c->oy[i] = o.y, c->oz[i] = o.z;
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
    c->dout[0] = c->rx, c->dout[1] = c->ry, c->dout[2] = c->rz;
    run_double(c, &c->height, 0, 0);
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

/* ---- timing: the median of c->runs runs, in ns per sample ---- */

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
static void m_double(acc_ctx *c, const void *a)
{
    const double *step = a;
    run_double(c, &c->height, *step > 0, *step);
}
static void m_forward(acc_ctx *c, const void *a) { run_forward(c, *(const float *)a); }
static void m_listing1(acc_ctx *c, const void *a) { (void)a; run_listing1(c); }

/* ---- the rows ---- */

/* A new row with an empty param. */
static bgt_accuracy_row *row_new(acc_ctx *c, const char *method, const char *precision)
{
    bgt_accuracy_row *r = &c->res->rows[c->res->nrows++];
    snprintf(r->method, sizeof r->method, "%s", method);
    r->param[0] = 0;
    r->precision = precision;
    return r;
}

static void step_done(acc_ctx *c, size_t k)
{
    c->done += k;
    bgt_progress_update(c->prog, c->done);
}

static void measure_analytic(acc_ctx *c)
{
    bgt_accuracy_row *r = row_new(c, "analytic", "float32");
    r->ns = median_time(c, m_fused, &c->height);
    acc_errors(c, c->ox, c->oy, c->oz, r);

    r = row_new(c, "analytic", "float64");
    double st = 0;
    c->dout[0] = c->dx, c->dout[1] = c->dy, c->dout[2] = c->dz;
    r->ns = median_time(c, m_double, &st);
    /* This is the reference itself; its error is 0 by construction. */
    r->mean = r->p99 = r->max = 0;
    step_done(c, 2);
}

static const double central_steps[] = {1e-7, 3e-7, 1e-6, 3e-6, 1e-5, 3e-5, 1e-4,
                                       3e-4, 1e-3, 3e-3, 1e-2, 3e-2, 1e-1};
enum { N_CENTRAL = sizeof central_steps / sizeof central_steps[0] };

static void measure_central(acc_ctx *c)
{
    for (int k = 0; k < N_CENTRAL; k++) {
        bg_height hc = c->height;
        hc.gradient = BG_GRADIENT_CENTRAL;
        hc.step = (float)central_steps[k];
        bgt_accuracy_row *r = row_new(c, "central", "float32");
        snprintf(r->param, sizeof r->param, "%g", central_steps[k]);
        r->ns = median_time(c, m_fused, &hc);
        acc_errors(c, c->ox, c->oy, c->oz, r);
        step_done(c, 1);

        r = row_new(c, "central", "float64");
        snprintf(r->param, sizeof r->param, "%g", central_steps[k]);
        double st = central_steps[k];
        c->dout[0] = c->dx, c->dout[1] = c->dy, c->dout[2] = c->dz;
        r->ns = median_time(c, m_double, &st);
        acc_errors_d(c, r);
        step_done(c, 1);
    }
}

static void measure_forward(acc_ctx *c)
{
    static const float fsteps[] = {1e-4f, 1e-3f, 1e-2f};
    for (int k = 0; k < 3; k++) {
        bgt_accuracy_row *r = row_new(c, "forward", "float32");
        snprintf(r->param, sizeof r->param, "%g", (double)fsteps[k]);
        r->ns = median_time(c, m_forward, &fsteps[k]);
        acc_errors(c, c->ox, c->oy, c->oz, r);
        step_done(c, 1);
    }
}

static void measure_truncated(acc_ctx *c)
{
    for (int oc = 1; oc < c->height.fractal.octaves && c->height.fractal.function != BG_FUNC_NOISE; oc++) {
        bg_height ht = c->height;
        ht.fractal.octaves = oc;
        bgt_accuracy_row *r = row_new(c, "truncated", "float32");
        snprintf(r->param, sizeof r->param, "%d", oc);
        r->ns = median_time(c, m_fused, &ht);
        acc_errors(c, c->ox, c->oy, c->oz, r);
        step_done(c, 1);
    }
}

/* Footprint-aware octaves against fixed 6 octaves, both judged against what
 * the pixel should show (the supersampled normal), at several densities. */
static void measure_footprint(acc_ctx *c)
{
    size_t n_all = c->n;
    c->n = n_all < 8192 ? n_all : 8192;
    static const double fdens[] = {16, 64, 256, 1024};
    for (int k = 0; k < 4; k++) {
        place_samples(c, 0);
        supersampled_reference(c, 1.0 / fdens[k]);
        bgt_accuracy_row *r = row_new(c, "fixed-octaves", "float32");
        snprintf(r->param, sizeof r->param, "%g", fdens[k]);
        r->ns = median_time(c, m_fused, &c->height);
        acc_errors(c, c->ox, c->oy, c->oz, r);
        r = row_new(c, "footprint", "float32");
        snprintf(r->param, sizeof r->param, "%g", fdens[k]);
        r->ns = median_time(c, m_footprint, &c->height);
        acc_errors(c, c->ox, c->oy, c->oz, r);
        step_done(c, 1);
    }
    c->n = n_all;
}

/* Listing 1: pixel density in pixels per object unit on the unit sphere. */
static void measure_listing1(acc_ctx *c)
{
    static const double dens[] = {64, 256, 1024, 4096};
    for (int k = 0; k < 4; k++) {
        place_samples(c, dens[k]);
        bgt_accuracy_row *r = row_new(c, "listing1", "float32");
        snprintf(r->param, sizeof r->param, "%g", dens[k]);
        r->ns = median_time(c, m_listing1, NULL);
        acc_errors(c, c->ox, c->oy, c->oz, r);
        step_done(c, 1);
    }
}

/* ---- buffers, output, the run ---- */

enum { N_FLOAT = 16, N_DOUBLE = 7 };

static void acc_columns(acc_ctx *c, float **fa[N_FLOAT], double **da[N_DOUBLE])
{
    float **f[N_FLOAT] = {&c->px, &c->py, &c->pz, &c->nx, &c->ny, &c->nz, &c->ox, &c->oy,
                          &c->oz, &c->h0, &c->h1, &c->h2, &c->h3, &c->qx, &c->qy, &c->qz};
    double **d[N_DOUBLE] = {&c->rx, &c->ry, &c->rz, &c->dx, &c->dy, &c->dz, &c->err};
    memcpy(fa, f, sizeof f);
    memcpy(da, d, sizeof d);
}

static void acc_free(acc_ctx *c)
{
    float **fa[N_FLOAT];
    double **da[N_DOUBLE];
    acc_columns(c, fa, da);
    for (int k = 0; k < N_FLOAT; k++)
        free(*fa[k]), *fa[k] = NULL;
    for (int k = 0; k < N_DOUBLE; k++)
        free(*da[k]), *da[k] = NULL;
}

/* Allocates every column (BG_OK) or none (BG_ERR_OUT_OF_MEMORY). */
static bg_status acc_alloc(acc_ctx *c, bgt_err *e)
{
    float **fa[N_FLOAT];
    double **da[N_DOUBLE];
    acc_columns(c, fa, da);
    int ok = 1;
    for (int k = 0; k < N_FLOAT; k++)
        ok &= (*fa[k] = malloc(c->n * sizeof(float))) != NULL;
    for (int k = 0; k < N_DOUBLE; k++)
        ok &= (*da[k] = malloc(c->n * sizeof(double))) != NULL;
    if (ok)
        return BG_OK;
    acc_free(c);
    return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
}

static bg_status write_csv(const char *path, const bgt_accuracy_result *r, bgt_err *e)
{
    bgt_safe_file of;
    bg_status s = bgt_safe_open(&of, path, e);
    if (s != BG_OK)
        return s;
    fprintf(of.fp, "method,param,precision,ns_per_sample,err_mean_deg,err_p99_deg,err_max_deg\n");
    for (int k = 0; k < r->nrows; k++) {
        const bgt_accuracy_row *w = &r->rows[k];
        fprintf(of.fp, "%s,%s,%s,%.4g,%.6g,%.6g,%.6g\n", w->method, w->param, w->precision, w->ns,
                w->mean, w->p99, w->max);
    }
    return bgt_safe_commit(&of, e);
}

bg_status bgt_accuracy_run(const bgt_accuracy_opts *o, bgt_accuracy_result *r, bgt_err *e)
{
    if (!o || !r || !o->out_dir)
        return bgt_fail(e, BG_ERR_NULL_POINTER, "no options, result or output folder");
    r->nrows = 0;
    if (o->samples < 4 || o->samples % 4 != 0)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "samples: expected a multiple of 4, got %zu",
                        o->samples);
    if (o->runs < 1 || o->runs > 15)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "runs: expected 1..15, got %d", o->runs);
    if (bg_height_validate(&o->height) != BG_OK)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "invalid height parameters");
    bg_status s = study_mkdir(o->out_dir, e);
    if (s != BG_OK)
        return s;

    acc_ctx c;
    memset(&c, 0, sizeof c);
    c.n = o->samples;
    c.height = o->height;
    c.height.gradient = BG_GRADIENT_ANALYTIC;
    c.runs = o->runs;
    c.res = r;
    c.prog = o->progress;
    char *path = study_join(o->out_dir, "accuracy.csv");
    if (!path)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    if ((s = acc_alloc(&c, e)) != BG_OK) {
        free(path);
        return s;
    }

    bgt_progress_begin(c.prog, "accuracy", (size_t)(2 * N_CENTRAL + 20));
    place_samples(&c, 0);
    measure_analytic(&c);
    measure_central(&c);
    measure_forward(&c);
    measure_truncated(&c);
    measure_footprint(&c);
    measure_listing1(&c);
    bgt_progress_end(c.prog);
    acc_free(&c);

    s = write_csv(path, r, e);
    if (s == BG_OK) {
        study_wrote(o->report, path);
        if (o->chart)
            s = study_chart_accuracy(o->out_dir, o->report, e);
    }
    free(path);
    return s;
}
