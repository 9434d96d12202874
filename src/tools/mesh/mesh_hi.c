/* SPDX-License-Identifier: MIT */
/* The high-poly source of `bumpgrad mesh LOW --from HIGH` (docs/MESH.md,
 * "High-poly to low-poly"): HIGH (any mesh assimp reads, UVs not needed,
 * several meshes flattened into one) in LOW's height frame, its unit vertex
 * normals (the file's, else angle-weighted), one Embree 3 scene of its usable
 * triangles, and an optional cage with LOW's triangles. mesh_hi_trace_n casts
 * the rays of a chunk of samples of the bake (mesh_bake.c). Embree is an optional
 * dependency of the tools: without it mesh_hi_open fails with a clear
 * message. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "mesh/mesh_internal.h"

#ifdef BG_HAVE_EMBREE
#include <embree3/rtcore.h>

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Load one mesh of --from / --cage; a load error names the option. */
static bg_status load(const char *opt, const char *path, unsigned join, bg_mesh *m, bgt_err *e)
{
    char err[512];
    bg_status st = bg_mesh_load_ex(path, join, m, err, sizeof err);
    if (st != BG_OK)
        return bgt_fail(e, bgt_read_status(st), "%s: %s", opt, err);
    return BG_OK;
}

/* Positions into the height frame (p - c) / r, in place (r = 1, c = 0: the
 * file's units). */
static void to_frame(bg_mesh *m, const double c[3], double r)
{
    for (size_t i = 0; i < m->vertex_count; i++) {
        m->px[i] = mesh_model_coord(m->px[i], c[0], r);
        m->py[i] = mesh_model_coord(m->py[i], c[1], r);
        m->pz[i] = mesh_model_coord(m->pz[i], c[2], r);
    }
}

#endif

void mesh_hi_close(mesh_hi *hi)
{
    if (!hi)
        return;
#ifdef BG_HAVE_EMBREE
    if (hi->scene)
        rtcReleaseScene((RTCScene)hi->scene);
    if (hi->device)
        rtcReleaseDevice((RTCDevice)hi->device);
#endif
    if (hi->own_normals) {
        free(hi->nx);
        free(hi->ny);
        free(hi->nz);
    }
    free(hi->prim);
    bg_mesh_free(&hi->high);
    if (hi->has_cage)
        bg_mesh_free(&hi->cage);
    memset(hi, 0, sizeof *hi);
}

bg_status mesh_hi_open(mesh_hi *hi, const char *high_path, const char *cage_path,
                       const bg_mesh *low, unsigned join, const double centre[3], double radius,
                       double distance, int threads, bgt_err *e)
{
    memset(hi, 0, sizeof *hi);
#ifndef BG_HAVE_EMBREE
    (void)high_path, (void)cage_path, (void)low, (void)join, (void)centre, (void)radius;
    (void)distance, (void)threads;
    return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                    "--from: this bumpgrad was built without Embree (libembree-dev), which the "
                    "high-poly bake casts its rays with");
#else
    if (!(distance > 0.0) || !isfinite(distance))
        return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                        "--ray-distance %g: expected a finite distance > 0", distance);
    hi->distance = (float)distance;
    bg_status st = load("--from", high_path, join, &hi->high, e);
    if (st != BG_OK)
        return st;
    bg_mesh *h = &hi->high;
    size_t usable = 0;
    for (size_t t = 0; t < h->triangle_count; t++)
        usable += (size_t)mesh_triangle_usable(h, t);
    if (usable == 0) {
        st = bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                      "--from '%s': no usable triangle (%zu triangles, all degenerate or with "
                      "NaN/Inf corners): nothing for the rays to hit",
                      high_path, h->triangle_count);
        goto fail;
    }
    if (usable > (size_t)UINT32_MAX / 3 || h->vertex_count > (size_t)UINT32_MAX) {
        st = bgt_fail(e, BG_ERR_INVALID_ARGUMENT, "--from '%s': %zu triangles are too many",
                      high_path, usable);
        goto fail;
    }
    /* Embree's copies (positions padded, indices) and ours (the primitive
     * map; the normals when computed). */
    double bytes = 16.0 * (double)h->vertex_count + 12.0 * (double)h->vertex_count +
                   16.0 * (double)usable + 64.0 * (double)usable /* the BVH, about */;
    if ((st = bgt_check_alloc(bytes, "the high-poly mesh's ray tracing", e)) != BG_OK)
        goto fail;
    to_frame(h, centre, radius);
    /* HIGH's unit shading normals: the file's, else angle-weighted. */
    if (h->nx) {
        hi->nx = h->nx, hi->ny = h->ny, hi->nz = h->nz;
        mesh_normalize_normals(h->vertex_count, hi->nx, hi->ny, hi->nz);
        hi->file_normals = 1;
    } else {
        size_t nv = h->vertex_count ? h->vertex_count : 1;
        hi->own_normals = 1;
        hi->nx = malloc(nv * sizeof *hi->nx);
        hi->ny = malloc(nv * sizeof *hi->ny);
        hi->nz = malloc(nv * sizeof *hi->nz);
        if (!hi->nx || !hi->ny || !hi->nz ||
            mesh_vertex_normals(h, hi->nx, hi->ny, hi->nz) == (size_t)-1) {
            st = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for the normals of --from");
            goto fail;
        }
    }
    hi->prim = malloc(usable * sizeof *hi->prim);
    if (!hi->prim) {
        st = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory for %zu triangles", usable);
        goto fail;
    }

    double t0 = now_seconds();
    char cfg[64];
    if (threads > 0)
        snprintf(cfg, sizeof cfg, "verbose=0,threads=%d", threads);
    else
        snprintf(cfg, sizeof cfg, "verbose=0");
    RTCDevice dev = rtcNewDevice(cfg);
    if (!dev) {
        st = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "embree: cannot create a device");
        goto fail;
    }
    hi->device = dev;
    RTCScene scene = rtcNewScene(dev);
    hi->scene = scene;
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_MEDIUM);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    /* Embree-owned buffers: shared ones must be readable 16 bytes past
     * their end, which our arrays do not promise. */
    float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                       3 * sizeof(float), h->vertex_count);
    unsigned *ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                           3 * sizeof(unsigned), usable);
    if (!v || !ix) {
        rtcReleaseGeometry(g);
        st = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "embree: out of memory for %zu triangles",
                      usable);
        goto fail;
    }
    for (size_t i = 0; i < h->vertex_count; i++) {
        /* a NaN vertex is only referenced by unusable triangles; give Embree 0 */
        int ok = isfinite(h->px[i]) && isfinite(h->py[i]) && isfinite(h->pz[i]);
        v[3 * i] = ok ? h->px[i] : 0.0f;
        v[3 * i + 1] = ok ? h->py[i] : 0.0f;
        v[3 * i + 2] = ok ? h->pz[i] : 0.0f;
    }
    size_t k = 0;
    for (size_t t = 0; t < h->triangle_count; t++) {
        if (!mesh_triangle_usable(h, t))
            continue;
        memcpy(ix + 3 * k, h->indices + 3 * t, 3 * sizeof *ix);
        hi->prim[k++] = (uint32_t)t;
    }
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
    if (rtcGetDeviceError(dev) != RTC_ERROR_NONE) {
        st = bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "embree: the scene build of --from failed");
        goto fail;
    }
    hi->build_seconds = now_seconds() - t0;
    hi->usable = usable;

    if (cage_path) {
        if ((st = load("--cage", cage_path, join, &hi->cage, e)) != BG_OK)
            goto fail;
        hi->has_cage = 1;
        if (hi->cage.triangle_count != low->triangle_count) {
            st = bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                          "--cage '%s' has another topology than the low-poly mesh: %zu "
                          "triangles against %zu (a cage is the low-poly mesh with its vertices "
                          "moved outward, triangle for triangle)",
                          cage_path, hi->cage.triangle_count, low->triangle_count);
            goto fail;
        }
        to_frame(&hi->cage, centre, radius);
    }
    return BG_OK;
fail:
    mesh_hi_close(hi);
    return st;
#endif
}

#ifdef BG_HAVE_EMBREE
/* HIGH's point and normal at a hit of primitive prim, barycentrics (b1, b2) */
static void hit_at(const mesh_hi *hi, unsigned prim, float b1, float b2, double dist,
                   mesh_hi_hit *out);

static void ray_init(struct RTCRayHit *rh, const float o[3], const float d[3], float tfar)
{
    rh->ray.org_x = o[0], rh->ray.org_y = o[1], rh->ray.org_z = o[2];
    rh->ray.dir_x = d[0], rh->ray.dir_y = d[1], rh->ray.dir_z = d[2];
    rh->ray.tnear = 0.0f;
    rh->ray.tfar = tfar;
    rh->ray.time = 0.0f;
    rh->ray.mask = 0xFFFFFFFFu;
    rh->ray.id = 0;
    rh->ray.flags = 0;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

#endif

int mesh_hi_trace_n(const mesh_hi *hi, size_t n, const float *px, const float *py,
                    const float *pz, const float *qx, const float *qy, const float *qz,
                    const float *cage, mesh_hi_hit *out, float *hit)
{
#ifndef BG_HAVE_EMBREE
    (void)hi, (void)n, (void)px, (void)py, (void)pz, (void)qx, (void)qy, (void)qz, (void)cage;
    (void)out, (void)hit;
    return 0;
#else
    struct RTCRayHit *rh = malloc((n ? n : 1) * sizeof *rh);
    float *len = malloc((n ? n : 1) * sizeof *len);
    if (!rh || !len) {
        free(rh);
        free(len);
        return 0;
    }
    /* front rays (or the cage's), as one coherent stream */
    for (size_t s = 0; s < n; s++) {
        double d[3];
        if (cage)
            d[0] = (double)px[s] - cage[3 * s], d[1] = (double)py[s] - cage[3 * s + 1],
            d[2] = (double)pz[s] - cage[3 * s + 2];
        else
            d[0] = qx[s], d[1] = qy[s], d[2] = qz[s];
        double l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        int ok = l > 0.0 && isfinite(l);
        float df[3] = {ok ? (float)(d[0] / l) : 0.0f, ok ? (float)(d[1] / l) : 0.0f,
                       ok ? (float)(d[2] / l) : 1.0f};
        float o[3] = {px[s], py[s], pz[s]};
        len[s] = (float)l;
        if (cage)
            ray_init(&rh[s], cage + 3 * s, df, ok ? (float)(2.0 * l) : -1.0f);
        else
            ray_init(&rh[s], o, df, ok ? hi->distance : -1.0f);
    }
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcIntersect1M((RTCScene)hi->scene, &ctx, rh, (unsigned)n, sizeof *rh);
    for (size_t s = 0; s < n; s++) {
        hit[s] = 0.0f;
        if (rh[s].hit.geomID == RTC_INVALID_GEOMETRY_ID)
            continue;
        hit[s] = 1.0f;
        double dist = cage ? (double)len[s] - (double)rh[s].ray.tfar : (double)rh[s].ray.tfar;
        hit_at(hi, rh[s].hit.primID, rh[s].hit.u, rh[s].hit.v, dist, &out[s]);
    }
    if (!cage) {
        /* behind, only a hit strictly nearer than the one in front can win */
        for (size_t s = 0; s < n; s++) {
            float o[3] = {px[s], py[s], pz[s]};
            float df[3] = {-rh[s].ray.dir_x, -rh[s].ray.dir_y, -rh[s].ray.dir_z};
            float tf = hit[s] != 0.0f ? out[s].dist : hi->distance;
            int ok = len[s] > 0.0f && isfinite(len[s]) && tf > 0.0f;
            ray_init(&rh[s], o, df, ok ? (hit[s] != 0.0f ? nextafterf(tf, 0.0f) : tf) : -1.0f);
        }
        rtcIntersect1M((RTCScene)hi->scene, &ctx, rh, (unsigned)n, sizeof *rh);
        for (size_t s = 0; s < n; s++) {
            if (rh[s].hit.geomID == RTC_INVALID_GEOMETRY_ID)
                continue;
            hit[s] = 1.0f;
            hit_at(hi, rh[s].hit.primID, rh[s].hit.u, rh[s].hit.v, -(double)rh[s].ray.tfar,
                   &out[s]);
        }
    }
    free(rh);
    free(len);
    return 1;
#endif
}

#ifdef BG_HAVE_EMBREE
static void hit_at(const mesh_hi *hi, unsigned prim, float b1, float b2, double dist,
                   mesh_hi_hit *out)
{
    const bg_mesh *h = &hi->high;
    const uint32_t *ix = h->indices + 3 * (size_t)hi->prim[prim];
    float w0 = 1.0f - b1 - b2;
    out->p[0] = w0 * h->px[ix[0]] + b1 * h->px[ix[1]] + b2 * h->px[ix[2]];
    out->p[1] = w0 * h->py[ix[0]] + b1 * h->py[ix[1]] + b2 * h->py[ix[2]];
    out->p[2] = w0 * h->pz[ix[0]] + b1 * h->pz[ix[1]] + b2 * h->pz[ix[2]];
    out->n[0] = w0 * hi->nx[ix[0]] + b1 * hi->nx[ix[1]] + b2 * hi->nx[ix[2]];
    out->n[1] = w0 * hi->ny[ix[0]] + b1 * hi->ny[ix[1]] + b2 * hi->ny[ix[2]];
    out->n[2] = w0 * hi->nz[ix[0]] + b1 * hi->nz[ix[1]] + b2 * hi->nz[ix[2]];
    if (out->n[0] == 0.0f && out->n[1] == 0.0f && out->n[2] == 0.0f) {
        /* vertices without a normal: the triangle's own (winding = front) */
        double e1[3] = {(double)h->px[ix[1]] - h->px[ix[0]], (double)h->py[ix[1]] - h->py[ix[0]],
                        (double)h->pz[ix[1]] - h->pz[ix[0]]};
        double e2[3] = {(double)h->px[ix[2]] - h->px[ix[0]], (double)h->py[ix[2]] - h->py[ix[0]],
                        (double)h->pz[ix[2]] - h->pz[ix[0]]};
        out->n[0] = (float)(e1[1] * e2[2] - e1[2] * e2[1]);
        out->n[1] = (float)(e1[2] * e2[0] - e1[0] * e2[2]);
        out->n[2] = (float)(e1[0] * e2[1] - e1[1] * e2[0]);
    }
    out->dist = (float)dist;
}
#endif
