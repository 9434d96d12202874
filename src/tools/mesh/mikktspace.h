/* SPDX-License-Identifier: MIT */
/* Per-corner tangent frames in the mikkTSpace convention: our own
 * implementation of the algorithm described in Mikkelsen's thesis ("Simulation
 * of wrinkled surfaces revisited", 2008, ch. 4) and in the documentation of
 * the reference mikktspace.h (welding, order-independent evaluation, fans of
 * same-orientation triangles, inheritance by degenerate primitives). It is
 * written from that description, not from the reference code, and compared
 * against the reference outside the repository (docs/MESH.md). Triangles only
 * (the meshes come triangulated by assimp). No I/O, libc + libm only.
 *
 * The rules, in order:
 *  1. Welding. Corners whose position, normal and UV are equal (float ==, so
 *     -0 == +0) are one vertex; everything below works on welded vertices, so
 *     an unwelded input gives the same result as its welded version.
 *  2. Degenerate triangles: two corners at the same position (or a non-finite
 *     position, our addition). They take part in nothing; afterwards each of
 *     their corners copies the frame of the first corner, in triangle order,
 *     of a non-degenerate triangle at the same welded vertex.
 *  3. Per triangle: the UV-space signed area A = du1 dv2 - du2 dv1 gives the
 *     orientation (A > 0: orientation preserving, sign +1; else -1) and the
 *     unit directions of dP/du and dP/dv, flipped by the orientation:
 *     os = s (e1 dv2 - e2 dv1) / |.|, ot = s (e2 du1 - e1 du2) / |.|.
 *     A triangle with |A|, |dP/du| or |dP/dv| not above FLT_MIN ("zero UV
 *     area") contributes no direction and joins whichever fan first reaches
 *     it, taking that fan's orientation.
 *  4. Fans. Around each welded vertex, triangles that are connected through
 *     shared edges (the two corners in opposite order, each edge matched once,
 *     first come first served in (min index, max index, triangle) order) and
 *     have the same orientation form one fan; each fan gets its own tangent.
 *  5. The tangent of a fan: sum over its non-zero-area triangles of
 *     angle * normalize(os - n (n . os)), with angle the corner angle between
 *     the two edges after projecting them onto the plane orthogonal to the
 *     corner's normal n; normalized. Triangles of a fan whose projected os
 *     (or ot) point exactly opposite are split apart first (the 180 degree
 *     threshold of the reference; skipped in fans of more than 256 triangles).
 *     "Exactly opposite" means a cosine not above cos(180 deg) rounded to
 *     float, i.e. -1, with the directions, projections, normalizations and
 *     the cosine computed in float in the order the description gives them:
 *     on real meshes (SphereWithLight.ac) cosines of -0.99999999999 occur,
 *     which float rounding sends to -1 or not, and only this order of float
 *     operations splits such pairs as the reference does.
 *  6. Output per corner: the tangent t (unit, orthogonal to n up to rounding)
 *     and the sign w = +1 / -1 of its fan; the bitangent is w cross(n, t).
 *     A corner that no fan reaches (a zero-UV-area island) gets (1,0,0), -1,
 *     like the reference. */
#ifndef BUMPGRAD_TOOLS_MIKKTSPACE_H
#define BUMPGRAD_TOOLS_MIKKTSPACE_H

#include <stddef.h>
#include <stdint.h>
#include "bumpgrad/common.h"

/** Input: an indexed triangle list with per-vertex attributes (SoA). The
 *  normals should be unit length (the projections assume it). */
typedef struct bgt_mikk_mesh {
    size_t vertex_count, triangle_count;
    const uint32_t *indices; /**< 3 per triangle */
    const float *px, *py, *pz;
    const float *nx, *ny, *nz;
    const float *u, *v;
} bgt_mikk_mesh;

typedef struct bgt_mikk_stats {
    size_t welded_vertices;  /**< distinct (position, normal, UV) among the referenced vertices */
    size_t degenerate;       /**< triangles with two corners at one position (rule 2) */
    size_t zero_uv_area;     /**< non-degenerate triangles without a UV direction (rule 3) */
    size_t fans;             /**< fans formed (rule 4) */
    size_t unreached;        /**< corners no fan reached (default frame) */
} bgt_mikk_stats;

/** Per-corner tangents: `out` holds 4 floats per corner (corner c = 3 t + k
 *  is corner k of triangle t): tangent x, y, z and the bitangent sign w.
 *  `stats` may be NULL. BG_OK, BG_ERR_NULL_POINTER, BG_ERR_INVALID_ARGUMENT
 *  (an index out of range, more than 2^31 - 1 triangles) or
 *  BG_ERR_OUT_OF_MEMORY. */
bg_status bgt_mikk_tangents(const bgt_mikk_mesh *m, float *out, bgt_mikk_stats *stats);
/** The same on `threads` worker threads (0: one per online core, which is
 *  what bgt_mikk_tangents uses; at most 256). The result does not depend on
 *  the count. */
bg_status bgt_mikk_tangents_threads(const bgt_mikk_mesh *m, float *out, bgt_mikk_stats *stats,
                                    int threads);

/** The frame a mikkTSpace renderer builds inside a triangle: the corner
 *  tangents, signs and normals interpolated with the barycentric weights w
 *  and NOT normalized (mikktspace.h, "pixel shader (fast transform out)"):
 *  t = sum w_k t_k, n = sum w_k n_k, b = (sum w_k s_k) cross(n, t).
 *  `tan` holds the triangle's 3 corners (4 floats each, as bgt_mikk_tangents
 *  writes them), `nrm` its 3 unit vertex normals (3 floats each). */
typedef struct bgt_mikk_frame {
    double t[3], b[3], n[3];
} bgt_mikk_frame;
void bgt_mikk_frame_at(const float *const tan[3], const float *const nrm[3], const double w[3],
                       bgt_mikk_frame *f);

/** The renderer's decoding: normalize(m.x t + m.y b + m.z n). Returns 0, or
 *  -1 (out set to 0) when the result has no direction. */
int bgt_mikk_decode(const bgt_mikk_frame *f, const double m[3], double out[3]);

/** The baker's encoding, the exact inverse of bgt_mikk_decode (the sampler of
 *  mikktspace.h): m = normalize(s (row0 . v, row1 . v, row2 . v)) with
 *  row0 = b x n, row1 = n x t, row2 = t x b and s the sign of t . row0, so
 *  that decoding m gives back normalize(v). Returns 0, or -1 (m set to 0)
 *  when the frame is singular or m has no direction. */
int bgt_mikk_encode(const bgt_mikk_frame *f, const double v[3], double m[3]);

#endif
