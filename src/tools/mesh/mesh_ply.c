/* SPDX-License-Identifier: MIT */
/* PLY writer of `bumpgrad mesh` (format: docs/MESH.md). Binary output is
 * little-endian on every host: bytes are assembled explicitly instead of
 * dumping memory, so a big-endian build writes the same file. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "mesh/mesh_internal.h"

/* Rows are staged in a buffer so that one fwrite moves many vertices. */
typedef struct sink {
    FILE *fp;
    unsigned char buf[1 << 16];
    size_t len;
    int bad;
} sink;

static void sink_flush(sink *s)
{
    if (s->len && fwrite(s->buf, 1, s->len, s->fp) != s->len)
        s->bad = 1;
    s->len = 0;
}

static void put_bytes(sink *s, const void *p, size_t n)
{
    if (s->len + n > sizeof s->buf)
        sink_flush(s);
    memcpy(s->buf + s->len, p, n);
    s->len += n;
}

static void put_u32(sink *s, uint32_t v)
{
    unsigned char b[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16),
                          (unsigned char)(v >> 24)};
    put_bytes(s, b, 4);
}

static void put_f32(sink *s, float f)
{
    uint32_t v;
    memcpy(&v, &f, 4);
    put_u32(s, v);
}

static void put_u8(sink *s, unsigned char c) { put_bytes(s, &c, 1); }

/* %.9g round-trips every float exactly; NaN is written as "nan" (lower case,
 * unsigned), which the common PLY readers (assimp, numpy, Blender) accept. */
static void put_text_f32(sink *s, float f, int last)
{
    char tmp[32];
    int n;
    if (f != f)
        n = snprintf(tmp, sizeof tmp, "nan");
    else
        n = snprintf(tmp, sizeof tmp, "%.9g", (double)f);
    if (n < 0 || (size_t)n >= sizeof tmp - 1)
        n = 0;
    tmp[n++] = last ? '\n' : ' ';
    put_bytes(s, tmp, (size_t)n);
}

int mesh_ply_write(FILE *fp, const mesh_ply_out *d)
{
    const char *prop[16];
    const float *col[16];
    int nprop = 0;
#define ADD(name, arr) (prop[nprop] = (name), col[nprop++] = (arr))
    ADD("x", d->px), ADD("y", d->py), ADD("z", d->pz);
    ADD("nx", d->nx), ADD("ny", d->ny), ADD("nz", d->nz);
    ADD("ox", d->ox), ADD("oy", d->oy), ADD("oz", d->oz);
    ADD("height", d->height);
    if (d->compare)
        ADD("compare_deg", d->compare);
    if (d->u && d->v) {
        ADD("s", d->u);
        ADD("t", d->v);
    }
#undef ADD

    fprintf(fp, "ply\nformat %s 1.0\n", d->ascii ? "ascii" : "binary_little_endian");
    if (d->comment)
        fprintf(fp, "comment %s\n", d->comment);
    fprintf(fp, "element vertex %zu\n", d->vertex_count);
    for (int k = 0; k < nprop; k++)
        fprintf(fp, "property float %s\n", prop[k]);
    fprintf(fp, "element face %zu\nproperty list uchar uint vertex_indices\nend_header\n",
            d->triangle_count);

    sink *s = malloc(sizeof *s); /* 64 KiB: too big for a polite stack frame */
    if (!s)
        return 1;
    s->fp = fp;
    s->len = 0;
    s->bad = 0;
    for (size_t i = 0; i < d->vertex_count && !s->bad; i++) {
        for (int k = 0; k < nprop; k++) {
            if (d->ascii)
                put_text_f32(s, col[k][i], k == nprop - 1);
            else
                put_f32(s, col[k][i]);
        }
    }
    for (size_t t = 0; t < d->triangle_count && !s->bad; t++) {
        const uint32_t *ix = d->indices + 3 * t;
        if (d->ascii) {
            char tmp[48];
            int n = snprintf(tmp, sizeof tmp, "3 %u %u %u\n", (unsigned)ix[0], (unsigned)ix[1],
                             (unsigned)ix[2]);
            put_bytes(s, tmp, (size_t)n);
        } else {
            put_u8(s, 3);
            put_u32(s, ix[0]);
            put_u32(s, ix[1]);
            put_u32(s, ix[2]);
        }
    }
    sink_flush(s);
    int bad = s->bad || ferror(fp);
    free(s);
    return bad;
}
