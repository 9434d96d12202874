/* SPDX-License-Identifier: MIT */
/* Ray casting through Embree 3 (libembree-dev; an optional dependency of the
 * tools only, never of libbumpgrad): one static triangle geometry built from a
 * render_mesh, rtcIntersect1 per ray. Embree's primID is the triangle index and
 * its (u, v) are the barycentrics of vertices 1 and 2, exactly what
 * render_mesh_intersect returns, so the rest of the renderer does not know
 * which one traced the ray. Without BG_HAVE_EMBREE the calls fail cleanly and
 * the renderer keeps its own BVH (render_mesh.c). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include "render/render_internal.h"

#ifdef BG_HAVE_EMBREE
#include <embree3/rtcore.h>

struct render_embree {
    RTCDevice device;
    RTCScene scene;
};

int render_embree_available(void) { return 1; }

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

bg_status render_embree_build(const render_mesh *m, int threads, render_embree **out,
                              double *build_seconds, bgt_err *e)
{
    *out = NULL;
    if (m->ntri > (size_t)UINT32_MAX / 3)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "embree: %zu triangles are too many", m->ntri);
    double t0 = now_seconds();
    render_embree *r = calloc(1, sizeof *r);
    if (!r)
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "out of memory");
    /* Embree's build threads: as many as the render's (--threads), else its
     * task scheduler's default, every core. */
    char cfg[64];
    if (threads > 0)
        snprintf(cfg, sizeof cfg, "verbose=0,threads=%d", threads);
    else
        snprintf(cfg, sizeof cfg, "verbose=0");
    r->device = rtcNewDevice(cfg);
    if (!r->device) {
        free(r);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "embree: cannot create a device");
    }
    r->scene = rtcNewScene(r->device);
    rtcSetSceneBuildQuality(r->scene, RTC_BUILD_QUALITY_MEDIUM);
    RTCGeometry g = rtcNewGeometry(r->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    /* A new (Embree-owned, padded) buffer: shared buffers must be readable 16
     * bytes past their end, which a malloc'ed soup does not promise. */
    float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                       3 * sizeof(float), m->ntri * 3);
    unsigned *ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                           3 * sizeof(unsigned), m->ntri);
    if (!v || !ix) {
        rtcReleaseGeometry(g);
        render_embree_free(r);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "embree: out of memory for %zu triangles",
                        m->ntri);
    }
    memcpy(v, m->pos, m->ntri * 9 * sizeof(float));
    for (size_t i = 0; i < m->ntri * 3; i++)
        ix[i] = (unsigned)i;
    rtcCommitGeometry(g);
    rtcAttachGeometry(r->scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(r->scene);
    if (rtcGetDeviceError(r->device) != RTC_ERROR_NONE) {
        render_embree_free(r);
        return bgt_fail(e, BG_ERR_OUT_OF_MEMORY, "embree: the scene build failed");
    }
    if (build_seconds)
        *build_seconds = now_seconds() - t0;
    *out = r;
    return BG_OK;
}

void render_embree_free(render_embree *r)
{
    if (!r)
        return;
    if (r->scene)
        rtcReleaseScene(r->scene);
    if (r->device)
        rtcReleaseDevice(r->device);
    free(r);
}

int render_embree_intersect(const render_embree *r, const float o[3], const float d[3],
                            render_hit *hit)
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRayHit rh;
    rh.ray.org_x = o[0], rh.ray.org_y = o[1], rh.ray.org_z = o[2];
    rh.ray.dir_x = d[0], rh.ray.dir_y = d[1], rh.ray.dir_z = d[2];
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = INFINITY;
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(r->scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return 0;
    hit->t = rh.ray.tfar;
    hit->prim = (int)rh.hit.primID;
    hit->b1 = rh.hit.u, hit->b2 = rh.hit.v;
    return 1;
}

#else /* !BG_HAVE_EMBREE */

struct render_embree {
    int unused;
};

int render_embree_available(void) { return 0; }

bg_status render_embree_build(const render_mesh *m, int threads, render_embree **out,
                              double *build_seconds, bgt_err *e)
{
    (void)m, (void)threads, (void)build_seconds;
    *out = NULL;
    return bgt_fail(e, BG_ERR_INVALID_ARGUMENT,
                    "--tracer embree: this bumpgrad was built without Embree (libembree-dev)");
}

void render_embree_free(render_embree *r) { free(r); }

int render_embree_intersect(const render_embree *r, const float o[3], const float d[3],
                            render_hit *hit)
{
    (void)r, (void)o, (void)d, (void)hit;
    return 0;
}

#endif
