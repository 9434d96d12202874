/* SPDX-License-Identifier: MIT */
/* Mesh-level frames for `bumpgrad mesh`: angle-weighted vertex normals (the
 * tangents are mikktspace.c's, per corner). Sums run in double: a vertex of
 * a fine mesh collects many small, nearly parallel contributions, and float
 * sums would lose the tail digits that the tests compare against a float64 reference. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "mesh/mesh_internal.h"
#include "vecmath.h"

static bg_dvec3 vertex_pos(const bg_mesh *m, uint32_t i)
{
    return (bg_dvec3){m->px[i], m->py[i], m->pz[i]};
}

int mesh_triangle_usable(const bg_mesh *m, size_t t)
{
    const uint32_t *ix = m->indices + 3 * t;
    if (ix[0] == ix[1] || ix[1] == ix[2] || ix[0] == ix[2])
        return 0;
    bg_dvec3 p0 = vertex_pos(m, ix[0]), p1 = vertex_pos(m, ix[1]), p2 = vertex_pos(m, ix[2]);
    bg_dvec3 c = bg_dv3_cross(bg_dv3_sub(p1, p0), bg_dv3_sub(p2, p0));
    double a = bg_dv3_length_naive(c);
    /* A NaN/Inf corner makes the length NaN/Inf, so one test covers both. */
    return isfinite(a) && a > 0.0;
}

/* Stores v / |v| (normalized in double, rounded once) or, when v has no
 * direction (zero, NaN, Inf: no usable triangle, or contributions that cancel
 * exactly), the surfgrad.h sentinel (0,0,0). Returns 1 for the sentinel. */
static int store_unit(bg_dvec3 v, float *x, float *y, float *z)
{
    double l = bg_dv3_length_naive(v);
    if (!(isfinite(l) && l > 0.0)) {
        *x = *y = *z = 0.0f;
        return 1;
    }
    *x = (float)(v.x / l), *y = (float)(v.y / l), *z = (float)(v.z / l);
    return 0;
}

size_t mesh_normalize_normals(size_t n, float *nx, float *ny, float *nz)
{
    size_t none = 0;
    for (size_t i = 0; i < n; i++) {
        bg_dvec3 v = {nx[i], ny[i], nz[i]};
        none += (size_t)store_unit(v, nx + i, ny + i, nz + i);
    }
    return none;
}

/* Corner angles of a triangle whose doubled area is `c2a` = |e01 x e02|: every
 * pair of edges has that same cross-product length, so atan2(|a x b|, a.b)
 * (accurate at any angle, unlike acos) needs one length for all three. */
static void corner_angles(bg_dvec3 p0, bg_dvec3 p1, bg_dvec3 p2, double c2a, double ang[3])
{
    bg_dvec3 e01 = bg_dv3_sub(p1, p0), e02 = bg_dv3_sub(p2, p0), e12 = bg_dv3_sub(p2, p1);
    ang[0] = atan2(c2a, bg_dv3_dot(e01, e02));
    ang[1] = atan2(c2a, -bg_dv3_dot(e01, e12));
    ang[2] = atan2(c2a, bg_dv3_dot(e02, e12));
}

size_t mesh_vertex_normals(const bg_mesh *m, float *nx, float *ny, float *nz)
{
    size_t nv = m->vertex_count;
    double *acc = calloc(nv ? 3 * nv : 1, sizeof *acc);
    if (!acc)
        return (size_t)-1;
    for (size_t t = 0; t < m->triangle_count; t++) {
        if (!mesh_triangle_usable(m, t))
            continue;
        const uint32_t *ix = m->indices + 3 * t;
        bg_dvec3 p0 = vertex_pos(m, ix[0]), p1 = vertex_pos(m, ix[1]), p2 = vertex_pos(m, ix[2]);
        bg_dvec3 c = bg_dv3_cross(bg_dv3_sub(p1, p0), bg_dv3_sub(p2, p0));
        double c2a = bg_dv3_length_naive(c);
        bg_dvec3 fn = bg_dv3_scale(c, 1.0 / c2a);
        double ang[3];
        corner_angles(p0, p1, p2, c2a, ang);
        for (int k = 0; k < 3; k++) {
            double *a = acc + 3 * (size_t)ix[k];
            a[0] += ang[k] * fn.x;
            a[1] += ang[k] * fn.y;
            a[2] += ang[k] * fn.z;
        }
    }
    size_t none = 0;
    for (size_t i = 0; i < nv; i++) {
        bg_dvec3 v = {acc[3 * i], acc[3 * i + 1], acc[3 * i + 2]};
        none += (size_t)store_unit(v, nx + i, ny + i, nz + i);
    }
    free(acc);
    return none;
}

double mesh_uv_signed_area(const bg_mesh *m, size_t t)
{
    const uint32_t *ix = m->indices + 3 * t;
    double du1 = (double)m->u[ix[1]] - m->u[ix[0]], dv1 = (double)m->v[ix[1]] - m->v[ix[0]];
    double du2 = (double)m->u[ix[2]] - m->u[ix[0]], dv2 = (double)m->v[ix[2]] - m->v[ix[0]];
    return du1 * dv2 - du2 * dv1;
}

/* The sphere around the finite vertices: its centre c (of their bounding
 * box) and radius, 0 or NaN when there is no finite extent. */
double mesh_bounding_sphere(const bg_mesh *bm, double c[3])
{
    const size_t nv = bm->vertex_count;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < nv; i++) {
        double p[3] = {bm->px[i], bm->py[i], bm->pz[i]};
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
            continue;
        for (int a = 0; a < 3; a++)
            lo[a] = fmin(lo[a], p[a]), hi[a] = fmax(hi[a], p[a]);
    }
    double rad = 0;
    for (int a = 0; a < 3; a++)
        c[a] = 0.5 * (lo[a] + hi[a]);
    for (size_t i = 0; i < nv; i++) {
        double d[3] = {bm->px[i] - c[0], bm->py[i] - c[1], bm->pz[i] - c[2]};
        double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (isfinite(r) && r > rad)
            rad = r;
    }
    return rad;
}
