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
 * This file: section 6 and the run; the sweeps are in stability_sweeps.c and
 * stability_listing1.c, and the output helpers they and this file write
 * through in stability_out.c, which calls neither. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "stability.h"

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
