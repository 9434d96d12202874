/* SPDX-License-Identifier: MIT */
/* bgt_stability_run (study.h), the study of `bumpgrad stability`:
 * sweeps that show where each way of bumping a normal fails, written as a
 * markdown report, CSV tables, gnuplot charts and a JSON summary that the
 * tests read:
 *  1. inward normals of the additive method vs the surface gradient (eq. 4)
 *     as the amplitude grows (the paper's Figure 2 claim);
 *  2. the float32 central-difference step U-curve and its optimum;
 *  3. large coordinates: float vs double entry points;
 *  4. turbulence creases: analytic vs central near zero crossings of an octave;
 *  5. Listing 1 at grazing angles, across silhouettes and as det -> 0;
 *  6. degenerate inputs of the perturbation.
 * This file: the output helpers, section 6 and the run; the sweeps are in
 * stability_sweeps.c and stability_listing1.c. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include "stability.h"

void st_json_num(st_out *o, const char *key, double v)
{
    fprintf(o->json, "%s\n  \"%s\": %.10g", o->json_first ? "" : ",", key, v);
    o->json_first = 0;
}

bg_status st_oom(st_out *o) { return bgt_fail(o->e, BG_ERR_OUT_OF_MEMORY, "out of memory"); }

FILE *st_csv_begin(st_out *o, const char *name, bgt_safe_file *of, const char *header,
                   const char *md_fmt, ...)
{
    char *p = study_join(o->dir, name);
    if (!p) {
        st_oom(o);
        return NULL;
    }
    bg_status s = bgt_safe_open(of, p, o->e);
    free(p);
    if (s != BG_OK)
        return NULL;
    fprintf(of->fp, "%s\n", header);
    va_list ap;
    va_start(ap, md_fmt);
    vfprintf(o->md, md_fmt, ap);
    va_end(ap);
    return of->fp;
}

bg_status st_chart(st_out *o, const char *name, const char *csv, const char *title,
                   const char *xlabel, const char *ylabel, int logx, int logy, const char *plot)
{
    if (!o->chart)
        return BG_OK;
    char gpname[96], pngname[96], tmpname[96];
    snprintf(gpname, sizeof gpname, "%s.gp", name);
    snprintf(pngname, sizeof pngname, "%s.png", name);
    snprintf(tmpname, sizeof tmpname, ".%s.tmp.png", name);
    char *gp = study_join(o->dir, gpname), *png = study_join(o->dir, pngname),
         *tmp = study_join(o->dir, tmpname), *data = study_join(o->dir, csv);
    bgt_safe_file of;
    bg_status rc = gp && png && tmp && data ? bgt_safe_open(&of, gp, o->e) : st_oom(o);
    if (rc == BG_OK) {
        fprintf(of.fp,
                "# Made by `bumpgrad stability`; rerun it to regenerate.\n"
                "set datafile separator ','\nset grid\nset key autotitle columnhead\n"
                "set terminal pngcairo size 900,560 noenhanced\nset output '%s'\n"
                "set title '%s'\nset xlabel '%s'\nset ylabel '%s'\n%s%s"
                "data = '%s'\n%s\n",
                tmp, title, xlabel, ylabel, logx ? "set logscale x\nset format x '%.0e'\n" : "",
                logy ? "set logscale y\nset format y '%.0e'\n" : "", data, plot);
        rc = bgt_safe_commit(&of, o->e);
    }
    if (rc == BG_OK) {
        const char *t[1] = {tmp}, *f[1] = {png};
        rc = study_gnuplot(gp, t, f, 1, o->report, o->e);
    }
    if (rc == BG_OK)
        fprintf(o->md, "\n![%s](%s)\n", title, pngname);
    free(gp), free(png), free(tmp), free(data);
    return rc;
}

/* ---- 6. degenerate inputs ---- */
static void st_degenerate(st_out *o)
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

/* Sections 1-6 into the open report and summary. */
static bg_status st_sweeps(st_out *o, size_t samples, const bgt_progress *pr)
{
    bg_status rc;
    size_t n = samples;
    bgt_progress_begin(pr, "stability", 5);
    rc = st_sweep_inward(o, n);
    bgt_progress_update(pr, 1);
    if (!rc)
        rc = st_sweep_step(o, n);
    bgt_progress_update(pr, 2);
    if (!rc)
        rc = st_sweep_large(o);
    bgt_progress_update(pr, 3);
    if (!rc)
        rc = st_sweep_creases(o, n);
    bgt_progress_update(pr, 4);
    if (!rc)
        rc = st_sweep_listing1(o, n / 4 > 1000 ? n / 4 : 1000);
    bgt_progress_end(pr);
    if (!rc)
        st_degenerate(o);
    return rc;
}

bg_status bgt_stability_run(const bgt_stability_opts *opt, bgt_err *e)
{
    bgt_err local;
    if (!e)
        e = &local;
    if (!opt || !opt->out_dir)
        return bgt_fail(e, BG_ERR_NULL_POINTER, "no options or output folder");
    if (opt->samples < 1)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "samples: expected at least 1, got 0");
    bg_status rc = study_mkdir(opt->out_dir, e);
    if (rc != BG_OK)
        return rc;
    st_out o = {opt->out_dir, NULL, NULL, opt->chart, 1, opt->report, e};
    char *mdp = study_join(opt->out_dir, "STABILITY.md"), *jp = study_join(opt->out_dir, "summary.json");
    bgt_safe_file md, js;
    rc = mdp && jp ? bgt_safe_open(&md, mdp, e) : st_oom(&o);
    if (rc == BG_OK && (rc = bgt_safe_open(&js, jp, e)) != BG_OK)
        bgt_safe_abort(&md);
    if (rc == BG_OK) {
        o.md = md.fp, o.json = js.fp;
        fprintf(o.json, "{");
        fprintf(o.md, "# Stability: where bump-mapping methods fail\n\n"
                      "Made by `bumpgrad stability --out %s --samples %zu` (bumpgrad %s, kernels: %s).\n",
                opt->out_dir, opt->samples, bg_version_string(), bg_isa_name(bg_isa_active()));
        rc = st_sweeps(&o, opt->samples, opt->progress);
        fprintf(o.json, "\n}\n");
        if (rc) {
            bgt_safe_abort(&md), bgt_safe_abort(&js);
        } else {
            rc = bgt_safe_commit(&md, e);
            if (rc == BG_OK)
                rc = bgt_safe_commit(&js, e);
            else
                bgt_safe_abort(&js);
        }
    }
    free(mdp), free(jp);
    return rc;
}
