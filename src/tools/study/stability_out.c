/* SPDX-License-Identifier: MIT */
/* The output of the stability study (stability.h): the JSON summary's
 * numbers, each sweep's CSV and report section, its gnuplot chart. The
 * sweeps (stability_sweeps.c, stability_listing1.c) and the run
 * (stability.c) call these; these call neither. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include "stability.h"

void st_json_num(st_out *o, const char *key, double v)
{
    fprintf(o->json, "%s\n  \"%s\": ", o->json_first ? "" : ",", key);
    /* JSON has no NaN or infinity: a number that is not finite is null. */
    if (isfinite(v))
        fprintf(o->json, "%.10g", v);
    else
        fputs("null", o->json);
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
