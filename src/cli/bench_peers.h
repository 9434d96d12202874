/* SPDX-License-Identifier: MIT */
/* Internal interface between `bumpgrad bench` (cmd_bench.c) and the peer
 * wrappers: other noise libraries from Debian measured in the same run, so that
 * the ratios in docs/PERFORMANCE.md come from one machine state. Each wrapper
 * file exists only if its library was found at configure time (meson defines
 * CLI_HAVE_PEER_STB / CLI_HAVE_PEER_CXX); the C++ ones sit behind extern "C". */
#ifndef BUMPGRAD_CLI_BENCH_PEERS_H
#define BUMPGRAD_CLI_BENCH_PEERS_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The three operations every peer is measured on (the same meaning for all):
 *  value        : one octave of 3-D Perlin noise per point;
 *  fbm          : 6 octaves, lacunarity 2, gain 0.5, first octave at frequency 1;
 *  grad_central : value plus a central-difference gradient with step
 *                 BG_DEFAULT_CENTRAL_STEP, i.e. 7 evaluations of one octave, the
 *                 way a caller without an analytic gradient gets one. */
typedef enum cli_peer_op {
    CLI_PEER_VALUE = 0,
    CLI_PEER_FBM = 1,
    CLI_PEER_GRAD_CENTRAL = 2
} cli_peer_op;

/* A batch over SoA points; gx/gy/gz are written only by CLI_PEER_GRAD_CENTRAL.
 * Reentrant (the peers keep no mutable state between calls). */
typedef void (*cli_peer_fn)(const float *x, const float *y, const float *z, size_t n, float *v,
                            float *gx, float *gy, float *gz);

typedef struct cli_peer {
    const char *library; /* "stb_perlin", "libnoise", "glm" */
    cli_peer_op op;
    cli_peer_fn run;
} cli_peer;

/* Each returns the number of entries written to `out` (at most `cap`). */
size_t cli_bench_peers_stb(cli_peer *out, size_t cap); /* bench_peer_stb.c */
size_t cli_bench_peers_cxx(cli_peer *out, size_t cap); /* bench_peers.cc */

#ifdef __cplusplus
}
#endif

#endif
