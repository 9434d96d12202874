/* SPDX-License-Identifier: MIT */
/* The table pass of eval and perturb (points_internal.h). As dav1d's tools/output picks
 * a muxer, the pass picks a reader and a writer once, by the file name, from
 * the lists below; the first that claims the name wins and the last claims
 * every name. */
#define _POSIX_C_SOURCE 200809L /* fseeko */
#include "points_internal.h"
#include <errno.h>
#include <stdint.h>
#include <sys/types.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "common/csv.h"
#include "common/npy.h"
#include "common/parallel.h"
#include "common/safe_file.h"

/* ---- readers ---- */

typedef struct table_in {
    bgt_csv csv; /* a CSV input; zeroed (no id, no extras) for the others */
    bgt_npy_in np;
} table_in;

typedef struct table_reader {
    int (*claims)(const char *path);
    bg_status (*open)(table_in *t, bgt_err *e, const char *path, const bgt_table_pass *p);
    bg_status (*read)(table_in *t, const bgt_table_pass *p, size_t *rows);
    size_t (*size)(const table_in *t);     /* bytes, 0 if unknown */
    size_t (*consumed)(const table_in *t); /* bytes read so far */
    void (*close)(table_in *t);
} table_reader;

/* A .npy name; "-" (standard input) is always CSV. */
static int npy_claims(const char *path) { return strcmp(path, "-") != 0 && bgt_npy_path(path); }
static int any_claims(const char *path) { return (void)path, 1; }

static bg_status npy_open(table_in *t, bgt_err *e, const char *path, const bgt_table_pass *p)
{
    size_t want = (size_t)p->count;
    bg_status rc = bgt_npy_open(&t->np, e, path, p->allow_nonfinite, &want, 1);
    if (!rc && p->range.have) {
        /* Rows begin..end-1: seek to the first, stop after the last. */
        bgt_npy_in *a = &t->np;
        size_t end = p->range.end == SIZE_MAX ? a->rows : p->range.end;
        if (p->range.begin > end || end > a->rows)
            rc = bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                          "--rows %zu:%zu: %s has %zu rows (A <= B <= rows)", p->range.begin,
                          end, path, a->rows);
        else if (fseeko(a->fp, (off_t)(a->data_off + p->range.begin * a->cols *
                                                         (a->f64 ? 8u : 4u)), SEEK_SET) != 0)
            rc = bgt_fail(e, BG_ERR_IO, "%s: cannot seek to row %zu: %s", path, p->range.begin,
                          strerror(errno));
        else
            a->row = p->range.begin, a->rows = end;
    }
    if (rc)
        bgt_npy_close(&t->np);
    return rc;
}

static bg_status npy_read(table_in *t, const bgt_table_pass *p, size_t *rows)
{
    return bgt_npy_read(&t->np, p->dbl, p->fcols, p->dcols, p->block, rows);
}

static size_t npy_size(const table_in *t) { return t->np.size; }

static size_t npy_consumed(const table_in *t)
{
    return t->np.data_off + t->np.row * t->np.cols * (t->np.f64 ? 8 : 4);
}

static void npy_close(table_in *t) { bgt_npy_close(&t->np); }

static bg_status csv_open(table_in *t, bgt_err *e, const char *path, const bgt_table_pass *p)
{
    if (p->range.have)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--rows: needs a .npy input (%s: CSV rows have no fixed size; split "
                        "the file instead)", path);
    bg_status rc = bgt_csv_open(&t->csv, e, path, p->allow_nonfinite);
    if (rc)
        return rc;
    if ((rc = bgt_csv_header_map(&t->csv, p->names, p->count)))
        bgt_csv_close(&t->csv);
    return rc;
}

static bg_status csv_read(table_in *t, const bgt_table_pass *p, size_t *rows)
{
    return p->dbl ? bgt_csv_read_double(&t->csv, p->count, p->dcols, p->block, rows)
                  : bgt_csv_read_float(&t->csv, p->count, p->fcols, p->block, rows);
}

static size_t csv_size(const table_in *t) { return t->csv.size; }
static size_t csv_consumed(const table_in *t) { return t->csv.consumed; }
static void csv_close(table_in *t) { bgt_csv_close(&t->csv); }

static const table_reader readers[] = {
    {npy_claims, npy_open, npy_read, npy_size, npy_consumed, npy_close},
    {any_claims, csv_open, csv_read, csv_size, csv_consumed, csv_close},
};

/* ---- writers ---- */

#define TABLE_MAX_COLS 12 /* output columns a pass may have (eval 7, perturb 11) */

typedef struct table_out {
    FILE *fp;
    const bgt_table_pass *p;
    const bgt_csv *in; /* the input's id and extra columns (none for .npy input) */
    bgt_npy_out npy;
} table_out;

typedef struct table_writer {
    int (*claims)(const char *path);
    bg_status (*begin)(table_out *o, bgt_err *e);
    void (*write)(table_out *o, size_t rows);
    bg_status (*finish)(table_out *o, const char *name, bgt_err *e);
} table_writer;

static bg_status npy_begin(table_out *o, bgt_err *e)
{
    return bgt_npy_begin(&o->npy, o->fp, o->p->dbl, (size_t)o->p->cols, e);
}

static void npy_write(table_out *o, size_t rows)
{
    bgt_npy_write(&o->npy, (const float *const *)o->p->fcols, (const double *const *)o->p->dcols,
                  rows);
}

static bg_status npy_finish(table_out *o, const char *name, bgt_err *e)
{
    return bgt_npy_finish(&o->npy, name, e);
}

static bg_status csv_begin(table_out *o, bgt_err *e)
{
    (void)e;
    bgt_csv_write_header(o->fp, o->in, o->p->csv_header);
    return BG_OK;
}

/* [id,]c0,c1,...[,extra...] per row: %.17g in double, %.9g in float (both
 * read back to the same value), the trailing flag columns as 0 or 1. One
 * fprintf a row, with a format built once and always TABLE_MAX_COLS
 * arguments (C11 7.21.6.1: the excess ones are evaluated and ignored). */
static void csv_write(table_out *o, size_t rows)
{
    const bgt_table_pass *p = o->p;
    FILE *fp = o->fp;
    const int nnum = p->cols - p->flag_cols;
    char fmt[TABLE_MAX_COLS * 6 + 1];
    size_t n = 0;
    for (int k = 0; k < nnum; k++)
        n += (size_t)snprintf(fmt + n, sizeof fmt - n, "%s%s", k ? "," : "",
                              p->dbl ? "%.17g" : "%.9g");
    for (size_t r = 0; r < rows; r++) {
        double v[TABLE_MAX_COLS] = {0};
        for (int k = 0; k < p->cols; k++)
            v[k] = p->dbl ? p->dcols[k][r] : (double)p->fcols[k][r];
        const char *x;
        size_t xl;
        bgt_csv_write_row_prefix(fp, o->in, r, &x, &xl);
        fprintf(fp, fmt, v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9], v[10], v[11]);
        for (int k = nnum; k < p->cols; k++) {
            putc(',', fp);
            putc(v[k] != 0 ? '1' : '0', fp);
        }
        bgt_csv_write_row_suffix(fp, o->in, x, xl);
    }
}

static bg_status csv_finish(table_out *o, const char *name, bgt_err *e)
{
    (void)o, (void)name, (void)e;
    return BG_OK;
}

static const table_writer writers[] = {
    {npy_claims, npy_begin, npy_write, npy_finish},
    {any_claims, csv_begin, csv_write, csv_finish},
};

static const table_reader *pick_reader(const char *path)
{
    const table_reader *r = readers;
    while (!r->claims(path))
        r++;
    return r;
}

static const table_writer *pick_writer(const char *path)
{
    const table_writer *w = writers;
    while (!w->claims(path))
        w++;
    return w;
}

/* ---- the pass ---- */

bg_status bgt_table_run(const bgt_table_pass *p, bgt_err *e)
{
    if (p->cols < 1 || p->cols > TABLE_MAX_COLS || p->count > p->cols || p->flag_cols < 0 ||
        p->flag_cols > p->cols - p->count)
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "%s: %d output columns (1..%d)", p->label,
                        p->cols, TABLE_MAX_COLS);
    const table_reader *rd = pick_reader(p->input);
    const table_writer *wr = pick_writer(p->output);
    table_in tin;
    memset(&tin, 0, sizeof tin);
    bg_status rc;
    if ((rc = rd->open(&tin, e, p->input, p)))
        return rc;
    void *mem = malloc(p->mem_bytes);
    if (!mem) {
        rd->close(&tin);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    }
    p->bind(p->ctx, mem);

    bgt_safe_file out;
    if ((rc = bgt_safe_open(&out, p->output, e))) {
        free(mem);
        rd->close(&tin);
        return rc;
    }
    static char obuf[1 << 16];
    setvbuf(out.fp, obuf, _IOFBF, sizeof obuf);
    table_out tout = {.fp = out.fp, .p = p, .in = &tin.csv};
    rc = wr->begin(&tout, e);

    bgt_progress_begin(p->progress, p->label, rd->size(&tin));
    size_t total_rows = 0;
    while (!rc) {
        size_t rows;
        rc = rd->read(&tin, p, &rows);
        if (rc || rows == 0)
            break;
        bgt_parallel_for(rows, p->chunk, p->threads, p->chunk_fn, p->ctx);
        if (p->block_done)
            p->block_done(p->ctx, rows);
        wr->write(&tout, rows);
        if (ferror(out.fp)) {
            rc = bgt_fail(e, BG_ERR_IO, "writing %s failed: %s",
                          strcmp(p->output, "-") ? p->output : "standard output", strerror(errno));
            break;
        }
        total_rows += rows;
        if (p->rows)
            *p->rows = total_rows;
        bgt_progress_update(p->progress, rd->consumed(&tin));
    }
    bgt_progress_end(p->progress);
    rd->close(&tin);
    free(mem);
    if (!rc)
        rc = wr->finish(&tout, p->output, e);
    if (rc) {
        bgt_safe_abort(&out);
        return rc;
    }
    return bgt_safe_commit(&out, e);
}
