/* SPDX-License-Identifier: MIT */
/* Between peers.c and the peer wrappers, each built only if its library was
 * found at configure time (bench/meson.build defines BGT_HAVE_PEER_STB and
 * BGT_HAVE_PEER_CXX); the C++ one sits behind extern "C". */
#ifndef BUMPGRAD_TOOLS_BENCH_PEERS_H
#define BUMPGRAD_TOOLS_BENCH_PEERS_H

#include <stddef.h>
#include "bench/bench.h"
#include "bumpgrad/noise.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Value + central-difference gradient from any scalar noise `f`: the 7
 * evaluations a caller without an analytic gradient pays, with the step of
 * bumpgrad's own central differences (BG_DEFAULT_CENTRAL_STEP), dividing by the
 * step actually taken in float, as bg_fractal3_grad_central does, so both sides
 * of the grad_central comparison do the same arithmetic. Inline so that a
 * constant `f` is inlined into each peer's loop. */
static inline void bench_central7_batch(float (*f)(float, float, float), const float *x,
                                        const float *y, const float *z, size_t n, float *v,
                                        float *gx, float *gy, float *gz)
{
    const float h = BG_DEFAULT_CENTRAL_STEP;
    for (size_t i = 0; i < n; i++) {
        float px = x[i], py = y[i], pz = z[i];
        float xp = px + h, xm = px - h, yp = py + h, ym = py - h, zp = pz + h, zm = pz - h;
        v[i] = f(px, py, pz);
        gx[i] = (f(xp, py, pz) - f(xm, py, pz)) / (xp - xm);
        gy[i] = (f(px, yp, pz) - f(px, ym, pz)) / (yp - ym);
        gz[i] = (f(px, py, zp) - f(px, py, zm)) / (zp - zm);
    }
}

/* Each returns the number of entries written to `out` (at most `cap`). */
size_t bench_peers_stb(bgt_bench_peer *out, size_t cap); /* peer_stb.c */
size_t bench_peers_cxx(bgt_bench_peer *out, size_t cap); /* peers_cxx.cc */

#ifdef __cplusplus
}
#endif

#endif
